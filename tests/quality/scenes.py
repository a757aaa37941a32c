"""Bundled quality scenes (issue 9): one small room per failure, as plain dicts.

Pure Python (no bpy). A scene dict has the layout tests/blender/cycles_ref.py
builds in Blender (`build_blender`):

    geometry:  list of dict(quad=[4 points], mat=name) or
               dict(tris=[[3 points], ...], normals=[[3 normals], ...] or None, mat=name)
               (normals: per-corner shading normals; the entry is smooth-shaded)
    materials: {name: dict(kind=diffuse|glossy|metal|principled|lambert_spec, color, roughness, ...,
               texture=image name: the image's RGB multiplies `color` (linear, bilinear, repeat))}
    images:    {name: dict(kind=planks|stripes|checker, size=(W, H), ...)} (optional): generated
               by texture_pixels; quads of a textured material carry uv=[4 (u, v)]
    lights:    list of dict(type=POINT|SPOT|SUN|AREA, energy, loc, rot (Euler XYZ degrees), ...)
    camera:    dict(type=PERSP|ORTHO, lens | ortho_scale, loc, rot, res=(W, H))

plus what only the harness reads: `extent` (m, the largest side of the room),
`convex` (True for an empty closed box: every point sees every other, so the
brute force needs no shadow rays),
`light_motion` (which light moves and how: `loc` a unit direction, or `rot` a
unit Euler-axis direction and `lever` (m), the distance at which the turn moves
the light's footprint by the step), `camera_motion` (a unit direction),
`feature` (what the scene is for, in words).

`case(name, size)` returns a scene at a size ("test", "bench" or (W, H));
`library_arrays(scene)` turns one into the keyword arguments of
`libvsgl.Scene` with Blender 3.4 semantics (no BLENDER_4 flags), exactly as
cycles_ref.library_scene does from the bpy-built scene (checked by
render_refs.py --check-builder); `animate(scene, kind, frame)` moves the light
or the camera by `extent / 1000` per frame.
"""
import copy
import math

import numpy as np

SIZES = {
    # name: (width, height, samples per seed)
    "test": (80, 60, 1024),
    "bench": (320, 240, 2048),
}
SEEDS = (1, 2)
FRAMES = 12
STEP = 1e-3  # of the scene's extent, per frame


# ---------------------------------------------------------------------------
# geometry helpers
# ---------------------------------------------------------------------------

def _r(v, nd=6):
    return tuple(round(float(x), nd) + 0.0 for x in v)  # + 0.0: no -0.0 in the hashed json


def look_rot(eye, target):
    """Blender Euler XYZ (degrees) of an object whose -Z axis points from eye
    to target with no roll (its +Y stays in the vertical plane)."""
    d = np.asarray(target, float) - np.asarray(eye, float)
    d /= np.linalg.norm(d)
    a = math.degrees(math.acos(max(-1.0, min(1.0, -d[2]))))
    c = math.degrees(math.atan2(-d[0], d[1]))
    return _r((a, 0.0, c), 4)


def quad(p0, p1, p2, p3, mat, uv=None):
    q = dict(quad=[_r(p0), _r(p1), _r(p2), _r(p3)], mat=mat)
    if uv is not None:
        q["uv"] = [_r(t) for t in uv]
    return q


def quad_uv(q, tile):
    """Quad q with UVs of `tile` m per repeat along its first and last edges (p0 -> p1, p0 -> p3)."""
    P = np.asarray(q["quad"], np.float64)
    a, b = np.linalg.norm(P[1] - P[0]) / tile, np.linalg.norm(P[3] - P[0]) / tile
    return dict(q, uv=[_r(t) for t in ((0.0, 0.0), (a, 0.0), (a, b), (0.0, b))])


def texture_pixels(spec):
    """An image of the scene's `images` table as (H, W, 4) float32 linear RGBA,
    rows bottom to top (Blender's Image.pixels order, the library's too):
    deterministic, from the spec alone (the cache key hashes the spec).
    planks: boards along u of `boards` per image, each its own tone of
    `color` times 0.7-1.3 (a fixed sequence) with dark seams; stripes:
    vertical bands alternating `colors` (`bands` per image); checker:
    `cells` x `cells` squares of the two `colors`."""
    w, h = spec["size"]
    u = (np.arange(w) + 0.5) / w
    v = (np.arange(h) + 0.5) / h
    U, V = np.meshgrid(u, v)
    k = spec["kind"]
    if k == "planks":
        n = spec["boards"]
        board = np.minimum((V * n).astype(int), n - 1)
        tone = 0.7 + 0.6 * ((np.arange(n) * 0.618034) % 1.0)
        grain = 0.92 + 0.08 * np.sin(U * 2 * np.pi * 7 + board * 1.7)
        seam = (np.abs((V * n) - np.round(V * n)) < 0.04).astype(np.float64)
        f = tone[board] * grain * (1.0 - 0.6 * seam)
        rgb = f[..., None] * np.asarray(spec["color"], np.float64)
    elif k == "stripes":
        c = np.asarray(spec["colors"], np.float64)
        idx = np.minimum((U * spec["bands"]).astype(int), spec["bands"] - 1) % len(c)
        rgb = c[idx]
    elif k == "checker":
        c = np.asarray(spec["colors"], np.float64)
        n = spec["cells"]
        idx = ((U * n).astype(int) + (V * n).astype(int)) % 2
        rgb = c[idx]
    else:
        raise ValueError("unknown image kind %r" % k)
    out = np.ones((h, w, 4), np.float32)
    out[..., :3] = np.clip(rgb, 0.0, 1.0)
    return out


def box_room(x0, x1, y0, y1, z0, z1, mats):
    """Six inward-facing quads; mats: floor, ceiling, left (x0), right (x1), back (y1), front (y0)."""
    return [
        quad((x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), mats["floor"]),
        quad((x0, y0, z1), (x0, y1, z1), (x1, y1, z1), (x1, y0, z1), mats["ceiling"]),
        quad((x0, y0, z0), (x0, y1, z0), (x0, y1, z1), (x0, y0, z1), mats["left"]),
        quad((x1, y0, z0), (x1, y0, z1), (x1, y1, z1), (x1, y1, z0), mats["right"]),
        quad((x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1), mats["back"]),
        quad((x0, y0, z0), (x0, y0, z1), (x1, y0, z1), (x1, y0, z0), mats["front"]),
    ]


def wall_x_with_hole(x, y0, y1, z0, z1, hy0, hy1, hz0, hz1, mat):
    """A wall in the plane x = const from (y0, z0) to (y1, z1) with a
    rectangular opening [hy0, hy1] x [hz0, hz1]: four quads around it."""
    def q(ya, yb, za, zb):
        return quad((x, ya, za), (x, yb, za), (x, yb, zb), (x, ya, zb), mat)
    return [q(y0, y1, z0, hz0), q(y0, y1, hz1, z1), q(y0, hy0, hz0, hz1), q(hy1, y1, hz0, hz1)]


def block(cx, cy, sx, sy, h, rot_z_deg, mat):
    """A block standing on z = 0 (five outward-facing quads, no bottom),
    sx x sy x h m, centred at (cx, cy), turned rot_z_deg about Z."""
    c, s = math.cos(math.radians(rot_z_deg)), math.sin(math.radians(rot_z_deg))

    def P(x, y, z):
        return (cx + c * x - s * y, cy + s * x + c * y, z)
    a, b = sx / 2, sy / 2
    return [quad(P(-a, -b, h), P(a, -b, h), P(a, b, h), P(-a, b, h), mat),
            quad(P(-a, -b, 0), P(a, -b, 0), P(a, -b, h), P(-a, -b, h), mat),
            quad(P(a, -b, 0), P(a, b, 0), P(a, b, h), P(a, -b, h), mat),
            quad(P(a, b, 0), P(-a, b, 0), P(-a, b, h), P(a, b, h), mat),
            quad(P(-a, b, 0), P(-a, -b, 0), P(-a, -b, h), P(-a, b, h), mat)]


def uv_sphere(centre, radius, segments, rings, mat):
    """Triangles of a UV sphere with radial (smooth) corner normals."""
    c = np.asarray(centre, float)

    def n_at(i, j):
        th = math.pi * j / rings
        ph = 2 * math.pi * i / segments
        return np.array([math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)])

    tris, nrms = [], []
    for j in range(rings):
        for i in range(segments):
            a, b = n_at(i, j), n_at(i + 1, j)
            cc, d = n_at(i + 1, j + 1), n_at(i, j + 1)
            faces = []
            if j > 0:
                faces.append((a, cc, b))      # a == b at the north pole
            if j < rings - 1:
                faces.append((a, d, cc))      # d == cc at the south pole
            for t in faces:
                tris.append([_r(c + radius * v) for v in t])
                nrms.append([_r(v) for v in t])
    return dict(tris=tris, normals=nrms, mat=mat)


# ---------------------------------------------------------------------------
# the scenes
# ---------------------------------------------------------------------------

WHITE = dict(kind="diffuse", color=(0.8, 0.8, 0.8))
GREY = dict(kind="diffuse", color=(0.6, 0.6, 0.6))


def _spot_metal_floor():
    # 6 x 6 x 3 m room; a spot under the ceiling aimed at the back wall; a
    # GGX metal floor (Glossy BSDF, roughness 0.2) reflects the lit ellipse
    mats = dict(floor="metal_floor", ceiling="ceiling", left="wall", right="wall", back="back_wall", front="wall")
    spot_loc, spot_target = (0.0, -1.0, 2.6), (0.0, 3.0, 1.5)
    cam_loc, cam_target = (0.0137, -2.8, 1.6), (0.0, 3.0, 0.9)
    return dict(
        name="spot_metal_floor",
        feature="a spot lights a diffuse back wall; the glossy metal floor (GGX, roughness 0.2) reflects the "
                "bright ellipse (issue 9: balanced/quality break it into blotchy lobes)",
        materials=dict(metal_floor=dict(kind="glossy", color=(0.9, 0.9, 0.9), roughness=0.2),
                       back_wall=WHITE, wall=WHITE, ceiling=WHITE),
        geometry=box_room(-3, 3, -3, 3, 0, 3, mats),
        lights=[dict(type="SPOT", energy=2500.0, loc=spot_loc, rot=look_rot(spot_loc, spot_target),
                     spot_size=40.0, spot_blend=0.3)],
        camera=dict(type="PERSP", lens=18.0, loc=cam_loc, rot=look_rot(cam_loc, cam_target)),
        convex=True,  # an empty closed box: every surface sees every other
        extent=6.0,
        light_motion=dict(light=0, loc=(1.0, 0.0, 0.0)),
        camera_motion=dict(loc=(1.0, 0.0, 0.0)),
    )


def _metal_floor_red_wall():
    # 5 x 5 x 2.8 m room; a spot lights the red left wall; red light reaches
    # the white back wall directly and through the glossy metal floor
    mats = dict(floor="metal_floor", ceiling="ceiling", left="red_wall", right="wall", back="back_wall",
                front="wall")
    spot_loc, spot_target = (1.6, -1.2, 2.5), (-2.5, 0.6, 1.1)
    cam_loc, cam_target = (1.2137, -2.3, 1.5), (-0.6, 2.5, 1.0)
    return dict(
        name="metal_floor_red_wall",
        feature="a spot lights a red diffuse wall; the back wall receives red light, directly and via the glossy "
                "metal floor (issue 9: round red blobs on the back wall, a visible grid in quality)",
        materials=dict(metal_floor=dict(kind="glossy", color=(0.85, 0.85, 0.85), roughness=0.25),
                       red_wall=dict(kind="diffuse", color=(0.8, 0.1, 0.1)),
                       back_wall=WHITE, wall=WHITE, ceiling=WHITE),
        geometry=box_room(-2.5, 2.5, -2.5, 2.5, 0, 2.8, mats),
        lights=[dict(type="SPOT", energy=2500.0, loc=spot_loc, rot=look_rot(spot_loc, spot_target),
                     spot_size=55.0, spot_blend=0.25)],
        camera=dict(type="PERSP", lens=18.0, loc=cam_loc, rot=look_rot(cam_loc, cam_target)),
        convex=True,  # an empty closed box: every surface sees every other
        extent=5.0,
        light_motion=dict(light=0, loc=(0.0, 1.0, 0.0)),
        camera_motion=dict(loc=(1.0, 0.0, 0.0)),
    )


def _box_point_area_glossy_green():
    # closed 3 x 3 x 2.5 m box, a point light and a small area light; the
    # right wall is a green GGX (roughness 0.25) that should show a smooth sheen
    mats = dict(floor="floor", ceiling="ceiling", left="wall", right="green_glossy", back="back_wall", front="wall")
    cam_loc, cam_target = (-1.2137, -1.35, 1.35), (0.9, 1.2, 1.3)
    return dict(
        name="box_point_area_glossy_green",
        feature="closed box lit by a point light and a small area light; one glossy green wall (GGX, roughness "
                "0.25) shows a sheen (issue 9: wavy, scalloped patches; balanced/quality 22-25 % dark); the "
                "camera frames the wall/ceiling and wall/floor junctions (issue 9: white-hot lines, dark seams)",
        materials=dict(green_glossy=dict(kind="glossy", color=(0.1, 0.7, 0.15), roughness=0.25),
                       floor=GREY, back_wall=WHITE, wall=WHITE, ceiling=WHITE),
        geometry=box_room(-1.5, 1.5, -1.5, 1.5, 0, 2.5, mats),
        lights=[dict(type="POINT", energy=80.0, loc=(-0.45, 0.25, 1.7), rot=(0.0, 0.0, 0.0)),
                dict(type="AREA", energy=40.0, loc=(0.55, 0.6, 2.45), rot=(0.0, 0.0, 0.0), shape="SQUARE",
                     size=0.3)],
        camera=dict(type="PERSP", lens=16.0, loc=cam_loc, rot=look_rot(cam_loc, cam_target)),
        convex=True,  # an empty closed box: every surface sees every other
        extent=3.0,
        light_motion=dict(light=0, loc=(1.0, 0.0, 0.0)),
        camera_motion=dict(loc=(1.0, 0.0, 0.0)),
    )


def _glossy_sphere_floor():
    # 5 x 5 x 3 m room; a glossy plastic sphere (Lambert + a GGX specular
    # layer, roughness 0.3) and the polished floor around it (Lambert + GGX
    # layer, roughness 0.2) lit by a spot; the sphere's reflection in the
    # floor (the floor's glossy pass). Tried first, with no usable Cycles
    # reference (two 1024-spp seeds differed by relMSE 0.07-0.46 at full
    # resolution, 0.004-0.03 at 4x4): a metal sphere (roughness 0.2 or 0.35)
    # under a spot (its caustic reaches every wall and a path tracer cannot
    # converge it), a metal floor lit by the spot (the same, through the
    # floor), and a spot on the sphere alone (the walls are then lit by a small
    # bright cap that few paths find).
    mats = dict(floor="polished_floor", ceiling="ceiling", left="wall", right="wall", back="back_wall",
                front="wall")
    centre = (0.0, 0.6, 0.6)
    spot_loc, spot_target = (1.2, -0.7, 2.7), (0.0, 0.6, 0.5)
    cam_loc, cam_target = (0.3137, -2.3, 1.3), (0.0, 0.8, 0.3)
    return dict(
        name="glossy_sphere_floor",
        feature="a glossy plastic sphere (Lambert + GGX layer, roughness 0.3) and the polished floor around it "
                "(Lambert + GGX layer, roughness 0.2) lit by a spot; the sphere's reflection in the floor's "
                "glossy pass (issue 9: splits into 3-4 blobs)",
        materials=dict(polished_floor=dict(kind="lambert_spec", color=(0.5, 0.5, 0.5), roughness=0.2),
                       sphere=dict(kind="lambert_spec", color=(0.8, 0.35, 0.1), roughness=0.3),
                       back_wall=WHITE, wall=WHITE, ceiling=WHITE),
        geometry=box_room(-2.5, 2.5, -2.5, 2.5, 0, 3.0, mats) + [uv_sphere(centre, 0.5, 48, 24, "sphere")],
        lights=[dict(type="SPOT", energy=2500.0, loc=spot_loc, rot=look_rot(spot_loc, spot_target),
                     spot_size=50.0, spot_blend=0.3)],
        camera=dict(type="PERSP", lens=24.0, loc=cam_loc, rot=look_rot(cam_loc, cam_target)),
        extent=5.0,
        light_motion=dict(light=0, loc=(1.0, 0.0, 0.0)),
        camera_motion=dict(loc=(1.0, 0.0, 0.0)),
    )


def _grazing_corridor():
    # a corridor 3 m wide, 20 m long and 3 m high; a spot at the far end
    # lights the end wall, and the polished floor (Lambert + GGX layer,
    # roughness 0.3), seen from 0.6 m above it, reflects the lit wall at
    # grazing angles (the view's cosine to the floor 0.03-0.2): a wet road's
    # or a long hall's reflection, where a receiver's lobe reaches below its
    # horizon (docs/math.md §5.4.3)
    mats = dict(floor="polished_floor", ceiling="ceiling", left="wall", right="wall", back="end_wall",
                front="wall")
    spot_loc, spot_target = (0.0, 13.0, 2.7), (0.0, 18.0, 1.4)
    cam_loc, cam_target = (0.3137, -1.5, 0.6), (0.0, 18.0, 0.45)
    return dict(
        name="grazing_corridor",
        feature="a spot lights the end wall of a 20 m corridor; the polished floor (Lambert + GGX layer, "
                "roughness 0.3), seen from 0.6 m above it, reflects the lit wall at grazing angles",
        materials=dict(polished_floor=dict(kind="lambert_spec", color=(0.4, 0.4, 0.4), roughness=0.3),
                       end_wall=WHITE, wall=WHITE, ceiling=WHITE),
        geometry=box_room(-1.5, 1.5, -2.0, 18.0, 0, 3.0, mats),
        lights=[dict(type="SPOT", energy=4000.0, loc=spot_loc, rot=look_rot(spot_loc, spot_target),
                     spot_size=50.0, spot_blend=0.3)],
        camera=dict(type="PERSP", lens=35.0, loc=cam_loc, rot=look_rot(cam_loc, cam_target)),
        convex=True,  # an empty closed box: every surface sees every other
        extent=20.0,
        light_motion=dict(light=0, loc=(1.0, 0.0, 0.0)),
        camera_motion=dict(loc=(1.0, 0.0, 0.0)),
    )


def _sun_opening():
    # closed 4 x 4 x 2.7 m room with a window (1.2 x 1.1 m) in its left wall;
    # a sun shines through it onto the floor (Diffuse + a Principled specular
    # layer, roughness 0.3: it has a glossy pass)
    mats = dict(floor="floor", ceiling="ceiling", left="window_wall", right="wall", back="back_wall", front="wall")
    geo = [g for g in box_room(-2, 2, -2, 2, 0, 2.7, mats) if g["mat"] != "window_wall"]
    geo += wall_x_with_hole(-2.0, -2.0, 2.0, 0.0, 2.7, -0.6, 0.6, 0.9, 2.0, "window_wall")
    geo += block(0.6, 1.45, 0.9, 0.5, 1.1, 8.0, "cabinet")  # a metal cabinet by the back wall
    # direction the light travels: 20 degrees above the horizon, so that the
    # patch covers the floor and the foot of the opposite wall
    el, az = math.radians(20.0), math.radians(12.0)
    sun_dir = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), -math.sin(el)])
    cam_loc, cam_target = (1.75, -1.7137, 1.5), (-1.2, 0.7, 0.9)
    return dict(
        name="sun_opening",
        feature="a closed room lit by a sun through a window in one wall; the sunlit patch on the floor and the "
                "foot of the opposite wall lights the room and is reflected by a brushed-metal cabinet (issue 9: "
                "the two-VSGL preview is 3x too bright, with no warning)",
        materials=dict(floor=dict(kind="lambert_spec", color=(0.6, 0.5, 0.4), roughness=0.3),
                       cabinet=dict(kind="glossy", color=(0.8, 0.8, 0.8), roughness=0.3),
                       window_wall=WHITE, back_wall=WHITE, wall=WHITE, ceiling=WHITE),
        geometry=geo,
        lights=[dict(type="SUN", energy=20.0, loc=(-4.0, -1.0, 4.0), rot=look_rot((0, 0, 0), sun_dir))],
        camera=dict(type="PERSP", lens=16.0, loc=cam_loc, rot=look_rot(cam_loc, cam_target)),
        extent=4.0,
        # a sun's position does nothing: turn it about Z so that its patch on
        # the floor, ~2.5 m from the window along the ray, moves ~extent/1000
        light_motion=dict(light=0, rot=(0.0, 0.0, 1.0), lever=2.5),
        camera_motion=dict(loc=(1.0, 0.0, 0.0)),
    )


def _sun_opening_thick():
    # the same room inside a closed outer shell 0.3 m away (walls and roof,
    # the window a tunnel through both): the sunlit exterior is no longer the
    # other side of the interior surfaces. Separates what zero-thickness
    # walls do (VSGLs of the sunlit roof and outer wall, 0 m from the ceiling
    # and the wall inside: white-hot junction lines) from the sun fit itself.
    s = _sun_opening()
    s["name"] = "sun_opening_thick"
    s["feature"] = ("the sun room inside a closed outer shell 0.3 m away, the window a tunnel: the sunlit exterior "
                    "is 0.3 m from the interior instead of 0 m (separates the zero-thickness-wall leak of "
                    "sun_opening from the fit of the sun's light)")
    s["materials"]["outer"] = WHITE
    g = box_room(-2.3, 2.3, -2.3, 2.3, 0, 3.0, dict(floor=None, ceiling="outer", left=None, right="outer",
                                                    back="outer", front="outer"))
    s["geometry"] += [q for q in g if q["mat"] is not None]
    s["geometry"] += wall_x_with_hole(-2.3, -2.3, 2.3, 0.0, 3.0, -0.6, 0.6, 0.9, 2.0, "outer")
    x0, x1, y0, y1, z0, z1 = -2.3, -2.0, -0.6, 0.6, 0.9, 2.0
    s["geometry"] += [quad((x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), "outer"),   # sill
                      quad((x0, y0, z1), (x0, y1, z1), (x1, y1, z1), (x1, y0, z1), "outer"),   # lintel
                      quad((x0, y0, z0), (x0, y0, z1), (x1, y0, z1), (x1, y0, z0), "outer"),   # jambs
                      quad((x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1), "outer")]
    return s


def _brushed_metal_floor():
    # the spot room of spot_metal_floor with a brushed (anisotropic) metal
    # floor: a Principled metal, roughness 0.3, anisotropy 0.8, Cycles'
    # default tangent (radial about Z in generated coordinates, which
    # library_arrays gives the library as corner tangents)
    s = _spot_metal_floor()
    s["name"] = "brushed_metal_floor"
    s["feature"] = ("the spot room with a brushed-metal floor (Principled metal, roughness 0.3, anisotropy 0.8, "
                    "Cycles' default radial tangent): the lit back wall's reflection is stretched")
    s["materials"]["metal_floor"] = dict(kind="metal", color=(0.9, 0.9, 0.9), roughness=0.3, anisotropy=0.8)
    s.pop("convex")  # the brute force then casts shadow rays; the room is still empty
    return s


def _with_light(base, name, feature, light):
    """Room `base` (a builder) with one more light, as scene `name` (the trade-only two-light rooms)."""
    s = base()
    s["name"], s["feature"] = name, feature
    s["lights"] = s["lights"] + [light]
    return s


def _spot_fill_metal_floor():
    # the spot room with a dim fill light: a point light in the corner behind
    # the camera lights the whole room softly (a key and a fill, issue 11's
    # per-light budget: the two lights' light on screen differs in amount and
    # in extent)
    return _with_light(_spot_metal_floor, "spot_fill_metal_floor",
                       "the spot room with a 60 W point fill light in a corner under the ceiling: a key and a fill "
                       "(issue 11: VSGLs and RSM texels per light)",
                       dict(type="POINT", energy=60.0, loc=(-2.3, -2.4, 2.6), rot=(0.0, 0.0, 0.0)))


def _sun_lamp_opening():
    # the sun room with a ceiling lamp (a small area light facing down): the
    # sun's RSM covers the whole scene, most of it the sunlit outside
    return _with_light(_sun_opening, "sun_lamp_opening",
                       "the sun room with a 0.4 m square 100 W ceiling lamp: a light that mostly lights the outside "
                       "(the sun) beside one that lights only the inside (issue 11: VSGLs and RSM texels per light)",
                       dict(type="AREA", energy=100.0, loc=(0.8, -0.9, 2.65), rot=(0.0, 0.0, 0.0), shape="SQUARE",
                            size=0.4))


def _red_wall_two_spots():
    # the red-wall room with a second, narrower and dimmer spot on the back wall
    spot_loc, spot_target = (-1.5, -1.8, 2.6), (0.8, 2.5, 1.2)
    return _with_light(_metal_floor_red_wall, "red_wall_two_spots",
                       "the red-wall room with a second spot (800 W, 30 degrees) on the white back wall "
                       "(issue 11: VSGLs and RSM texels per light)",
                       dict(type="SPOT", energy=800.0, loc=spot_loc, rot=look_rot(spot_loc, spot_target),
                            spot_size=30.0, spot_blend=0.2))


def heightfield(x0, x1, y0, y1, n, height, mat):
    """A bumpy floor of 2 n^2 flat-shaded triangles over [x0, x1] x [y0, y1]:
    z = height * (bumps of a few wavelengths), >= 0."""
    xs, ys = np.linspace(x0, x1, n + 1), np.linspace(y0, y1, n + 1)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    Z = height * 0.25 * (2 + np.sin(7.1 * X + 1.3 * np.sin(3.3 * Y)) + np.cos(6.3 * Y - 0.7 * np.sin(4.1 * X)))
    P = np.round(np.stack([X, Y, Z], -1), 6) + 0.0
    a, b, c, d = P[:-1, :-1], P[1:, :-1], P[1:, 1:], P[:-1, 1:]  # counter-clockwise from above
    tris = np.concatenate([np.stack([a, b, c], -2).reshape(-1, 3, 3), np.stack([a, c, d], -2).reshape(-1, 3, 3)])
    return dict(tris=tris.tolist(), normals=None, mat=mat)


def _dense_floor():
    # 5 x 5 x 3 m room with a bumpy floor of 500k flat triangles (a 500 x 500
    # grid, bumps up to 10 cm) lit by a spot; one glossy wall reflects it
    mats = dict(floor=None, ceiling="ceiling", left="wall", right="glossy_wall", back="back_wall", front="wall")
    geo = [q for q in box_room(-2.5, 2.5, -2.5, 2.5, 0, 3.0, mats) if q["mat"] is not None]
    geo.append(heightfield(-2.5, 2.5, -2.5, 2.5, 500, 0.1, "bumpy_floor"))
    spot_loc, spot_target = (-1.0, -1.2, 2.7), (0.6, 0.8, 0.0)
    cam_loc, cam_target = (0.2137, -2.3, 1.6), (0.3, 1.5, 0.5)
    return dict(
        name="dense_floor",
        feature="a room whose floor is a bumpy heightfield of 500k flat triangles, lit by a spot; a glossy wall "
                "(GGX, roughness 0.3) reflects the lit floor (scene size: export, BVH and G-buffer cost)",
        materials=dict(bumpy_floor=dict(kind="lambert_spec", color=(0.6, 0.55, 0.45), roughness=0.35),
                       glossy_wall=dict(kind="glossy", color=(0.8, 0.8, 0.85), roughness=0.3),
                       back_wall=WHITE, wall=WHITE, ceiling=WHITE),
        geometry=geo,
        lights=[dict(type="SPOT", energy=2500.0, loc=spot_loc, rot=look_rot(spot_loc, spot_target),
                     spot_size=50.0, spot_blend=0.3)],
        camera=dict(type="PERSP", lens=18.0, loc=cam_loc, rot=look_rot(cam_loc, cam_target)),
        extent=5.0,
        light_motion=dict(light=0, loc=(1.0, 0.0, 0.0)),
        camera_motion=dict(loc=(1.0, 0.0, 0.0)),
    )


def _textured_interior():
    # 4 x 5 x 2.8 m room: a spot aimed at the back wall's striped wallpaper,
    # a blue-and-yellow checker on the left wall, a varnished plank floor
    # (textured diffuse + a GGX specular layer, roughness 0.3) that reflects
    # them; the patterns bleed onto the floor and ceiling
    mats = dict(floor="planks", ceiling="ceiling", left="checker", right="wall", back="wallpaper", front="wall")
    geo = box_room(-2, 2, -2.5, 2.5, 0, 2.8, mats)
    tiles = dict(planks=1.0, checker=1.4, wallpaper=0.9)
    geo = [quad_uv(q, tiles[q["mat"]]) if q["mat"] in tiles else q for q in geo]
    spot_loc, spot_target = (0.6, -0.8, 2.6), (-0.2, 2.5, 1.3)
    cam_loc, cam_target = (0.5137, -2.3, 1.5), (-0.3, 2.5, 0.8)
    return dict(
        name="textured_interior",
        feature="a textured interior: a spot lights a striped wallpaper (red / cream) that bleeds its mean "
                "colour onto a varnished plank floor (textured base colour, GGX specular, roughness 0.3), "
                "which reflects it; a blue / yellow checker wall (issue 11: a textured interior)",
        images=dict(planks=dict(kind="planks", size=(64, 64), boards=6, color=(0.55, 0.36, 0.2)),
                    stripes=dict(kind="stripes", size=(64, 8), bands=8,
                                 colors=((0.75, 0.12, 0.1), (0.85, 0.8, 0.65))),
                    checker=dict(kind="checker", size=(32, 32), cells=4,
                                 colors=((0.1, 0.2, 0.7), (0.85, 0.75, 0.15)))),
        materials=dict(planks=dict(kind="lambert_spec", color=(1.0, 1.0, 1.0), roughness=0.3, texture="planks"),
                       wallpaper=dict(kind="diffuse", color=(1.0, 1.0, 1.0), texture="stripes"),
                       checker=dict(kind="diffuse", color=(1.0, 1.0, 1.0), texture="checker"),
                       wall=WHITE, ceiling=WHITE),
        geometry=geo,
        lights=[dict(type="SPOT", energy=2000.0, loc=spot_loc, rot=look_rot(spot_loc, spot_target),
                     spot_size=55.0, spot_blend=0.3)],
        camera=dict(type="PERSP", lens=18.0, loc=cam_loc, rot=look_rot(cam_loc, cam_target)),
        convex=True,  # an empty closed box: every surface sees every other
        extent=5.0,
        light_motion=dict(light=0, loc=(1.0, 0.0, 0.0)),
        camera_motion=dict(loc=(1.0, 0.0, 0.0)),
    )


def _rough_room():
    # 5 x 4 x 2.8 m room whose walls, ceiling and floor are rough glossy
    # dielectrics (Lambert + a GGX specular layer, roughness 0.7-0.9) around
    # a rough metal sphere (roughness 0.7), lit by a spot on the back wall:
    # every receiver's glossy lobe is broad, as the demo's walls (docs/math.md
    # §5.4.4, "Broad lobes"). Lambert + layer rather than a Principled BSDF:
    # Blender 3.4's Principled diffuse is Burley's, which this builder does
    # not flag (the add-on does). The sphere was a rough dielectric until
    # 2026-12-07; as a metal its side away from the lit wall and floor had
    # 3.5x Cycles' glossy light (the planar model's footprint reaching
    # clusters behind the receiver, docs/accuracy.md "A rough metal sphere")
    mats = dict(floor="rough_floor", ceiling="ceiling", left="wall", right="wall", back="back_wall", front="wall")
    centre = (-0.8, 0.9, 0.55)
    spot_loc, spot_target = (0.8, -1.2, 2.5), (0.3, 2.0, 1.0)
    cam_loc, cam_target = (-0.3137, -1.8, 1.4), (0.2, 2.0, 0.9)
    return dict(
        name="rough_room",
        feature="a room of rough glossy dielectrics (Lambert + GGX layer: walls 0.9, back wall 0.85, floor 0.7) "
                "and a rough metal sphere (0.7) lit by a spot on the back wall: every receiver's glossy lobe is "
                "broad (issue 9: the sphere's dark side 3.5x too bright in Gloss before 2026-12-07)",
        materials=dict(rough_floor=dict(kind="lambert_spec", color=(0.45, 0.35, 0.25), roughness=0.7),
                       back_wall=dict(kind="lambert_spec", color=(0.75, 0.75, 0.7), roughness=0.85),
                       wall=dict(kind="lambert_spec", color=(0.3, 0.55, 0.5), roughness=0.9),
                       ceiling=dict(kind="lambert_spec", color=(0.8, 0.8, 0.8), roughness=0.9),
                       sphere=dict(kind="glossy", color=(0.9, 0.6, 0.3), roughness=0.7)),
        geometry=box_room(-2.5, 2.5, -2.0, 2.0, 0, 2.8, mats) + [uv_sphere(centre, 0.55, 48, 24, "sphere")],
        lights=[dict(type="SPOT", energy=2000.0, loc=spot_loc, rot=look_rot(spot_loc, spot_target),
                     spot_size=60.0, spot_blend=0.3)],
        camera=dict(type="PERSP", lens=20.0, loc=cam_loc, rot=look_rot(cam_loc, cam_target)),
        extent=5.0,
        light_motion=dict(light=0, loc=(1.0, 0.0, 0.0)),
        camera_motion=dict(loc=(1.0, 0.0, 0.0)),
    )


_BUILDERS = [_spot_metal_floor, _metal_floor_red_wall, _box_point_area_glossy_green, _glossy_sphere_floor,
             _sun_opening, _sun_opening_thick, _textured_interior, _grazing_corridor, _rough_room]
NAMES = [b.__name__[1:] for b in _BUILDERS]
# scenes of the trade measurement only (tools/trade.py, issue 11): not in the
# quality suite (NAMES), which `make test` runs
_TRADE_BUILDERS = [_brushed_metal_floor, _dense_floor]
# several lights (issue 11's per-light budget; with box_point_area_glossy_green)
_MULTI_LIGHT_BUILDERS = [_spot_fill_metal_floor, _sun_lamp_opening, _red_wall_two_spots]
_TRADE_BUILDERS = _TRADE_BUILDERS + _MULTI_LIGHT_BUILDERS
MULTI_LIGHT_NAMES = ["box_point_area_glossy_green"] + [b.__name__[1:] for b in _MULTI_LIGHT_BUILDERS]
TRADE_NAMES = [b.__name__[1:] for b in _TRADE_BUILDERS]


def scene(name):
    """The scene dict (camera without a resolution)."""
    for b in _BUILDERS + _TRADE_BUILDERS:
        if b.__name__[1:] == name:
            s = b()
            assert s["name"] == name, (s["name"], name)
            return s
    raise KeyError("unknown scene %r (one of %s)" % (name, ", ".join(NAMES)))


def size_of(size):
    """(width, height, samples per seed) of a size name or a (W, H[, spp]) tuple."""
    if isinstance(size, str):
        if size in SIZES:
            return SIZES[size]
        parts = size.lower().replace(":", "x").split("x")
        w, h = int(parts[0]), int(parts[1])
        return (w, h, int(parts[2]) if len(parts) > 2 else 1024)
    w, h = size[:2]
    return (int(w), int(h), int(size[2]) if len(size) > 2 else 1024)


def case(name, size="test"):
    """The scene at a size: the dict cycles_ref.build_blender takes."""
    s = scene(name) if isinstance(name, str) else copy.deepcopy(name)
    w, h, _ = size_of(size)
    s["camera"] = dict(s["camera"], res=(w, h))
    return s


def blender_case(s):
    """Only what Blender renders (the cache key hashes this)."""
    out = {k: s[k] for k in ("geometry", "materials", "lights", "camera")}
    if s.get("images"):  # only textured scenes: the others' keys stay as they were
        out["images"] = s["images"]
    return out


# ---------------------------------------------------------------------------
# animation
# ---------------------------------------------------------------------------

def animate(s, kind, frame):
    """A copy of scene `s` at `frame` (0 = the still) of animation `kind`:
    "light" (the scene's light_motion) or "camera" (camera_motion), moving
    by STEP * extent per frame."""
    out = copy.deepcopy(s)
    if frame == 0 or kind in (None, "still"):
        return out
    step = STEP * s["extent"] * frame
    if kind == "light":
        m = s["light_motion"]
        L = out["lights"][m["light"]]
        if "loc" in m:
            L["loc"] = tuple(float(a) + step * float(d) for a, d in zip(L["loc"], m["loc"]))
        else:
            deg = math.degrees(step / m["lever"])
            L["rot"] = tuple(float(a) + deg * float(d) for a, d in zip(L["rot"], m["rot"]))
    elif kind == "camera":
        m = s["camera_motion"]
        c = out["camera"]
        c["loc"] = tuple(float(a) + step * float(d) for a, d in zip(c["loc"], m["loc"]))
    else:
        raise ValueError("unknown animation %r (light or camera)" % kind)
    return out


# ---------------------------------------------------------------------------
# the library's scene (Blender 3.4 semantics), as cycles_ref.library_scene
# ---------------------------------------------------------------------------

def euler_xyz(rot_deg):
    """Blender's Euler XYZ rotation matrix (X applied first): Rz Ry Rx."""
    a, b, c = (math.radians(float(v)) for v in rot_deg)
    ca, sa, cb, sb, cc, sc = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(c), math.sin(c)
    Rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    Ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    Rz = np.array([[cc, -sc, 0], [sc, cc, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def world_matrix(loc, rot, scale=(1.0, 1.0, 1.0)):
    """4x4 matrix_world of an object at loc with Euler XYZ rot (degrees) and scale."""
    M = np.eye(4)
    M[:3, :3] = euler_xyz(rot) @ np.diag([float(v) for v in scale])
    M[:3, 3] = [float(v) for v in loc]
    return M


def material_order(s):
    """Material names in the order build_blender assigns their indices."""
    order = []
    for g in s["geometry"]:
        if g["mat"] not in order:
            order.append(g["mat"])
    return order


def library_material(L, spec):
    """A libvsgl.Material of a material spec, Blender 3.4 semantics."""
    m = L.Material()
    m.base_color[:] = tuple(float(c) for c in spec["color"])
    k = spec["kind"]
    if k == "diffuse":
        m.metallic, m.roughness, m.specular_f0 = 0.0, 1.0, 0.0
    elif k == "lambert_spec":
        m.metallic, m.roughness, m.specular_f0 = 0.0, spec["roughness"], 0.08 * 0.5
    elif k == "glossy":
        m.metallic, m.roughness, m.specular_f0 = 1.0, spec["roughness"], 0.0
    else:  # metal / principled
        m.metallic = 1.0 if k == "metal" else spec.get("metallic", 0.0)
        m.roughness, m.specular_f0 = spec["roughness"], 0.08 * 0.5
        m.anisotropy = spec.get("anisotropy", 0.0)
    return m


_LIGHT_TYPES = {"POINT": 0, "SPOT": 1, "SUN": 2, "AREA": 3}
_SHAPES = {"SQUARE": 0, "RECTANGLE": 1, "DISK": 2, "ELLIPSE": 3}


def library_light(L, ls):
    """A libvsgl.Light of a light spec as build_blender makes it in Blender 3.4
    (point/spot radius 0, sun angle 0; colour white)."""
    t = ls["type"]
    o = L.Light()
    o.type = _LIGHT_TYPES[t]
    o.color[:] = (1.0, 1.0, 1.0)
    o.power = float(ls["energy"])
    o.world_from_light[:] = [float(v) for v in
                             world_matrix(ls["loc"], ls["rot"], ls.get("scale", (1, 1, 1)))[:3, :].reshape(-1)]
    # radius: shadow_soft_size as Blender 3.4 reports it: 0 for point/spot as
    # built, the default 0.25 for a sun, the size for an area light
    o.radius = {"POINT": 0.0, "SPOT": 0.0, "SUN": 0.25}.get(t, ls.get("size", 0.25))
    o.spot_size = math.radians(ls["spot_size"]) if t == "SPOT" else 1.0
    o.spot_blend = ls["spot_blend"] if t == "SPOT" else 0.0
    o.sun_angle = 0.0
    if t == "AREA":
        o.area_shape = _SHAPES[ls["shape"]]
        o.size_x = ls["size"]
        o.size_y = ls.get("size_y", ls["size"])
        o.spread = math.radians(ls.get("spread", 180))
    else:
        o.size_x = o.size_y = 1.0
        o.spread = math.pi
    return o


def library_camera(L, cs):
    c = L.Camera()
    c.type = 0 if cs["type"] == "PERSP" else 1
    c.sensor_fit = 0  # AUTO
    c.world_from_camera[:] = [float(v) for v in world_matrix(cs["loc"], cs["rot"])[:3, :].reshape(-1)]
    c.lens_mm = cs.get("lens", 50.0)
    c.sensor_width_mm, c.sensor_height_mm = 36.0, 24.0
    c.ortho_scale = cs.get("ortho_scale", 6.0)
    c.shift_x = c.shift_y = 0.0
    c.clip_start, c.clip_end = 0.01, 100.0
    c.width, c.height = cs["res"]
    c.pixel_aspect_x = c.pixel_aspect_y = 1.0
    return c


def library_arrays(s, L):
    """The keyword arguments of libvsgl.Scene (L: the libvsgl module) for scene
    dict `s` (with a camera resolution): positions, indices (quads fanned as
    (0,1,2), (0,2,3) like cycles_ref.library_scene), corner normals (face
    normals, or the entry's smooth normals), material indices, materials,
    lights, camera."""
    order = material_order(s)
    mi = {n: i for i, n in enumerate(order)}
    V, I, Mi, N = [], [], [], []
    for g in s["geometry"]:
        polys = [g["quad"]] if "quad" in g else g["tris"]
        nrms = g.get("normals") if "tris" in g else None
        if "tris" in g and len(polys) > 1000:  # the same, vectorised (dense_floor's 500k triangles)
            P = np.asarray(polys, np.float64)
            base = len(V)
            V += [tuple(p) for p in P.reshape(-1, 3).tolist()]
            I += [(base + 3 * t, base + 3 * t + 1, base + 3 * t + 2) for t in range(len(P))]
            Mi += [mi[g["mat"]]] * len(P)
            if nrms is not None:
                N += list(np.asarray(nrms, np.float64))
            else:
                fn = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
                fn /= np.linalg.norm(fn, axis=1, keepdims=True)
                N += list(np.repeat(fn[:, None, :], 3, axis=1))
            continue
        for k, poly in enumerate(polys):
            base = len(V)
            V += [tuple(map(float, p)) for p in poly]
            P = np.asarray(poly, np.float64)
            fn = np.cross(P[1] - P[0], P[2] - P[0])
            fn /= np.linalg.norm(fn)
            for j in range(1, len(poly) - 1):
                I.append((base, base + j, base + j + 1))
                Mi.append(mi[g["mat"]])
                if nrms is not None:
                    N.append([nrms[k][0], nrms[k][j], nrms[k][j + 1]])
                else:
                    N.append([fn, fn, fn])
    out = dict(positions=np.ascontiguousarray(V, np.float32),
               indices=np.ascontiguousarray(I, np.uint32),
               corner_normals=np.ascontiguousarray(N, np.float32),
               material_indices=np.ascontiguousarray(Mi, np.uint32),
               materials=[library_material(L, s["materials"][n]) for n in order],
               lights=[library_light(L, ls) for ls in s["lights"]],
               camera=library_camera(L, s["camera"]))
    if any(m.get("anisotropy", 0.0) for m in s["materials"].values()):
        out["corner_tangents"] = radial_tangents(out["positions"], out["indices"])
    if s.get("images"):
        out.update(library_textures(L, s, order))
    return out


def polygon_uvs(s):
    """Each polygon's corner UVs, in the order build_blender makes the
    polygons ((0, 0) where an entry has none): the library fans them into
    triangles (library_textures), Blender takes them per loop
    (tests/blender/cycles_textures.py)."""
    for g in s["geometry"]:
        polys = [g["quad"]] if "quad" in g else g["tris"]
        uv = g.get("uv")
        for poly in polys:
            yield uv if uv is not None else [(0.0, 0.0)] * len(poly)


def library_textures(L, s, order):
    """corner_uvs, textures and material_textures of a textured scene: each
    textured material's base colour reads its image (linear, bilinear,
    repeat), as an Image Texture node linked straight into the colour input
    (tests/blender/cycles_textures.py) with the input's constant 1."""
    names = sorted(s["images"])
    uvs = [[t[0], t[j], t[j + 1]] for t in polygon_uvs(s) for j in range(1, len(t) - 1)]
    mts = []
    for n in order:
        mt = L.MaterialTextures()
        img = s["materials"][n].get("texture")
        if img is not None:
            mt.base_color.texture = names.index(img) + 1
            mt.base_color.filter = L.FILTER_LINEAR
            mt.base_color.wrap = L.WRAP_REPEAT
        mts.append(mt)
    return dict(corner_uvs=np.ascontiguousarray(uvs, np.float32),
                textures=[texture_pixels(s["images"][k]) for k in names],
                material_textures=mts)


def radial_tangents(positions, indices):
    """Corner tangents (T, 3, 4: xyz, bitangent sign 1) of Cycles' default
    anisotropy tangent for one mesh object at the origin (build_blender's):
    radial about Z in generated coordinates, (-g.y, g.x, 0) with g =
    (p - bounding-box centre) / (bounding-box size), as the add-on's
    export.default_tangents_local."""
    p = np.asarray(positions, np.float64)
    lo, hi = p.min(0), p.max(0)
    size = np.where(hi - lo == 0, 2.0, hi - lo)
    g = (p - (lo + hi) / 2) / size
    t = np.stack([-g[:, 1], g[:, 0], np.zeros(len(g)), np.ones(len(g))], -1)
    return np.ascontiguousarray(t[np.asarray(indices, np.int64)], np.float32)
