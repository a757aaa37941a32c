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

# The package imports nothing from Blender itself: its pure modules
# (convert, materials, textures, config, engine, live) are importable and
# tested without bpy (tests/python/test_addon_pure.py). The Blender glue is
# imported when Blender registers the add-on.
# Executed again (F8, addon_utils reload): the globals of the first run are
# still here, and register() reloads the submodules once.
_reload_pending = "_GLUE" in globals()
_GLUE = ("settings", "operators", "ui", "handlers", "viewport")
_RELOAD = ("compat", "convert", "textures", "materials", "config", "checks", "export", "engine",
           "runner", "compositor", "cycles_colors", "live") + _GLUE


def _glue_modules():
    global _reload_pending
    import importlib
    import sys
    if _reload_pending:
        _reload_pending = False
        for name in _RELOAD:
            m = sys.modules.get(__name__ + "." + name)
            if m is not None:
                importlib.reload(m)
    return [importlib.import_module(__name__ + "." + name) for name in _GLUE]


def register():
    for m in _glue_modules():
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
    import importlib
    atexit.unregister(_unregister_at_exit)
    for name in reversed(_GLUE):
        importlib.import_module(__name__ + "." + name).unregister()


def _unregister_at_exit():
    try:
        import bpy
        if "vsgl_indirect" in bpy.types.Scene.bl_rna.properties:
            unregister()
    except Exception:  # never turn a clean exit into a failure
        pass
