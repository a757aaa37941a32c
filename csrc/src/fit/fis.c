/* N VSGLs per light by filtered importance sampling (Tokuyoshi 2016, FIS
 * supplement Sec. 3.3 and Algorithm 1): cluster centres drawn with
 * probability proportional to VPL power (stratified inverse CDF), the mip
 * level of each by bisection so that a cluster carries about 1/N of the
 * light's power, and each cluster's sums weighted by 1/(N * mass) so the
 * estimate of the whole map is unbiased. N = 1 is the whole map, i.e. the
 * two-VSGL fit. */
#include "fit/grid.h"
#include "core/context.h"

#include <stdlib.h>
#include <string.h>

static uint64_t mix64(uint64_t z)
{
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

float vsgl__hash_uniform(uint32_t seed, uint32_t light, uint32_t index, uint32_t dim)
{
    uint64_t h = mix64(((uint64_t)seed << 32) ^ light);
    h = mix64(h ^ ((uint64_t)index << 8) ^ dim);
    return (float)(h >> 40) * 0x1.0p-24f;
}

double *vsgl__importance_cdf(const vsgl_grid *g, size_t n)
{
    double *cdf = malloc((n + 1) * sizeof *cdf);
    if (!cdf)
        return NULL;
    cdf[0] = 0.0;
    const float *d = g->level[0].data;
    for (size_t t = 0; t < n; ++t) {
        double w = (double)d[t * VSGL__GRID_STRIDE] + (double)d[t * VSGL__GRID_STRIDE + VSGL__GRID_FIELDS];
        cdf[t + 1] = cdf[t] + (w > 0.0 ? w : 0.0);
    }
    return cdf;
}

size_t vsgl__find_texel(const double *cdf, size_t n, double target)
{
    size_t lo = 0, hi = n; /* first t with cdf[t+1] > target */
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (cdf[mid + 1] > target)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo < n ? lo : n - 1;
}

size_t vsgl__stratified_texel(const vsgl_grid *g, const double *cdf, size_t n, uint32_t seed, uint32_t light,
                              uint32_t i, uint32_t count, uint32_t *face, uint32_t *x, uint32_t *y)
{
    double u = (i + vsgl__hash_uniform(seed, light, i, 0)) / count;
    size_t t = vsgl__find_texel(cdf, n, u * cdf[n]);
    size_t per_face = (size_t)g->res * g->res, rem = t % per_face;
    *face = (uint32_t)(t / per_face);
    *x = (uint32_t)(rem % g->res);
    *y = (uint32_t)(rem / g->res);
    return t;
}

static double mass_at(const vsgl_grid *g, uint32_t face, float x, float y, float l, double total, double *s)
{
    vsgl__grid_sample(g, face, x, y, l, s);
    return (s[0] + s[VSGL__GRID_FIELDS]) / total;
}

static vsgl_result push_cluster(const double *s, double scale, const vsgl_grid *g, int32_t estimator,
                                uint32_t light, vsgl_vsgl_set *out)
{
    for (uint32_t lobe = 0; lobe < 2; ++lobe) {
        vsgl_moments m, scaled;
        vsgl__grid_moments(s + lobe * VSGL__GRID_FIELDS, &m);
        memset(&scaled, 0, sizeof scaled);
        vsgl__moments_add(&scaled, &m, scale);
        vsgl_vsgl v;
        if (vsgl__moments_to_vsgl(&scaled, g->origin, estimator, light, lobe, &v)) {
            vsgl_result r = vsgl__vsgl_set_push(out, &v);
            if (r != VSGL_OK)
                return r;
        }
    }
    return VSGL_OK;
}

vsgl_result vsgl__fit_fis(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm,
                          const vsgl_render_settings *s, vsgl_vsgl_set *out)
{
    uint32_t n_clusters = s->vsgl_count ? s->vsgl_count : 64;
    vsgl_grid g;
    vsgl_result r = vsgl__grid_build(ctx, scene, rsm, s->sharpness_estimator, n_clusters > 1, &g);
    if (r != VSGL_OK)
        return r;
    double total = g.total[0] + g.total[VSGL__GRID_FIELDS];
    if (!(total > 0.0)) {
        vsgl__grid_free(&g);
        return VSGL_OK;
    }
    if (n_clusters == 1 || g.valid <= 1) {
        r = push_cluster(g.total, 1.0, &g, s->sharpness_estimator, rsm->light, out);
        vsgl__grid_free(&g);
        return r == VSGL_OK ? VSGL_OK : vsgl__fail(ctx, r, "fit: out of memory");
    }
    size_t n = (size_t)g.faces * g.res * g.res;
    double *cdf = vsgl__importance_cdf(&g, n);
    if (!cdf) {
        vsgl__grid_free(&g);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "fit: out of memory for the importance table");
    }
    uint32_t iterations = s->fis_iterations ? s->fis_iterations : 8;
    double target = 1.0 / n_clusters; /* K / N with K = 1 */
    double sums[VSGL__GRID_STRIDE];
    for (uint32_t i = 0; i < n_clusters && r == VSGL_OK; ++i) {
        uint32_t face, tx, ty;
        (void)vsgl__stratified_texel(&g, cdf, n, s->seed, rsm->light, i, n_clusters, &face, &tx, &ty);
        float x = (float)tx + vsgl__hash_uniform(s->seed, rsm->light, i, 1);
        float y = (float)ty + vsgl__hash_uniform(s->seed, rsm->light, i, 2);
        float lmin = 0.0f, lmax = (float)(g.levels - 1);
        for (uint32_t k = 0; k < iterations; ++k) {
            float l = 0.5f * (lmin + lmax);
            if (mass_at(&g, face, x, y, l, total, sums) < target)
                lmin = l;
            else
                lmax = l;
        }
        double mass = mass_at(&g, face, x, y, 0.5f * (lmin + lmax), total, sums);
        if (mass > 0.0)
            r = push_cluster(sums, 1.0 / (n_clusters * mass), &g, s->sharpness_estimator, rsm->light, out);
    }
    free(cdf);
    vsgl__grid_free(&g);
    return r == VSGL_OK ? VSGL_OK : vsgl__fail(ctx, r, "fit: out of memory");
}
