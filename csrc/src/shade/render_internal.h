/* Internal: render orchestration helpers. */
#ifndef VSGL_SHADE_RENDER_INTERNAL_H
#define VSGL_SHADE_RENDER_INTERNAL_H

#include "vsgl/render.h"
#include "fit/vsgl_set.h"

/* Copy `in` (NULL = defaults) into `s`, fill defaults for zero fields and
 * validate; the error names the field. */
vsgl_result vsgl__settings_resolve(vsgl_context *ctx, const vsgl_render_settings *in,
                                   vsgl_render_settings *s);

/* Estimate what a render of `scene` with resolved settings `s` allocates
 * (plus `output_bytes` of caller planes) into `e`, and fail with
 * VSGL_ERROR_OUT_OF_MEMORY, naming the size and the limit, above the
 * context's limit (shade/memory.c). */
vsgl_result vsgl__memory_estimate(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                                  uint64_t output_bytes, vsgl_memory_estimate *e);

/* Fit the VSGLs of every light (settings resolved), one RSM alive at a
 * time; skipped lights are noted in `st`. */
vsgl_result vsgl__fit_lights(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                             vsgl_vsgl_set *set, vsgl_render_stats *st);

#endif
