/* About N VSGLs per light on a world-space lattice (the "stable" fit).
 *
 * The importance-sampled fits (FIS, k-means) draw their cluster centres
 * from the RSM's power distribution, so a light that moves by a millimetre
 * reshuffles every cluster (flicker), and clusters of random size and
 * shape sum to blotches. Here the clusters are fixed in the world:
 *
 *  - orientation: a VPL of normal n belongs to the signed-axis bin of
 *    each axis a it faces, with weights max(n_a^2 - d^2, 0) over their sum
 *    (they sum to 1, continuous in n), so a cluster never mixes a floor
 *    with a wall: its VPLs face one way, which is what lets the shading
 *    clip its emission to its own hemisphere. The dead zone d
 *    (VSGL__LATTICE_BIN_DEAD) keeps a surface tilted a little off an axis
 *    in that axis's bin alone: with d = 0 a bumpy floor also filled the
 *    four side bins, each with a few % of its light, at the full lattice
 *    density (dense_floor: 1930 clusters for 192 asked);
 *  - position: within bin b (axis a), lattice points h apart in the two
 *    axes across a, with tent (bilinear) weights, which sum to 1 and are
 *    continuous in the VPL's position; along a, slabs h thick (surfaces of
 *    one bin at different heights, a floor and a table top, stay apart;
 *    thinner slabs cut a sphere into more clusters for no gain), centred
 *    on the bounds' faces (bin_texels);
 *  - the lattice is anchored at the scene's bounds, not at the light, and
 *    h follows the light's effective lit area A (the power-weighted
 *    participation area (sum w)^2 / sum(w^2 / a)), h = sqrt(A / N): both
 *    change smoothly as the light moves.
 *
 * So every VSGL's sums are continuous functions of the RSM; a light that
 * moves a little changes them a little. The tents of neighbouring lattice
 * points overlap, so their Gaussians sum to a smooth field. Seen through
 * a sharp glossy lobe, the sum of Gaussians of the tents' own variance
 * (h^2 / 6 per axis) still ripples by ~7 % (stripes in a metal floor's
 * reflection of a lit wall); the planar glossy model widens each by
 * VSGL__LATTICE_OVERLAP h^2 (fit/vsgl_set.h: ripple ~0.6 %). The diffuse
 * light is not widened: wider Gaussians spill light past a junction, where
 * the wall beside the floor cannot see it (-4 % of the diffuse light in a
 * box). */
#include "fit/grid.h"
#include "core/context.h"
#include "scene/scene_internal.h"
#include "shade/kernel.h" /* VSGL__GGX_CORE_K and its kin: the receivers' split, the same for emitters */

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The orientation bins' dead zone: a normal's component along an axis
 * must exceed this (sin 14.5 deg) to put any weight in that axis's bin.
 * Measured (tests/quality/evaluate.py, balanced): dense_floor at 320 x 240
 * 3421 -> 962 VSGLs, its render 2.2 -> 1.0 s at the same error (relMSE
 * 0.0068 -> 0.0067, FLIP 0.1920 -> 0.1920); the sphere room's FLIP 0.1075
 * -> 0.1083 (its side bins' clusters hold more tilted texels) for 5 % fewer
 * VSGLs; rooms of axis-aligned walls unchanged (a weight of 1 stays 1). */
#define VSGL__LATTICE_BIN_DEAD 0.25
/* Slab thickness along a bin's axis, in units of h. */
#define VSGL__LATTICE_SLAB 1.0
/* A planar cluster's specular lobe as GGX's core, tail and far tail (the
 * receivers' core, VSGL__GGX_EMIT_* in shade/kernel.h): one SG of the
 * cluster's sharpness has no tail, so a metal floor's reflection of a lit
 * patch was too bright in the middle and missing around it (round blobs on
 * the wall it lights: the red-wall room's diffuse structured error 0.00289 ->
 * 0.00210, FLIP 0.138 -> 0.126 at 80x60). The split applies to planar
 * clusters only, faded in over coherence 0.990-0.995: a curved surface's
 * cluster's sharpness is mostly the spread of its VPLs' mirror directions,
 * which the split would sharpen (the sphere room's diffuse error 0.00140 ->
 * 0.00164 split everywhere). Not with one-lobe receivers (glossy mode ASG
 * or SG; MRP and hybrid take ASG2's diffuse): the live viewport keeps one
 * VSGL per cluster and its cost (the spot room's Live light edit had 212
 * VSGLs, 317 with the split). */
#define VSGL__LATTICE_SPLIT_LO 0.990f
#define VSGL__LATTICE_SPLIT_HI 0.995f

/* At most this many clusters per requested VSGL: past it the spacing grows
 * (bright and tiny lit spots, e.g. a light a few mm from a wall, made
 * 500 x the request; usual scenes stay at 1.6-6.5 x and never reach it). */
#define VSGL__LATTICE_MAX_PER_VSGL 16.0

/* The least share of a sheared cluster's variance left given the
 * direction (shear_of): the linear model's floor. */
#define VSGL__SHEAR_MIN_VAR 0.05

/* Open-addressing map from a packed lattice key to a cluster's sums. */
typedef struct cell_map {
    uint64_t *keys;      /* 0 = empty (packed keys are never 0) */
    uint32_t *slot;      /* index into sums, in first-touch order */
    size_t cap, count;
    double *sums;        /* count * VSGL__GRID_STRIDE */
    double *ext;         /* count * 4: the VPLs' extent in u and v (lattice units) */
    int32_t *cell;       /* count * 3: bin, i, j */
    uint32_t *part;      /* count: the convex part its shares are of (the smallest seen), VSGL__PART_NONE */
    double *pw;          /* count * 4: that part's weight outside, inside, for the diffuse then specular lobe */
    double *xd;          /* count * 9: the specular lobe's sum of w (x - origin) d^T (shear_of) */
    size_t sums_cap;
} cell_map;

/* Bit 3 of a cell's bin: the fine lattice of a curved part's outside
 * (VSGL__LATTICE_CURVED). */
#define VSGL__BIN_FINE 8u

static uint64_t pack_key(uint32_t bin, int32_t k, int32_t i, int32_t j)
{
    /* bit 63: the fine lattice; 3 bits of bin + 1; three 20-bit biased coordinates */
    const int32_t bias = 1 << 19;
    return ((uint64_t)(bin >> 3) << 63) | ((uint64_t)((bin & 7u) + 1) << 60) | ((uint64_t)(uint32_t)(k + bias) << 40) |
           ((uint64_t)(uint32_t)(i + bias) << 20) | (uint64_t)(uint32_t)(j + bias);
}

static uint64_t hash64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static int map_grow(cell_map *m)
{
    size_t cap = m->cap ? m->cap * 2 : 1024;
    uint64_t *keys = calloc(cap, sizeof *keys);
    uint32_t *slot = malloc(cap * sizeof *slot);
    if (!keys || !slot) {
        free(keys);
        free(slot);
        return 0;
    }
    for (size_t e = 0; e < m->cap; ++e) {
        if (!m->keys[e])
            continue;
        size_t p = hash64(m->keys[e]) & (cap - 1);
        while (keys[p])
            p = (p + 1) & (cap - 1);
        keys[p] = m->keys[e];
        slot[p] = m->slot[e];
    }
    free(m->keys);
    free(m->slot);
    m->keys = keys;
    m->slot = slot;
    m->cap = cap;
    return 1;
}

/* The sums of `key`, created (zeroed) on first use; NULL if out of memory. */
static double *map_get(cell_map *m, uint64_t key)
{
    if ((m->count + 1) * 2 > m->cap && !map_grow(m))
        return NULL;
    size_t p = hash64(key) & (m->cap - 1);
    while (m->keys[p] && m->keys[p] != key)
        p = (p + 1) & (m->cap - 1);
    if (m->keys[p])
        return m->sums + (size_t)m->slot[p] * VSGL__GRID_STRIDE;
    if (m->count == m->sums_cap) {
        size_t cap = m->sums_cap ? m->sums_cap * 2 : 256;
        /* each per-cell array to n entries per cell (NULL if memory is short) */
#define MAP_GROW(arr, n)                                            \
    do {                                                            \
        void *grown_ = realloc((arr), cap * (n) * sizeof *(arr));   \
        if (!grown_)                                                \
            return NULL;                                            \
        (arr) = grown_;                                             \
    } while (0)
        MAP_GROW(m->sums, VSGL__GRID_STRIDE);
        MAP_GROW(m->ext, 4);
        MAP_GROW(m->cell, 3);
        MAP_GROW(m->part, 1);
        MAP_GROW(m->pw, 4);
        MAP_GROW(m->xd, 9);
#undef MAP_GROW
        m->sums_cap = cap;
    }
    m->keys[p] = key;
    m->slot[p] = (uint32_t)m->count;
    double *s = m->sums + m->count * VSGL__GRID_STRIDE;
    memset(s, 0, VSGL__GRID_STRIDE * sizeof *s);
    double *e = m->ext + m->count * 4;
    e[0] = e[2] = INFINITY;
    e[1] = e[3] = -INFINITY;
    m->part[m->count] = VSGL__PART_NONE;
    memset(m->pw + m->count * 4, 0, 4 * sizeof *m->pw);
    memset(m->xd + m->count * 9, 0, 9 * sizeof *m->xd);
    ++m->count;
    return s;
}

static void map_free(cell_map *m)
{
    free(m->keys);
    free(m->slot);
    free(m->sums);
    free(m->ext);
    free(m->cell);
    free(m->part);
    free(m->pw);
    free(m->xd);
    memset(m, 0, sizeof *m);
}

/* Split specular cluster v into GGX's core (v, sharper, less power), tail
 * and far tail (pushed to out, power fractions C/K of theirs:
 * VSGL__GGX_EMIT_*) as far as v is planar: the powers sum to v's and all
 * change continuously with it. */
static vsgl_result split_specular(vsgl_vsgl *v, vsgl_vsgl_set *out)
{
    float f = (v->coherence - VSGL__LATTICE_SPLIT_LO) / (VSGL__LATTICE_SPLIT_HI - VSGL__LATTICE_SPLIT_LO);
    f = f < 0.0f ? 0.0f : f > 1.0f ? 1.0f : f * f * (3.0f - 2.0f * f);
    if (!(f > 0.0f))
        return VSGL_OK;
    static const float sharp[2] = {VSGL__GGX_EMIT_TAIL_K, VSGL__GGX_EMIT_FAR_K};
    static const float share[2] = {VSGL__GGX_EMIT_TAIL_C / VSGL__GGX_EMIT_TAIL_K,
                                   VSGL__GGX_EMIT_FAR_C / VSGL__GGX_EMIT_FAR_K};
    vsgl_vsgl t[2] = {*v, *v};
    for (int k = 0; k < 2; ++k) {
        t[k].sharpness *= sharp[k];
        for (int c = 0; c < 3; ++c)
            t[k].power[c] = v->power[c] * f * share[k];
    }
    v->sharpness *= 1.0f + f * (VSGL__GGX_CORE_K - 1.0f);
    for (int c = 0; c < 3; ++c)
        v->power[c] -= t[0].power[c] + t[1].power[c];
    vsgl_result r = vsgl__vsgl_set_push(out, &t[0]);
    return r == VSGL_OK ? vsgl__vsgl_set_push(out, &t[1]) : r;
}

/* The lattice spacing for about n clusters over the light's lit area. */
/* texel: the typical texel size, for the fine lattice's floor (NULL: not wanted). */
static double lattice_spacing(const vsgl_rsm *rsm, const vsgl_grid *g, double n, double extent, double *texel_out)
{
    double sw = 0.0, sw2a = 0.0, swa = 0.0;
    size_t per_face = (size_t)rsm->res * rsm->res;
    for (size_t t = 0; t < rsm->count; ++t) {
        size_t rem = t % per_face;
        size_t gi = ((t / per_face) * g->res + rem / rsm->res) * g->res + rem % rsm->res;
        const float *m = g->level[0].data + gi * VSGL__GRID_STRIDE;
        double w = (double)m[0] + m[VSGL__GRID_FIELDS];
        double a = rsm->area[t];
        if (!(w > 0.0) || !(a > 0.0) || !(a < INFINITY))
            continue;
        sw += w;
        sw2a += w * w / a;
        swa += w * a;
    }
    if (!(sw > 0.0) || !(sw2a > 0.0))
        return extent > 0.0 ? extent : 1.0;
    double area = sw * sw / sw2a;
    double h = sqrt(area / (n >= 1.0 ? n : 1.0));
    /* a cluster should hold a few texels: h >= 1.5 x the typical texel size */
    double texel = sqrt(swa / sw);
    if (texel_out)
        *texel_out = texel;
    if (h < 1.5 * texel)
        h = 1.5 * texel;

    /* keys hold 20-bit coordinates */
    double hmin = (extent > 0.0 ? extent : 1.0) / 200000.0;
    return h > hmin ? h : hmin;
}

/* A texel on part key `key` (scene_internal.h) with tent weight w and grid
 * sums m into slot's part shares. A cell keeps the smallest part it has
 * seen: a cell holding two parts' VPLs (rare: the bins keep surfaces
 * facing different ways apart, the slabs surfaces at different heights)
 * drops the light of one of them only. */
static void add_part(cell_map *map, size_t slot, uint32_t key, double w, const float *m)
{
    if (key == VSGL__PART_NONE)
        return;
    uint32_t part = key >> 1, inner = key & 1u;
    double *pw = map->pw + slot * 4;
    if (map->part[slot] == VSGL__PART_NONE || part < map->part[slot]) {
        map->part[slot] = part;
        memset(pw, 0, 4 * sizeof *pw);
    } else if (part != map->part[slot]) {
        return;
    }
    pw[inner] += w * m[0];
    pw[2 + inner] += w * m[VSGL__GRID_FIELDS];
}

/* Every lit texel's moments into the tents of its lattice cells, spacing h
 * (h_fine on a curved part's outside, VSGL__LATTICE_CURVED). */
static vsgl_result bin_texels(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm, const vsgl_grid *gp,
                              const double anchor[3], const double far[3], double h, double h_fine, cell_map *out)
{
    const vsgl_grid g = *gp;
    cell_map map;
    memset(&map, 0, sizeof map);
    const double inv_coarse = 1.0 / h, inv_fine = 1.0 / h_fine;
    vsgl_result r = VSGL_OK;
    size_t per_face = (size_t)rsm->res * rsm->res;
    /* Sequential in texel order: the sums and the VSGLs' order are the same
     * for any thread count. */
    for (size_t t = 0; t < rsm->count && r == VSGL_OK; ++t) {
        size_t rem = t % per_face;
        size_t gi = ((t / per_face) * g.res + rem / rsm->res) * g.res + rem % rsm->res;
        const float *m = g.level[0].data + gi * VSGL__GRID_STRIDE;
        if (!(m[0] + m[VSGL__GRID_FIELDS] > 0.0f))
            continue;
        const double p[3] = {rsm->pos[0][t], rsm->pos[1][t], rsm->pos[2][t]};
        const double po[3] = {p[0] - g.origin.x, p[1] - g.origin.y, p[2] - g.origin.z};
        const double nrm[3] = {rsm->nrm[0][t], rsm->nrm[1][t], rsm->nrm[2][t]};
        const uint32_t key = rsm->part ? rsm->part[t] : VSGL__PART_NONE;
        const uint32_t fine = key != VSGL__PART_NONE && !(key & 1u) && vsgl__scene_part_curved(scene, key >> 1)
                                  ? VSGL__BIN_FINE : 0u;
        const double inv_h = fine ? inv_fine : inv_coarse;
        double q[3];
        for (int a = 0; a < 3; ++a)
            q[a] = (p[a] - anchor[a]) * inv_h;
        /* orientation weights max(n_a^2 - d^2, 0) over their sum */
        double ew[3], norm = 0.0;
        for (int a = 0; a < 3; ++a) {
            ew[a] = nrm[a] * nrm[a] - VSGL__LATTICE_BIN_DEAD * VSGL__LATTICE_BIN_DEAD;
            norm += ew[a] > 0.0 ? ew[a] : 0.0;
        }
        for (uint32_t bin = 0; bin < 6 && r == VSGL_OK; ++bin) {
            int a = (int)(bin >> 1);
            double na = (bin & 1) ? -nrm[a] : nrm[a];
            if (!(na > 0.0) || !(ew[a] > 0.0)) /* ew[a] > 0: norm >= ew[a] > 0 */
                continue;
            double wb = ew[a] / norm;
            int u = (a + 1) % 3, v = (a + 2) % 3;
            /* slabs centred on the bounds' faces, counted from the face
             * the bin's surfaces look away from: a room's walls lie on
             * those faces, and a face on a slab boundary split a wall's
             * texels between two clusters of the same cell by the rounding
             * of their positions, differently from frame to frame (the
             * sphere room's preview: the left wall's foot in two clusters
             * whose powers swung 0.043 -> 0.034 -> 0.021 W as the light
             * moved 5 mm, the floor's reflection of it 20 %) */
            double qa = (bin & 1) ? (far[a] - p[a]) * inv_h : q[a];
            int32_t k = (int32_t)floor(qa * (1.0 / VSGL__LATTICE_SLAB) + 0.5);
            double fu = floor(q[u]), fv = floor(q[v]);
            double tu = q[u] - fu, tv = q[v] - fv;
            for (int du = 0; du < 2; ++du)
                for (int dv = 0; dv < 2; ++dv) {
                    double w = wb * (du ? tu : 1.0 - tu) * (dv ? tv : 1.0 - tv);
                    if (!(w > 0.0))
                        continue;
                    double *dst = map_get(&map, pack_key(bin | fine, k, (int32_t)fu + du, (int32_t)fv + dv));
                    if (!dst) {
                        r = vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "fit: out of memory for the lattice clusters");
                        break;
                    }
                    for (int f = 0; f < VSGL__GRID_STRIDE; ++f)
                        dst[f] += w * m[f];
                    size_t slot = (size_t)(dst - map.sums) / VSGL__GRID_STRIDE;
                    int32_t *cc = map.cell + slot * 3;
                    cc[0] = (int32_t)(bin | fine);
                    cc[1] = (int32_t)fu + du;
                    cc[2] = (int32_t)fv + dv;
                    add_part(&map, slot, key, w, m);
                    if (fine) { /* the shear's cross moments (shear_of): curved parts only */
                        const float *sd = m + VSGL__GRID_FIELDS + 4; /* the specular lobe's sum w d (its dir, vsgl__grid_moments) */
                        double *xd = map.xd + slot * 9;
                        for (int ra = 0; ra < 3; ++ra)
                            for (int rc = 0; rc < 3; ++rc)
                                xd[3 * ra + rc] += w * po[ra] * sd[rc];
                    }
                    double *e = map.ext + slot * 4;
                    double half = 0.5 * sqrt(rsm->area[t] > 0.0f ? (double)rsm->area[t] : 0.0) * inv_h;
                    e[0] = fmin(e[0], q[u] - half);
                    e[1] = fmax(e[1], q[u] + half);
                    e[2] = fmin(e[2], q[v] - half);
                    e[3] = fmax(e[3], q[v] + half);
                }
        }
    }
    if (r != VSGL_OK)
        map_free(&map);
    *out = map;
    return r;
}

/* The shear of specular cluster v (vsgl_vsgl.shear) from its moments mo
 * (positions relative to the grid's origin) and cross moments xd = sum w
 * (x - origin) d^T: Cov(x, d) = xd / W - mean d_mean^T, shear = lambda
 * Cov, and the variance left given the direction, variance - lambda |Cov|^2
 * / 2, kept to at least VSGL__SHEAR_MIN_VAR of it. */
static void shear_of(vsgl_vsgl *v, const vsgl_moments *mo, const double *xd)
{
    const double W = mo->weight;
    if (!(W > 0.0) || !(v->variance > 0.0f) || !(v->sharpness > 0.0f))
        return;
    double c[9], c2 = 0.0;
    for (int a = 0; a < 3; ++a)
        for (int d = 0; d < 3; ++d) {
            c[3 * a + d] = xd[3 * a + d] / W - (mo->pos[a] / W) * (mo->dir[d] / W);
            c2 += c[3 * a + d] * c[3 * a + d];
        }
    const double lam = v->sharpness;
    const double left = (double)v->variance - 0.5 * lam * c2;
    const double floor_var = VSGL__SHEAR_MIN_VAR * v->variance;
    for (int e = 0; e < 9; ++e)
        v->shear[e] = (float)(lam * c[e]);
    v->shear_variance = (float)(left > floor_var ? left : floor_var);
    v->sheared = 1;
}

/* How far inside the cut a probe starts and how far above the plane it
 * runs, in spacings: well beyond the cut's half-texel uncertainty. */
#define VSGL__LATTICE_END_INSIDE 0.15
#define VSGL__LATTICE_END_ABOVE 0.02

/* 1 if cell v's surface ends at the cut on side sd of in-plane axis k
 * (vsgl_vsgl.cell_ends): something rises there (a ray along the plane,
 * just above it, from inside the cut outwards, is blocked; the cut then
 * moves to where it hit) or the plane stops (a ray down onto it just
 * beyond the cut misses). A shadow's edge or a spot's rim cuts the VPLs
 * too, but the surface goes on there. */
static int surface_ends(const vsgl_scene *scene, vsgl_vsgl *v, int k, int sd)
{
    const int a = (int)v->cell_axis, ax = (a + 1 + k) % 3, other = (a + 2 - k) % 3;
    const float h = v->cell_h, up = v->cell_side ? -1.0f : 1.0f, out = sd ? 1.0f : -1.0f;
    const float b = sd ? v->cell_hi[k] : v->cell_lo[k];
    const float above = (float)VSGL__LATTICE_END_ABOVE * h, inside = (float)VSGL__LATTICE_END_INSIDE * h;
    const float m[3] = {v->mean.x, v->mean.y, v->mean.z};
    float p[3];
    p[a] = m[a] + up * above;
    p[other] = m[other];
    p[ax] = b - out * inside;
    float d[3] = {0.0f, 0.0f, 0.0f};
    d[ax] = out;
    vsgl_hit hit;
    if (vsgl__scene_intersect(scene, v3_make(p[0], p[1], p[2]), v3_make(d[0], d[1], d[2]), 0.0f, 2.0f * inside,
                              &hit)) {
        /* the wall's face: where the cut is, exactly (the VPLs' extent
         * wanders by half a texel as the light moves, and the fold and the
         * near field's steps with it) */
        float at = p[ax] + out * hit.t;
        if (sd)
            v->cell_hi[k] = at;
        else
            v->cell_lo[k] = at;
        return 1;
    }
    p[ax] = b + out * inside;
    d[ax] = 0.0f;
    d[a] = -up;
    return !vsgl__scene_occluded(scene, v3_make(p[0], p[1], p[2]), v3_make(d[0], d[1], d[2]), 0.0f, 2.0f * above);
}

vsgl_result vsgl__fit_lattice(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm,
                              const vsgl_render_settings *s, vsgl_vsgl_set *out)
{
    return vsgl__fit_lattice_n(ctx, scene, rsm, s, s->vsgl_count ? (double)s->vsgl_count : 64.0, out);
}

vsgl_result vsgl__fit_lattice_n(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm,
                                const vsgl_render_settings *s, double n_clusters, vsgl_vsgl_set *out)
{
    if (!(n_clusters >= 1.0))
        n_clusters = 1.0;
    vsgl_grid g;
    vsgl_result r = vsgl__grid_build(ctx, scene, rsm, s->sharpness_estimator, 0, &g);
    if (r != VSGL_OK)
        return r;
    v3 lo, hi;
    vsgl__scene_bounds(scene, &lo, &hi);
    double extent = v3_length(v3_sub(hi, lo));
    double texel = 0.0;
    double h = lattice_spacing(rsm, &g, n_clusters, extent, &texel), h_fine = h;
    const double anchor[3] = {lo.x, lo.y, lo.z}, far[3] = {hi.x, hi.y, hi.z};
    cell_map map;
    memset(&map, 0, sizeof map);
    for (int attempt = 0;; ++attempt) {
        /* a curved part's spacing: finer, but not below the texels' floor (lattice_spacing) */
        h_fine = fmax(h * VSGL__LATTICE_CURVED, fmin(h, 1.5 * texel));
        r = bin_texels(ctx, scene, rsm, &g, anchor, far, h, h_fine, &map);
        double cap = VSGL__LATTICE_MAX_PER_VSGL * n_clusters;
        if (r != VSGL_OK || (double)map.count <= cap || attempt == 3)
            break;
        h *= 1.05 * sqrt((double)map.count / cap);
        map_free(&map);
    }
    double total = g.total[0] + g.total[VSGL__GRID_FIELDS];
    /* The fold at a cut that moves with the light (a shadow's edge, a
     * spot's rim) only with two-lobe receivers, as the specular split: it
     * moves in texel steps, which a one-lobe preview's sharp core showed as
     * flicker (the sphere room's glossy light flicker 0.015, 0.009 without
     * it); balanced's two lobes stay below 0.009 and gain most from it (the
     * sun rooms' glossy structured error 0.00106 -> 0.00016). */
    const int fold_moving = s->glossy_mode != VSGL_GLOSSY_ASG && s->glossy_mode != VSGL_GLOSSY_SG;
    for (size_t c = 0; c < map.count && r == VSGL_OK; ++c)
        for (uint32_t lobe = 0; lobe < 2 && r == VSGL_OK; ++lobe) {
            const double *f = map.sums + c * VSGL__GRID_STRIDE + lobe * VSGL__GRID_FIELDS;
            if (!(f[0] > 1e-9 * total)) /* a sliver of a tent: nothing a pixel could show */
                continue;
            vsgl_moments mo;
            vsgl_vsgl v;
            vsgl__grid_moments(f, &mo);
            const int32_t *cc = map.cell + c * 3;
            const double hc = (cc[0] & (int32_t)VSGL__BIN_FINE) ? h_fine : h; /* the cell's spacing */
            if (vsgl__moments_to_vsgl(&mo, g.origin, s->sharpness_estimator, rsm->light, lobe, &v)) {
                v.widen = (float)(VSGL__LATTICE_OVERLAP * hc * hc);
                if (lobe == VSGL__LOBE_SPECULAR && (cc[0] & (int32_t)VSGL__BIN_FINE))
                    shear_of(&v, &mo, map.xd + c * 9);
                if (map.part[c] != VSGL__PART_NONE) {
                    const double *pw = map.pw + c * 4 + lobe * 2;
                    v.part = map.part[c];
                    v.part_out = (float)fmin(fmax(pw[0] / f[0], 0.0), 1.0);
                    v.part_in = (float)fmin(fmax(pw[1] / f[0], 0.0), 1.0 - v.part_out);
                }
                int ax = (cc[0] & 7) >> 1, au = (ax + 1) % 3, av = (ax + 2) % 3;
                /* The VPLs' extent, within the scene's bounds (0 at the
                 * anchor, the bounds' low corner). The texels' footprints
                 * reach past a wall by up to half a texel, by an amount that
                 * changes as the light moves: the sphere room's back-wall
                 * corner cell was cut at x = -2.504, -2.499, -2.519 around
                 * the wall at -2.5 in three frames, and its reflection in the
                 * floor lost 27 % in one of them (the preview's glossy light
                 * flicker 0.0101 -> 0.0089). No surface lies there; the near
                 * field's cells, which ended past the walls too, now give the
                 * junctions the light of the brute force on a converged RSM
                 * (test_near_field.c). */
                const double *ex = map.ext + c * 4;
                const double e[4] = {fmax(ex[0], 0.0), fmin(ex[1], (far[au] - anchor[au]) / hc), fmax(ex[2], 0.0),
                                     fmin(ex[3], (far[av] - anchor[av]) / hc)};
                v.cell_h = (float)hc;
                v.cell_axis = (uint32_t)ax;
                v.cell_side = (uint32_t)(cc[0] & 1);
                v.cell_centre[0] = (float)(anchor[au] + cc[1] * hc);
                v.cell_centre[1] = (float)(anchor[av] + cc[2] * hc);
                v.cell_lo[0] = (float)(anchor[au] + fmax(e[0], cc[1] - 1.0) * hc);
                v.cell_hi[0] = (float)(anchor[au] + fmin(e[1], cc[1] + 1.0) * hc);
                v.cell_lo[1] = (float)(anchor[av] + fmax(e[2], cc[2] - 1.0) * hc);
                v.cell_hi[1] = (float)(anchor[av] + fmin(e[3], cc[2] + 1.0) * hc);
                v.cell_ends = 0;
                for (int k = 0; k < 2; ++k) {
                    const double short_by[2] = {fmax(e[2 * k], cc[1 + k] - 1.0) - (cc[1 + k] - 1.0),
                                                (cc[1 + k] + 1.0) - fmin(e[2 * k + 1], cc[1 + k] + 1.0)};
                    /* The probe also moves a cut to the wall's face where a
                     * wall rises. A specular cell's cut is always probed:
                     * its near field then reaches the junction (the VPLs'
                     * extent stopped up to half a texel short, and a wall's
                     * foot beside a metal floor lost the floor's reflection
                     * there: the red wall room's diffuse structured error
                     * 0.00035 -> 0.00030 in balanced, docs/pipeline.md). A
                     * diffuse cell's only where the fold needs the verdict
                     * (one-lobe receivers): with two lobes, a cut that moves
                     * (the sun's patch by the cabinet) snapped to the
                     * cabinet and the sun rooms' glossy light flickered
                     * 0.009 -> 0.013 a frame. */
                    const int probe = lobe == VSGL__LOBE_SPECULAR || !fold_moving;
                    for (int sd = 0; sd < 2; ++sd) {
                        if (!(short_by[sd] > 0.02))
                            continue;
                        const int ends = probe && surface_ends(scene, &v, k, sd);
                        if (lobe == VSGL__LOBE_DIFFUSE && (fold_moving || ends))
                            v.cell_ends |= 1u << (2 * k + sd);
                    }
                }
                /* not with one-lobe receivers (ASG, SG: the live viewport); the
                 * tail keeps the cell (the near field of specular emitters) */
                if (lobe == VSGL__LOBE_SPECULAR && s->glossy_mode != VSGL_GLOSSY_ASG &&
                    s->glossy_mode != VSGL_GLOSSY_SG) {
                    r = split_specular(&v, out);
                    if (r != VSGL_OK) {
                        r = vsgl__fail(ctx, r, "fit: out of memory");
                        break;
                    }
                }
                r = vsgl__vsgl_set_push(out, &v);
                if (r != VSGL_OK)
                    r = vsgl__fail(ctx, r, "fit: out of memory");
            }
        }
    vsgl__log(ctx, VSGL_LOG_DEBUG, "fit: light %u: lattice spacing %.4g m, %zu clusters", rsm->light, h, map.count);
    map_free(&map);
    vsgl__grid_free(&g);
    return r;
}
