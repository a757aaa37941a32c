"""Extra script for a render process: its own beauty output folder
($VSGL_TEST_OUT), as separate farm workers would write their frames."""
import os

import bpy

bpy.context.scene.render.filepath = os.environ["VSGL_TEST_OUT"]
