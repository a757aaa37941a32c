"""Blender version differences in one place (3.4 ... 5.x)."""
import os

import bpy
import numpy as np

VERSION = tuple(bpy.app.version)


def corner_normals(mesh):
    """Split (corner) normals of an evaluated mesh as an (n_loops, 3) float32 array."""
    n = len(mesh.loops)
    out = np.empty(n * 3, dtype=np.float32)
    if hasattr(mesh, "corner_normals"):          # 4.1+
        mesh.corner_normals.foreach_get("vector", out)
    else:                                         # 3.x / 4.0
        mesh.calc_normals_split()
        mesh.loops.foreach_get("normal", out)
    return out.reshape(n, 3)


def light_exposure(light):
    """Light exposure in stops (Blender 4.3+; 0 before)."""
    return float(getattr(light, "exposure", 0.0))


def light_blackbody(light):
    """RGB multiplier of a light's temperature (4.5+ ``use_temperature``), else white."""
    if getattr(light, "use_temperature", False):
        return tuple(getattr(light, "temperature_color", (1.0, 1.0, 1.0)))[:3]
    return (1.0, 1.0, 1.0)


def is_holdout(obj):
    return bool(getattr(obj, "is_holdout", False))


def material_uses_nodes(mat):
    # 5.0 always uses nodes (use_nodes is deprecated there).
    if VERSION >= (5, 0, 0):
        return mat.node_tree is not None
    return bool(mat.use_nodes) and mat.node_tree is not None


def shader_output_node(tree):
    node = None
    try:
        node = tree.get_output_node("CYCLES")
    except Exception:
        node = None
    if node is None:
        for n in tree.nodes:
            if n.bl_idname == "ShaderNodeOutputMaterial" and getattr(n, "is_active_output", True):
                return n
    return node


# --- compositor -------------------------------------------------------------

HAS_NODE_GROUP_COMPOSITOR = "compositing_node_group" in bpy.types.Scene.bl_rna.properties  # 5.0+


def compositor_tree(scene, create=True):
    """The scene's compositor node tree, created (with Render Layers -> output) if asked."""
    if HAS_NODE_GROUP_COMPOSITOR:
        tree = scene.compositing_node_group
        if tree is None and create:
            tree = bpy.data.node_groups.new("%s Compositing" % scene.name, "CompositorNodeTree")
            tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
            rl = tree.nodes.new("CompositorNodeRLayers")
            rl.location = (-300, 0)
            out = tree.nodes.new("NodeGroupOutput")
            out.location = (300, 0)
            tree.links.new(rl.outputs["Image"], out.inputs[0])
            scene.compositing_node_group = tree
        return tree
    if create and not scene.use_nodes:
        scene.use_nodes = True
    return scene.node_tree


def compositor_output_socket(tree):
    """The input socket whose image becomes the render result."""
    for n in tree.nodes:
        if n.bl_idname == "CompositorNodeComposite":
            return n.inputs[0]
    for n in tree.nodes:
        if n.bl_idname == "NodeGroupOutput" and n.inputs and getattr(n, "is_active_output", True):
            return n.inputs[0]
    if HAS_NODE_GROUP_COMPOSITOR:
        if not any(i.in_out == "OUTPUT" for i in tree.interface.items_tree
                   if getattr(i, "item_type", "SOCKET") == "SOCKET"):
            tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
        out = tree.nodes.new("NodeGroupOutput")
        return out.inputs[0]
    out = tree.nodes.new("CompositorNodeComposite")
    return out.inputs[0]


def new_add_node(tree):
    """(node, input_a, input_b, output) of an RGB Add node."""
    if HAS_NODE_GROUP_COMPOSITOR or not hasattr(bpy.types, "CompositorNodeMixRGB"):
        node = tree.nodes.new("ShaderNodeMix")
        node.data_type = "RGBA"
        node.blend_type = "ADD"
        fac = [s for s in node.inputs if s.name == "Factor" and s.enabled][0]
        fac.default_value = 1.0
        a = [s for s in node.inputs if s.name == "A" and s.enabled][0]
        b = [s for s in node.inputs if s.name == "B" and s.enabled][0]
        res = [s for s in node.outputs if s.name == "Result" and s.enabled][0]
        return node, a, b, res
    node = tree.nodes.new("CompositorNodeMixRGB")
    node.blend_type = "ADD"
    node.inputs[0].default_value = 1.0
    return node, node.inputs[1], node.inputs[2], node.outputs[0]


def set_add_factor(node, value):
    """The factor of an Add node made by :func:`new_add_node` (result = A + factor * B)."""
    if node.bl_idname == "ShaderNodeMix":
        sock = [s for s in node.inputs if s.name == "Factor" and s.enabled][0]
    else:
        sock = node.inputs[0]
    if abs(sock.default_value - value) > 1e-9:
        sock.default_value = value


def add_node_sockets(node):
    """(a, b, result) sockets of an Add node made by :func:`new_add_node`."""
    if node.bl_idname == "ShaderNodeMix":
        a = [s for s in node.inputs if s.name == "A" and s.enabled][0]
        b = [s for s in node.inputs if s.name == "B" and s.enabled][0]
        res = [s for s in node.outputs if s.name == "Result" and s.enabled][0]
        return a, b, res
    return node.inputs[1], node.inputs[2], node.outputs[0]


# --- File Output node (5.0 replaced base_path/layer_slots) --------------------

def file_output_set_path(node, prefix):
    """Write to ``prefix`` + frame number + extension."""
    if hasattr(node, "file_output_items"):        # 5.0+
        d, name = os.path.split(prefix)
        if node.directory != d + os.sep:
            node.directory = d + os.sep
        if node.file_name != name:
            node.file_name = name
    elif node.base_path != prefix:
        node.base_path = prefix


def file_output_names(node):
    if hasattr(node, "file_output_items"):
        return [i.name for i in node.file_output_items]
    return [s.name for s in node.layer_slots]


_ITEM_TYPES = {"VALUE": "FLOAT", "VECTOR": "VECTOR", "RGBA": "RGBA"}


def file_output_set_names(node, slots):
    """Replace the node's inputs by one per (name, source socket type) (a
    multilayer EXR layer each; 3.x/4.x adapt the channels to what is linked)."""
    if hasattr(node, "file_output_items"):
        node.file_output_items.clear()
        for n, t in slots:
            node.file_output_items.new(_ITEM_TYPES.get(t, "RGBA"), n)
        return
    node.layer_slots.clear()
    for n, _ in slots:
        node.layer_slots.new(n)
