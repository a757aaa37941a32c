/* Render settings: presets, defaults for zero fields, validation. */
#include "render/render_internal.h"
#include "core/versioned.h"
#include "core/context.h"
#include "shade/shade.h"

#include <string.h>

void vsgl_render_settings_preset(int32_t preset, vsgl_render_settings *out)
{
    if (!out)
        return;
    memset(out, 0, sizeof *out);
    out->size = sizeof *out;
    out->method = VSGL_METHOD_VSGL;
    out->sharpness_estimator = VSGL_SHARPNESS_TOKSVIG;
    out->glossy_mode = VSGL_GLOSSY_ASG;
    out->visibility = VSGL_VISIBILITY_NONE;
    out->fis_iterations = 8;
    out->shade_stride = 1;
    out->mrp_min_area = VSGL_MRP_MIN_AREA_DEFAULT; /* what 0 means, spelled out (the add-on's panel shows it) */
    out->glossy_lobes = 4;                         /* the same */
    out->visibility_budget = VSGL_VISIBILITY_BUDGET_DEFAULT; /* the same */
    out->visibility_spread = VSGL_VISIBILITY_SPREAD_DEFAULT; /* the same */
    /* Every preset traces 4 rays for a pair that carries 0.5 % or more of a
     * receiver's light where its block holds a receiver that VSGL is hidden
     * from (render.h): with one, a soft indirect shadow was grain (rough_room's
     * floor beside the sphere at 320 x 240, the pixel-scale noise 0.068 of
     * the light in the preview, 0.020 in balanced; the wall behind the sun
     * room's cabinet in balanced at 960 x 540, 0.032); with 4, 0.022, 0.007
     * and 0.007, at 0.9-1.1x the time at 960 x 540 (docs/pipeline.md). */
    out->dominant_rays = 4;
    /* Every preset fits on the lattice: the importance-drawn fits flicker
     * as a light moves (0.1-0.75 of the AOV per 1/1000-extent step, docs/
     * quality.md) and break a reflection into blotches; with the emitter
     * clip the pulled-out cosine is as accurate as the accurate form at half
     * the cost. Shading one pixel in 2 x 2 (sparse.c) changes the error by
     * a few per cent and pays for visibility rays, which pay where something
     * stands between a lit surface and a receiver (a sun room's cabinet:
     * structured error 1400x -> 73x the reference's noise at 320 x 240);
     * balanced with both takes 1.1-1.5x what it took without either. */
    out->fit_mode = VSGL_FIT_LATTICE;
    /* Every preset resolves edges with 8 x 8 rays (coverage only, gbuffer/
     * edges.c): as the camera moves 1/1000 of the scene a frame, the frame-to-
     * frame change of the bundled rooms at 80 x 60 falls from 0.012-0.11 to
     * 0.006-0.07 (the rest is the true change and silhouette shading,
     * docs/quality.md), for 5-35 % more time at that size, less at larger
     * sizes where fewer pixels are edges. At 1 x 1 (the preview) a pixel gets
     * a second slot for a second surface: half the preview's time of taking
     * 2 x 2 samples for it, at about the same flicker. Balanced and quality
     * take 12 x 12 (below). */
    out->edge_samples = 8;
    /* Every preset takes one sample per pixel from 320 x 240 up (edges keep
     * their edge rays; docs/pipeline.md, "Anti-aliasing by image size"): at
     * 320 x 240 against Cycles the combined relMSE of the six quality rooms
     * is 0.99-1.06x that of balanced's 2 x 2 samples and 0.98-1.07x that of
     * quality's 3 x 3 (the sun rooms the +5-7 %), FLIP within 0.3 %, and
     * quality stays more accurate than balanced in every room; balanced
     * takes 0.64-0.91x the time at 960 x 540, quality 0.44-0.99x at 320 x
     * 240. At 80 x 60 a pixel is large against the light's changes (the box
     * room's relMSE 0.00468 with one sample against 0.00416 with 2 x 2), so
     * the test rooms of docs/quality.md keep their aa x aa. */
    out->aa_pixel_limit = VSGL_AA_PIXEL_LIMIT_PRESETS;
    /* Every preset's stride (2) holds up to 320 x 240 and grows with the
     * image's side above it: one pixel in 5 x 5 at 960 x 540, in 8 x 8 at
     * 1920 x 1080 (docs/pipeline.md, "The stride by image size"). At
     * 960 x 540 against Cycles (2 x 256 spp), balanced's combined
     * structured error moved by -0.8 % to +2.5 % in four rooms (the glossy
     * pass's up to +4 %), FLIP by under 0.0002, for 0.44-0.80x the render
     * time; the frame-to-frame change as a light or the camera moves stays
     * within that of shading every pixel. Larger strides save nothing: the
     * interpolation test shades more pixels (the sphere room at 960 x 540:
     * 1.0e8 pairs at 4 and 5, 1.1e8 at 6, 1.5e8 at 8). */
    out->stride_pixels = VSGL_STRIDE_PIXELS_PRESETS;
    out->diffuse_mode = VSGL_COSINE_PULLED_OUT;
    /* Every preset takes GGX as two lobes (VSGL_GLOSSY_ASG2): with one, a
     * metal floor's reflection of a lit wall was too bright in its middle
     * and too dark around it, which no VSGL count fixed (the spot room's
     * glossy structured error 0.0049 at lattice 192, 0.0058 at 1024; 0.0004
     * with two lobes). The preview took one until its sun rooms' glint on
     * the cabinet was seen to shimmer as the sun moved: with one lobe, a
     * small lit patch of floor seen in a glossy surface changes by +-8 % a
     * frame as the lattice's clusters drift under the lobe (light-motion
     * Gloss 0.0162 / 0.0212 a frame, Cycles' own 0.011); with two, and the
     * half-vector model they bring, 0.0074 / 0.0091. At 80 x 60 the
     * preview's FLIP falls in every room (spot room 0.141 -> 0.088, red wall
     * 0.138 -> 0.112, sun rooms 0.083 / 0.088 -> 0.078 / 0.082; the sphere's
     * the same), its glossy structured error 2.5-3.5x, and its Gloss bias
     * moves to within 1-3 % of Cycles' but in the sphere room (0.966 ->
     * 0.950). It costs the preview 1.2-1.45x its time at 960 x 540. The
     * viewport's Live quality keeps one lobe (addon/vsgl_indirect/live.py),
     * for its time. */
    switch (preset) {
    case VSGL_PRESET_PREVIEW: /* within +-21 % of Cycles per pass on the bundled scenes */
        out->aa_samples = 1;
        out->rsm_resolution = 128;
        out->vsgl_count = 32;
        /* a quarter of the shading pairs; structured error and FLIP within
         * 1-3 % of shading every pixel at 320 x 240 (docs/quality.md) */
        out->shade_stride = 2;
        /* Visibility rays (skipped in convex rooms, budgeted elsewhere): without
         * them the sun room's cabinet cast no indirect shadow on the wall and
         * the room was 10 % too bright (Diff bias 1.101 -> 0.999, structured
         * error 420x -> 2.4x the reference's noise, FLIP 0.176 -> 0.083 at
         * 80 x 60; glossy_sphere_floor FLIP 0.193 -> 0.170), at 1.5-1.8x the
         * time in the rooms that are not convex. The viewport's Live quality
         * leaves them out (addon/vsgl_indirect/live.py). */
        out->visibility = VSGL_VISIBILITY_RAY;
        out->glossy_mode = VSGL_GLOSSY_ASG2;
        break;
    case VSGL_PRESET_QUALITY: /* finer cells, RSMs, samples and GGX lobes than balanced: lower
                                 structured error in every pass of the bundled rooms but two glossy
                                 ones, the sun room's (a tie) and the rough room's (docs/quality.md);
                                 shading every pixel instead of one in 2 x 2 gave the same error at
                                 5-10x the time */
        out->aa_samples = 3;
        out->glossy_lobes = 5;
        out->rsm_resolution = 512;
        out->vsgl_count = 256;
        out->visibility = VSGL_VISIBILITY_RAY;
        out->shade_stride = 2;
        out->glossy_mode = VSGL_GLOSSY_ASG2;
        out->edge_samples = 12; /* as balanced (below) */
        break;
    case VSGL_PRESET_AUTO: /* balanced's knobs as ceilings, chosen per scene at render time (budget_auto.c) */
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, out);
        out->auto_target = VSGL_AUTO_BALANCED;
        break;
    default: /* BALANCED: lattice 192, not 128: at 128 the coarser clusters' emitter clip
                takes 5-6 % of the light of three bundled rooms (metal floor + red wall
                Diff 0.943, sphere Gloss 0.942, sun room Gloss 0.947 of Cycles); at 192
                every pass of the six is within 5 % (0.951-1.032) */
        out->aa_samples = 2;
        out->rsm_resolution = 256;
        out->vsgl_count = 192;
        out->visibility = VSGL_VISIBILITY_RAY;
        out->shade_stride = 2;
        out->glossy_mode = VSGL_GLOSSY_ASG2;
        /* Edge pixels resolved with 12 x 12 rays, not 8 x 8: a glossy
         * sphere's bright silhouette steps less as the camera moves (80 x 60,
         * camera 1/1000 a frame: the sphere room's Diff / Gloss change 0.0230
         * / 0.0418 -> 0.0211 / 0.0397, Cycles' own 0.0205 / 0.0396; the red
         * wall room's Diff 0.0097 -> 0.0087; quality's sphere Gloss 0.0394 ->
         * 0.0374) at 0-3 % more time at 960 x 540. The preview keeps 8: at
         * 12 its sun room changes more (Gloss 0.0235 -> 0.0247), and it pays
         * 2-9 %. */
        out->edge_samples = 12;
        break;
    }
}

vsgl_result vsgl__settings_resolve(vsgl_context *ctx, const vsgl_render_settings *in,
                                   vsgl_render_settings *s)
{
    vsgl_result r = vsgl__copy_versioned(ctx, s, sizeof *s, in, "vsgl_render_settings");
    if (r != VSGL_OK)
        return r;
    s->size = sizeof *s;
    if (!s->aa_samples)
        s->aa_samples = 1;
    if (!s->rsm_resolution)
        s->rsm_resolution = 256;
    if (!s->vsgl_count)
        s->vsgl_count = 64;
    if (!s->fis_iterations)
        s->fis_iterations = 8;

#define CHECK_ENUM(field, lo, hi)                                                         \
    if (s->field < (lo) || s->field > (hi))                                              \
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "settings: " #field " is %d (valid %d..%d)", \
                          (int)s->field, (int)(lo), (int)(hi));
    CHECK_ENUM(method, VSGL_METHOD_VSGL, VSGL_METHOD_BRUTE_FORCE)
    CHECK_ENUM(fit_mode, VSGL_FIT_TWO, VSGL_FIT_LATTICE)
    CHECK_ENUM(sharpness_estimator, VSGL_SHARPNESS_TOKSVIG, VSGL_SHARPNESS_BANERJEE)
    CHECK_ENUM(diffuse_mode, VSGL_COSINE_ACCURATE, VSGL_COSINE_PULLED_OUT)
    CHECK_ENUM(glossy_mode, VSGL_GLOSSY_ASG, VSGL_GLOSSY_HYBRID)
    CHECK_ENUM(visibility, VSGL_VISIBILITY_NONE, VSGL_VISIBILITY_RAY)
    CHECK_ENUM(leak_correction, VSGL_LEAK_AUTO, VSGL_LEAK_CLIP)
    CHECK_ENUM(sample_merging, VSGL_MERGE_AUTO, VSGL_MERGE_OFF)
    CHECK_ENUM(auto_target, VSGL_AUTO_OFF, VSGL_AUTO_BALANCED)
#undef CHECK_ENUM
    if (s->aa_samples > VSGL_AA_SAMPLES_MAX)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "settings: aa_samples is %u (valid 1..%d)", s->aa_samples,
                          VSGL_AA_SAMPLES_MAX);
    if (s->rsm_resolution < VSGL_RSM_RESOLUTION_MIN || s->rsm_resolution > VSGL_RSM_RESOLUTION_MAX)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "settings: rsm_resolution is %u (valid %d..%d)",
                          s->rsm_resolution, VSGL_RSM_RESOLUTION_MIN, VSGL_RSM_RESOLUTION_MAX);
    if (s->vsgl_count > VSGL_VSGL_COUNT_MAX)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "settings: vsgl_count is %u (valid 1..%d)",
                          s->vsgl_count, VSGL_VSGL_COUNT_MAX);
    if (!s->shade_stride)
        s->shade_stride = 1;
    if (s->shade_stride > VSGL_SHADE_STRIDE_MAX)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "settings: shade_stride is %u (valid 1..%d)",
                          s->shade_stride, VSGL_SHADE_STRIDE_MAX);
    if (s->edge_samples > VSGL_AA_SAMPLES_MAX)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "settings: edge_samples is %u (valid 0..%d)",
                          s->edge_samples, VSGL_AA_SAMPLES_MAX);
    if (!(s->mrp_min_area >= 0.0f) || !(s->mrp_min_area < INFINITY))
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "settings: mrp_min_area is %g (valid: finite, >= 0; "
                          "0 = %g m^2)", (double)s->mrp_min_area, (double)VSGL_MRP_MIN_AREA_DEFAULT);
    if (s->mrp_min_area == 0.0f)
        s->mrp_min_area = VSGL_MRP_MIN_AREA_DEFAULT;
    if (!s->glossy_lobes)
        s->glossy_lobes = 4;
    if (s->glossy_lobes != 4 && s->glossy_lobes != 5)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "settings: glossy_lobes is %u (valid 4 or 5; 0 = 4)",
                          s->glossy_lobes);
    if (!(s->visibility_budget <= 0.5f) || s->visibility_budget != s->visibility_budget)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "settings: visibility_budget is %g (valid: at most "
                          "0.5; 0 = %g, negative = a ray for every pair)", (double)s->visibility_budget,
                          (double)VSGL_VISIBILITY_BUDGET_DEFAULT);
    if (s->visibility_budget == 0.0f)
        s->visibility_budget = VSGL_VISIBILITY_BUDGET_DEFAULT;
    else if (s->visibility_budget < 0.0f)
        s->visibility_budget = -1.0f; /* off */
    if (!(s->visibility_spread <= VSGL_VISIBILITY_SPREAD_MAX) || s->visibility_spread != s->visibility_spread)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "settings: visibility_spread is %g (valid: at most "
                          "%g; 0 = %g, negative = rays at each cluster's centre)", (double)s->visibility_spread,
                          (double)VSGL_VISIBILITY_SPREAD_MAX, (double)VSGL_VISIBILITY_SPREAD_DEFAULT);
    if (s->dominant_rays > VSGL_DOMINANT_RAYS_MAX)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "settings: dominant_rays is %u (valid: 1..%u; 0 = 1)",
                          s->dominant_rays, VSGL_DOMINANT_RAYS_MAX);
    if (s->dominant_rays == 0)
        s->dominant_rays = 1;
    if (s->visibility_spread == 0.0f)
        s->visibility_spread = VSGL_VISIBILITY_SPREAD_DEFAULT;
    else if (s->visibility_spread < 0.0f)
        s->visibility_spread = -1.0f; /* the centre */
    if (s->fis_iterations > VSGL_FIS_ITERATIONS_MAX)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "settings: fis_iterations is %u (valid 1..%d)",
                          s->fis_iterations, VSGL_FIS_ITERATIONS_MAX);
    return VSGL_OK;
}

uint32_t vsgl__stride_for_image(const vsgl_render_settings *s, uint32_t width, uint32_t height)
{
    const uint64_t pixels = (uint64_t)width * height;
    if (!s->stride_pixels || pixels <= s->stride_pixels || s->shade_stride <= 1)
        return s->shade_stride; /* 1 is every pixel at every size */
    /* S sqrt(P / P0), rounded down: the largest S' with S'^2 P0 <= S^2 P (exact in integers) */
    const uint64_t limit = (uint64_t)s->shade_stride * s->shade_stride * pixels;
    uint32_t st = s->shade_stride;
    while (st < VSGL_SHADE_STRIDE_MAX && (uint64_t)(st + 1) * (st + 1) * s->stride_pixels <= limit)
        ++st;
    return st;
}

vsgl_result vsgl__settings_resolve_for(vsgl_context *ctx, const vsgl_render_settings *in, const vsgl_scene *scene,
                                       vsgl_render_settings *s, vsgl__image_rules *rules)
{
    memset(rules, 0, sizeof *rules);
    vsgl_result r = vsgl__settings_resolve(ctx, in, s);
    if (r != VSGL_OK)
        return r;
    const vsgl_camera *cam = vsgl__scene_camera(scene);
    if (s->aa_pixel_limit && s->aa_samples > 1 && (uint64_t)cam->width * cam->height >= s->aa_pixel_limit) {
        rules->aa_asked = s->aa_samples;
        s->aa_samples = 1;
    }
    const uint32_t stride = vsgl__stride_for_image(s, cam->width, cam->height);
    if (stride != s->shade_stride) {
        rules->stride_asked = s->shade_stride;
        s->shade_stride = stride;
    }
    /* the reference path has no sparse shading: every pixel, whatever the
     * stride. Said as it is, not as asked. */
    if (vsgl__shades_by_reference(s) && s->shade_stride > 1) {
        rules->stride_ignored = s->shade_stride;
        rules->stride_asked = 0;
        s->shade_stride = 1;
    }
    return VSGL_OK;
}
