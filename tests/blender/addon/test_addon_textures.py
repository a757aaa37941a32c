"""Textured materials in the export (issue 13): what reaches libvsgl for the
node setups artists use, and a warning naming everything that is ignored.
(Colours against Cycles: tests/blender/run_textures.sh.)"""
import bpy
import numpy as np

from conftest import camera, light, link, plane, principled, room
from vsgl_indirect import engine, export, libvsgl


def collect(scene):
    return export.collect(bpy.context.evaluated_depsgraph_get(), scene)


def image(name, px, colorspace="sRGB"):
    h, w = px.shape[:2]
    im = bpy.data.images.new(name, w, h, alpha=True)
    im.colorspace_settings.name = colorspace
    im.pixels.foreach_set(np.ascontiguousarray(px, np.float32).reshape(-1))
    return im


def test_image_texture_second_uv_map_and_vertex_colours(scene):
    px = np.ones((4, 8, 4), np.float32)
    px[..., 0] = np.linspace(0, 1, 8)[None, :]
    im = image("ramp", px)
    mat = principled("Tex")
    nt = mat.node_tree
    t = nt.nodes.new("ShaderNodeTexImage")
    t.image, t.interpolation, t.extension = im, "Closest", "CLIP"
    uvm = nt.nodes.new("ShaderNodeUVMap")
    uvm.uv_map = "Second"
    nt.links.new(uvm.outputs["UV"], t.inputs["Vector"])
    vc = nt.nodes.new("ShaderNodeVertexColor")
    vc.layer_name = "Col"
    mix = nt.nodes.new("ShaderNodeMixRGB")
    mix.blend_type = "MULTIPLY"
    mix.inputs["Fac"].default_value = 1.0
    nt.links.new(t.outputs["Color"], mix.inputs["Color1"])
    nt.links.new(vc.outputs["Color"], mix.inputs["Color2"])
    nt.links.new(mix.outputs["Color"], nt.nodes["Principled BSDF"].inputs["Base Color"])
    ob = link(scene, plane("P", 2.0, material=mat))
    me = ob.data
    me.uv_layers.new(name="UVMap")
    second = me.uv_layers.new(name="Second")
    for i, d in enumerate(second.data):
        d.uv = (0.25, 0.75)
    col = me.color_attributes.new("Col", "FLOAT_COLOR", "CORNER")
    for d in col.data:
        d.color = (0.5, 0.25, 1.0, 1.0)
    camera(scene)
    light(scene)
    sd = collect(scene)
    assert len(sd.textures) == 1
    pixels, flags = sd.textures[0]
    assert flags == 1 and pixels.shape == (4, 8, 4)          # sRGB 8-bit: decoded by the library
    slots = sd.material_textures[0]["slots"]
    assert set(slots) == {"base_color"} and slots["base_color"]["filter"] == 1 and slots["base_color"]["wrap"] == 2
    assert sd.material_textures[0]["flags"] == 1              # x corner colours
    assert np.allclose(sd.corner_uvs, 0.25 * np.array([1, 3])[None, None, :])   # the UV Map node's layer
    assert np.allclose(sd.corner_colors, (0.5, 0.25, 1.0))
    assert sd.materials[0]["base_color"] == (1.0, 1.0, 1.0)
    # the library takes it
    ctx = libvsgl.Context()
    libvsgl.Scene(ctx, **engine.scene_arrays(sd, libvsgl)).close()


def test_chains_are_baked_and_ramp_on_roughness(scene):
    px = np.full((2, 2, 4), 1.0, np.float32)
    px[..., :3] = 0.5
    im = image("grey", px, "Non-Color")
    mat = principled("Chain")
    nt = mat.node_tree
    b = nt.nodes["Principled BSDF"]
    t = nt.nodes.new("ShaderNodeTexImage")
    t.image = im
    inv = nt.nodes.new("ShaderNodeInvert")
    inv.inputs["Fac"].default_value = 0.5
    nt.links.new(t.outputs["Color"], inv.inputs["Color"])
    mix = nt.nodes.new("ShaderNodeMixRGB")
    mix.inputs["Fac"].default_value = 0.25
    mix.inputs["Color2"].default_value = (1.0, 0.0, 0.0, 1.0)
    nt.links.new(inv.outputs["Color"], mix.inputs["Color1"])
    nt.links.new(mix.outputs["Color"], b.inputs["Base Color"])
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.2, 0.2, 0.2, 1)
    ramp.color_ramp.elements[1].color = (0.6, 0.6, 0.6, 1)
    nt.links.new(t.outputs["Color"], ramp.inputs["Fac"])
    nt.links.new(ramp.outputs["Color"], b.inputs["Roughness"])
    link(scene, plane("P", 2.0, material=mat)).data.uv_layers.new()
    camera(scene)
    light(scene)
    sd = collect(scene)
    slots = sd.material_textures[0]["slots"]
    base = sd.textures[slots["base_color"]["texture"] - 1][0]
    rough = sd.textures[slots["roughness"]["texture"] - 1][0]
    # invert(0.5) of 0.5 = 0.5; mix 0.25 with red: (0.625, 0.375, 0.375)
    assert np.allclose(base[0, 0, :3], (0.625, 0.375, 0.375), atol=2e-3)
    assert np.allclose(rough[0, 0, 0], 0.4, atol=2e-3)          # ramp at 0.5 (128/255) of 0.2 .. 0.6
    assert sd.materials[0]["roughness"] == 1.0


def test_everything_ignored_is_named_in_a_warning(scene):
    floor, wall = room(scene)
    w = bpy.data.worlds.new("Sky")
    w.use_nodes = True
    w.node_tree.nodes["Background"].inputs["Strength"].default_value = 2.0
    scene.world = w
    wall.visible_diffuse = False
    coll = bpy.data.collections.new("Held")
    scene.collection.children.link(coll)
    coll.objects.link(plane("Matte", 1.0, (0, 1, 0.5)))
    bpy.context.view_layer.layer_collection.children["Held"].holdout = True
    glass = principled("Glassy", Alpha=0.5)
    nt = glass.node_tree
    nm = nt.nodes.new("ShaderNodeNormalMap")
    nt.links.new(nm.outputs["Normal"], nt.nodes["Principled BSDF"].inputs["Normal"])
    grp = nt.nodes.new("ShaderNodeBlackbody")          # a node the export does not evaluate
    nt.links.new(grp.outputs["Color"], nt.nodes["Principled BSDF"].inputs["Base Color"])
    link(scene, plane("Pane", 1.0, (1, 0, 1), glass))
    sd = collect(scene)
    text = "\n".join(sd.warnings)
    assert "world 'Sky'" in text
    assert "object 'Wall': ray visibility (diffuse off)" in text
    assert "collection 'Held': holdout" in text
    assert "material 'Glassy'" in text and "transparency" in text
    assert "Normal input" in text
    assert "'Base Color'" in text and "is not evaluated" in text
