/* Rectangle proxies from a scene's planar faces and their radiance from
 * the RSMs of this frame (proxies.h, docs/mrp.md §4). */
#include "mrp/proxies.h"
#include "mrp/geom.h"
#include "math/constants.h"
#include "scene/material.h"
#include "scene/triangles.h"
#include "core/context.h"

#include <stdlib.h>
#include <string.h>

#define MAX_PROXIES 256
#define MIN_COVERAGE 0.7

typedef struct tri_key {
    int64_t k[4]; /* quantised normal (3) and plane offset */
    uint32_t tri;
} tri_key;

static int key_cmp(const void *a, const void *b)
{
    const tri_key *x = a, *y = b;
    for (int i = 0; i < 4; ++i)
        if (x->k[i] != y->k[i])
            return x->k[i] < y->k[i] ? -1 : 1;
    return x->tri < y->tri ? -1 : (x->tri > y->tri);
}

static d3 vert(const float *pos, const uint32_t *idx, uint32_t t, int c)
{
    const float *p = pos + 3 * (size_t)idx[3 * (size_t)t + c];
    return d3_make(p[0], p[1], p[2]);
}

/* Normal with its largest component positive: both faces of a plane share it. */
static d3 canonical(const float *fn)
{
    d3 n = d3_make(fn[0], fn[1], fn[2]);
    double ax = fabs(n.x), ay = fabs(n.y), az = fabs(n.z);
    double big = ax >= ay && ax >= az ? n.x : (ay >= az ? n.y : n.z);
    return big < 0.0 ? d3_scale(n, -1.0) : n;
}

static uint32_t ceil_shift(uint32_t n, uint32_t l) { return (n + (1u << l) - 1u) >> l; }

/* Levels of a proxy's pyramid: down to one block along both sides. */
static uint32_t pyramid_levels(uint32_t nu, uint32_t nv)
{
    uint32_t l = 1;
    while (l < VSGL__MRP_MAX_LEVELS && (ceil_shift(nu, l - 1) > 1 || ceil_shift(nv, l - 1) > 1))
        ++l;
    return l;
}

/* Floats of levels 1 .. levels - 1 of one side. */
static size_t pyramid_floats(uint32_t nu, uint32_t nv, uint32_t levels)
{
    size_t f = 0;
    for (uint32_t l = 1; l < levels; ++l)
        f += (size_t)ceil_shift(nu, l) * ceil_shift(nv, l) * 4;
    return f;
}

const float *vsgl__mrp_level(const vsgl__mrp_proxy *p, int side, uint32_t level, uint32_t *nu, uint32_t *nv,
                             uint32_t *stride)
{
    *nu = ceil_shift(p->nu, level);
    *nv = ceil_shift(p->nv, level);
    *stride = level ? 4 : 3;
    if (level == 0)
        return p->power + (size_t)side * p->nu * p->nv * 3;
    size_t off = (size_t)side * pyramid_floats(p->nu, p->nv, p->levels);
    for (uint32_t l = 1; l < level; ++l)
        off += (size_t)ceil_shift(p->nu, l) * ceil_shift(p->nv, l) * 4;
    return p->pyramid + off;
}

typedef struct group_rect { vsgl__mrp_rect rect; double area, coverage; } group_rect;

static int by_area_desc(const void *a, const void *b)
{
    double x = ((const group_rect *)a)->rect.half_u * ((const group_rect *)a)->rect.half_v;
    double y = ((const group_rect *)b)->rect.half_u * ((const group_rect *)b)->rect.half_v;
    return x > y ? -1 : (x < y);
}

/* Bounds of the group's vertices along u, v = n x u, n; returns the box area. */
static double group_box(const float *pos, const uint32_t *idx, const tri_key *keys, size_t b, size_t e, d3 n, d3 u,
                        double lo[3], double hi[3])
{
    d3 v = d3_cross(n, u);
    for (int a = 0; a < 3; ++a)
        lo[a] = INFINITY, hi[a] = -INFINITY;
    for (size_t k = b; k < e; ++k)
        for (int c = 0; c < 3; ++c) {
            d3 p = vert(pos, idx, keys[k].tri, c);
            double q[3] = {d3_dot(p, u), d3_dot(p, v), d3_dot(p, n)};
            for (int a = 0; a < 3; ++a) {
                lo[a] = fmin(lo[a], q[a]);
                hi[a] = fmax(hi[a], q[a]);
            }
        }
    return (hi[0] - lo[0]) * (hi[1] - lo[1]);
}

/* The rectangle of triangles keys[b..e): of the three edge directions of
 * the largest triangle, the one whose box around the group's vertices is
 * smallest (a quad's side, not its diagonal). */
static void fit_group(const float *pos, const uint32_t *idx, const float *fn, const tri_key *keys, size_t b, size_t e,
                      group_rect *out)
{
    d3 n = canonical(fn + 3 * (size_t)keys[b].tri);
    double best = -1.0, area = 0.0;
    uint32_t big = keys[b].tri;
    for (size_t k = b; k < e; ++k) {
        uint32_t t = keys[k].tri;
        d3 p0 = vert(pos, idx, t, 0), p1 = vert(pos, idx, t, 1), p2 = vert(pos, idx, t, 2);
        double a = 0.5 * d3_length(d3_cross(d3_sub(p1, p0), d3_sub(p2, p0)));
        area += a;
        if (a > best)
            best = a, big = t;
    }
    double lo[3], hi[3], best_box = INFINITY;
    d3 u = d3_make(0, 0, 0);
    for (int c = 0; c < 3; ++c) {
        d3 ed = d3_sub(vert(pos, idx, big, (c + 1) % 3), vert(pos, idx, big, c));
        d3 cand = d3_normalize(d3_sub(ed, d3_scale(n, d3_dot(ed, n))));
        if (d3_is_zero(cand))
            continue;
        double box = group_box(pos, idx, keys, b, e, n, cand, lo, hi);
        if (box < best_box)
            best_box = box, u = cand;
    }
    if (d3_is_zero(u)) {
        d3 t;
        d3_basis(n, &u, &t);
    }
    group_box(pos, idx, keys, b, e, n, u, lo, hi);
    d3 v = d3_cross(n, u);
    d3 c = d3_add(d3_add(d3_scale(u, 0.5 * (lo[0] + hi[0])), d3_scale(v, 0.5 * (lo[1] + hi[1]))),
                  d3_scale(n, 0.5 * (lo[2] + hi[2])));
    vsgl__mrp_rect_make(c, n, u, 0.5 * (hi[0] - lo[0]), 0.5 * (hi[1] - lo[1]), &out->rect);
    double ra = 4.0 * out->rect.half_u * out->rect.half_v;
    out->area = area;
    out->coverage = ra > 0.0 ? area / ra : 0.0;
}

vsgl_result vsgl__mrp_proxies_build(vsgl_context *ctx, const vsgl_scene *scene, double min_area, uint32_t cells,
                                    vsgl__mrp_proxy_set *out)
{
    memset(out, 0, sizeof *out);
    const float *pos, *fn;
    const uint32_t *idx, *mat;
    uint32_t nt = vsgl__scene_triangles(scene, &pos, &idx, &fn, &mat);
    v3 lo, hi;
    vsgl__scene_bounds(scene, &lo, &hi);
    double diag = v3_length(v3_sub(hi, lo));
    diag = diag > 0.0 ? diag : 1.0;
    out->plane_tol = 1e-3 * diag;
    cells = cells < 1 ? 1 : (cells > 64 ? 64 : cells);
    if (nt == 0)
        return VSGL_OK;
    tri_key *keys = malloc(nt * sizeof *keys);
    group_rect *groups = malloc(nt * sizeof *groups);
    if (!keys || !groups) {
        free(keys);
        free(groups);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "mrp: out of memory for %u triangles", nt);
    }
    const double qn = 1e3, qd = 1e4 / diag;
    for (uint32_t t = 0; t < nt; ++t) {
        d3 n = canonical(fn + 3 * (size_t)t), p = vert(pos, idx, t, 0);
        keys[t].k[0] = llround(n.x * qn);
        keys[t].k[1] = llround(n.y * qn);
        keys[t].k[2] = llround(n.z * qn);
        keys[t].k[3] = llround(d3_dot(n, p) * qd);
        keys[t].tri = t;
    }
    qsort(keys, nt, sizeof *keys, key_cmp);
    size_t ng = 0;
    for (size_t b = 0; b < nt;) {
        size_t e = b + 1;
        while (e < nt && memcmp(keys[e].k, keys[b].k, sizeof keys[b].k) == 0)
            ++e;
        fit_group(pos, idx, fn, keys, b, e, &groups[ng]);
        double ra = 4.0 * groups[ng].rect.half_u * groups[ng].rect.half_v;
        if (ra >= min_area && ra > 0.0 && groups[ng].coverage >= MIN_COVERAGE)
            ++ng;
        b = e;
    }
    free(keys);
    qsort(groups, ng, sizeof *groups, by_area_desc);
    ng = ng < MAX_PROXIES ? ng : MAX_PROXIES;
    size_t floats = 0;
    out->items = calloc(ng + 1, sizeof *out->items);
    for (size_t k = 0; k < ng && out->items; ++k) {
        vsgl__mrp_proxy *p = &out->items[k];
        p->rect = groups[k].rect;
        p->coverage = groups[k].coverage;
        double lu = p->rect.half_u, lv = p->rect.half_v, big = lu > lv ? lu : lv;
        p->nu = (uint32_t)fmax(1.0, round(cells * lu / big));
        p->nv = (uint32_t)fmax(1.0, round(cells * lv / big));
        p->levels = pyramid_levels(p->nu, p->nv);
        floats += 2 * ((size_t)p->nu * p->nv * 3 + pyramid_floats(p->nu, p->nv, p->levels));
    }
    free(groups);
    out->storage = out->items ? calloc(floats + 1, sizeof(float)) : NULL;
    if (!out->items || !out->storage) {
        vsgl__mrp_proxies_free(out);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "mrp: out of memory for %zu proxies", ng);
    }
    float *at = out->storage;
    for (size_t k = 0; k < ng; ++k) {
        vsgl__mrp_proxy *p = &out->items[k];
        p->power = at;
        at += 2 * (size_t)p->nu * p->nv * 3;
        p->pyramid = at;
        at += 2 * pyramid_floats(p->nu, p->nv, p->levels);
    }
    out->count = ng;
    return VSGL_OK;
}

void vsgl__mrp_proxies_add_rsm(vsgl__mrp_proxy_set *set, const vsgl_scene *scene, const vsgl_rsm *rsm)
{
    uint32_t mcount = 0;
    const vsgl_material *materials = vsgl__scene_materials(scene, &mcount);
    vsgl_material last; /* the material of the last texel added, and its parameters */
    vsgl_brdf_params bp;
    int have = 0;
    memset(&last, 0, sizeof last);
    memset(&bp, 0, sizeof bp);
    for (size_t i = 0; i < rsm->count; ++i) {
        if (rsm->material[i] == VSGL__RSM_EMPTY)
            continue;
        d3 x = d3_make(rsm->pos[0][i], rsm->pos[1][i], rsm->pos[2][i]);
        d3 nt = d3_make(rsm->nrm[0][i], rsm->nrm[1][i], rsm->nrm[2][i]);
        for (size_t k = 0; k < set->count; ++k) {
            vsgl__mrp_proxy *p = &set->items[k];
            d3 d = d3_sub(x, p->rect.center);
            double cn = d3_dot(nt, p->rect.normal);
            if (fabs(d3_dot(d, p->rect.normal)) > set->plane_tol || fabs(cn) < 0.95)
                continue;
            double cu = d3_dot(d, p->rect.u), cv = d3_dot(d, p->rect.v);
            if (fabs(cu) > p->rect.half_u || fabs(cv) > p->rect.half_v)
                continue;
            uint32_t iu = (uint32_t)fmin(p->nu - 1.0, floor((cu / p->rect.half_u + 1.0) * 0.5 * p->nu));
            uint32_t iv = (uint32_t)fmin(p->nv - 1.0, floor((cv / p->rect.half_v + 1.0) * 0.5 * p->nv));
            vsgl_material m;
            vsgl__rsm_material(rsm, materials, i, &m);
            if (!have || memcmp(&m, &last, sizeof m) != 0) { /* neighbouring texels share their material */
                vsgl__material_params(&m, &bp);
                last = m;
                have = 1;
            }
            int side = cn > 0.0 ? 0 : 1;
            float *cell = p->power + (((size_t)side * p->nv + iv) * p->nu + iu) * 3;
            /* the diffuse power the texel reflects, as the VSGL fit takes it
             * (fit/moments.c): Blender 4.x+'s dimming, 3.x's Burley albedo */
            const v3 wi = v3_make(rsm->wi[0][i], rsm->wi[1][i], rsm->wi[2][i]);
            const float kd = vsgl__scene_diffuse_power(scene, rsm->material[i], &bp,
                                                       v3_dot(wi, v3_make((float)nt.x, (float)nt.y, (float)nt.z)));
            for (int c = 0; c < 3; ++c)
                cell[c] += rsm->flux[c][i] * bp.diffuse[c] * kd;
            break;
        }
    }
}

void vsgl__mrp_proxies_finish(vsgl__mrp_proxy_set *set)
{
    for (size_t k = 0; k < set->count; ++k) {
        vsgl__mrp_proxy *p = &set->items[k];
        double cell_area = 4.0 * p->rect.half_u * p->rect.half_v / ((double)p->nu * p->nv);
        float scale = cell_area > 0.0 ? (float)(1.0 / (VSGL__PI_D * cell_area)) : 0.0f;
        for (int side = 0; side < 2; ++side) {
            p->side_total[side] = 0.0f;
            float *c = p->power + (size_t)side * p->nu * p->nv * 3;
            for (size_t j = 0; j < (size_t)p->nu * p->nv * 3; ++j) {
                c[j] *= scale;
                p->side_total[side] += c[j];
            }
            for (uint32_t l = 1; l < p->levels; ++l) { /* each block: the mean of the cells it covers */
                uint32_t bu, bv, st;
                float *b = (float *)vsgl__mrp_level(p, side, l, &bu, &bv, &st);
                for (uint32_t jv = 0; jv < bv; ++jv)
                    for (uint32_t ju = 0; ju < bu; ++ju) {
                        uint32_t u0 = ju << l, v0 = jv << l;
                        uint32_t u1 = u0 + (1u << l) < p->nu ? u0 + (1u << l) : p->nu;
                        uint32_t v1 = v0 + (1u << l) < p->nv ? v0 + (1u << l) : p->nv;
                        double sum[3] = {0, 0, 0}, lo = INFINITY, hi = 0.0;
                        for (uint32_t iv = v0; iv < v1; ++iv)
                            for (uint32_t iu = u0; iu < u1; ++iu) {
                                const float *cc = c + ((size_t)iv * p->nu + iu) * 3;
                                double t = (double)cc[0] + cc[1] + cc[2];
                                lo = fmin(lo, t);
                                hi = fmax(hi, t);
                                for (int ch = 0; ch < 3; ++ch)
                                    sum[ch] += cc[ch];
                            }
                        double n = (double)(u1 - u0) * (v1 - v0);
                        float *o = b + ((size_t)jv * bu + ju) * st;
                        for (int ch = 0; ch < 3; ++ch)
                            o[ch] = (float)(sum[ch] / n);
                        o[3] = hi > 0.0 ? (float)((hi - lo) / (hi + lo)) : 0.0f; /* contrast */
                    }
            }
        }
    }
}

void vsgl__mrp_proxies_free(vsgl__mrp_proxy_set *set)
{
    free(set->items);
    free(set->storage);
    memset(set, 0, sizeof *set);
}
