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
 *     (vsgl__shade_sparse_batch). So is every slot of a pixel that edge
 *     refinement rewrote (gbuffer.h vsgl__gbuffer_refined): a slot there
 *     stands for a group of rays anywhere in the pixel, not for a
 *     position in the anchor cell, and interpolated at its grid position
 *     it took the anchors' light in some frames and its own in others (the
 *     corridor's end-wall edges as the camera moved; docs/accuracy.md,
 *     "Edges that move in steps"). That shades ~3 % more pairs. Beside a
 *     junction, where no anchor sees the light bend, an anchor's second
 *     difference is taken from its light's step towards the junction
 *     (sparse.h, SPARSE_JUNCTION_SLOPE).
 * The light of a sample, not its colour, is interpolated: DiffCol and
 * GlossCol stay per pixel. The shading work falls by about S^2 except at
 * edges and where the light bends (at S = 2 and 2 x 2 samples, 320 x 240:
 * 6.1x fewer pairs than shading every sample in the spot room, 6.5x in the
 * sphere room; 8x and 10x with bilinear weights everywhere);
 * tests/c/test_render.c and tests/quality measure the error.
 *
 * This file: the anchors, and a render that records a plan or has none
 * (classify, shade, resolve). sparse_replay.c replays a plan (a light
 * edit); sparse_plan.c allocates plans. */

#include "shade/sparse.h"
#include "core/parallel.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>
#if defined(__x86_64__) || defined(__i386__)
#  include <xmmintrin.h>
#endif
#if defined(__SSE2__)
#  include <emmintrin.h>
#endif

static size_t anchor_pixel(const shade_job *j, uint32_t ax, uint32_t ay)
{
    const vsgl_gbuffer *g = j->g;
    uint32_t x = ax * j->stride, y = ay * j->stride;
    x = x < g->width ? x : g->width - 1;
    y = y < g->height ? y : g->height - 1;
    return (size_t)y * g->width + x;
}

static float same_surface_weight(const shade_job *j, size_t s, size_t a);

/* Hit anchors [b, e) of j->alist, packed into full kernel blocks (their
 * order is the raster order of the anchors, whatever the rows). */
static int32_t anchor_blocks(void *user, size_t chunk, size_t b, size_t e)
{
    shade_job *j = user;
#if defined(__x86_64__) || defined(__i386__)
    unsigned int saved_csr = _mm_getcsr();
    _mm_setcsr(saved_csr | 0x8040u); /* FTZ | DAZ, as the full-resolution path */
#endif
    vsgl_shade_plan *plan = j->plan;
    size_t n = e - b;
    size_t *list = malloc((n + 1) * sizeof *list);
    const vsgl__plan_lane **from = malloc((n + 1) * sizeof *from);
    float *light = malloc((n + 1) * 6 * sizeof *light);
    vsgl__plan_lane *lanes = plan && !j->replay ? malloc((n + 1) * sizeof *lanes) : NULL;
    int32_t rc = 0;
    if (!list || !from || !light || (plan && !j->replay && !lanes)) {
        rc = VSGL_ERROR_OUT_OF_MEMORY;
    } else {
        for (size_t k = 0; k < n; ++k) {
            size_t a = j->alist[b + k];
            list[k] = j->anchor_sample[a];
            from[k] = j->replay ? &plan->anchor_lane[a] : NULL;
        }
        j->anchor_pairs[chunk] = j->replay ? vsgl__shade_lanes(j, from, n, light)
                                           : vsgl__shade_list(j, list, n, NULL, light, lanes);
        for (size_t k = 0; k < n; ++k) {
            size_t a = j->alist[b + k];
            memcpy(j->anchor_light + a * 6, light + k * 6, 6 * sizeof *light);
            if (lanes) /* the plan's record: each anchor's lane */
                plan->anchor_lane[a] = lanes[k];
        }
    }
    free(list);
    free(from);
    free(light);
    free(lanes);
#if defined(__x86_64__) || defined(__i386__)
    _mm_setcsr(saved_csr);
#endif
    return rc;
}

vsgl_result vsgl__shade_anchors(vsgl_context *ctx, shade_job *j)
{
    const vsgl_gbuffer *g = j->g;
    vsgl_shade_plan *plan = j->plan;
    size_t na = (size_t)j->aw * j->ah, nh = 0;
    /* each anchor's first hit sample (or the plan's), and the list of hit anchors */
    for (size_t a = 0; a < na; ++a) {
        if (j->replay) {
            j->anchor_sample[a] = plan->anchor_sample[a];
        } else {
            size_t px = anchor_pixel(j, (uint32_t)(a % j->aw), (uint32_t)(a / j->aw));
            j->anchor_sample[a] = SIZE_MAX;
            for (size_t k = 0; k < g->spp; ++k)
                if (g->material[px * g->spp + k] != VSGL__GBUFFER_MISS) {
                    j->anchor_sample[a] = px * g->spp + k;
                    break;
                }
        }
        if (j->anchor_sample[a] != SIZE_MAX)
            j->alist[nh++] = a;
    }
    if (vsgl__parallel_ctx(ctx, nh, SPARSE_CHUNK, anchor_blocks, j) != 0)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "shade: out of memory for the sparse anchors");
    if (plan && !j->replay) {
        memcpy(plan->anchor_sample, j->anchor_sample, na * sizeof *plan->anchor_sample);
        plan->row_ok[plan->height] = 1;
    }
    if (j->replay) { /* the same from the plan's record of which neighbours share a surface */
        vsgl__sparse_anchor_pack(j);
        return VSGL_OK;
    }
    const int record = plan != NULL;
    /* each anchor's second differences along x and y through its neighbours on its surface;
     * beside a junction, a bend from its light's step (SPARSE_JUNCTION_SLOPE) */
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
                if (ms == SIZE_MAX || ps == SIZE_MAX)
                    continue;
                const int sm = same_surface_weight(j, as, ms) > 0.0f, sp = same_surface_weight(j, as, ps) > 0.0f;
                if (sm != sp && sparse_beside_junction(g, as, sm ? ms : ps, sm ? ps : ms)) {
                    if (record) /* bit 2 + axis: beside a junction; 4 + axis: its same-surface neighbour is p */
                        plan->d2_ok[a] |= (unsigned char)((4u | (sp ? 16u : 0u)) << axis);
                    for (int l = 0; l < 2; ++l) {
                        const float *A = j->anchor_light + a * 6 + 3 * l, *S = j->anchor_light + (sm ? m : p) * 6 + 3 * l;
                        D[2 * l + axis] = sparse_junction_bend(A[0] + A[1] + A[2], S[0] + S[1] + S[2]);
                    }
                    continue;
                }
                if (!sm || !sp)
                    continue;
                if (record)
                    plan->d2_ok[a] |= (unsigned char)(1u << axis);
                for (int l = 0; l < 2; ++l) {
                    const float *A = j->anchor_light + a * 6 + 3 * l, *M = j->anchor_light + m * 6 + 3 * l,
                                *P = j->anchor_light + p * 6 + 3 * l;
                    D[2 * l + axis] = sparse_d2(M[0] + M[1] + M[2], A[0] + A[1] + A[2], P[0] + P[1] + P[2]);
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
    if (record) { /* what record_rows reads: the anchors' light and surfaces, packed */
        vsgl__sparse_anchor_pack(j);
        for (size_t a = 0; a < (size_t)j->aw * j->ah; ++a) {
            size_t as = j->anchor_sample[a];
            float *q = plan->geo + a * 8;
            if (as == SIZE_MAX) {
                memset(q, 0, 8 * sizeof *q);
                continue;
            }
            for (int c = 0; c < 3; ++c) {
                q[c] = g->nrm[c][as];
                q[3 + c] = g->pos[c][as];
            }
            uint32_t m = g->material[as];
            memcpy(&q[6], &m, sizeof m);
            q[7] = 0.0f;
        }
    }
    return VSGL_OK;
}

/* How much anchor sample a stands on sample s's surface, in [0, 1]. */
static float same_surface_weight(const shade_job *j, size_t s, size_t a)
{
    const vsgl_gbuffer *g = j->g;
    if (g->material[a] != g->material[s])
        return 0.0f;
    v3 ns = v3_make(g->nrm[0][s], g->nrm[1][s], g->nrm[2][s]);
    v3 na = v3_make(g->nrm[0][a], g->nrm[1][a], g->nrm[2][a]);
    float c = v3_dot(ns, na), inv, cmin = sparse_normal_cos(j, g->material[s], &inv);
    if (!(c > cmin))
        return 0.0f;
    float wn = (c - cmin) * inv;
    v3 d = v3_make(g->pos[0][a] - g->pos[0][s], g->pos[1][a] - g->pos[1][s], g->pos[2][a] - g->pos[2][s]);
    float off = fabsf(v3_dot(d, ns)), tol = SPARSE_PLANE_REL * v3_length(d) + j->plane_tol;
    float wp = 1.0f - off / tol;
    if (!(wp > 0.0f))
        return 0.0f;
    return wn * wp;
}

/* A junction: the sample's surface ends within its anchor cell against
 * another surface that touches it (a wall's foot, a room's corner), so the
 * anchors on its surface lie on one side of it only along a row or a
 * column, and interpolation would extrapolate into the near field of the
 * junction, where light changes fastest (1-px bright lines along a box's
 * corners, a floor caustic's foot on a wall reduced to every other pixel).
 * The sample is shaded itself there. `same` and `other`: bit dy * 2 + dx
 * per anchor of the cell (of positive bilinear weight) on the sample's
 * surface, and on another surface within SPARSE_JUNCTION times the
 * farthest same-surface anchor's distance (further away it is an
 * occluder's or a background's edge: a depth step, no near field). */
static inline int sparse_junction(unsigned same, unsigned other)
{
    const unsigned row0 = 0x3u, row1 = 0xcu, col0 = 0x5u, col1 = 0xau;
    return (((same & row0) == 0) != ((same & row1) == 0) && (other & ((same & row0) ? row1 : row0))) ||
           (((same & col0) == 0) != ((same & col1) == 0) && (other & ((same & col0) ? col1 : col0)));
}

/* other's bits of anchors within SPARSE_JUNCTION times the farthest
 * same-surface one (squared distances d2 per anchor of the cell). */
static inline unsigned sparse_touching(unsigned same, unsigned other, const float *d2)
{
    float far2 = 0.0f;
    for (unsigned i = 0; i < 4; ++i)
        if ((same >> i & 1u) && d2[i] > far2)
            far2 = d2[i];
    unsigned t = 0;
    for (unsigned i = 0; i < 4; ++i)
        if ((other >> i & 1u) && d2[i] <= SPARSE_JUNCTION * SPARSE_JUNCTION * far2)
            t |= 1u << i;
    return t;
}

/* The anchor cell around sample si: its raster position against the
 * anchors' (each shaded at its pixel's first sample; sparse_slot_offset). */
static inline void sample_cell(const shade_job *j, size_t si, size_t spp, uint32_t aa, float inv_aa, uint32_t *ax,
                               uint32_t *ay, float *tx, float *ty)
{
    const size_t W = j->g->width, px = si / spp, k = si % spp;
    float ox, oy;
    sparse_slot_offset(k, aa, inv_aa, &ox, &oy);
    sparse_axis_cell((uint32_t)(px % W), ox, j->stride, j->g->width, ax, tx);
    sparse_axis_cell((uint32_t)(px / W), oy, j->stride, j->g->height, ay, ty);
}

/* Rows [b0, e0) of the batch (one row per chunk) of a render without a
 * plan: each sample's interpolated light, or a mark to shade it itself.
 * (A record does the same from packed anchors, record_rows, and keeps the
 * weights and codes; a replay reads them, replay_rows.) */
static int32_t sparse_classify(void *user, size_t chunk, size_t b0, size_t e0)
{
    sparse_batch *bt = user;
    shade_job *j = bt->j;
    (void)chunk;
    const vsgl_gbuffer *g = j->g;
    const size_t spp = g->spp;
    const size_t first = (j->base + b0) * spp, ns = (e0 - b0) * spp;
    const uint32_t aa = g->aa;
    const float inv_aa = 1.0f / (float)aa;
    int refined = 0; /* the sample's pixel's, once per pixel (first is a pixel's first sample) */
    for (size_t i = 0; i < ns; ++i) {
        size_t si = first + i, bi = si - bt->first;
        if (i % spp == 0)
            refined = vsgl__gbuffer_refined(g, si / spp);
        bt->direct_of[bi] = SIZE_MAX;
        if (g->material[si] == VSGL__GBUFFER_MISS)
            continue;
        uint32_t ax, ay;
        float tx, ty;
        sample_cell(j, si, spp, aa, inv_aa, &ax, &ay, &tx, &ty);
        float wsum = 0.0f, L[6] = {0, 0, 0, 0, 0, 0}, ad2[4] = {0, 0, 0, 0};
        float lo[2] = {FLT_MAX, FLT_MAX}, hi[2] = {0.0f, 0.0f}, dx2[2] = {-1.0f, -1.0f}, dy2[2] = {-1.0f, -1.0f};
        unsigned same = 0, other = 0;
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
                const unsigned bit = 1u << (dy * 2 + dx);
                float d0 = g->pos[0][as] - g->pos[0][si], d1 = g->pos[1][as] - g->pos[1][si],
                      dz = g->pos[2][as] - g->pos[2][si];
                ad2[dy * 2 + dx] = d0 * d0 + d1 * d1 + dz * dz;
                if (!(w > 0.0f)) {
                    other |= bit;
                    continue;
                }
                same |= bit;
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
         * (a reflection's edge, a shadow's), the sample is shaded itself;
         * near that, shaded and blended with its interpolation (SPARSE_BLEND) */
        float t = 1.0f;
        if (wsum > 0.05f) {
            t = 0.0f;
            for (int l = 0; l < 2; ++l) {
                float m = (L[3 * l] + L[3 * l + 1] + L[3 * l + 2]) / wsum;
                float bound = SPARSE_TOL * m + j->contrast_floor[l], tl;
                if (dx2[l] < 0.0f && dy2[l] < 0.0f) {
                    tl = sparse_shade_weight(hi[l] - lo[l], SPARSE_CONTRAST * (hi[l] + lo[l]) + j->contrast_floor[l]);
                } else {
                    /* (a missing second difference, -1, counts as 0; a compare, not
                     * fmaxf, which without -ffinite-math-only is a libm call per sample) */
                    float ex = dx2[l] > 0.0f ? dx2[l] : 0.0f, ey = dy2[l] > 0.0f ? dy2[l] : 0.0f;
                    tl = sparse_shade_weight(0.5f * (tx * (1.0f - tx) * ex + ty * (1.0f - ty) * ey), bound);
                }
                t = tl > t ? tl : t;
            }
            if (!(t < 1.0f))
                t = 1.0f;
        }
        if (t < 1.0f && (refined || sparse_past_anchor(tx, ty) || sparse_junction(same, sparse_touching(same, other, ad2))))
            t = 1.0f;
        if (t < 1.0f)
            for (int c = 0; c < 6; ++c)
                bt->interp[bi * 6 + c] = L[c] / wsum;
        if (t > 0.0f) {
            bt->direct_of[bi] = SPARSE_MARK;
            bt->blend[bi] = t;
        }
    }
    return 0;
}

/* Entries [b, e) of the batch's list of samples shaded themselves. A
 * record keeps their lanes; a replay takes a sample's recorded lane when
 * the record shaded it too (most do: a light edit moves few contrasts),
 * else makes it from the G-buffer. */
int32_t vsgl__sparse_direct(void *user, size_t chunk, size_t b, size_t e)
{
    sparse_batch *bt = user;
    shade_job *j = bt->j;
    const vsgl_shade_plan *plan = j->plan;
    int32_t rc = 0;
#if defined(__x86_64__) || defined(__i386__)
    unsigned int saved_csr = _mm_getcsr();
    _mm_setcsr(saved_csr | 0x8040u);
#endif
    if (j->replay) {
        const vsgl__plan_lane **from = malloc((e - b + 1) * sizeof *from);
        if (!from) {
            rc = VSGL_ERROR_OUT_OF_MEMORY;
        } else {
            for (size_t k = b; k < e; ++k) {
                int32_t d = plan->dlane_of[bt->dlist[k]];
                if (d >= 0) {
                    from[k - b] = &plan->dlanes[d];
                } else {
                    vsgl__sample_lane(j, bt->dlist[k], &bt->lanes[k]);
                    from[k - b] = &bt->lanes[k];
                }
            }
            bt->dpairs[chunk] = vsgl__shade_lanes(j, from, e - b, bt->dlight + b * 6);
            free(from);
        }
    } else {
        bt->dpairs[chunk] = vsgl__shade_list(j, bt->dlist + b, e - b, NULL, bt->dlight + b * 6,
                                             bt->lanes ? bt->lanes + b : NULL);
    }
    /* near the test's bound: (1 - t) x the interpolated light + t x the shaded (SPARSE_BLEND) */
    for (size_t k = b; rc == 0 && k < e; ++k) {
        const size_t bi = bt->dlist[k] - bt->first;
        const float t = bt->blend[bi];
        if (t < 1.0f) {
            const float *I = bt->interp + bi * 6;
            float *D = bt->dlight + k * 6;
            for (int c = 0; c < 6; ++c)
                D[c] = I[c] + t * (D[c] - I[c]);
        }
    }
#if defined(__x86_64__) || defined(__i386__)
    _mm_setcsr(saved_csr);
#endif
    return rc;
}

/* A record: pixel px's colours and coverage, as the replay writes them. */
static inline void keep_colour(vsgl_shade_plan *plan, const vsgl_pixel_planes *pl, size_t px)
{
    float *col = plan->colour + px * 7;
    for (int c = 0; c < 3; ++c) {
        col[c] = pl->diffuse_color[px * 3 + c];
        col[3 + c] = pl->glossy_color[px * 3 + c];
    }
    col[6] = pl->coverage[px];
}

/* Rows [b0, e0) of the batch: every pixel from its samples' light and
 * colours (a record keeps the colours and factors: replay_pixel). */
static int32_t sparse_resolve(void *user, size_t chunk, size_t b0, size_t e0)
{
    sparse_batch *bt = user;
    shade_job *j = bt->j;
    (void)chunk;
    const vsgl_gbuffer *g = j->g;
    const vsgl_pixel_planes *pl = j->planes;
    const size_t spp = g->spp, W = g->width;
    vsgl_shade_plan *plan = j->plan;
    const int record = plan && b0 % W == 0 && e0 - b0 == W;
    const float *Ls[VSGL__GBUFFER_MAX_SPP];
    for (size_t px = j->base + b0; px < j->base + e0; ++px) {
#if defined(__SSE2__)
        if (spp == 1 && j->params && px + 4 <= j->base + e0) { /* four pixels' colours at once (pixel4.c) */
            for (size_t k = 0; k < 4; ++k) {
                size_t bi = px + k - bt->first;
                Ls[k] = g->material[px + k] == VSGL__GBUFFER_MISS ? NULL
                        : bt->direct_of[bi] != SIZE_MAX           ? bt->dlight + bt->direct_of[bi] * 6
                                                                  : bt->interp + bi * 6;
            }
            vsgl__write_pixels4(j, px, Ls, record ? plan->cd + px * 4 : NULL);
            if (record)
                for (size_t k = 0; k < 4; ++k)
                    keep_colour(plan, pl, px + k);
            px += 3;
            continue;
        }
#endif
        for (size_t k = 0; k < spp; ++k) {
            size_t si = px * spp + k, bi = si - bt->first;
            if (g->material[si] == VSGL__GBUFFER_MISS)
                Ls[k] = NULL;
            else
                Ls[k] = bt->direct_of[bi] != SIZE_MAX ? bt->dlight + bt->direct_of[bi] * 6 : bt->interp + bi * 6;
        }
        vsgl__write_pixel(j, px, Ls, record ? plan->cd + px * spp * 4 : NULL);
        if (record)
            keep_colour(plan, pl, px);
    }
    if (record)
        for (size_t y = (j->base + b0) / W; y < (j->base + e0) / W; ++y)
            plan->row_ok[y] = 1;
    return 0;
}

/* same_surface_weight of an anchor packed in q (plan->geo) for a sample of
 * normal n, position x and material m: the same operations. */
static inline float packed_surface_weight(const shade_job *j, const float *n, const float *x, uint32_t m,
                                          const float *q)
{
    uint32_t qm;
    memcpy(&qm, &q[6], sizeof qm);
    if (qm != m)
        return 0.0f;
    float c = n[0] * q[0] + n[1] * q[1] + n[2] * q[2], inv, cmin = sparse_normal_cos(j, m, &inv);
    if (!(c > cmin))
        return 0.0f;
    float wn = (c - cmin) * inv;
    float d0 = q[3] - x[0], d1 = q[4] - x[1], d2 = q[5] - x[2];
    float off = fabsf(d0 * n[0] + d1 * n[1] + d2 * n[2]);
    float tol = SPARSE_PLANE_REL * sqrtf(d0 * d0 + d1 * d1 + d2 * d2) + j->plane_tol;
    float wp = 1.0f - off / tol;
    if (!(wp > 0.0f))
        return 0.0f;
    return wn * wp;
}

#if defined(__SSE2__)
/* Four pixels px..px+3 of one row, one sample each, every one a hit, in one
 * anchor cell (ax, ay) at tx[0..3], ty: record_rows below with the four
 * samples in the lanes, the same operations per lane (packed_surface_weight,
 * then vsgl__sparse_interp4 for replay_sample). */
static void record_cell4(sparse_batch *bt, size_t px, uint32_t ax, uint32_t ay, const float *tx, float ty)
{
    const shade_job *j = bt->j;
    vsgl_shade_plan *plan = j->plan;
    const vsgl_gbuffer *g = j->g;
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
    const __m128 n0 = _mm_loadu_ps(g->nrm[0] + px), n1 = _mm_loadu_ps(g->nrm[1] + px),
                 n2 = _mm_loadu_ps(g->nrm[2] + px);
    const __m128 x0 = _mm_loadu_ps(g->pos[0] + px), x1 = _mm_loadu_ps(g->pos[1] + px),
                 x2 = _mm_loadu_ps(g->pos[2] + px);
    const __m128i mat = _mm_loadu_si128((const __m128i *)(const void *)(g->material + px));
    const __m128 vtx = _mm_loadu_ps(tx), abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    const __m128 tol0 = _mm_set1_ps(j->plane_tol);
    __m128 w[4], wsum = zero;
    /* the junction test's inputs (record_rows): per anchor, which lanes it is on the
     * surface of (same) or not (other), and its squared distance per lane */
    unsigned same_bits[4] = {0, 0, 0, 0}, other_bits[4] = {0, 0, 0, 0};
    float ad2[4][4] = {{0}};
    for (uint32_t dy = 0; dy < 2; ++dy)
        for (uint32_t dx = 0; dx < 2; ++dx) {
            const uint32_t cx = ax + dx, cy = ay + dy;
            __m128 *wi = &w[dy * 2 + dx];
            *wi = zero;
            if (cx >= j->aw || cy >= j->ah)
                continue;
            const size_t a = (size_t)cy * j->aw + cx, as = j->anchor_sample[a];
            if (as == SIZE_MAX)
                continue;
            const __m128 wb = _mm_mul_ps(dx ? vtx : _mm_sub_ps(one, vtx), _mm_set1_ps(dy ? ty : 1.0f - ty));
            /* packed_surface_weight, four samples against anchor a */
            const float *q = plan->geo + a * 8;
            uint32_t qm;
            memcpy(&qm, &q[6], sizeof qm);
            const __m128 same = _mm_castsi128_ps(_mm_cmpeq_epi32(mat, _mm_set1_epi32((int)qm)));
            const __m128 c = _mm_add_ps(_mm_add_ps(_mm_mul_ps(n0, _mm_set1_ps(q[0])), _mm_mul_ps(n1, _mm_set1_ps(q[1]))),
                                        _mm_mul_ps(n2, _mm_set1_ps(q[2])));
            float inv, cmin = sparse_normal_cos(j, qm, &inv); /* (lanes of another material weigh 0) */
            const __m128 c_ok = _mm_cmpgt_ps(c, _mm_set1_ps(cmin));
            const __m128 wn = _mm_mul_ps(_mm_sub_ps(c, _mm_set1_ps(cmin)), _mm_set1_ps(inv));
            const __m128 d0 = _mm_sub_ps(_mm_set1_ps(q[3]), x0), d1 = _mm_sub_ps(_mm_set1_ps(q[4]), x1),
                         d2 = _mm_sub_ps(_mm_set1_ps(q[5]), x2);
            const __m128 off = _mm_and_ps(
                abs_mask, _mm_add_ps(_mm_add_ps(_mm_mul_ps(d0, n0), _mm_mul_ps(d1, n1)), _mm_mul_ps(d2, n2)));
            const __m128 dd = _mm_add_ps(_mm_add_ps(_mm_mul_ps(d0, d0), _mm_mul_ps(d1, d1)), _mm_mul_ps(d2, d2));
            const __m128 len = _mm_sqrt_ps(dd);
            _mm_storeu_ps(ad2[dy * 2 + dx], dd);
            const __m128 tol = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(SPARSE_PLANE_REL), len), tol0);
            const __m128 wp = _mm_sub_ps(one, _mm_div_ps(off, tol));
            const __m128 p_ok = _mm_and_ps(_mm_and_ps(same, c_ok), _mm_cmpgt_ps(wp, zero));
            __m128 sw = _mm_and_ps(p_ok, _mm_mul_ps(wn, wp));
            if (as >= px && as < px + 4) { /* the anchor is one of these samples: its weight 1 */
                const __m128 self = _mm_castsi128_ps(
                    _mm_cmpeq_epi32(_mm_setr_epi32(0, 1, 2, 3), _mm_set1_epi32((int)(as - px))));
                sw = _mm_or_ps(_mm_and_ps(self, one), _mm_andnot_ps(self, sw));
            }
            const __m128 wa = _mm_mul_ps(wb, sw), on_b = _mm_cmpgt_ps(wb, zero), on_a = _mm_cmpgt_ps(wa, zero);
            *wi = _mm_and_ps(_mm_and_ps(on_b, on_a), wa);
            wsum = _mm_add_ps(wsum, *wi);
            same_bits[dy * 2 + dx] = (unsigned)_mm_movemask_ps(_mm_and_ps(on_b, on_a));
            other_bits[dy * 2 + dx] = (unsigned)_mm_movemask_ps(_mm_andnot_ps(on_a, on_b));
        }
    __m128 r0 = w[0], r1 = w[1], r2 = w[2], r3 = w[3];
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3); /* ri: the four weights of sample i */
    float *w4 = plan->w4 + px * 4;
    _mm_storeu_ps(w4, r0);
    _mm_storeu_ps(w4 + 4, r1);
    _mm_storeu_ps(w4 + 8, r2);
    _mm_storeu_ps(w4 + 12, r3);
    const unsigned near = (unsigned)_mm_movemask_ps(_mm_cmpgt_ps(wsum, _mm_set1_ps(0.05f)));
    float out[6][4], t4[4];
    const unsigned ok = vsgl__sparse_interp4(j, plan->pack, w4, ax, ay, tx, ty, out, t4);
    /* no anchor of the cell off a lane's surface: no junction (sparse_touching gives 0) in any lane */
    const unsigned any_other = other_bits[0] | other_bits[1] | other_bits[2] | other_bits[3];
    for (unsigned k = 0; k < 4; ++k) {
        const size_t si = px + k, bi = si - bt->first;
        int junction = 0;
        if (any_other >> k & 1u) {
            unsigned same = 0, other = 0;
            float d2k[4];
            for (unsigned i = 0; i < 4; ++i) {
                same |= (same_bits[i] >> k & 1u) << i;
                other |= (other_bits[i] >> k & 1u) << i;
                d2k[i] = ad2[i][k];
            }
            junction = sparse_junction(same, sparse_touching(same, other, d2k));
        }
        plan->direct[si] = near >> k & 1u && !junction ? PLAN_NEAR : PLAN_ALONE;
        const float t = plan->direct[si] == PLAN_NEAR && ok >> k & 1u ? t4[k] : 1.0f;
        bt->direct_of[bi] = t > 0.0f ? SPARSE_MARK : SIZE_MAX;
        bt->blend[bi] = t;
        if (t < 1.0f)
            for (int c = 0; c < 6; ++c)
                bt->interp[bi * 6 + c] = out[c][k];
    }
}
#endif

/* Rows [b0, e0) of a record's batch (one row per chunk): sparse_classify
 * from the packed anchors (their surfaces, plan->geo, and light,
 * plan->pack) and the cell tables; records the weights and codes. */
static int32_t record_rows(void *user, size_t chunk, size_t b0, size_t e0)
{
    sparse_batch *bt = user;
    const shade_job *j = bt->j;
    vsgl_shade_plan *plan = j->plan;
    const vsgl_gbuffer *g = j->g;
    const size_t spp = plan->spp, W = plan->width;
    const uint32_t aw = j->aw, ah = j->ah;
    (void)chunk;
    size_t px = j->base + b0, x = px % W, y = px / W;
    for (; px < j->base + e0; ++px) {
#if defined(__SSE2__)
        /* one sample per pixel (the live viewport's): four hit pixels of one cell at a time */
        if (spp == 1 && x + 4 <= W && px + 4 <= j->base + e0 && plan->cell_x[x] == plan->cell_x[x + 3] &&
            g->material[px] != VSGL__GBUFFER_MISS && g->material[px + 1] != VSGL__GBUFFER_MISS &&
            g->material[px + 2] != VSGL__GBUFFER_MISS && g->material[px + 3] != VSGL__GBUFFER_MISS) {
            record_cell4(bt, px, plan->cell_x[x], plan->cell_y[y], plan->cell_tx + x, plan->cell_ty[y]);
            px += 3;
            x += 3;
            if (++x == W) {
                x = 0;
                ++y;
            }
            continue;
        }
#endif
        const int refined = vsgl__gbuffer_refined(g, px);
        for (size_t k = 0; k < spp; ++k) {
            const size_t si = px * spp + k, bi = si - bt->first;
            float *w = plan->w4 + si * 4;
            bt->direct_of[bi] = SIZE_MAX;
            plan->direct[si] = PLAN_MISS;
            w[0] = w[1] = w[2] = w[3] = 0.0f;
            const uint32_t m = g->material[si];
            if (m == VSGL__GBUFFER_MISS)
                continue;
            const uint32_t ax = plan->cell_x[x * spp + k], ay = plan->cell_y[y * spp + k];
            const float tx = plan->cell_tx[x * spp + k], ty = plan->cell_ty[y * spp + k];
            const float n[3] = {g->nrm[0][si], g->nrm[1][si], g->nrm[2][si]};
            const float xs[3] = {g->pos[0][si], g->pos[1][si], g->pos[2][si]};
            float wsum = 0.0f, ad2[4] = {0, 0, 0, 0};
            unsigned same = 0, other = 0;
            for (uint32_t dy = 0; dy < 2; ++dy)
                for (uint32_t dx = 0; dx < 2; ++dx) {
                    uint32_t cx = ax + dx, cy = ay + dy;
                    if (cx >= aw || cy >= ah)
                        continue;
                    size_t a = (size_t)cy * aw + cx, as = j->anchor_sample[a];
                    float wb = (dx ? tx : 1.0f - tx) * (dy ? ty : 1.0f - ty);
                    if (as == SIZE_MAX || !(wb > 0.0f))
                        continue;
                    float wa = wb * (as == si ? 1.0f : packed_surface_weight(j, n, xs, m, plan->geo + a * 8));
                    const float *q = plan->geo + a * 8;
                    const float d0 = q[3] - xs[0], d1 = q[4] - xs[1], d2 = q[5] - xs[2];
                    ad2[dy * 2 + dx] = d0 * d0 + d1 * d1 + d2 * d2;
                    if (!(wa > 0.0f)) {
                        other |= 1u << (dy * 2 + dx);
                        continue;
                    }
                    same |= 1u << (dy * 2 + dx);
                    wsum += wa;
                    w[dy * 2 + dx] = wa;
                }
            plan->direct[si] = wsum > 0.05f && !refined && !sparse_junction(same, sparse_touching(same, other, ad2))
                                   ? PLAN_NEAR
                                   : PLAN_ALONE;
            float t = 1.0f;
            if (plan->direct[si] == PLAN_ALONE ||
                !vsgl__sparse_interp(j, plan->pack, w, ax, ay, tx, ty, bt->interp + bi * 6, &t) || t > 0.0f)
                bt->direct_of[bi] = SPARSE_MARK;
            bt->blend[bi] = t;
        }
        if (++x == W) {
            x = 0;
            ++y;
        }
    }
    return 0;
}

vsgl_result vsgl__shade_sparse_batch(vsgl_context *ctx, shade_job *j, size_t row, size_t end)
{
    if (j->replay)
        return vsgl__sparse_replay_batch(ctx, j, row, end);
    const vsgl_gbuffer *g = j->g;
    const size_t W = g->width, spp = g->spp;
    sparse_batch bt;
    memset(&bt, 0, sizeof bt);
    bt.j = j;
    bt.first = row * W * spp;
    bt.ns = (end - row) * W * spp;
    bt.interp = malloc((bt.ns + 1) * 6 * sizeof *bt.interp);
    bt.blend = malloc((bt.ns + 1) * sizeof *bt.blend);
    bt.direct_of = malloc((bt.ns + 1) * sizeof *bt.direct_of);
    bt.dlist = malloc((bt.ns + 1) * sizeof *bt.dlist);
    vsgl_result r = VSGL_OK;
    if (!bt.interp || !bt.blend || !bt.direct_of || !bt.dlist ||
        vsgl__parallel_ctx(ctx, (end - row) * W, W, j->plan ? record_rows : sparse_classify, &bt) != 0) {
        r = VSGL_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    /* the samples to shade, in sample order, in full blocks whatever their rows */
    size_t nd = 0;
    for (size_t i = 0; i < bt.ns; ++i)
        if (bt.direct_of[i] == SPARSE_MARK) {
            bt.direct_of[i] = nd;
            bt.dlist[nd++] = bt.first + i;
        }
    bt.dlight = malloc((nd + 1) * 6 * sizeof *bt.dlight);
    bt.dpairs = calloc(nd / SPARSE_CHUNK + 2, sizeof *bt.dpairs);
    vsgl_shade_plan *plan = j->plan;
    if (plan) /* a record keeps the lanes */
        bt.lanes = malloc((nd + 1) * sizeof *bt.lanes);
    if (!bt.dlight || !bt.dpairs || (plan && !bt.lanes) ||
        vsgl__parallel_ctx(ctx, nd, SPARSE_CHUNK, vsgl__sparse_direct, &bt) != 0 ||
        vsgl__parallel_ctx(ctx, (end - row) * W, W, sparse_resolve, &bt) != 0) {
        r = VSGL_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    if (plan) { /* the record: these samples' lanes, for the next renders */
        for (size_t i = bt.first; i < bt.first + bt.ns; ++i)
            plan->dlane_of[i] = -1;
        if (plan->ndlanes + nd > plan->dlanes_cap) {
            size_t cap = 2 * (plan->ndlanes + nd) + 64;
            vsgl__plan_lane *grown = realloc(plan->dlanes, cap * sizeof *grown);
            if (grown) {
                plan->dlanes = grown;
                plan->dlanes_cap = cap;
            } else {
                plan->row_ok[plan->height] = 0; /* no memory for them: the plan is not kept */
                nd = 0;
            }
        }
        for (size_t k = 0; k < nd && plan->ndlanes < (size_t)INT32_MAX; ++k) {
            plan->dlane_of[bt.dlist[k]] = (int32_t)plan->ndlanes;
            plan->dlanes[plan->ndlanes++] = bt.lanes[k];
        }
    }
    for (size_t c = 0; c < nd / SPARSE_CHUNK + 2; ++c)
        j->pairs[0] += bt.dpairs[c];
done:
    free(bt.interp);
    free(bt.blend);
    free(bt.direct_of);
    free(bt.dlist);
    free(bt.dlight);
    free(bt.dpairs);
    free(bt.lanes);
    return r == VSGL_OK ? VSGL_OK : vsgl__fail(ctx, r, "shade: out of memory");
}

void vsgl__sparse_normal_cos(const vsgl_material *materials, uint32_t count, float *out)
{
    for (uint32_t k = 0; k < count; ++k) {
        vsgl_brdf_params bp;
        vsgl__material_params(&materials[k], &bp);
        float c = SPARSE_NORMAL_COS;
        if (bp.glossy) {
            float turn = SPARSE_GLOSSY_TURN * sqrtf(bp.alpha_x * bp.alpha_y);
            turn = turn > SPARSE_GLOSSY_MIN_TURN ? turn : SPARSE_GLOSSY_MIN_TURN;
            const float cg = cosf(turn);
            c = cg > c ? cg : c;
        }
        out[2 * (size_t)k] = c;
        out[2 * (size_t)k + 1] = 1.0f / (1.0f - c);
    }
}
