"""``blender -b FILE --python bootstrap_addon.py [-f N | -s A -e B -a]`` for the
pip bpy module: python3 bpy_render.py FILE N|A:B [extra scripts...]."""
import os
import runpy
import sys

import bpy

blend, spec = sys.argv[1], sys.argv[2]
bpy.ops.wm.open_mainfile(filepath=blend)
here = os.path.dirname(os.path.abspath(__file__))
runpy.run_path(os.path.join(here, "..", "bootstrap_addon.py"))
for extra in sys.argv[3:]:
    runpy.run_path(extra)
scene = bpy.context.scene
if ":" in spec:
    a, b = (int(x) for x in spec.split(":"))
else:
    a = b = int(spec)
scene.frame_start, scene.frame_end = a, b
bpy.ops.render.render(animation=True)
