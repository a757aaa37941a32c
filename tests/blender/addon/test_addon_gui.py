"""The add-on in Blender's real UI (Xvfb, software OpenGL): the panels draw,
the double-count fix works from the panel, Preview opens an Image Editor when
none is open and a second Preview reuses it with its layer/pass menus
(tools/panel_screenshots.py prints one line per check). Only inside the
Blender binary (the pip module has no windows) and where xvfb-run exists."""
import os
import shutil
import subprocess

import pytest

from conftest import IS_BINARY, REPO


@pytest.mark.skipif(not IS_BINARY, reason="the pip bpy module has no UI")
@pytest.mark.skipif(shutil.which("xvfb-run") is None, reason="needs xvfb-run (apt: xvfb)")
def test_panels_preview_and_editor_in_the_real_ui(tmp_path):
    import bpy
    env = dict(os.environ, BLENDER=bpy.app.binary_path)
    r = subprocess.run([os.path.join(REPO, "tools", "panel_screenshots.sh"), str(tmp_path)],
                       env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True, timeout=300)
    lines = [l for l in r.stdout.splitlines() if l.startswith("VSGL-UI")]
    assert "VSGL-UI done all ok" in lines, r.stdout[-4000:]
    for what in ("preview shown in an image editor", "second preview reuses the editor",
                 "second preview keeps the passes", "no second editor opened",
                 "double counting shown", "direct light only", "compositor setup"):
        assert "VSGL-UI ok %s" % what in lines, (what, lines)
    for name in ("panel.png", "panel_off.png", "compositor.png", "preview.png"):
        assert os.path.getsize(str(tmp_path / name)) > 10000, name
