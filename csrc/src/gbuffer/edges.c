/* Edge refinement of the camera G-buffer (vsgl_render_settings.edge_samples).
 *
 * With aa x aa samples on a fixed pattern, a geometric edge that crosses a
 * pixel covers 0, 1/spp, 2/spp ... of it: as the camera moves, the edge
 * pixel jumps in steps of 1/spp, which an animation shows as crawling
 * silhouettes (docs/quality.md, "camera flicker"). Shading more samples
 * would cost spp-fold in the shade stage. Instead, as MSAA separates
 * coverage from shading:
 *  1. mark: a pixel is an edge when two of its samples, or one of its
 *     samples and the nearest sample of a 4-neighbour, lie on different
 *     surfaces (hit vs miss, another material, normals more than ~25
 *     degrees apart, or off each other's tangent plane);
 *  2. refine: an edge pixel is traced again with edge_aa x edge_aa rays
 *     (the sheared pattern of gbuffer.h: edge_aa^2 coverage steps for a
 *     horizontal or vertical edge, not edge_aa),
 *     the rays are grouped by surface (neighbouring rays on one surface
 *     chain into one piece, so a curved rim is one group; at most spp
 *     groups, a further surface joins its most similar group; group_rays),
 *     and slot q of the pixel holds the ray nearest the centre of group q,
 *     weighted by the group's share of the rays. Unused slots are misses
 *     of weight 0.
 * The shade stage still shades at most spp samples per pixel; only the
 * coverage is resolved finer. Every pixel is decided from its own and its
 * neighbours' first-pass samples, and refined in place: the result does
 * not depend on the thread count. */
#include "gbuffer/trace.h"
#include "scene/camera.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Normals further apart than this (cosine) are different surfaces. */
#define EDGE_NORMAL_COS 0.9f
/* Off the tangent plane by more than this fraction of the distance (plus the job's plane_tol). */
#define EDGE_PLANE_REL 0.05f

static v3 at3(float *const a[3], size_t i)
{
    return v3_make(a[0][i], a[1][i], a[2][i]);
}

/* Do samples a and b lie on one surface? Two misses do. */
static int same_surface(const vsgl_gbuffer *g, size_t a, size_t b, float plane_tol)
{
    if (g->material[a] != g->material[b])
        return 0;
    if (g->material[a] == VSGL__GBUFFER_MISS)
        return 1;
    v3 na = at3(g->nrm, a), nb = at3(g->nrm, b);
    if (!(v3_dot(na, nb) > EDGE_NORMAL_COS))
        return 0;
    v3 d = v3_sub(at3(g->pos, b), at3(g->pos, a));
    float tol = EDGE_PLANE_REL * v3_length(d) + plane_tol;
    return fabsf(v3_dot(d, na)) <= tol && fabsf(v3_dot(d, nb)) <= tol;
}

/* Sample (i, j) of pixel (x, y) on the aa x aa grid. */
static size_t sample_at(const vsgl_gbuffer *g, uint32_t aa, uint32_t x, uint32_t y, uint32_t i, uint32_t j)
{
    return ((size_t)y * g->width + x) * g->spp + (size_t)j * aa + i;
}

/* Do two samples of pixel (x, y) lie on different surfaces? */
static int inside_differs(const gb_job *job, uint32_t x, uint32_t y)
{
    const vsgl_gbuffer *g = job->g;
    const uint32_t aa = job->aa;
    size_t p0 = ((size_t)y * g->width + x) * g->spp;
    for (size_t k = 1; k < (size_t)aa * aa; ++k)
        if (!same_surface(g, p0, p0 + k, job->plane_tol))
            return 1;
    return 0;
}

/* Do pixel (x, y)'s samples next to its right (or lower) border and the
 * neighbour's across it lie on different surfaces? (same_surface is
 * symmetric to the bit, so each border is tested once for both pixels;
 * the upper border of a range's first row once more, by that range.) */
static int border_differs(const gb_job *job, uint32_t x, uint32_t y, int lower)
{
    const vsgl_gbuffer *g = job->g;
    const uint32_t aa = job->aa;
    for (uint32_t t = 0; t < aa; ++t) {
        size_t a = lower ? sample_at(g, aa, x, y, t, aa - 1) : sample_at(g, aa, x, y, aa - 1, t);
        size_t b = lower ? sample_at(g, aa, x, y + 1, t, 0) : sample_at(g, aa, x + 1, y, 0, t);
        if (!same_surface(g, a, b, job->plane_tol))
            return 1;
    }
    return 0;
}

int32_t vsgl__gbuffer_mark_edges(void *user, size_t chunk, size_t begin, size_t end)
{
    (void)chunk;
    gb_job *job = user;
    const uint32_t W = job->g->width, H = job->g->height;
    /* the borders above and below the current row, per column */
    unsigned char *above = malloc(2 * (size_t)W + 1);
    if (!above)
        return VSGL_ERROR_OUT_OF_MEMORY;
    unsigned char *below = above + W;
    uint32_t y0 = job->row0 + (uint32_t)begin;
    for (uint32_t x = 0; x < W; ++x)
        above[x] = (unsigned char)(y0 > 0 && border_differs(job, x, y0 - 1, 1));
    for (size_t r = begin; r < end; ++r) {
        uint32_t y = job->row0 + (uint32_t)r;
        for (uint32_t x = 0; x < W; ++x)
            below[x] = (unsigned char)(y + 1 < H && border_differs(job, x, y, 1));
        int left = 0;
        for (uint32_t x = 0; x < W; ++x) {
            int right = x + 1 < W && border_differs(job, x, y, 0);
            int e = left || right || above[x] || below[x] || inside_differs(job, x, y);
            job->edge[(size_t)y * W + x] = (unsigned char)e;
            left = right;
        }
        memcpy(above, below, W);
    }
    free(above);
    return 0;
}

/* Copy sample `from` of `src` into slot `to` of `dst`. */
static void copy_sample(vsgl_gbuffer *dst, size_t to, const vsgl_gbuffer *src, size_t from)
{
    for (int k = 0; k < 3; ++k) {
        dst->pos[k][to] = src->pos[k][from];
        dst->nrm[k][to] = src->nrm[k][from];
        dst->view[k][to] = src->view[k][from];
        dst->tan[k][to] = src->tan[k][from];
    }
    dst->material[to] = src->material[from];
    if (dst->part)
        dst->part[to] = src->part ? src->part[from] : VSGL__PART_NONE;
    /* (the edge rays' buffer has no lift or textured inputs: refine_pixel
     * computes them for the rays it keeps) */
    if (dst->lift[0] && src->lift[0])
        for (int k = 0; k < 3; ++k)
            dst->lift[k][to] = src->lift[k][from];
    if (dst->surf[0] && src->surf[0])
        for (int q = 0; q < VSGL__SURF_N; ++q)
            dst->surf[q][to] = src->surf[q][from];
}

/* The group a further surface joins when every slot is taken: the one
 * with the same material (hit or miss) and the closest normal. */
static uint32_t nearest_group(const vsgl_gbuffer *sub, const size_t *founder, uint32_t groups, size_t s)
{
    uint32_t best = 0;
    float best_score = -1e30f;
    for (uint32_t q = 0; q < groups; ++q) {
        size_t f = founder[q];
        float score = sub->material[f] == sub->material[s] ? 2.0f : 0.0f;
        if (sub->material[f] != VSGL__GBUFFER_MISS && sub->material[s] != VSGL__GBUFFER_MISS)
            score += v3_dot(at3(sub->nrm, f), at3(sub->nrm, s));
        if (score > best_score) {
            best_score = score;
            best = q;
        }
    }
    return best;
}

/* Slot `to` (a copy of one of group q's rays) takes the mean of the group's
 * rays on its material: the representative ray jumps from one ray to the
 * next as an edge moves across the pixel, the mean moves by one ray's
 * share. Where the light turns across the pixel, that is what makes the
 * slot's shading follow the edge smoothly:
 *  - the shading normal, on a curved surface's rim (the tangent is made
 *    orthogonal to it);
 *  - on a flat surface, the position and the view direction, where the
 *    light changes fast across it: a floor at a cabinet's foot, whose
 *    glossy light from the cabinet's face doubles within a pixel, jumped by
 *    ~60 % in one frame of a camera animation as its representative moved
 *    by an eighth of a pixel (the sun room's glossy jitter as the camera
 *    moves 0.0109 -> 0.0089 at 80 x 60). On a curved surface the mean point
 *    lies off the surface, where a pixel at a sphere's rim spans much of
 *    it: the sphere room's camera flicker rose 0.023 -> 0.037 (Diff) with
 *    it, so a curved group takes the point (and view) of its ray whose
 *    normal is nearest the mean: a point of the surface where it has about
 *    that normal. (The ray nearest the group's centre did, while a rim
 *    was two groups; as one, that point's own normal is far from the
 *    mean's, and visibility rays leaving along the mean normal grazed the
 *    sphere there.) */
#define MEAN_FLAT 1e-3f
/* Returns the ray whose lift the slot takes (n: its representative's, or
 * none on a plane, where the lift was set to 0). */
static uint32_t mean_surface(vsgl_gbuffer *g, size_t to, const vsgl_gbuffer *sub, const uint8_t *group, uint32_t q,
                             uint32_t n)
{
    v3 sum = v3_make(0.0f, 0.0f, 0.0f), psum = sum, vsum = sum;
    uint32_t count = 0;
    for (uint32_t s = 0; s < n; ++s)
        if (group[s] == q && sub->material[s] == g->material[to]) {
            sum = v3_add(sum, at3(sub->nrm, s));
            psum = v3_add(psum, at3(sub->pos, s));
            vsum = v3_add(vsum, at3(sub->view, s));
            ++count;
        }
    float len = v3_length(sum), vlen = v3_length(vsum);
    if (!(len > 0.0f) || !(vlen > 0.0f) || count < 2)
        return n;
    v3 m = v3_scale(sum, 1.0f / len), t = at3(g->tan, to);
    g->spread[to] = len / (float)count < 1.0f ? len / (float)count : 1.0f;
    t = v3_sub(t, v3_scale(m, v3_dot(m, t)));
    float tl = v3_length(t);
    if (!(tl > 1e-6f))
        return n;
    t = v3_scale(t, 1.0f / tl);
    v3 p = v3_scale(psum, 1.0f / (float)count), v = v3_scale(vsum, 1.0f / vlen);
    /* the mean point where the rays' hits lie on one plane (within MEAN_FLAT
     * of their spread), else the representative's */
    float hmax = 0.0f, r2max = 0.0f, best = -2.0f;
    uint32_t along = n;
    for (uint32_t s = 0; s < n; ++s)
        if (group[s] == q && sub->material[s] == g->material[to]) {
            v3 d = v3_sub(at3(sub->pos, s), p);
            float h = fabsf(v3_dot(d, m)), r2 = v3_dot(d, d), c = v3_dot(at3(sub->nrm, s), m);
            hmax = h > hmax ? h : hmax;
            r2max = r2 > r2max ? r2 : r2max;
            if (c > best) {
                best = c;
                along = s;
            }
        }
    uint32_t lift_from = n;
    if (!(hmax <= MEAN_FLAT * sqrtf(r2max)) && along < n) {
        p = at3(sub->pos, along);
        v = at3(sub->view, along);
        lift_from = along;
    } else if (g->lift[0]) {
        for (int k = 0; k < 3; ++k)
            g->lift[k][to] = 0.0f; /* on one plane */
    }
    const float mv[3] = {m.x, m.y, m.z}, tv[3] = {t.x, t.y, t.z}, pv[3] = {p.x, p.y, p.z}, vv[3] = {v.x, v.y, v.z};
    for (int k = 0; k < 3; ++k) {
        g->nrm[k][to] = mv[k];
        g->tan[k][to] = tv[k];
        g->pos[k][to] = pv[k];
        g->view[k][to] = vv[k];
    }
    return lift_from;
}

static uint32_t find_root(uint16_t *parent, uint32_t s)
{
    while (parent[s] != s) {
        parent[s] = parent[parent[s]];
        s = parent[s];
    }
    return s;
}

/* Group the E x E rays of an edge pixel (in `sub`) by surface, at most spp
 * groups; returns their number, group[s] for each ray and each group's
 * founder (its first ray). Rays joined by a chain of neighbours on one
 * surface are one piece first: a glossy sphere's rim, whose normal turns
 * by more than EDGE_NORMAL_COS across a pixel but little from a ray to the
 * next, stays one piece. Compared ray by ray with each group's first ray
 * (as before), the rim split where the first ray happened to fall, and
 * the split moved from frame to frame as the camera moved. Then each
 * piece, in the order of its first ray, joins the first group whose
 * founder lies on its first ray's surface (two parts of a floor on either
 * side of a pole), else founds a group, else (all slots taken) joins the
 * most similar group. */
static uint32_t group_rays(const gb_job *job, const vsgl_gbuffer *sub, size_t *founder, uint8_t *group)
{
    const uint32_t E = job->edge_aa, n = E * E, spp = job->g->spp;
    uint16_t parent[VSGL__GBUFFER_MAX_SPP];
    int16_t piece_group[VSGL__GBUFFER_MAX_SPP];
    for (uint32_t s = 0; s < n; ++s) {
        parent[s] = (uint16_t)s;
        piece_group[s] = -1;
    }
    for (uint32_t s = 0; s < n; ++s) {
        uint32_t nb[2] = {s % E + 1 < E ? s + 1 : s, s + E < n ? s + E : s};
        for (int k = 0; k < 2; ++k) {
            if (nb[k] == s || !same_surface(sub, s, nb[k], job->plane_tol))
                continue;
            uint32_t a = find_root(parent, s), b = find_root(parent, nb[k]);
            if (a != b)
                parent[a > b ? a : b] = (uint16_t)(a < b ? a : b); /* the smaller index is the root */
        }
    }
    uint32_t groups = 0;
    for (uint32_t s = 0; s < n; ++s) {
        uint32_t r = find_root(parent, s);
        if (piece_group[r] < 0) {
            uint32_t q = groups;
            for (uint32_t t = 0; t < groups && q == groups; ++t)
                if (same_surface(sub, founder[t], s, job->plane_tol))
                    q = t;
            if (q == groups) {
                if (groups < spp)
                    founder[groups++] = s;
                else
                    q = nearest_group(sub, founder, groups, s);
            }
            piece_group[r] = (int16_t)q;
        }
        group[s] = (uint8_t)piece_group[r];
    }
    return groups;
}

/* A group of rays on a curved surface (its normals' mean resultant length
 * below 1 - SPLIT_SPREAD) takes the slots its pixel has to spare, cut into
 * runs (split_curved): the shade stage shades one point per slot, and
 * across a glossy sphere's rim one point with the group's mean normal (its
 * lobe widened by the spread, shade.c) is not the mean of the light over
 * the rim. Against 16 x 16 samples shaded one by one, a glossy cylinder's
 * rim pixels were off by 13.8 % of their glossy light, cut 5.9 %
 * (tests/c/test_render.c); the sphere room's glossy change as the camera
 * moves, above Cycles' own, 0.0145 -> 0.0099 at 80 x 60 (docs/accuracy.md,
 * "A curved rim shaded at several points"). Flat groups are not cut
 * (their slot already takes their rays' mean point): splitting them too
 * lowered the camera animations' excess in the flat rooms a little more,
 * but at 960 x 540 balanced, where one pixel in 5 x 5 is shaded and every
 * edge pixel is, the extra slots cost the sun room 17-35 % of its render. */
#define SPLIT_SPREAD 1e-3f

/* 1 - the mean resultant length of group q's normals, or -1 if it holds a
 * miss; *count its rays. */
static float group_spread(const vsgl_gbuffer *sub, const uint8_t *group, uint32_t q, uint32_t n, uint32_t *count)
{
    v3 sum = v3_make(0.0f, 0.0f, 0.0f);
    uint32_t c = 0;
    int hit = 1;
    for (uint32_t s = 0; s < n; ++s)
        if (group[s] == q) {
            hit &= sub->material[s] != VSGL__GBUFFER_MISS;
            sum = v3_add(sum, at3(sub->nrm, s));
            ++c;
        }
    *count = c;
    return hit && c > 0 ? 1.0f - v3_length(sum) / (float)c : -1.0f;
}

/* Cut curved group q (m rays, listed in member) into `parts` runs of
 * equal count along the grid direction in which its normal turns fastest
 * (the principal axis of sum_s (r_s - r_mean) (x) n_s): the first run
 * keeps label q, the others take first, first + 1, ... As the edge moves by
 * one ray the cuts move by a fraction of one. */
static void cut_group(const gb_job *job, const vsgl_gbuffer *sub, uint8_t *group, uint16_t *member, uint32_t m,
                      uint32_t parts, uint32_t first)
{
    const uint32_t E = job->edge_aa;
    float key[VSGL__GBUFFER_MAX_SPP];
    float xm = 0.0f, ym = 0.0f;
    for (uint32_t k = 0; k < m; ++k) {
        xm += (float)(member[k] % E);
        ym += (float)(member[k] / E);
    }
    xm /= (float)m;
    ym /= (float)m;
    v3 cx = v3_make(0.0f, 0.0f, 0.0f), cy = cx;
    for (uint32_t k = 0; k < m; ++k) {
        const uint32_t s = member[k];
        const v3 ns = at3(sub->nrm, s);
        cx = v3_add(cx, v3_scale(ns, (float)(s % E) - xm));
        cy = v3_add(cy, v3_scale(ns, (float)(s / E) - ym));
    }
    const float a = v3_dot(cx, cx), b = v3_dot(cx, cy), c = v3_dot(cy, cy);
    const float th = 0.5f * atan2f(2.0f * b, a - c), dx = cosf(th), dy = sinf(th);
    /* the members by their position along it (insertion sort, stable: ties keep the ray order) */
    for (uint32_t k = 0; k < m; ++k) {
        const uint32_t s = member[k];
        const float t = ((float)(s % E) - xm) * dx + ((float)(s / E) - ym) * dy;
        uint32_t j = k;
        while (j > 0 && key[j - 1] > t) {
            key[j] = key[j - 1];
            member[j] = member[j - 1];
            --j;
        }
        key[j] = t;
        member[j] = (uint16_t)s;
    }
    for (uint32_t k = 0; k < m; ++k) {
        const uint32_t run = k * parts / m;
        if (run > 0)
            group[member[k]] = (uint8_t)(first + run - 1);
    }
}

/* Give an edge pixel's free slots to its curved groups, one at a time to
 * the group whose runs would hold the most rays each (ties: the first),
 * and cut each into that many runs (cut_group). One rim in a pixel takes
 * every free slot, so its runs do not change as its ray count does (halving
 * the larger half again, the third slot went to one half or the other as
 * the count's parity changed, and the rim's normals jumped by a fifth of
 * their turn in a 1/16-pixel step). Returns the new number of groups. */
static uint32_t split_curved(const gb_job *job, const vsgl_gbuffer *sub, uint8_t *group, uint32_t groups)
{
    const uint32_t n = job->edge_aa * job->edge_aa, spp = job->g->spp;
    uint32_t count[VSGL__GBUFFER_MAX_SPP], parts[VSGL__GBUFFER_MAX_SPP];
    int curved[VSGL__GBUFFER_MAX_SPP];
    for (uint32_t q = 0; q < groups; ++q) {
        curved[q] = group_spread(sub, group, q, n, &count[q]) > SPLIT_SPREAD;
        parts[q] = 1;
    }
    for (uint32_t free_slots = spp - groups; free_slots > 0; --free_slots) {
        uint32_t best = groups;
        for (uint32_t q = 0; q < groups; ++q)
            if (curved[q] && count[q] > parts[q] &&
                (best == groups || (uint64_t)count[q] * parts[best] > (uint64_t)count[best] * parts[q]))
                best = q;
        if (best == groups)
            break;
        ++parts[best];
    }
    uint16_t member[VSGL__GBUFFER_MAX_SPP];
    const uint32_t before = groups;
    for (uint32_t q = 0; q < before; ++q) {
        if (parts[q] < 2)
            continue;
        uint32_t m = 0;
        for (uint32_t s = 0; s < n; ++s)
            if (group[s] == q)
                member[m++] = (uint16_t)s;
        cut_group(job, sub, group, member, m, parts[q], groups);
        groups += parts[q] - 1;
    }
    return groups;
}

/* Raster position of edge ray s of pixel (x, y) on its E x E pattern (inv
 * = 1 / E; gbuffer.h vsgl__gbuffer_pattern): the trace and the deferred
 * inputs of the rays kept must take the same, to the bit. */
static inline void edge_ray_at(uint32_t x, uint32_t y, uint32_t s, uint32_t E, float inv, float *rx, float *ry)
{
    float ox, oy;
    vsgl__gbuffer_pattern(s, E, inv, &ox, &oy);
    *rx = (float)x + ox;
    *ry = (float)y + oy;
}

/* Refine pixel (x, y): trace E x E rays into `sub` and rewrite its slots. */
static void refine_pixel(const gb_job *job, vsgl_gbuffer *sub, vsgl_hit *hits, uint32_t x, uint32_t y)
{
    vsgl_gbuffer *g = job->g;
    const uint32_t E = job->edge_aa, n = E * E, spp = g->spp;
    const float inv = 1.0f / (float)E;
    /* the texture footprint of a first-pass sample (gbuffer/trace.h) */
    const float foot = vsgl__texture_footprint(1.0f / (float)job->aa);
    float rx[VSGL__GBUFFER_BATCH], ry[VSGL__GBUFFER_BATCH];
    size_t dst[VSGL__GBUFFER_BATCH];
    for (uint32_t b = 0; b < n; b += VSGL__GBUFFER_BATCH) {
        uint32_t m = n - b < VSGL__GBUFFER_BATCH ? n - b : VSGL__GBUFFER_BATCH;
        for (uint32_t k = 0; k < m; ++k) {
            uint32_t s = b + k;
            edge_ray_at(x, y, s, E, inv, &rx[k], &ry[k]);
            dst[k] = s;
        }
        vsgl__gbuffer_trace(job, sub, m, rx, ry, dst, foot, hits);
    }
    size_t founder[VSGL__GBUFFER_MAX_SPP];
    uint32_t count[VSGL__GBUFFER_MAX_SPP];
    float cx[VSGL__GBUFFER_MAX_SPP], cy[VSGL__GBUFFER_MAX_SPP];
    uint8_t group[VSGL__GBUFFER_MAX_SPP];
    const uint32_t pieces = group_rays(job, sub, founder, group);
    const uint32_t groups = split_curved(job, sub, group, pieces);
    for (uint32_t q = 0; q < groups; ++q) {
        count[q] = 0;
        cx[q] = cy[q] = 0.0f;
    }
    for (uint32_t s = 0; s < n; ++s) {
        uint32_t q = group[s];
        count[q] += 1;
        cx[q] += (float)(s % E);
        cy[q] += (float)(s / E);
    }
    size_t base = ((size_t)y * g->width + x) * spp;
    for (uint32_t q = 0; q < groups; ++q) {
        /* the member nearest the group's centre (ties: the first) */
        float mx = cx[q] / (float)count[q], my = cy[q] / (float)count[q], best = 1e30f;
        uint32_t rep = 0; /* (every group has a member: split_curved makes no more runs than rays) */
        for (uint32_t s = 0; s < n; ++s) {
            if (group[s] != q)
                continue;
            float dx = (float)(s % E) - mx, dy = (float)(s / E) - my, d2 = dx * dx + dy * dy;
            if (d2 < best) {
                best = d2;
                rep = s;
            }
        }
        copy_sample(g, base + q, sub, rep);
        g->weight[base + q] = (float)count[q] / (float)n;
        g->spread[base + q] = 1.0f;
        float px, py;
        edge_ray_at(x, y, rep, E, inv, &px, &py);
        vsgl__gbuffer_store_deferred(job, g, base + q, &hits[rep], px, py, foot, 1);
        if (sub->material[rep] != VSGL__GBUFFER_MISS && count[q] > 1) {
            uint32_t a = mean_surface(g, base + q, sub, group, q, n);
            if (a < n && g->lift[0]) {
                edge_ray_at(x, y, a, E, inv, &px, &py);
                vsgl__gbuffer_store_deferred(job, g, base + q, &hits[a], px, py, foot, 0);
            }
        }
    }
    for (uint32_t q = groups; q < spp; ++q)
        vsgl__gbuffer_clear_slot(g, base + q, base);
    /* unsplit slots with the grid's weights (one surface over the whole
     * pixel at aa 1): not refined for the shade stage (gbuffer.h refined) */
    int grid = groups == pieces;
    for (uint32_t q = 0; q < spp && grid; ++q)
        grid = g->weight[base + q] == vsgl__gbuffer_grid_weight(job->aa, q);
    if (grid)
        job->edge[(size_t)y * g->width + x] = VSGL__GBUFFER_TRACED;
}

int32_t vsgl__gbuffer_refine_edges(void *user, size_t chunk, size_t begin, size_t end)
{
    (void)chunk;
    gb_job *job = user;
    const uint32_t W = job->g->width;
    vsgl_gbuffer sub;
    memset(&sub, 0, sizeof sub);
    /* the edge rays' geometry and hits; the lift and textured inputs only
     * of the rays a slot keeps (vsgl__gbuffer_store_deferred) */
    const size_t n = (size_t)job->edge_aa * job->edge_aa;
    vsgl_hit *hits = malloc(n * sizeof *hits);
    if (!hits || !vsgl__gbuffer_alloc(&sub, n, 0, 0, 0)) {
        free(hits);
        return VSGL_ERROR_OUT_OF_MEMORY;
    }
    for (size_t r = begin; r < end; ++r) {
        uint32_t y = job->row0 + (uint32_t)r;
        for (uint32_t x = 0; x < W; ++x)
            if (job->edge[(size_t)y * W + x])
                refine_pixel(job, &sub, hits, x, y);
    }
    vsgl__gbuffer_free(&sub);
    free(hits);
    return 0;
}
