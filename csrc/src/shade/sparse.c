/* Shading one pixel in S x S (vsgl_render_settings.shade_stride = S > 1).
 *
 * Indirect light changes slowly across a surface, so most of a frame can
 * be interpolated from a sparse set of shaded receivers:
 *  1. anchors: the pixels (S ax, S ay) of a lattice over the image (the last
 *     row and column included), each shaded at its first hit sample
 *     (vsgl__shade_anchors);
 *  2. every other sample takes the light of the four anchors around its
 *     own position in the pixel (so that 2 x 2 samples still anti-alias the
 *     light), weighted bilinearly and by how much each lies on the same
 *     surface (same material, normals within ~6 degrees, off the sample's
 *     tangent plane by at most ~5 % of their distance): a joint bilateral
 *     filter on the G-buffer. A sample is shaded itself where no anchor
 *     shares its surface (an edge, a thin object) or where bilinear
 *     interpolation would be off by more than 4 % of its light, judged from
 *     the anchors' second differences around the cell (SPARSE_TOL below):
 *     the edge of a glossy floor's reflection of a lit wall, which bilinear
 *     weights blurred (the spot room's glossy structured error 3.6x, its
 *     diffuse 2x what these samples give, docs/quality.md)
 *     (vsgl__shade_chunk_sparse).
 * The light of a sample, not its colour, is interpolated: DiffCol and
 * GlossCol stay per pixel. The shading work falls by about S^2 except at
 * edges and where the light bends (at S = 2 and 2 x 2 samples, 320 x 240:
 * 6.1x fewer pairs than shading every sample in the spot room, 6.5x in the
 * sphere room; 8x and 10x with bilinear weights everywhere);
 * tests/c/test_render.c and tests/quality measure the error. */
#include "shade/shade_job.h"
#include "core/context.h"
#include "core/parallel.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>
#if defined(__x86_64__) || defined(__i386__)
#  include <xmmintrin.h>
#endif

/* A same-surface test's tolerances (see the file comment). */
/* Normals within ~6 degrees: a curved surface at a grazing view (a sphere's
 * rim) is shaded where its normal turns faster than that between anchors;
 * with ~25 degrees its rim, interpolated from anchors further inside, jumped
 * as the silhouette crossed them (the sphere room's glossy frame-to-frame
 * change as the camera moves 0.114 -> 0.043 at 80 x 60; 0.053 shading 8 x 8
 * samples in every pixel). Flat surfaces have one normal. */
#define SPARSE_NORMAL_COS 0.995f
#define SPARSE_PLANE_REL 0.05f
/* Interpolate only where bilinear interpolation is accurate: its error at
 * (tx, ty) in a cell is about (tx (1 - tx) d2x + ty (1 - ty) d2y) / 2, d2
 * the anchors' second differences along x and y (from the anchors around
 * the cell on the sample's surface). A sample is shaded itself where that
 * exceeds SPARSE_TOL of its interpolated light plus SPARSE_FLOOR of the
 * frame's mean, per lobe: a step between anchors of more than ~30 %, or a
 * falloff steeper than ~1.8x per anchor (2 % shaded 1.35x the samples of
 * the sphere room for no gain in its error). Where no second difference can be
 * taken (fewer than three anchors in a row on the surface), anchors that
 * differ by more than SPARSE_CONTRAST of their sum. */
#define SPARSE_TOL 0.04f
#define SPARSE_CONTRAST 0.1f
#define SPARSE_FLOOR 0.002f

static size_t anchor_pixel(const shade_job *j, uint32_t ax, uint32_t ay)
{
    const vsgl_gbuffer *g = j->g;
    uint32_t x = ax * j->stride, y = ay * j->stride;
    x = x < g->width ? x : g->width - 1;
    y = y < g->height ? y : g->height - 1;
    return (size_t)y * g->width + x;
}

/* Anchor rows [b, e): shade each anchor's first hit sample. */
static int32_t anchor_rows(void *user, size_t chunk, size_t b, size_t e)
{
    shade_job *j = user;
    (void)chunk;
#if defined(__x86_64__) || defined(__i386__)
    unsigned int saved_csr = _mm_getcsr();
    _mm_setcsr(saved_csr | 0x8040u); /* FTZ | DAZ, as the full-resolution path */
#endif
    const vsgl_gbuffer *g = j->g;
    size_t n_max = (e - b) * j->aw;
    size_t *list = malloc((n_max + 1) * sizeof *list);
    size_t *where = malloc((n_max + 1) * sizeof *where);
    float *light = malloc((n_max + 1) * 6 * sizeof *light);
    int32_t rc = 0;
    if (!list || !where || !light) {
        rc = VSGL_ERROR_OUT_OF_MEMORY;
    } else {
        size_t n = 0;
        for (size_t ay = b; ay < e; ++ay)
            for (uint32_t ax = 0; ax < j->aw; ++ax) {
                size_t a = ay * j->aw + ax, px = anchor_pixel(j, ax, (uint32_t)ay);
                j->anchor_sample[a] = SIZE_MAX;
                for (size_t k = 0; k < g->spp; ++k)
                    if (g->material[px * g->spp + k] != VSGL__GBUFFER_MISS) {
                        j->anchor_sample[a] = px * g->spp + k;
                        list[n] = px * g->spp + k;
                        where[n++] = a;
                        break;
                    }
            }
        j->anchor_pairs[b] = vsgl__shade_list(j, list, n, NULL, light);
        for (size_t k = 0; k < n; ++k)
            memcpy(j->anchor_light + where[k] * 6, light + k * 6, 6 * sizeof *light);
    }
    free(list);
    free(where);
    free(light);
#if defined(__x86_64__) || defined(__i386__)
    _mm_setcsr(saved_csr);
#endif
    return rc;
}

/* How much anchor sample a stands on sample s's surface, in [0, 1]. */
static float same_surface_weight(const shade_job *j, size_t s, size_t a)
{
    const vsgl_gbuffer *g = j->g;
    if (g->material[a] != g->material[s])
        return 0.0f;
    v3 ns = v3_make(g->nrm[0][s], g->nrm[1][s], g->nrm[2][s]);
    v3 na = v3_make(g->nrm[0][a], g->nrm[1][a], g->nrm[2][a]);
    float c = v3_dot(ns, na);
    if (!(c > SPARSE_NORMAL_COS))
        return 0.0f;
    float wn = (c - SPARSE_NORMAL_COS) * (1.0f / (1.0f - SPARSE_NORMAL_COS));
    v3 d = v3_make(g->pos[0][a] - g->pos[0][s], g->pos[1][a] - g->pos[1][s], g->pos[2][a] - g->pos[2][s]);
    float off = fabsf(v3_dot(d, ns)), tol = SPARSE_PLANE_REL * v3_length(d) + j->plane_tol;
    float wp = 1.0f - off / tol;
    if (!(wp > 0.0f))
        return 0.0f;
    return wn * wp;
}

vsgl_result vsgl__shade_anchors(vsgl_context *ctx, shade_job *j)
{
    if (vsgl__parallel_for(vsgl_context_thread_count(ctx), j->ah, 1, anchor_rows, j) != 0)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "shade: out of memory for the sparse anchors");
    /* each anchor's second differences along x and y through its neighbours on its surface */
    for (uint32_t ay = 0; ay < j->ah; ++ay)
        for (uint32_t ax = 0; ax < j->aw; ++ax) {
            size_t a = (size_t)ay * j->aw + ax, as = j->anchor_sample[a];
            float *D = j->anchor_d2 + a * 4;
            D[0] = D[1] = D[2] = D[3] = -1.0f;
            if (as == SIZE_MAX)
                continue;
            for (int axis = 0; axis < 2; ++axis) {
                if (axis == 0 ? (ax == 0 || ax + 1 >= j->aw) : (ay == 0 || ay + 1 >= j->ah))
                    continue;
                size_t step = axis == 0 ? 1 : j->aw, m = a - step, p = a + step;
                size_t ms = j->anchor_sample[m], ps = j->anchor_sample[p];
                if (ms == SIZE_MAX || ps == SIZE_MAX || !(same_surface_weight(j, as, ms) > 0.0f) ||
                    !(same_surface_weight(j, as, ps) > 0.0f))
                    continue;
                for (int l = 0; l < 2; ++l) {
                    const float *A = j->anchor_light + a * 6 + 3 * l, *M = j->anchor_light + m * 6 + 3 * l,
                                *P = j->anchor_light + p * 6 + 3 * l;
                    D[2 * l + axis] = fabsf((M[0] + M[1] + M[2]) - 2.0f * (A[0] + A[1] + A[2]) + (P[0] + P[1] + P[2]));
                }
            }
        }
    /* the interpolation test's floor: a fraction of the frame's mean light per lobe */
    double sum[2] = {0.0, 0.0};
    size_t n = 0;
    for (size_t a = 0; a < (size_t)j->aw * j->ah; ++a) {
        if (j->anchor_sample[a] == SIZE_MAX)
            continue;
        const float *A = j->anchor_light + a * 6;
        sum[0] += (double)A[0] + A[1] + A[2];
        sum[1] += (double)A[3] + A[4] + A[5];
        ++n;
    }
    for (int l = 0; l < 2; ++l)
        j->contrast_floor[l] = n ? (float)(SPARSE_FLOOR * sum[l] / (double)n) : 0.0f;
    return VSGL_OK;
}

int32_t vsgl__shade_chunk_sparse(void *user, size_t chunk, size_t b0, size_t e0)
{
    shade_job *j = user;
    const vsgl_gbuffer *g = j->g;
    const size_t spp = g->spp, W = g->width;
    const size_t first = (j->base + b0) * spp, ns = (e0 - b0) * spp;
    const float inv_s = 1.0f / (float)j->stride;
    /* sample k of pixel (x, y) lies at (x + (k % aa + 0.5) / aa, ...): its
     * offset from the first sample's, where the anchors were shaded */
    const uint32_t aa = g->weight && spp == 2 ? 1u : (uint32_t)(sqrtf((float)spp) + 0.5f);
    const float inv_aa = 1.0f / (float)aa;
    float *interp = malloc((ns + 1) * 6 * sizeof *interp);
    size_t *direct = malloc((ns + 1) * sizeof *direct);
    size_t *direct_of = malloc((ns + 1) * sizeof *direct_of); /* per sample: index in direct, or SIZE_MAX */
    float *dlight = malloc((ns + 1) * 6 * sizeof *dlight);
    int32_t rc = 0;
    if (!interp || !direct || !direct_of || !dlight) {
        rc = VSGL_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    size_t nd = 0;
    for (size_t i = 0; i < ns; ++i) {
        size_t si = first + i, px = si / spp;
        direct_of[i] = SIZE_MAX;
        if (g->material[si] == VSGL__GBUFFER_MISS)
            continue;
        /* the anchor cell around the sample: its raster position against
         * the anchors' (each shaded at its pixel's first sample) */
        size_t k = si % spp;
        float ox = k < aa * aa ? (float)(k % aa) * inv_aa : 0.0f, oy = k < aa * aa ? (float)(k / aa) * inv_aa : 0.0f;
        float fx = ((float)(px % W) + ox) * inv_s, fy = ((float)(px / W) + oy) * inv_s;
        uint32_t ax = (uint32_t)fx, ay = (uint32_t)fy;
        float tx = fx - (float)ax, ty = fy - (float)ay;
        float wsum = 0.0f, L[6] = {0, 0, 0, 0, 0, 0};
        float lo[2] = {FLT_MAX, FLT_MAX}, hi[2] = {0.0f, 0.0f}, dx2[2] = {-1.0f, -1.0f}, dy2[2] = {-1.0f, -1.0f};
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
                uint32_t cx = ax + (uint32_t)dx, cy = ay + (uint32_t)dy;
                if (cx >= j->aw || cy >= j->ah)
                    continue;
                size_t a = (size_t)cy * j->aw + cx, as = j->anchor_sample[a];
                float wb = (dx ? tx : 1.0f - tx) * (dy ? ty : 1.0f - ty);
                if (as == SIZE_MAX || !(wb > 0.0f))
                    continue;
                float w = wb * (as == si ? 1.0f : same_surface_weight(j, si, as));
                if (!(w > 0.0f))
                    continue;
                wsum += w;
                const float *A = j->anchor_light + a * 6;
                for (int c = 0; c < 6; ++c)
                    L[c] += w * A[c];
                const float *D = j->anchor_d2 + a * 4;
                for (int l = 0; l < 2; ++l) {
                    float v = A[3 * l] + A[3 * l + 1] + A[3 * l + 2];
                    lo[l] = v < lo[l] ? v : lo[l];
                    hi[l] = v > hi[l] ? v : hi[l];
                    dx2[l] = D[2 * l] > dx2[l] ? D[2 * l] : dx2[l];
                    dy2[l] = D[2 * l + 1] > dy2[l] ? D[2 * l + 1] : dy2[l];
                }
            }
        /* where bilinear interpolation would be off by more than SPARSE_TOL
         * (a reflection's edge, a shadow's), the sample is shaded itself */
        int smooth = 1;
        if (wsum > 0.05f) {
            for (int l = 0; l < 2; ++l) {
                float m = (L[3 * l] + L[3 * l + 1] + L[3 * l + 2]) / wsum;
                float bound = SPARSE_TOL * m + j->contrast_floor[l];
                if (dx2[l] < 0.0f && dy2[l] < 0.0f) {
                    smooth &= !(hi[l] - lo[l] > SPARSE_CONTRAST * (hi[l] + lo[l]) + j->contrast_floor[l]);
                    continue;
                }
                float e = 0.5f * ((dx2[l] > 0.0f ? tx * (1.0f - tx) * dx2[l] : 0.0f) +
                                  (dy2[l] > 0.0f ? ty * (1.0f - ty) * dy2[l] : 0.0f));
                smooth &= !(e > bound);
            }
        }
        if (wsum > 0.05f && smooth) {
            for (int c = 0; c < 6; ++c)
                interp[i * 6 + c] = L[c] / wsum;
        } else {
            direct_of[i] = nd;
            direct[nd++] = si;
        }
    }
#if defined(__x86_64__) || defined(__i386__)
    unsigned int saved_csr = _mm_getcsr();
    _mm_setcsr(saved_csr | 0x8040u);
#endif
    j->pairs[chunk] = vsgl__shade_list(j, direct, nd, NULL, dlight);
#if defined(__x86_64__) || defined(__i386__)
    _mm_setcsr(saved_csr);
#endif
    const float *Ls[VSGL__GBUFFER_MAX_SPP];
    for (size_t px = j->base + b0; px < j->base + e0; ++px) {
        for (size_t k = 0; k < spp; ++k) {
            size_t i = (px - j->base - b0) * spp + k;
            if (g->material[first + i] == VSGL__GBUFFER_MISS)
                Ls[k] = NULL;
            else
                Ls[k] = direct_of[i] != SIZE_MAX ? dlight + direct_of[i] * 6 : interp + i * 6;
        }
        vsgl__write_pixel(j, px, Ls);
    }
done:
    free(interp);
    free(direct);
    free(direct_of);
    free(dlight);
    return rc;
}
