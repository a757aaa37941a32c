"""Compositor option "Cycles Colours": the library's light-only passes times
Cycles' own colour passes of the same render.

Cycles computes DiffCol and GlossCol for every pixel from the full node
graph (any texture, any node), so ``DiffInd x DiffCol(Cycles) + GlossInd x
GlossCol(Cycles)`` is the indirect light with exact receiver colours; the
AOV's own Diff / Gloss use the library's colours (textures it evaluates,
a documented fallback for the rest). The two differ only where the export
approximated a material (docs/addon.md, "Textures").

Builds two Multiply nodes per view layer and returns their outputs for the
Add nodes of compositor.ensure() (which calls :func:`sources` when
``Options.use_cycles_colors`` is set, :func:`remove` otherwise).
"""

from . import compat

MULTIPLY_NODE = "VSGL Cycles Colours %s [%s]"   # kind (Diffuse, Glossy), view layer
#: (kind, VSGL light pass, Render Layers colour socket names (3.x/4.x, 5.x), view layer flag)
KINDS = (("Diffuse", "DiffInd", ("DiffCol", "Diffuse Color"), "use_pass_diffuse_color"),
         ("Glossy", "GlossInd", ("GlossCol", "Glossy Color"), "use_pass_glossy_color"))


def _multiply_node(tree, name):
    node = tree.nodes.get(name)
    if node is None:
        node, a, b, res = compat.new_add_node(tree)
        node.name = name
    if node.blend_type != "MULTIPLY":
        node.blend_type = "MULTIPLY"
    compat.set_add_factor(node, 1.0)
    return node


def sources(tree, scene, view_layer, image_node, rl):
    """[diffuse, glossy] sockets: VSGL DiffInd x Cycles DiffCol, VSGL GlossInd x
    Cycles GlossCol (``rl``: the view layer's Render Layers node). Turns the
    view layer's colour passes on."""
    vl = scene.view_layers.get(view_layer)
    for _, _, _, flag in KINDS:
        if vl is not None and not getattr(vl, flag):
            setattr(vl, flag, True)
    out = []
    for kind, light, colour_names, _ in KINDS:
        node = _multiply_node(tree, MULTIPLY_NODE % (kind, view_layer))
        label = "VSGL %s x Cycles %s" % (light, colour_names[0])
        if node.label != label:
            node.label = label
        a, b, res = compat.add_node_sockets(node)
        src_light = image_node.outputs.get(light)
        src_col = next((rl.outputs.get(n) for n in colour_names if rl.outputs.get(n) is not None
                        and rl.outputs.get(n).enabled), None)
        if src_light is None or src_col is None:
            raise RuntimeError("compositor: '%s' or the render's %s pass is missing" % (light, colour_names[0]))
        if not a.is_linked or a.links[0].from_socket != src_light:
            tree.links.new(src_light, a)
        if not b.is_linked or b.links[0].from_socket != src_col:
            tree.links.new(src_col, b)
        out.append(res)
    return out


def nodes(tree, view_layer):
    return [n for n in (tree.nodes.get(MULTIPLY_NODE % (k[0], view_layer)) for k in KINDS) if n is not None]


def remove(tree, view_layer):
    for n in nodes(tree, view_layer):
        tree.nodes.remove(n)
