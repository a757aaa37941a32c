"""Used by test_extension_zip_install: python3 ext_install_render.py ZIP BLEND
(with BLENDER_USER_RESOURCES set): install the zip as a 4.2+ extension,
open BLEND, render frame 1, print the library path."""
import sys

import bpy

zip_path, blend = sys.argv[1], sys.argv[2]
print("install", bpy.ops.extensions.package_install_files(
    filepath=zip_path, repo="user_default", enable_on_install=True))
bpy.ops.wm.open_mainfile(filepath=blend)
mod = sys.modules["bl_ext.user_default.vsgl_indirect.engine"]
print("STATUS", mod.library_status())
scene = bpy.context.scene
scene.frame_start = scene.frame_end = 1
bpy.ops.render.render(animation=True)
