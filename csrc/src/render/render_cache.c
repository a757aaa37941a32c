/* vsgl_render_cache: the G-buffer and the VSGLs of the last render, with
 * the inputs they were made from (compared bytewise by vsgl_render_cached). */
#include "render/render_internal.h"
#include "scene/scene_internal.h"
#include "core/context.h"

#include <stdlib.h>
#include <string.h>

vsgl_result vsgl_render_cache_create(vsgl_context *ctx, vsgl_render_cache **out)
{
    vsgl__clear_error(ctx);
    if (!out)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "render_cache_create: out is NULL");
    *out = calloc(1, sizeof **out);
    if (!*out)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "render_cache_create: out of memory");
    return VSGL_OK;
}

void vsgl__cache_clear(vsgl_render_cache *c)
{
    if (!c)
        return;
    vsgl__gbuffer_free(&c->g);
    vsgl__shade_plan_free(c->plan);
    vsgl__vsgl_set_free(&c->set);
    free(c->f_lights);
    free(c->planes);
    memset(c, 0, sizeof *c);
}

float *vsgl__cache_planes(vsgl_render_cache *c, size_t floats)
{
    if (c->planes && c->planes_floats == floats)
        return c->planes;
    free(c->planes);
    c->planes = calloc(floats + 1, sizeof *c->planes);
    c->planes_floats = c->planes ? floats : 0;
    return c->planes;
}

void vsgl_render_cache_destroy(vsgl_render_cache *cache)
{
    vsgl__cache_clear(cache);
    free(cache);
}

static int same_scene(const vsgl_scene *a, uint64_t a_id, const vsgl_scene *b)
{
    return a == b && a_id == vsgl__scene_identity(b);
}

int vsgl__cache_gbuffer_hit(const vsgl_render_cache *c, const vsgl_scene *scene, uint32_t aa, uint32_t edge_aa)
{
    return c && c->has_g && same_scene(c->g_scene, c->g_identity, scene) && c->g_aa == aa && c->g_edge_aa == edge_aa &&
           memcmp(&c->g_camera, vsgl__scene_camera(scene), sizeof c->g_camera) == 0;
}

void vsgl__cache_keep_gbuffer(vsgl_render_cache *c, const vsgl_scene *scene, uint32_t aa, uint32_t edge_aa,
                              vsgl_gbuffer *g, vsgl_shade_plan *plan)
{
    if (c->plan != plan)
        vsgl__shade_plan_free(c->plan);
    vsgl__gbuffer_free(&c->g);
    c->g = *g;
    c->plan = plan; /* recorded from g, or NULL */
    memset(g, 0, sizeof *g);
    c->g_scene = scene;
    c->g_identity = vsgl__scene_identity(scene);
    c->g_camera = *vsgl__scene_camera(scene);
    c->g_aa = aa;
    c->g_edge_aa = edge_aa;
    c->has_g = 1;
}

int vsgl__cache_fit_hit(const vsgl_render_cache *c, const vsgl_scene *scene, const vsgl_render_settings *s)
{
    if (!c || !c->has_f || !same_scene(c->f_scene, c->f_identity, scene) ||
        memcmp(&c->f_settings, s, sizeof *s) != 0)
        return 0;
    uint32_t n = 0;
    const vsgl_light *lights = vsgl__scene_lights(scene, &n);
    if (n != c->f_light_count || (n && memcmp(lights, c->f_lights, (size_t)n * sizeof *lights) != 0))
        return 0;
    /* a budget shared among lights follows what the camera sees (render/budget.h) */
    return !c->f_budget[0] || memcmp(vsgl__scene_camera(scene), &c->f_camera, sizeof c->f_camera) == 0;
}

vsgl_result vsgl__cache_keep_fit(vsgl_render_cache *c, const vsgl_scene *scene, const vsgl_render_settings *s,
                                 vsgl_vsgl_set *set, const vsgl_render_stats *st)
{
    uint32_t n = 0;
    const vsgl_light *lights = vsgl__scene_lights(scene, &n);
    vsgl_light *copy = NULL;
    if (n) {
        copy = malloc((size_t)n * sizeof *copy);
        if (!copy) { /* not kept: the next render fits again */
            c->has_f = 0;
            return VSGL_OK;
        }
        memcpy(copy, lights, (size_t)n * sizeof *copy);
    }
    vsgl__vsgl_set_free(&c->set);
    free(c->f_lights);
    c->set = *set;
    memset(set, 0, sizeof *set);
    c->f_lights = copy;
    c->f_light_count = n;
    c->f_scene = scene;
    c->f_identity = vsgl__scene_identity(scene);
    c->f_settings = *s;
    c->f_lights_used = st->lights_used;
    c->f_lights_skipped = st->lights_skipped;
    memcpy(c->f_skipped, st->skipped, sizeof c->f_skipped);
    memcpy(c->f_budget, st->budget, sizeof c->f_budget);
    c->f_camera = *vsgl__scene_camera(scene);
    c->has_f = 1;
    return VSGL_OK;
}
