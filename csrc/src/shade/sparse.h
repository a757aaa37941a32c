/* Internal to shading one pixel in S x S (shade_stride > 1): what the
 * record / classify path (sparse.c), the replay (sparse_replay.c) and the
 * plan's lifetime (sparse_plan.c) share. See sparse.c for the method. */
#ifndef VSGL_SHADE_SPARSE_H
#define VSGL_SHADE_SPARSE_H

#include "shade/shade_job.h"
#include "core/context.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>

/* A same-surface test's tolerances (see the file comment). */
/* Normals within ~6 degrees: a curved surface at a grazing view (a sphere's
 * rim) is shaded where its normal turns faster than that between anchors;
 * with ~25 degrees its rim, interpolated from anchors further inside, jumped
 * as the silhouette crossed them (the sphere room's glossy frame-to-frame
 * change as the camera moves 0.114 -> 0.043 at 80 x 60; 0.053 shading 8 x 8
 * samples in every pixel). Flat surfaces have one normal. */
#define SPARSE_NORMAL_COS 0.995f
/* ... and tighter on a sharp glossy material, whose reflection turns
 * twice as fast as its normal: normals within SPARSE_GLOSSY_TURN times the
 * GGX alpha (sqrt(alpha_x alpha_y) of the material's constants). Within ~6
 * degrees a sample on the glossy sphere's rim (alpha 0.09, 5.2 degrees)
 * took the light of an anchor a pixel further inside, whose reflection
 * differed by more than its lobe: pixels lost a fifth of their Gloss for
 * one frame as the camera moved (320 x 240, balanced: Gloss camera
 * flicker above a dense render 0.0276 -> 0.0206, 0.0202 shading every
 * pixel; in a build that also shaded samples lacking a second difference,
 * 0.0260 -> 0.0206 with 0.5 x alpha, 0.0230 with 1 x alpha). */
#define SPARSE_GLOSSY_TURN 0.5f
/* ... but never under 0.01 radians (0.6 degrees): a mirror's alpha is
 * 5e-10, whose cosine is 1 in float, and no two normals, not even a flat
 * floor's own, would then be one surface. */
#define SPARSE_GLOSSY_MIN_TURN 0.01f

/* The same-surface cosine of material m and 1 / (1 - it) in *inv. */
static inline float sparse_normal_cos(const shade_job *j, uint32_t m, float *inv)
{
    if (j->normal_cos) {
        *inv = j->normal_cos[2 * (size_t)m + 1];
        return j->normal_cos[2 * (size_t)m];
    }
    *inv = 1.0f / (1.0f - SPARSE_NORMAL_COS);
    return SPARSE_NORMAL_COS;
}
#define SPARSE_PLANE_REL 0.05f

/* Slot k's raster offset from its pixel's first sample (the anchors are
 * shaded at their pixels' first samples), for k on the aa x aa pattern
 * (vsgl__gbuffer_pattern); 0 for the slots beyond it. sparse.c's
 * sample_cell and sparse_plan.c's cell tables take it alike, to the bit. */
static inline void sparse_slot_offset(size_t k, uint32_t aa, float inv_aa, float *ox, float *oy)
{
    *ox = *oy = 0.0f;
    if (k < (size_t)aa * aa) {
        float x0, y0;
        vsgl__gbuffer_pattern((uint32_t)k, aa, inv_aa, ox, oy);
        vsgl__gbuffer_pattern(0u, aa, inv_aa, &x0, &y0);
        *ox -= x0;
        *oy -= y0;
    }
}
/* The anchor cell c and the weight t of the next anchor along one axis
 * for raster position x + o (o: the slot's offset, sparse_slot_offset) of
 * an image n pixels long: anchors sit at S c, the last one on pixel n - 1
 * (vsgl__shade_anchors). A cell that reaches past it is narrower than S,
 * and t is taken across its own width: as if it were S wide, the last
 * column's samples took half their light from the anchor a pixel before
 * (the sun room's last row and column at 80 x 60, stride 2: Diff up to
 * 3.5 % off where every pixel shaded is within 0.2 %). Past the last
 * anchor (the last pixel's later slots, aa > 1) t exceeds 1: such a sample
 * would be extrapolated, and is shaded itself (sparse_past_anchor).
 * sparse.c's sample_cell and sparse_plan.c's tables both call it. */
static inline void sparse_axis_cell(uint32_t x, float o, uint32_t stride, uint32_t n, uint32_t *c, float *t)
{
    const float f = ((float)x + o) * (1.0f / (float)stride);
    uint32_t a = (uint32_t)f;
    float w = f - (float)a;
    if (stride * (a + 1) > n - 1) { /* the last cell: its far anchor is pixel n - 1 */
        const float x0 = (float)(stride * a), width = (float)(n - 1) - x0;
        if (width > 0.0f) {
            w = ((float)x + o - x0) / width;
        } else if (a > 0) { /* on the last anchor itself: past the cell before it */
            a -= 1;
            w = 1.0f + ((float)x + o - x0) * (1.0f / (float)stride);
        } else { /* a one-pixel side: its one anchor */
            w = 0.0f;
        }
    }
    *c = a;
    *t = w;
}

/* A sample past the last anchor of its row or column (sparse_axis_cell's
 * t above 1): its light would be extrapolated; it is shaded itself. Taken
 * from the last anchor, the floor's reflected ellipse in the spot room's
 * last row at 80 x 60 (quality: 3 x 3 samples, the anchor shaded at the
 * pixel's first, where the reflection falls by a quarter per pixel) was
 * 12 % too bright. (Its bilinear weights, one of them negative and
 * skipped, are computed like any sample's but never used.) */
static inline int sparse_past_anchor(float tx, float ty)
{
    return tx > 1.0f || ty > 1.0f;
}

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
/* Beside a junction. Where an anchor's neighbour along an axis lies on
 * another surface that touches its own (a wall's foot, a room's corner),
 * the light bends towards the junction within the cell before it, and no
 * second difference through the anchors sees that: the red-wall room's
 * ceiling row next to the back wall, interpolated, was 3-12 % darker than
 * every pixel shaded (80 x 60, stride 2: a dark seam). The anchor's second
 * difference along that axis is then taken as SPARSE_JUNCTION_SLOPE times
 * the step of its light from its neighbour on its own surface: a bend
 * proportional to the light's change there, none where the light is flat
 * (1: half the pairs' rise at 80 x 60 for about half the gain, and
 * test_render.c's seam 10 pixels long, not 5; every sample there shaded:
 * 1.2-2x the pairs at 80 x 60; docs/accuracy.md, "Seams beside a
 * junction"). */
#ifndef SPARSE_JUNCTION_SLOPE
#define SPARSE_JUNCTION_SLOPE 2.0f
#endif
/* An anchor's second difference along an axis from the light sums (per
 * lobe: R + G + B) of its neighbours m, p and itself a; beside a junction,
 * the bend from its own sum a and its same-surface neighbour's s. The
 * record (sparse.c, from the anchors' light) and a replay (sparse_replay.c,
 * from the packed sums) take these same functions of the same sums: their
 * verdicts agree bit for bit. */
static inline float sparse_d2(float m, float a, float p) { return fabsf(m - 2.0f * a + p); }
static inline float sparse_junction_bend(float a, float s) { return SPARSE_JUNCTION_SLOPE * fabsf(a - s); }
/* How far an anchor on another surface may lie and still touch the
 * sample's (times the distance of an anchor on the sample's own surface:
 * the farthest of the cell's, or the neighbour's along the axis): further
 * away it is an occluder's or a background's edge, a depth step with no
 * near field (sparse.c's junction tests). */
#define SPARSE_JUNCTION 3.0f
/* ... and it is a junction only where the surfaces meet at a crease (the
 * normals more than ~25 degrees apart) or the material changes: not at a
 * bump of one bumpy surface (the 500k-triangle floor's pairs at 960 x 540
 * +23 % without this, +3 % with it). */
#define SPARSE_JUNCTION_CREASE_COS 0.9f
/* Anchor as (its sample) beside a junction along one axis: its neighbour s
 * there shares its surface, the one on the other side, o, does not, and
 * touches it at a crease. */
static inline int sparse_beside_junction(const vsgl_gbuffer *g, size_t as, size_t s, size_t o)
{
    float ds = 0.0f, dO = 0.0f;
    for (int c = 0; c < 3; ++c) {
        const float u = g->pos[c][s] - g->pos[c][as], v = g->pos[c][o] - g->pos[c][as];
        ds += u * u;
        dO += v * v;
    }
    const float c = g->nrm[0][as] * g->nrm[0][o] + g->nrm[1][as] * g->nrm[1][o] + g->nrm[2][as] * g->nrm[2][o];
    return dO <= SPARSE_JUNCTION * SPARSE_JUNCTION * ds &&
           (g->material[o] != g->material[as] || c < SPARSE_JUNCTION_CREASE_COS);
}
/* The verdict is soft: a sample whose estimated error e is up to
 * SPARSE_BLEND of the bound is interpolated, one beyond the bound shaded,
 * and one in between shaded too and given (1 - t) x its interpolated light
 * + t x its shaded light, t rising linearly from 0 to 1 across the band
 * (sparse_shade_weight). A hard verdict flips wherever the test's inputs
 * cross the bound, and as the camera moves the anchors slide over a
 * surface: pixels then jumped between light off by up to SPARSE_TOL and
 * exact light, speckles inside a glossy cabinet's face. The sun room's
 * glossy jitter as the camera moves (80 x 60, balanced, with the edge
 * slots' mean point, gbuffer/edges.c): 0.0099 hard, 0.0095 from 3/4,
 * 0.0089 from 1/2; shaded pairs at 320 x 240 in the sun rooms and the
 * sphere room +3 / +9 / +14 % from 3/4, +10 / +26 / +39 % from 1/2.
 * (-DSPARSE_BLEND=1 builds the hard verdict, for such measurements.) */
#ifndef SPARSE_BLEND
#define SPARSE_BLEND 0.75f
#endif

/* t for error e against bound (contrast: the anchors' spread against its bound):
 * 0 interpolated, 1 shaded, between: blended (see SPARSE_BLEND). Each path
 * computes it with these operations in this order (the SSE forms in
 * sparse_replay.c), so a render with a plan and one without agree bit for bit. */
static inline float sparse_shade_weight(float e, float bound)
{
    if (e > bound)
        return 1.0f;
    const float x = e - SPARSE_BLEND * bound;
    if (!(x > 0.0f))
        return 0.0f;
    const float t = x / ((1.0f - SPARSE_BLEND) * bound);
    return t < 1.0f ? t : 1.0f;
}

/* Anchors, and samples shaded themselves, per parallel chunk: four kernel blocks. */
#define SPARSE_CHUNK (4 * VSGL__KERNEL_BLOCK)

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
    float *blend;            /* per sample shaded itself: t (sparse_shade_weight), 1 where it has no interpolation */
    size_t *direct_of;       /* per sample: SIZE_MAX (interpolated or a miss), else its index in dlist */
    size_t *dlist;           /* the samples shaded themselves, in sample order */
    float *dlight;           /* 6 per entry of dlist */
    uint64_t *dpairs;        /* per chunk of dlist */
    vsgl__plan_lane *lanes;  /* per entry of dlist: its lane (recorded, or for a replay read or made) */
    uint32_t *nmarks;        /* a replay: per row of the batch, its samples to shade (plan->marks) */
} sparse_batch;

#define SPARSE_MARK (SIZE_MAX - 1) /* direct_of of a sample to shade, before it has its index */

/* Entries [b, e) of the batch's list of samples shaded themselves, in full
 * kernel blocks (sparse.c; vsgl__parallel_for's callback, user: a sparse_batch). */
int32_t vsgl__sparse_direct(void *user, size_t chunk, size_t b, size_t e);

/* The anchors' light packed for the interpolation (plan->pack), and for a
 * replay their second differences and the test's floor (sparse_replay.c). */
void vsgl__sparse_anchor_pack(shade_job *j);

/* A sample's light interpolated from the packed anchors of its cell (ax, ay)
 * at (tx, ty) with the weights w (4) into out (6) and its t
 * (sparse_shade_weight) into *t; 0 where it has no interpolation (shaded
 * itself, t = 1) (sparse_replay.c). */
int vsgl__sparse_interp(const shade_job *j, const float *pack, const float *w, uint32_t ax, uint32_t ay, float tx,
                        float ty, float *out, float *t);

#if defined(__SSE2__)
/* The same for four samples of one row (one per pixel) in one cell, at
 * tx[0..3], ty, with the weights w4 (4 per sample): their light into
 * out[c][k] and t into t4[k], the samples that have an interpolation as
 * bits (sparse_replay.c). */
unsigned vsgl__sparse_interp4(const shade_job *j, const float *pack, const float *w4, uint32_t ax, uint32_t ay,
                              const float *tx, float ty, float out[6][4], float t4[4]);
#endif

/* vsgl__shade_sparse_batch for a replay (sparse_replay.c). */
vsgl_result vsgl__sparse_replay_batch(vsgl_context *ctx, shade_job *j, size_t row, size_t end);

#endif
