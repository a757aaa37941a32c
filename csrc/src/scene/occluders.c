/* Which segments can a triangle block at all? Answered from bounds, before
 * a visibility ray is traced.
 *
 * A room's walls, floor and ceiling lie on the faces of the scene's
 * bounding box. A segment whose two ends lie strictly inside the box (by
 * more than the faces' tolerance) stays inside it, so it cannot meet a
 * triangle lying within that tolerance of a face: only the other
 * triangles (furniture, a sphere, a window's reveal; "the occluders") can
 * block it. They are bounded by a few boxes (a midpoint split of their
 * centroids); a segment inside the scene's box that misses every one of
 * them is unblocked, and no ray is traced for it. Every other segment is
 * traced against the whole scene as before, so the answer is the ray's
 * own: the test only ever proves "unblocked", with boxes padded well past
 * float rounding.
 *
 * Balanced at 320x240: the glossy-sphere room's segments are half clear
 * (51 of 106 M), though those were Embree's cheap ones (a miss at its
 * root): 2.27 -> 2.17 s, the box test costing most of what it saves; the
 * sun rooms' cabinet and window reveals leave more of the room free. */
#include "scene/scene_data.h"

#include <math.h>
#include <stdlib.h>

/* Leaves of the occluders' split: at most 2^depth boxes, each with at least
 * this many triangles unless the split runs out of depth. */
#define VSGL__OCC_DEPTH 4
#define VSGL__OCC_LEAF 32u
/* The leaves are kept only when their surface areas sum to less than this
 * fraction of their union's. */
#define VSGL__OCC_LEAVES_PAY 0.5

static double surface_area(const float *b)
{
    double x = (double)b[3] - b[0], y = (double)b[4] - b[1], z = (double)b[5] - b[2];
    return 2.0 * (x * y + y * z + z * x);
}

/* 1 if triangle t lies within tol of one face of [lo, hi]. */
static int on_box_face(const vsgl_scene *s, uint32_t t, float tol)
{
    const float *p[3];
    for (int k = 0; k < 3; ++k)
        p[k] = s->positions + 3 * (size_t)s->indices[3 * (size_t)t + k];
    const float lo[3] = {s->lo.x, s->lo.y, s->lo.z}, hi[3] = {s->hi.x, s->hi.y, s->hi.z};
    for (int a = 0; a < 3; ++a) {
        int at_lo = 1, at_hi = 1;
        for (int k = 0; k < 3; ++k) {
            at_lo &= p[k][a] - lo[a] <= tol;
            at_hi &= hi[a] - p[k][a] <= tol;
        }
        if (at_lo || at_hi)
            return 1;
    }
    return 0;
}

/* Positions are finite (validated): plain compares, no libm calls */
static inline float min_f(float a, float b)
{
    return a < b ? a : b;
}

static inline float max_f(float a, float b)
{
    return a > b ? a : b;
}

static void tri_bounds(const vsgl_scene *s, uint32_t t, float b[6])
{
    b[0] = b[1] = b[2] = INFINITY;
    b[3] = b[4] = b[5] = -INFINITY;
    for (int k = 0; k < 3; ++k) {
        const float *p = s->positions + 3 * (size_t)s->indices[3 * (size_t)t + k];
        for (int a = 0; a < 3; ++a) {
            b[a] = min_f(b[a], p[a]);
            b[3 + a] = max_f(b[3 + a], p[a]);
        }
    }
}

/* Boxes of the triangles tri[0..n) (indices into bounds, 6 floats each:
 * lo xyz, hi xyz) into s->occ_boxes, split at the midpoint of their
 * centroids' extent along its longest axis. */
static void split(vsgl_scene *s, const float *bounds, uint32_t *tri, uint32_t n, int depth, float pad)
{
    float c_lo[3] = {INFINITY, INFINITY, INFINITY}, c_hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    float box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < n; ++i) {
        const float *b = bounds + 6 * (size_t)tri[i];
        for (int a = 0; a < 3; ++a) {
            float c = 0.5f * (b[a] + b[3 + a]);
            c_lo[a] = min_f(c_lo[a], c);
            c_hi[a] = max_f(c_hi[a], c);
            box[a] = min_f(box[a], b[a]);
            box[3 + a] = max_f(box[3 + a], b[3 + a]);
        }
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (c_hi[a] - c_lo[a] > c_hi[axis] - c_lo[axis])
            axis = a;
    float mid = 0.5f * (c_lo[axis] + c_hi[axis]);
    uint32_t m = 0;
    if (depth < VSGL__OCC_DEPTH && n >= 2 * VSGL__OCC_LEAF && c_hi[axis] > c_lo[axis]) {
        for (uint32_t i = 0; i < n; ++i) { /* partition: centroid below mid first */
            const float *b = bounds + 6 * (size_t)tri[i];
            if (0.5f * (b[axis] + b[3 + axis]) < mid) {
                uint32_t x = tri[i];
                tri[i] = tri[m];
                tri[m++] = x;
            }
        }
    }
    if (m > 0 && m < n) {
        split(s, bounds, tri, m, depth + 1, pad);
        split(s, bounds, tri + m, n - m, depth + 1, pad);
        return;
    }
    float *o = s->occ_boxes + 6 * (size_t)s->occ_count++;
    for (int a = 0; a < 6; ++a)
        o[a] = box[a] + (a < 3 ? -pad : pad);
}

vsgl_result vsgl__scene_build_occluders(vsgl_context *ctx, vsgl_scene *s)
{
    s->occ_count = 0;
    s->occ_boxes = NULL;
    s->occ_inner_lo = v3_make(INFINITY, INFINITY, INFINITY); /* empty: nothing is inside, every ray traced */
    s->occ_inner_hi = v3_make(-INFINITY, -INFINITY, -INFINITY);
    if (s->triangle_count == 0)
        return VSGL_OK;
    v3 ext = v3_sub(s->hi, s->lo);
    float size = v3_length(ext);
    float mag = fmaxf(fmaxf(fmaxf(fabsf(s->lo.x), fabsf(s->lo.y)), fmaxf(fabsf(s->lo.z), fabsf(s->hi.x))),
                      fmaxf(fabsf(s->hi.y), fabsf(s->hi.z)));
    /* a face's tolerance: float jitter of a transformed vertex (~2 ulp of the
     * coordinates), below the shading's ray offset (1e-5 of the extent) */
    float tol = fmaxf(1e-6f * size, 2.4e-7f * mag);
    if (!(size > 0.0f) || !(size < INFINITY))
        return VSGL_OK;
    uint32_t *tri = malloc((size_t)s->triangle_count * sizeof *tri);
    if (!tri)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: no memory for the occluders' list (%u triangles)",
                          s->triangle_count);
    /* the occluders' bounds, once (the split reads them at every level) */
    float *bounds = malloc((size_t)s->triangle_count * 6 * sizeof *bounds);
    if (!bounds) {
        free(tri);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: no memory for the occluders' bounds (%u triangles)",
                          s->triangle_count);
    }
    uint32_t n = 0;
    for (uint32_t t = 0; t < s->triangle_count; ++t)
        if (!on_box_face(s, t, tol)) {
            tri_bounds(s, t, bounds + 6 * (size_t)n);
            tri[n] = t; /* the occluders' ids first, for occlude_few.c */
            ++n;
        }
    s->occ_triangles = n;
    vsgl_result r = VSGL_OK;
    if (n > 0 && n <= VSGL__OCC_FEW)
        r = vsgl__scene_build_few(ctx, s, tri, n);
    if (r != VSGL_OK) {
        free(tri);
        free(bounds);
        return r;
    }
    for (uint32_t i = 0; i < n; ++i)
        tri[i] = i;
    if (n > 0) {
        s->occ_boxes = malloc(sizeof(float) * 6 * ((size_t)1 << VSGL__OCC_DEPTH));
        if (!s->occ_boxes) {
            free(tri);
            free(bounds);
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: no memory for the occluders' boxes");
        }
        /* padded by far more than the rounding of a segment's end points */
        split(s, bounds, tri, n, 0, 4.0f * tol + 1e-5f * size);
        for (int a = 0; a < 3; ++a) {
            s->occ_union[a] = INFINITY;
            s->occ_union[3 + a] = -INFINITY;
        }
        double leaves = 0.0;
        for (uint32_t i = 0; i < s->occ_count; ++i) {
            leaves += surface_area(s->occ_boxes + 6 * (size_t)i);
            for (int a = 0; a < 3; ++a) {
                s->occ_union[a] = fminf(s->occ_union[a], s->occ_boxes[6 * i + a]);
                s->occ_union[3 + a] = fmaxf(s->occ_union[3 + a], s->occ_boxes[6 * i + 3 + a]);
            }
        }
        /* a segment meets a box with a chance ~ its surface area: leaves
         * that together are not much smaller than their union (one compact
         * object: a sphere's octants) would be tested for nothing */
        if (leaves > VSGL__OCC_LEAVES_PAY * surface_area(s->occ_union)) {
            s->occ_count = 1;
            for (int a = 0; a < 6; ++a)
                s->occ_boxes[a] = s->occ_union[a];
        }
    }
    free(tri);
    free(bounds);
    /* twice the tolerance: a segment's end points are rounded too */
    s->occ_inner_lo = v3_make(s->lo.x + 2.0f * tol, s->lo.y + 2.0f * tol, s->lo.z + 2.0f * tol);
    s->occ_inner_hi = v3_make(s->hi.x - 2.0f * tol, s->hi.y - 2.0f * tol, s->hi.z - 2.0f * tol);
    return VSGL_OK;
}

/* Does segment p + t d, t in [0, 1], meet box b (lo xyz, hi xyz)? inv =
 * 1 / d per axis (inf where d is 0). */
static int segment_meets_box(v3 p, v3 d, v3 inv, const float *b)
{
    float t0 = 0.0f, t1 = 1.0f;
    const float pa[3] = {p.x, p.y, p.z}, da[3] = {d.x, d.y, d.z}, ia[3] = {inv.x, inv.y, inv.z};
    for (int a = 0; a < 3; ++a) {
        if (da[a] == 0.0f) { /* parallel to the slab: inside it or never */
            if (pa[a] < b[a] || pa[a] > b[3 + a])
                return 0;
            continue;
        }
        float u0 = (b[a] - pa[a]) * ia[a], u1 = (b[3 + a] - pa[a]) * ia[a];
        float lo = u0 < u1 ? u0 : u1, hi = u0 < u1 ? u1 : u0;
        t0 = lo > t0 ? lo : t0;
        t1 = hi < t1 ? hi : t1;
    }
    return t0 <= t1;
}

int vsgl__scene_segment_clear(const vsgl_scene *s, v3 a, v3 b)
{
    if (!vsgl__scene_strictly_inside(s, a.x, a.y, a.z) || !vsgl__scene_strictly_inside(s, b.x, b.y, b.z))
        return 0;
    if (s->occ_count == 0)
        return 1;
    v3 d = v3_sub(b, a);
    v3 inv = v3_make(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
    if (!segment_meets_box(a, d, inv, s->occ_union))
        return 1;
    if (s->occ_count == 1) /* the union is the only box */
        return 0;
    for (uint32_t i = 0; i < s->occ_count; ++i)
        if (segment_meets_box(a, d, inv, s->occ_boxes + 6 * (size_t)i))
            return 0;
    return 1;
}
