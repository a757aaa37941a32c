"""Compositor wiring: one Image node per view layer reading this frame's
multilayer EXR, optionally an Add node putting its ``Combined`` onto the
render. Idempotent: nodes are found again by name, never duplicated.
3.x/4.x use ``scene.node_tree``; 5.0+ the scene's compositing node group
(see compat.py).
"""
import os

import bpy

from . import compat, engine

IMAGE_NODE = "VSGL Indirect [%s]"
ADD_NODE = "VSGL Add [%s]"
IMAGE_NAME = "VSGL %s %s"   # scene, view layer
FIRST_FRAME = -500000
DURATION = 1048574


def image_node_name(view_layer):
    return IMAGE_NODE % view_layer


def add_node_name(view_layer):
    return ADD_NODE % view_layer


def placeholder(path, width, height, exclusive=False):
    """Write a black EXR with every pass so the Image node gets its sockets
    before the real file exists. ``exclusive``: never replace an existing
    file (another process may have written that frame's real AOV
    meanwhile): returns the placeholder's inode (for
    ``handlers.remove_if_inode``), or None if a file was there."""
    import numpy as np
    z = np.zeros((max(height, 1), max(width, 1), 3), np.float32)
    planes = {p: z for p in engine.PASS_NAMES}
    planes["alpha"] = np.zeros(z.shape[:2], np.float32)
    from .config import Options
    if not exclusive:
        engine.write_exr(path, planes, Options())
        return True
    d, name = os.path.split(path)
    tmp = os.path.join(d, ".%s.setup-%d" % (name, os.getpid()))
    engine.write_exr(tmp, planes, Options())
    try:
        os.link(tmp, path)      # atomic, fails if the file exists
        return os.stat(tmp).st_ino
    except FileExistsError:
        return None
    finally:
        os.unlink(tmp)


def _combined_socket(node):
    for name in ("Combined", "Image"):
        s = node.outputs.get(name)
        if s is not None and s.enabled:
            return s
    return None


def _render_layers_node(tree, scene, view_layer):
    for n in tree.nodes:
        if n.bl_idname == "CompositorNodeRLayers" and n.layer == view_layer and \
                (n.scene is None or n.scene == scene):
            return n
    n = tree.nodes.new("CompositorNodeRLayers")
    n.scene = scene
    n.layer = view_layer
    return n


def has_passes(node, add_to_render=True):
    """The Image node shows the AOV's passes (and, with ``add_to_render``,
    its Combined output feeds our Add node)."""
    if node is None or "DiffInd" not in node.outputs or not node.outputs["DiffInd"].enabled:
        return False
    src = _combined_socket(node)
    if src is None or src.name != "Combined":
        return False
    if not add_to_render:
        return True
    return any(l.to_node.name.startswith("VSGL Add [") for l in src.links)


def ensure(scene, view_layer, path, add_to_render=True):
    """Set up (or update) the nodes for ``view_layer`` to read the sequence
    ``path`` belongs to (any frame's file) and return the Image node.
    ``path`` must exist (see :func:`placeholder`) so Blender creates the pass
    sockets. Call it before a render starts (render_init, file load, settings
    change), never from render_pre: changing the node tree there stops Blender
    3.4 from calling frame_change_post for the following frames of ``-a``."""
    tree = compat.compositor_tree(scene, create=True)
    name = IMAGE_NAME % (scene.name, view_layer)
    img = bpy.data.images.get(name)
    if img is None:
        img = bpy.data.images.load(path, check_existing=False)
        img.name = name
    if os.path.normpath(bpy.path.abspath(img.filepath)) != os.path.normpath(path):
        img.filepath = path
    if img.source != "SEQUENCE":
        img.source = "SEQUENCE"

    node = tree.nodes.get(image_node_name(view_layer))
    if node is None:
        node = tree.nodes.new("CompositorNodeImage")
        node.name = image_node_name(view_layer)
        node.label = "VSGL indirect (%s)" % view_layer
        node.location = (-300, -400 - 300 * len([n for n in tree.nodes
                                                 if n.name.startswith("VSGL Indirect")]))
    # File number = scene frame for every frame in [FIRST, FIRST + DURATION):
    # Blender reads clamp(frame - start + 1, 0, duration) + offset. Static, so
    # nothing changes in the tree while frames render.
    if node.frame_start != FIRST_FRAME:
        node.frame_start = FIRST_FRAME
    if node.frame_duration != DURATION:
        node.frame_duration = DURATION
    if node.frame_offset != FIRST_FRAME - 1:
        node.frame_offset = FIRST_FRAME - 1
    if not node.use_auto_refresh:
        node.use_auto_refresh = True
    if node.image != img or _combined_socket(node) is None or "DiffInd" not in node.outputs:
        img.reload()        # a failed read (a file that vanished meanwhile) is cached
        node.image = None
        node.image = img
    if hasattr(node, "layer") and node.has_layers:
        try:
            node.layer = engine.LAYER
        except TypeError:
            pass

    add = tree.nodes.get(add_node_name(view_layer))
    if add_to_render:
        src = _combined_socket(node)
        if src is None:
            raise engine.AovError("compositor: the Image node '%s' shows no Combined pass for "
                                  "'%s'" % (node.name, path))
        out = compat.compositor_output_socket(tree)
        if add is None:
            rl = _render_layers_node(tree, scene, view_layer)
            # What currently reaches the output (the beauty chain), else the render layer.
            beauty = out.links[0].from_socket if out.is_linked else rl.outputs["Image"]
            add, a, b, res = compat.new_add_node(tree)
            add.name = add_node_name(view_layer)
            add.label = "Add VSGL indirect (%s)" % view_layer
            add.location = (out.node.location.x - 200, out.node.location.y - 150)
            tree.links.new(beauty, a)
            tree.links.new(res, out)
        a, b, res = compat.add_node_sockets(add)
        if not b.is_linked or b.links[0].from_socket != src:
            tree.links.new(src, b)
        if not out.is_linked or out.links[0].from_node != add:
            # Something was plugged into the output after us: add onto it.
            if out.is_linked and out.links[0].from_node != add:
                tree.links.new(out.links[0].from_socket, a)
            tree.links.new(res, out)
    elif add is not None:
        remove_add(tree, add)
    return node


def remove_add(tree, add):
    """Remove our Add node, reconnecting what fed its A input to its outputs."""
    a, b, res = compat.add_node_sockets(add)
    src = a.links[0].from_socket if a.is_linked else None
    targets = [l.to_socket for l in res.links]
    tree.nodes.remove(add)
    if src is not None:
        for t in targets:
            tree.links.new(src, t)


def remove(scene):
    """Remove every node and image this add-on created for ``scene``."""
    tree = compat.compositor_tree(scene, create=False)
    if tree is None:
        return
    for n in list(tree.nodes):
        if n.name.startswith("VSGL Add ["):
            remove_add(tree, n)
    for n in list(tree.nodes):
        if n.name.startswith("VSGL Indirect ["):
            tree.nodes.remove(n)
    for img in list(bpy.data.images):
        if img.name.startswith("VSGL %s " % scene.name) and img.users == 0:
            bpy.data.images.remove(img)
