"""Checks of the scene around the AOV, shown in the panel and logged at
render start. No bpy: they read attributes of the objects passed in, so the
tests can call them with stand-ins too."""
import os
import tempfile

#: Cycles' bounce settings 'Cycles: Direct Light Only' sets to 0 (and
#: 'Restore Bounces' puts back). Transmission, volume and transparency are
#: kept: the AOV has no glass, so glass keeps rendering.
BOUNCE_KEYS = ("diffuse_bounces", "glossy_bounces")
SAVED_KEYS = ("max_bounces",) + BOUNCE_KEYS


def double_counting(scene):
    """A message if Cycles renders its own diffuse/glossy indirect light
    while the AOV is added onto the render (counted twice), else ''."""
    props = getattr(scene, "vsgl_indirect", None)
    if props is None or not props.enabled or not props.add_to_render:
        return ""
    if getattr(scene.render, "engine", "") != "CYCLES":
        return ""
    cy = getattr(scene, "cycles", None)
    if cy is None or int(getattr(cy, "max_bounces", 0)) <= 0:
        return ""
    on = ["%s %d" % (k.split("_")[0], int(getattr(cy, k, 0))) for k in BOUNCE_KEYS
          if int(getattr(cy, k, 0)) > 0]
    if not on:
        return ""
    return ("Cycles also renders indirect light (Light Paths > Max Bounces: total %d, %s) and "
            "the AOV is added onto it: the indirect light is counted twice "
            "(use 'Cycles: Direct Light Only')" % (int(cy.max_bounces), ", ".join(on)))


def temp_dirs():
    dirs = {os.path.realpath(tempfile.gettempdir()), "/tmp", "/var/tmp", "/dev/shm"}
    return {os.path.realpath(d) for d in dirs}


def in_temp_dir(path):
    """Is ``path`` (absolute) inside a temporary directory (/tmp, $TMPDIR)?"""
    p = os.path.realpath(os.path.abspath(path))
    return any(p == d or p.startswith(d.rstrip(os.sep) + os.sep) for d in temp_dirs())


def temp_output_warning(path):
    if not in_temp_dir(path):
        return ""
    return ("the AOV goes to %s, a temporary folder the system may clear: set the render "
            "output (Output Properties) or the Output template to keep it" % os.path.dirname(path))
