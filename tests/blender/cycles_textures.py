"""The textures of a quality scene in Blender (run inside Blender, after
cycles_ref.build_blender): its UV map, its images and the Image Texture
nodes that feed them to the materials' colour inputs.

A scene's `images` table (tests/quality/scenes.py, texture_pixels) gives
each image's linear RGBA pixels; a textured material's colour input
(the Diffuse BSDF's Color, the Principled's Base Color) is linked to an
Image Texture node (Linear interpolation, Repeat, the mesh's UV map) and
keeps its constant colour, which such a material sets to white:
scenes.library_textures gives the library the same. Untextured scenes are
left as built: their reference cache keys (tests/quality/refs.py) do not
hash this file; textured scenes' keys do (refs.TEXTURE_CODE).
"""
import os
import sys

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "quality"))
import scenes  # noqa: E402


def apply_textures(case, ob):
    """Add case's UVs, images and texture nodes to the mesh object `ob` that
    build_blender made from it (its polygons in geometry order, each
    polygon's loops in its points' order). No-op without case["images"]."""
    if not case.get("images"):
        return
    me = ob.data
    layer = me.uv_layers.new(name="UVMap")
    uv = [p for t in scenes.polygon_uvs(case) for p in t]
    layer.data.foreach_set("uv", np.asarray(uv, np.float32).reshape(-1))
    images = {}
    for name, spec in sorted(case["images"].items()):
        px = scenes.texture_pixels(spec)
        img = bpy.data.images.new(name, px.shape[1], px.shape[0], alpha=True, float_buffer=True)
        img.colorspace_settings.name = "Non-Color"  # the pixels are linear values, used as they are
        img.pixels.foreach_set(px.reshape(-1))
        images[name] = img
    for slot in ob.material_slots:
        m = slot.material
        spec = case["materials"].get(m.name.split(".")[0]) if m else None
        if not spec or not spec.get("texture"):
            continue
        nt = m.node_tree
        target = None
        for n in nt.nodes:
            if n.type == "BSDF_DIFFUSE":
                target = n.inputs["Color"]
            elif n.type == "BSDF_PRINCIPLED" and spec["kind"] != "lambert_spec":
                target = n.inputs["Base Color"]
        if target is None:
            raise RuntimeError("cycles_textures: material %s has no colour input to texture" % m.name)
        tex = nt.nodes.new("ShaderNodeTexImage")
        tex.image = images[spec["texture"]]
        tex.interpolation = "Linear"
        tex.extension = "REPEAT"
        nt.links.new(tex.outputs["Color"], target)
    bpy.context.view_layer.update()
