/* Internal: render orchestration helpers. */
#ifndef VSGL_SHADE_RENDER_INTERNAL_H
#define VSGL_SHADE_RENDER_INTERNAL_H

#include "vsgl/render.h"
#include "fit/vsgl_set.h"

/* Copy `in` (NULL = defaults) into `s`, fill defaults for zero fields and
 * validate; the error names the field. */
vsgl_result vsgl__settings_resolve(vsgl_context *ctx, const vsgl_render_settings *in,
                                   vsgl_render_settings *s);

/* Fit the VSGLs of every light (settings resolved), one RSM alive at a
 * time; skipped lights are noted in `st`. */
vsgl_result vsgl__fit_lights(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                             vsgl_vsgl_set *set, vsgl_render_stats *st);

#endif
