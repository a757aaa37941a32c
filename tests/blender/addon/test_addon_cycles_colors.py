"""Compositor option "Cycles Colours" (cycles_colors.py, issue 13): the Add
nodes take VSGL DiffInd x Cycles DiffCol and VSGL GlossInd x Cycles
GlossCol instead of the AOV's Diff / Gloss; off again restores them."""
from conftest import room
from vsgl_indirect import compat, compositor, handlers


def _b_source(tree, kind):
    add = tree.nodes["VSGL Add %s [ViewLayer]" % kind]
    return compat.add_node_sockets(add)[1].links[0].from_node


def test_cycles_colours_multiply_light_passes_by_the_renders_colours(scene, tmp_path):
    room(scene, str(tmp_path / "aov" / "{scene}_{view_layer}_####.exr"))
    scene.render.filepath = str(tmp_path / "out" / "b_")
    tree = compat.compositor_tree(scene, create=True)
    scene.vsgl_indirect.use_cycles_colors = True
    for _ in range(2):      # idempotent
        assert handlers.setup_scene(scene) == []
    vl = scene.view_layers["ViewLayer"]
    assert vl.use_pass_diffuse_color and vl.use_pass_glossy_color
    for kind, light, colour in (("Diffuse", "DiffInd", ("DiffCol", "Diffuse Color")),
                                ("Glossy", "GlossInd", ("GlossCol", "Glossy Color"))):
        mul = _b_source(tree, kind)
        assert mul.name == "VSGL Cycles Colours %s [ViewLayer]" % kind
        assert mul.blend_type == "MULTIPLY"
        a, b, _ = compat.add_node_sockets(mul)
        assert a.links[0].from_node.name == "VSGL Indirect [ViewLayer]" and a.links[0].from_socket.name == light
        assert b.links[0].from_node.bl_idname == "CompositorNodeRLayers"
        assert b.links[0].from_socket.name in colour
        assert mul.parent == tree.nodes["VSGL Frame"]
    assert len([n for n in tree.nodes if n.name.startswith("VSGL Cycles Colours")]) == 2
    scene.vsgl_indirect.use_cycles_colors = False
    assert handlers.setup_scene(scene) == []
    assert _b_source(tree, "Diffuse").name == "VSGL Indirect [ViewLayer]"
    assert not [n for n in tree.nodes if n.name.startswith("VSGL Cycles Colours")]
    scene.vsgl_indirect.use_cycles_colors = True
    handlers.setup_scene(scene)
    compositor.remove(scene)
    assert not [n for n in tree.nodes if n.name.startswith("VSGL")]
