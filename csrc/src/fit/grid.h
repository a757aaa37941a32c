/* Internal: per-texel moment sums of an RSM as a float grid with a mip
 * pyramid of block sums (FIS) — shared by the FIS and k-means fits. */
#ifndef VSGL_FIT_GRID_H
#define VSGL_FIT_GRID_H

#include "fit/vsgl_set.h"

#define VSGL__GRID_FIELDS 14 /* weight, power[3], dir[3], pos[3], pos2, nrm[3] */
#define VSGL__GRID_STRIDE (2 * VSGL__GRID_FIELDS) /* diffuse then specular */

typedef struct vsgl_grid_level {
    uint32_t side;       /* texels per side of each face at this level */
    float *data;         /* faces * side * side * VSGL__GRID_STRIDE block sums */
} vsgl_grid_level;

typedef struct vsgl_grid {
    uint32_t faces, res, levels; /* level 0 = res (padded to a power of two) */
    vsgl_grid_level level[24];
    v3 origin;
    double total[VSGL__GRID_STRIDE]; /* whole-map sums (double, fixed order) */
    size_t valid;        /* texels carrying power */
} vsgl_grid;

/* Level 0 from the RSM (parallel) and, if `mips`, the pyramid. */
vsgl_result vsgl__grid_build(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm,
                             int32_t estimator, int mips, vsgl_grid *out);
void vsgl__grid_free(vsgl_grid *g);

/* Block sums at continuous level l in [0, levels-1] around level-0 texel
 * coordinates (x, y) of `face`: bilinear within a level, linear between
 * levels, clamp to edge. */
void vsgl__grid_sample(const vsgl_grid *g, uint32_t face, float x, float y, float l,
                       double out[VSGL__GRID_STRIDE]);

/* Unpack one lobe of a sample into moments. */
void vsgl__grid_moments(const double *lobe_fields, vsgl_moments *out);

/* Deterministic uniform in [0,1) from (seed, light, index, dimension). */
float vsgl__hash_uniform(uint32_t seed, uint32_t light, uint32_t index, uint32_t dim);

/* Prefix sums (n + 1 entries) of level-0 texel importance (both lobes'
 * weights), double precision; NULL if out of memory. */
double *vsgl__importance_cdf(const vsgl_grid *g, size_t n);

/* The texel t with cdf[t] <= target < cdf[t + 1]. */
size_t vsgl__find_texel(const double *cdf, size_t n, double target);

/* Stratified importance sampling of level-0 texels: sample i of `count`
 * (u = (i + hash) / count through the CDF) for (seed, light); returns the
 * texel index and its face and integer texel coordinates. FIS and k-means
 * seed their clusters with it. */
size_t vsgl__stratified_texel(const vsgl_grid *g, const double *cdf, size_t n, uint32_t seed, uint32_t light,
                              uint32_t i, uint32_t count, uint32_t *face, uint32_t *x, uint32_t *y);

#endif
