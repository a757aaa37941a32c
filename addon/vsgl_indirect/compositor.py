"""Compositor wiring: one Image node per view layer reading this frame's
multilayer EXR, optionally an Add node putting its ``Combined`` onto the
render. Idempotent: nodes are found again by name, never duplicated.
3.x/4.x use ``scene.node_tree``; 5.0+ the scene's compositing node group
(see compat.py).
"""
import os

import bpy

from . import compat, cycles_colors, engine

IMAGE_NODE = "VSGL Indirect [%s]"
ADD_NODE = "VSGL Add [%s]"          # before issue 15 (one Add of Combined): replaced on setup
ADD_NODES = "VSGL Add %s [%s]"      # kind (Diffuse, Glossy), view layer
FRAME_NODE = "VSGL Frame"
RLAYERS_NODE = "VSGL Render Layers [%s]"   # only for a view layer the tree has none for
FILE_OUTPUT_NODE = "VSGL Passes Output"
IMAGE_NAME = "VSGL %s %s"   # scene, view layer
FIRST_FRAME = -500000
DURATION = 1048574


def image_node_name(view_layer):
    return IMAGE_NODE % view_layer


def placeholder(path, width, height, exclusive=False, options=None):
    """Write a black EXR with the passes a render with ``options`` (default:
    the defaults) writes, so the Image node gets its sockets before the real
    file exists. ``exclusive``: never replace an existing
    file (another process may have written that frame's real AOV
    meanwhile): returns the placeholder's inode (for
    ``handlers.remove_if_inode``), or None if a file was there."""
    import numpy as np
    z = np.zeros((max(height, 1), max(width, 1), 3), np.float32)
    planes = {p: z for p in engine.PASS_NAMES}
    planes["alpha"] = np.zeros(z.shape[:2], np.float32)
    from .config import Options
    options = options or Options()
    if not exclusive:
        engine.write_exr(path, planes, options)
        return True
    d, name = os.path.split(path)
    tmp = os.path.join(d, ".%s.setup-%d" % (name, os.getpid()))
    engine.write_exr(tmp, planes, options)
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


def _render_layers_node(tree, scene, view_layer, ours=False):
    for n in tree.nodes:
        if n.bl_idname == "CompositorNodeRLayers" and n.layer == view_layer and \
                (n.scene is None or n.scene == scene):
            return n
    n = tree.nodes.new("CompositorNodeRLayers")
    n.scene = scene
    n.layer = view_layer
    if ours:
        # Only the passes file reads it: ours (in the frame, removed with it).
        # One feeding the composite stays the user's (removing it would
        # leave the output unlinked).
        n.name = RLAYERS_NODE % view_layer
        n.label = "Render Layers %s (for VSGL)" % view_layer
        frame = tree.nodes.get(FRAME_NODE)
        if frame is not None:
            n.parent = frame
    return n


def _ours(node):
    return node.name.startswith("VSGL ")


def has_passes(node, add_to_render=True):
    """The Image node shows the AOV's passes (and, with ``add_to_render``,
    its Diff output feeds our Add node)."""
    if node is None or "DiffInd" not in node.outputs or not node.outputs["DiffInd"].enabled:
        return False
    src = _combined_socket(node)
    if src is None or src.name != "Combined":
        return False
    if not add_to_render:
        return True
    diff = node.outputs.get("Diff")
    if diff is not None and any(l.to_node.name.startswith("VSGL Add") for l in diff.links):
        return True
    # "Cycles Colours" (cycles_colors.py): DiffInd feeds its Multiply node instead
    light = node.outputs.get("DiffInd")
    return any(l.to_node.name.startswith("VSGL Cycles Colours") for l in light.links)


# --- layout: our nodes in one labelled Frame beside the user's tree -----------

FRAME_LABEL = "VSGL Indirect Light (add-on; Render Properties > VSGL Indirect Light)"
NODE_W, NODE_H = 240.0, 320.0     # node size estimates (dimensions are 0 until drawn)


def _bounds(nodes):
    """(xmin, ymin, xmax, ymax) of ``nodes`` in the editor's coordinates."""
    xs, ys = [], []
    for n in nodes:
        x, y = _absolute(n)
        w = n.width or NODE_W
        h = n.dimensions[1] if n.dimensions[1] > 0 else NODE_H
        xs += [x, x + w]
        ys += [y - h, y]
    return (min(xs), min(ys), max(xs), max(ys)) if xs else (0.0, 0.0, 0.0, 0.0)


def _absolute(node):
    if hasattr(node, "location_absolute"):
        return tuple(node.location_absolute)
    x, y = node.location
    p = node.parent
    while p is not None:            # 3.x/4.x: a child's location is its frame's offset
        x, y = x + p.location[0], y + p.location[1]
        p = p.parent
    return x, y


def _place(node, frame, x, y):
    """Put ``node`` in ``frame`` at absolute (x, y)."""
    if node.parent != frame:
        node.parent = frame
    if hasattr(node, "location_absolute"):
        node.location_absolute = (x, y)
    else:
        node.location = (x - frame.location[0], y - frame.location[1])


def _frame(tree):
    frame = tree.nodes.get(FRAME_NODE)
    if frame is None:
        frame = tree.nodes.new("NodeFrame")
        frame.name = FRAME_NODE
        frame.label = FRAME_LABEL
        frame.label_size = 14
        frame.shrink = True
        frame.use_custom_color = True
        frame.color = (0.22, 0.27, 0.33)
        others = [n for n in tree.nodes if not _ours(n) and n.bl_idname != "NodeFrame"]
        x0, y0, x1, y1 = _bounds(others)
        # Below the user's tree, left-aligned with it: beside, never over it.
        frame.location = (x0, y0 - 120.0)
    return frame


def _layout(tree, frame):
    """Image nodes in a column at the frame's left, the Add nodes of each
    layer to their right, the File Output node after them."""
    fx, fy = _absolute(frame)
    images = sorted((n for n in tree.nodes if n.name.startswith("VSGL Indirect [")),
                    key=lambda n: n.name)
    for i, img in enumerate(images):
        layer = img.name[len("VSGL Indirect ["):-1]
        y = fy - 40.0 - i * (NODE_H + 60.0)
        _place(img, frame, fx + 20.0, y)
        for j, name in enumerate((add_node_name(layer, "Diffuse"), add_node_name(layer, "Glossy"))):
            n = tree.nodes.get(name)
            if n is not None:
                _place(n, frame, fx + 20.0 + NODE_W + 60.0 + j * 200.0, y - 20.0)
    out = tree.nodes.get(FILE_OUTPUT_NODE)
    if out is not None:
        _place(out, frame, fx + 20.0 + NODE_W + 480.0, fy - 40.0)
    rls = sorted((n for n in tree.nodes if n.name.startswith("VSGL Render Layers [")),
                 key=lambda n: n.name)
    for i, rl in enumerate(rls):
        _place(rl, frame, fx + 20.0 + i * (NODE_W + 40.0),
               fy - 40.0 - len(images) * (NODE_H + 60.0))


def ensure(scene, view_layer, path, add_to_render=True, options=None):
    """Set up (or update) the nodes for ``view_layer`` to read the sequence
    ``path`` belongs to (any frame's file) and return the Image node.
    ``path`` must exist (see :func:`placeholder`) so Blender creates the pass
    sockets. Call it before a render starts (render_init, file load, settings
    change), never from render_pre: changing the node tree there stops Blender
    3.4 from calling frame_change_post for the following frames of ``-a``.

    Added onto the render: Diff and Gloss, each through an Add node whose
    factor is ``options.strength`` (0 for a pass switched off):
    render + strength * (Diff + Gloss) = render + strength * Combined."""
    from .config import Options
    options = options or Options()
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

    frame = _frame(tree)
    node = tree.nodes.get(image_node_name(view_layer))
    if node is None:
        node = tree.nodes.new("CompositorNodeImage")
        node.name = image_node_name(view_layer)
    # File number = scene frame for every frame in [FIRST, FIRST + DURATION):
    # Blender reads clamp(frame - start + 1, 0, duration) + offset. Static, so
    # nothing changes in the tree while frames render. The node's options
    # (which would show these numbers) are hidden; the label says it.
    label = "VSGL AOV %s (file number = frame)" % view_layer
    if node.label != label:
        node.label = label
    if node.frame_start != FIRST_FRAME:
        node.frame_start = FIRST_FRAME
    if node.frame_duration != DURATION:
        node.frame_duration = DURATION
    if node.frame_offset != FIRST_FRAME - 1:
        node.frame_offset = FIRST_FRAME - 1
    if not node.use_auto_refresh:
        node.use_auto_refresh = True
    if node.show_options:
        node.show_options = False
    if node.image != img or _combined_socket(node) is None or "DiffInd" not in node.outputs:
        img.reload()        # a failed read (a file that vanished meanwhile) is cached
        node.image = None
        node.image = img
    if hasattr(node, "layer") and node.has_layers:
        try:
            node.layer = engine.LAYER
        except TypeError:
            pass

    old = tree.nodes.get(ADD_NODE % view_layer)      # before issue 15: one Add of Combined
    if old is not None:
        remove_add(tree, old)
    adds = [tree.nodes.get(add_node_name(view_layer, k)) for k in ("Diffuse", "Glossy")]
    if add_to_render:
        srcs = [node.outputs.get("Diff"), node.outputs.get("Gloss")]
        if _combined_socket(node) is None or None in srcs:
            raise engine.AovError("compositor: the Image node '%s' shows no Diff/Gloss passes "
                                  "for '%s'" % (node.name, path))
        if getattr(options, "use_cycles_colors", False):    # issue 13: cycles_colors.py
            try:
                srcs = cycles_colors.sources(tree, scene, view_layer, node,
                                             _render_layers_node(tree, scene, view_layer))
            except RuntimeError as e:
                raise engine.AovError(str(e))
        else:
            cycles_colors.remove(tree, view_layer)
        out = compat.compositor_output_socket(tree)
        if None in adds:
            for a in adds:
                if a is not None:
                    remove_add(tree, a)
            rl = _render_layers_node(tree, scene, view_layer)
            # What currently reaches the output (the beauty chain), else the render layer.
            beauty = out.links[0].from_socket if out.is_linked else rl.outputs["Image"]
            adds = []
            for kind in ("Diffuse", "Glossy"):
                add, a, b, res = compat.new_add_node(tree)
                add.name = add_node_name(view_layer, kind)
                tree.links.new(beauty, a)
                beauty = res
                adds.append(add)
            tree.links.new(beauty, out)
        last_res = compat.add_node_sockets(adds[1])[2]
        for add, src in zip(adds, srcs):
            a, b, res = compat.add_node_sockets(add)
            if not b.is_linked or b.links[0].from_socket != src:
                tree.links.new(src, b)
        _grade(adds, options)
        if not out.is_linked or out.links[0].from_node != adds[1]:
            # Something was plugged into the output after us: add onto it.
            if out.is_linked and out.links[0].from_node != adds[1]:
                tree.links.new(out.links[0].from_socket, compat.add_node_sockets(adds[0])[0])
            tree.links.new(last_res, out)
    else:
        for a in adds:
            if a is not None:
                remove_add(tree, a)
    for n in [node] + [a for a in adds if a is not None and a.name in tree.nodes] + \
            cycles_colors.nodes(tree, view_layer):
        if n.parent != frame:
            n.parent = frame
    _layout(tree, frame)
    return node


# --- AOV export: the render's passes + the VSGL passes in one EXR per frame --

#: Render Layers socket names (5.0 spells them out) -> Blender's pass names
#: in a multilayer EXR (what its own render output and Cycles call them).
PASS_NAMES = {
    "Image": "Combined", "Diffuse Direct": "DiffDir", "Diffuse Indirect": "DiffInd",
    "Diffuse Color": "DiffCol", "Glossy Direct": "GlossDir", "Glossy Indirect": "GlossInd",
    "Glossy Color": "GlossCol", "Transmission Direct": "TransDir",
    "Transmission Indirect": "TransInd", "Transmission Color": "TransCol",
    "Volume Direct": "VolumeDir", "Volume Indirect": "VolumeInd", "Emission": "Emit",
    "Environment": "Env", "Ambient Occlusion": "AO", "Depth": "Depth", "Normal": "Normal",
    "Position": "Position", "Vector": "Vector", "UV": "UV", "Mist": "Mist",
    "Shadow Catcher": "Shadow Catcher", "Object Index": "IndexOB", "Material Index": "IndexMA",
}
#: The VSGL passes' names in that file: <view layer>.VSGL_<pass>.
VSGL_PASSES = ("DiffInd", "GlossInd", "DiffCol", "GlossCol", "Diff", "Gloss", "Combined")


def export_slots(tree, scene, layers):
    """[(slot name, source socket)] of the passes file: per rendered view
    layer its render passes (Blender's names, ``ViewLayer.DiffDir``), the
    VSGL passes (``ViewLayer.VSGL_DiffInd``, ...), then ``Composite``, the
    composited image (render + AOV)."""
    slots = []
    for layer in layers:
        rl = _render_layers_node(tree, scene, layer, ours=True)
        for o in rl.outputs:
            if not o.enabled or o.name in ("Alpha", "Noisy Image") or o.name.startswith("Denoising"):
                continue
            slots.append(("%s.%s" % (layer, PASS_NAMES.get(o.name, o.name.replace(" ", ""))), o))
        img = tree.nodes.get(image_node_name(layer))
        if img is not None:
            for p in VSGL_PASSES:
                o = img.outputs.get(p)
                if o is not None and o.enabled:
                    slots.append(("%s.VSGL_%s" % (layer, p), o))
    out = compat.compositor_output_socket(tree)
    if out.is_linked:
        slots.append(("Composite", out.links[0].from_socket))
    return slots


def ensure_export(scene, layers, prefix, options):
    """Create/update the File Output node writing one multilayer EXR per
    frame (``prefix`` + frame number + .exr) with :func:`export_slots`, or
    remove it when ``options.export_passes`` is off."""
    tree = compat.compositor_tree(scene, create=True)
    node = tree.nodes.get(FILE_OUTPUT_NODE)
    if not options.export_passes:
        if node is not None:
            tree.nodes.remove(node)
        return None
    if node is None:
        node = tree.nodes.new("CompositorNodeOutputFile")
        node.name = FILE_OUTPUT_NODE
        node.label = "VSGL + render passes (one EXR per frame)"
        node.width = 260
    fmt = node.format
    if fmt.file_format != "OPEN_EXR_MULTILAYER":
        fmt.file_format = "OPEN_EXR_MULTILAYER"
    depth = "16" if options.half_float else "32"
    if fmt.color_depth != depth:
        fmt.color_depth = depth
    if fmt.exr_codec != "ZIP":
        fmt.exr_codec = "ZIP"
    compat.file_output_set_path(node, prefix)
    slots = export_slots(tree, scene, layers)
    have = compat.file_output_names(node)
    if have != [n for n, _ in slots]:
        compat.file_output_set_names(node, [(n, src.type) for n, src in slots])
    inputs = [i for i in node.inputs if i.enabled and i.name]
    for (name, src), sock in zip(slots, inputs):
        if not sock.is_linked or sock.links[0].from_socket != src:
            tree.links.new(src, sock)
    frame = tree.nodes.get(FRAME_NODE)
    if frame is not None and node.parent != frame:
        node.parent = frame
    if frame is not None:
        _layout(tree, frame)
    return node


def _grade(adds, options):
    """Strength and the per-pass switches: the Add nodes' factors and labels."""
    for add, kind, on in zip(adds, ("Diffuse", "Glossy"), (options.use_diffuse, options.use_glossy)):
        compat.set_add_factor(add, float(options.strength) if on else 0.0)
        label = "Add VSGL %s x %.3g%s" % (kind.lower(), options.strength, "" if on else " (off)")
        if add.label != label:
            add.label = label


def update_grading(scene, options):
    """Apply Strength and the Diffuse/Glossy switches to the Add nodes that
    exist (a slider drag must not redo the whole setup). False if there are
    none (the caller then sets everything up)."""
    tree = compat.compositor_tree(scene, create=False)
    if tree is None:
        return False
    found = False
    for n in tree.nodes:
        if n.name.startswith("VSGL Add Diffuse ["):
            layer = n.name[len("VSGL Add Diffuse ["):-1]
            gloss = tree.nodes.get(add_node_name(layer, "Glossy"))
            if gloss is not None:
                _grade([n, gloss], options)
                found = True
    return found


def add_node_name(view_layer, kind):
    return ADD_NODES % (kind, view_layer)


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
        if n.name.startswith("VSGL Add"):
            remove_add(tree, n)
    for n in list(tree.nodes):
        if n.name.startswith(("VSGL Indirect [", "VSGL Render Layers [", "VSGL Cycles Colours ")) or \
                n.name in (FILE_OUTPUT_NODE, FRAME_NODE):
            tree.nodes.remove(n)
    for img in list(bpy.data.images):
        if img.name.startswith("VSGL %s " % scene.name) and img.users == 0:
            bpy.data.images.remove(img)
