"""Scene settings of the add-on (``scene.vsgl_indirect``)."""
import os

import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty,
                       StringProperty)

from . import config
from .libvsgl import (AA_SAMPLES_MAX, FIS_ITERATIONS_MAX, RSM_RESOLUTION_MAX, RSM_RESOLUTION_MIN,
                      VSGL_COUNT_MAX)


def _update_compositor(self, context):
    """Keep the compositor in step with the settings (main thread, UI edits)."""
    from . import compositor, engine, handlers
    scene = self.id_data
    if not isinstance(scene, bpy.types.Scene):
        return
    try:
        if not self.enabled:
            compositor.remove(scene)
        elif engine.can_render():
            handlers.setup_scene(scene)
    except Exception as e:  # never break a property edit
        print("VSGL WARNING: compositor update failed: %r" % (e,))


# Only inside the Blender application: the pip bpy module has no UI to keep
# in step (render_init sets the compositor up), and its 4.2 LTS build
# segfaults at exit (status 139, after every render) while an update=
# callback is registered, even after unregistering it (issue 10; 5.0 does
# not). The handlers are removed at exit by __init__._unregister_at_exit.
IN_APPLICATION = "blender" in os.path.basename(bpy.app.binary_path or "").lower()
_UPDATE = {"update": _update_compositor} if IN_APPLICATION else {}


# Blender 4.5+ warns about '//' in path properties unless they opt in.
_PATH_OPTIONS = ({"options": {"PATH_SUPPORTS_BLEND_RELATIVE"}}
                 if bpy.app.version >= (4, 5, 0) else {})


def _items(names, descriptions=None):
    descriptions = descriptions or {}
    return [(n, n.replace("_", " ").title(), descriptions.get(n, "")) for n in names]


class VSGLIndirectSettings(bpy.types.PropertyGroup):
    enabled: BoolProperty(
        name="Compute on Render", default=False, **_UPDATE,
        description="Compute the indirect-light AOV of every rendered frame before it is "
                    "rendered and composited (F12, -f, -a)")
    add_to_render: BoolProperty(
        name="Add to Render", default=True, **_UPDATE,
        description="Add the AOV's Combined pass onto the render in the compositor "
                    "(otherwise only the Image node is set up)")
    preset: EnumProperty(
        name="Preset", default="BALANCED",
        items=[("PREVIEW", "Preview", "Fastest: few samples, small shadow maps"),
               ("BALANCED", "Balanced", "Default trade of speed and quality"),
               ("QUALITY", "Quality", "Slowest, closest to Cycles one-bounce")])
    use_advanced: BoolProperty(name="Advanced", default=False,
                               description="Use the knobs below instead of the preset's values")
    method: EnumProperty(name="Method", items=_items(config.KNOBS["method"][0]), default="VSGL")
    aa_samples: IntProperty(name="AA Samples", default=config.KNOBS["aa_samples"][1], min=1, max=AA_SAMPLES_MAX,
                            description="Camera samples per pixel per axis (N x N)")
    rsm_resolution: IntProperty(name="RSM Resolution", default=256, min=RSM_RESOLUTION_MIN,
                                max=RSM_RESOLUTION_MAX,
                                description="Reflective shadow map side per light (texels)")
    fit_mode: EnumProperty(name="Fit", items=_items(config.KNOBS["fit_mode"][0]),
                           default=config.KNOBS["fit_mode"][1],
                           description="Two VSGLs per light, filtered importance sampling, k-means, or a "
                                       "world-space lattice (steady in animation, no blotches)")
    vsgl_count: IntProperty(name="VSGLs per Light", default=config.KNOBS["vsgl_count"][1], min=1,
                            max=VSGL_COUNT_MAX)
    fis_iterations: IntProperty(name="FIS Iterations", default=8, min=1, max=FIS_ITERATIONS_MAX)
    sharpness_estimator: EnumProperty(name="Sharpness",
                                      items=_items(config.KNOBS["sharpness_estimator"][0]),
                                      default="TOKSVIG")
    diffuse_mode: EnumProperty(name="Diffuse Cosine", items=_items(config.KNOBS["diffuse_mode"][0]),
                               default=config.KNOBS["diffuse_mode"][1])
    glossy_mode: EnumProperty(name="Glossy Lobe", items=_items(config.KNOBS["glossy_mode"][0]),
                              default="ASG")
    visibility: EnumProperty(name="Visibility", items=_items(config.KNOBS["visibility"][0]),
                             default="NONE", description="Indirect shadows: none, or one ray per VSGL")
    seed: IntProperty(name="Seed", default=0, min=0)
    leak_correction: EnumProperty(name="Leak Correction", items=_items(config.KNOBS["leak_correction"][0]),
                                  default="AUTO",
                                  description="Clip a VSGL's light to the front of its surface "
                                              "(auto: on)")
    sample_merging: EnumProperty(name="Sample Merging", items=_items(config.KNOBS["sample_merging"][0]),
                                 default="AUTO",
                                 description="Shade a pixel's samples on one surface once (auto: on)")
    output_path: StringProperty(
        name="Output", subtype="FILE_PATH", default=config.DEFAULT_TEMPLATE,
        **_PATH_OPTIONS, **_UPDATE,
        description="Per-frame multilayer EXR. {render_dir} = the render output's folder, "
                    "{scene}, {view_layer}; #### = frame number (must be the last digits)")
    threads: IntProperty(name="Threads", default=0, min=0, max=1024,
                         description="Worker threads of the library (0 = all cores)")
    max_memory_gb: FloatProperty(
        name="Max Memory (GiB)", default=0.0, min=0.0, soft_max=256.0, precision=1,
        description="Refuse a frame whose estimated memory is above this, with a message "
                    "naming its size (0 = the memory this machine has available)")
    half_float: BoolProperty(name="Half Float", default=False,
                             description="Write 16-bit half floats instead of 32-bit")


classes = (VSGLIndirectSettings,)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.vsgl_indirect = PointerProperty(type=VSGLIndirectSettings)


def unregister():
    del bpy.types.Scene.vsgl_indirect
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
