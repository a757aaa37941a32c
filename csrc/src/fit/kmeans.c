/* N VSGLs per light by k-means-style clustering in image + world space
 * (the FIS supplement's comparison, Sec. 5): centres drawn by importance
 * like FIS, every VPL assigned to its nearest centre, one VSGL pair per
 * cluster from the exact sums (no re-weighting needed: a partition). */
#include "fit/grid.h"
#include "core/context.h"
#include "core/parallel.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

typedef struct centre {
    uint32_t face;
    float x, y;          /* level-0 texel coordinates */
    v3 p;                /* world position */
    v3 n;                /* the centre texel's normal (0 if it has none) */
} centre;

/* The cost of a VPL whose normal is perpendicular to a centre's, on the
 * scale of the image and world terms (1: as far as another cube face). A
 * cluster then does not straddle a crease: one spanning the corner of two
 * walls had its mean off both, 0.12 m from a wall it partly lies on, and its
 * normals too incoherent for the emitter clip; it lit that wall ~85x too
 * brightly (sun_opening, k-means 256, a blotch by the window wall). */
#define KMEANS_NORMAL_WEIGHT 1.0f

typedef struct assign_job {
    const vsgl_rsm *rsm;
    const vsgl_grid *g;
    const centre *c;
    uint32_t n;
    float image_weight, world_weight; /* 1/res^2 and 1/diag^2 */
    uint32_t *label;     /* per rsm texel, UINT32_MAX = no power */
} assign_job;

static int32_t assign_chunk(void *user, size_t chunk, size_t b, size_t e)
{
    (void)chunk;
    assign_job *j = user;
    const vsgl_rsm *r = j->rsm;
    size_t per_face = (size_t)r->res * r->res;
    for (size_t t = b; t < e; ++t) {
        uint32_t face = (uint32_t)(t / per_face);
        size_t rem = t % per_face;
        size_t gi = ((size_t)face * j->g->res + rem / r->res) * j->g->res + rem % r->res;
        const float *m = j->g->level[0].data + gi * VSGL__GRID_STRIDE;
        if (!(m[0] + m[VSGL__GRID_FIELDS] > 0.0f)) {
            j->label[t] = UINT32_MAX;
            continue;
        }
        float x = (float)(rem % r->res) + 0.5f, y = (float)(rem / r->res) + 0.5f;
        v3 p = v3_make(r->pos[0][t], r->pos[1][t], r->pos[2][t]);
        v3 nt = v3_make(r->nrm[0][t], r->nrm[1][t], r->nrm[2][t]);
        float best = FLT_MAX;
        uint32_t arg = 0;
        for (uint32_t k = 0; k < j->n; ++k) {
            const centre *c = &j->c[k];
            float di = 1.0f;
            if (c->face == face) {
                float dx = x - c->x, dy = y - c->y;
                di = (dx * dx + dy * dy) * j->image_weight;
            }
            v3 d = v3_sub(p, c->p);
            float dist = di + v3_dot(d, d) * j->world_weight;
            dist += KMEANS_NORMAL_WEIGHT * (1.0f - v3_dot(nt, c->n));
            if (dist < best) {
                best = dist;
                arg = k;
            }
        }
        j->label[t] = arg;
    }
    return 0;
}

vsgl_result vsgl__fit_kmeans(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm,
                             const vsgl_render_settings *s, vsgl_vsgl_set *out)
{
    uint32_t n_clusters = s->vsgl_count ? s->vsgl_count : 64;
    vsgl_grid g;
    vsgl_result r = vsgl__grid_build(ctx, scene, rsm, s->sharpness_estimator, 0, &g);
    if (r != VSGL_OK)
        return r;
    size_t n = (size_t)g.faces * g.res * g.res;
    double *cdf = vsgl__importance_cdf(&g, n);
    centre *c = malloc((size_t)n_clusters * sizeof *c);
    uint32_t *label = malloc(rsm->count * sizeof *label);
    double *sums = calloc((size_t)n_clusters * VSGL__GRID_STRIDE, sizeof *sums);
    if (!cdf || !c || !label || !sums) {
        r = vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "fit: out of memory for %u k-means clusters", n_clusters);
        goto done;
    }
    if (!(cdf[n] > 0.0))
        goto done;
    for (uint32_t i = 0; i < n_clusters; ++i) {
        uint32_t tx, ty;
        size_t t = vsgl__stratified_texel(&g, cdf, n, s->seed, rsm->light, i, n_clusters, &c[i].face, &tx, &ty);
        c[i].x = (float)tx + 0.5f;
        c[i].y = (float)ty + 0.5f;
        /* the texel's mean position from its moments */
        const float *m = g.level[0].data + t * VSGL__GRID_STRIDE;
        double w = (double)m[0] + m[VSGL__GRID_FIELDS];
        c[i].p = v3_make((float)(g.origin.x + (m[7] + m[VSGL__GRID_FIELDS + 7]) / w),
                         (float)(g.origin.y + (m[8] + m[VSGL__GRID_FIELDS + 8]) / w),
                         (float)(g.origin.z + (m[9] + m[VSGL__GRID_FIELDS + 9]) / w));
        c[i].n = v3_make(0.0f, 0.0f, 0.0f);
        if (tx < rsm->res && ty < rsm->res) {
            size_t ri = ((size_t)c[i].face * rsm->res + ty) * rsm->res + tx;
            c[i].n = v3_make(rsm->nrm[0][ri], rsm->nrm[1][ri], rsm->nrm[2][ri]);
        }
    }
    v3 lo, hi;
    vsgl__scene_bounds(scene, &lo, &hi);
    v3 diag = v3_sub(hi, lo);
    float diag2 = v3_dot(diag, diag);
    assign_job j = {rsm, &g, c, n_clusters, 1.0f / ((float)rsm->res * (float)rsm->res),
                    diag2 > 0.0f ? 1.0f / diag2 : 1.0f, label};
    vsgl__parallel_for(vsgl_context_thread_count(ctx), rsm->count, 1024, assign_chunk, &j);
    /* Sequential accumulation in texel order: deterministic for any thread count. */
    size_t per_face = (size_t)rsm->res * rsm->res;
    for (size_t t = 0; t < rsm->count; ++t) {
        if (label[t] == UINT32_MAX)
            continue;
        size_t rem = t % per_face;
        size_t gi = ((t / per_face) * g.res + rem / rsm->res) * g.res + rem % rsm->res;
        const float *m = g.level[0].data + gi * VSGL__GRID_STRIDE;
        double *dst = sums + (size_t)label[t] * VSGL__GRID_STRIDE;
        for (int k = 0; k < VSGL__GRID_STRIDE; ++k)
            dst[k] += m[k];
    }
    for (uint32_t k = 0; k < n_clusters && r == VSGL_OK; ++k)
        for (uint32_t lobe = 0; lobe < 2 && r == VSGL_OK; ++lobe) {
            vsgl_moments m;
            vsgl_vsgl v;
            vsgl__grid_moments(sums + (size_t)k * VSGL__GRID_STRIDE + lobe * VSGL__GRID_FIELDS, &m);
            if (vsgl__moments_to_vsgl(&m, g.origin, s->sharpness_estimator, rsm->light, lobe, &v))
                r = vsgl__vsgl_set_push(out, &v);
        }
    if (r != VSGL_OK)
        r = vsgl__fail(ctx, r, "fit: out of memory");
done:
    free(cdf);
    free(c);
    free(label);
    free(sums);
    vsgl__grid_free(&g);
    return r;
}
