"""Build the demo scene (run inside Blender):

    blender -b --factory-startup --python tools/make_demo_scene.py -- OUT.blend [W H SPP]

A small room: glossy floor, red and green side walls and a white back wall
lit by a spot light, an anisotropic brushed-metal panel, an area light.
Cycles renders direct light only (max_bounces 0); the add-on's AOV adds
the one-bounce indirect light in the compositor. The compositor also
writes the direct render to //direct/direct_####.exr for the comparison.
"""
import math
import os
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
out = os.path.abspath(argv[0] if argv else "out/demo/demo.blend")
W = int(argv[1]) if len(argv) > 1 else 320
H = int(argv[2]) if len(argv) > 2 else 240
SPP = int(argv[3]) if len(argv) > 3 else 32

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "addon"))
import vsgl_indirect  # noqa: E402

if "vsgl_indirect" not in bpy.types.Scene.bl_rna.properties:
    vsgl_indirect.register()

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
VERSION = bpy.app.version


def material(name, color, metallic=0.0, roughness=0.5, spec=0.5, aniso=0.0, rot=0.0):
    m = bpy.data.materials.new(name)
    if m.node_tree is None:
        m.use_nodes = True
    b = m.node_tree.nodes["Principled BSDF"]
    b.inputs["Base Color"].default_value = color + (1.0,)
    b.inputs["Metallic"].default_value = metallic
    b.inputs["Roughness"].default_value = roughness
    b.inputs["Specular" if VERSION < (4, 0, 0) else "Specular IOR Level"].default_value = spec
    b.inputs["Anisotropic"].default_value = aniso
    b.inputs["Anisotropic Rotation"].default_value = rot
    m.diffuse_color = color + (1.0,)
    return m


def quad(name, size, loc, rot, mat):
    sx, sy = size
    me = bpy.data.meshes.new(name)
    me.from_pydata([(-sx / 2, -sy / 2, 0), (sx / 2, -sy / 2, 0), (sx / 2, sy / 2, 0),
                    (-sx / 2, sy / 2, 0)], [], [(0, 1, 2, 3)])
    me.uv_layers.new()
    me.materials.append(mat)
    ob = bpy.data.objects.new(name, me)
    ob.location, ob.rotation_euler = loc, rot
    scene.collection.objects.link(ob)
    return ob


r90 = math.pi / 2
quad("Floor", (4, 4), (0, 0, 0), (0, 0, 0), material("GlossyFloor", (0.7, 0.7, 0.7), roughness=0.15))
quad("BackWall", (4, 3), (0, 2, 1.5), (r90, 0, 0), material("White", (0.8, 0.8, 0.8), roughness=0.8))
quad("LeftWall", (4, 3), (-2, 0, 1.5), (r90, 0, r90), material("Red", (0.8, 0.1, 0.08), roughness=0.7))
quad("RightWall", (4, 3), (2, 0, 1.5), (r90, 0, -r90), material("Green", (0.1, 0.7, 0.15), roughness=0.7))
quad("BrushedPanel", (1.4, 1.0), (0.6, 1.2, 0.9), (1.2, 0, -0.5),
     material("BrushedMetal", (0.9, 0.85, 0.8), metallic=1.0, roughness=0.35, aniso=0.8))


def add_light(name, kind, energy, loc, rot, **kw):
    ld = bpy.data.lights.new(name, kind)
    ld.energy = energy
    for k, v in kw.items():
        setattr(ld, k, v)
    ob = bpy.data.objects.new(name, ld)
    ob.location, ob.rotation_euler = loc, rot
    scene.collection.objects.link(ob)
    return ob


add_light("Spot", "SPOT", 600.0, (-1.2, -1.0, 2.8), (0.6, 0, -0.6), spot_size=0.9, spot_blend=0.3,
          shadow_soft_size=0.05)
add_light("Area", "AREA", 150.0, (1.2, -0.5, 2.9), (0.2, 0.3, 0), shape="RECTANGLE", size=0.6,
          size_y=0.3)

cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
cam.location, cam.rotation_euler = (0, -4.2, 1.4), (math.radians(84), 0, 0)
cam.data.lens = 24
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
scene.world = None

os.makedirs(os.path.dirname(out), exist_ok=True)
bpy.ops.wm.save_as_mainfile(filepath=out)   # so '//' paths resolve next to it
props = scene.vsgl_indirect
props.output_path = "//aov/indirect_####.exr"
props.add_to_render = True
props.preset = "BALANCED"
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
