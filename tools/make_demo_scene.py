"""Build the demo scene (run inside Blender):

    blender -b --factory-startup --python tools/make_demo_scene.py -- OUT.blend [W H SPP PRESET]

A small textured interior, everything generated here (no downloads): a
glossy wooden floor (planks texture), a teal patterned wallpaper (texture x
colour through a Mix node), a terracotta plaster wall (noise texture
through Hue/Saturation), a white wall with a window the sun shines
through, a checkered rug, a warm emissive ceiling panel (an Emission
shader: exported as area lights), an orange cabinet, a gold sphere and a
blue box. Cycles renders direct light only (max_bounces 0); the add-on's
AOV adds the one-bounce indirect light in the compositor. The compositor
also writes the direct render to //direct/direct_####.exr for the
comparison.
"""
import math
import os
import sys

import bpy
import numpy as np
from mathutils import Vector

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
out = os.path.abspath(argv[0] if argv else "out/demo/demo.blend")
W = int(argv[1]) if len(argv) > 1 else 960
H = int(argv[2]) if len(argv) > 2 else 540
SPP = int(argv[3]) if len(argv) > 3 else 8
PRESET = argv[4] if len(argv) > 4 else "BALANCED"

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "addon"))
import vsgl_indirect  # noqa: E402

if "vsgl_indirect" not in bpy.types.Scene.bl_rna.properties:
    vsgl_indirect.register()

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
VERSION = bpy.app.version
SPEC = "Specular" if VERSION < (4, 0, 0) else "Specular IOR Level"
rng = np.random.default_rng(7)


# ---- textures (numpy -> packed 8-bit sRGB images) ---------------------------

def image(name, rgb, colorspace="sRGB"):
    h, w = rgb.shape[:2]
    px = np.ones((h, w, 4), np.float32)
    px[..., :3] = np.clip(rgb, 0, 1)
    im = bpy.data.images.new(name, w, h, alpha=True)
    im.colorspace_settings.name = colorspace
    im.pixels.foreach_set(px.reshape(-1))
    im.pack()
    return im


def smooth_noise(h, w, cells, seed):
    r = np.random.default_rng(seed).random((cells + 1, cells + 1))
    y = np.linspace(0, cells, h, endpoint=False)
    x = np.linspace(0, cells, w, endpoint=False)
    y0, x0 = y.astype(int), x.astype(int)
    fy, fx = (y - y0)[:, None], (x - x0)[None, :]
    fy, fx = fy * fy * (3 - 2 * fy), fx * fx * (3 - 2 * fx)
    a = r[y0][:, x0] * (1 - fx) + r[y0][:, x0 + 1] * fx
    b = r[y0 + 1][:, x0] * (1 - fx) + r[y0 + 1][:, x0 + 1] * fx
    return a * (1 - fy) + b * fy


def planks(n=512):
    """Wooden planks along u: 8 planks across, staggered joints, grain."""
    v = np.arange(n)[:, None] / n
    u = np.arange(n)[None, :] / n
    plank = np.floor(v * 8).astype(int)
    tone = np.random.default_rng(3).uniform(0.75, 1.15, 8)[plank]
    grain = 0.85 + 0.15 * np.sin(u * 90 + 6 * smooth_noise(n, n, 6, 4)) * smooth_noise(n, n, 24, 5)
    offset = (plank * 0.37) % 1.0
    joint = ((u + offset) % 0.5 < 0.004) | ((v * 8) % 1 < 0.03)
    base = np.array([0.62, 0.38, 0.20])
    rgb = base[None, None, :] * (tone * grain)[..., None]
    rgb[joint] *= 0.45
    return rgb


def wallpaper(n=256):
    """A light damask-like pattern (grey levels; tinted teal by a Mix node)."""
    y, x = np.mgrid[0:n, 0:n] / n * 2 * math.pi * 4
    p = 0.5 + 0.5 * np.sin(x) * np.sin(y) * np.cos(0.5 * (x + y))
    g = 0.55 + 0.4 * (p > 0.62) + 0.05 * smooth_noise(n, n, 16, 9)
    return np.repeat(g[..., None], 3, axis=2)


def plaster(n=256):
    g = 0.7 + 0.3 * smooth_noise(n, n, 12, 11) + 0.08 * smooth_noise(n, n, 48, 12)
    return np.stack([0.75 * g, 0.45 * g, 0.32 * g], -1)


def rug(n=256):
    y, x = np.mgrid[0:n, 0:n]
    c = ((x // 32) + (y // 32)) % 2
    border = (x < 16) | (y < 16) | (x >= n - 16) | (y >= n - 16)
    rgb = np.where(c[..., None] == 0, np.array([0.65, 0.08, 0.07]), np.array([0.85, 0.78, 0.6]))
    rgb[border] = (0.1, 0.12, 0.3)
    return rgb


# ---- materials ----------------------------------------------------------------

def principled(name, color=(0.8, 0.8, 0.8), roughness=0.5, metallic=0.0, spec=0.5):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    b = m.node_tree.nodes["Principled BSDF"]
    b.inputs["Base Color"].default_value = tuple(color) + (1.0,)
    b.inputs["Roughness"].default_value = roughness
    b.inputs["Metallic"].default_value = metallic
    b.inputs[SPEC].default_value = spec
    m.diffuse_color = tuple(color) + (1.0,)
    return m, m.node_tree, b


def textured(name, im, roughness=0.6, spec=0.5, tint=None, hue=None):
    m, nt, b = principled(name, roughness=roughness, spec=spec)
    t = nt.nodes.new("ShaderNodeTexImage")
    t.image = im
    col = t.outputs["Color"]
    if tint is not None:                 # Multiply by a colour through a Mix node
        if VERSION >= (3, 4, 0):
            mix = nt.nodes.new("ShaderNodeMix")
            mix.data_type = "RGBA"
            mix.blend_type = "MULTIPLY"
            ins = {s.identifier: s for s in mix.inputs}
            ins["Factor_Float"].default_value = 1.0
            ins["B_Color"].default_value = tuple(tint) + (1.0,)
            nt.links.new(col, ins["A_Color"])
            col = {s.identifier: s for s in mix.outputs}["Result_Color"]
        else:
            mix = nt.nodes.new("ShaderNodeMixRGB")
            mix.blend_type = "MULTIPLY"
            mix.inputs["Fac"].default_value = 1.0
            mix.inputs["Color2"].default_value = tuple(tint) + (1.0,)
            nt.links.new(col, mix.inputs["Color1"])
            col = mix.outputs["Color"]
    if hue is not None:                  # Hue/Saturation in front of Base Color
        hs = nt.nodes.new("ShaderNodeHueSaturation")
        hs.inputs["Hue"].default_value, hs.inputs["Saturation"].default_value = hue
        nt.links.new(col, hs.inputs["Color"])
        col = hs.outputs["Color"]
    nt.links.new(col, b.inputs["Base Color"])
    return m


def emission(name, color, strength):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    e = nt.nodes.new("ShaderNodeEmission")
    e.inputs["Color"].default_value = tuple(color) + (1.0,)
    e.inputs["Strength"].default_value = strength
    nt.links.new(e.outputs["Emission"], nt.nodes["Material Output"].inputs["Surface"])
    return m


# ---- geometry ------------------------------------------------------------------

def mesh(name, verts, faces, mat, uv_size=None):
    """Faces with UVs in metres / uv_size (planar per face, tiled textures)."""
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    lay = me.uv_layers.new(name="UVMap")
    V = np.array(verts, float)
    for poly in me.polygons:
        idx = [me.loops[li].vertex_index for li in poly.loop_indices]
        p = V[idx]
        n = np.cross(p[1] - p[0], p[2] - p[0])
        n /= np.linalg.norm(n)
        a = p[1] - p[0]
        a /= np.linalg.norm(a)
        b = np.cross(n, a)
        for li, vi in zip(poly.loop_indices, idx):
            d = V[vi] - p[0]
            s = uv_size or 1.0
            lay.data[li].uv = (np.dot(d, a) / s, np.dot(d, b) / s)
    me.materials.append(mat)
    ob = bpy.data.objects.new(name, me)
    scene.collection.objects.link(ob)
    return ob


def quad(name, p0, p1, p2, p3, mat, uv_size=None):
    return mesh(name, [p0, p1, p2, p3], [(0, 1, 2, 3)], mat, uv_size)


def box(name, lo, hi, mat):
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1),
         (x0, y1, z1)]
    f = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    return mesh(name, v, f, mat, 0.5)


# room: x in [-3, 3], y in [-2.5, 2.5], z in [0, 2.8]; the window is in the right wall (x = 3)
X0, X1, Y0, Y1, Z1 = -3.0, 3.0, -2.5, 2.5, 2.8
wood = textured("Wood floor", image("planks", planks()), roughness=0.18, spec=0.5)
paper = textured("Teal wallpaper", image("wallpaper", wallpaper()), roughness=0.9, spec=0.2,
                 tint=(0.25, 0.62, 0.6))
terra = textured("Terracotta plaster", image("plaster", plaster()), roughness=0.9, spec=0.2,
                 hue=(0.52, 1.2))
white, _, _ = principled("White paint", (0.82, 0.8, 0.76), roughness=0.8, spec=0.3)
ceil, _, _ = principled("Ceiling", (0.85, 0.85, 0.85), roughness=0.9, spec=0.2)
rugm = textured("Rug", image("rug", rug()), roughness=0.95, spec=0.1)
orange, _, _ = principled("Orange lacquer", (0.9, 0.35, 0.05), roughness=0.35)
gold, _, _ = principled("Gold", (1.0, 0.75, 0.35), roughness=0.3, metallic=1.0)
blue, _, _ = principled("Blue", (0.1, 0.2, 0.7), roughness=0.5)
lamp = emission("Lamp panel", (1.0, 0.8, 0.55), 12.0)

quad("Floor", (X0, Y0, 0), (X1, Y0, 0), (X1, Y1, 0), (X0, Y1, 0), wood, 2.0)
quad("Ceiling", (X0, Y0, Z1), (X0, Y1, Z1), (X1, Y1, Z1), (X1, Y0, Z1), ceil, 2.0)
quad("Back wall", (X0, Y1, 0), (X1, Y1, 0), (X1, Y1, Z1), (X0, Y1, Z1), paper, 1.2)
quad("Left wall", (X0, Y0, 0), (X0, Y1, 0), (X0, Y1, Z1), (X0, Y0, Z1), terra, 1.5)
quad("Front wall", (X1, Y0, 0), (X0, Y0, 0), (X0, Y0, Z1), (X1, Y0, Z1), white, 2.0)
# right wall with a window opening y in [-0.6, 1.2], z in [0.9, 2.2]
wy0, wy1, wz0, wz1 = -0.6, 1.2, 0.9, 2.2
for i, (a, b) in enumerate([((Y0, 0), (wy0, Z1)), ((wy1, 0), (Y1, Z1)), ((wy0, 0), (wy1, wz0)),
                            ((wy0, wz1), (wy1, Z1))]):
    (ya, za), (yb, zb) = a, b
    quad("Right wall %d" % i, (X1, ya, za), (X1, ya, zb), (X1, yb, zb), (X1, yb, za), white, 2.0)
quad("Rug", (-1.6, -1.2, 0.005), (0.9, -1.2, 0.005), (0.9, 0.6, 0.005), (-1.6, 0.6, 0.005), rugm, 1.8)
box("Cabinet", (-2.9, 0.9, 0), (-1.8, 2.4, 1.1), orange)
box("Blue box", (0.9, 1.3, 0), (1.6, 2.0, 0.7), blue)
bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=0.45, location=(-0.4, 1.2, 0.45))
sph = bpy.context.active_object
sph.name = "Gold sphere"
sph.data.materials.append(gold)
for p in sph.data.polygons:
    p.use_smooth = True
# a flat LED fixture hanging 10 cm under the ceiling: a 3 cm box whose bottom
# face emits (the emission's back side faces the box's top 3 cm away: the
# export skips it and says so)
fixture = box("Lamp panel", (-1.2, -0.5, Z1 - 0.13), (0.2, 0.3, Z1 - 0.10), white)
fixture.data.materials.append(lamp)
fixture.data.polygons[0].material_index = 1        # the bottom face (0, 3, 2, 1) faces down

sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
sun.data.energy = 8.0
sun.data.color = (1.0, 0.93, 0.8)
sun.data.angle = math.radians(1.5)
# light travels along d: in through the window (x = 3) and down onto the floor and the left wall
d = Vector((-1.0, -0.15, -0.75)).normalized()
sun.rotation_euler = (-d).to_track_quat("Z", "Y").to_euler()
scene.collection.objects.link(sun)

cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
cam.location = (-2.75, -2.25, 1.5)
cam.rotation_euler = (Vector((1.6, 1.3, 0.85)) - cam.location).to_track_quat("-Z", "Y").to_euler()
cam.data.lens = 17
scene.collection.objects.link(cam)
scene.camera = cam

r = scene.render
r.engine = "CYCLES"
r.resolution_x, r.resolution_y, r.resolution_percentage = W, H, 100
r.filepath = "//composite_"
r.image_settings.file_format = "OPEN_EXR"
r.image_settings.color_depth = "32"
scene.frame_start = scene.frame_end = scene.frame_current = 1
c = scene.cycles
c.samples = SPP
c.use_denoising = False
c.max_bounces = 0          # direct light only: the AOV brings the first bounce
c.seed = 0
c.use_adaptive_sampling = False
scene.world = None
vl = scene.view_layers[0]
vl.use_pass_diffuse_color = True    # for the "Cycles Colours" comparison
vl.use_pass_glossy_color = True

os.makedirs(os.path.dirname(out), exist_ok=True)
bpy.ops.wm.save_as_mainfile(filepath=out)   # so '//' paths resolve next to it
props = scene.vsgl_indirect
props.output_path = "//aov/indirect_####.exr"
props.add_to_render = True
props.preset = PRESET
props.enabled = True

# Direct-light copy for the side-by-side preview (File Output runs in background).
from vsgl_indirect import compat  # noqa: E402
tree = compat.compositor_tree(scene, create=True)
rl = [n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers"][0]
fo = tree.nodes.new("CompositorNodeOutputFile")
fo.name = "Direct copy"
fo.location = (rl.location.x + 300, rl.location.y + 300)
if hasattr(fo, "base_path"):
    fo.base_path = "//direct/"
    fo.file_slots[0].path = "direct_"
else:   # 5.0
    fo.directory = "//direct/"
    fo.file_name = "direct_"
fo.format.file_format = "OPEN_EXR"
fo.format.color_depth = "32"
tree.links.new(rl.outputs["Image"], fo.inputs[0])

os.makedirs(os.path.dirname(out), exist_ok=True)
bpy.ops.wm.save_as_mainfile(filepath=out)
print("make_demo_scene: wrote %s (%dx%d, %d spp)" % (out, W, H, SPP))
