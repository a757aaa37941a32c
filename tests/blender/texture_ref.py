"""Textured materials through the add-on's export vs Cycles (run inside Blender).

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/texture_ref.py -- \
        --lib build/libvsgl.so --out build/blender/textures

Scenes are built in bpy with the node setups artists use (images generated
by numpy: sRGB 8-bit and Non-Color, a second UV map, a Mapping node,
Closest / Clip, a colour attribute, Mix / Multiply / Invert / Hue-Saturation
in front of Base Color, a Color Ramp on Roughness), exported with
``vsgl_indirect.export.collect`` exactly as a render does, and rendered by
libvsgl. Checks:

- diffcol: the library's DiffCol against Cycles' DiffCol pass (box filter
  over the pixel, 64 spp; the library: 4 x 4 samples per pixel) per pixel:
  mean |difference| / mean(Cycles) < 1 % over the pixels both cover;
- bleed: a spot-lit textured wall bleeding onto a white floor: the mean
  coloured indirect diffuse light (DiffInd x DiffCol) over the floor below
  the camera's horizon, per channel, within 5 % of Cycles one-bounce
  (1024 spp, cached) for the quality preset and the brute-force gather;
  and the same wall with a flat grey of equal luminance must differ from
  the textured one by more than the tolerance (the texture matters).
- emission: an emissive panel (no lamps) lighting a room: the library's
  mean coloured indirect diffuse within 10 % of Cycles one-bounce;
- emission_units: the panel's lights' RSM flux in a closed box against the
  emitted power 2 pi A S C (0.5 %), and the irradiance their RSM implies on
  the floor against Cycles' DiffDir (2 %).

Cycles renders are cached under --out (key: this file, the case, Blender's
version). Writes report.md and summary.txt ("N passed, N failed").
"""
import hashlib
import math
import os
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "addon"))
sys.path.insert(0, HERE)

TOL_DIFFCOL = 0.01
DIFFCOL_SPP = 1024   # Cycles' own noise at texture edges stays below the tolerance
DIFFCOL_AA = 16      # the library: 16 x 16 samples per pixel (edges of stripes and texels)
TOL_BLEED = 0.05
TOL_EMISSION = 0.10
TOL_PRINCIPLED = 0.03
TOL_BURLEY_FLAT = 0.01


def args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    a = {"--lib": os.path.join(ROOT, "build", "libvsgl.so"),
         "--out": os.path.join(ROOT, "build", "blender", "textures"), "--only": ""}
    for i in range(0, len(argv) - 1, 2):
        a[argv[i]] = argv[i + 1]
    return a


A = args()
os.environ.setdefault("VSGL_LIBRARY", os.path.abspath(A["--lib"]))
from vsgl_indirect import engine, export, libvsgl  # noqa: E402
import cycles_ref  # noqa: E402  (its Cycles pass renderer and EXR readers)


# ---------------------------------------------------------------------------
# scene building
# ---------------------------------------------------------------------------

def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    return sc


def image(name, pixels, colorspace="sRGB", float_buffer=False):
    """A generated image with ``pixels`` (H, W, 4) rows bottom to top."""
    h, w = pixels.shape[:2]
    im = bpy.data.images.new(name, w, h, alpha=True, float_buffer=float_buffer)
    im.colorspace_settings.name = colorspace
    im.pixels.foreach_set(np.ascontiguousarray(pixels, np.float32).reshape(-1))
    im.pack()
    return im


def stripes(w, h, cols, period=8, vertical=True):
    x = np.arange(w)[None, :] if vertical else np.arange(h)[:, None]
    idx = (x // period) % len(cols)
    idx = np.broadcast_to(idx, (h, w))
    px = np.ones((h, w, 4), np.float32)
    px[..., :3] = np.array(cols, np.float32)[idx]
    return px


def checker(w, h, a, b, n=4):
    yy, xx = np.mgrid[0:h, 0:w]
    m = ((xx * n // w) + (yy * n // h)) % 2 == 0
    px = np.ones((h, w, 4), np.float32)
    px[..., :3] = np.where(m[..., None], np.array(a, np.float32), np.array(b, np.float32))
    return px


def noise(w, h, seed=3):
    rng = np.random.default_rng(seed)
    px = np.ones((h, w, 4), np.float32)
    px[..., :3] = rng.random((h, w, 3))
    return px


def mesh(name, verts, faces, uvs=None, uv2=None, colors=None, mat=None):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    if uvs is not None:
        lay = me.uv_layers.new(name="UVMap")
        for li, loop in enumerate(me.loops):
            lay.data[li].uv = uvs[loop.vertex_index]
    if uv2 is not None:
        lay = me.uv_layers.new(name="Second")
        for li, loop in enumerate(me.loops):
            lay.data[li].uv = uv2[loop.vertex_index]
    if colors is not None:
        attr = me.color_attributes.new("Col", "FLOAT_COLOR", "POINT")
        for vi, c in enumerate(colors):
            attr.data[vi].color = tuple(c) + (1.0,)
    me.update()
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    if mat is not None:
        ob.data.materials.append(mat)
    return ob


def quad(name, p0, p1, p2, p3, mat, uv_scale=(1.0, 1.0), uv2=False, colors=None):
    uvs = [(0, 0), (uv_scale[0], 0), (uv_scale[0], uv_scale[1]), (0, uv_scale[1])]
    second = [(1 - u / max(uv_scale[0], 1e-9), v / max(uv_scale[1], 1e-9)) for u, v in uvs] if uv2 else None
    return mesh(name, [p0, p1, p2, p3], [(0, 1, 2, 3)], uvs, second, colors, mat)


def material(name, build):
    """A Principled material whose node tree ``build(nodes, links, bsdf)`` edits."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Roughness"].default_value = 1.0
    spec = "Specular" if bpy.app.version < (4, 0, 0) else "Specular IOR Level"
    bsdf.inputs[spec].default_value = 0.0
    build(nt.nodes, nt.links, bsdf)
    return m


def flat(color, rough=1.0):
    def b(nodes, links, bsdf):
        bsdf.inputs["Base Color"].default_value = tuple(color) + (1.0,)
        bsdf.inputs["Roughness"].default_value = rough
    return b


def lambert(name, color):
    """A Diffuse BSDF of roughness 0: Lambert, the library's diffuse model
    (Blender 3.4's Principled diffuse is Burley's, up to ~10 % off at grazing
    angles; cycles_ref.py's notes)."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    d = nt.nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = tuple(color) + (1.0,)
    d.inputs["Roughness"].default_value = 0.0
    nt.links.new(d.outputs["BSDF"], nt.nodes["Material Output"].inputs["Surface"])
    return m


def tex_node(nodes, im, interpolation="Linear", extension="REPEAT"):
    t = nodes.new("ShaderNodeTexImage")
    t.image = im
    t.interpolation = interpolation
    t.extension = extension
    return t


def mix_node(nodes, blend, fac):
    """A colour Mix node of either generation: (node, fac, A, B, out) sockets."""
    if bpy.app.version >= (3, 4, 0):
        n = nodes.new("ShaderNodeMix")
        n.data_type = "RGBA"
        n.blend_type = blend
        ins = {s.identifier: s for s in n.inputs}
        outs = {s.identifier: s for s in n.outputs}
        ins["Factor_Float"].default_value = fac
        return n, ins["A_Color"], ins["B_Color"], outs["Result_Color"]
    n = nodes.new("ShaderNodeMixRGB")
    n.blend_type = blend
    n.inputs["Fac"].default_value = fac
    return n, n.inputs["Color1"], n.inputs["Color2"], n.outputs["Color"]


def camera(sc, loc, rot_deg, res, lens=30.0):
    cam = bpy.data.cameras.new("Cam")
    cam.lens = lens
    ob = bpy.data.objects.new("Cam", cam)
    ob.location = loc
    ob.rotation_euler = [math.radians(a) for a in rot_deg]
    sc.collection.objects.link(ob)
    sc.camera = ob
    sc.render.resolution_x, sc.render.resolution_y = res
    sc.render.resolution_percentage = 100
    return ob


def spot(sc, loc, rot_deg, energy, size_deg=60.0):
    lt = bpy.data.lights.new("Spot", "SPOT")
    lt.energy = energy
    lt.spot_size = math.radians(size_deg)
    lt.spot_blend = 0.2
    lt.shadow_soft_size = 0.0
    ob = bpy.data.objects.new("Spot", lt)
    ob.location = loc
    ob.rotation_euler = [math.radians(a) for a in rot_deg]
    sc.collection.objects.link(ob)
    return ob


# ---- cases ------------------------------------------------------------------

def build_diffcol():
    """Receivers with every supported setup, seen by one camera."""
    sc = reset()
    im_s = image("stripes", stripes(64, 64, [(0.9, 0.2, 0.1, ), (0.1, 0.4, 0.9), (0.95, 0.9, 0.3)][:3], 6))
    im_c = image("checker", checker(32, 32, (0.8, 0.8, 0.8), (0.1, 0.1, 0.1)), "Non-Color")
    im_n = image("noise", noise(16, 16), "sRGB")
    im_f = image("floatimg", noise(24, 24, 7) * 0.7, "Linear", float_buffer=True)

    def plain(nodes, links, bsdf):       # sRGB image straight into Base Color
        links.new(tex_node(nodes, im_s).outputs["Color"], bsdf.inputs["Base Color"])

    def closest_clip(nodes, links, bsdf):  # Closest + Clip, on a second UV map via a UV Map node
        t = tex_node(nodes, im_n, "Closest", "CLIP")
        uvm = nodes.new("ShaderNodeUVMap")
        uvm.uv_map = "Second"
        links.new(uvm.outputs["UV"], t.inputs["Vector"])
        links.new(t.outputs["Color"], bsdf.inputs["Base Color"])

    def mapped_mix(nodes, links, bsdf):   # Mapping (scale, rotate) -> texture; Mix with a constant
        t = tex_node(nodes, im_c, "Linear", "EXTEND")
        tc = nodes.new("ShaderNodeTexCoord")
        mp = nodes.new("ShaderNodeMapping")
        mp.inputs["Scale"].default_value = (2.0, 1.5, 1.0)
        mp.inputs["Rotation"].default_value = (0.0, 0.0, 0.3)
        links.new(tc.outputs["UV"], mp.inputs["Vector"])
        links.new(mp.outputs["Vector"], t.inputs["Vector"])
        n, a, b, out = mix_node(nodes, "MIX", 0.35)
        links.new(t.outputs["Color"], a)
        b.default_value = (0.9, 0.5, 0.1, 1.0)
        links.new(out, bsdf.inputs["Base Color"])

    def multiply_invert_hsv(nodes, links, bsdf):  # Multiply two textures, Invert, Hue/Sat
        t1 = tex_node(nodes, im_s)
        t2 = tex_node(nodes, im_f)
        n, a, b, out = mix_node(nodes, "MULTIPLY", 1.0)
        links.new(t1.outputs["Color"], a)
        links.new(t2.outputs["Color"], b)
        inv = nodes.new("ShaderNodeInvert")
        inv.inputs["Fac"].default_value = 0.3
        links.new(out, inv.inputs["Color"])
        hs = nodes.new("ShaderNodeHueSaturation")
        hs.inputs["Hue"].default_value = 0.6
        hs.inputs["Saturation"].default_value = 1.3
        hs.inputs["Value"].default_value = 0.9
        links.new(inv.outputs["Color"], hs.inputs["Color"])
        links.new(hs.outputs["Color"], bsdf.inputs["Base Color"])

    def vertex_colour(nodes, links, bsdf):  # texture x colour attribute; Color Ramp on roughness
        t = tex_node(nodes, im_n)
        vc = nodes.new("ShaderNodeVertexColor")
        vc.layer_name = "Col"
        n, a, b, out = mix_node(nodes, "MULTIPLY", 1.0)
        links.new(t.outputs["Color"], a)
        links.new(vc.outputs["Color"], b)
        links.new(out, bsdf.inputs["Base Color"])
        ramp = nodes.new("ShaderNodeValToRGB")
        links.new(tex_node(nodes, im_c).outputs["Color"], ramp.inputs["Fac"])
        links.new(ramp.outputs["Color"], bsdf.inputs["Roughness"])

    mats = [material(n, f) for n, f in (("plain", plain), ("closest_clip", closest_clip),
                                        ("mapped_mix", mapped_mix), ("multiply", multiply_invert_hsv),
                                        ("vcol", vertex_colour))]
    # five panels facing the camera (-y), in a row; the clip one's UVs reach past [0, 1]
    for i, m in enumerate(mats):
        x0 = -2.5 + i * 1.0
        kw = {}
        if m.name == "closest_clip":
            kw["uv2"] = True
        if m.name == "vcol":
            kw["colors"] = [(1, 0.2, 0.2), (0.2, 1, 0.2), (0.2, 0.2, 1), (1, 1, 1)]
        quad(m.name, (x0, 0, 0), (x0 + 0.95, 0, 0), (x0 + 0.95, 0, 1.5), (x0, 0, 1.5), m,
             uv_scale=(1.3, 1.6) if m.name in ("closest_clip", "mapped_mix") else (1.0, 1.0), **kw)
    # a receding floor: minified texture (mip levels)
    mfl = material("floor", plain)
    quad("Floor", (-3, -1, -0.01), (3, -1, -0.01), (3, 8, -0.01), (-3, 8, -0.01), mfl, uv_scale=(6, 9))
    camera(sc, (0, -4.5, 0.9), (84, 0, 0), (160, 90), lens=26)
    spot(sc, (0, -3, 3), (40, 0, 0), 100.0)
    return sc


def build_bleed(textured=True):
    """A white room; its back wall textured; a spot lights the wall."""
    sc = reset()
    white = material("white", flat((0.8, 0.8, 0.8)))
    cols = [(0.9, 0.15, 0.05), (0.1, 0.3, 0.9), (0.95, 0.85, 0.2)]
    px = stripes(96, 96, cols, 12)
    if textured:
        im = image("wallpaper", px)

        def wall(nodes, links, bsdf):
            links.new(tex_node(nodes, im).outputs["Color"], bsdf.inputs["Base Color"])
        wm = material("wallpaper", wall)
    else:  # the same wall, flat grey of the texture's mean luminance
        lin = np.where(px[..., :3] <= 0.04045, px[..., :3] / 12.92, ((px[..., :3] + 0.055) / 1.055) ** 2.4)
        g = float((lin.reshape(-1, 3) @ np.array([0.2126, 0.7152, 0.0722])).mean())
        wm = material("grey", flat((g, g, g)))
    quad("Floor", (-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0), white)
    quad("Back", (-2, 2, 0), (2, 2, 0), (2, 2, 3), (-2, 2, 3), wm, uv_scale=(2, 1.5))
    quad("Left", (-2, -2, 0), (-2, 2, 0), (-2, 2, 3), (-2, -2, 3), white)
    quad("Right", (2, -2, 0), (2, -2, 3), (2, 2, 3), (2, 2, 0), white)
    camera(sc, (0, -3.8, 2.2), (65, 0, 0), (128, 96), lens=22)
    spot(sc, (0, -1.0, 2.8), (62, 0, 0), 300.0, 70.0)
    return sc


def build_emission(principled=False):
    """A room lit only by an emissive ceiling panel (Emission shader) and a
    small emissive Principled box on the floor; its walls Lambert (Diffuse
    BSDF) or, with ``principled``, rough Principled BSDFs without a specular
    layer (Burley's diffuse in Blender 3.x, Lambert's in 4.x+)."""
    sc = reset()
    if principled:
        white = material("white", flat((0.8, 0.8, 0.8), 0.9))
        red = material("red", flat((0.8, 0.1, 0.05), 0.9))
    else:
        white = lambert("white", (0.8, 0.8, 0.8))
        red = lambert("red", (0.8, 0.1, 0.05))

    def emit(nodes, links, bsdf):
        e = nodes.new("ShaderNodeEmission")
        e.inputs["Strength"].default_value = 8.0
        e.inputs["Color"].default_value = (1.0, 0.9, 0.7, 1.0)
        out = nodes["Material Output"]
        links.new(e.outputs["Emission"], out.inputs["Surface"])
    panel = material("panel", emit)
    quad("Floor", (-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0), white)
    quad("Back", (-2, 2, 0), (2, 2, 0), (2, 2, 3), (-2, 2, 3), white)
    quad("Left", (-2, -2, 0), (-2, 2, 0), (-2, 2, 3), (-2, -2, 3), red)
    quad("Right", (2, -2, 0), (2, -2, 3), (2, 2, 3), (2, 2, 0), white)
    quad("Ceiling", (-2, -2, 3), (-2, 2, 3), (2, 2, 3), (2, -2, 3), white)
    # the panel hangs 5 cm below the ceiling, facing down
    quad("Panel", (-0.6, -0.4, 2.95), (-0.6, 0.4, 2.95), (0.6, 0.4, 2.95), (0.6, -0.4, 2.95), panel)
    camera(sc, (0, -3.8, 1.6), (80, 0, 0), (128, 96), lens=20)
    return sc


def check_emission(out_dir, report):
    passes = ["DiffInd", "DiffCol"]
    cyc, _ = cycles("emission", build_emission, passes, 1024, 1.0, out_dir)
    ref = cyc["DiffInd"] * cyc["DiffCol"]
    sc = build_emission()
    lib, secs, sd = library(sc, preset("QUALITY"))
    print("  export:", sd.summary())
    for w in sd.warnings:
        print("  export warning:", w)
    got = lib["diffuse"]
    m = (ref.max(-1) > 0) & (got.max(-1) >= 0)
    g, w = got[m].mean(0), ref[m].mean(0)
    rel = np.abs(g - w) / w
    ok = bool((rel < TOL_EMISSION).all()) and len(sd.lights) >= 2
    line = ("%s emission: panel -> %d area lights; mean coloured indirect diffuse lib %s Cycles %s rel %s %% "
            "(tol %.0f %%), %.2f s" % ("PASS" if ok else "FAIL", len(sd.lights), np.round(g, 5), np.round(w, 5),
                                       np.round(100 * rel, 2), 100 * TOL_EMISSION, secs))
    print(line)
    report.append(line)
    save_pair(out_dir, "emission", got * 4, ref * 4)
    return ok


def check_principled_diffuse(out_dir, report):
    """The emission room with rough Principled walls against the same room
    with Lambert walls, each against Cycles: the panel's own modelling error
    (check_emission) cancels in the ratio of the two ratios, which is the
    Principled diffuse's. Blender 3.4's is Burley's (VSGL_MATERIAL_FLAG_BURLEY):
    Cycles' room is ~10 % brighter than a Lambert model gives at these
    grazing views; 4.x+'s is Lambert's."""
    passes = ["DiffInd", "DiffCol"]
    ratios = []
    for principled in (False, True):
        name = "emission_principled" if principled else "emission"
        cyc, _ = cycles(name, lambda: build_emission(principled), passes, 1024, 1.0, out_dir)
        ref = cyc["DiffInd"] * cyc["DiffCol"]
        build_emission(principled)
        lib, _, sd = library(bpy.context.scene, preset("QUALITY"))
        got = lib["diffuse"]
        m = (ref.max(-1) > 0) & (got.max(-1) >= 0)
        ratios.append(got[m].mean(0) / ref[m].mean(0))
    rr = ratios[1] / ratios[0]
    ok = bool((np.abs(rr - 1.0) < TOL_PRINCIPLED).all())
    line = ("%s principled diffuse: (lib / Cycles) with rough Principled walls over the same with Lambert walls "
            "%s (tol %.0f %%; lib / Cycles %s and %s)"
            % ("PASS" if ok else "FAIL", np.round(rr, 4), 100 * TOL_PRINCIPLED, np.round(ratios[1], 4),
               np.round(ratios[0], 4)))
    print(line)
    report.append(line)
    return ok


def burley_direct_ratio(rough, out_dir):
    """Cycles' DiffDir of a Principled floor (roughness ``rough``,
    no specular layer) under a low point light, seen from 45 degrees, over
    the library's exact diffuse BRDF (vsgl_reference_brdf, with and
    without VSGL_MATERIAL_FLAG_BURLEY) times the light's irradiance, in
    bins of the light's incidence cosine: (bin means with the flag,
    without). A model that is Cycles' own is the same constant in every bin
    (the light unit's factor); Lambert's drifts with the incidence."""
    sc = reset()
    quad("Floor", (-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0), material("p", flat((0.5, 0.5, 0.5), rough)))
    L, P = (2.5, 0.0, 0.6), 100.0
    lo = bpy.data.objects.new("L", bpy.data.lights.new("L", "POINT"))
    lo.location, lo.data.energy, lo.data.shadow_soft_size = L, P, 0.0
    sc.collection.objects.link(lo)
    cam = bpy.data.objects.new("C", bpy.data.cameras.new("C"))
    cam.data.type, cam.data.ortho_scale = "ORTHO", 3.0
    cam.location, cam.rotation_euler = (-3.0, 0.0, 3.0), (math.radians(45), 0.0, math.radians(-90))
    sc.collection.objects.link(cam)
    sc.camera = cam
    W = 64
    sc.render.resolution_x = sc.render.resolution_y = W
    sc.render.resolution_percentage = 100
    bpy.context.view_layer.update()  # matrix_world from the transforms (a cached render evaluates nothing)
    cyc, _ = cycles("burley_direct_%.2f" % rough, lambda: None, ["DiffDir", "DiffCol"], 64, 1.0, out_dir)
    M = np.array(cam.matrix_world, np.float64)
    c = (np.arange(W) + 0.5) / W * 3.0 - 1.5
    U, V = np.meshgrid(c, -c)
    org = M[:3, 0][None] * U.reshape(-1, 1) + M[:3, 1][None] * V.reshape(-1, 1) + M[:3, 3][None]
    fwd = -M[:3, 2] / np.linalg.norm(M[:3, 2])
    pos = org - (org[:, 2:3] / fwd[2]) * fwd[None]
    d = np.array(L)[None] - pos
    d2 = (d * d).sum(1)
    wi = (d / np.sqrt(d2)[:, None]).astype(np.float32)
    n = len(pos)
    N = np.tile(np.float32([0, 0, 1]), (n, 1))
    T = np.tile(np.float32([1, 0, 0]), (n, 1))
    WO = np.tile((-fwd).astype(np.float32), (n, 1))
    got = cyc["DiffDir"][..., 0].reshape(-1)  # Cycles' DiffDir has the colour (DiffCol) divided out
    ok = (cyc["DiffCol"][..., 0].reshape(-1) > 0.1) & (wi[:, 2] > 0.05)
    out = []
    for flags in (libvsgl.MATERIAL_FLAG_BURLEY, 0):
        m = libvsgl.vsgl_material()
        m.base_color[:] = (1.0, 1.0, 1.0)
        m.roughness, m.flags = rough, flags
        fd, _ = libvsgl.reference_brdf(m, N, T, wi, WO)
        r = got / np.maximum(fd[:, 0] * P / (4 * math.pi * d2), 1e-12)
        out.append([float(r[ok & (wi[:, 2] >= a) & (wi[:, 2] < b)].mean())
                    for a, b in ((0.05, 0.15), (0.15, 0.3), (0.3, 1.01))])
    return out


def check_burley_direct(out_dir, report):
    """Blender 3.4's Principled diffuse is the library's Burley form: Cycles'
    direct light over the library's BRDF is flat across the incidence (the
    bins' spread, and each bin's distance from 1, within TOL_BURLEY_FLAT),
    where Lambert's is not (its spread is printed beside). In 4.x+ the Principled diffuse is Lambert's:
    skipped there."""
    if bpy.app.version >= (4, 0, 0):
        report.append("SKIP burley direct: Blender %s's Principled diffuse is Lambert's" % bpy.app.version_string)
        return True
    ok = True
    for rough in (0.0, 0.5, 1.0):
        with_flag, lambert = burley_direct_ratio(rough, out_dir)
        spread = max(with_flag) / min(with_flag) - 1.0
        spread_l = max(lambert) / min(lambert) - 1.0
        good = spread < TOL_BURLEY_FLAT and all(abs(r - 1.0) < TOL_BURLEY_FLAT for r in with_flag)
        ok &= good
        line = ("%s burley direct, roughness %.1f: Cycles DiffDir over the library's BRDF x E in incidence bins "
                "0.05-0.15 / 0.15-0.3 / 0.3-1: %s, spread %.2f %% (tol %.1f %%); Lambert's %s, spread %.1f %%"
                % ("PASS" if good else "FAIL", rough, np.round(with_flag, 4), 100 * spread, 100 * TOL_BURLEY_FLAT,
                   np.round(lambert, 4), 100 * spread_l))
        print(line)
        report.append(line)
    return ok


EMIT_S, EMIT_C = 8.0, (1.0, 0.9, 0.7)


def build_emission_units(closed=False):
    """An emissive 1.2 x 0.8 m panel 1.5 m above a white floor (closed: inside
    a 6 m box, for the power balance), seen from above."""
    sc = reset()
    white = lambert("white", (0.8, 0.8, 0.8))

    def emit(nodes, links, bsdf):
        e = nodes.new("ShaderNodeEmission")
        e.inputs["Strength"].default_value = EMIT_S
        e.inputs["Color"].default_value = EMIT_C + (1.0,)
        links.new(e.outputs["Emission"], nodes["Material Output"].inputs["Surface"])
    panel = material("panel", emit)
    quad("Floor", (-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0), white)
    if closed:
        quad("Top", (-4, -4, 3), (-4, 4, 3), (4, 4, 3), (4, -4, 3), white)
        quad("W1", (-4, 4, 0), (4, 4, 0), (4, 4, 3), (-4, 4, 3), white)
        quad("W2", (-4, -4, 0), (-4, 4, 0), (-4, 4, 3), (-4, -4, 3), white)
        quad("W3", (4, -4, 0), (4, -4, 3), (4, 4, 3), (4, 4, 0), white)
        quad("W4", (4, -4, 0), (-4, -4, 0), (-4, -4, 3), (4, -4, 3), white)
    quad("Panel", (-0.6, -0.4, 1.5), (-0.6, 0.4, 1.5), (0.6, 0.4, 1.5), (0.6, -0.4, 1.5), panel)
    cam = bpy.data.cameras.new("Top")
    cam.type = "ORTHO"
    cam.ortho_scale = 4.0
    ob = bpy.data.objects.new("Top", cam)
    ob.location = (0, 0, 1.2)      # under the panel: it sees the floor only
    sc.collection.objects.link(ob)
    sc.camera = ob
    sc.render.resolution_x = sc.render.resolution_y = 96
    sc.render.resolution_percentage = 100
    return sc


def check_emission_units(out_dir, report):
    """The emissive panel's lights: RSM flux against the emitted power (closed
    box: both sides' light lands somewhere), and the irradiance the RSM
    implies on the floor against Cycles' DiffDir (cos^2 kernel of half-width
    0.3 m at 9 points, as cycles_ref.py's light-unit suite)."""
    ok = True
    sc = build_emission_units(closed=True)
    sd = export.collect(bpy.context.evaluated_depsgraph_get(), sc)
    ctx = libvsgl.Context()
    scene = libvsgl.Scene(ctx, **engine.scene_arrays(sd, libvsgl))
    total = sum(libvsgl.reference_rsm(ctx, scene, i, 256)["flux"].astype(np.float64).sum(0)
                for i in range(len(sd.lights)))
    scene.close()
    want = 2 * math.pi * 1.2 * 0.8 * EMIT_S * np.array(EMIT_C)
    rel = np.abs(total / want - 1)
    good = bool((rel < 0.005).all()) and len(sd.lights) == 2
    ok &= good
    line = "%s emission units: %d lights, RSM flux %s W vs emitted 2 pi A S C = %s W (rel %s %%)" % (
        "PASS" if good else "FAIL", len(sd.lights), np.round(total, 3), np.round(want, 3), np.round(100 * rel, 3))
    print(line)
    report.append(line)
    cyc, _ = cycles("emission_units", build_emission_units, ["DiffDir"], 256, 1.0, out_dir)
    E_cyc = math.pi * cyc["DiffDir"][..., 0] / EMIT_C[0]
    sc = build_emission_units()
    sd = export.collect(bpy.context.evaluated_depsgraph_get(), sc)
    scene = libvsgl.Scene(ctx, **engine.scene_arrays(sd, libvsgl))
    rs = [libvsgl.reference_rsm(ctx, scene, i, 512) for i in range(len(sd.lights))]
    scene.close()
    P = np.concatenate([r["positions"] for r in rs])
    F = np.concatenate([r["flux"][:, 0] for r in rs]) / EMIT_C[0]
    h, w = E_cyc.shape
    xs = (np.arange(w) + 0.5) / w * 4.0 - 2.0
    ys = 2.0 - (np.arange(h) + 0.5) / h * 4.0
    X, Y = np.meshgrid(xs, ys)
    pix = (4.0 / w) * (4.0 / h)
    worst = 0.0
    for gx in (-1.0, 0.0, 1.0):
        for gy in (-1.0, 0.0, 1.0):
            ec = float(np.sum(E_cyc * cycles_ref.kernel(X - gx, Y - gy, 0.3)) * pix)
            sel = (np.abs(P[:, 0] - gx) < 0.3) & (np.abs(P[:, 1] - gy) < 0.3) & (np.abs(P[:, 2]) < 1e-3)
            er = float(np.sum(F[sel] * cycles_ref.kernel(P[sel, 0] - gx, P[sel, 1] - gy, 0.3)))
            worst = max(worst, abs(er / ec - 1))
    good = worst < 0.02
    ok &= good
    line = "%s emission irradiance: RSM-implied E vs Cycles DiffDir under the panel, worst of 9 points %.2f %% " \
           "(tol 2 %%)" % ("PASS" if good else "FAIL", 100 * worst)
    print(line)
    report.append(line)
    return ok


# ---------------------------------------------------------------------------
# rendering
# ---------------------------------------------------------------------------

def cycles(name, build, passes, samples, filter_width, out_dir):
    key = hashlib.sha1((open(__file__).read() + name + repr(passes) + bpy.app.version_string + str(samples)
                        + str(filter_width)).encode()).hexdigest()[:12]
    prefix = os.path.join(out_dir, "cycles", "%s_%s" % (name, key))
    blender5 = not hasattr(bpy.context.scene, "node_tree")
    files = [prefix + "_all.exr"] if blender5 else [prefix + "_" + p + "_0001.exr" for p in passes]
    secs = None
    if not all(os.path.exists(f) for f in files):
        os.makedirs(os.path.dirname(prefix), exist_ok=True)
        build()
        sc = bpy.context.scene
        t0 = time.time()
        render_cycles(sc, passes, prefix, samples, filter_width)
        secs = time.time() - t0
    if blender5:
        return cycles_ref.read_passes_exr(files[0], passes), secs
    return {p: cycles_ref.load_exr_rgb(f) for p, f in zip(passes, files)}, secs


def render_cycles(sc, passes, prefix, samples, filter_width):
    """cycles_ref's one-bounce settings (no clamps, black world, fixed seed),
    with a box pixel filter of ``filter_width`` pixels (it sets 0.01: the
    pixel centre) restored just before the render starts."""
    def pre(scene, *a):
        scene.cycles.filter_width = filter_width
    bpy.app.handlers.render_pre.append(pre)
    try:
        cycles_ref.render_cycles(None, passes, prefix, samples)
    finally:
        bpy.app.handlers.render_pre.remove(pre)


def library(sc, settings, aa=None):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    sd = export.collect(depsgraph, sc)
    ctx = libvsgl.Context()
    scene = libvsgl.Scene(ctx, **engine.scene_arrays(sd, libvsgl))
    s = settings
    if aa is not None:
        s.aa_samples = aa
    t0 = time.time()
    planes, stats = libvsgl.render(ctx, scene, s)
    secs = time.time() - t0
    scene.close()
    return planes, secs, sd


def preset(name):
    return libvsgl.render_settings_preset(getattr(libvsgl.Preset, name))


def brute(res=256, aa=2):
    s = libvsgl.vsgl_render_settings(method=libvsgl.Method.BRUTE_FORCE, rsm_resolution=res, aa_samples=aa)
    return s


# ---------------------------------------------------------------------------
# checks
# ---------------------------------------------------------------------------

def check_diffcol(out_dir, report):
    cyc, _ = cycles("diffcol", build_diffcol, ["DiffCol"], DIFFCOL_SPP, 1.0, out_dir)
    sc = build_diffcol()
    lib, secs, sd = library(sc, preset("PREVIEW"), aa=DIFFCOL_AA)
    for w in sd.warnings:
        print("  export warning:", w)
    a, b = lib["diffuse_color"], cyc["DiffCol"]
    mask = (a.max(-1) > 0) & (b.max(-1) > 0)
    rel = np.abs(a - b)[mask].mean() / b[mask].mean()
    bias = a[mask].mean(0) / b[mask].mean(0) - 1
    ok = rel < TOL_DIFFCOL and bool((np.abs(bias) < TOL_DIFFCOL).all())
    line = ("%s diffcol: per pixel mean |lib - Cycles| / mean Cycles = %.3f %%, mean RGB bias %s %% over %d "
            "pixels (tol %.1f %%)" % ("PASS" if ok else "FAIL", 100 * rel, np.round(100 * bias, 3), mask.sum(),
                                      100 * TOL_DIFFCOL))
    print(line)
    report.append(line)
    # per panel (columns of the image), to locate a failing setup
    W = a.shape[1]
    for i in range(5):
        c0, c1 = int(W * (0.5 + (-2.5 + i) / 5.6)), int(W * (0.5 + (-1.6 + i) / 5.6))
        rows = slice(int(0.15 * a.shape[0]), int(0.55 * a.shape[0]))
        m = mask[rows, c0:c1]
        if m.sum():
            ra = a[rows, c0:c1][m].mean(0)
            rb = b[rows, c0:c1][m].mean(0)
            report.append("  panel %d: lib %s Cycles %s" % (i, np.round(ra, 4), np.round(rb, 4)))
    save_pair(out_dir, "diffcol", a, b)
    return ok


def save_pair(out_dir, name, a, b):
    try:
        from imgutil import save_png
        img = np.concatenate([a, b, np.abs(a - b) * 4], axis=1)
        save_png(os.path.join(out_dir, name + ".png"), np.clip(img, 0, 1) ** (1 / 2.2))
    except Exception as e:  # pictures are a courtesy
        print("  (no picture: %s)" % e)


def floor_mask(h, w):
    m = np.zeros((h, w), bool)
    m[int(0.62 * h):, int(0.1 * w):int(0.9 * w)] = True
    return m


def check_bleed(out_dir, report):
    passes = ["DiffInd", "DiffCol"]
    cyc, _ = cycles("bleed", lambda: build_bleed(True), passes, 1024, 1.0, out_dir)
    ref = cyc["DiffInd"] * cyc["DiffCol"]
    m = floor_mask(*ref.shape[:2])
    want = ref[m].mean(0)
    ok_all = True
    for label, settings in (("quality", preset("QUALITY")), ("brute force", brute(96, 1))):
        sc = build_bleed(True)
        lib, secs, sd = library(sc, settings)
        got = lib["diffuse"][m].mean(0)
        rel = np.abs(got - want) / want
        ok = bool((rel < TOL_BLEED).all())
        ok_all &= ok
        line = "%s bleed %s: floor mean RGB lib %s Cycles %s rel %s %% (tol %.0f %%), %.2f s" % (
            "PASS" if ok else "FAIL", label, np.round(got, 5), np.round(want, 5), np.round(100 * rel, 2),
            100 * TOL_BLEED, secs)
        print(line)
        report.append(line)
        if label == "quality":
            save_pair(out_dir, "bleed", lib["diffuse"] * 4, ref * 4)
    # the texture matters: a flat grey wall of the same luminance bleeds another colour
    sc = build_bleed(False)
    lib, secs, sd = library(sc, preset("QUALITY"))
    grey = lib["diffuse"][m].mean(0)
    chroma = lambda v: v / v.sum()  # noqa: E731
    d = np.abs(chroma(grey) - chroma(want)).max() / chroma(want).max()
    ok = d > TOL_BLEED
    line = "%s bleed: a flat grey wall's floor colour differs from the textured wall's by %.1f %% (> %.0f %%)" % (
        "PASS" if ok else "FAIL", 100 * d, 100 * TOL_BLEED)
    print(line)
    report.append(line)
    return ok_all and ok


def main():
    out_dir = os.path.abspath(A["--out"])
    os.makedirs(out_dir, exist_ok=True)
    report = ["# Textures vs Cycles (%s)" % bpy.app.version_string, ""]
    checks = [("diffcol", check_diffcol), ("bleed", check_bleed), ("emission", check_emission),
              ("emission_units", check_emission_units), ("principled_diffuse", check_principled_diffuse),
              ("burley_direct", check_burley_direct)]
    extra = globals().get("EXTRA_CHECKS", [])
    p = f = 0
    for name, fn in checks + extra:
        if A["--only"] and name not in A["--only"].split(","):
            continue
        try:
            ok = fn(out_dir, report)
        except Exception as e:
            import traceback
            traceback.print_exc()
            report.append("FAIL %s: %s" % (name, e))
            ok = False
        p += int(ok)
        f += int(not ok)
    with open(os.path.join(out_dir, "report.md"), "w") as fh:
        fh.write("\n".join(report) + "\n")
    summary = "%d passed, %d failed" % (p, f)
    with open(os.path.join(out_dir, "summary.txt"), "w") as fh:
        fh.write("\n".join(report[2:]) + "\n" + summary + "\n")
    print(summary)
    if f:
        sys.exit(1)


if __name__ == "__main__":
    main()
