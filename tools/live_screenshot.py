"""Drive the live viewport preview in Blender's real UI and screenshot it.

    blender -b --factory-startup --python tools/live_screenshot.py -- OUT_DIR
    xvfb-run -s "-screen 0 1280x800x24" blender OUT_DIR/live.blend \
        --python tools/live_screenshot.py -- OUT_DIR

(tools/live_screenshot.sh runs both.) The first builds a small room and
saves it (a file given on the command line spares the splash screen); the
second opens the UI on it, turns the live
indirect light on in the 3D viewport (looking through the scene camera),
edits the light twice and a material once, orbits the view once, then
keeps orbiting it (the coarse image drawn while the view moves) and lets
it rest (the full image). After each step writes OUT_DIR/live_N.png once
its image has been drawn, and one line of timings to OUT_DIR/live.txt
(times from the script's edit; "TIMEOUT" in the line if no image newer
than the edit came within 60 s). Exits Blender when done (exit status 1 if
no image was drawn or a step timed out).
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
TIMEOUT_S = 60.0
#: what the viewport last drew (drawn()): the screenshot shows that frame,
#: and its line in live.txt that image's times
DRAWN = {"serial": -1}
STATE = {"t_edit": 0.0, "timed_out": False, "timeouts": 0}


def step(fn):
    STEPS.append(fn)
    return fn


def watch(s):
    """Time stamps on every image of session ``s``: when its render was
    submitted (t_submit) and when the worker finished it (t_done)."""
    submit = s.renderer.submit

    def timed_submit(key, work, interruptible=True):
        def timed(job):
            out = work(job)
            if out is not None:
                out["t_submit"], out["t_done"] = job.t_submit, time.perf_counter()
            return out
        return submit(key, timed, interruptible)
    s.renderer.submit = timed_submit


def drawn():
    """POST_PIXEL draw handler (added after the add-on's): what was drawn, when."""
    from vsgl_indirect import viewport
    s = viewport.session()
    if s is not None and s.image is not None and DRAWN["serial"] != s.image_serial:
        DRAWN.update(serial=s.image_serial, image=s.image, timings=dict(s.timings), seen=s.last_done,
                     drawn=time.perf_counter(), message=s.message)


def settled(s, d, t_edit):
    """The full image of everything up to the edit has been drawn."""
    return (not s.renderer.busy() and s.dirty_since is None and d["serial"] == s.image_serial
            and d["image"].get("t_submit", -1) >= t_edit and d["image"].get("coarse", 1) == 1)


def settle_then(next_index, t_edit, until):
    """Wait until ``until(session, DRAWN, t_edit)`` (at most TIMEOUT_S)."""
    from vsgl_indirect import viewport

    def wait():
        s = viewport.session()
        if s is None:
            return None
        if not (DRAWN["serial"] >= 0 and until(s, DRAWN, t_edit)):
            if time.perf_counter() - t_edit > TIMEOUT_S:
                STATE["timed_out"] = True
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


def log_step(i, s, d, t_edit):
    """One line of live.txt about the image drawn (``d``): its times from the
    script's edit ``t_edit`` (taken just before the edit), not from the
    session's last_edit, which the add-on moves on to every later view
    change or depsgraph update it sees."""
    t, img = d["timings"], d["image"]
    line = ("step %d: %s  %s%d x %d%s, edit->image %.0f ms (render %.0f, scene %.0f, export %.0f, encode %.0f)"
            % (i, STEPS[i - 1].__doc__, "TIMEOUT (%.0f s): " % TIMEOUT_S if STATE["timed_out"] else "",
               img["width"], img["height"], " coarse" if img.get("coarse", 1) > 1 else "",
               1000 * (d["seen"] - t_edit), 1000 * t["render"], 1000 * t["scene"], 1000 * t["export"],
               1000 * t["encode"]))
    if d["message"]:
        line += " " + d["message"]
    line += (" [renders %d (coarse %d), depsgraph updates %d; edit->submit %.0f ms, submit->done %.0f ms, "
             "done->seen %.0f ms, seen->drawn %.0f ms]"
             % (s.submits, s.coarse_submits, s.updates, 1000 * (img["t_submit"] - t_edit),
                1000 * (img["t_done"] - img["t_submit"]), 1000 * (d["seen"] - img["t_done"]),
                1000 * (d["drawn"] - d["seen"])))
    LOG.append(line)


def run(i):
    from vsgl_indirect import viewport
    s = viewport.session()
    if i > 0:
        shot("live_%d.png" % i)
        if s is not None and DRAWN["serial"] >= 0:
            log_step(i, s, DRAWN, STATE["t_edit"])
        else:
            LOG.append("step %d: %s  no image drawn%s" % (i, STEPS[i - 1].__doc__, " " + s.message if s else ""))
        STATE["timeouts"] += STATE["timed_out"]
        STATE["timed_out"] = False
    if i == len(STEPS):
        with open(os.path.join(OUT, "live.txt"), "w") as fh:
            fh.write("\n".join(LOG) + "\n")
        ok = s is not None and DRAWN["serial"] >= 0 and not STATE["timeouts"]
        viewport.stop()
        print("\n".join(LOG))
        os._exit(0 if ok else 1)
    # the edit's time is taken just before the edit; step 1 starts the
    # session itself, so that its first images are newer than its edit
    STATE["t_edit"] = t_edit = time.perf_counter()
    STEPS[i]()
    if i == 0:
        watch(viewport.session())
    until = getattr(STEPS[i], "until", settled)
    bpy.app.timers.register(settle_then(i + 1, t_edit, until), first_interval=0.05)
    return None


def main():
    if bpy.app.background:
        build()
        bpy.ops.wm.save_as_mainfile(filepath=os.path.join(OUT, "live.blend"))
        return
    vsgl_indirect.register()
    light = bpy.data.objects["Spot"]
    cam = bpy.data.objects["Cam"]
    area = view3d()
    space = area.spaces.active
    rv3d = space.region_3d
    rv3d.view_perspective = "CAMERA"
    space.shading.type = "SOLID"
    space.overlay.show_overlays = False
    from vsgl_indirect import viewport
    props = bpy.context.window_manager.vsgl_live
    props.scale = 2
    props.coarse = 2      # the default "Divider While Moving", explicitly
    bpy.types.SpaceView3D.draw_handler_add(drawn, (), "WINDOW", "POST_PIXEL")
    from mathutils import Euler, Vector

    def orbit(angle):
        """Turn the free view about the world Z axis through its pivot."""
        rv3d.view_rotation.rotate(Euler((0, 0, angle)))

    @step
    def first():
        """live preview on"""
        viewport.start(area)

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
        # a free view from the camera's place, pivoting on the room's centre,
        # turned 0.3 rad about the vertical
        rv3d.view_perspective = "PERSP"
        pivot = Vector((0.0, 0.0, 1.5))
        rv3d.view_rotation = cam.matrix_world.to_quaternion()
        rv3d.view_location = pivot
        rv3d.view_distance = (cam.matrix_world.translation - pivot).length
        orbit(0.3)

    ORBIT = {"on": False}

    def orbit_tick():
        if not ORBIT["on"]:
            return None
        orbit(-0.01)
        return 0.02

    @step
    def moving():
        """view orbiting (coarse image while it moves)"""
        ORBIT["on"] = True
        bpy.app.timers.register(orbit_tick, first_interval=0.0)

    # shot while the view still moves: a coarse image newer than the step
    moving.until = lambda s, d, t_edit: (d["image"].get("coarse", 1) > 1
                                         and d["image"].get("t_submit", -1) >= t_edit)

    @step
    def rest():
        """view at rest again (the full image follows)"""
        ORBIT["on"] = False

    bpy.app.timers.register(lambda: run(0), first_interval=1.0)


main()
