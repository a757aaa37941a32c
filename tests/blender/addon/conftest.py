"""Shared fixtures of the add-on tests. Runs inside Blender 3.4
(tests/blender/pytest_in_blender.py) and in the pip ``bpy`` module (5.x)."""
import os
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
# addon/ and this folder are on setup.cfg's pythonpath (pytest finds it
# from the repository root, in Blender as in the pip module)

import bpy  # noqa: E402
import vsgl_indirect  # noqa: E402

if "vsgl_indirect" not in bpy.types.Scene.bl_rna.properties:
    vsgl_indirect.register()

from vsgl_indirect import engine  # noqa: E402

VERSION = tuple(bpy.app.version)
#: True inside the Blender binary (3.4 here), False in the pip bpy module.
IS_BINARY = bool(bpy.app.binary_path) and "blender" in os.path.basename(bpy.app.binary_path)
BOOTSTRAP = os.path.join(REPO, "tests", "blender", "bootstrap_addon.py")
BPY_RENDER = os.path.join(HERE, "bpy_render.py")


def real_render_or_skip():
    missing = engine.library_error()
    if missing:
        pytest.skip("libvsgl cannot render yet: %s" % missing)


@pytest.fixture
def scene():
    """An empty scene at factory settings, Cycles, tiny, no denoiser."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    s = bpy.context.scene
    s.render.engine = "CYCLES"
    s.cycles.samples = 1
    s.cycles.use_denoising = False
    s.render.resolution_x, s.render.resolution_y = 32, 24
    s.render.resolution_percentage = 100
    s.render.image_settings.file_format = "OPEN_EXR"
    s.world = None
    return s


def link(scene, obj, collection=None):
    (collection or scene.collection).objects.link(obj)
    return obj


def mesh_object(name, verts, faces, location=(0, 0, 0), material=None):
    me = bpy.data.meshes.new(name)
    me.from_pydata([tuple(v) for v in verts], [], [tuple(f) for f in faces])
    me.update()
    ob = bpy.data.objects.new(name, me)
    ob.location = location
    if material is not None:
        me.materials.append(material)
    return ob


def plane(name, size=2.0, location=(0, 0, 0), material=None):
    h = size / 2
    return mesh_object(name, [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], [(0, 1, 2, 3)],
                       location, material)


def cube(name, size=2.0, location=(0, 0, 0), material=None):
    h = size / 2
    v = [(x, y, z) for x in (-h, h) for y in (-h, h) for z in (-h, h)]
    f = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return mesh_object(name, v, f, location, material)


def principled(name, color=(0.8, 0.8, 0.8, 1), metallic=0.0, roughness=0.5, **extra):
    mat = bpy.data.materials.new(name)
    if mat.node_tree is None:
        mat.use_nodes = True
    bsdf = mat.node_tree.nodes.get("Principled BSDF")
    bsdf.inputs["Base Color"].default_value = color
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    for k, v in extra.items():
        bsdf.inputs[k].default_value = v
    return mat


def shader_material(name, bl_idname):
    """A material whose surface is one new node of type ``bl_idname`` (the
    default nodes removed); returns (material, node)."""
    mat = bpy.data.materials.new(name)
    if mat.node_tree is None:
        mat.use_nodes = True
    nt = mat.node_tree
    for n in list(nt.nodes):
        if n.bl_idname != "ShaderNodeOutputMaterial":
            nt.nodes.remove(n)
    node = nt.nodes.new(bl_idname)
    nt.links.new(node.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    return mat, node


def camera(scene, location=(0, -6, 1), rotation=(1.4, 0, 0), lens=35.0):
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.location = location
    cam.rotation_euler = rotation
    cam.data.lens = lens
    link(scene, cam)
    scene.camera = cam
    return cam


def light(scene, kind="POINT", name=None, energy=100.0, location=(0, -1, 3), **props):
    ld = bpy.data.lights.new(name or kind.title(), kind)
    ld.energy = energy
    for k, v in props.items():
        setattr(ld, k, v)
    ob = bpy.data.objects.new(name or kind.title(), ld)
    ob.location = location
    return link(scene, ob)


def room(scene, aov_template=None):
    """Floor + coloured back wall + spot light + camera: a lit scene."""
    floor = link(scene, plane("Floor", 8, (0, 0, 0), principled("FloorMat", roughness=0.3)))
    wall = link(scene, plane("Wall", 8, (0, 3, 2), principled("WallMat", (0.8, 0.1, 0.1, 1))))
    wall.rotation_euler = (1.5708, 0, 0)
    camera(scene)
    light(scene, "SPOT", "Spot", 500.0, (0, 0, 4), spot_size=1.2)
    if aov_template:
        scene.vsgl_indirect.output_path = aov_template
    scene.vsgl_indirect.enabled = True
    return floor, wall


def save(path):
    bpy.ops.wm.save_as_mainfile(filepath=path)
    return path


def render(blend, frames, env=None, timeout=240, extra=()):
    """Render ``frames`` (int for -f N, (start, end) for -s/-e -a) of ``blend``
    in a new process with the add-on registered. Returns CompletedProcess
    (stdout and stderr merged in .stdout)."""
    e = dict(os.environ)
    e.update(env or {})
    if IS_BINARY:
        cmd = [bpy.app.binary_path, "-b", "--factory-startup", blend, "--python", BOOTSTRAP]
        for x in extra:
            cmd += ["--python", x]
        if isinstance(frames, int):
            cmd += ["-f", str(frames)]
        else:
            cmd += ["-s", str(frames[0]), "-e", str(frames[1]), "-a"]
    else:
        spec = str(frames) if isinstance(frames, int) else "%d:%d" % frames
        cmd = [sys.executable, BPY_RENDER, blend, spec] + list(extra)
    return subprocess.run(cmd, env=e, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          universal_newlines=True, timeout=timeout)
