/* Replaying a shading plan (shade_stride > 1, a render through a
 * vsgl_render_cache whose G-buffer stands still: a light edit). The plan
 * (shade_job.h) holds what no light changes; a replay interpolates every
 * sample from the anchors' new light with the recorded weights, runs the
 * interpolation test again, shades the samples it marks in full kernel
 * blocks and writes every pixel from the recorded colours. The same
 * arithmetic in the same order as the record (sparse.c): bit-identical
 * planes (tests/c/test_scene_view.c). */

#include "shade/sparse.h"
#include "core/parallel.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#  include <emmintrin.h>

/* sparse_shade_weight (sparse.h) per lane, the same operations */
static inline __m128 shade_weight4(__m128 e, __m128 bound)
{
    const __m128 one = _mm_set1_ps(1.0f), over = _mm_cmpgt_ps(e, bound);
    const __m128 x = _mm_sub_ps(e, _mm_mul_ps(_mm_set1_ps(SPARSE_BLEND), bound));
    __m128 t = _mm_min_ps(_mm_div_ps(x, _mm_mul_ps(_mm_set1_ps(1.0f - SPARSE_BLEND), bound)), one);
    t = _mm_and_ps(_mm_cmpgt_ps(x, _mm_setzero_ps()), t);
    return _mm_or_ps(_mm_and_ps(over, one), _mm_andnot_ps(over, t));
}

static inline __m128 select4(__m128 mask, __m128 a, __m128 b)
{
    return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}
#endif

/* A replay's anchors: each anchor's light, its sum per lobe and its second
 * differences, packed (plan->pack: 12 floats; a missed anchor's light 0),
 * and the interpolation test's floor. The same values, in the same order
 * of operations, as the record's (vsgl__shade_anchors, sparse.c), but which
 * neighbours share an anchor's surface is read from the record. */
void vsgl__sparse_anchor_pack(shade_job *j)
{
    vsgl_shade_plan *plan = j->plan;
    const size_t na = (size_t)j->aw * j->ah;
    float *P = plan->pack;
    double sum[2] = {0.0, 0.0};
    size_t n = 0;
    for (size_t a = 0; a < na; ++a) {
        float *q = P + a * 12;
        if (j->anchor_sample[a] == SIZE_MAX) {
            for (int c = 0; c < 8; ++c)
                q[c] = 0.0f;
        } else {
            const float *A = j->anchor_light + a * 6;
            for (int c = 0; c < 6; ++c)
                q[c] = A[c];
            q[6] = A[0] + A[1] + A[2];
            q[7] = A[3] + A[4] + A[5];
            sum[0] += (double)A[0] + A[1] + A[2];
            sum[1] += (double)A[3] + A[4] + A[5];
            ++n;
        }
        q[8] = q[9] = q[10] = q[11] = -1.0f;
    }
    if (!j->replay) { /* a record: the second differences it computed (vsgl__shade_anchors) */
        for (size_t a = 0; a < na; ++a)
            memcpy(P + a * 12 + 8, j->anchor_d2 + a * 4, 4 * sizeof *P);
        return;
    }
    for (uint32_t ay = 0; ay < j->ah; ++ay)
        for (uint32_t ax = 0; ax < j->aw; ++ax) {
            size_t a = (size_t)ay * j->aw + ax;
            unsigned bits = plan->d2_ok[a];
            for (int axis = 0; axis < 2; ++axis) {
                if (bits >> (2 + axis) & 1u) { /* beside a junction (vsgl__shade_anchors) */
                    size_t step = axis == 0 ? 1 : j->aw, o = bits >> (4 + axis) & 1u ? a + step : a - step;
                    for (int l = 0; l < 2; ++l)
                        P[a * 12 + 8 + 2 * l + axis] = sparse_junction_bend(P[a * 12 + 6 + l], P[o * 12 + 6 + l]);
                }
                if (!(bits >> axis & 1u))
                    continue;
                size_t step = axis == 0 ? 1 : j->aw, m = a - step, p = a + step;
                for (int l = 0; l < 2; ++l)
                    P[a * 12 + 8 + 2 * l + axis] = sparse_d2(P[m * 12 + 6 + l], P[a * 12 + 6 + l], P[p * 12 + 6 + l]);
            }
        }
    for (int l = 0; l < 2; ++l)
        j->contrast_floor[l] = n ? (float)(SPARSE_FLOOR * sum[l] / (double)n) : 0.0f;
}

/* A replay's sample: its light interpolated from the packed anchors of its
 * cell (ax, ay) at (tx, ty) with the recorded weights w (4), into out (6),
 * and its t (sparse_shade_weight) into *t; 0 where it has no interpolation
 * (t = 1: shaded itself). sparse_classify's arithmetic in its
 * order: an anchor of weight 0 adds 0 x its light (finite, 0 for a miss)
 * and leaves the bounds and second differences as they are. */
static inline int replay_sample(const shade_job *j, const float *pack, const float *w, uint32_t ax, uint32_t ay,
                                float tx, float ty, float *out, float *t)
{
    if (sparse_past_anchor(tx, ty)) { /* extrapolated: shaded itself */
        *t = 1.0f;
        return 0;
    }
    const size_t a0 = (size_t)ay * j->aw + ax;
    const size_t sx = ax + 1 < j->aw ? 1 : 0, sy = ay + 1 < j->ah ? j->aw : 0; /* (off the lattice: weight 0) */
    const float *q[4] = {pack + a0 * 12, pack + (a0 + sx) * 12, pack + (a0 + sy) * 12, pack + (a0 + sx + sy) * 12};
#if defined(__SSE2__)
    /* the same operations four lanes at a time: light RGB + glossy R, glossy GB
     * + the sums per lobe (their bounds), the second differences */
    float wsum = 0.0f;
    __m128 l0 = _mm_setzero_ps(), l1 = _mm_setzero_ps(), vlo = _mm_set1_ps(FLT_MAX), vhi = _mm_setzero_ps(),
           vd2 = _mm_set1_ps(-1.0f);
#  define REPLAY_ANCHOR(i)                                                                                      \
    do {                                                                                                        \
        const int on = w[i] > 0.0f;                                                                            \
        const float wi = on ? w[i] : 0.0f;                                                                     \
        const __m128 m = _mm_castsi128_ps(_mm_set1_epi32(-on)), W4 = _mm_set1_ps(wi);                          \
        const __m128 A0 = _mm_loadu_ps(q[i]), A1 = _mm_loadu_ps(q[i] + 4), A2 = _mm_loadu_ps(q[i] + 8);         \
        wsum += wi;                                                                                             \
        l0 = _mm_add_ps(l0, _mm_mul_ps(W4, A0));                                                                \
        l1 = _mm_add_ps(l1, _mm_mul_ps(W4, A1));                                                                \
        vlo = _mm_min_ps(_mm_or_ps(_mm_and_ps(m, A1), _mm_andnot_ps(m, _mm_set1_ps(FLT_MAX))), vlo);           \
        vhi = _mm_max_ps(_mm_and_ps(m, A1), vhi);                                                               \
        vd2 = _mm_max_ps(_mm_or_ps(_mm_and_ps(m, A2), _mm_andnot_ps(m, _mm_set1_ps(-1.0f))), vd2);             \
    } while (0)
    REPLAY_ANCHOR(0);
    REPLAY_ANCHOR(1);
    REPLAY_ANCHOR(2);
    REPLAY_ANCHOR(3);
#  undef REPLAY_ANCHOR
    if (!(wsum > 0.05f)) {
        *t = 1.0f;
        return 0;
    }
    /* the interpolation test below, both lobes at once (lanes 0, 1) */
    {
        float L[8], tl[4];
        _mm_storeu_ps(L, l0);
        _mm_storeu_ps(L + 4, l1);
        const __m128 ws = _mm_set1_ps(wsum), zero = _mm_setzero_ps();
        const __m128 fl = _mm_setr_ps(j->contrast_floor[0], j->contrast_floor[1], 0.0f, 0.0f);
        const __m128 m = _mm_div_ps(_mm_setr_ps(L[0] + L[1] + L[2], L[3] + L[4] + L[5], 0.0f, 0.0f), ws);
        const __m128 bound = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(SPARSE_TOL), m), fl);
        const __m128 dx2 = _mm_shuffle_ps(vd2, vd2, _MM_SHUFFLE(3, 3, 2, 0));
        const __m128 dy2 = _mm_shuffle_ps(vd2, vd2, _MM_SHUFFLE(3, 3, 3, 1));
        const __m128 lo2 = _mm_movehl_ps(vlo, vlo), hi2 = _mm_movehl_ps(vhi, vhi);
        const __m128 contrast = _mm_and_ps(_mm_cmplt_ps(dx2, zero), _mm_cmplt_ps(dy2, zero));
        const __m128 e = _mm_mul_ps(_mm_set1_ps(0.5f),
                                    _mm_add_ps(_mm_mul_ps(_mm_set1_ps(tx * (1.0f - tx)), _mm_max_ps(dx2, zero)),
                                               _mm_mul_ps(_mm_set1_ps(ty * (1.0f - ty)), _mm_max_ps(dy2, zero))));
        const __m128 ce = _mm_sub_ps(hi2, lo2),
                     cb = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(SPARSE_CONTRAST), _mm_add_ps(hi2, lo2)), fl);
        _mm_storeu_ps(tl, shade_weight4(select4(contrast, ce, e), select4(contrast, cb, bound)));
        *t = tl[0] > tl[1] ? tl[0] : tl[1];
        if (!(*t < 1.0f)) {
            *t = 1.0f;
            return 0;
        }
        _mm_storeu_ps(out, _mm_div_ps(l0, ws));
        _mm_storel_pi((__m64 *)(void *)(out + 4), _mm_div_ps(l1, ws));
    }
#else
    float wsum = 0.0f, L[6] = {0, 0, 0, 0, 0, 0};
    float lo[2] = {FLT_MAX, FLT_MAX}, hi[2] = {0.0f, 0.0f}, d2[4] = {-1.0f, -1.0f, -1.0f, -1.0f};
    for (int i = 0; i < 4; ++i) {
        const int on = w[i] > 0.0f;
        const float wi = on ? w[i] : 0.0f;
        const float *A = q[i];
        wsum += wi;
        for (int c = 0; c < 6; ++c)
            L[c] += wi * A[c];
        for (int l = 0; l < 2; ++l) {
            float vlo = on ? A[6 + l] : FLT_MAX, vhi = on ? A[6 + l] : 0.0f;
            lo[l] = vlo < lo[l] ? vlo : lo[l];
            hi[l] = vhi > hi[l] ? vhi : hi[l];
        }
        for (int c = 0; c < 4; ++c) {
            float d = on ? A[8 + c] : -1.0f;
            d2[c] = d > d2[c] ? d : d2[c];
        }
    }
    if (!(wsum > 0.05f)) {
        *t = 1.0f;
        return 0;
    }
    float tw = 0.0f;
    for (int l = 0; l < 2; ++l) {
        float m = (L[3 * l] + L[3 * l + 1] + L[3 * l + 2]) / wsum;
        float bound = SPARSE_TOL * m + j->contrast_floor[l];
        float dx2 = d2[2 * l], dy2 = d2[2 * l + 1], tl;
        if (dx2 < 0.0f && dy2 < 0.0f) {
            tl = sparse_shade_weight(hi[l] - lo[l], SPARSE_CONTRAST * (hi[l] + lo[l]) + j->contrast_floor[l]);
        } else {
            float ex = dx2 > 0.0f ? dx2 : 0.0f, ey = dy2 > 0.0f ? dy2 : 0.0f;
            tl = sparse_shade_weight(0.5f * (tx * (1.0f - tx) * ex + ty * (1.0f - ty) * ey), bound);
        }
        tw = tl > tw ? tl : tw;
    }
    *t = tw;
    if (!(tw < 1.0f)) {
        *t = 1.0f;
        return 0;
    }
    for (int c = 0; c < 6; ++c)
        out[c] = L[c] / wsum;
#endif
    return 1;
}

int vsgl__sparse_interp(const shade_job *j, const float *pack, const float *w, uint32_t ax, uint32_t ay, float tx,
                        float ty, float *out, float *t)
{
    return replay_sample(j, pack, w, ax, ay, tx, ty, out, t);
}

/* Pixel px of a replay from its samples' light: sparse_resolve's sums. */
static void replay_pixel(const shade_job *j, size_t px, const float *const *Ls)
{
    const vsgl_shade_plan *plan = j->plan;
    const vsgl_pixel_planes *pl = j->planes;
    const size_t spp = plan->spp;
    float acc[6] = {0, 0, 0, 0, 0, 0};
    for (size_t k = 0; k < spp; ++k) {
        if (!Ls[k])
            continue;
        const float *L = Ls[k], *cd = plan->cd + (px * spp + k) * 4;
        for (int c = 0; c < 3; ++c) {
            acc[c] += cd[c] * L[c];
            acc[3 + c] += cd[3] * L[3 + c];
        }
    }
    for (int c = 0; c < 3; ++c) {
        pl->diffuse[px * 3 + c] = acc[c];
        pl->glossy[px * 3 + c] = acc[3 + c];
    }
    if (plan->colours_kept) /* the planes hold them from the last record or replay */
        return;
    const float *col = plan->colour + px * 7;
    for (int c = 0; c < 3; ++c) {
        pl->diffuse_color[px * 3 + c] = col[c];
        pl->glossy_color[px * 3 + c] = col[3 + c];
    }
    pl->coverage[px] = col[6];
}

/* replay_pixel for one sample per pixel: its light L (6), or NULL for a miss. */
static inline void replay_pixel1(const shade_job *j, size_t px, const float *L)
{
    const vsgl_shade_plan *plan = j->plan;
    const vsgl_pixel_planes *pl = j->planes;
    const float *cd = plan->cd + px * 4;
    float *d = pl->diffuse + px * 3, *gl = pl->glossy + px * 3;
    if (L) {
        for (int c = 0; c < 3; ++c) {
            d[c] = 0.0f + cd[c] * L[c];
            gl[c] = 0.0f + cd[3] * L[3 + c];
        }
    } else {
        for (int c = 0; c < 3; ++c)
            d[c] = gl[c] = 0.0f;
    }
    if (plan->colours_kept) /* the planes hold them from the last record or replay */
        return;
    const float *col = plan->colour + px * 7;
    memcpy(pl->diffuse_color + px * 3, col, 3 * sizeof *col);
    memcpy(pl->glossy_color + px * 3, col + 3, 3 * sizeof *col);
    pl->coverage[px] = col[6];
}

#if defined(__SSE2__)
/* Four samples of one row (one per pixel) interpolated from the same cell
 * (ax, ay), at tx[0..3], ty, with the weights w4 (4 per sample):
 * replay_sample with the four samples in the lanes, the same operations per
 * lane. Their light into out[c][k] and t into t4[k] (1 where a sample has
 * no interpolation); the samples that have one, returned as bits. */
static inline unsigned interp4(const shade_job *j, const float *pack, const float *w4, uint32_t ax, uint32_t ay,
                               const float *tx, float ty, float out[6][4], float t4[4])
{
    const size_t a0 = (size_t)ay * j->aw + ax;
    const size_t sx = ax + 1 < j->aw ? 1 : 0, sy = ay + 1 < j->ah ? j->aw : 0;
    const float *q[4] = {pack + a0 * 12, pack + (a0 + sx) * 12, pack + (a0 + sy) * 12, pack + (a0 + sx + sy) * 12};
    __m128 r0 = _mm_loadu_ps(w4), r1 = _mm_loadu_ps(w4 + 4), r2 = _mm_loadu_ps(w4 + 8), r3 = _mm_loadu_ps(w4 + 12);
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3); /* ri: anchor i's weight for each of the four samples */
    const __m128 zero = _mm_setzero_ps(), big = _mm_set1_ps(FLT_MAX), neg1 = _mm_set1_ps(-1.0f);
    const __m128 wv[4] = {r0, r1, r2, r3};
    __m128 wsum = zero, L[6], lo[2], hi[2], d2[4];
    _Pragma("GCC unroll 8")
    for (int c = 0; c < 6; ++c)
        L[c] = zero;
    _Pragma("GCC unroll 8")
    for (int l = 0; l < 2; ++l) {
        lo[l] = big;
        hi[l] = zero;
    }
    _Pragma("GCC unroll 8")
    for (int c = 0; c < 4; ++c)
        d2[c] = neg1;
    _Pragma("GCC unroll 8")
    for (int i = 0; i < 4; ++i) {
        const __m128 on = _mm_cmpgt_ps(wv[i], zero), wi = _mm_and_ps(on, wv[i]);
        const float *A = q[i];
        wsum = _mm_add_ps(wsum, wi);
        _Pragma("GCC unroll 8")
        for (int c = 0; c < 6; ++c)
            L[c] = _mm_add_ps(L[c], _mm_mul_ps(wi, _mm_set1_ps(A[c])));
        _Pragma("GCC unroll 8")
        for (int l = 0; l < 2; ++l) {
            const __m128 v = _mm_set1_ps(A[6 + l]);
            lo[l] = _mm_min_ps(_mm_or_ps(_mm_and_ps(on, v), _mm_andnot_ps(on, big)), lo[l]);
            hi[l] = _mm_max_ps(_mm_and_ps(on, v), hi[l]);
        }
        _Pragma("GCC unroll 8")
        for (int c = 0; c < 4; ++c)
            d2[c] = _mm_max_ps(_mm_or_ps(_mm_and_ps(on, _mm_set1_ps(A[8 + c])), _mm_andnot_ps(on, neg1)), d2[c]);
    }
    const __m128 near = _mm_cmpgt_ps(wsum, _mm_set1_ps(0.05f));
    const __m128 vtx = _mm_loadu_ps(tx);
    const __m128 ftx = _mm_mul_ps(vtx, _mm_sub_ps(_mm_set1_ps(1.0f), vtx)), fty = _mm_set1_ps(ty * (1.0f - ty));
    __m128 tw = zero;
    _Pragma("GCC unroll 8")
    for (int l = 0; l < 2; ++l) {
        const __m128 fl = _mm_set1_ps(j->contrast_floor[l]);
        const __m128 m = _mm_div_ps(_mm_add_ps(_mm_add_ps(L[3 * l], L[3 * l + 1]), L[3 * l + 2]), wsum);
        const __m128 bound = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(SPARSE_TOL), m), fl);
        const __m128 dx2 = d2[2 * l], dy2 = d2[2 * l + 1];
        const __m128 contrast = _mm_and_ps(_mm_cmplt_ps(dx2, zero), _mm_cmplt_ps(dy2, zero));
        const __m128 ce = _mm_sub_ps(hi[l], lo[l]),
                     cb = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(SPARSE_CONTRAST), _mm_add_ps(hi[l], lo[l])), fl);
        const __m128 e = _mm_mul_ps(_mm_set1_ps(0.5f), _mm_add_ps(_mm_mul_ps(ftx, _mm_max_ps(dx2, zero)),
                                                                    _mm_mul_ps(fty, _mm_max_ps(dy2, zero))));
        const __m128 tl = shade_weight4(select4(contrast, ce, e), select4(contrast, cb, bound));
        tw = select4(_mm_cmpgt_ps(tl, tw), tl, tw); /* the scalar form's max, not _mm_max_ps */
    }
    const __m128 one = _mm_set1_ps(1.0f), ok = _mm_and_ps(near, _mm_cmplt_ps(tw, one));
    _mm_storeu_ps(t4, select4(ok, tw, one));
    const unsigned bits = (unsigned)_mm_movemask_ps(ok);
    if (!bits)
        return 0;
    _Pragma("GCC unroll 8")
    for (int c = 0; c < 6; ++c)
        _mm_storeu_ps(out[c], _mm_div_ps(L[c], wsum));
    return bits;
}

unsigned vsgl__sparse_interp4(const shade_job *j, const float *pack, const float *w4, uint32_t ax, uint32_t ay,
                              const float *tx, float ty, float out[6][4], float t4[4])
{
    return interp4(j, pack, w4, ax, ay, tx, ty, out, t4);
}

/* Four pixels px..px+3 of one row (one sample each, interpolated from the
 * same cell (ax, ay), at tx[0..3], ty): interp4 and replay_pixel1. Writes
 * the pixels whose samples are interpolated alone (t = 0) and returns them
 * as bits; the others are to be shaded, with t and any interpolated light
 * kept for the blend (plan->blend, plan->interp, at batch index bi0 + k). */
static unsigned replay_cell4(const shade_job *j, const float *pack, size_t px, uint32_t ax, uint32_t ay,
                             const float *tx, float ty, size_t bi0)
{
    const vsgl_shade_plan *plan = j->plan;
    float out[6][4], t4[4];
    const unsigned bits = interp4(j, pack, plan->w4 + px * 4, ax, ay, tx, ty, out, t4);
    unsigned done = 0;
    for (unsigned k = 0; k < 4; ++k) {
        const float light[6] = {out[0][k], out[1][k], out[2][k], out[3][k], out[4][k], out[5][k]};
        if (bits >> k & 1u && t4[k] == 0.0f) {
            replay_pixel1(j, px + k, light);
            done |= 1u << k;
            continue;
        }
        plan->blend[bi0 + k] = t4[k];
        if (bits >> k & 1u)
            memcpy(plan->interp + (bi0 + k) * 6, light, sizeof light);
    }
    return done;
}
#endif

/* A replay's rows [b0, e0) of the batch (one row per chunk): each sample
 * interpolated or marked to be shaded itself (its index in the batch in
 * plan->marks, row by row), and every pixel without such a sample written;
 * the others wait for their samples' light (replay_fixup). */
static int32_t replay_rows(void *user, size_t chunk, size_t b0, size_t e0)
{
    sparse_batch *bt = user;
    const shade_job *j = bt->j;
    const vsgl_shade_plan *plan = j->plan;
    const size_t spp = plan->spp, W = plan->width;
    const float *pack = plan->pack;
    uint32_t *marks = plan->marks + b0 * spp, nm = 0;
    const float *Ls[VSGL__GBUFFER_MAX_SPP];
    float light[VSGL__GBUFFER_MAX_SPP * 6]; /* the pixel's interpolated light (plan->interp only if marked) */
    size_t px = j->base + b0, x = px % W, y = px / W;
    if (spp == 1) { /* the same, one sample per pixel (the live viewport's) */
        for (; px < j->base + e0; ++px, ++x) {
            if (x == W) {
                x = 0;
                ++y;
            }
#if defined(__SSE2__)
            /* four pixels of one row in one cell: their samples four lanes at a time */
            if (x + 4 <= W && px + 4 <= j->base + e0 && plan->cell_x[x] == plan->cell_x[x + 3] &&
                plan->direct[px] == PLAN_NEAR && plan->direct[px + 1] == PLAN_NEAR &&
                plan->direct[px + 2] == PLAN_NEAR && plan->direct[px + 3] == PLAN_NEAR) {
                unsigned ok = replay_cell4(j, pack, px, plan->cell_x[x], plan->cell_y[y], plan->cell_tx + x,
                                           plan->cell_ty[y], px - bt->first);
                for (unsigned k = 0; k < 4; ++k)
                    if (!(ok >> k & 1u))
                        marks[nm++] = (uint32_t)(px + k - bt->first);
                px += 3;
                x += 3;
                continue;
            }
#endif
            const int32_t code = plan->direct[px];
            float t = 1.0f;
            if (code == PLAN_MISS) {
                replay_pixel1(j, px, NULL);
            } else if (code == PLAN_NEAR && replay_sample(j, pack, plan->w4 + px * 4, plan->cell_x[x], plan->cell_y[y],
                                                          plan->cell_tx[x], plan->cell_ty[y], light, &t) &&
                       t == 0.0f) {
                replay_pixel1(j, px, light);
            } else { /* shaded, and blended with its interpolation where t < 1 */
                const size_t bi = px - bt->first;
                marks[nm++] = (uint32_t)bi;
                plan->blend[bi] = t;
                if (t < 1.0f)
                    memcpy(plan->interp + bi * 6, light, 6 * sizeof *light);
            }
        }
        bt->nmarks[chunk] = nm;
        return 0;
    }
    for (; px < j->base + e0; ++px) {
        int marked = 0;
        for (size_t k = 0; k < spp; ++k) {
            const size_t si = px * spp + k, bi = si - bt->first;
            const int32_t code = plan->direct[si];
            if (code == PLAN_MISS) {
                Ls[k] = NULL;
                continue;
            }
            float *o = light + k * 6, t = 1.0f;
            Ls[k] = o;
            if (code == PLAN_ALONE ||
                !replay_sample(j, pack, plan->w4 + si * 4, plan->cell_x[x * spp + k], plan->cell_y[y * spp + k],
                               plan->cell_tx[x * spp + k], plan->cell_ty[y * spp + k], o, &t) ||
                t > 0.0f) { /* shaded, and blended with its interpolation (o) where t < 1 */
                marks[nm++] = (uint32_t)bi;
                plan->blend[bi] = t;
                marked = 1;
            }
        }
        if (marked) {
            const size_t bi = px * spp - bt->first;
            memcpy(plan->interp + bi * 6, light, spp * 6 * sizeof *light);
            for (size_t k = 0; k < spp; ++k) /* its interpolated samples (the marked ones are numbered later) */
                plan->direct_of[bi + k] = UINT32_MAX;
        } else {
            replay_pixel(j, px, Ls);
        }
        if (++x == W) {
            x = 0;
            ++y;
        }
    }
    bt->nmarks[chunk] = nm;
    return 0;
}

/* Entries [b, e) of a replay's samples shaded themselves: the pixel of each
 * first entry of its pixel, from its samples' light. */
static int32_t replay_fixup(void *user, size_t chunk, size_t b, size_t e)
{
    sparse_batch *bt = user;
    const shade_job *j = bt->j;
    const vsgl_shade_plan *plan = j->plan;
    const size_t spp = plan->spp;
    const float *Ls[VSGL__GBUFFER_MAX_SPP];
    (void)chunk;
    for (size_t k = b; k < e; ++k) {
        size_t px = bt->dlist[k] / spp;
        if (k > 0 && bt->dlist[k - 1] / spp == px)
            continue;
        for (size_t s = 0; s < spp; ++s) {
            size_t si = px * spp + s, bi = si - bt->first;
            uint32_t d = plan->direct_of[bi];
            Ls[s] = plan->direct[si] == PLAN_MISS ? NULL
                    : d != UINT32_MAX             ? bt->dlight + (size_t)d * 6
                                                  : plan->interp + bi * 6;
        }
        replay_pixel(j, px, Ls);
    }
    return 0;
}

/* One sample per pixel: entries [b, e) shaded (vsgl__sparse_direct) and
 * their pixels written at once (replay_fixup): each pixel reads its one
 * entry, shaded just before in this chunk. One parallel loop, not two. */
static int32_t replay_direct1(void *user, size_t chunk, size_t b, size_t e)
{
    int32_t r = vsgl__sparse_direct(user, chunk, b, e);
    return r != 0 ? r : replay_fixup(user, chunk, b, e);
}

/* The lanes this replay made from the G-buffer (samples the record did
 * not shade itself: a light edit moves the test's verdict along a shadow
 * or a lit patch's edge), kept in the plan for the next replays: the
 * next light edit shades mostly the same samples, and a lane's setup (the
 * receiver's lobes, their horizon cut) is ~1 us. The same lane a fresh
 * render would make, so the planes stay bit-identical. Up to
 * PLAN_LANES_MAX_BYTES of lanes in all; past it, lanes are made per
 * replay as before. */
#define PLAN_LANES_MAX_BYTES ((size_t)64 << 20)
static void keep_new_lanes(vsgl_shade_plan *plan, const sparse_batch *bt, size_t nd)
{
    size_t made = 0;
    for (size_t k = 0; k < nd; ++k)
        made += plan->dlane_of[bt->dlist[k]] < 0;
    if (!made || (plan->ndlanes + made) * sizeof *plan->dlanes > PLAN_LANES_MAX_BYTES ||
        plan->ndlanes + made >= (size_t)INT32_MAX)
        return;
    if (plan->ndlanes + made > plan->dlanes_cap) {
        size_t cap = 2 * (plan->ndlanes + made) + 64;
        vsgl__plan_lane *grown = realloc(plan->dlanes, cap * sizeof *grown);
        if (!grown)
            return; /* no memory: the next replay makes them again */
        plan->dlanes = grown;
        plan->dlanes_cap = cap;
    }
    for (size_t k = 0; k < nd; ++k) {
        int32_t *d = &plan->dlane_of[bt->dlist[k]];
        if (*d < 0) {
            *d = (int32_t)plan->ndlanes;
            plan->dlanes[plan->ndlanes++] = bt->lanes[k];
        }
    }
}

/* vsgl__shade_sparse_batch for a replay: interpolate and write what can be
 * (replay_rows), shade the rest in full kernel blocks (vsgl__sparse_direct), then
 * write their pixels (replay_fixup). */
vsgl_result vsgl__sparse_replay_batch(vsgl_context *ctx, shade_job *j, size_t row, size_t end)
{
    vsgl_shade_plan *plan = j->plan;
    const size_t W = plan->width, spp = plan->spp, rows = end - row;
    sparse_batch bt;
    memset(&bt, 0, sizeof bt);
    bt.j = j;
    bt.first = row * W * spp;
    bt.ns = rows * W * spp;
    vsgl_result r = VSGL_OK;
    if (plan->scratch_ns < bt.ns) {
        free(plan->interp);
        free(plan->blend);
        free(plan->direct_of);
        free(plan->marks);
        plan->interp = malloc((bt.ns + 1) * 6 * sizeof *plan->interp);
        plan->blend = malloc((bt.ns + 1) * sizeof *plan->blend);
        plan->direct_of = malloc((bt.ns + 1) * sizeof *plan->direct_of);
        plan->marks = malloc((bt.ns + 1) * sizeof *plan->marks);
        plan->scratch_ns = plan->interp && plan->blend && plan->direct_of && plan->marks ? bt.ns : 0;
        if (!plan->scratch_ns) {
            r = VSGL_ERROR_OUT_OF_MEMORY;
            goto done;
        }
    }
    bt.interp = plan->interp; /* the blend's inputs (vsgl__sparse_direct) */
    bt.blend = plan->blend;
    bt.nmarks = malloc((rows + 1) * sizeof *bt.nmarks);
    if (!bt.nmarks || vsgl__parallel_ctx(ctx, rows * W, W, replay_rows, &bt) != 0) {
        r = VSGL_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    size_t nd = 0;
    for (size_t y = 0; y < rows; ++y)
        nd += bt.nmarks[y];
    bt.dlist = malloc((nd + 1) * sizeof *bt.dlist);
    bt.dlight = malloc((nd + 1) * 6 * sizeof *bt.dlight);
    bt.dpairs = calloc(nd / SPARSE_CHUNK + 2, sizeof *bt.dpairs);
    bt.lanes = malloc((nd + 1) * sizeof *bt.lanes);
    if (!bt.dlist || !bt.dlight || !bt.dpairs || !bt.lanes) {
        r = VSGL_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    /* the samples to shade, in sample order (rows in order, each row's in order) */
    size_t k = 0;
    for (size_t y = 0; y < rows; ++y) {
        const uint32_t *m = plan->marks + y * W * spp;
        for (uint32_t i = 0; i < bt.nmarks[y]; ++i, ++k) {
            plan->direct_of[m[i]] = (uint32_t)k;
            bt.dlist[k] = bt.first + m[i];
        }
    }
    if (spp == 1 ? vsgl__parallel_ctx(ctx, nd, SPARSE_CHUNK, replay_direct1, &bt) != 0
                 : (vsgl__parallel_ctx(ctx, nd, SPARSE_CHUNK, vsgl__sparse_direct, &bt) != 0 ||
                    vsgl__parallel_ctx(ctx, nd, 1024, replay_fixup, &bt) != 0)) {
        r = VSGL_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    for (size_t c = 0; c < nd / SPARSE_CHUNK + 2; ++c)
        j->pairs[0] += bt.dpairs[c];
    keep_new_lanes(plan, &bt, nd);
done:
    free(bt.nmarks);
    free(bt.dlist);
    free(bt.dlight);
    free(bt.dpairs);
    free(bt.lanes);
    return r == VSGL_OK ? VSGL_OK : vsgl__fail(ctx, r, "shade: out of memory");
}
