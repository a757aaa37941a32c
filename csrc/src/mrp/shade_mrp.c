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

#include <string.h>

/* 1: cells are culled against the warped lobe's ASG (anisotropic); 0: only
 * the isotropic box around the peak (tools/mrp_quality.sh measures both). */
#ifndef VSGL__MRP_CULL
#define VSGL__MRP_CULL 1
#endif
/* Hybrid: 1 takes, in a pixel MRP takes, the larger of MRP's and the
 * on-proxy VSGLs' estimate of the proxies' light (no seam where MRP's
 * reach ends: a dark band showed there); 0: MRP's alone (docs/mrp.md §4). */
#ifndef VSGL__MRP_HYBRID_MAX
#define VSGL__MRP_HYBRID_MAX 1
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
    /* e^{-9} of the peak of the widest lobe (GGX's tail when there are two)
     * along the warped ASG's wider axis (a grazing view stretches it in the
     * plane of incidence: Eq. 8's isotropic SG is up to 1/sqrt(2 |o.n|) narrower) */
    const vsgl_asg wa = rcv.warped;
    double nu = fmin((double)wa.lambda, (double)wa.mu) * (j->opt.lobes == 2 ? VSGL__GGX_TAIL_K : 1.0);
    double spread = 3.0 / sqrt(nu > 1e-6 ? nu : 1e-6);
    /* the core's reach, where there are two lobes: cells beyond it skip the core */
    const double core_frac = j->opt.lobes == 2 ? sqrt((double)VSGL__GGX_TAIL_K / VSGL__GGX_CORE_K) : 1.0;
    /* per cell, the anisotropic test against the warped lobe (the box test
     * above is isotropic: at grazing views the lobe is narrow across the
     * plane of incidence); bandwidth scales of the widest lobe and the core */
    const int cull = VSGL__MRP_CULL;
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
            d3 dy = d3_sub(y, plane.center);
            /* cell (iu, iv) is where proxies.c put it: along the proxy's own v
             * (the back side's flipped plane.v would mirror its radiance) */
            const d3 pv0 = p->rect.v;
            double yu = d3_dot(dy, plane.u), yv = d3_dot(dy, pv0);
            double cu = plane.half_u / p->nu, cv = plane.half_v / p->nv;
            const float *rad = p->power + (size_t)side * p->nu * p->nv * 3;
            for (uint32_t iv = 0; iv < p->nv; ++iv) {
                double mv = -plane.half_v + (2.0 * iv + 1.0) * cv;
                double dv = fabs(yv - mv) - cv;
                if (dv > reach)
                    continue;
                for (uint32_t iu = 0; iu < p->nu; ++iu) {
                    const float *L = rad + ((size_t)iv * p->nu + iu) * 3;
                    if (!(L[0] + L[1] + L[2] > 0.0f))
                        continue;
                    double mu = -plane.half_u + (2.0 * iu + 1.0) * cu;
                    double du = fabs(yu - mu) - cu;
                    if (du > reach)
                        continue;
                    unsigned skip = du > reach * core_frac || dv > reach * core_frac ? 1u : 0u;
                    vsgl__mrp_rect cell = plane;
                    cell.center = d3_add(plane.center, d3_add(d3_scale(plane.u, mu), d3_scale(pv0, mv)));
                    cell.half_u = cu;
                    cell.half_v = cv;
                    if (cull) { /* the lobe itself at the cell: its ASG exponent past e^{-9}, the cell's
                                 * angular radius taken off both offsets (conservative) */
                        d3 dc = d3_sub(cell.center, x);
                        double dist = d3_length(dc), ang = sqrt(cu * cu + cv * cv) / (dist > 0.0 ? dist : 1e-30);
                        d3 vd = d3_scale(dc, 1.0 / (dist > 0.0 ? dist : 1e-30));
                        if (d3_dot(vd, wz) < -ang)
                            continue;
                        double ax = fmax(0.0, fabs(d3_dot(vd, wx)) - ang), ay = fmax(0.0, fabs(d3_dot(vd, wy)) - ang);
                        double ex = (double)wa.lambda * ax * ax + (double)wa.mu * ay * ay;
                        if (ex * k_wide > 9.0)
                            continue;
                        if (ex * k_core > 9.0)
                            skip |= 1u;
                    }
#ifdef VSGL__MRP_EXACT_CELLS
                    { /* diagnostic build (tools/mrp_quality.sh): the exact BRDF integrated over the cell
                       * (N x N midpoints, -DVSGL__MRP_EXACT_CELLS=N) instead of the MRP term, to tell
                       * the term's error from the cells' radiance */
                        const int Q = VSGL__MRP_EXACT_CELLS;
                        for (int a = 0; a < Q; ++a)
                            for (int b = 0; b < Q; ++b) {
                                double pu = mu + cu * (2.0 * (a + 0.5) / Q - 1.0), pv = mv + cv * (2.0 * (b + 0.5) / Q - 1.0);
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
                                double w = 4.0 * cu * cv / (Q * Q) * cr / r2;
                                for (int c = 0; c < 3; ++c)
                                    acc[c] += w * gl[c] * ms[c] * L[c];
                            }
                        continue;
                    }
#endif
                    d3 axis[2];
                    double v[2];
                    int parts = vsgl__mrp_glossy_parts_at(&cell, x, &rcv, &j->opt, skip, v, axis);
                    for (int q = 0; q < parts; ++q) {
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

static int32_t mrp_chunk(void *user, size_t chunk, size_t b, size_t e)
{
    (void)chunk;
    const mrp_job *j = user;
    const vsgl_gbuffer *g = j->g;
    size_t spp = g->spp;
    unsigned char done[256];
    for (size_t px = b; px < e; ++px) {
        float acc[3] = {0, 0, 0};
        if (j->glossy_q && !pixel_sharp(j, px))
            continue; /* hybrid: a rough receiver keeps the VSGL glossy light */
        memset(done, 0, sizeof done);
        for (size_t s = 0; s < spp; ++s) {
            size_t i = px * spp + s;
            if (g->material[i] == VSGL__GBUFFER_MISS || (s < 256 && done[s]))
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
            float l[3];
            sample_glossy(j, i, d3_scale(xs, 1.0 / ws), n0, d3_normalize(os), l);
            for (int c = 0; c < 3; ++c)
                acc[c] += (float)ws * l[c];
        }
        if (j->glossy_q) { /* hybrid: MRP where it finds lit proxies, with the VSGLs off them */
            if (!(acc[0] + acc[1] + acc[2] > 0.0f))
                continue;
#if VSGL__MRP_HYBRID_MAX
            /* the proxies' light as the larger of MRP's and the on-proxy VSGLs' (all - off):
             * MRP stops at e^{-9} of its tail lobe, the VSGLs keep a haze beyond it */
            const float *ga = j->planes->glossy + px * 3, *gq = j->glossy_q + px * 3;
            float pm = acc[0] + acc[1] + acc[2], pv = 0.0f, pvc[3];
            for (int c = 0; c < 3; ++c) {
                pvc[c] = ga[c] > gq[c] ? ga[c] - gq[c] : 0.0f;
                pv += pvc[c];
            }
            if (pv > pm)
                for (int c = 0; c < 3; ++c)
                    acc[c] = pvc[c];
#endif
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
                 glossy_q, max_alpha};
    size_t pixels = (size_t)g->width * g->height;
    int32_t r = vsgl__parallel_for(vsgl_context_thread_count(ctx), pixels, 64, mrp_chunk, &j);
    return r == 0 ? VSGL_OK : vsgl__fail(ctx, (vsgl_result)r, "mrp: glossy shading failed");
}
