"""Drive the live viewport preview in Blender's real UI and screenshot it.

    blender -b --factory-startup --python tools/live_screenshot.py -- OUT_DIR
    xvfb-run -s "-screen 0 1280x800x24" blender OUT_DIR/live.blend \
        --python tools/live_screenshot.py -- OUT_DIR

(tools/live_screenshot.sh runs both.) The first builds a small room and
saves it (a file given on the command line spares the splash screen); the
second opens the UI on it, turns the live
indirect light on in the 3D viewport (looking through the scene camera),
moves the light three times and the view once, and after each settles
writes OUT_DIR/live_N.png and one line of timings to OUT_DIR/live.txt.
Exits Blender when done (exit status 1 if no image was drawn).
"""
import math
import os
import sys
import time

import bpy

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
sys.path.insert(0, os.path.join(REPO, "addon"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vsgl_indirect  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
OUT = os.path.abspath(argv[0] if argv else os.path.join(REPO, "build", "live"))
os.makedirs(OUT, exist_ok=True)


def build():
    from live_room import build_room
    return build_room(bpy.context.scene)[0]


def view3d():
    for area in bpy.context.window.screen.areas:
        if area.type == "VIEW_3D":
            return area
    raise RuntimeError("no 3D viewport in the default screen")


STEPS = []
LOG = []


def step(fn):
    STEPS.append(fn)
    return fn


def settle_then(next_index, t_edit):
    """Wait until the live session has drawn a result newer than the edit."""
    from vsgl_indirect import viewport
    s = viewport.session()

    def wait():
        if s is None:
            return None
        if s.renderer.busy() or s.dirty_since is not None or not s.timings or s.last_done < t_edit:
            if time.perf_counter() - t_edit > 60:
                LOG.append("timeout")
                return run(next_index)
            return 0.05
        return run(next_index)
    return wait


def shot(name):
    area = view3d()
    path = os.path.join(OUT, name)
    with bpy.context.temp_override(window=bpy.context.window, area=area):
        bpy.ops.screen.screenshot_area(filepath=path)
    return path


def run(i):
    from vsgl_indirect import viewport
    if i > 0:
        s = viewport.session()
        t = s.timings
        shot("live_%d.png" % i)
        LOG.append("step %d: %s  edit->image %.0f ms (render %.0f, scene %.0f, export %.0f, encode %.0f) %s"
                   % (i, STEPS[i - 1].__doc__, 1000 * (s.last_done - s.last_edit), 1000 * t["render"],
                      1000 * t["scene"], 1000 * t["export"], 1000 * t["encode"], s.message)
                   + " [renders %d (coarse %d), depsgraph updates %d; edit->submit %.0f ms, "
                     "submit->result %.0f ms, result seen %.0f ms later]"
                   % (s.submits, s.coarse_submits, s.updates, 1000 * (s.last_submit - s.last_edit),
                      1000 * t["total"], 1000 * (s.last_done - s.last_submit - t["total"])))
    if i == len(STEPS):
        with open(os.path.join(OUT, "live.txt"), "w") as fh:
            fh.write("\n".join(LOG) + "\n")
        ok = viewport.session() is not None and viewport.session().image is not None
        viewport.stop()
        print("\n".join(LOG))
        os._exit(0 if ok else 1)
    t_edit = time.perf_counter()
    viewport.session().last_edit = t_edit
    STEPS[i]()
    bpy.app.timers.register(settle_then(i + 1, t_edit), first_interval=0.05)
    return None


def main():
    if bpy.app.background:
        build()
        bpy.ops.wm.save_as_mainfile(filepath=os.path.join(OUT, "live.blend"))
        return
    vsgl_indirect.register()
    light = bpy.data.objects["Spot"]
    area = view3d()
    space = area.spaces.active
    space.region_3d.view_perspective = "CAMERA"
    space.shading.type = "SOLID"
    space.overlay.show_overlays = False
    from vsgl_indirect import viewport
    bpy.context.window_manager.vsgl_live.scale = 2
    viewport.start(area)

    @step
    def first():
        """live preview on"""

    @step
    def move1():
        """light moved 0.5 m"""
        light.location.x += 0.5

    @step
    def move2():
        """light turned 20 degrees"""
        light.rotation_euler.y += math.radians(20)

    @step
    def colour():
        """right wall colour changed"""
        bpy.data.materials["Green"].node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = \
            (0.1, 0.2, 0.8, 1)

    @step
    def view():
        """view orbited (free view)"""
        space.region_3d.view_perspective = "PERSP"
        space.region_3d.view_rotation.rotate(__import__("mathutils").Euler((0, 0, 0.3)))

    bpy.app.timers.register(lambda: run(0), first_interval=1.0)


main()
