/* The auto budget (VSGL_AUTO_BALANCED, budget.h): the knobs a scene needs
 * for the balanced preset's error, chosen from what the camera probe sees;
 * each light's RSM side from its footprint follows in the per-light budget
 * (render.c, light_budget). Every choice is said in the stats' budget text
 * and the log. */
#include "render/budget.h"
#include "render/render_internal.h"
#include "core/context.h"
#include "vsgl/render.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static void say(vsgl_context *ctx, vsgl_render_stats *st, const char *fmt, ...) VSGL_PRINTF(3, 4);
static void say(vsgl_context *ctx, vsgl_render_stats *st, const char *fmt, ...)
{
    char line[192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    vsgl__log(ctx, VSGL_LOG_INFO, "auto: %s", line);
    size_t used = strlen(st->budget);
    if (used + strlen(line) + 8 < sizeof st->budget)
        snprintf(st->budget + used, sizeof st->budget - used, "auto: %s\n", line);
}

vsgl_result vsgl__auto_choose(vsgl_context *ctx, const vsgl_scene *scene, uint32_t aa_asked,
                              vsgl_render_settings *s, vsgl_render_stats *st)
{
    if (s->auto_target == VSGL_AUTO_OFF || s->method != VSGL_METHOD_VSGL)
        return VSGL_OK;
    vsgl_budget_view v;
    vsgl_result r = vsgl__budget_view(ctx, scene, &v);
    if (r != VSGL_OK)
        return r;
    const vsgl_camera *cam = vsgl__scene_camera(scene);
    uint64_t pixels = (uint64_t)cam->width * cam->height;

    /* anti-aliasing: from the image size, as every render (aa_pixel_limit, render.c) */
    if (aa_asked)
        say(ctx, st, "aa 1 (not %u): %ux%u, >= %u pixels", aa_asked, cam->width, cam->height, s->aa_pixel_limit);
    else if (s->aa_pixel_limit && s->aa_samples > 1 && pixels < s->aa_pixel_limit)
        say(ctx, st, "aa %u: %ux%u, < %u pixels", s->aa_samples, cam->width, cam->height, s->aa_pixel_limit);
    else
        say(ctx, st, "aa %u: as set", s->aa_samples);
    /* the glossy lobe model: two ASGs only where a sharp glossy surface is seen */
    if (s->glossy_mode == VSGL_GLOSSY_ASG2) {
        if (v.glossy == 0 || v.sharpest_roughness >= VSGL__AUTO_SHARP_ROUGHNESS) {
            say(ctx, st, "glossy asg (not asg2): nothing seen sharper than roughness %.2f",
                (double)VSGL__AUTO_SHARP_ROUGHNESS);
            s->glossy_mode = VSGL_GLOSSY_ASG;
        } else {
            say(ctx, st, "glossy asg2: roughness %.2f seen (< %.2f)", (double)v.sharpest_roughness,
                (double)VSGL__AUTO_SHARP_ROUGHNESS);
        }
    }
    return VSGL_OK;
}
