"""Cycles one-bounce reference of the demo scene (run inside Blender on
out/demo/demo.blend): max_bounces 1 (diffuse and glossy 1), no clamps, no
blur, fixed seed, no denoising, SPP samples; no compositor (the add-on is
not enabled here). Writes //reference.exr, a multilayer EXR with
Combined, DiffInd, DiffCol, GlossInd and GlossCol.

    blender -b out/demo/demo.blend --python tools/demo_reference.py -- SPP
"""
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "blender"))
from cycles_ref import one_bounce  # noqa: E402  (the test references' one-bounce settings)

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
spp = int(argv[0]) if argv else 32
sc = bpy.context.scene
one_bounce(sc.cycles, spp, 0)
vl = sc.view_layers[0]
for flag in ("use_pass_diffuse_indirect", "use_pass_diffuse_color", "use_pass_glossy_indirect",
             "use_pass_glossy_color"):
    setattr(vl, flag, True)
sc.use_nodes = False
s = sc.render.image_settings
s.file_format = "OPEN_EXR_MULTILAYER"
s.color_depth = "32"
s.exr_codec = "ZIP"
sc.render.filepath = "//reference"
sc.frame_set(1)
bpy.ops.render.render(write_still=True)
