/* vsgl_debug_vsgls: the fitted VSGLs, for tests and inspection. */
#include "vsgl/debug.h"
#include "render/render_internal.h"
#include "core/context.h"

#include <string.h>

vsgl_result vsgl_debug_vsgls(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *settings,
                             size_t *count, vsgl_debug_vsgl *out)
{
    vsgl__clear_error(ctx);
    if (!scene || !count)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "debug_vsgls: %s is NULL", scene ? "count" : "scene");
    vsgl_render_settings s;
    vsgl_result r = vsgl__settings_resolve(ctx, settings, &s);
    if (r != VSGL_OK)
        return r;
    vsgl_vsgl_set set;
    memset(&set, 0, sizeof set);
    vsgl_render_stats st;
    memset(&st, 0, sizeof st);
    r = vsgl__fit_lights(ctx, scene, &s, &set, &st);
    if (r == VSGL_OK && out && *count < set.count)
        r = vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "debug_vsgls: capacity %zu is below the %zu VSGLs", *count,
                       set.count);
    if (r == VSGL_OK && out)
        for (size_t k = 0; k < set.count; ++k) {
            const vsgl_vsgl *v = &set.items[k];
            vsgl_debug_vsgl *o = &out[k];
            o->mean[0] = v->mean.x; o->mean[1] = v->mean.y; o->mean[2] = v->mean.z;
            o->variance = v->variance;
            o->axis[0] = v->axis.x; o->axis[1] = v->axis.y; o->axis[2] = v->axis.z;
            o->sharpness = v->sharpness;
            memcpy(o->power, v->power, sizeof o->power);
            o->normal[0] = v->normal.x; o->normal[1] = v->normal.y; o->normal[2] = v->normal.z;
            o->coherence = v->coherence;
            o->light = v->light;
            o->lobe = v->lobe;
        }
    if (r == VSGL_OK || (out && *count < set.count))
        *count = set.count;
    vsgl__vsgl_set_free(&set);
    return r;
}
