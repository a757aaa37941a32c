/* Internal: render orchestration helpers. */
#ifndef VSGL_SHADE_RENDER_INTERNAL_H
#define VSGL_SHADE_RENDER_INTERNAL_H

#include "vsgl/render.h"

/* Copy `in` (NULL = defaults) into `s`, fill defaults for zero fields and
 * validate; the error names the field. */
vsgl_result vsgl__settings_resolve(vsgl_context *ctx, const vsgl_render_settings *in,
                                   vsgl_render_settings *s);

#endif
