"""The room the live-preview tools use (tools/live_screenshot.py,
tools/bench_live.py): a 6 x 6 x 3 m box with a metal floor, red and green
walls, a spot light at the ceiling aimed at the left wall, a 24 mm camera.
Built in the current Blender scene with bpy."""
import math

import bpy


def material(name, rgb, rough=0.5, metal=0.0):
    m = bpy.data.materials.new(name)
    if m.node_tree is None:
        m.use_nodes = True
    b = m.node_tree.nodes["Principled BSDF"]
    b.inputs["Base Color"].default_value = tuple(rgb) + (1,)
    b.inputs["Roughness"].default_value = rough
    b.inputs["Metallic"].default_value = metal
    return m


def quad(scene, name, verts, mat):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], [(0, 1, 2, 3)])
    me.materials.append(mat)
    ob = bpy.data.objects.new(name, me)
    scene.collection.objects.link(ob)
    return ob


def build_room(scene):
    """Returns (spot light object, camera object)."""
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    white = material("White", (0.8, 0.8, 0.8))
    metal = material("Floor", (0.7, 0.7, 0.7), 0.25, 1.0)
    quad(scene, "Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], metal)
    quad(scene, "Back", [(-3, 3, 0), (3, 3, 0), (3, 3, 3), (-3, 3, 3)], white)
    quad(scene, "Left", [(-3, -3, 0), (-3, 3, 0), (-3, 3, 3), (-3, -3, 3)], material("Red", (0.8, 0.05, 0.05)))
    quad(scene, "Right", [(3, 3, 0), (3, -3, 0), (3, -3, 3), (3, 3, 3)], material("Green", (0.05, 0.6, 0.1)))
    quad(scene, "Ceiling", [(-3, -3, 3), (-3, 3, 3), (3, 3, 3), (3, -3, 3)], white)
    ld = bpy.data.lights.new("Spot", "SPOT")
    ld.energy, ld.spot_size = 800.0, 1.0
    light = bpy.data.objects.new("Spot", ld)
    light.location = (-1.5, 0.0, 2.8)
    light.rotation_euler = (0.0, math.radians(-60), 0.0)
    scene.collection.objects.link(light)
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.location, cam.rotation_euler = (0, -7.5, 1.6), (math.radians(85), 0, 0)
    cam.data.lens = 24
    scene.collection.objects.link(cam)
    scene.camera = cam
    return light, cam
