/* Visibility against a handful of occluders, without Embree.
 *
 * A segment strictly inside the scene's bounds can meet only the triangles
 * off the bounds' faces (occluders.c). When those are few (a cabinet, a
 * block: VSGL__OCC_FEW at most), testing each of a batch's segments against
 * every one of them, vectorised over the segments, costs less than
 * Embree's stream of the same rays, whose cost per ray is mostly its own
 * set-up: in sun_opening (10 occluders of 28 triangles) Embree and the
 * rays' packing were a quarter of the balanced render at 960 x 540; its
 * shade stage 0.69 -> 0.56 s (docs/performance.md). With 34 (the
 * thick-walled sun room) the test costs more than Embree, and a BVH of the
 * occluders alone was slower than the whole scene's: both were measured
 * and dropped. Built with -O3 and cloned for AVX-512 / AVX2 (Makefile), as
 * the shading kernel is. */
#include "scene/scene_data.h"

#include <math.h>
#include <stdlib.h>

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#  define FEW_ATTR __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#  define FEW_ATTR
#endif

/* Barycentric slack: the edges are closed a little (a ray along the shared
 * edge of two triangles is blocked by both, never by neither), where
 * Embree's robust test is watertight; the answers differ only for rays
 * within ~1e-6 of an occluder's edge. */
#define VSGL__FEW_SLACK 1e-6f

vsgl_result vsgl__scene_build_few(vsgl_context *ctx, vsgl_scene *s, const uint32_t *ids, uint32_t n)
{
    s->occ_few = malloc(sizeof(float) * 12 * (size_t)(n ? n : 1));
    if (!s->occ_few)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: no memory for the %u occluders", n);
    for (uint32_t i = 0; i < n; ++i) {
        const float *p[3];
        for (int k = 0; k < 3; ++k)
            p[k] = s->positions + 3 * (size_t)s->indices[3 * (size_t)ids[i] + k];
        float *o = s->occ_few + 12 * (size_t)i;
        for (int a = 0; a < 3; ++a) {
            o[a] = p[0][a];
            o[3 + a] = p[1][a] - p[0][a];
            o[6 + a] = p[2][a] - p[0][a];
        }
        o[9] = o[4] * o[8] - o[5] * o[7]; /* n = e1 x e2 */
        o[10] = o[5] * o[6] - o[3] * o[8];
        o[11] = o[3] * o[7] - o[4] * o[6];
    }
    s->occ_few_count = n;
    return VSGL_OK;
}

/* hit[i] = 1 if segment i, o + t e for t in [0, reach[i]] (e not unit),
 * meets one of the scene's few occluders, for i < m. Moeller-Trumbore in
 * triple products, without its divisions: with n = e1 x e2, w = s x e
 * (s = o - v0) and det = -e.n, the hit's u = e2.w / det, v = -e1.w / det,
 * t = s.n / det; each compared with det's sign taken out. */
FEW_ATTR
void vsgl__scene_occluded_few(const vsgl_scene *s, uint32_t m, const float *restrict ox, const float *restrict oy,
                              const float *restrict oz, const float *restrict ex, const float *restrict ey,
                              const float *restrict ez, const float *restrict reach, unsigned char *restrict hit)
{
    int h[VSGL__OCC_STREAM];
    for (uint32_t i = 0; i < m; ++i)
        h[i] = 0;
    for (uint32_t t = 0; t < s->occ_few_count; ++t) {
        const float *T = s->occ_few + 12 * (size_t)t;
        const float vx = T[0], vy = T[1], vz = T[2], ax = T[3], ay = T[4], az = T[5], bx = T[6], by = T[7],
                    bz = T[8], nx = T[9], ny = T[10], nz = T[11];
        for (uint32_t i = 0; i < m; ++i) {
            float sx = ox[i] - vx, sy = oy[i] - vy, sz = oz[i] - vz;
            float wx = sy * ez[i] - sz * ey[i], wy = sz * ex[i] - sx * ez[i], wz = sx * ey[i] - sy * ex[i];
            float det = -(ex[i] * nx + ey[i] * ny + ez[i] * nz);
            float sg = det < 0.0f ? -1.0f : 1.0f, ad = det * sg;
            float u = (bx * wx + by * wy + bz * wz) * sg, v = -(ax * wx + ay * wy + az * wz) * sg;
            float d = (sx * nx + sy * ny + sz * nz) * sg, slack = VSGL__FEW_SLACK * ad;
            h[i] |= (ad > 0.0f) & (u >= -slack) & (v >= -slack) & (u + v <= ad + slack) & (d >= 0.0f) &
                    (d <= reach[i] * ad);
        }
    }
    for (uint32_t i = 0; i < m; ++i)
        hit[i] = (unsigned char)h[i];
}

/* Segments o + t e, t in [0, 1], i < m, shortened by eps at their far end:
 * inv[i] = 1 / |e|, reach[i] = 1 - eps / |e|, route[i] 0 (eps long or
 * less: no ray), 1 (trace against the whole scene) or 2 (both ends strictly
 * inside the bounds: only the occluders can block it). Vectorised as the
 * test above (the batch's set-up was 14 % of the sun room's render in
 * scalar code). */
FEW_ATTR
void vsgl__scene_segments_route(const vsgl_scene *s, uint32_t m, const float *restrict ox,
                                const float *restrict oy, const float *restrict oz, const float *restrict ex,
                                const float *restrict ey, const float *restrict ez, float eps, float *restrict inv,
                                float *restrict reach, int *restrict route)
{
    for (uint32_t i = 0; i < m; ++i) {
        float dist = sqrtf(ex[i] * ex[i] + ey[i] * ey[i] + ez[i] * ez[i]);
        inv[i] = 1.0f / dist;
        reach[i] = 1.0f - eps * inv[i];
        int in = vsgl__scene_strictly_inside(s, ox[i], oy[i], oz[i]) &
                 vsgl__scene_strictly_inside(s, ox[i] + ex[i] * reach[i], oy[i] + ey[i] * reach[i],
                                             oz[i] + ez[i] * reach[i]);
        route[i] = dist > eps ? 1 + in : 0;
    }
}
