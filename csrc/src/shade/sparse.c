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
 *     (vsgl__shade_sparse_batch).
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
#if defined(__SSE2__)
#  include <emmintrin.h>
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

void vsgl__shade_plan_free(vsgl_shade_plan *p)
{
    if (!p)
        return;
    free(p->row_ok);
    free(p->dlane_of);
    free(p->dlanes);
    free(p->anchor_sample);
    free(p->anchor_lane);
    free(p->w4);
    free(p->direct);
    free(p->cd);
    free(p->colour);
    free(p->cell_x);
    free(p->cell_y);
    free(p->cell_tx);
    free(p->cell_ty);
    free(p->d2_ok);
    free(p->geo);
    free(p->pack);
    free(p->interp);
    free(p->direct_of);
    free(p->marks);
    free(p);
}

/* The anchor cell of slot k of column x (or row y): as sample_cell. */
static void cell_table(uint32_t n, size_t spp, uint32_t aa, uint32_t stride, uint32_t *cell, float *t, int rows)
{
    const float inv_aa = 1.0f / (float)aa, inv_s = 1.0f / (float)stride;
    for (uint32_t x = 0; x < n; ++x)
        for (size_t k = 0; k < spp; ++k) {
            float o = k < (size_t)aa * aa ? (float)(rows ? k / aa : k % aa) * inv_aa : 0.0f;
            float f = ((float)x + o) * inv_s;
            uint32_t c = (uint32_t)f;
            cell[(size_t)x * spp + k] = c;
            t[(size_t)x * spp + k] = f - (float)c;
        }
}

vsgl_shade_plan *vsgl__shade_plan_new(const vsgl_gbuffer *g, const vsgl_render_settings *s, uint32_t aw, uint32_t ah)
{
    vsgl_shade_plan *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    size_t na = (size_t)aw * ah, pixels = (size_t)g->width * g->height;
    p->stride = s->shade_stride;
    p->glossy_mode = (uint32_t)s->glossy_mode;
    p->width = g->width;
    p->height = g->height;
    p->aw = aw;
    p->ah = ah;
    p->spp = g->spp;
    p->count = g->count;
    p->anchor_sample = malloc((na + 1) * sizeof *p->anchor_sample);
    p->anchor_lane = malloc((na + 1) * sizeof *p->anchor_lane);
    p->w4 = malloc((g->count + 1) * 4 * sizeof *p->w4);
    p->direct = malloc((g->count + 1) * sizeof *p->direct);
    p->cd = malloc((g->count + 1) * 4 * sizeof *p->cd);
    p->colour = malloc((pixels + 1) * 7 * sizeof *p->colour);
    p->row_ok = calloc((size_t)g->height + 2, 1);
    p->dlane_of = malloc((g->count + 1) * sizeof *p->dlane_of);
    p->cell_x = malloc(((size_t)g->width * g->spp + 1) * sizeof *p->cell_x);
    p->cell_tx = malloc(((size_t)g->width * g->spp + 1) * sizeof *p->cell_tx);
    p->cell_y = malloc(((size_t)g->height * g->spp + 1) * sizeof *p->cell_y);
    p->cell_ty = malloc(((size_t)g->height * g->spp + 1) * sizeof *p->cell_ty);
    p->d2_ok = calloc(na + 1, 1);
    p->pack = malloc((na + 1) * 12 * sizeof *p->pack);
    p->geo = malloc((na + 1) * 8 * sizeof *p->geo);
    if (!p->anchor_sample || !p->anchor_lane || !p->w4 || !p->direct || !p->cd || !p->colour || !p->row_ok ||
        !p->dlane_of || !p->cell_x || !p->cell_tx || !p->cell_y || !p->cell_ty || !p->d2_ok || !p->pack || !p->geo) {
        vsgl__shade_plan_free(p);
        return NULL;
    }
    cell_table(g->width, g->spp, g->aa, p->stride, p->cell_x, p->cell_tx, 0);
    cell_table(g->height, g->spp, g->aa, p->stride, p->cell_y, p->cell_ty, 1);
    return p;
}

int vsgl__shade_plan_matches(const vsgl_shade_plan *p, const vsgl_gbuffer *g, const vsgl_render_settings *s,
                             uint32_t aw, uint32_t ah)
{
    return p && p->stride == s->shade_stride && p->glossy_mode == (uint32_t)s->glossy_mode &&
           p->width == g->width && p->height == g->height && p->spp == g->spp && p->count == g->count &&
           p->aw == aw && p->ah == ah;
}

int vsgl__shade_plan_complete(const vsgl_shade_plan *p)
{
    for (size_t y = 0; y <= (size_t)p->height; ++y)
        if (!p->row_ok[y])
            return 0;
    return 1;
}

static float same_surface_weight(const shade_job *j, size_t s, size_t a);

/* Anchors shaded per parallel chunk: four kernel blocks. */
#define ANCHOR_CHUNK (4 * VSGL__KERNEL_BLOCK)

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

/* A replay's anchors: each anchor's light, its sum per lobe and its second
 * differences, packed (plan->pack: 12 floats; a missed anchor's light 0),
 * and the interpolation test's floor. The same values, in the same order
 * of operations, as the record's (vsgl__shade_anchors below), but which
 * neighbours share an anchor's surface is read from the record. */
static void anchor_pack(shade_job *j)
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
                if (!(bits >> axis & 1u))
                    continue;
                size_t step = axis == 0 ? 1 : j->aw, m = a - step, p = a + step;
                for (int l = 0; l < 2; ++l)
                    P[a * 12 + 8 + 2 * l + axis] =
                        fabsf(P[m * 12 + 6 + l] - 2.0f * P[a * 12 + 6 + l] + P[p * 12 + 6 + l]);
            }
        }
    for (int l = 0; l < 2; ++l)
        j->contrast_floor[l] = n ? (float)(SPARSE_FLOOR * sum[l] / (double)n) : 0.0f;
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
    if (vsgl__parallel_for(vsgl_context_thread_count(ctx), nh, ANCHOR_CHUNK, anchor_blocks, j) != 0)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "shade: out of memory for the sparse anchors");
    if (plan && !j->replay) {
        memcpy(plan->anchor_sample, j->anchor_sample, na * sizeof *plan->anchor_sample);
        plan->row_ok[plan->height] = 1;
    }
    if (j->replay) { /* the same from the plan's record of which neighbours share a surface */
        anchor_pack(j);
        return VSGL_OK;
    }
    const int record = plan != NULL;
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
                if (record)
                    plan->d2_ok[a] |= (unsigned char)(1u << axis);
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
    if (record) { /* what record_rows reads: the anchors' light and surfaces, packed */
        anchor_pack(j);
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
#define SPARSE_JUNCTION 3.0f
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
 * anchors' (each shaded at its pixel's first sample); sample k of pixel
 * (x, y) lies at (x + (k % aa + 0.5) / aa, ...). */
static inline void sample_cell(const shade_job *j, size_t si, size_t spp, uint32_t aa, float inv_aa, uint32_t *ax,
                               uint32_t *ay, float *tx, float *ty)
{
    const size_t W = j->g->width, px = si / spp, k = si % spp;
    const float inv_s = 1.0f / (float)j->stride;
    float ox = k < aa * aa ? (float)(k % aa) * inv_aa : 0.0f, oy = k < aa * aa ? (float)(k / aa) * inv_aa : 0.0f;
    float fx = ((float)(px % W) + ox) * inv_s, fy = ((float)(px / W) + oy) * inv_s;
    *ax = (uint32_t)fx;
    *ay = (uint32_t)fy;
    *tx = fx - (float)*ax;
    *ty = fy - (float)*ay;
}

/* Plan codes per sample (vsgl_shade_plan.direct): */
#define PLAN_MISS (-2)
#define PLAN_ALONE (-3)  /* no anchor shares its surface: always shaded itself */
#define PLAN_NEAR (-1)   /* interpolated where the interpolation test passes (per render: it reads the light) */

/* The rows of one batch (vsgl__shade_sparse_batch): their samples' interpolated light,
 * which are shaded themselves, and those samples' light, packed in full kernel blocks. */
typedef struct sparse_batch {
    shade_job *j;
    size_t first, ns;        /* the batch's first sample, its sample count */
    float *interp;           /* 6 per sample */
    size_t *direct_of;       /* per sample: SIZE_MAX (interpolated or a miss), else its index in dlist */
    size_t *dlist;           /* the samples shaded themselves, in sample order */
    float *dlight;           /* 6 per entry of dlist */
    uint64_t *dpairs;        /* per chunk of dlist */
    vsgl__plan_lane *lanes;  /* per entry of dlist: its lane (recorded, or for a replay read or made) */
    uint32_t *nmarks;        /* a replay: per row of the batch, its samples to shade (plan->marks) */
} sparse_batch;

#define SPARSE_MARK (SIZE_MAX - 1) /* direct_of of a sample to shade, before it has its index */

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
    for (size_t i = 0; i < ns; ++i) {
        size_t si = first + i, bi = si - bt->first;
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
                /* (a missing second difference, -1, counts as 0; a compare, not
                 * fmaxf, which without -ffinite-math-only is a libm call per sample) */
                float ex = dx2[l] > 0.0f ? dx2[l] : 0.0f, ey = dy2[l] > 0.0f ? dy2[l] : 0.0f;
                float e = 0.5f * (tx * (1.0f - tx) * ex + ty * (1.0f - ty) * ey);
                smooth &= !(e > bound);
            }
        }
        if (sparse_junction(same, sparse_touching(same, other, ad2)))
            smooth = 0;
        if (wsum > 0.05f && smooth) {
            for (int c = 0; c < 6; ++c)
                bt->interp[bi * 6 + c] = L[c] / wsum;
        } else {
            bt->direct_of[bi] = SPARSE_MARK;
        }
    }
    return 0;
}

/* Entries [b, e) of the batch's list of samples shaded themselves. A
 * record keeps their lanes; a replay takes a sample's recorded lane when
 * the record shaded it too (most do: a light edit moves few contrasts),
 * else makes it from the G-buffer. */
static int32_t sparse_direct(void *user, size_t chunk, size_t b, size_t e)
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
#if defined(__x86_64__) || defined(__i386__)
    _mm_setcsr(saved_csr);
#endif
    return rc;
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
        for (size_t k = 0; k < spp; ++k) {
            size_t si = px * spp + k, bi = si - bt->first;
            if (g->material[si] == VSGL__GBUFFER_MISS)
                Ls[k] = NULL;
            else
                Ls[k] = bt->direct_of[bi] != SIZE_MAX ? bt->dlight + bt->direct_of[bi] * 6 : bt->interp + bi * 6;
        }
        vsgl__write_pixel(j, px, Ls, record ? plan->cd + px * spp * 4 : NULL);
        if (record) {
            float *col = plan->colour + px * 7;
            for (int c = 0; c < 3; ++c) {
                col[c] = pl->diffuse_color[px * 3 + c];
                col[3 + c] = pl->glossy_color[px * 3 + c];
            }
            col[6] = pl->coverage[px];
        }
    }
    if (record)
        for (size_t y = (j->base + b0) / W; y < (j->base + e0) / W; ++y)
            plan->row_ok[y] = 1;
    return 0;
}

/* A replay's sample: its light interpolated from the packed anchors of its
 * cell (ax, ay) at (tx, ty) with the recorded weights w (4), into out (6);
 * 0 where it is to be shaded itself. sparse_classify's arithmetic in its
 * order: an anchor of weight 0 adds 0 x its light (finite, 0 for a miss)
 * and leaves the bounds and second differences as they are. */
static inline int replay_sample(const shade_job *j, const float *pack, const float *w, uint32_t ax, uint32_t ay,
                                float tx, float ty, float *out)
{
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
    if (!(wsum > 0.05f))
        return 0;
    /* the interpolation test below, both lobes at once (lanes 0, 1) */
    {
        float L[8];
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
        const __m128 cfail = _mm_cmpgt_ps(
            _mm_sub_ps(hi2, lo2), _mm_add_ps(_mm_mul_ps(_mm_set1_ps(SPARSE_CONTRAST), _mm_add_ps(hi2, lo2)), fl));
        const __m128 e = _mm_mul_ps(_mm_set1_ps(0.5f),
                                    _mm_add_ps(_mm_mul_ps(_mm_set1_ps(tx * (1.0f - tx)), _mm_max_ps(dx2, zero)),
                                               _mm_mul_ps(_mm_set1_ps(ty * (1.0f - ty)), _mm_max_ps(dy2, zero))));
        const __m128 efail = _mm_cmpgt_ps(e, bound);
        const __m128 fail = _mm_or_ps(_mm_and_ps(contrast, cfail), _mm_andnot_ps(contrast, efail));
        if (_mm_movemask_ps(fail) & 3)
            return 0;
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
    if (!(wsum > 0.05f))
        return 0;
    int smooth = 1;
    for (int l = 0; l < 2; ++l) {
        float m = (L[3 * l] + L[3 * l + 1] + L[3 * l + 2]) / wsum;
        float bound = SPARSE_TOL * m + j->contrast_floor[l];
        float dx2 = d2[2 * l], dy2 = d2[2 * l + 1];
        if (dx2 < 0.0f && dy2 < 0.0f) {
            smooth &= !(hi[l] - lo[l] > SPARSE_CONTRAST * (hi[l] + lo[l]) + j->contrast_floor[l]);
            continue;
        }
        float ex = dx2 > 0.0f ? dx2 : 0.0f, ey = dy2 > 0.0f ? dy2 : 0.0f;
        float e = 0.5f * (tx * (1.0f - tx) * ex + ty * (1.0f - ty) * ey);
        smooth &= !(e > bound);
    }
    if (!smooth)
        return 0;
    for (int c = 0; c < 6; ++c)
        out[c] = L[c] / wsum;
#endif
    return 1;
}

/* same_surface_weight of an anchor packed in q (plan->geo) for a sample of
 * normal n, position x and material m: the same operations. */
static inline float packed_surface_weight(const float *n, const float *x, uint32_t m, const float *q, float plane_tol)
{
    uint32_t qm;
    memcpy(&qm, &q[6], sizeof qm);
    if (qm != m)
        return 0.0f;
    float c = n[0] * q[0] + n[1] * q[1] + n[2] * q[2];
    if (!(c > SPARSE_NORMAL_COS))
        return 0.0f;
    float wn = (c - SPARSE_NORMAL_COS) * (1.0f / (1.0f - SPARSE_NORMAL_COS));
    float d0 = q[3] - x[0], d1 = q[4] - x[1], d2 = q[5] - x[2];
    float off = fabsf(d0 * n[0] + d1 * n[1] + d2 * n[2]);
    float tol = SPARSE_PLANE_REL * sqrtf(d0 * d0 + d1 * d1 + d2 * d2) + plane_tol;
    float wp = 1.0f - off / tol;
    if (!(wp > 0.0f))
        return 0.0f;
    return wn * wp;
}

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
                    float wa = wb * (as == si ? 1.0f : packed_surface_weight(n, xs, m, plan->geo + a * 8, j->plane_tol));
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
            plan->direct[si] =
                wsum > 0.05f && !sparse_junction(same, sparse_touching(same, other, ad2)) ? PLAN_NEAR : PLAN_ALONE;
            if (plan->direct[si] == PLAN_ALONE || !replay_sample(j, plan->pack, w, ax, ay, tx, ty, bt->interp + bi * 6))
                bt->direct_of[bi] = SPARSE_MARK;
        }
        if (++x == W) {
            x = 0;
            ++y;
        }
    }
    return 0;
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
    const float *col = plan->colour + px * 7;
    for (int c = 0; c < 3; ++c) {
        pl->diffuse[px * 3 + c] = acc[c];
        pl->glossy[px * 3 + c] = acc[3 + c];
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
    const float *cd = plan->cd + px * 4, *col = plan->colour + px * 7;
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
    memcpy(pl->diffuse_color + px * 3, col, 3 * sizeof *col);
    memcpy(pl->glossy_color + px * 3, col + 3, 3 * sizeof *col);
    pl->coverage[px] = col[6];
}

#if defined(__SSE2__)
/* Four pixels px..px+3 of one row (one sample each, interpolated from the
 * same cell (ax, ay), at tx[0..3], ty): replay_sample and replay_pixel1 with
 * the four samples in the lanes, the same operations per lane. Writes the
 * pixels whose samples pass the interpolation test; returns them as bits. */
static unsigned replay_cell4(const shade_job *j, const float *pack, size_t px, uint32_t ax, uint32_t ay,
                             const float *tx, float ty)
{
    const vsgl_shade_plan *plan = j->plan;
    const size_t a0 = (size_t)ay * j->aw + ax;
    const size_t sx = ax + 1 < j->aw ? 1 : 0, sy = ay + 1 < j->ah ? j->aw : 0;
    const float *q[4] = {pack + a0 * 12, pack + (a0 + sx) * 12, pack + (a0 + sy) * 12, pack + (a0 + sx + sy) * 12};
    const float *w4 = plan->w4 + px * 4;
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
    __m128 ok = _mm_cmpgt_ps(wsum, _mm_set1_ps(0.05f));
    const __m128 vtx = _mm_loadu_ps(tx);
    const __m128 ftx = _mm_mul_ps(vtx, _mm_sub_ps(_mm_set1_ps(1.0f), vtx)), fty = _mm_set1_ps(ty * (1.0f - ty));
    _Pragma("GCC unroll 8")
    for (int l = 0; l < 2; ++l) {
        const __m128 fl = _mm_set1_ps(j->contrast_floor[l]);
        const __m128 m = _mm_div_ps(_mm_add_ps(_mm_add_ps(L[3 * l], L[3 * l + 1]), L[3 * l + 2]), wsum);
        const __m128 bound = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(SPARSE_TOL), m), fl);
        const __m128 dx2 = d2[2 * l], dy2 = d2[2 * l + 1];
        const __m128 contrast = _mm_and_ps(_mm_cmplt_ps(dx2, zero), _mm_cmplt_ps(dy2, zero));
        const __m128 cfail = _mm_cmpgt_ps(_mm_sub_ps(hi[l], lo[l]),
                                          _mm_add_ps(_mm_mul_ps(_mm_set1_ps(SPARSE_CONTRAST), _mm_add_ps(hi[l], lo[l])), fl));
        const __m128 e = _mm_mul_ps(_mm_set1_ps(0.5f), _mm_add_ps(_mm_mul_ps(ftx, _mm_max_ps(dx2, zero)),
                                                                    _mm_mul_ps(fty, _mm_max_ps(dy2, zero))));
        const __m128 fail = _mm_or_ps(_mm_and_ps(contrast, cfail), _mm_andnot_ps(contrast, _mm_cmpgt_ps(e, bound)));
        ok = _mm_andnot_ps(fail, ok);
    }
    const unsigned bits = (unsigned)_mm_movemask_ps(ok);
    if (!bits)
        return 0;
    float out[6][4];
    _Pragma("GCC unroll 8")
    for (int c = 0; c < 6; ++c)
        _mm_storeu_ps(out[c], _mm_div_ps(L[c], wsum));
    for (unsigned k = 0; k < 4; ++k)
        if (bits >> k & 1u) {
            const float light[6] = {out[0][k], out[1][k], out[2][k], out[3][k], out[4][k], out[5][k]};
            replay_pixel1(j, px + k, light);
        }
    return bits;
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
                                           plan->cell_ty[y]);
                for (unsigned k = 0; k < 4; ++k)
                    if (!(ok >> k & 1u))
                        marks[nm++] = (uint32_t)(px + k - bt->first);
                px += 3;
                x += 3;
                continue;
            }
#endif
            const int32_t code = plan->direct[px];
            if (code == PLAN_MISS) {
                replay_pixel1(j, px, NULL);
            } else if (code == PLAN_ALONE || !replay_sample(j, pack, plan->w4 + px * 4, plan->cell_x[x],
                                                             plan->cell_y[y], plan->cell_tx[x], plan->cell_ty[y],
                                                             light)) {
                marks[nm++] = (uint32_t)(px - bt->first);
            } else {
                replay_pixel1(j, px, light);
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
            float *o = light + k * 6;
            Ls[k] = o;
            if (code == PLAN_ALONE ||
                !replay_sample(j, pack, plan->w4 + si * 4, plan->cell_x[x * spp + k], plan->cell_y[y * spp + k],
                               plan->cell_tx[x * spp + k], plan->cell_ty[y * spp + k], o)) {
                marks[nm++] = (uint32_t)bi;
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

/* vsgl__shade_sparse_batch for a replay: interpolate and write what can be
 * (replay_rows), shade the rest in full kernel blocks (sparse_direct), then
 * write their pixels (replay_fixup). */
static vsgl_result replay_batch(vsgl_context *ctx, shade_job *j, size_t row, size_t end)
{
    vsgl_shade_plan *plan = j->plan;
    const size_t W = plan->width, spp = plan->spp, rows = end - row;
    const uint32_t threads = vsgl_context_thread_count(ctx);
    sparse_batch bt;
    memset(&bt, 0, sizeof bt);
    bt.j = j;
    bt.first = row * W * spp;
    bt.ns = rows * W * spp;
    vsgl_result r = VSGL_OK;
    if (plan->scratch_ns < bt.ns) {
        free(plan->interp);
        free(plan->direct_of);
        free(plan->marks);
        plan->interp = malloc((bt.ns + 1) * 6 * sizeof *plan->interp);
        plan->direct_of = malloc((bt.ns + 1) * sizeof *plan->direct_of);
        plan->marks = malloc((bt.ns + 1) * sizeof *plan->marks);
        plan->scratch_ns = plan->interp && plan->direct_of && plan->marks ? bt.ns : 0;
        if (!plan->scratch_ns) {
            r = VSGL_ERROR_OUT_OF_MEMORY;
            goto done;
        }
    }
    bt.nmarks = malloc((rows + 1) * sizeof *bt.nmarks);
    if (!bt.nmarks || vsgl__parallel_for(threads, rows * W, W, replay_rows, &bt) != 0) {
        r = VSGL_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    size_t nd = 0;
    for (size_t y = 0; y < rows; ++y)
        nd += bt.nmarks[y];
    bt.dlist = malloc((nd + 1) * sizeof *bt.dlist);
    bt.dlight = malloc((nd + 1) * 6 * sizeof *bt.dlight);
    bt.dpairs = calloc(nd / ANCHOR_CHUNK + 2, sizeof *bt.dpairs);
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
    if (vsgl__parallel_for(threads, nd, ANCHOR_CHUNK, sparse_direct, &bt) != 0 ||
        vsgl__parallel_for(threads, nd, 1024, replay_fixup, &bt) != 0) {
        r = VSGL_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    for (size_t c = 0; c < nd / ANCHOR_CHUNK + 2; ++c)
        j->pairs[0] += bt.dpairs[c];
done:
    free(bt.nmarks);
    free(bt.dlist);
    free(bt.dlight);
    free(bt.dpairs);
    free(bt.lanes);
    return r == VSGL_OK ? VSGL_OK : vsgl__fail(ctx, r, "shade: out of memory");
}

vsgl_result vsgl__shade_sparse_batch(vsgl_context *ctx, shade_job *j, size_t row, size_t end)
{
    if (j->replay)
        return replay_batch(ctx, j, row, end);
    const vsgl_gbuffer *g = j->g;
    const size_t W = g->width, spp = g->spp;
    const uint32_t threads = vsgl_context_thread_count(ctx);
    sparse_batch bt;
    memset(&bt, 0, sizeof bt);
    bt.j = j;
    bt.first = row * W * spp;
    bt.ns = (end - row) * W * spp;
    bt.interp = malloc((bt.ns + 1) * 6 * sizeof *bt.interp);
    bt.direct_of = malloc((bt.ns + 1) * sizeof *bt.direct_of);
    bt.dlist = malloc((bt.ns + 1) * sizeof *bt.dlist);
    vsgl_result r = VSGL_OK;
    if (!bt.interp || !bt.direct_of || !bt.dlist ||
        vsgl__parallel_for(threads, (end - row) * W, W, j->plan ? record_rows : sparse_classify, &bt) != 0) {
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
    bt.dpairs = calloc(nd / ANCHOR_CHUNK + 2, sizeof *bt.dpairs);
    vsgl_shade_plan *plan = j->plan;
    if (plan) /* a record keeps the lanes */
        bt.lanes = malloc((nd + 1) * sizeof *bt.lanes);
    if (!bt.dlight || !bt.dpairs || (plan && !bt.lanes) ||
        vsgl__parallel_for(threads, nd, ANCHOR_CHUNK, sparse_direct, &bt) != 0 ||
        vsgl__parallel_for(threads, (end - row) * W, W, sparse_resolve, &bt) != 0) {
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
    for (size_t c = 0; c < nd / ANCHOR_CHUNK + 2; ++c)
        j->pairs[0] += bt.dpairs[c];
done:
    free(bt.interp);
    free(bt.direct_of);
    free(bt.dlist);
    free(bt.dlight);
    free(bt.dpairs);
    free(bt.lanes);
    return r == VSGL_OK ? VSGL_OK : vsgl__fail(ctx, r, "shade: out of memory");
}
