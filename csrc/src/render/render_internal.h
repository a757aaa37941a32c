/* Internal: render orchestration helpers. */
#ifndef VSGL_RENDER_RENDER_INTERNAL_H
#define VSGL_RENDER_RENDER_INTERNAL_H

#include "vsgl/render.h"
#include "fit/vsgl_set.h"
#include "gbuffer/gbuffer.h"
#include "shade/shade.h"

/* Copy `in` (NULL = defaults) into `s`, fill defaults for zero fields and
 * validate; the error names the field. */
vsgl_result vsgl__settings_resolve(vsgl_context *ctx, const vsgl_render_settings *in,
                                   vsgl_render_settings *s);
/* What the image-size rules changed (vsgl__settings_resolve_for): the
 * settings as asked where a rule changed them, else 0. */
typedef struct vsgl__image_rules {
    uint32_t aa_asked;     /* aa_samples that aa_pixel_limit lowered to 1 */
    uint32_t stride_asked; /* shade_stride that stride_pixels raised */
    uint32_t stride_ignored; /* shade_stride > 1 that glossy sg does not take: the scalar reference path
                                (shade.c) shades every pixel */
} vsgl__image_rules;

/* vsgl__settings_resolve, then the rules for the scene camera's image:
 * aa_pixel_limit (one sample per pixel from that many pixels up) and
 * stride_pixels (the stride scaled with the image's side). What a render
 * and its memory estimate both start from. */
vsgl_result vsgl__settings_resolve_for(vsgl_context *ctx, const vsgl_render_settings *in, const vsgl_scene *scene,
                                       vsgl_render_settings *s, vsgl__image_rules *rules);

/* The stride stride_pixels gives a width x height image (settings resolved). */
uint32_t vsgl__stride_for_image(const vsgl_render_settings *s, uint32_t width, uint32_t height);

/* Estimate what a render of `scene` with resolved settings `s` allocates
 * (plus `output_bytes` of caller planes) into `e`, and fail with
 * VSGL_ERROR_OUT_OF_MEMORY, naming the size and the limit, above the
 * context's limit (render/memory.c). */
vsgl_result vsgl__memory_estimate(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                                  uint64_t output_bytes, vsgl_memory_estimate *e);

/* Fit the VSGLs of every light (settings resolved), one RSM alive at a
 * time; skipped lights are noted in `st`. */
vsgl_result vsgl__fit_lights(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                             vsgl_vsgl_set *set, vsgl_render_stats *st);

/* vsgl__fit_lights, and each light's RSM also added to the MRP proxies
 * @p mrp (vsgl__mrp_proxies_add_rsm, before its fit; may be NULL): *mrp_lit
 * is 1 when every lit light's RSM was (its size the settings'
 * rsm_resolution, as the MRP pass would build it), else 0 (the auto
 * budget gave a light another size: the pass builds its own RSMs). */
struct vsgl__mrp_proxy_set;
vsgl_result vsgl__fit_lights_mrp(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                                 vsgl_vsgl_set *set, vsgl_render_stats *st, struct vsgl__mrp_proxy_set *mrp,
                                 int *mrp_lit);

/* What a vsgl_render_cache holds (render_cache.c). */
struct vsgl_render_cache {
    int has_g;                   /* the G-buffer of g_scene seen by g_camera with g_aa, g_edge_aa */
    const vsgl_scene *g_scene;
    uint64_t g_identity;
    vsgl_camera g_camera;
    uint32_t g_aa, g_edge_aa;
    vsgl_gbuffer g;
    vsgl_shade_plan *plan;       /* NULL, or the shading plan of g (shade/shade_job.h) */
    int has_f;                   /* the VSGLs of f_scene's f_lights with f_settings, and the fit's stats */
    const vsgl_scene *f_scene;
    uint64_t f_identity;
    vsgl_light *f_lights;
    uint32_t f_light_count;
    vsgl_render_settings f_settings;
    vsgl_vsgl_set set;
    uint32_t f_lights_used, f_lights_skipped;
    char f_skipped[sizeof(((vsgl_render_stats *)0)->skipped)];
    char f_budget[sizeof(((vsgl_render_stats *)0)->budget)]; /* non-empty: the lights shared a budget
                                                                 measured from f_camera's view */
    vsgl_camera f_camera;
    float *planes;               /* the last render's pixel planes, reused (render.c); planes_floats floats */
    size_t planes_floats;
};

void vsgl__cache_clear(vsgl_render_cache *c);
int vsgl__cache_gbuffer_hit(const vsgl_render_cache *c, const vsgl_scene *scene, uint32_t aa, uint32_t edge_aa);
/* Takes `g` (zeroed afterwards) and `plan` (its shading plan, or NULL). */
void vsgl__cache_keep_gbuffer(vsgl_render_cache *c, const vsgl_scene *scene, uint32_t aa, uint32_t edge_aa,
                              vsgl_gbuffer *g, vsgl_shade_plan *plan);
/* `floats` floats of pixel planes owned by the cache (kept between renders:
 * no allocation and no page faults per render), or NULL when memory is
 * short. Zero when first allocated; afterwards they hold the last render's. */
float *vsgl__cache_planes(vsgl_render_cache *c, size_t floats);
int vsgl__cache_fit_hit(const vsgl_render_cache *c, const vsgl_scene *scene, const vsgl_render_settings *s);
/* Takes `set` (zeroed afterwards) with the fit's stats from `st`. */
vsgl_result vsgl__cache_keep_fit(vsgl_render_cache *c, const vsgl_scene *scene, const vsgl_render_settings *s,
                                 vsgl_vsgl_set *set, const vsgl_render_stats *st);

#endif
