/* The glossy plane from the rectangle proxies (proxies.h): every shading
 * point (a pixel's samples on one flat surface) sums the MRP term of the lit
 * cells its lobe can reach; the hybrid's per-pixel rule (docs/mrp.md §4). */
#include "mrp/proxies.h"
#include "mrp/geom.h"
#include "core/context.h"
#include "core/parallel.h"
#include "scene/material.h"
#include "shade/kernel.h"
#include "vsgl/lobes.h"

#include <stdlib.h>
#include <string.h>

/* 1: cells are culled against the warped lobe's ASG (anisotropic); 0: only
 * the isotropic box around the peak (tools/mrp_quality.sh measures both). */
#ifndef VSGL__MRP_CULL
#define VSGL__MRP_CULL 1
#endif
/* A lobe reaches the cells where its ASG exponent is at most this (e^{-6}
 * of its peak: 0.25 % of a 2-D Gaussian's energy lies beyond). e^{-9}
 * (1e-4) took 1.35x the lobe terms on the quality suite's metal floors for
 * the same hybrid glossy relMSE, FLIP and light flicker (docs/mrp.md §4);
 * MRP alone loses 0.3 % of its glossy light, its FLIP +0.001-0.003. */
#ifndef VSGL__MRP_REACH
#define VSGL__MRP_REACH 6.0
#endif
/* The same in the hybrid, where beyond MRP's reach the VSGLs' estimate of
 * the proxies' light takes over (VSGL__MRP_HYBRID_RATIO): e^{-3} halves the
 * lobe terms against e^{-6} (docs/mrp.md §4, "Speed, second round"). */
#ifndef VSGL__MRP_REACH_HYBRID
#define VSGL__MRP_REACH_HYBRID 3.0
#endif
/* A block of cells of the proxy's pyramid is shaded whole when its diagonal
 * is at most this many times the lobe's sampling disk (its radius, at the
 * block's clamped peak): the disk's Gaussian light blurs anything finer.
 * 0: every cell on its own (the pass before the pyramid; docs/mrp.md §4
 * measures both). */
#ifndef VSGL__MRP_MERGE
#define VSGL__MRP_MERGE 1.0
#endif
/* ... and when its cells' radiance (sum of channels) differs by at most this
 * contrast (max - min) / (max + min): the edge of a sharp sun patch is
 * shaded cell by cell. */
#ifndef VSGL__MRP_MERGE_CONTRAST
#define VSGL__MRP_MERGE_CONTRAST 0.25
#endif
/* Hybrid: in a pixel MRP takes, the proxies' light is MRP's where it is
 * more than this many times the on-proxy VSGLs' estimate of it, else the
 * VSGLs'. 2: MRP only where the VSGLs miss most of the light it finds.
 * Since the half-vector model (docs/pipeline.md), taking MRP's light where
 * it is 1x-1.5x the lattice's moves the quality rooms' glossy pass away
 * from Cycles; on their metal floors this rule leaves the lattice's light
 * in every pixel (docs/mrp.md §4). 1: the larger of the two (the rule before:
 * no seam where MRP's reach ends, but MRP's excess at the rim of every
 * reflection); 0: MRP's light alone (a dark band where its reach ends). */
#ifndef VSGL__MRP_HYBRID_RATIO
#define VSGL__MRP_HYBRID_RATIO 2.0
#endif

typedef struct mrp_job {
    const vsgl_scene *scene;
    const vsgl_gbuffer *g;
    const vsgl__mrp_proxy_set *set;
    const vsgl_pixel_planes *planes;
    const vsgl_material *materials;
    vsgl__mrp_options opt;
    const float *glossy_q; /* hybrid: the VSGL glossy of the clusters off the proxies, else NULL */
    double max_alpha;      /* hybrid: the largest GGX alpha of a receiver that takes MRP */
    double merge;          /* VSGL__MRP_MERGE */
    double reach;          /* VSGL__MRP_REACH, or VSGL__MRP_REACH_HYBRID in the hybrid */
} mrp_job;

/* Hybrid rule, first half: 1 if every glossy sample of pixel px is sharp
 * enough for MRP (alpha <= max_alpha); pixels without glossy samples too. */
static int pixel_sharp(const mrp_job *j, size_t px)
{
    const vsgl_gbuffer *g = j->g;
    for (size_t s = 0; s < g->spp; ++s) {
        size_t i = px * g->spp + s;
        if (g->material[i] == VSGL__GBUFFER_MISS)
            continue;
        vsgl_material m;
        vsgl__gbuffer_material(g, j->materials, i, &m);
        vsgl_brdf_params bp;
        vsgl__material_params(&m, &bp);
        if (bp.glossy && !(sqrt((double)bp.alpha_x * bp.alpha_y) <= j->max_alpha))
            return 0;
    }
    return 1;
}

/* Glossy radiance (RGB, smooth factor included) at position x, normal n,
 * view o with the material of sample i. */
static void sample_glossy(const mrp_job *j, size_t i, d3 x, d3 n, d3 o, float out[3])
{
    out[0] = out[1] = out[2] = 0.0f;
    const vsgl_gbuffer *g = j->g;
    vsgl_material m;
    vsgl__gbuffer_material(g, j->materials, i, &m);
    vsgl_brdf_params bp;
    vsgl__material_params(&m, &bp);
    if (!bp.glossy || !(d3_dot(n, o) > 0.0))
        return;
    double alpha = sqrt((double)bp.alpha_x * bp.alpha_y);
    vsgl__mrp_receiver rcv; /* the receiver's lobes, once for every cell */
    vsgl__mrp_receiver_make(n, o, alpha, &j->opt, &rcv);
    vsgl_sg lobe;
    vsgl__mrp_receiver_sg(n, o, alpha, &lobe);
    d3 z = d3_of_v3(lobe.axis);
    /* e^{-REACH} of the peak of the widest lobe (GGX's tail when there are two)
     * along the warped ASG's wider axis (a grazing view stretches it in the
     * plane of incidence: Eq. 8's isotropic SG is up to 1/sqrt(2 |o.n|) narrower) */
    const vsgl_asg wa = rcv.warped;
    double nu = fmin((double)wa.lambda, (double)wa.mu) * (j->opt.lobes == 2 ? VSGL__GGX_TAIL_K : 1.0);
    double spread = sqrt(j->reach / (nu > 1e-6 ? nu : 1e-6));
    /* the core's reach, where there are two lobes: cells beyond it skip the core */
    const double core_frac = j->opt.lobes == 2 ? sqrt((double)VSGL__GGX_TAIL_K / VSGL__GGX_CORE_K) : 1.0;
    /* per cell, the anisotropic test against the warped lobe (the box test
     * above is isotropic: at grazing views the lobe is narrow across the
     * plane of incidence); bandwidth scales of the widest lobe and the core */
    const int cull = VSGL__MRP_CULL;
#ifdef VSGL__MRP_EXACT_CELLS
    const int exact = 1; /* the widest lobe's cells, one by one */
#else
    const int exact = 0;
#endif
    const double k_wide = j->opt.lobes == 2 ? VSGL__GGX_TAIL_K : 1.0, k_core = j->opt.lobes == 2 ? VSGL__GGX_CORE_K : 1.0;
    const d3 wx = d3_of_v3(wa.x), wy = d3_of_v3(wa.y), wz = d3_of_v3(wa.z);
    v3 nf = d3_to_v3(n), of = d3_to_v3(o);
    float ms[3];
    for (int c = 0; c < 3; ++c)
        ms[c] = vsgl__ms_scale(&bp, c, v3_dot(nf, of));
    double acc[3] = {0, 0, 0};
    for (size_t k = 0; k < j->set->count; ++k) {
        const vsgl__mrp_proxy *p = &j->set->items[k];
        for (int side = 0; side < 2; ++side) {
            if (!(p->side_total[side] > 0.0f))
                continue;
            vsgl__mrp_rect plane = p->rect;
            if (side) {
                plane.normal = d3_scale(plane.normal, -1.0);
                plane.v = d3_scale(plane.v, -1.0); /* keep v = n x u */
            }
            d3 y;
            if (!vsgl__mrp_peak(&plane, x, d3_scale(z, -1.0), &y))
                continue; /* behind the plane, or the lobe's axis leaves it */
            /* cells farther from the peak than the lobe's reach are skipped */
            double d = d3_length(d3_sub(y, x)), cs = d3_dot(d3_sub(x, y), plane.normal) / (d > 0.0 ? d : 1.0);
            double reach = d * spread / (cs > 0.05 ? cs : 0.05);
            double h = d3_dot(d3_sub(x, plane.center), plane.normal);
            d3 dy = d3_sub(y, plane.center);
            /* cell (iu, iv) is where proxies.c put it: along the proxy's own v
             * (the back side's flipped plane.v would mirror its radiance) */
            const d3 pv0 = p->rect.v;
            double yu = d3_dot(dy, plane.u), yv = d3_dot(dy, pv0);
            const float *lv[VSGL__MRP_MAX_LEVELS] = {0}; /* this side's pyramid levels, looked up once */
            uint32_t lnu[VSGL__MRP_MAX_LEVELS] = {0}, lst[VSGL__MRP_MAX_LEVELS] = {0};
            for (uint32_t l = 0; l < p->levels && l < VSGL__MRP_MAX_LEVELS; ++l) {
                uint32_t nv_l;
                lv[l] = vsgl__mrp_level(p, side, l, &lnu[l], &nv_l, &lst[l]);
            }
            double cu = plane.half_u / p->nu, cv = plane.half_v / p->nv;
            /* each lobe walks the cell pyramid from its top: a block is taken whole when it is
             * within the lobe's reach and no larger than VSGL__MRP_MERGE x the lobe's disk
             * there, split into its four children when larger, dropped when out of reach */
            for (int q = exact ? rcv.parts - 1 : 0; q < rcv.parts; ++q) {
                const double reach_q = q == 0 ? reach * core_frac : reach, k_q = q == 0 ? k_core : k_wide;
                uint32_t stack[3 * 64], sp = 0;
                stack[sp++] = p->levels - 1, stack[sp++] = 0, stack[sp++] = 0;
                while (sp) {
                    uint32_t bv = stack[--sp], bu = stack[--sp], l = stack[--sp];
                    const float *L = lv[l] + ((size_t)bv * lnu[l] + bu) * lst[l];
                    if (!(L[0] + L[1] + L[2] > 0.0f))
                        continue;
                    uint32_t u0 = bu << l, v0 = bv << l;
                    uint32_t u1 = u0 + (1u << l) < p->nu ? u0 + (1u << l) : p->nu;
                    uint32_t v1 = v0 + (1u << l) < p->nv ? v0 + (1u << l) : p->nv;
                    double mv = -plane.half_v + (double)(v0 + v1) * cv, hv = (double)(v1 - v0) * cv;
                    double dv = fabs(yv - mv) - hv;
                    if (dv > reach_q)
                        continue;
                    double mu = -plane.half_u + (double)(u0 + u1) * cu, hu = (double)(u1 - u0) * cu;
                    double du = fabs(yu - mu) - hu;
                    if (du > reach_q)
                        continue;
                    vsgl__mrp_rect cell = plane;
                    cell.center = d3_add(plane.center, d3_add(d3_scale(plane.u, mu), d3_scale(pv0, mv)));
                    cell.half_u = hu;
                    cell.half_v = hv;
                    if (cull) { /* the lobe itself at the cell: its ASG exponent past REACH, the cell's
                                 * angular radius taken off both offsets (conservative) */
                        d3 dc = d3_sub(cell.center, x);
                        double dist = d3_length(dc), ang = sqrt(hu * hu + hv * hv) / (dist > 0.0 ? dist : 1e-30);
                        d3 vd = d3_scale(dc, 1.0 / (dist > 0.0 ? dist : 1e-30));
                        if (d3_dot(vd, wz) < -ang)
                            continue;
                        double ax = d_max(0.0, fabs(d3_dot(vd, wx)) - ang), ay = d_max(0.0, fabs(d3_dot(vd, wy)) - ang);
                        double ex = (double)wa.lambda * ax * ax + (double)wa.mu * ay * ay;
                        if (ex * k_q > j->reach)
                            continue;
                    }
                    if (l > 0) { /* whole, or its children */
                        double pu = d_min(d_max(yu, mu - hu), mu + hu), pv = d_min(d_max(yv, mv - hv), mv + hv);
                        double db = sqrt(h * h + (yu - pu) * (yu - pu) + (yv - pv) * (yv - pv));
                        double rd = vsgl__mrp_lobe_disk_radius(&rcv, q, &j->opt, db, db > 0.0 ? h / db : 1.0);
                        if (exact || !(L[3] <= VSGL__MRP_MERGE_CONTRAST) ||
                            !(2.0 * sqrt(hu * hu + hv * hv) <= j->merge * rd)) {
                            uint32_t cnu = (p->nu + (1u << (l - 1)) - 1) >> (l - 1);
                            uint32_t cnv = (p->nv + (1u << (l - 1)) - 1) >> (l - 1);
                            for (uint32_t c = 0; c < 4; ++c) {
                                uint32_t cbu = 2 * bu + (c & 1u), cbv = 2 * bv + (c >> 1);
                                if (cbu < cnu && cbv < cnv && sp + 3 <= sizeof stack / sizeof stack[0])
                                    stack[sp++] = l - 1, stack[sp++] = cbu, stack[sp++] = cbv;
                            }
                            continue;
                        }
                    }
#ifdef VSGL__MRP_EXACT_CELLS
                    { /* diagnostic build (tools/mrp_quality.sh): the exact BRDF integrated over the cell
                       * (N x N midpoints, -DVSGL__MRP_EXACT_CELLS=N) instead of the MRP term, to tell
                       * the term's error from the cells' radiance */
                        const int Q = VSGL__MRP_EXACT_CELLS;
                        for (int a = 0; a < Q; ++a)
                            for (int b = 0; b < Q; ++b) {
                                double pu = mu + hu * (2.0 * (a + 0.5) / Q - 1.0), pv = mv + hv * (2.0 * (b + 0.5) / Q - 1.0);
                                d3 pp = d3_add(plane.center, d3_add(d3_scale(plane.u, pu), d3_scale(pv0, pv)));
                                d3 wi = d3_sub(pp, x);
                                double r2 = d3_dot(wi, wi);
                                wi = d3_scale(wi, 1.0 / sqrt(r2));
                                double cr = -d3_dot(wi, plane.normal);
                                if (!(cr > 0.0))
                                    continue;
                                float dif[3], gl[3];
                                v3 tf = v3_make(g->tan[0][i], g->tan[1][i], g->tan[2][i]);
                                vsgl__brdf_eval(&bp, nf, tf, d3_to_v3(wi), of, dif, gl);
                                double w = 4.0 * hu * hv / (Q * Q) * cr / r2;
                                for (int c = 0; c < 3; ++c)
                                    acc[c] += w * gl[c] * ms[c] * L[c];
                            }
                        continue;
                    }
#endif
                    d3 axis[2];
                    double v[2];
                    unsigned skip = rcv.parts == 2 ? 1u << (1 - q) : 0u; /* this lobe only */
                    vsgl__mrp_glossy_parts_at(&cell, x, &rcv, &j->opt, skip, v, axis);
                    if (!(v[q] > 0.0))
                        continue;
                    float sf[3];
                    vsgl__specular_factor(&bp, nf, of, d3_to_v3(axis[q]), (float)alpha, sf);
                    for (int c = 0; c < 3; ++c)
                        acc[c] += v[q] * sf[c] * ms[c] * L[c];
                }
            }
        }
    }
    for (int c = 0; c < 3; ++c)
        out[c] = acc[c] > 0.0 && acc[c] < 3e38 ? (float)acc[c] : 0.0f;
}

/* The samples of a pixel on one flat surface (same material, normals within
 * ~0.5 degree) are shaded once, at their weighted mean position and view:
 * the glossy light of a flat mirror-like floor changes little within a
 * pixel (the VSGL pass shades one anchor per 2 x 2 pixels and interpolates),
 * and the mode's cost is per shading point. */
#define MRP_GROUP_COS 0.99996

/* Shading one pixel in 2 x 2 (MRP's cost is per shading point): anchors at
 * the even columns and rows (and the last ones) are shaded; any other pixel
 * takes the mean of its two or four neighbouring anchors when it and they
 * lie on one flat surface (one material, normals within MRP_GROUP_COS, on
 * one plane, every sample a hit) and the anchors' light differs by at most
 * half of VSGL__MRP_SPARSE_CONTRAST ((max - min) / (max + min) of the sums
 * of channels); from there to VSGL__MRP_SPARSE_CONTRAST it is shaded and
 * blended with that mean (linearly in the contrast: a pixel does not jump
 * between the two as a light moves); elsewhere (edges, the rim of a
 * reflection) it is shaded itself. 0 shades every pixel. docs/mrp.md §4
 * measures both. */
#ifndef VSGL__MRP_SPARSE_CONTRAST
#define VSGL__MRP_SPARSE_CONTRAST 0.1
#endif

/* Per pixel: its one flat surface, when all its samples hit one. */
typedef struct mrp_surface {
    float n[3], x[3];
    uint32_t material;
    uint8_t flat;  /* 1: every sample a hit, one group */
    uint8_t state; /* 0 not shaded yet, 1 raw holds its light, 2 hybrid: a rough pixel (not MRP's) */
} mrp_surface;

typedef struct mrp_pass {
    const mrp_job *j;
    float *raw;          /* per pixel: MRP's light (RGB) */
    mrp_surface *surf;
    int phase;           /* 0 anchors, 1 the others, 2 write */
} mrp_pass;

/* MRP's light of pixel px (its samples grouped by surface) when @p shade,
 * and its surface. */
static void shade_pixel(const mrp_job *j, size_t px, int shade, float acc[3], mrp_surface *sf)
{
    const vsgl_gbuffer *g = j->g;
    size_t spp = g->spp;
    unsigned char done[256];
    int groups = 0, misses = 0;
    acc[0] = acc[1] = acc[2] = 0.0f;
    memset(done, 0, sizeof done);
    for (size_t s = 0; s < spp; ++s) {
        size_t i = px * spp + s;
        if (g->material[i] == VSGL__GBUFFER_MISS) {
            misses += vsgl__gbuffer_weight(g, i) > 0.0f; /* an unused slot weighs 0 */
            continue;
        }
        if (s < 256 && done[s])
            continue;
        d3 n0 = d3_make(g->nrm[0][i], g->nrm[1][i], g->nrm[2][i]);
        d3 xs = d3_make(0, 0, 0), os = d3_make(0, 0, 0);
        double ws = 0.0;
        for (size_t t = s; t < spp; ++t) { /* s and the later samples of its group */
            size_t k = px * spp + t;
            if (t >= 256 && t != s)
                break;
            if (t != s && (done[t] || g->material[k] != g->material[i] ||
                           d3_dot(n0, d3_make(g->nrm[0][k], g->nrm[1][k], g->nrm[2][k])) < MRP_GROUP_COS))
                continue;
            double w = vsgl__gbuffer_weight(g, k); /* the sample's share of its pixel */
            xs = d3_add(xs, d3_scale(d3_make(g->pos[0][k], g->pos[1][k], g->pos[2][k]), w));
            os = d3_add(os, d3_scale(d3_make(g->view[0][k], g->view[1][k], g->view[2][k]), w));
            ws += w;
            if (t < 256)
                done[t] = 1;
        }
        if (!(ws > 0.0))
            continue;
        if (++groups == 1 && !shade) {
            d3 xm = d3_scale(xs, 1.0 / ws);
            sf->n[0] = (float)n0.x, sf->n[1] = (float)n0.y, sf->n[2] = (float)n0.z;
            sf->x[0] = (float)xm.x, sf->x[1] = (float)xm.y, sf->x[2] = (float)xm.z;
            sf->material = g->material[i];
        }
        if (!shade)
            continue;
        float l[3];
        sample_glossy(j, i, d3_scale(xs, 1.0 / ws), n0, d3_normalize(os), l);
        for (int c = 0; c < 3; ++c)
            acc[c] += (float)ws * l[c];
    }
    if (!shade)
        sf->flat = groups == 1 && misses == 0 && spp <= 256;
}

static int is_anchor(uint32_t v, uint32_t n) { return (v & 1u) == 0 || v + 1 == n; }

/* The mean of the anchors around pixel (x, y) into acc and its weight
 * (1: the mean alone, 0: shade the pixel, between: blend; see
 * VSGL__MRP_SPARSE_CONTRAST). */
static float interpolate(const mrp_pass *P, uint32_t x, uint32_t y, float acc[3])
{
    const vsgl_gbuffer *g = P->j->g;
    const mrp_surface *me = &P->surf[(size_t)y * g->width + x];
    if (!me->flat)
        return 0;
    uint32_t xs[2] = {x, x}, ys[2] = {y, y};
    int nx = 1, ny = 1;
    if (!is_anchor(x, g->width))
        xs[0] = x - 1, xs[1] = x + 1, nx = 2;
    if (!is_anchor(y, g->height))
        ys[0] = y - 1, ys[1] = y + 1, ny = 2;
    float lo = INFINITY, hi = 0.0f, sum[3] = {0, 0, 0};
    for (int b = 0; b < ny; ++b)
        for (int a = 0; a < nx; ++a) {
            size_t q = (size_t)ys[b] * g->width + xs[a];
            const mrp_surface *o = &P->surf[q];
            if (o->state != 1 || !o->flat || o->material != me->material)
                return 0;
            double dn = (double)o->n[0] * me->n[0] + (double)o->n[1] * me->n[1] + (double)o->n[2] * me->n[2];
            double dx[3] = {(double)o->x[0] - me->x[0], (double)o->x[1] - me->x[1], (double)o->x[2] - me->x[2]};
            double off = fabs(dx[0] * me->n[0] + dx[1] * me->n[1] + dx[2] * me->n[2]);
            if (dn < MRP_GROUP_COS || off > 1e-3 * sqrt(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]) + 1e-6)
                return 0;
            const float *r = P->raw + q * 3;
            float t = r[0] + r[1] + r[2];
            lo = t < lo ? t : lo;
            hi = t > hi ? t : hi;
            for (int c = 0; c < 3; ++c)
                sum[c] += r[c];
        }
    const float t1 = (float)VSGL__MRP_SPARSE_CONTRAST, t0 = 0.5f * t1;
    float contrast = hi > 0.0f ? (hi - lo) / (hi + lo) : 0.0f;
    if (!(contrast < t1))
        return 0;
    for (int c = 0; c < 3; ++c)
        acc[c] = sum[c] / (float)(nx * ny);
    return contrast <= t0 ? 1.0f : (t1 - contrast) / (t1 - t0);
}

static int32_t mrp_chunk(void *user, size_t chunk, size_t b, size_t e)
{
    (void)chunk;
    const mrp_pass *P = user;
    const mrp_job *j = P->j;
    const vsgl_gbuffer *g = j->g;
    for (size_t px = b; px < e; ++px) {
        uint32_t x = (uint32_t)(px % g->width), y = (uint32_t)(px / g->width);
        mrp_surface *sf = &P->surf[px];
        float *raw = P->raw + px * 3;
        int anchor = VSGL__MRP_SPARSE_CONTRAST <= 0.0 || (is_anchor(x, g->width) && is_anchor(y, g->height));
        if (P->phase == 0) /* every pixel's surface */
            shade_pixel(j, px, 0, raw, sf);
        if (P->phase < 2) {
            if (anchor != (P->phase == 0))
                continue;
            if (j->glossy_q && !pixel_sharp(j, px)) {
                sf->state = 2; /* hybrid: a rough receiver keeps the VSGL glossy light */
                continue;
            }
            float mean[3], w = P->phase == 0 ? 0.0f : interpolate(P, x, y, mean);
            if (w < 1.0f)
                shade_pixel(j, px, 1, raw, sf);
            for (int c = 0; c < 3 && w > 0.0f; ++c)
                raw[c] = w * mean[c] + (1.0f - w) * (w < 1.0f ? raw[c] : 0.0f);
            sf->state = 1;
            continue;
        }
        if (sf->state != 1)
            continue;
        float acc[3] = {raw[0], raw[1], raw[2]};
        if (j->glossy_q) { /* hybrid: MRP where it finds lit proxies, with the VSGLs off them */
            if (!(acc[0] + acc[1] + acc[2] > 0.0f))
                continue;
            /* the proxies' light: MRP's, or the on-proxy VSGLs' (all - off) where MRP's is not above
             * VSGL__MRP_HYBRID_RATIO times theirs (MRP stops at e^{-VSGL__MRP_REACH_HYBRID} of its tail lobe) */
            const float *ga = j->planes->glossy + px * 3, *gq = j->glossy_q + px * 3;
            float pm = acc[0] + acc[1] + acc[2], pv = 0.0f, pvc[3];
            for (int c = 0; c < 3; ++c) {
                pvc[c] = ga[c] > gq[c] ? ga[c] - gq[c] : 0.0f;
                pv += pvc[c];
            }
            if (!(pm > (float)VSGL__MRP_HYBRID_RATIO * pv))
                for (int c = 0; c < 3; ++c)
                    acc[c] = pvc[c];
            for (int c = 0; c < 3; ++c)
                acc[c] += j->glossy_q[px * 3 + c];
        }
        for (int c = 0; c < 3; ++c)
            j->planes->glossy[px * 3 + c] = acc[c];
    }
    return 0;
}

vsgl_result vsgl__mrp_shade_glossy(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_gbuffer *g,
                                   const vsgl__mrp_proxy_set *set, const vsgl_pixel_planes *planes,
                                   const float *glossy_q, double max_alpha)
{
    uint32_t mcount = 0;
    mrp_job j = {scene, g, set, planes, vsgl__scene_materials(scene, &mcount), vsgl__mrp_options_default(),
                 glossy_q, max_alpha, VSGL__MRP_MERGE, glossy_q ? VSGL__MRP_REACH_HYBRID : VSGL__MRP_REACH};
    size_t pixels = (size_t)g->width * g->height;
    mrp_pass P = {&j, malloc((pixels ? pixels : 1) * 3 * sizeof(float)), calloc(pixels ? pixels : 1, sizeof(mrp_surface)), 0};
    int32_t r = 0;
    if (!P.raw || !P.surf)
        r = VSGL_ERROR_OUT_OF_MEMORY;
    for (int phase = 0; phase < 3 && r == 0; ++phase) { /* anchors, the others, the planes */
        P.phase = phase;
        r = vsgl__parallel_for(vsgl_context_thread_count(ctx), pixels, 64, mrp_chunk, &P);
    }
    free(P.raw);
    free(P.surf);
    return r == 0 ? VSGL_OK : vsgl__fail(ctx, (vsgl_result)r, "mrp: glossy shading failed");
}
