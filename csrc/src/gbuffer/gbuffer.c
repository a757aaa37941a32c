/* Camera G-buffer: aa x aa stratified primary rays per pixel, traced in
 * parallel over rows (Embree ray streams), surface attributes per sample.
 *
 * Sample s = j * aa + i of pixel (col, row) is at raster position
 * (col + (i + 0.5) / aa, row + (j + 0.5) / aa), row 0 = top; aa = 1 gives
 * the pixel centre. Positions depend only on (col, row, s): the buffer is
 * bit-identical for any thread count. */
#include "gbuffer/gbuffer.h"
#include "core/context.h"
#include "core/parallel.h"
#include "scene/camera.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Largest aa accepted (aa x aa = 256 samples per pixel). */
#define VSGL__GBUFFER_MAX_AA 16
/* Rays traced per Embree stream call. */
#define VSGL__GBUFFER_BATCH 64
/* Progress is reported (and cancellation checked) this many times. */
#define VSGL__GBUFFER_STEPS 32

typedef struct gb_job {
    const vsgl_scene *scene;
    vsgl_camera_model cam;
    uint32_t aa;
    vsgl_gbuffer *g;
    uint32_t row0;   /* first row of the current step */
} gb_job;

static void store3(float *const a[3], size_t i, v3 v)
{
    a[0][i] = v.x;
    a[1][i] = v.y;
    a[2][i] = v.z;
}

static int32_t trace_rows(void *user, size_t chunk, size_t begin, size_t end)
{
    (void)chunk;
    const gb_job *j = user;
    vsgl_gbuffer *g = j->g;
    const uint32_t aa = j->aa, spp = aa * aa, width = g->width;
    const float inv = 1.0f / (float)aa;
    v3 org[VSGL__GBUFFER_BATCH], dir[VSGL__GBUFFER_BATCH];
    float tmin[VSGL__GBUFFER_BATCH], tmax[VSGL__GBUFFER_BATCH];
    vsgl_hit hit[VSGL__GBUFFER_BATCH];
    const v3 zero = v3_make(0.0f, 0.0f, 0.0f);
    for (size_t r = begin; r < end; ++r) {
        uint32_t row = j->row0 + (uint32_t)r;
        size_t base = (size_t)row * width * spp;
        size_t n = (size_t)width * spp;
        for (size_t b = 0; b < n; b += VSGL__GBUFFER_BATCH) {
            uint32_t m = (uint32_t)(n - b < VSGL__GBUFFER_BATCH ? n - b : VSGL__GBUFFER_BATCH);
            for (uint32_t k = 0; k < m; ++k) {
                size_t idx = b + k;
                uint32_t col = (uint32_t)(idx / spp), s = (uint32_t)(idx % spp);
                float px = (float)col + ((float)(s % aa) + 0.5f) * inv;
                float py = (float)row + ((float)(s / aa) + 0.5f) * inv;
                vsgl__camera_ray(&j->cam, px, py, &org[k], &dir[k], &tmin[k], &tmax[k]);
            }
            vsgl__scene_intersect_many(j->scene, m, org, dir, tmin, tmax, 1, hit);
            for (uint32_t k = 0; k < m; ++k) {
                size_t i = base + b + k;
                store3(g->view, i, v3_neg(dir[k]));
                if (hit[k].triangle == VSGL__HIT_NONE) {
                    store3(g->pos, i, zero);
                    store3(g->nrm, i, zero);
                    store3(g->tan, i, zero);
                    g->material[i] = VSGL__GBUFFER_MISS;
                    if (g->surf[0])
                        for (int q = 0; q < VSGL__SURF_N; ++q)
                            g->surf[q][i] = 0.0f;
                    continue;
                }
                vsgl_surface sf;
                vsgl__scene_surface(j->scene, &hit[k], dir[k], &sf);
                store3(g->pos, i, sf.position);
                store3(g->nrm, i, sf.normal);
                store3(g->tan, i, sf.tangent);
                g->material[i] = sf.material;
                if (g->surf[0]) {
                    /* the sample's footprint: its share of the pixel (1/aa of a
                     * side each way) at the hit, on the surface */
                    size_t idx = b + k;
                    uint32_t col = (uint32_t)(idx / spp), s = (uint32_t)(idx % spp);
                    float px = (float)col + ((float)(s % aa) + 0.5f) * inv;
                    float py = (float)row + ((float)(s / aa) + 0.5f) * inv;
                    v3 o1, d1, o2, d2;
                    float t0, t1;
                    vsgl__camera_ray(&j->cam, px + inv, py, &o1, &d1, &t0, &t1);
                    vsgl__camera_ray(&j->cam, px, py + inv, &o2, &d2, &t0, &t1);
                    float t = hit[k].t;
                    v3 p0 = v3_add(org[k], v3_scale(dir[k], t));
                    v3 ex = v3_sub(v3_add(o1, v3_scale(d1, t)), p0), ey = v3_sub(v3_add(o2, v3_scale(d2, t)), p0);
                    v3 cr = v3_cross(ex, ey);
                    float cs = fabsf(v3_dot(sf.geometric_normal, dir[k]));
                    float area = sqrtf(v3_dot(cr, cr)) / fmaxf(cs, 0.02f);
                    float in[VSGL__SURF_N];
                    vsgl__scene_inputs(j->scene, &hit[k], area, in);
                    for (int q = 0; q < VSGL__SURF_N; ++q)
                        g->surf[q][i] = in[q];
                }
            }
        }
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
    }
    free(g->material);
    for (int k = 0; k < VSGL__SURF_N; ++k)
        free(g->surf[k]);
    memset(g, 0, sizeof *g);
}

vsgl_result vsgl__gbuffer_build(vsgl_context *ctx, const vsgl_scene *scene, uint32_t aa, vsgl_gbuffer *out)
{
    if (!scene || !out)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "gbuffer: scene or output is NULL");
    memset(out, 0, sizeof *out);
    if (aa == 0)
        aa = 1;
    if (aa > VSGL__GBUFFER_MAX_AA)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "gbuffer: aa_samples is %u (must be in [1, %d])",
                          (unsigned)aa, VSGL__GBUFFER_MAX_AA);
    const vsgl_camera *cam = vsgl__scene_camera(scene);
    gb_job job;
    job.scene = scene;
    vsgl__camera_model(cam, &job.cam);
    job.aa = aa;
    job.g = out;
    out->width = cam->width;
    out->height = cam->height;
    out->spp = aa * aa;
    out->count = (size_t)cam->width * cam->height * out->spp;
    size_t n = out->count;
    int ok = 1;
    for (int k = 0; k < 3; ++k) {
        ok &= (out->pos[k] = malloc(n * sizeof(float))) != NULL;
        ok &= (out->nrm[k] = malloc(n * sizeof(float))) != NULL;
        ok &= (out->view[k] = malloc(n * sizeof(float))) != NULL;
        ok &= (out->tan[k] = malloc(n * sizeof(float))) != NULL;
    }
    ok &= (out->material = malloc(n * sizeof(uint32_t))) != NULL;
    if (vsgl__scene_textured(scene))
        for (int k = 0; k < VSGL__SURF_N; ++k)
            ok &= (out->surf[k] = malloc(n * sizeof(float))) != NULL;
    if (!ok) {
        vsgl__gbuffer_free(out);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "gbuffer: out of memory for %ux%u pixels x %u samples",
                          (unsigned)cam->width, (unsigned)cam->height, (unsigned)(aa * aa));
    }
    uint32_t threads = vsgl_context_thread_count(ctx);
    uint32_t h = cam->height;
    uint32_t step = (h + VSGL__GBUFFER_STEPS - 1) / VSGL__GBUFFER_STEPS;
    for (uint32_t row = 0; row < h; row += step) {
        uint32_t rows = h - row < step ? h - row : step;
        if (vsgl__progress(ctx, "gbuffer", (float)row / (float)h)) {
            vsgl__gbuffer_free(out);
            return vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "gbuffer: cancelled at row %u of %u", (unsigned)row, (unsigned)h);
        }
        job.row0 = row;
        int32_t r = vsgl__parallel_for(threads, rows, 1, trace_rows, &job);
        if (r != 0) {
            vsgl__gbuffer_free(out);
            return vsgl__fail(ctx, r, "gbuffer: tracing rows %u..%u failed", (unsigned)row, (unsigned)(row + rows - 1));
        }
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
