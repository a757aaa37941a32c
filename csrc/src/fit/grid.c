/* Moment grid of an RSM and its mip pyramid of block sums. */
#include "fit/grid.h"
#include "core/context.h"
#include "core/parallel.h"

#include <stdlib.h>
#include <string.h>

typedef struct grid_job {
    const vsgl_scene *scene;
    const vsgl_rsm *rsm;
    vsgl_grid *g;
    int32_t estimator;
    double *partial;   /* per chunk: VSGL__GRID_STRIDE sums + valid count */
} grid_job;

static void pack(const vsgl_moments *m, float *f)
{
    f[0] = (float)m->weight;
    for (int c = 0; c < 3; ++c) {
        f[1 + c] = (float)m->power[c];
        f[4 + c] = (float)m->dir[c];
        f[7 + c] = (float)m->pos[c];
    }
    f[10] = (float)m->pos2;
    for (int c = 0; c < 3; ++c)
        f[11 + c] = (float)m->nrm[c];
}

void vsgl__grid_moments(const double *f, vsgl_moments *m)
{
    m->weight = f[0];
    for (int c = 0; c < 3; ++c) {
        m->power[c] = f[1 + c];
        m->dir[c] = f[4 + c];
        m->pos[c] = f[7 + c];
    }
    m->pos2 = f[10];
    for (int c = 0; c < 3; ++c)
        m->nrm[c] = f[11 + c];
}

static int32_t level0_chunk(void *user, size_t chunk, size_t b, size_t e)
{
    grid_job *j = user;
    const vsgl_rsm *r = j->rsm;
    vsgl_grid *g = j->g;
    double *acc = j->partial + chunk * (VSGL__GRID_STRIDE + 1);
    for (size_t t = b; t < e; ++t) {
        size_t face = t / ((size_t)r->res * r->res);
        size_t rem = t % ((size_t)r->res * r->res);
        size_t row = rem / r->res, col = rem % r->res;
        float *dst = g->level[0].data + ((face * g->res + row) * g->res + col) * VSGL__GRID_STRIDE;
        vsgl_moments m[2];
        if (!vsgl__vpl_moments(j->scene, r, t, g->origin, j->estimator, m))
            continue;
        pack(&m[0], dst);
        pack(&m[1], dst + VSGL__GRID_FIELDS);
        for (int k = 0; k < VSGL__GRID_STRIDE; ++k)
            acc[k] += dst[k];
        acc[VSGL__GRID_STRIDE] += 1.0;
    }
    return 0;
}

void vsgl__grid_free(vsgl_grid *g)
{
    for (uint32_t l = 0; l < g->levels; ++l)
        free(g->level[l].data);
    memset(g, 0, sizeof *g);
}

vsgl_result vsgl__grid_build(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm,
                             int32_t estimator, int mips, vsgl_grid *g)
{
    memset(g, 0, sizeof *g);
    g->faces = rsm->faces;
    uint32_t side = 1;
    while (side < rsm->res)
        side *= 2;
    g->res = side;
    g->origin = vsgl__rsm_origin(rsm);
    g->levels = 1;
    if (mips)
        while ((side >> (g->levels - 1)) > 1)
            ++g->levels;
    for (uint32_t l = 0; l < g->levels; ++l) {
        g->level[l].side = side >> l;
        size_t n = (size_t)g->faces * g->level[l].side * g->level[l].side * VSGL__GRID_STRIDE;
        g->level[l].data = calloc(n, sizeof(float));
        if (!g->level[l].data) {
            vsgl__grid_free(g);
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "fit: out of memory for a %u^2 moment grid", side);
        }
    }
    enum { CHUNK = 4096 };
    size_t chunks = vsgl__chunk_count(rsm->count, CHUNK);
    grid_job j = {scene, rsm, g, estimator, calloc(chunks * (VSGL__GRID_STRIDE + 1) + 1, sizeof(double))};
    if (!j.partial) {
        vsgl__grid_free(g);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "fit: out of memory");
    }
    vsgl__parallel_ctx(ctx, rsm->count, CHUNK, level0_chunk, &j);
    for (size_t c = 0; c < chunks; ++c) {
        const double *p = j.partial + c * (VSGL__GRID_STRIDE + 1);
        for (int k = 0; k < VSGL__GRID_STRIDE; ++k)
            g->total[k] += p[k];
        g->valid += (size_t)p[VSGL__GRID_STRIDE];
    }
    free(j.partial);
    for (uint32_t l = 1; l < g->levels; ++l) {
        uint32_t s = g->level[l].side, ps = g->level[l - 1].side;
        for (uint32_t f = 0; f < g->faces; ++f)
            for (uint32_t y = 0; y < s; ++y)
                for (uint32_t x = 0; x < s; ++x) {
                    float *d = g->level[l].data + (((size_t)f * s + y) * s + x) * VSGL__GRID_STRIDE;
                    for (uint32_t dy = 0; dy < 2; ++dy)
                        for (uint32_t dx = 0; dx < 2; ++dx) {
                            const float *src = g->level[l - 1].data +
                                (((size_t)f * ps + 2 * y + dy) * ps + 2 * x + dx) * VSGL__GRID_STRIDE;
                            for (int k = 0; k < VSGL__GRID_STRIDE; ++k)
                                d[k] += src[k];
                        }
                }
    }
    return VSGL_OK;
}

static void sample_level(const vsgl_grid *g, uint32_t face, float x, float y, uint32_t l, double *out)
{
    const vsgl_grid_level *lv = &g->level[l];
    float scale = 1.0f / (float)(1u << l);
    float fx = x * scale - 0.5f, fy = y * scale - 0.5f;
    float x0f = floorf(fx), y0f = floorf(fy);
    float tx = fx - x0f, ty = fy - y0f;
    int x0 = (int)x0f, y0 = (int)y0f, s = (int)lv->side;
    for (int k = 0; k < VSGL__GRID_STRIDE; ++k)
        out[k] = 0.0;
    for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
            int xx = x0 + dx, yy = y0 + dy;
            xx = xx < 0 ? 0 : (xx >= s ? s - 1 : xx);
            yy = yy < 0 ? 0 : (yy >= s ? s - 1 : yy);
            double w = (dx ? tx : 1.0f - tx) * (dy ? ty : 1.0f - ty);
            const float *src = lv->data + (((size_t)face * lv->side + (size_t)yy) * lv->side + (size_t)xx) * VSGL__GRID_STRIDE;
            for (int k = 0; k < VSGL__GRID_STRIDE; ++k)
                out[k] += w * src[k];
        }
}

void vsgl__grid_sample(const vsgl_grid *g, uint32_t face, float x, float y, float l, double out[VSGL__GRID_STRIDE])
{
    float top = (float)(g->levels - 1);
    l = l < 0.0f ? 0.0f : (l > top ? top : l);
    uint32_t l0 = (uint32_t)l;
    float t = l - (float)l0;
    sample_level(g, face, x, y, l0, out);
    if (t > 0.0f && l0 + 1 < g->levels) {
        double hi[VSGL__GRID_STRIDE];
        sample_level(g, face, x, y, l0 + 1, hi);
        for (int k = 0; k < VSGL__GRID_STRIDE; ++k)
            out[k] = out[k] * (1.0 - t) + hi[k] * t;
    }
}
