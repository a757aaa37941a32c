"""VSGL Indirect: fast one-bounce diffuse + glossy indirect light as a
compositor AOV, computed by libvsgl (C) from the evaluated scene."""

bl_info = {
    "name": "VSGL Indirect Light",
    "author": "vsgl-indirect contributors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render > VSGL Indirect Light; File > Export > VSGL scene bundle",
    "description": "One-bounce indirect light (virtual spherical Gaussian lights) as a "
                   "multilayer EXR AOV wired into the compositor",
    "category": "Render",
}

if "bpy" in locals():   # script reload
    import importlib
    for _m in ("compat", "convert", "materials", "config", "checks", "exr", "export", "engine",
               "runner", "compositor", "settings", "operators", "ui", "handlers", "live", "viewport"):
        if _m in locals():
            importlib.reload(locals()[_m])

import bpy  # noqa: E402

from . import settings, operators, ui, handlers, viewport  # noqa: E402

_modules = (settings, operators, ui, handlers, viewport)


def register():
    for m in _modules:
        m.register()
    # The pip bpy 4.2 LTS module segfaults at exit (status 139, after every
    # render) while any of our functions is still stored in Blender (a
    # handler, a registered class's callbacks): unregister before it exits.
    import atexit
    atexit.unregister(_unregister_at_exit)
    atexit.register(_unregister_at_exit)
    from . import engine
    ok, msg = engine.library_status()
    if not ok:
        # Still usable (settings, UI); every render reports the same message.
        print("VSGL WARNING: %s" % msg)


def unregister():
    import atexit
    atexit.unregister(_unregister_at_exit)
    for m in reversed(_modules):
        m.unregister()


def _unregister_at_exit():
    try:
        if "vsgl_indirect" in bpy.types.Scene.bl_rna.properties:
            unregister()
    except Exception:  # never turn a clean exit into a failure
        pass
