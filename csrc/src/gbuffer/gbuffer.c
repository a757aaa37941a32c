/* Camera G-buffer: aa x aa stratified primary rays per pixel, traced in
 * parallel over rows (Embree ray streams), surface attributes per sample.
 *
 * Sample s of pixel (col, row) is at raster position (col, row) +
 * vsgl__gbuffer_pattern(s, aa) (a sheared aa x aa grid, gbuffer.h), row
 * 0 = top; aa = 1 gives the pixel centre. Positions depend only on (col,
 * row, s): the buffer is bit-identical for any thread count. */
#include "gbuffer/gbuffer.h"
#include "gbuffer/trace.h"
#include "core/context.h"
#include "core/parallel.h"
#include "scene/camera.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Largest aa accepted (aa x aa = 256 samples per pixel). */
#define VSGL__GBUFFER_MAX_AA 16
/* Progress is reported (and cancellation checked) this many times. */
#define VSGL__GBUFFER_STEPS 32


static void store3(float *const a[3], size_t i, v3 v)
{
    a[0][i] = v.x;
    a[1][i] = v.y;
    a[2][i] = v.z;
}

/* Sample i's surface sf seen along the ray (org, dir), with its material
 * inputs in a textured G-buffer: textures filtered over the sample's
 * footprint at the hit, on the surface, from the rays fr = (o1, d1, o2, d2)
 * one footprint (foot pixels) to the right and down (NULL if untextured). */
static void store_inputs(const gb_job *j, vsgl_gbuffer *g, size_t i, const vsgl_surface *sf, v3 org, v3 dir,
                         const vsgl_hit *hit, const v3 *fr);

static void store_hit(const gb_job *j, vsgl_gbuffer *g, size_t i, const vsgl_surface *sf, v3 org, v3 dir,
                      const vsgl_hit *hit, const v3 *fr)
{
    store3(g->view, i, v3_neg(dir));
    store3(g->pos, i, sf->position);
    if (g->lift[0])
        store3(g->lift, i, v3_sub(vsgl__scene_smooth_point(j->scene, hit, sf), sf->position));
    /* shaded with the normal Cycles' BSDF takes: on a smooth-shaded
     * silhouette the interpolated normal can face away from the camera,
     * which left the rim's samples no glossy light (scene_internal.h) */
    vsgl_surface shaded = *sf;
    vsgl__surface_valid_reflection(&shaded, v3_neg(dir));
    store3(g->nrm, i, shaded.normal);
    store3(g->tan, i, shaded.tangent);
    g->material[i] = sf->material;
    if (g->part)
        g->part[i] = sf->part;
    if (g->surf[0] && fr)
        store_inputs(j, g, i, sf, org, dir, hit, fr);
}

/* Sample i's textured inputs (g->surf), filtered over the footprint of the
 * rays fr = (o1, d1, o2, d2). */
static void store_inputs(const gb_job *j, vsgl_gbuffer *g, size_t i, const vsgl_surface *sf, v3 org, v3 dir,
                         const vsgl_hit *hit, const v3 *fr)
{
    const v3 o1 = fr[0], d1 = fr[1], o2 = fr[2], d2 = fr[3];
    float t = hit->t;
    v3 p0 = v3_add(org, v3_scale(dir, t));
    v3 ex = v3_sub(v3_add(o1, v3_scale(d1, t)), p0), ey = v3_sub(v3_add(o2, v3_scale(d2, t)), p0);
    v3 cr = v3_cross(ex, ey);
    float cs = fabsf(v3_dot(sf->geometric_normal, dir));
    float area = sqrtf(v3_dot(cr, cr)) / fmaxf(cs, 0.02f);
    float in[VSGL__SURF_N];
    vsgl__scene_inputs(j->scene, hit, area, in);
    for (int q = 0; q < VSGL__SURF_N; ++q)
        g->surf[q][i] = in[q];
}

/* The texture footprint's rays of the sample at raster (rx, ry): `foot`
 * pixels to the right and down, fr = (o1, d1, o2, d2). */
static void footprint_rays(const gb_job *j, float rx, float ry, float foot, v3 fr[4])
{
    float t0, t1;
    vsgl__camera_ray(&j->cam, rx + foot, ry, &fr[0], &fr[1], &t0, &t1);
    vsgl__camera_ray(&j->cam, rx, ry + foot, &fr[2], &fr[3], &t0, &t1);
}

void vsgl__gbuffer_store_deferred(const gb_job *j, vsgl_gbuffer *g, size_t i, const vsgl_hit *hit, float rx,
                                  float ry, float foot, int inputs)
{
    if (hit->triangle == VSGL__HIT_NONE || (!(inputs && g->surf[0]) && !g->lift[0]))
        return;
    v3 org, dir, fr[4];
    float t0, t1;
    vsgl__camera_ray(&j->cam, rx, ry, &org, &dir, &t0, &t1);
    vsgl_surface sf;
    vsgl__scene_surface(j->scene, hit, dir, &sf);
    if (g->lift[0])
        store3(g->lift, i, v3_sub(vsgl__scene_smooth_point(j->scene, hit, &sf), sf.position));
    if (!inputs || !g->surf[0])
        return;
    footprint_rays(j, rx, ry, foot, fr);
    store_inputs(j, g, i, &sf, org, dir, hit, fr);
}

void vsgl__gbuffer_trace(const gb_job *j, vsgl_gbuffer *g, uint32_t m, const float *rx, const float *ry,
                         const size_t *dst, float foot, vsgl_hit *hits)
{
    /* not zeroed (2 KB per call): entries [0, m) are written by the camera rays before anything reads them */
    v3 org[VSGL__GBUFFER_BATCH], dir[VSGL__GBUFFER_BATCH];
    float tmin[VSGL__GBUFFER_BATCH], tmax[VSGL__GBUFFER_BATCH];
    vsgl_hit hit[VSGL__GBUFFER_BATCH];
    const v3 zero = v3_make(0.0f, 0.0f, 0.0f);
    if (m == 0 || m > VSGL__GBUFFER_BATCH)
        return;
    uint32_t k0 = 0;
#if defined(__SSE2__)
    for (; k0 + 4 <= m; k0 += 4) /* four rays at a time, the same as one by one */
        vsgl__camera_ray4(&j->cam, rx + k0, ry + k0, org + k0, dir + k0, tmin + k0, tmax + k0);
#endif
    for (uint32_t k = k0; k < m; ++k)
        vsgl__camera_ray(&j->cam, rx[k], ry[k], &org[k], &dir[k], &tmin[k], &tmax[k]);
    vsgl__scene_intersect_many(j->scene, m, org, dir, tmin, tmax, 1, hit);
    if (hits)
        for (uint32_t k = 0; k < m; ++k)
            hits[dst[k]] = hit[k];
    for (uint32_t k = 0; k < m; ++k) {
#if defined(__SSE2__)
        if (k % 4 == 0 && k + 4 <= m && hit[k].triangle != VSGL__HIT_NONE && hit[k + 1].triangle != VSGL__HIT_NONE &&
            hit[k + 2].triangle != VSGL__HIT_NONE &&
            hit[k + 3].triangle != VSGL__HIT_NONE) { /* four hits' surfaces at once (scene/surface4.c) */
            vsgl_surface sf4[4];
            vsgl__scene_surface4(j->scene, &hit[k], &dir[k], sf4);
            v3 o1[4], d1[4], o2[4], d2[4], fr[4][4];
            if (g->surf[0]) { /* the footprint's rays */
                float t0[4], t1[4], rxf[4], ryf[4];
                for (uint32_t q = 0; q < 4; ++q)
                    rxf[q] = rx[k + q] + foot, ryf[q] = ry[k + q] + foot;
                vsgl__camera_ray4(&j->cam, rxf, ry + k, o1, d1, t0, t1);
                vsgl__camera_ray4(&j->cam, rx + k, ryf, o2, d2, t0, t1);
                for (uint32_t q = 0; q < 4; ++q)
                    fr[q][0] = o1[q], fr[q][1] = d1[q], fr[q][2] = o2[q], fr[q][3] = d2[q];
            }
            for (uint32_t q = 0; q < 4; ++q)
                store_hit(j, g, dst[k + q], &sf4[q], org[k + q], dir[k + q], &hit[k + q], g->surf[0] ? fr[q] : NULL);
            k += 3;
            continue;
        }
#endif
        size_t i = dst[k];
        if (hit[k].triangle == VSGL__HIT_NONE) {
            store3(g->view, i, v3_neg(dir[k]));
            store3(g->pos, i, zero);
            store3(g->nrm, i, zero);
            store3(g->tan, i, zero);
            g->material[i] = VSGL__GBUFFER_MISS;
            if (g->part)
                g->part[i] = VSGL__PART_NONE;
            if (g->lift[0])
                store3(g->lift, i, zero);
            if (g->surf[0])
                for (int q = 0; q < VSGL__SURF_N; ++q)
                    g->surf[q][i] = 0.0f;
            continue;
        }
        vsgl_surface sf;
        vsgl__scene_surface(j->scene, &hit[k], dir[k], &sf);
        v3 fr[4];
        if (g->surf[0])
            footprint_rays(j, rx[k], ry[k], foot, fr);
        store_hit(j, g, i, &sf, org[k], dir[k], &hit[k], g->surf[0] ? fr : NULL);
    }
}

static int32_t trace_rows(void *user, size_t chunk, size_t begin, size_t end)
{
    (void)chunk;
    const gb_job *j = user;
    vsgl_gbuffer *g = j->g;
    const uint32_t aa = j->aa, grid = aa * aa, spp = g->spp, width = g->width;
    const float inv = 1.0f / (float)aa;
    float rx[VSGL__GBUFFER_BATCH], ry[VSGL__GBUFFER_BATCH];
    size_t dst[VSGL__GBUFFER_BATCH];
    for (size_t r = begin; r < end; ++r) {
        uint32_t row = j->row0 + (uint32_t)r;
        size_t base = (size_t)row * width * spp;
        size_t n = (size_t)width * grid;
        for (size_t b = 0; b < n; b += VSGL__GBUFFER_BATCH) {
            uint32_t m = (uint32_t)(n - b < VSGL__GBUFFER_BATCH ? n - b : VSGL__GBUFFER_BATCH);
            for (uint32_t k = 0; k < m; ++k) {
                size_t idx = b + k;
                /* (one sample per pixel: no integer division per sample) */
                uint32_t col = grid == 1 ? (uint32_t)idx : (uint32_t)(idx / grid), s = grid == 1 ? 0u : (uint32_t)(idx % grid);
                float ox, oy;
                vsgl__gbuffer_pattern(s, aa, inv, &ox, &oy);
                rx[k] = (float)col + ox;
                ry[k] = (float)row + oy;
                dst[k] = base + (size_t)col * spp + s;
            }
            vsgl__gbuffer_trace(j, g, m, rx, ry, dst, vsgl__texture_footprint(inv), NULL);
        }
        /* slots beyond the grid (one sample per pixel, refined): empty until an edge fills them */
        for (uint32_t col = 0; spp > grid && col < width; ++col)
            for (uint32_t s = grid; s < spp; ++s)
                vsgl__gbuffer_clear_slot(g, base + (size_t)col * spp + s, base + (size_t)col * spp);
    }
    return 0;
}

void vsgl__gbuffer_free(vsgl_gbuffer *g)
{
    if (!g)
        return;
    for (int k = 0; k < 3; ++k) {
        free(g->pos[k]);
        free(g->nrm[k]);
        free(g->view[k]);
        free(g->tan[k]);
        free(g->lift[k]);
    }
    free(g->material);
    free(g->part);
    free(g->weight);
    free(g->spread);
    free(g->refined);
    for (int k = 0; k < VSGL__SURF_N; ++k)
        free(g->surf[k]);
    memset(g, 0, sizeof *g);
}

int vsgl__gbuffer_alloc(vsgl_gbuffer *g, size_t n, int textured, int weighted, int smooth)
{
    int ok = 1;
    for (int k = 0; k < 3; ++k) {
        ok &= (g->pos[k] = malloc((n + 1) * sizeof(float))) != NULL;
        ok &= (g->nrm[k] = malloc((n + 1) * sizeof(float))) != NULL;
        ok &= (g->view[k] = malloc((n + 1) * sizeof(float))) != NULL;
        ok &= (g->tan[k] = malloc((n + 1) * sizeof(float))) != NULL;
    }
    ok &= (g->material = malloc((n + 1) * sizeof(uint32_t))) != NULL;
    ok &= (g->part = malloc((n + 1) * sizeof(uint32_t))) != NULL;
    if (weighted) {
        ok &= (g->weight = malloc((n + 1) * sizeof(float))) != NULL;
        ok &= (g->spread = malloc((n + 1) * sizeof(float))) != NULL;
    }
    if (smooth)
        for (int k = 0; k < 3; ++k)
            ok &= (g->lift[k] = malloc((n + 1) * sizeof(float))) != NULL;
    if (textured)
        for (int k = 0; k < VSGL__SURF_N; ++k)
            ok &= (g->surf[k] = malloc((n + 1) * sizeof(float))) != NULL;
    if (!ok)
        vsgl__gbuffer_free(g);
    return ok;
}

/* Run `fn` over every row in VSGL__GBUFFER_STEPS steps, none under 2^17
 * samples (each step is a parallel loop ending in a wait for its slowest
 * row: a live viewport's 960 x 540 has 4, not 32), reporting progress
 * from p0 to p1 and checking for cancellation; frees *out on failure. */
static vsgl_result for_rows(vsgl_context *ctx, gb_job *job, vsgl_range_fn fn, float p0, float p1, const char *what)
{
    vsgl_gbuffer *out = job->g;
    uint32_t h = out->height;
    uint32_t step = (h + VSGL__GBUFFER_STEPS - 1) / VSGL__GBUFFER_STEPS;
    const size_t row_samples = (size_t)out->width * out->spp, min_rows = ((size_t)1 << 17) / (row_samples ? row_samples : 1) + 1;
    if (step < min_rows)
        step = (uint32_t)(min_rows < h ? min_rows : h);
    for (uint32_t row = 0; row < h; row += step) {
        uint32_t rows = h - row < step ? h - row : step;
        if (vsgl__progress(ctx, "gbuffer", p0 + (p1 - p0) * (float)row / (float)h)) {
            vsgl__gbuffer_free(out);
            return vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "gbuffer: cancelled at row %u of %u (%s)", (unsigned)row,
                              (unsigned)h, what);
        }
        job->row0 = row;
        int32_t r = vsgl__parallel_ctx(ctx, rows, 1, fn, job);
        if (r != 0) {
            vsgl__gbuffer_free(out);
            return vsgl__fail(ctx, r, "gbuffer: %s rows %u..%u failed", what, (unsigned)row,
                              (unsigned)(row + rows - 1));
        }
    }
    return VSGL_OK;
}

vsgl_result vsgl__gbuffer_build(vsgl_context *ctx, const vsgl_scene *scene, uint32_t aa, uint32_t edge_aa,
                                vsgl_gbuffer *out)
{
    if (!scene || !out)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "gbuffer: scene or output is NULL");
    memset(out, 0, sizeof *out);
    if (aa == 0)
        aa = 1;
    if (aa > VSGL__GBUFFER_MAX_AA)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "gbuffer: aa_samples is %u (must be in [1, %d])",
                          (unsigned)aa, VSGL__GBUFFER_MAX_AA);
    if (edge_aa > VSGL__GBUFFER_MAX_AA)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "gbuffer: edge_samples is %u (must be in [0, %d])",
                          (unsigned)edge_aa, VSGL__GBUFFER_MAX_AA);
    int refine = edge_aa > aa;
    uint32_t spp = vsgl__gbuffer_slots(aa, refine);
    const vsgl_camera *cam = vsgl__scene_camera(scene);
    gb_job job;
    memset(&job, 0, sizeof job);
    job.scene = scene;
    vsgl__camera_model(cam, &job.cam);
    job.aa = aa;
    job.edge_aa = refine ? edge_aa : 0;
    job.g = out;
    v3 lo, hi;
    vsgl__scene_bounds(scene, &lo, &hi);
    job.plane_tol = 1e-3f * v3_length(v3_sub(hi, lo));
    if (!vsgl__gbuffer_alloc(out, (size_t)cam->width * cam->height * spp, vsgl__scene_textured(scene), refine,
                              vsgl__scene_smooth(scene)))
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "gbuffer: out of memory for %ux%u pixels x %u samples",
                          (unsigned)cam->width, (unsigned)cam->height, (unsigned)spp);
    out->width = cam->width;
    out->height = cam->height;
    out->spp = spp;
    out->aa = aa;
    out->count = (size_t)cam->width * cam->height * out->spp;
    vsgl_result r = for_rows(ctx, &job, trace_rows, 0.0f, refine ? 0.6f : 1.0f, "tracing");
    if (r != VSGL_OK)
        return r;
    if (refine) {
        for (size_t i = 0; i < out->count; ++i) {
            out->weight[i] = vsgl__gbuffer_grid_weight(aa, i % spp);
            out->spread[i] = 1.0f;
        }
        job.edge = calloc((size_t)out->width * out->height + 1, 1);
        if (!job.edge) {
            vsgl__gbuffer_free(out);
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "gbuffer: out of memory for the edge mask");
        }
        r = for_rows(ctx, &job, vsgl__gbuffer_mark_edges, 0.6f, 0.65f, "finding edges in");
        if (r == VSGL_OK)
            r = for_rows(ctx, &job, vsgl__gbuffer_refine_edges, 0.65f, 1.0f, "refining the edges of");
        out->refined = job.edge; /* the buffer's from here (freed with it) */
        if (r == VSGL_OK)
            for (size_t p = 0; p < (size_t)out->width * out->height; ++p)
                out->edge_pixels += job.edge[p] != 0;
        if (r != VSGL_OK) {
            vsgl__gbuffer_free(out);
            return r;
        }
        vsgl__log(ctx, VSGL_LOG_INFO, "gbuffer: %zu edge pixels (%.1f %%) traced again with %u x %u rays each",
                  out->edge_pixels, 100.0 * (double)out->edge_pixels / (double)((size_t)out->width * out->height),
                  (unsigned)edge_aa, (unsigned)edge_aa);
    }
    if (vsgl__progress(ctx, "gbuffer", 1.0f)) {
        vsgl__gbuffer_free(out);
        return vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "gbuffer: cancelled after the last row");
    }
    return VSGL_OK;
}

void vsgl__gbuffer_material(const vsgl_gbuffer *g, const vsgl_material *materials, size_t i, vsgl_material *out)
{
    const vsgl_material *m = &materials[g->material[i]];
    if (!g->surf[0]) {
        *out = *m;
        return;
    }
    float in[VSGL__SURF_N];
    for (int q = 0; q < VSGL__SURF_N; ++q)
        in[q] = g->surf[q][i];
    vsgl__material_with_inputs(m, in, out);
}
