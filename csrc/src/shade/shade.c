/* Shading with VSGLs: incident radiance as one SG (Eq. 7), diffuse via the
 * SG x clamped-cosine integral (three modes), glossy via the warped
 * receiver NDF as an ASG (or SG) convolved with the incident SG, with the
 * smooth Fresnel/shadowing factor at the integrand's lobe axis. */
#include "shade/shade.h"
#include "shade/halfvec.h"
#include "math/broad_lobe.h"
#include "math/warp_lanes.h"
#include "math/constants.h"
#include "math/normal.h"
#include "math/sg_internal.h"
#include "shade/kernel.h"
#include "shade/near_field.h"
#include "shade/shade_job.h"
#include "core/context.h"
#include "core/parallel.h"
#include "scene/material.h"
#include "vsgl/lobes.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>
#if defined(__x86_64__) || defined(__i386__)
#  include <xmmintrin.h>
#endif

/* Variance floor relative to the squared receiver distance (docs/references.md §4): 2^-41. */
#define VARIANCE_FLOOR 4.547473508864641e-13f

float vsgl__foreshortening_weight(const vsgl_vsgl *v)
{
    return v->lobe == VSGL__LOBE_DIFFUSE ? v->coherence * v->coherence : 0.0f;
}

int vsgl__vsgl_incident_sg(const vsgl_vsgl *v, v3 x, vsgl_sg *sg)
{
    return vsgl__vsgl_incident_sg_with(v, x, vsgl__vsgl_lobe_integral(v), sg);
}

int vsgl__vsgl_incident_sg_with(const vsgl_vsgl *v, v3 x, float lobe_integral, vsgl_sg *sg)
{
    v3 d = v3_sub(v->mean, x);
    float dist2 = v3_dot(d, d);
    float var = v->variance;
    if (var < dist2 * VARIANCE_FLOOR)
        var = dist2 * VARIANCE_FLOOR;
    if (!(var > 0.0f) || !(var < INFINITY))
        return 0;
    vsgl_sg light_lobe = {v3_neg(v->axis), v->sharpness, 0.0f};
    vsgl_sg spread;
    spread.axis = dist2 > 0.0f ? v3_scale(d, 1.0f / sqrtf(dist2)) : v3_neg(v->axis);
    spread.sharpness = dist2 / var;
    spread.log_amplitude = 0.0f;
    /* the product with the spread foreshortened and the distance lobe
     * (shade.h, kernel.h vsgl__plane_spread); its sharpness the round product's */
    float round = v3_length(v3_add(v3_scale(light_lobe.axis, light_lobe.sharpness),
                                   v3_scale(spread.axis, spread.sharpness)));
    float ce = -v3_dot(spread.axis, v->normal), kd;
    spread.sharpness *= vsgl__plane_spread(ce, vsgl__foreshortening_weight(v), &kd);
    vsgl_sg_product(&light_lobe, &spread, sg);
    if (kd > 0.0f) {
        vsgl_sg dist = {v3_neg(v->normal), kd, kd * (1.0f - ce)};
        vsgl_sg_product(sg, &dist, sg);
    }
    sg->sharpness = round;
    /* c_v / (2 pi var) with c_v = power / A(lambda_v) (a specular lobe's A
     * its part above its surface, vsgl__vsgl_lobe_integral); power applied
     * by the caller */
    sg->log_amplitude -= logf(VSGL__2PI * var) + logf(lobe_integral);
    return 1;
}

float vsgl__vsgl_part_keep(const vsgl_vsgl *v, uint32_t part)
{
    if (v->part == VSGL__PART_NONE || part == VSGL__PART_NONE || part >> 1 != v->part)
        return 1.0f;
    return fmaxf(1.0f - v->part_out - ((part & 1u) ? 0.0f : v->part_in), 0.0f);
}

float vsgl__emitter_clip(const vsgl_vsgl *v, v3 x, v3 n, int on)
{
    if (!on)
        return 1.0f;
    v3 d = v3_sub(x, v->mean);
    float d2 = v3_dot(d, d);
    float var = fmaxf(v->variance, d2 * VARIANCE_FLOOR);
    float h = v3_dot(d, v->normal);
    float s = var > 0.0f ? d2 / var : 0.0f;
    float w = s / (s + VSGL__CLIP_NEAR);
    /* the parallel clip in the near field only: far away the receiver's own cosine does it */
    float par = 1.0f - (1.0f - smoothstep01f((1.0f - v3_dot(n, v->normal)) * (1.0f / VSGL__CLIP_PARALLEL))) * (1.0f - w);
    float fw, fs;
    vsgl__clip_fade(var, v->coherence, &fw, &fs);
    float e = smoothstep01f((h + fs) / (fw + VSGL__TINY)) * par;
    if (v->lobe == VSGL__LOBE_DIFFUSE) {
        float c = d2 > 0.0f ? clampf(h / sqrtf(d2), 0.0f, 1.0f) : 0.0f;
        float ld = vsgl_sg_cosine_sharpness();
        float rho = vsgl_sg_integral(ld) * VSGL__INV_PI * c * expf(ld * (1.0f - c));
        e *= (1.0f - w) + w * rho;
    }
    return 1.0f - v->coherence * v->coherence * (1.0f - e);
}

/* A lattice cell's cuts along its in-plane axes k (u = axis + 1, v =
 * axis + 2): where its VPLs' extent stops short of its tent's on the low
 * side (side 0, the surface at u > b) and the high side (1, u < b), and
 * each cut's weight: a smoothstep of the shortfall from 0.02 to 0.1
 * spacings, so that the fold comes in continuously (a hard threshold made
 * the preview's glossy pass jitter as a sun moved: light flicker 0.004 ->
 * 0.014 in the thick-walled sun room). Only where the surface ends
 * (vsgl_vsgl.cell_ends): a shadow's edge or a spot's rim moves with the
 * light, and the cut, in texel steps. */
typedef struct cell_cuts {
    float b[2][2], a[2][2]; /* [axis][side]: boundary (m, on the axis), weight */
} cell_cuts;

static int cell_cuts_of(const vsgl_vsgl *v, cell_cuts *c)
{
    const float h = v->cell_h;
    int any = 0;
    memset(c, 0, sizeof *c);
    if (!(h > 0.0f))
        return 0;
    for (int k = 0; k < 2; ++k) {
        const float cc = v->cell_centre[k];
        const float short_by[2] = {(v->cell_lo[k] - (cc - h)) / h, ((cc + h) - v->cell_hi[k]) / h};
        c->b[k][0] = v->cell_lo[k];
        c->b[k][1] = v->cell_hi[k];
        for (int sd = 0; sd < 2; ++sd) {
            if (!(v->cell_ends >> (2 * k + sd) & 1u))
                continue;
            float t = fminf(fmaxf((short_by[sd] - 0.02f) / 0.08f, 0.0f), 1.0f);
            c->a[k][sd] = t * t * (3.0f - 2.0f * t);
            any |= c->a[k][sd] > 0.0f;
        }
    }
    return any;
}

/* How far the fold applies to v, in [0, 1]: a lattice cell on a plane
 * facing its axis (facing x coherence 0.98 -> 0.995, as the near field's
 * cells), cut somewhere; 0 for other clusters (a sphere's cells are cut by
 * its curvature, not by a junction). */
static float fold_weight(const vsgl_vsgl *v, cell_cuts *c)
{
    if (!cell_cuts_of(v, c))
        return 0.0f;
    const float nc[3] = {v->normal.x, v->normal.y, v->normal.z};
    float facing = nc[v->cell_axis] * (v->cell_side ? -1.0f : 1.0f) * v->coherence;
    float w = fminf(fmaxf((facing - 0.98f) / 0.015f, 0.0f), 1.0f);
    return w * w * (3.0f - 2.0f * w);
}

/* Along in-plane axis k of a cut cell whose VPLs' mean is m0 there: the
 * mean its images are built on. A cut tent's mean lies inside the cut
 * (h / 3 from it for a tent cut at its centre), so a Gaussian at that
 * mean, mirrored across the cut, is spread thin at the very end: a floor beside a wall read the
 * wall's foot 12-22 % dark (tests/c/test_planar_fold.c). Built on the
 * tent's centre instead, the folded Gaussian is the whole tent's, as if
 * the surface went on. Blended in by the axis's larger cut weight, and
 * out where the cell is not uniformly lit: there the preview's large
 * cells carried a spot's light on its back wall past the ellipse's edge
 * (the spot room's floor, in the row beside the wall, 16-20 % too bright:
 * relMSE of the combined pass 0.0100 -> 0.0136; 0.0106 with the gate). */
static float fold_mean(const vsgl_vsgl *v, const cell_cuts *c, int k, float m0)
{
    float w = fmaxf(c->a[k][0], c->a[k][1]);
    const float h = v->cell_h, cc = v->cell_centre[k];
    if (!(w > 0.0f) || !(h > 0.0f))
        return m0;
    /* the mean of a uniformly lit tent over the VPLs' extent */
    double mass, unif, var;
    vsgl__tent_moments(fmax(v->cell_lo[k], cc - h), fmin(v->cell_hi[k], cc + h), cc, h, &mass, &unif, &var);
    if (!(mass > 1e-6 * h))
        return m0;
    /* uniform radiosity only, as the near field's steps: a spot's edge or
     * a shadow crossing the cell moves its VPLs' mean off a uniformly lit
     * cut tent's, and the whole tent would then carry its light into the
     * dark */
    float off = fabsf(m0 - (float)unif) / h;
    w *= 1.0f - smoothstep01f((off - VSGL__NEAR_UNIFORM) / (2.0f * VSGL__NEAR_UNIFORM));
    return m0 + w * (cc - (float)unif);
}

/* The cell's in-plane axes u = axis + 1, v = axis + 2 (mod 3). */
static void cell_axes(const vsgl_vsgl *v, v3 *u1, v3 *u2)
{
    const uint32_t a = v->cell_axis;
    *u1 = v3_make(a == 2, a == 0, a == 1);
    *u2 = v3_make(a == 1, a == 2, a == 0);
}

/* Along one axis with cuts lo, hi (weights al, ah): image img's mean (0:
 * the cluster's m0, 1: mirrored across lo, 2: across hi) and its weight,
 * its footprint-blurred density's share on the surface's side of each cut
 * (the product of the cluster's Gaussian, variance var, and the
 * footprint's about y, variance f2, is a Gaussian of mean (m f2 + y var) /
 * (var + f2) and variance var f2 / (var + f2)). */
static float fold_image(float m0, float lo, float hi, float al, float ah, int img, float y, float var, float f2,
                        float *m)
{
    *m = img == 0 ? m0 : 2.0f * (img == 1 ? lo : hi) - m0;
    f2 = fmaxf(f2, 1e-12f * var);
    float i1 = 1.0f / (var + f2), mp = (*m * f2 + y * var) * i1, isp = 1.0f / sqrtf(var * f2 * i1);
    float tl = vsgl__normal_cdf((mp - lo) * isp), th = vsgl__normal_cdf((hi - mp) * isp);
    float wl = 1.0f - al + al * tl, wh = 1.0f - ah + ah * th;
    return img == 0 ? wl * wh : img == 1 ? al * tl * wh : ah * th * wl;
}

/* The receiver's horizon in the planar model where its lobe grazes it or
 * the cluster's mean lies behind it (kernel.h, VSGL__HORIZON_*,
 * vsgl__behind_ramp): the share of the product of the cluster's
 * Gaussian and the footprint's (S = var I + footprint; mean var S^-1 d
 * from the cluster's, covariance var I - var^2 S^-1) above the receiver's
 * tangent plane, n_r . (y - x) > 0, taken along nu, the normal's part in
 * the cluster's plane (u1, u2). */
static float planar_horizon(const vsgl_vsgl *v, v3 x, v3 nr, vsgl_vec3 z, float var, float d1, float d2, float s11,
                            float s22, float s12, float det, v3 u1, v3 u2)
{
    float gw = smoothstep01f(fmaxf(vsgl__graze_ramp(nr.x * z.x + nr.y * z.y + nr.z * z.z),
                                   vsgl__behind_ramp(v3_dot(nr, v3_sub(v->mean, x)) / sqrtf(fmaxf(var, VSGL__TINY)))));
    if (!(gw > 0.0f))
        return 1.0f;
    float nu1 = v3_dot(nr, u1), nu2 = v3_dot(nr, u2);
    float g0 = v3_dot(nr, v3_sub(v->mean, x)) + var * (nu1 * (s22 * d1 - s12 * d2) + nu2 * (s11 * d2 - s12 * d1)) / det;
    float gv = var * (nu1 * nu1 + nu2 * nu2 - var * (s22 * nu1 * nu1 - 2.0f * s12 * nu1 * nu2 + s11 * nu2 * nu2) / det);
    gv = fmaxf(gv, 1e-12f * var);
    float above = 0.5f * erfcf(-g0 / sqrtf(2.0f * gv));
    return 1.0f - (1.0f - above) * gw;
}

/* A lane's part of the horizon tilt (kernel.h, vsgl__planar_tilt) against
 * the plane of table dir (an axis and side) for the lobe of frame (X, Y,
 * Z) and sharpnesses lam, mu: Phi and D; 1 and 0 where the lane needs
 * none. The kernel's block tables and the scalar form both take it from
 * here. */
static float tilt_lane(vsgl_vec3 X, vsgl_vec3 Y, vsgl_vec3 Z, float lam, float mu, int dir, float *D)
{
    const int k = dir >> 1;
    const float sg = dir & 1 ? -1.0f : 1.0f;
    const float nz = sg * (k == 0 ? Z.x : k == 1 ? Z.y : Z.z), nx = sg * (k == 0 ? X.x : k == 1 ? X.y : X.z),
                ny = sg * (k == 0 ? Y.x : k == 1 ? Y.y : Y.z);
    lam = fmaxf(lam, 0.01f);
    mu = fmaxf(mu, 0.01f);
    *D = 0.0f;
    if (!vsgl__planar_tilt_needed(nz, nx, ny, lam, mu))
        return 1.0f;
    float sigma;
    const float a = vsgl__planar_tilt_a(nz, nx, ny, lam, mu, &sigma);
    return vsgl__planar_tilt_pre(a, sigma, expf(-0.5f * a * a), D);
}

/* The block's tilt tables (vsgl_kernel_block.tphi, td) for its glossy
 * lanes and the planes of `dirs` (bit d: some VSGL faces axis plane d); no
 * other row is read (tany 0). */
static void tilt_table(vsgl_kernel_block *b, unsigned dirs)
{
    for (int d = 0; d < VSGL__TILT_DIRS; ++d) {
        b->tany[d] = 0;
        if (!(dirs >> d & 1u))
            continue;
        for (size_t i = 0; i < VSGL__KERNEL_BLOCK; ++i) {
            const vsgl_vec3 X = {b->Xx[i], b->Xy[i], b->Xz[i]}, Y = {b->Yx[i], b->Yy[i], b->Yz[i]},
                            Z = {b->Zx[i], b->Zy[i], b->Zz[i]};
            b->tphi[d][i] = 1.0f;
            b->td[d][i] = 0.0f;
            if (b->camp[i] > 0.0f)
                b->tphi[d][i] = tilt_lane(X, Y, Z, b->lam[i], b->mu[i], d, &b->td[d][i]);
            b->tany[d] |= b->td[d][i] > 0.0f;
        }
    }
}

static float planar_glossy(const vsgl_vsgl *v, v3 x, v3 nr, const vsgl_asg *lobe, const vsgl_asg *whole,
                           const receiver *rs);

float vsgl__planar_glossy(const vsgl_vsgl *v, v3 x, v3 nr, const vsgl_asg *lobe)
{
    return planar_glossy(v, x, nr, lobe, lobe, NULL);
}

float vsgl__planar_glossy_part(const vsgl_vsgl *v, v3 x, v3 nr, const vsgl_asg *lobe, const vsgl_asg *whole)
{
    return planar_glossy(v, x, nr, lobe, whole, NULL);
}

/* rs: NULL, or the receiver whose smooth-factor ratio (kernel.h,
 * vsgl__smooth_ratio; its constants rs->sm) is taken towards the
 * product's mean, as the kernel's k_planar_lobe */
static float planar_glossy(const vsgl_vsgl *v, v3 x, v3 nr, const vsgl_asg *lobe, const vsgl_asg *whole,
                           const receiver *rs)
{
    v3 n = v->normal;
    float h = v3_dot(n, v3_sub(x, v->mean));
    if (!(h > 0.0f) || !(lobe->log_amplitude > -INFINITY))
        return 0.0f;
    /* the share of the whole lobe that meets the plane, its axis tilted
     * towards it by where that share centres (kernel.h, vsgl__planar_tilt;
     * the kernel's from the block's table, tilt_table) */
    float var = v->variance + v->widen, share = 1.0f;
    v3 z = v3_make(lobe->z.x, lobe->z.y, lobe->z.z);
    const int dir = vsgl__planar_tilt_dir(n.x, n.y, n.z);
    if (dir >= 0 && v->lobe == VSGL__LOBE_DIFFUSE) {
        float D, tp, tq;
        const float Phi = tilt_lane(whole->x, whole->y, whole->z, whole->lambda, whole->mu, dir, &D);
        const float w = vsgl__planar_tilt_weight(v->coherence) * vsgl__planar_tilt_gate(h / sqrtf(fmaxf(var, VSGL__TINY)));
        share = vsgl__planar_tilt(v3_dot(n, z), Phi, D, w, &tp, &tq);
        z = v3_sub(v3_scale(z, tp), v3_scale(n, tq));
    }
    float nz = v3_dot(n, z);
    if (!(nz < -1e-6f))
        return 0.0f;
    /* within 0.6 degrees of the plane nothing, faded in up to 2.9 (kernel.h VSGL__PLANAR_NZ_*) */
    const float fade = vsgl__planar_nz_weight(nz) * share;
    if (!(fade > 0.0f))
        return 0.0f;
    float t = h / -nz;
    v3 y0 = v3_add(x, v3_scale(z, t));
    v3 dlt = v3_sub(y0, v->mean);
    v3 ex = v3_scale(v3_sub(lobe->x, v3_scale(z, v3_dot(n, lobe->x) / nz)), t);
    v3 ey = v3_scale(v3_sub(lobe->y, v3_scale(z, v3_dot(n, lobe->y) / nz)), t);
    v3 u1, u2;
    cell_cuts cuts;
    float wf = fold_weight(v, &cuts);
    if (wf > 0.0f)
        cell_axes(v, &u1, &u2);
    else
        v3_basis(n, &u1, &u2);
    float lam = fmaxf(lobe->lambda, 0.01f), mu = fmaxf(lobe->mu, 0.01f);
    float a1 = v3_dot(ex, u1), a2 = v3_dot(ex, u2), b1 = v3_dot(ey, u1), b2 = v3_dot(ey, u2);
    float d1 = v3_dot(dlt, u1), d2 = v3_dot(dlt, u2);
    float il = 0.5f / lam, im = 0.5f / mu;
    float s11 = var + a1 * a1 * il + b1 * b1 * im;
    float s22 = var + a2 * a2 * il + b2 * b2 * im;
    float s12 = a1 * a2 * il + b1 * b2 * im;
    float cr = a1 * b2 - a2 * b1; /* det = var^2 + var tr(A) + det(A): no cancellation */
    float det = var * (var + (a1 * a1 + a2 * a2) * il + (b1 * b1 + b2 * b2) * im) + cr * cr * il * im;
    if (!(det > 0.0f))
        return 0.0f;
    /* the footprint at the distance where the lobe meets the cluster
     * (kernel.h, vsgl__planar_reach): ym - mean = var S^-1 d, e = ym - y0 */
    float reach;
    {
        const float e1 = var * (s22 * d1 - s12 * d2) / det - d1, e2 = var * (s11 * d2 - s12 * d1) / det - d2;
        const float k2 = vsgl__planar_reach(t, e1, e2, v3_dot(z, u1), v3_dot(z, u2), var, &reach);
        const float f11 = s11 - var, f22 = s22 - var;
        s11 = var + k2 * f11;
        s22 = var + k2 * f22;
        s12 *= k2;
        det = var * (var + k2 * (f11 + f22)) + k2 * k2 * cr * cr * il * im;
        if (!(det > 0.0f) || !(reach > 0.0f))
            return 0.0f;
    }
    /* lobe amplitude x its integral pi / sqrt(lam mu) x the radiance density N / pi */
    float scale = reach * expf(lobe->log_amplitude) / (VSGL__2PI * sqrtf(fmaxf(det * lam * mu, VSGL__TINY)));
    scale *= planar_horizon(v, x, nr, lobe->z, var, d1, d2, s11, s22, s12, det, u1, u2) * fade;
    if (rs) { /* towards the product's mean, mean + var S^-1 d */
        const v3 ym = v3_add(v3_sub(v->mean, x), v3_add(v3_scale(u1, var * (s22 * d1 - s12 * d2) / det),
                                                        v3_scale(u2, var * (s11 * d2 - s12 * d1) / det)));
        const float iy = 1.0f / sqrtf(v3_dot(ym, ym) + 1e-30f);
        scale *= vsgl__smooth_ratio_of(&rs->sm, rs->fres, v3_dot(nr, ym) * iy, v3_dot(rs->o, ym) * iy);
    }
    float q0 = fmaxf((s22 * d1 * d1 - 2.0f * s12 * d1 * d2 + s11 * d2 * d2) / det, 0.0f);
    if (!(wf > 0.0f))
        return scale * expf(-0.5f * q0);
    /* a cell cut by its surface's end: its Gaussian's part beyond each cut
     * folded back (an image mean mirrored across it), every image's
     * footprint-blurred density kept to the surface's side */
    float mm[2] = {v3_dot(v->mean, u1), v3_dot(v->mean, u2)}, y0u[2] = {v3_dot(y0, u1), v3_dot(y0, u2)};
    mm[0] = fold_mean(v, &cuts, 0, mm[0]);
    mm[1] = fold_mean(v, &cuts, 1, mm[1]);
    float sum = 0.0f;
    for (int i1 = 0; i1 < 3; ++i1) {
        if (i1 && !(cuts.a[0][i1 - 1] > 0.0f))
            continue;
        float m1, w1 = fold_image(mm[0], cuts.b[0][0], cuts.b[0][1], cuts.a[0][0], cuts.a[0][1], i1, y0u[0], var,
                                  s11 - var, &m1);
        for (int i2 = 0; i2 < 3; ++i2) {
            if (i2 && !(cuts.a[1][i2 - 1] > 0.0f))
                continue;
            float m2, w2 = fold_image(mm[1], cuts.b[1][0], cuts.b[1][1], cuts.a[1][0], cuts.a[1][1], i2, y0u[1],
                                      var, s22 - var, &m2);
            float e1 = y0u[0] - m1, e2 = y0u[1] - m2;
            float q = fmaxf((s22 * e1 * e1 - 2.0f * s12 * e1 * e2 + s11 * e2 * e2) / det, 0.0f);
            sum += w1 * w2 * expf(-0.5f * q);
        }
    }
    return scale * ((1.0f - wf) * expf(-0.5f * q0) + wf * sum);
}

/* The BRDF parameters of G-buffer sample i: its material's, from the
 * job's table where no sample has inputs of its own (untextured scenes),
 * the same function of the same inputs either way. */
static void sample_params(const shade_job *j, size_t i, vsgl_brdf_params *bp)
{
    if (j->params) {
        *bp = j->params[j->g->material[i]];
        return;
    }
    vsgl_material m;
    vsgl__gbuffer_material(j->g, j->materials, i, &m);
    vsgl__material_params(&m, bp);
}

/* A sample that stands for normals of mean resultant length R < 1 (an
 * edge slot on a curved surface, gbuffer.h spread): its GGX lobe convolved
 * with their spread, as filtered glossy lighting does. As SGs, GGX of alpha
 * is about sharpness 2 / alpha^2, and normals of resultant length R are
 * about a vMF of sharpness 1 / (1 - R); sharpnesses of a convolution add
 * as reciprocals: alpha'^2 = alpha^2 + 2 (1 - R). A glossy sphere's rim,
 * whose reflection turns across a pixel, is otherwise shaded at one normal
 * per surface, and that normal's sharp reflection changes from frame to
 * frame as the camera moves: the sphere room's camera Gloss jitter (80 x
 * 60, balanced) 0.0359 -> 0.0307 (0.0285 shading 8 x 8 samples), its
 * frame-to-frame change 0.0499 -> 0.0447 (Cycles' own 0.0396); its still's
 * Gloss structured error 0.00034 -> 0.00036. (4 (1 - R) gave 0.0285 /
 * 0.0417 and 0.00039.) */
static void widen_by_spread(vsgl_brdf_params *bp, float R)
{
    const float k = 2.0f * (1.0f - R);
    float ax = sqrtf(bp->alpha_x * bp->alpha_x + k), ay = sqrtf(bp->alpha_y * bp->alpha_y + k);
    bp->alpha_x = ax < 1.0f ? ax : 1.0f;
    bp->alpha_y = ay < 1.0f ? ay : 1.0f;
}

/* GGX as two lobes, core and tail (kernel.h): ASG2 and the hybrid's VSGL term. */
static int two_lobes(int32_t mode)
{
    return mode == VSGL_GLOSSY_ASG2 || mode == VSGL_GLOSSY_HYBRID;
}

/* Receiver of G-buffer sample i up to its glossy ASG lobe; nm: NULL, or
 * the unit normal to take instead of the sample's (a merged group's mean,
 * vsgl__shade_list). Returns 1 where that lobe is still to be made (the
 * glossy ASG modes): the receiver's warp inputs are then lane `lane` of
 * w, and *bscale, *bamp its broad-lobe factors (setup_receiver_lobe). */
static int setup_receiver_base(const shade_job *j, size_t i, receiver *r, const v3 *nm, vsgl_warp_lanes *w,
                               size_t lane, float *bscale, float *bamp)
{
    const vsgl_gbuffer *g = j->g;
    r->x = v3_make(g->pos[0][i], g->pos[1][i], g->pos[2][i]);
    r->n = nm ? *nm : v3_make(g->nrm[0][i], g->nrm[1][i], g->nrm[2][i]);
    r->o = v3_make(g->view[0][i], g->view[1][i], g->view[2][i]);
    r->lift = g->lift[0] ? v3_make(g->lift[0][i], g->lift[1][i], g->lift[2][i]) : v3_make(0.0f, 0.0f, 0.0f);
    r->key = vsgl__ray_key(i, g->width, g->spp, g->aa);
    r->part = g->part ? g->part[i] : VSGL__PART_NONE;
    sample_params(j, i, &r->bp);
    if (g->spread && g->spread[i] < 1.0f)
        widen_by_spread(&r->bp, g->spread[i]);
    r->alpha = sqrtf(r->bp.alpha_x * r->bp.alpha_y);
    r->glossy = r->bp.glossy && v3_dot(r->n, r->o) > 0.0f;
    r->fres[0] = 0.0f;
    r->fres[1] = 1.0f;
    r->fres[2] = 0.0f;
    r->fh = 0.0f;
    if (!r->glossy)
        return 0;
    vsgl__ms_scale3(&r->bp, v3_dot(r->n, r->o), r->ms);
    if (j->s->glossy_mode == VSGL_GLOSSY_SG) {
        vsgl_sg ndf;
        vsgl_ndf_to_sg(&r->n, r->alpha, VSGL_NDF_GGX, &ndf);
        vsgl_warp_ndf_sg(&ndf, &r->o, &r->sg);
        r->sm = vsgl__shadow_lane(r->alpha, v3_dot(r->n, r->o), v3_dot(r->n, r->sg.axis), 0);
        return 0;
    }
    /* (with a normal nm the tangent is not orthogonal to it: the warp
     * makes it so, math/warp_lanes.c) */
    vsgl__warp_lane_set(w, lane, r->n, v3_make(g->tan[0][i], g->tan[1][i], g->tan[2][i]), r->o, r->bp.alpha_x,
                        r->bp.alpha_y);
    /* a rough lobe widened and scaled to be closest to GGX's (math/broad_lobe.h) */
    vsgl__broad_lobe(r->alpha, (r->bp.f0[0] + r->bp.f0[1] + r->bp.f0[2]) * (1.0f / 3.0f), v3_dot(r->n, r->o),
                     two_lobes(j->s->glossy_mode), bscale, bamp);
    return 1;
}

/* The rest of a glossy ASG receiver's set-up, its warped NDF in lane k
 * of w (vsgl__receiver_asg's steps, a block's receivers warped at once). */
static void setup_receiver_lobe(const shade_job *j, receiver *r, const vsgl_warp_lanes *w, size_t k, float bscale,
                                float bamp)
{
    vsgl__warp_lane_get(w, k, &r->asg);
    vsgl__receiver_asg_finish(r->n, r->o, bscale, bamp, &r->asg);
    /* the Fresnel shape at the axis, once for the ratio and fill_lane's specular factor */
    r->fh = v3_dot(r->n, r->asg.z) > 0.0f ? vsgl__fresnel_shape_at(&r->bp, r->o, r->asg.z) : 0.0f;
    vsgl__fresnel_ratio_fh(&r->bp, r->n, r->o, r->asg.z, r->fh, r->fres);
    /* the scalar reference path's (glossy_light); the kernel's lanes
     * take the same constants per block (run_block, shadow4.c) */
    if (j->path == VSGL__SHADE_REFERENCE)
        r->sm = vsgl__shadow_lane(r->alpha, v3_dot(r->n, r->o), v3_dot(r->n, r->asg.z),
                                  two_lobes(j->s->glossy_mode));
}

/* Receiver of G-buffer sample i, alone (nm as setup_receiver_base). */
static void setup_receiver_n(const shade_job *j, size_t i, receiver *r, const v3 *nm)
{
    vsgl_warp_lanes w;
    float bscale, bamp;
    if (!setup_receiver_base(j, i, r, nm, &w, 0, &bscale, &bamp))
        return;
    vsgl__warp_lanes(&w, 1);
    setup_receiver_lobe(j, r, &w, 0, bscale, bamp);
}

static void setup_receiver(const shade_job *j, size_t i, receiver *r)
{
    setup_receiver_n(j, i, r, NULL);
}

/* No visibility ray where a VSGL cannot light the receiver
 * (visibility_rays): its clip at least this, the receiver below this
 * fraction of the behind fade. */
#define VSGL__VIS_SKIP_CLIP 0.999f
#define VSGL__VIS_SKIP_BEHIND 1e-3f

/* The cell (a fraction of the scene's extent) of a cluster's centre that
 * seeds its points and its receivers' picks (ray_targets.h). A seed from
 * the exact centre changes with every step of a moving light and
 * reshuffles every penumbra's dither: the glossy-sphere room's light
 * flicker (320 x 240, 1/1000 of the extent a frame) went 0.0056 -> 0.0089
 * (Diff) with it, 0.0061 with 1/32 of the extent, unchanged with 1/16. */
#define VSGL__RAY_SEED_CELL (1.0f / 16.0f)

/* 1 if VSGLs a and b (kernel lights ka, kb) get the same visibility rays at
 * every receiver: the same ray target and the same skip test
 * (visibility_rays). The lattice's glossy clusters split into a core and a
 * tail (fit/lattice.c) are such pairs: a quarter of the sun rooms' VSGLs. */
static int same_rays(const vsgl_vsgl *a, const vsgl_kernel_light *ka, const vsgl_vsgl *b,
                     const vsgl_kernel_light *kb)
{
    return a->mean.x == b->mean.x && a->mean.y == b->mean.y && a->mean.z == b->mean.z &&
           a->normal.x == b->normal.x && a->normal.y == b->normal.y && a->normal.z == b->normal.z &&
           a->coherence == b->coherence && a->variance == b->variance && ka->clip == kb->clip &&
           ka->ibehind == kb->ibehind && ka->boff == kb->boff && ka->mx == kb->mx && ka->my == kb->my &&
           ka->mz == kb->mz && ka->nx == kb->nx && ka->ny == kb->ny && ka->nz == kb->nz;
}

/* The bits of lanes [0, n). */
static uint64_t lanes_of(size_t n)
{
    return n < 64 ? ((uint64_t)1 << n) - 1 : ~(uint64_t)0;
}

/* Where visibility rays start: receiver k offset along its normal by eps
 * (coordinates by lane; visibility_rays lifts the grazing ones), and the
 * key that picks its point of each cluster (receiver.key). */
typedef struct ray_origins {
    float x[VSGL__KERNEL_BLOCK], y[VSGL__KERNEL_BLOCK], z[VSGL__KERNEL_BLOCK];
    uint32_t key[VSGL__KERNEL_BLOCK];
} ray_origins;

static void origins_of(const shade_job *j, const receiver *rec, size_t n, ray_origins *o)
{
    for (size_t k = 0; k < n; ++k) {
        v3 p = v3_add(rec[k].x, v3_scale(rec[k].n, j->eps));
        o->x[k] = p.x;
        o->y[k] = p.y;
        o->z[k] = p.z;
        o->key[k] = rec[k].key;
    }
}

/* How much of a smooth-shaded receiver's lift (gbuffer.h) a visibility
 * ray takes, by the cosine c of its direction to the receiver's normal:
 * all of it up to VSGL__LIFT_FULL, none from VSGL__LIFT_NONE (as Cycles
 * offsets only its shadow rays near the horizon). A ray near the horizon
 * may leave below the receiver's flat triangle and hit its own mesh (the
 * shadow terminator); a steep one does not, and starting it off the
 * surface would let it pass under an occluder that touches the surface
 * (a low-poly smooth-shaded mesh's lift reaches centimetres). */
#define VSGL__LIFT_FULL 0.25f
#define VSGL__LIFT_NONE 0.5f
static float lift_share(float c)
{
    float a = (VSGL__LIFT_NONE - c) * (1.0f / (VSGL__LIFT_NONE - VSGL__LIFT_FULL));
    return a < 0.0f ? 0.0f : (a > 1.0f ? 1.0f : a);
}

v3 vsgl__lifted_origin(v3 o, v3 x, v3 n, v3 lift, v3 target)
{
    if (lift.x == 0.0f && lift.y == 0.0f && lift.z == 0.0f)
        return o;
    v3 d = v3_sub(target, x);
    float len = v3_length(d);
    return len > 0.0f ? v3_add(o, v3_scale(lift, lift_share(v3_dot(n, d) / len))) : o;
}

/* The origins of lanes idx[0..m), each towards its own target (to),
 * lifted (vsgl__lifted_origin) into *lifted. By the lane's own point of
 * the cluster, not the cluster's centre: a point near the horizon of a
 * receiver that sees the centre steeply took no lift, left the receiver's
 * flat triangle and hit its own mesh. On a smooth sphere's underside
 * above a lit floor, a pixel lost half its light for one frame of a
 * camera animation (320 x 240, balanced: Diff 2.40 -> 1.23 -> 2.41);
 * the preview's camera flicker above a dense render there fell 0.0134 ->
 * 0.0061 (Diff), and at 80 x 60 above Cycles' 0.0116 -> 0.0062. */
static const ray_origins *lift_grazing(const receiver *rec, const ray_origins *org, const uint32_t *idx, uint32_t m,
                                       const ray_origins *to, ray_origins *lifted)
{
    for (uint32_t i = 0; i < m; ++i) {
        uint32_t k = idx[i];
        v3 o = vsgl__lifted_origin(v3_make(org->x[k], org->y[k], org->z[k]), rec[k].x, rec[k].n, rec[k].lift,
                                   v3_make(to->x[k], to->y[k], to->z[k]));
        lifted->x[k] = o.x;
        lifted->y[k] = o.y;
        lifted->z[k] = o.z;
    }
    return lifted;
}

/* Where a receiver at x with normal n aims its visibility ray at a
 * cluster of ray centre c, given its dithered point t of it (ray_targets.h):
 * t, or for a point below the receiver's horizon, where the kernel sees
 * the cluster above it (its ray would enter the receiver's own surface: a
 * sphere's underside and the floor around it, 2 % dark; the kernel's
 * cosine already counts the part of the cluster that sets), its mirror
 * image through the centre, raised to VSGL__RAY_RISE of its distance above
 * the horizon if it is lower. Aimed at the centre where the mirror image
 * set too, below the horizon as well, the ray entered the receiver's own
 * surface and took all the cluster's light: a sphere's rim above the
 * floor behind it lost a quarter of its Gloss until the camera moved the
 * centre above its horizon (the preview at 80 x 60, pixel (45, 31): 0.91
 * -> 1.23 in one frame, where Cycles rises smoothly; camera Gloss above
 * Cycles' motion 0.0236 -> 0.0208, balanced 0.0149 -> 0.0137). */
#define VSGL__RAY_RISE 0.05f
v3 vsgl__ray_aim(v3 x, v3 n, v3 c, v3 t)
{
    if (v3_dot(n, v3_sub(t, x)) > 0.0f)
        return t;
    t = v3_sub(v3_scale(c, 2.0f), t);
    v3 d = v3_sub(t, x);
    float h = v3_dot(n, d), rise = VSGL__RAY_RISE * v3_length(d);
    return h < rise ? v3_add(t, v3_scale(n, rise - h)) : t;
}

/* Visibility of VSGL `item` (set order; each receiver aims at its own
 * point of the cluster, ray `ray` of `rays`, ray_targets.h) from the receivers k <
 * n <= VSGL__KERNEL_BLOCK whose bit is set in `lanes`: one batched
 * occlusion query (an Embree ray stream) of just those, each from the
 * receiver's origin in org. Returns their visible bits (a blocked
 * ray's bit and every lane outside `lanes` are 0). A receiver within eps
 * of its target traces no ray (visible). With L (the VSGL's kernel light;
 * NULL: every lane traced), no ray for a receiver the VSGL cannot light:
 * behind or within 1e-3 of the behind fade of its plane (VSGL__CLIP_BEHIND
 * sigma) with its emitter clip at >= 0.999 (its light there is at most
 * 0.1 % of the unclipped lobe's: a floor's clusters and the floor's own
 * receivers, a wall's cluster and the wall beside it); visible. */
_Static_assert(VSGL__KERNEL_BLOCK <= 64, "a block's lanes are kept in 64-bit masks");
static uint64_t visibility_rays(const shade_job *j, size_t item, const vsgl_kernel_light *L, const receiver *rec,
                                const ray_origins *org, size_t n, uint64_t lanes, uint32_t ray, uint32_t rays)
{
    unsigned char blocked[VSGL__KERNEL_BLOCK];
    uint32_t idx[VSGL__KERNEL_BLOCK], m = 0;
    uint64_t visible = 0;
    const int may_skip = L && L->clip >= VSGL__VIS_SKIP_CLIP;
    for (uint64_t rest = lanes & lanes_of(n); rest; rest &= rest - 1) {
        uint32_t k = (uint32_t)__builtin_ctzll(rest);
        if (may_skip) { /* the kernel's h (kernel_impl.h, k_geometry) */
            float h = -((L->mx - rec[k].x.x) * L->nx + (L->my - rec[k].x.y) * L->ny + (L->mz - rec[k].x.z) * L->nz);
            if (h * L->ibehind + L->boff < VSGL__VIS_SKIP_BEHIND) {
                visible |= (uint64_t)1 << k; /* not traced */
                continue;
            }
        }
        idx[m++] = k;
    }
    if (m) {
        ray_origins lifted, to; /* to: each lane's point of the cluster (ray_targets.h) */
        const v3 c = vsgl__ray_centre(&j->set->items[item]);
        for (uint32_t i = 0; i < m; ++i) {
            const receiver *r = &rec[idx[i]];
            const float *p = vsgl__ray_target_for(j->targets, item, org->key[idx[i]], ray, rays);
            v3 t = vsgl__ray_aim(r->x, r->n, c, v3_make(p[0], p[1], p[2]));
            to.x[idx[i]] = t.x;
            to.y[idx[i]] = t.y;
            to.z[idx[i]] = t.z;
        }
        const float *const tgt[3] = {to.x, to.y, to.z};
        /* only scenes with smooth-shaded meshes have a lift to apply */
        const ray_origins *from = j->g->lift[0] ? lift_grazing(rec, org, idx, m, &to, &lifted) : org;
        vsgl__scene_occluded_towards_each(j->scene, m, idx, from->x, from->y, from->z, tgt, j->eps, blocked);
    }
    for (uint32_t i = 0; i < m; ++i)
        visible |= (uint64_t)!blocked[i] << idx[i];
    return visible;
}

/* visibility_rays from one receiver to one VSGL's target (every lane traced). */
static int visible_from(const shade_job *j, const vsgl_vsgl *v, const receiver *r)
{
    ray_origins o;
    origins_of(j, r, 1, &o);
    return (int)(visibility_rays(j, (size_t)(v - j->set->items), NULL, r, &o, 1, 1, 0, 1) & 1u);
}

/* Part q (0 core, 1 tail) of a GGX lobe's ASG (kernel.h, VSGL__KERNEL_GGX_TAIL). */
static vsgl_asg ggx_part(const vsgl_asg *a, int q)
{
    vsgl_asg r = *a;
    float k = q ? VSGL__GGX_TAIL_K : VSGL__GGX_CORE_K, c = q ? VSGL__GGX_TAIL_C : VSGL__GGX_CORE_C;
    r.lambda *= k;
    r.mu *= k;
    r.log_amplitude += logf(c);
    return r;
}

/* The receiver's GGX alpha for the half-vector model (halfvec.h), 0 where
 * it does not apply: anisotropic roughness (the model is isotropic). */
static float hv_alpha(const receiver *r)
{
    float ax = r->bp.alpha_x, ay = r->bp.alpha_y;
    return r->glossy && fabsf(ax - ay) <= 1e-3f * fmaxf(ax, ay) ? r->alpha : 0.0f;
}

/* The receiver's smooth-factor ratio (kernel.h, vsgl__smooth_ratio)
 * towards where its lobe (axis z, sharpness lr) times light of direction p
 * and sharpness lin peaks, lr z + lin p, as the kernel's k_glossy. */
static float shadow_towards(const receiver *r, v3 z, float lr, v3 p, float lin)
{
    v3 q = v3_add(v3_scale(z, lr), v3_scale(p, lin));
    const float il = 1.0f / sqrtf(v3_dot(q, q) + VSGL__TINY);
    return vsgl__smooth_ratio_of(&r->sm, r->fres, v3_dot(r->n, q) * il, v3_dot(r->o, q) * il);
}

/* Glossy integral of the receiver's lobe with the incident SG, and the
 * axis where the smooth factor is evaluated: the receiver's lobe axis
 * (Xu et al. Eq. 30), the same for every VSGL, as in the kernel; times
 * the smooth-factor ratio towards the light (shadow_towards). */
static float glossy_integral(const shade_job *j, const receiver *r, const vsgl_sg *in, v3 *axis, int part)
{
    if (j->s->glossy_mode == VSGL_GLOSSY_SG) {
        *axis = r->sg.axis;
        return vsgl_sg_product_integral(&r->sg, in) *
               shadow_towards(r, r->sg.axis, r->sg.sharpness, in->axis, in->sharpness);
    }
    *axis = r->asg.z;
    vsgl_asg a = two_lobes(j->s->glossy_mode) ? ggx_part(&r->asg, part) : r->asg;
    return vsgl_asg_sg_product_integral(&a, in) * shadow_towards(r, r->asg.z, a.lambda + a.mu, in->axis, in->sharpness);
}

/* The glossy light of VSGL v through the receiver's lobe (each part of it
 * for GGX's core and tail): the SG model, and for a coherent diffuse
 * cluster with the clip the planar model blended in by coherence^2 (less
 * for a receiver on the same bumpy surface: kernel.h vsgl__planar_weight),
 * as the kernel does. */
static float glossy_light(const shade_job *j, const receiver *r, const vsgl_vsgl *v, const vsgl_sg *in, v3 *axis)
{
    int parts = two_lobes(j->s->glossy_mode) ? 2 : 1;
    float sum = 0.0f;
    /* with GGX as lobes, a planar cluster that subtends little through the
     * half-vector model (halfvec.h), the planar one taking the rest */
    float hw = 0.0f, hv = 0.0f;
    /* the planar model (a diffuse cluster, the clip on) and its weight for this receiver (kernel.h
     * vsgl__planar_weight) */
    const int planar = j->leak && v->lobe == VSGL__LOBE_DIFFUSE;
    const float k2 = planar ? vsgl__planar_weight(v->coherence * v->coherence, vsgl__planar_bump(v->coherence),
                                                  v3_dot(r->n, v->normal))
                            : 0.0f;
    if (parts == 2 && planar && v->coherence > 0.0f)
        hv = vsgl__halfvec_glossy(v, r->x, r->n, r->o, r->asg.z, hv_alpha(r), (int)j->s->glossy_lobes, r->fres, &hw);
    for (int q = 0; q < parts; ++q) {
        float gi = glossy_integral(j, r, in, axis, q);
        if (planar) {
            vsgl_asg lobe = r->asg;
            if (j->s->glossy_mode == VSGL_GLOSSY_SG)
                vsgl_sg_to_asg(&r->sg, &lobe);
            const vsgl_asg whole = lobe; /* its spread sets the tilt of every part (the kernel's b->lam, b->mu) */
            if (j->s->glossy_mode != VSGL_GLOSSY_SG && parts == 2)
                lobe = ggx_part(&r->asg, q);
            gi = (1.0f - k2) * gi + k2 * (1.0f - hw) * planar_glossy(v, r->x, r->n, &lobe, &whole, r);
        }
        sum += gi;
    }
    return sum + k2 * hw * hv;
}

static int32_t shade_chunk(void *user, size_t chunk, size_t b, size_t e)
{
    shade_job *j = user;
    const vsgl_gbuffer *g = j->g;
    const vsgl_pixel_planes *pl = j->planes;
    const size_t spp = g->spp;
    uint64_t pairs = 0;
    for (size_t px = j->base + b; px < j->base + e; ++px) {
        float acc_d[3] = {0, 0, 0}, acc_g[3] = {0, 0, 0}, col_d[3] = {0, 0, 0}, col_g[3] = {0, 0, 0};
        float covered = 0.0f;
        for (size_t sidx = 0; sidx < spp; ++sidx) {
            size_t i = px * spp + sidx;
            if (g->material[i] == VSGL__GBUFFER_MISS)
                continue;
            const float w = vsgl__gbuffer_weight(g, i);
            covered += w;
            receiver r;
            setup_receiver(j, i, &r);
            float gcol[3] = {0, 0, 0};
            if (r.glossy)
                vsgl__glossy_color(&r.bp, r.n, r.o, gcol);
            /* Blender 4.x+: the dielectric layer dims the diffuse base seen from o */
            float wd = vsgl__scene_diffuse_weight(j->scene, g->material[i], v3_dot(r.n, r.o));
            for (int c = 0; c < 3; ++c) {
                col_d[c] += w * r.bp.diffuse[c] * wd;
                col_g[c] += w * gcol[c];
            }
            int has_diffuse = r.bp.diffuse[0] + r.bp.diffuse[1] + r.bp.diffuse[2] > 0.0f;
            float ld[3] = {0, 0, 0}, ls[3] = {0, 0, 0};
            for (size_t k = 0; k < j->set->count; ++k) {
                const vsgl_vsgl *v = &j->set->items[k];
                vsgl_sg in;
                ++pairs;
                if (!vsgl__vsgl_incident_sg_with(v, r.x, j->lobe_int[k], &in))
                    continue;
                if (j->leak)
                    in.log_amplitude += logf(fmaxf(vsgl__emitter_clip(v, r.x, r.n, 1) *
                                                   vsgl__vsgl_part_keep(v, r.part), VSGL__TINY));
                if (j->s->visibility == VSGL_VISIBILITY_RAY) {
                    if (!visible_from(j, v, &r))
                        continue;
                }
                if (has_diffuse) {
                    const float e_sg = vsgl_sg_cosine_integral(&in, &r.n, j->s->diffuse_mode) * VSGL__INV_PI;
                    float e_d = e_sg;
                    if (j->near->cell_of && j->near->cell_of[k] >= 0) {
                        float wn, q = vsgl__near_diffuse(&j->near->cells[j->near->cell_of[k]], r.x, r.n, &wn);
                        if (wn > 0.0f)
                            e_d = (1.0f - wn) * e_d + wn * q;
                    }
                    if (r.bp.burley >= 0.0f) {
                        /* Blender 3.x's Burley diffuse as the kernel takes it: the SG's
                         * part at its axis (k_burley), the near field's towards the
                         * cluster's mean (near_correct) */
                        const float near = e_d - e_sg;
                        e_d = e_sg * vsgl__burley_towards(r.bp.burley, r.n, r.o, in.axis);
                        if (near != 0.0f)
                            e_d += near * vsgl__burley_towards(r.bp.burley, r.n, r.o,
                                                               v3_normalize(v3_sub(v->mean, r.x)));
                    }
                    for (int c = 0; c < 3; ++c)
                        ld[c] += v->power[c] * e_d;
                }
                if (r.glossy) {
                    v3 axis;
                    float gi = glossy_light(j, &r, v, &in, &axis);
                    if (gi > 0.0f) {
                        float sf[3];
                        vsgl__specular_factor(&r.bp, r.n, r.o, axis, r.alpha, sf);
                        for (int c = 0; c < 3; ++c)
                            ls[c] += v->power[c] * gi * sf[c] * r.ms[c];
                    }
                }
            }
            for (int c = 0; c < 3; ++c) {
                acc_d[c] += w * r.bp.diffuse[c] * wd * ld[c];
                acc_g[c] += w * ls[c];
            }
        }
        for (int c = 0; c < 3; ++c) {
            pl->diffuse[px * 3 + c] = acc_d[c];
            pl->glossy[px * 3 + c] = acc_g[c];
            pl->diffuse_color[px * 3 + c] = col_d[c];
            pl->glossy_color[px * 3 + c] = col_g[c];
        }
        pl->coverage[px] = covered;
    }
    j->pairs[chunk] = pairs;
    return 0;
}


/* A lane's fields of a convex part key (scene_internal.h; kernel.h vsgl__part_keep). */
static void part_lane(uint32_t key, float *part, float *outer)
{
    *part = key == VSGL__PART_NONE ? -1.0f : (float)(key >> 1);
    *outer = key == VSGL__PART_NONE ? 0.0f : (float)(1u - (key & 1u));
}

/* Lane `k` of a kernel block as a receiver at (x, y, z) with no lobe: finite
 * everywhere, contributes nothing (misses, and the padding of a last block). */
static void clear_lane(vsgl_kernel_block *b, size_t k, float x, float y, float z)
{
    b->x[k] = x; b->y[k] = y; b->z[k] = z;
    b->nx[k] = b->ny[k] = 0.0f;
    b->nz[k] = 1.0f;
    b->ox[k] = b->oy[k] = 0.0f;
    b->oz[k] = 1.0f;
    b->diffuse[k] = 0.0f;
    b->burley[k] = -1.0f;
    b->part[k] = -1.0f;
    b->pouter[k] = 0.0f;
    b->Xx[k] = 1.0f; b->Xy[k] = b->Xz[k] = 0.0f;
    b->Yy[k] = 1.0f; b->Yx[k] = b->Yz[k] = 0.0f;
    b->Zz[k] = 1.0f; b->Zx[k] = b->Zy[k] = 0.0f;
    b->lam[k] = b->mu[k] = b->camp[k] = b->alpha[k] = 0.0f;
    b->f0r[k] = b->f0g[k] = b->f0b[k] = 0.0f;
    b->fe[k] = 0.0f;
    b->fa[k] = 1.0f;
    b->fb[k] = 0.0f;
    vsgl__kernel_set_smooth(b, k, (vsgl_smooth_lane){0.0f, 0.0f, 0.0f, 0.0f, 0.0f});
}

/* Lane `k` of a kernel block from receiver r (set up). */
static void put_lane(const shade_job *j, vsgl_kernel_block *b, size_t k, const receiver *r)
{
    b->x[k] = r->x.x; b->y[k] = r->x.y; b->z[k] = r->x.z;
    b->nx[k] = r->n.x; b->ny[k] = r->n.y; b->nz[k] = r->n.z;
    b->ox[k] = r->o.x; b->oy[k] = r->o.y; b->oz[k] = r->o.z;
    part_lane(r->part, &b->part[k], &b->pouter[k]);
    b->diffuse[k] = r->bp.diffuse[0] + r->bp.diffuse[1] + r->bp.diffuse[2] > 0.0f ? 1.0f : 0.0f;
    b->burley[k] = b->diffuse[k] > 0.0f ? r->bp.burley : -1.0f; /* Blender 3.x's Burley diffuse, per pair */
    /* VSGL_GLOSSY_MRP replaces the glossy plane (mrp/pass.c): the kernel
     * skips the glossy lobe of lanes with camp 0 */
    if (r->glossy && j->s->glossy_mode != VSGL_GLOSSY_MRP) {
        b->Xx[k] = r->asg.x.x; b->Xy[k] = r->asg.x.y; b->Xz[k] = r->asg.x.z;
        b->Yx[k] = r->asg.y.x; b->Yy[k] = r->asg.y.y; b->Yz[k] = r->asg.y.z;
        b->Zx[k] = r->asg.z.x; b->Zy[k] = r->asg.z.y; b->Zz[k] = r->asg.z.z;
        b->lam[k] = r->asg.lambda;
        b->mu[k] = r->asg.mu;
        b->camp[k] = expf(r->asg.log_amplitude);
        /* the half-vector model's alpha; negative (its magnitude for the
         * shadowing ratio, shadow_lane) where that model does not apply */
        b->alpha[k] = hv_alpha(r) > 0.0f ? hv_alpha(r) : -r->alpha;
    } else {
        b->Xx[k] = 1.0f; b->Xy[k] = b->Xz[k] = 0.0f;
        b->Yy[k] = 1.0f; b->Yx[k] = b->Yz[k] = 0.0f;
        b->Zz[k] = 1.0f; b->Zx[k] = b->Zy[k] = 0.0f;
        b->lam[k] = b->mu[k] = b->camp[k] = b->alpha[k] = 0.0f;
    }
    float m[3] = {0.0f, 0.0f, 0.0f};
    if (r->glossy && j->s->glossy_mode != VSGL_GLOSSY_MRP) {
        vsgl__specular_factor_fh(&r->bp, r->n, r->o, r->asg.z, r->alpha, r->fh, m);
        for (int c = 0; c < 3; ++c)
            m[c] *= r->ms[c];
    }
    b->f0r[k] = m[0];
    b->f0g[k] = m[1];
    b->f0b[k] = m[2];
    b->fe[k] = r->fres[0];
    b->fa[k] = r->fres[1];
    b->fb[k] = r->fres[2];
}

/* Fill lane `k` of a kernel block from G-buffer sample i (nm: NULL, or the
 * normal to take instead of its own, setup_receiver_n); returns 0 for a
 * miss. */
static int fill_lane_n(const shade_job *j, size_t i, vsgl_kernel_block *b, size_t k, receiver *r, const v3 *nm)
{
    if (j->g->material[i] == VSGL__GBUFFER_MISS) {
        memset(r, 0, sizeof *r);
        r->part = VSGL__PART_NONE;
        clear_lane(b, k, 0.0f, 0.0f, 0.0f);
        return 0;
    }
    setup_receiver_n(j, i, r, nm);
    put_lane(j, b, k, r);
    return 1; /* its shadowing constants: run_block, for the whole block (shadow4.c) */
}

static int fill_lane(const shade_job *j, size_t i, vsgl_kernel_block *b, size_t k, receiver *r)
{
    return fill_lane_n(j, i, b, k, r, NULL);
}

/* Sample merging: within a pixel, a sample on the same surface as an
 * earlier one (same material, normals within ~5 degrees, no step along the
 * normal, not a sharp glossy material) takes the light shaded at the
 * group's centroid instead of being shaded again; its own colours still
 * weight it. Indirect light barely changes across a pixel,
 * so with aa x aa samples this shades about one sample per pixel except at
 * edges. */
#define MERGE_COS 0.996f
/* floats per merged group (vsgl__shade_list): position sum, count, members
 * whose normal is not the first's, normal sum */
#define VSGL__CENTROID 8

static int same_surface(const vsgl_gbuffer *g, const vsgl_material *materials, size_t a, size_t b, float plane_tol)
{
    if (g->material[a] != g->material[b] || g->material[a] == VSGL__GBUFFER_MISS)
        return 0;
    /* glossy reflections change across a pixel with the view: only rough
     * (alpha >= 0.25, roughness >= 0.5) or non-glossy surfaces merge */
    vsgl_brdf_params bp;
    vsgl__material_params(&materials[g->material[a]], &bp);
    if (bp.glossy && bp.alpha_x * bp.alpha_y < 0.0625f)
        return 0;
    v3 na = v3_make(g->nrm[0][a], g->nrm[1][a], g->nrm[2][a]);
    v3 nb = v3_make(g->nrm[0][b], g->nrm[1][b], g->nrm[2][b]);
    if (v3_dot(na, nb) < MERGE_COS)
        return 0;
    v3 d = v3_make(g->pos[0][b] - g->pos[0][a], g->pos[1][b] - g->pos[1][a], g->pos[2][b] - g->pos[2][a]);
    return fabsf(v3_dot(d, na)) <= plane_tol;
}

/* A kernel lane's receiver fields (vsgl_kernel_block without the
 * accumulators) and its receiver's lift and key, as a shading plan keeps
 * them (shade_job.h). */
static void lane_get(const vsgl_kernel_block *b, size_t k, const receiver *r, vsgl__plan_lane *o)
{
    o->lift[0] = r->lift.x;
    o->lift[1] = r->lift.y;
    o->lift[2] = r->lift.z;
    o->key = r->key;
    o->part = r->part;
    float *v = o->v;
    *v++ = b->x[k]; *v++ = b->y[k]; *v++ = b->z[k];
    *v++ = b->nx[k]; *v++ = b->ny[k]; *v++ = b->nz[k];
    *v++ = b->ox[k]; *v++ = b->oy[k]; *v++ = b->oz[k];
    *v++ = b->diffuse[k];
    *v++ = b->burley[k];
    *v++ = b->Xx[k]; *v++ = b->Xy[k]; *v++ = b->Xz[k];
    *v++ = b->Yx[k]; *v++ = b->Yy[k]; *v++ = b->Yz[k];
    *v++ = b->Zx[k]; *v++ = b->Zy[k]; *v++ = b->Zz[k];
    *v++ = b->lam[k]; *v++ = b->mu[k]; *v++ = b->camp[k]; *v++ = b->alpha[k];
    *v++ = b->f0r[k]; *v++ = b->f0g[k]; *v++ = b->f0b[k];
    *v++ = b->fe[k]; *v++ = b->fa[k]; *v = b->fb[k];
}

/* The inverse, and the receiver fields visibility rays read (position,
 * normal, lift, key; a replay has no G-buffer sample to read them from). */
static void lane_put(vsgl_kernel_block *b, size_t k, const vsgl__plan_lane *o, receiver *r)
{
    r->x = v3_make(o->v[0], o->v[1], o->v[2]);
    r->n = v3_make(o->v[3], o->v[4], o->v[5]);
    r->lift = v3_make(o->lift[0], o->lift[1], o->lift[2]);
    r->key = o->key;
    r->part = o->part;
    const float *v = o->v;
    b->x[k] = *v++; b->y[k] = *v++; b->z[k] = *v++;
    b->nx[k] = *v++; b->ny[k] = *v++; b->nz[k] = *v++;
    b->ox[k] = *v++; b->oy[k] = *v++; b->oz[k] = *v++;
    b->diffuse[k] = *v++;
    b->burley[k] = *v++;
    b->Xx[k] = *v++; b->Xy[k] = *v++; b->Xz[k] = *v++;
    b->Yx[k] = *v++; b->Yy[k] = *v++; b->Yz[k] = *v++;
    b->Zx[k] = *v++; b->Zy[k] = *v++; b->Zz[k] = *v++;
    b->lam[k] = *v++; b->mu[k] = *v++; b->camp[k] = *v++; b->alpha[k] = *v++;
    b->f0r[k] = *v++; b->f0g[k] = *v++; b->f0b[k] = *v++;
    b->fe[k] = *v++; b->fa[k] = *v++; b->fb[k] = *v;
    part_lane(o->part, &b->part[k], &b->pouter[k]);
}

/* The far-field diffuse light per watt of VSGL v at (x, n), as the kernel
 * computes it: the incident SG, the emitter clip, the cosine integral. */
static float far_diffuse(const shade_job *j, const vsgl_vsgl *v, float lobe_integral, v3 x, v3 n)
{
    vsgl_sg in;
    if (!vsgl__vsgl_incident_sg_with(v, x, lobe_integral, &in))
        return 0.0f;
    if (j->leak)
        in.log_amplitude += logf(fmaxf(vsgl__emitter_clip(v, x, n, 1), VSGL__TINY));
    return vsgl_sg_cosine_integral(&in, &n, j->s->diffuse_mode) * VSGL__INV_PI;
}

/* The near field of the lattice clusters around receiver r (near_field.h):
 * within it the kernel's far-field term gives way to the cell's form
 * factor. ld: the kernel's diffuse light, corrected in place. burley, o:
 * the lane's Burley roughness (< 0: Lambert) and view (a replay's receiver
 * has only the lane's fields). */
static void near_correct(const shade_job *j, const receiver *r, float burley, v3 o, float *ld0, float *ld1,
                         float *ld2)
{
    size_t n;
    const uint32_t *c = vsgl__near_candidates(j->near, r->x, &n);
    float d[3] = {0.0f, 0.0f, 0.0f};
    for (size_t i = 0; i < n; ++i) {
        const vsgl_near_cell *cell = &j->near->cells[c[i]];
        float w;
        float q = vsgl__near_diffuse(cell, r->x, r->n, &w);
        if (!(w > 0.0f))
            continue;
        const vsgl_vsgl *v = &j->set->items[cell->vsgl];
        /* the kernel's far field took the part's share (vsgl__part_keep): so does the near field */
        float e = w * (q - far_diffuse(j, v, j->lobe_int[cell->vsgl], r->x, r->n)) *
                  (j->leak ? vsgl__vsgl_part_keep(v, r->part) : 1.0f);
        if (e == 0.0f)
            continue;
        if (burley >= 0.0f) /* Blender 3.x's Burley diffuse towards the cluster, as the kernel's */
            e *= vsgl__burley_towards(burley, r->n, o, v3_normalize(v3_sub(v->mean, r->x)));
        if (j->s->visibility == VSGL_VISIBILITY_RAY) {
            if (!visible_from(j, v, r))
                e = 0.0f;
        }
        for (int k = 0; k < 3; ++k)
            d[k] += v->power[k] * e;
    }
    *ld0 = fmaxf(*ld0 + d[0], 0.0f);
    *ld1 = fmaxf(*ld1 + d[1], 0.0f);
    *ld2 = fmaxf(*ld2 + d[2], 0.0f);
}


/* A receiver's dominant pairs (vsgl_render_settings.dominant_rays): from
 * half of VSGL_DOMINANT_SHARE of its light up, a pair's visibility is
 * (1 - t) x its first ray's + t x the mean of all its rays, t rising
 * linearly to 1 at the share: a pair whose weight crosses the share as a
 * light or the camera moves changes its estimate smoothly, not from 0 or
 * 1 to a fraction in one frame. */
static float dominant_mix(float w, float total)
{
    /* 0 < w <= total here (the pair is dominant): the share is in (0, 1] */
    const float t = (w / total - 0.5f * VSGL_DOMINANT_SHARE) / (0.5f * VSGL_DOMINANT_SHARE);
    return t < 1.0f ? t : 1.0f;
}

/* Visibility of every (VSGL, receiver) pair of a block: bit k of vis[v] and
 * skip[v] for receiver k and kernel light v; the pairs under each
 * receiver's budget (vsgl_render_settings.visibility_budget: the VSGLs
 * whose light there, vsgl__kernel_pair_weights, sums to at most that fraction of all of
 * theirs, the weakest first; glossy_sphere_floor at 320 x 240: 26.4 M rays
 * -> 4.5 M at 0.02) are skipped and get share[k], the traced pairs' mean
 * visibility weighted by their light. w: count x VSGL__KERNEL_BLOCK floats
 * (the weights; NULL without a budget or dominant rays). With dominant
 * rays (frac not NULL), bit k of dom[v] marks a receiver whose pair with v traced them
 * (dominant_mix above) and frac[v * VSGL__KERNEL_BLOCK + k] holds its
 * visibility in [0, 1] (vis[v]'s bit: above 0). */
static void block_visibility(const shade_job *j, const vsgl_kernel_block *blk, const receiver *rec, size_t n,
                             uint64_t *vis, uint64_t *skip, uint64_t *dom, float *w, float *frac, float *share)
{
    const size_t count = j->set->count, B = VSGL__KERNEL_BLOCK;
    ray_origins org_s, *org = &org_s;
    origins_of(j, rec, n, org);
    float total[VSGL__KERNEL_BLOCK], cut[VSGL__KERNEL_BLOCK];
    double seen[VSGL__KERNEL_BLOCK], lit[VSGL__KERNEL_BLOCK];
    memset(total, 0, sizeof total);
    for (size_t k = 0; k < B; ++k)
        seen[k] = lit[k] = 0.0;
    const float budget = j->s->visibility_budget;
    const uint32_t rays = frac ? j->s->dominant_rays : 1u;
    if (w) /* every pair's light: the budget's cut, the dominant pairs */
        vsgl__kernel_pair_weights(blk, j->klights, count, w, total);
    if (budget > 0.0f) /* the highest cut whose pairs' light fits the budget */
        vsgl__kernel_weight_cut(w, count, total, budget, cut);
    for (size_t v = 0; v < count; ++v) {
        const float *wv = w ? w + v * B : NULL;
        uint64_t sbits = budget > 0.0f ? vsgl__kernel_lanes_within(wv, cut) & lanes_of(n) : 0;
        skip[v] = sbits;
        vis[v] = 0;
        dom[v] = 0;
        if (sbits == lanes_of(n))
            continue; /* no ray for this VSGL at any receiver of the block */
        uint64_t want = lanes_of(n) & ~sbits, vbits = 0;
        const int twin = v > 0 && j->ray_twin && j->ray_twin[v];
        if (twin) { /* the light before's rays, where it traced them */
            uint64_t have = want & ~skip[v - 1];
            vbits = vis[v - 1] & have;
            want &= ~have;
            if (rays > 1) { /* and its dominant rays, with its mix */
                dom[v] = dom[v - 1] & have;
                for (uint64_t r = dom[v]; r; r &= r - 1) {
                    size_t k = (size_t)__builtin_ctzll(r);
                    frac[v * B + k] = frac[(v - 1) * B + k];
                }
            }
        }
        if (want)
            vbits |= visibility_rays(j, j->korder[v], &j->klights[v], rec, org, n, want, 0, rays);
        if (budget > 0.0f)
            vsgl__kernel_vis_accumulate(wv, lanes_of(n) & ~sbits, vbits, seen, lit);
        const uint64_t blocked = want & ~vbits;
        if (rays > 1 && blocked) { /* (every traced receiver sees it: no receiver takes more rays) */
            /* the receivers for which this pair is dominant and whose block
             * holds another receiver its first ray found blocked: where every
             * other receiver sees the cluster, the shadow's edge is seldom
             * near, and the rays would buy nothing (the sphere room's open
             * floor). The test reads only the other receivers' rays, so the
             * choice does not depend on this receiver's own: its estimate
             * keeps its expectation either way. */
            uint64_t more = 0;
            for (uint64_t r = want; r; r &= r - 1) {
                size_t k = (size_t)__builtin_ctzll(r);
                if (wv[k] > 0.5f * VSGL_DOMINANT_SHARE * total[k] && (blocked & ~((uint64_t)1 << k)))
                    more |= (uint64_t)1 << k;
            }
            if (more) {
                float hits[VSGL__KERNEL_BLOCK];
                for (uint64_t r = more; r; r &= r - 1) {
                    size_t k = (size_t)__builtin_ctzll(r);
                    hits[k] = (float)((vbits >> k) & 1u);
                }
                for (uint32_t ray = 1; ray < rays; ++ray) {
                    uint64_t b = visibility_rays(j, j->korder[v], &j->klights[v], rec, org, n, more, ray, rays);
                    for (uint64_t r = more; r; r &= r - 1) {
                        size_t k = (size_t)__builtin_ctzll(r);
                        hits[k] += (float)((b >> k) & 1u);
                    }
                }
                for (uint64_t r = more; r; r &= r - 1) {
                    size_t k = (size_t)__builtin_ctzll(r);
                    const float first = (float)((vbits >> k) & 1u), t = dominant_mix(wv[k], total[k]);
                    frac[v * B + k] = first + t * (hits[k] / (float)rays - first);
                    if (frac[v * B + k] > 0.0f)
                        vbits |= (uint64_t)1 << k;
                }
                dom[v] |= more;
                const uint64_t np = (uint64_t)__builtin_popcountll(more);
                __atomic_fetch_add(&j->counts->dominant_pairs, np, __ATOMIC_RELAXED);
                __atomic_fetch_add(&j->counts->dominant_rays, np * (rays - 1u), __ATOMIC_RELAXED);
            }
        }
        vis[v] = vbits;
    }
    for (size_t k = 0; k < B; ++k)
        share[k] = seen[k] > 0.0 ? (float)(lit[k] / seen[k]) : 1.0f;
}

/* The visibility budget's working memory, allocated once per list of
 * receivers (not per block): per VSGL its visibility, skip and dominant
 * bits and, under a budget or with dominant rays, its light at each lane
 * (and with dominant rays their visibility). bits NULL: no rays, or no
 * memory (then every pair traces its ray, as without a budget). */
typedef struct vis_scratch {
    uint64_t *bits;  /* 3 x count: visible, skipped, dominant */
    float *weights;  /* count x VSGL__KERNEL_BLOCK, or NULL without a budget and dominant rays */
    float *frac;     /* count x VSGL__KERNEL_BLOCK, or NULL without dominant rays */
} vis_scratch;

static void vis_scratch_init(const shade_job *j, vis_scratch *vs)
{
    const size_t count = j->set->count ? j->set->count : 1;
    const int dominant = j->s->dominant_rays > 1;
    vs->bits = NULL;
    vs->weights = vs->frac = NULL;
    if (j->s->visibility != VSGL_VISIBILITY_RAY)
        return;
    vs->bits = malloc(3 * count * sizeof *vs->bits);
    if (vs->bits && (j->s->visibility_budget > 0.0f || dominant)) {
        vs->weights = malloc(count * VSGL__KERNEL_BLOCK * sizeof *vs->weights);
        vs->frac = dominant ? malloc(count * VSGL__KERNEL_BLOCK * sizeof *vs->frac) : NULL;
        if (!vs->weights || (dominant && !vs->frac)) {
            free(vs->bits);
            free(vs->weights);
            free(vs->frac);
            vs->bits = NULL;
            vs->weights = vs->frac = NULL;
        }
    }
}

static void vis_scratch_free(vis_scratch *vs)
{
    free(vs->bits);
    free(vs->weights);
    free(vs->frac);
}

/* Shade a filled block of n receivers (lanes [0, n) of blk, rec[k].x and
 * .n for visibility rays) and write 6 floats per receiver to light. */
static uint64_t run_block(const shade_job *j, const vis_scratch *vs, vsgl_kernel_block *blk, const receiver *rec,
                          size_t n, float *light)
{
    float vis[2 * VSGL__KERNEL_BLOCK]; /* visibility of two VSGLs */
    uint64_t pairs = 0;
    int32_t lobes = 0;
    vsgl__shadow_lanes(blk, n, two_lobes(j->s->glossy_mode));
    for (size_t k = 0; k < n; ++k)
        lobes |= (blk->diffuse[k] > 0.0f ? VSGL__KERNEL_DIFFUSE : 0) | (blk->camp[k] > 0.0f ? VSGL__KERNEL_GLOSSY : 0) |
                 (blk->diffuse[k] > 0.0f && blk->burley[k] >= 0.0f ? VSGL__KERNEL_BURLEY : 0);
    if ((lobes & VSGL__KERNEL_GLOSSY) && two_lobes(j->s->glossy_mode))
        lobes |= VSGL__KERNEL_GGX_TAIL | (j->s->glossy_lobes == VSGL__HV5_LOBES ? VSGL__KERNEL_HV5 : 0);
    for (size_t k = 0; k < n && !(lobes & VSGL__KERNEL_GRAZE); ++k)
        if (blk->camp[k] > 0.0f &&
            vsgl__graze_ramp(blk->Zx[k] * blk->nx[k] + blk->Zy[k] * blk->ny[k] + blk->Zz[k] * blk->nz[k]) > 0.0f)
            lobes |= VSGL__KERNEL_GRAZE;
    for (size_t k = n; k < VSGL__KERNEL_BLOCK; ++k) {
        /* padding lanes: shaded, never read; at lane 0's position so that
         * they do not change the block's choice of short forms */
        clear_lane(blk, k, blk->x[0], blk->y[0], blk->z[0]);
        vis[k] = vis[VSGL__KERNEL_BLOCK + k] = 0.0f;
    }
    memset(blk->ld, 0, sizeof blk->ld);
    memset(blk->ls, 0, sizeof blk->ls);
    if ((lobes & VSGL__KERNEL_GLOSSY) && j->tilt_dirs)
        tilt_table(blk, j->tilt_dirs);
    if (lobes) {
        size_t (*kernel)(vsgl_kernel_block *, const vsgl_kernel_light *, size_t, const float *, int32_t, int32_t,
                         float) =
            j->path == VSGL__SHADE_KERNEL_SCALAR ? vsgl__kernel_shade_scalar : vsgl__kernel_shade;
        const size_t count = j->set->count;
        size_t faint = 0;
        if (vs->bits) {
            uint64_t *bits = vs->bits;
            float share[VSGL__KERNEL_BLOCK];
            block_visibility(j, blk, rec, n, bits, bits + count, bits + 2 * count, vs->weights, vs->frac, share);
            /* two VSGLs per kernel call, the pairs it interleaves */
            for (size_t v = 0; v < count; v += 2) {
                size_t m = count - v < 2 ? count - v : 2;
                uint64_t any = 0; /* a lane that sees either VSGL, or takes the share for it */
                for (size_t q = 0; q < m; ++q)
                    any |= bits[count + v + q] | bits[v + q];
                if (!any)
                    continue; /* both blocked at every receiver: they add nothing */
                for (size_t q = 0; q < m; ++q) {
                    vsgl__kernel_vis_fill(bits[count + v + q], bits[v + q], share, vis + q * VSGL__KERNEL_BLOCK);
                    if (vs->frac) /* the dominant pairs' mean over their rays */
                        for (uint64_t r = bits[2 * count + v + q]; r; r &= r - 1) {
                            size_t k = (size_t)__builtin_ctzll(r);
                            vis[q * VSGL__KERNEL_BLOCK + k] = vs->frac[(v + q) * VSGL__KERNEL_BLOCK + k];
                        }
                }
                faint += kernel(blk, &j->klights[v], m, vis, j->s->diffuse_mode, lobes, VSGL__FAINT);
            }
        } else if (j->s->visibility == VSGL_VISIBILITY_RAY) { /* no memory for it: a ray for every pair */
            ray_origins org;
            origins_of(j, rec, n, &org);
            for (size_t v = 0; v < count; v += 2) {
                size_t m = count - v < 2 ? count - v : 2;
                for (size_t q = 0; q < m; ++q) {
                    uint64_t bits = visibility_rays(j, j->korder[v + q],
                                                    &j->klights[v + q], rec, &org, n, lanes_of(n), 0, 1);
                    for (size_t k = 0; k < n; ++k)
                        vis[q * VSGL__KERNEL_BLOCK + k] = (float)((bits >> k) & 1u);
                }
                faint += kernel(blk, &j->klights[v], m, vis, j->s->diffuse_mode, lobes, VSGL__FAINT);
            }
        } else {
            faint += kernel(blk, j->klights, count, NULL, j->s->diffuse_mode, lobes, VSGL__FAINT);
        }
        pairs += (uint64_t)n * j->set->count;
        if (faint)
            __atomic_fetch_add(&j->counts->faint, (uint64_t)n * faint, __ATOMIC_RELAXED);
        if ((lobes & VSGL__KERNEL_DIFFUSE) && j->near->start)
            for (size_t k = 0; k < n; ++k)
                if (blk->diffuse[k] > 0.0f)
                    near_correct(j, &rec[k], blk->burley[k], v3_make(blk->ox[k], blk->oy[k], blk->oz[k]),
                                 &blk->ld[0][k], &blk->ld[1][k], &blk->ld[2][k]);
    }
    for (size_t k = 0; k < n; ++k)
        for (int c = 0; c < 3; ++c) {
            light[k * 6 + c] = blk->ld[c][k];
            light[k * 6 + 3 + c] = blk->ls[c][k];
        }
    return pairs;
}

/* Shade G-buffer samples list[0..n) through the kernel, VSGL__KERNEL_BLOCK at
 * a time, each at its own position or, where centroid (VSGL__CENTROID
 * floats per entry: a position sum, a count, how many members' normals
 * differ from the first's and their sum) has a count above 1, at the
 * centroid of a merged group; writes 6 floats per entry (diffuse light
 * RGB, glossy RGB).
 * Every listed sample must be a hit. lanes: NULL, or n entries that
 * receive each receiver's kernel lane (a shading plan's record). Returns
 * the number of pairs. */
uint64_t vsgl__shade_list(const shade_job *j, const size_t *shaded, size_t nshaded, const float *centroid,
                          float *light, vsgl__plan_lane *lanes)
{
    vsgl_kernel_block blk;
    receiver rec[VSGL__KERNEL_BLOCK];
    uint64_t pairs = 0;
    vis_scratch vs;
    vis_scratch_init(j, &vs);
    /* the block's glossy receivers' lobes are warped together (math/warp_lanes.h) */
    _Static_assert(VSGL__WARP_LANES >= VSGL__KERNEL_BLOCK, "a block's receivers fit the warp's lanes");
    vsgl_warp_lanes warp;
    float bscale[VSGL__KERNEL_BLOCK], bamp[VSGL__KERNEL_BLOCK];
    uint8_t wlane[VSGL__KERNEL_BLOCK], curved[VSGL__KERNEL_BLOCK];
    for (size_t s0 = 0; s0 < nshaded; s0 += VSGL__KERNEL_BLOCK) {
        size_t n = nshaded - s0 < VSGL__KERNEL_BLOCK ? nshaded - s0 : VSGL__KERNEL_BLOCK, nw = 0;
        for (size_t k = 0; k < n; ++k) {
            const float *cg = centroid ? centroid + (s0 + k) * VSGL__CENTROID : NULL;
            /* a merged group on a curved or faceted surface (its members'
             * normals not all the same) takes their mean normal: its first
             * sample's is off to one side (a smooth diffuse cylinder's
             * merged light was 1.3 % over every sample shaded, a rough
             * metal sphere's ~3 % under) */
            curved[k] = cg && cg[3] > 1.0f && cg[4] > 0.0f;
            v3 nm = curved[k] ? v3_normalize(v3_make(cg[5], cg[6], cg[7])) : v3_make(0.0f, 0.0f, 0.0f);
            /* every shaded sample is a hit */
            wlane[k] = UINT8_MAX;
            if (setup_receiver_base(j, shaded[s0 + k], &rec[k], curved[k] ? &nm : NULL, &warp, nw, &bscale[k], &bamp[k]))
                wlane[k] = (uint8_t)nw++;
        }
        vsgl__warp_lanes(&warp, nw);
        for (size_t k = 0; k < n; ++k) {
            const float *cg = centroid ? centroid + (s0 + k) * VSGL__CENTROID : NULL;
            if (wlane[k] != UINT8_MAX)
                setup_receiver_lobe(j, &rec[k], &warp, wlane[k], bscale[k], bamp[k]);
            put_lane(j, &blk, k, &rec[k]);
            if (cg && cg[3] > 1.0f) { /* a merged group is shaded at its centroid: its mean light to first order */
                float inv = 1.0f / cg[3];
                v3 xc = v3_make(cg[0] * inv, cg[1] * inv, cg[2] * inv);
                /* on a curved or faceted surface (its members' normals not
                 * all the same) the centroid of points on two facets of a
                 * convex mesh lies inside it, below both, and visibility
                 * rays from there hit the mesh (the rough room's metal
                 * sphere lost a third of its glossy light at stride 1):
                 * there the receiver (its rays, its near field) stays at
                 * its first sample, on the surface; the kernel takes the
                 * centroid */
                if (!curved[k])
                    rec[k].x = xc;
                blk.x[k] = xc.x;
                blk.y[k] = xc.y;
                blk.z[k] = xc.z;
            }
            if (lanes)
                lane_get(&blk, k, &rec[k], &lanes[s0 + k]);
        }
        pairs += run_block(j, &vs, &blk, rec, n, light + s0 * 6);
    }
    vis_scratch_free(&vs);
    return pairs;
}

/* The kernel lane of G-buffer sample i (a hit), as vsgl__shade_list fills it. */
void vsgl__sample_lane(const shade_job *j, size_t i, vsgl__plan_lane *lane)
{
    vsgl_kernel_block blk;
    receiver r;
    fill_lane(j, i, &blk, 0, &r);
    lane_get(&blk, 0, &r, lane);
}

/* The same from recorded lanes (a shading plan's replay): bit-identical
 * to vsgl__shade_list on the samples they were recorded from. */
uint64_t vsgl__shade_lanes(const shade_job *j, const vsgl__plan_lane *const *lanes, size_t n_total, float *light)
{
    vsgl_kernel_block blk;
    receiver rec[VSGL__KERNEL_BLOCK];
    uint64_t pairs = 0;
    vis_scratch vs;
    vis_scratch_init(j, &vs);
    for (size_t s0 = 0; s0 < n_total; s0 += VSGL__KERNEL_BLOCK) {
        size_t n = n_total - s0 < VSGL__KERNEL_BLOCK ? n_total - s0 : VSGL__KERNEL_BLOCK;
        for (size_t k = 0; k < n; ++k) {
            lane_put(&blk, k, lanes[s0 + k], &rec[k]);
        }
        pairs += run_block(j, &vs, &blk, rec, n, light + s0 * 6);
    }
    vis_scratch_free(&vs);
    return pairs;
}

/* Pixel px of the planes from its samples' light (Ls[k]: 6 floats, NULL
 * for a miss) and their own colours; cd (NULL or 4 floats per sample)
 * receives each hit sample's diffuse colour x weight and its weight. */
void vsgl__write_pixel(const shade_job *j, size_t px, const float *const *Ls, float *cd)
{
    const vsgl_gbuffer *g = j->g;
    const vsgl_pixel_planes *pl = j->planes;
    const size_t spp = g->spp;
    float acc[12] = {0};
    float covered = 0.0f;
    for (size_t k = 0; k < spp; ++k) {
        size_t si = px * spp + k;
        if (!Ls[k])
            continue;
        vsgl_brdf_params bp;
        sample_params(j, si, &bp);
        v3 n = v3_make(g->nrm[0][si], g->nrm[1][si], g->nrm[2][si]);
        v3 o = v3_make(g->view[0][si], g->view[1][si], g->view[2][si]);
        float gcol[3] = {0, 0, 0};
        if (bp.glossy && v3_dot(n, o) > 0.0f)
            vsgl__glossy_color(&bp, n, o, gcol);
        const float *L = Ls[k];
        const float w = vsgl__gbuffer_weight(g, si);
        float wd = w * vsgl__scene_diffuse_weight(j->scene, g->material[si], v3_dot(n, o));
        if (cd) {
            for (int c = 0; c < 3; ++c)
                cd[k * 4 + c] = bp.diffuse[c] * wd;
            cd[k * 4 + 3] = w;
        }
        for (int c = 0; c < 3; ++c) {
            acc[c] += bp.diffuse[c] * wd * L[c];
            acc[3 + c] += w * L[3 + c];
            acc[6 + c] += bp.diffuse[c] * wd;
            acc[9 + c] += w * gcol[c];
        }
        covered += w;
    }
    for (int c = 0; c < 3; ++c) {
        pl->diffuse[px * 3 + c] = acc[c];
        pl->glossy[px * 3 + c] = acc[3 + c];
        pl->diffuse_color[px * 3 + c] = acc[6 + c];
        pl->glossy_color[px * 3 + c] = acc[9 + c];
    }
    pl->coverage[px] = covered;
}

/* Rows of pixels through the vectorised kernel, VSGL__KERNEL_BLOCK shaded
 * samples at a time. */
static int32_t shade_chunk_kernel(void *user, size_t chunk, size_t b0, size_t e0)
{
    shade_job *j = user;
#if defined(__x86_64__) || defined(__i386__)
    /* Flush denormals to zero while the kernel runs (restored below):
     * amplitudes far below anything visible otherwise cost microcode
     * assists of ~100 cycles each. Values stay finite and >= 0. */
    unsigned int saved_csr = _mm_getcsr();
    _mm_setcsr(saved_csr | 0x8040u); /* FTZ | DAZ */
#endif
    const vsgl_gbuffer *g = j->g;
    const size_t spp = g->spp;
    const size_t first = (j->base + b0) * spp, last = (j->base + e0) * spp, ns = last - first;
    uint64_t pairs = 0;
    /* which samples are shaded (shaded[]), and the slot each sample reads its light from */
    size_t *shaded = malloc((ns + 1) * sizeof *shaded);
    uint32_t *slot = malloc((ns + 1) * sizeof *slot);
    float *light = malloc((ns + 1) * 6 * sizeof *light);
    /* per slot (vsgl__shade_list); only where samples can merge: a slot of
     * one sample is shaded at its own position and normal */
    const int merging = j->merge && spp > 1;
    float *centroid = merging ? calloc((ns + 1) * VSGL__CENTROID, sizeof *centroid) : NULL;
    if (!shaded || !slot || !light || (merging && !centroid)) {
        free(shaded);
        free(slot);
        free(light);
        free(centroid);
#if defined(__x86_64__) || defined(__i386__)
        _mm_setcsr(saved_csr);
#endif
        return VSGL_ERROR_OUT_OF_MEMORY;
    }
    size_t nshaded = 0;
    for (size_t i = 0; i < ns; ++i) {
        size_t si = first + i;
        slot[i] = UINT32_MAX;
        if (g->material[si] == VSGL__GBUFFER_MISS)
            continue;
        if (merging)
            for (size_t k = i - i % spp; k < i && slot[i] == UINT32_MAX; ++k)
                if (slot[k] != UINT32_MAX && shaded[slot[k]] == first + k && same_surface(g, j->materials, first + k, si, j->plane_tol))
                    slot[i] = slot[k];
        if (slot[i] == UINT32_MAX) {
            slot[i] = (uint32_t)nshaded;
            shaded[nshaded++] = si;
        }
        if (!merging)
            continue;
        float *cg = centroid + (size_t)slot[i] * VSGL__CENTROID;
        cg[0] += g->pos[0][si];
        cg[1] += g->pos[1][si];
        cg[2] += g->pos[2][si];
        cg[3] += 1.0f;
        const size_t f = shaded[slot[i]]; /* the group's first sample */
        cg[4] += g->nrm[0][si] != g->nrm[0][f] || g->nrm[1][si] != g->nrm[1][f] || g->nrm[2][si] != g->nrm[2][f];
        cg[5] += g->nrm[0][si];
        cg[6] += g->nrm[1][si];
        cg[7] += g->nrm[2][si];
    }
    pairs += vsgl__shade_list(j, shaded, nshaded, centroid, light, NULL);
    /* every covered sample: its own colours, the light of its slot */
    const float *Ls[VSGL__GBUFFER_MAX_SPP];
    for (size_t px = j->base + b0; px < j->base + e0; ++px) {
#if defined(__SSE2__)
        /* four pixels' colours at once (pixel4.c), bit for bit */
        if (spp == 1 && j->params && px + 4 <= j->base + e0) {
            for (size_t k = 0; k < 4; ++k) {
                size_t i = px + k - j->base - b0;
                Ls[k] = slot[i] == UINT32_MAX ? NULL : light + (size_t)slot[i] * 6;
            }
            vsgl__write_pixels4(j, px, Ls, NULL);
            px += 3;
            continue;
        }
#endif
        for (size_t k = 0; k < spp; ++k) {
            size_t i = (px - j->base - b0) * spp + k;
            Ls[k] = slot[i] == UINT32_MAX ? NULL : light + (size_t)slot[i] * 6;
        }
        vsgl__write_pixel(j, px, Ls, NULL);
    }
    free(shaded);
    free(slot);
    free(light);
    free(centroid);
    j->pairs[chunk] = pairs;
#if defined(__x86_64__) || defined(__i386__)
    _mm_setcsr(saved_csr);
#endif
    return 0;
}

vsgl_result vsgl__shade(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_gbuffer *g,
                        const vsgl_vsgl_set *set, const vsgl_render_settings *s,
                        const vsgl_pixel_planes *planes, int path, uint64_t *pairs)
{
    return vsgl__shade_planned(ctx, scene, g, set, s, planes, path, pairs, NULL, NULL);
}

vsgl_result vsgl__shade_planned(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_gbuffer *g,
                                const vsgl_vsgl_set *set, const vsgl_render_settings *s,
                                const vsgl_pixel_planes *planes, int path, uint64_t *pairs, vsgl_shade_counts *counts,
                                vsgl_shade_plan **plan)
{
    size_t pixels = (size_t)g->width * g->height;
    size_t chunk = g->width ? g->width : 1; /* one row per chunk */
    size_t chunks = vsgl__chunk_count(pixels, chunk);
    uint64_t *per_chunk = calloc(chunks + 1, sizeof *per_chunk);
    /* each VSGL's lobe integral (a quadrature for a specular lobe) once, for
     * the kernel's amplitudes, the near field and the reference path alike */
    float *lobe_int = malloc((set->count + 1) * sizeof *lobe_int);
    if (!per_chunk || !lobe_int) {
        free(per_chunk);
        free(lobe_int);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "shade: out of memory");
    }
    for (size_t k = 0; k < set->count; ++k)
        lobe_int[k] = vsgl__vsgl_lobe_integral(&set->items[k]);
    /* a plan's colours stay in the planes only from its own record or replay to the next */
    const float *colours_in = plan && *plan ? (*plan)->colours_in : NULL;
    if (plan && *plan)
        (*plan)->colours_in = NULL;
    v3 lo, hi;
    vsgl__scene_bounds(scene, &lo, &hi);
    float extent = v3_length(v3_sub(hi, lo));
    /* Ray offset: a fraction of the scene's size, but never below a few ulps
     * of its coordinates (a scene 100 km from the origin has 1 cm floats). */
    float max_abs = fmaxf(fmaxf(fmaxf(fabsf(lo.x), fabsf(hi.x)), fmaxf(fabsf(lo.y), fabsf(hi.y))),
                          fmaxf(fabsf(lo.z), fabsf(hi.z)));
    float eps = fmaxf((extent > 0.0f ? extent : 1.0f) * 1e-5f, max_abs * 1e-6f);
    uint32_t material_count;
    if (vsgl__shades_by_reference(s))
        path = VSGL__SHADE_REFERENCE;
    int leak = s->leak_correction == VSGL_LEAK_ON || s->leak_correction == VSGL_LEAK_AUTO ||
               s->leak_correction == VSGL_LEAK_CLIP;
    vsgl_kernel_light *kl = NULL;
    size_t *korder = NULL;
    if (path != VSGL__SHADE_REFERENCE) {
        kl = malloc((set->count + 1) * sizeof *kl);
        if (!kl) {
            free(per_chunk);
            free(lobe_int);
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "shade: out of memory");
        }
        for (size_t k = 0; k < set->count; ++k) {
            const vsgl_vsgl *v = &set->items[k];
            vsgl_kernel_light *o = &kl[k];
            o->mx = v->mean.x; o->my = v->mean.y; o->mz = v->mean.z;
            /* a sheared cluster: the part a receiver sees, about a shifted mean */
            const int sheared = v->sheared && v->variance > 0.0f && v->shear_variance > 0.0f;
            const float var = sheared ? v->shear_variance : v->variance;
            o->var = var;
            o->var2 = 2.0f * var;
            /* a single-texel cluster has variance 0: 1e30, not FLT_MAX, so that
             * d^2 / var stays finite in the kernel (FLT_MAX x d^2 > 1 m^2 overflowed
             * to inf and inf / inf gave NaN pixels beside a light 5 mm from a wall) */
            o->ivar = 1.0f / fmaxf(var, VSGL__TINY);
            for (int e = 0; e < 9; ++e)
                o->sh[e] = sheared ? v->shear[e] : 0.0f;
            o->ishift = sheared ? 0.25f / v->variance : 0.0f;
            o->shear = sheared ? 1.0f : 0.0f;
            o->valid = v->variance > 0.0f ? 1.0f : 0.0f;
            o->ax = -v->axis.x; o->ay = -v->axis.y; o->az = -v->axis.z;
            o->lv = v->sharpness;
            o->lax = o->lv * o->ax; o->lay = o->lv * o->ay; o->laz = o->lv * o->az;
            o->c0 = 1.0f / (VSGL__2PI * lobe_int[k]);
            o->pr = v->power[0]; o->pg = v->power[1]; o->pb = v->power[2];
            o->nx = v->normal.x; o->ny = v->normal.y; o->nz = v->normal.z;
            o->clip = leak ? v->coherence * v->coherence : 0.0f;
            o->part = leak && v->part != VSGL__PART_NONE ? (float)v->part : -2.0f;
            o->pout = v->part_out;
            o->pin = v->part_in;
            o->conv = v->lobe == VSGL__LOBE_DIFFUSE ? 1.0f : 0.0f;
            o->fore = vsgl__foreshortening_weight(v);
            float fw, fs;
            vsgl__clip_fade(v->variance, v->coherence, &fw, &fs);
            o->ibehind = 1.0f / (fw + VSGL__TINY);
            o->boff = fs * o->ibehind;
            o->planar = leak && v->lobe == VSGL__LOBE_DIFFUSE ? v->coherence * v->coherence : 0.0f;
            o->bump = o->planar > 0.0f ? vsgl__planar_bump(v->coherence) : 0.0f;
            o->pvar = v->variance + v->widen;
            v3 u1, u2;
            cell_cuts cuts;
            o->fold = o->planar > 0.0f ? fold_weight(v, &cuts) : 0.0f;
            const int tdir = vsgl__planar_tilt_dir(v->normal.x, v->normal.y, v->normal.z);
            o->tilt = o->planar > 0.0f && tdir >= 0 ? vsgl__planar_tilt_weight(v->coherence) : 0.0f;
            o->tdir = tdir >= 0 ? (uint32_t)tdir : 0u;
            memset(o->fb, 0, sizeof o->fb);
            memset(o->fa, 0, sizeof o->fa);
            o->fs[0] = o->fs[1] = 0.0f;
            o->freach = 0.0f;
            if (o->fold > 0.0f) {
                cell_axes(v, &u1, &u2);
                float is = 1.0f / sqrtf(fmaxf(o->pvar, VSGL__TINY));
                const float mm[2] = {v3_dot(v->mean, u1), v3_dot(v->mean, u2)};
                float far2[2] = {0.0f, 0.0f};
                for (int ax = 0; ax < 2; ++ax)
                    for (int sd = 0; sd < 2; ++sd) {
                        o->fb[ax][sd] = (cuts.b[ax][sd] - mm[ax]) * is;
                        o->fa[ax][sd] = cuts.a[ax][sd];
                        if (o->fa[ax][sd] > 0.0f)
                            far2[ax] = fmaxf(far2[ax], o->fb[ax][sd] * o->fb[ax][sd]);
                    }
                for (int ax = 0; ax < 2; ++ax)
                    o->fs[ax] = (fold_mean(v, &cuts, ax, mm[ax]) - mm[ax]) * is;
                float reach = sqrtf(50.0f) + 2.0f * sqrtf(far2[0] + far2[1]) +
                              sqrtf(o->fs[0] * o->fs[0] + o->fs[1] * o->fs[1]);
                o->freach = 0.5f * reach * reach;
            } else {
                v3_basis(v->normal, &u1, &u2);
            }
            o->u1x = u1.x; o->u1y = u1.y; o->u1z = u1.z;
            o->u2x = u2.x; o->u2y = u2.y; o->u2z = u2.z;
        }
        /* The kernel shades VSGLs two at a time, and a pair that mixes a
         * planar cluster with another computes both glossy models for both
         * (the lattice emits them alternating: every pair was mixed). In
         * the order planar 0, between, 1, each kept in the fit's order, at
         * most two pairs mix. korder[k]: the VSGL of kernel light k. */
        korder = malloc((set->count + 1) * sizeof *korder);
        vsgl_kernel_light *sorted = malloc((set->count + 1) * sizeof *sorted);
        if (!korder || !sorted) {
            free(korder);
            free(sorted);
            free(kl);
            free(per_chunk);
            free(lobe_int);
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "shade: out of memory");
        }
        size_t n = 0;
        for (int cls = 0; cls < 3; ++cls)
            for (size_t k = 0; k < set->count; ++k) {
                float q = kl[k].planar;
                if ((q == 0.0f ? 0 : q == 1.0f ? 2 : 1) == cls) {
                    korder[n] = k;
                    sorted[n++] = kl[k];
                }
            }
        free(kl);
        kl = sorted;
    }
    unsigned char *twin = path != VSGL__SHADE_REFERENCE && s->visibility == VSGL_VISIBILITY_RAY
                              ? calloc(set->count + 1, 1) : NULL; /* no memory: every light traces its own */
    for (size_t k = 1; twin && k < set->count; ++k)
        twin[k] = same_rays(&set->items[korder[k]], &kl[k], &set->items[korder[k - 1]], &kl[k - 1]);
    vsgl_ray_targets targets = {NULL, NULL};
    if (s->visibility == VSGL_VISIBILITY_RAY &&
        vsgl__ray_targets_build(scene, set, fmaxf(s->visibility_spread, 0.0f),
                                (extent > 0.0f ? extent : 1.0f) * VSGL__RAY_SEED_CELL, &targets) != VSGL_OK) {
        free(twin);
        free(korder);
        free(kl);
        free(per_chunk);
        free(lobe_int);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "shade: out of memory");
    }
    vsgl_shade_counts totals = {0, 0, 0};
    shade_job j = {scene, g, set, s, planes, vsgl__scene_materials(scene, &material_count),
                   eps, 0, per_chunk, &totals, kl, korder, lobe_int, path, leak,
                   s->sample_merging != VSGL_MERGE_OFF && g->spp > 1, (extent > 0.0f ? extent : 1.0f) * 1e-3f,
                   0, 0, 0, NULL, NULL, NULL, NULL, NULL, {0.0f, 0.0f}, NULL, 0, NULL, NULL, twin, &targets, 0u, NULL};
    for (size_t k = 0; kl && k < set->count; ++k) /* the axis planes the horizon tilt is taken against */
        if (kl[k].tilt > 0.0f)
            j.tilt_dirs |= 1u << kl[k].tdir;
    /* untextured: each material's BRDF parameters once, not once per sample */
    vsgl_brdf_params *params = g->surf[0] ? NULL : malloc(((size_t)material_count + 1) * sizeof *params);
    if (params)
        for (uint32_t k = 0; k < material_count; ++k)
            vsgl__material_params(&j.materials[k], &params[k]);
    j.params = params;
    /* sparse interpolation: each material's same-surface normal tolerance (no memory: the loosest) */
    float *normal_cos = s->shade_stride > 1 ? malloc(((size_t)material_count + 1) * 2 * sizeof *normal_cos) : NULL;
    if (normal_cos)
        vsgl__sparse_normal_cos(j.materials, material_count, normal_cos);
    j.normal_cos = normal_cos;
    vsgl_near_index near;
    memset(&near, 0, sizeof near);
    if (leak && s->leak_correction != VSGL_LEAK_CLIP)
        vsgl__near_index_build(set, &near); /* short of memory: no near field */
    j.near = &near;
    vsgl_result r = VSGL_OK;
    /* One pixel in S x S (sparse.c): the anchors now, the rest row by row below. */
    int sparse = s->shade_stride > 1 && path != VSGL__SHADE_REFERENCE && g->width && g->height;
    uint64_t anchor_total = 0;
    if (sparse) {
        j.stride = s->shade_stride;
        j.aw = (g->width - 1) / j.stride + 2;
        j.ah = (g->height - 1) / j.stride + 2;
        size_t na = (size_t)j.aw * j.ah;
        j.anchor_sample = malloc(na * sizeof *j.anchor_sample);
        j.anchor_light = malloc(na * 6 * sizeof *j.anchor_light);
        j.anchor_d2 = malloc(na * 4 * sizeof *j.anchor_d2);
        j.anchor_pairs = calloc(na + 1, sizeof *j.anchor_pairs); /* per chunk of anchors: fewer than na */
        j.alist = malloc((na + 1) * sizeof *j.alist);
        if (plan) { /* replay a plan of this G-buffer, or record one */
            if (*plan && vsgl__shade_plan_matches(*plan, g, s, j.aw, j.ah)) {
                j.plan = *plan;
                j.replay = 1;
                j.plan->colours_kept = colours_in == planes->diffuse_color;
            } else {
                j.plan = vsgl__shade_plan_new(g, s, j.aw, j.ah);
            }
        }
        if (!j.anchor_sample || !j.anchor_light || !j.anchor_d2 || !j.anchor_pairs || !j.alist)
            r = vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "shade: out of memory for the sparse anchors");
        else
            r = vsgl__shade_anchors(ctx, &j);
        for (size_t a = 0; r == VSGL_OK && a < na; ++a)
            anchor_total += j.anchor_pairs[a];
    }
    /* Rows in batches so progress can be reported and cancellation honoured:
     * 20 of them, but none under 2^17 pixels (each batch ends in a wait for
     * its slowest row: a live viewport's 960 x 540 has 4, not 20) */
    size_t rows_per_batch = g->height / 20 + 1, min_rows = ((size_t)1 << 17) / (chunk ? chunk : 1) + 1;
    if (rows_per_batch < min_rows)
        rows_per_batch = min_rows;
    for (size_t row = 0; row < g->height && r == VSGL_OK; row += rows_per_batch) {
        size_t end = row + rows_per_batch < g->height ? row + rows_per_batch : g->height;
        j.base = row * chunk;
        j.pairs = per_chunk + row;
        if (sparse) {
            r = vsgl__shade_sparse_batch(ctx, &j, row, end);
            if (r != VSGL_OK)
                break;
        } else if (vsgl__parallel_ctx(ctx, (end - row) * chunk, chunk,
                                      path == VSGL__SHADE_REFERENCE ? shade_chunk : shade_chunk_kernel, &j) != 0) {
            r = vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "shade: out of memory");
            break;
        }
        if (vsgl__progress(ctx, "shade", (float)end / (float)g->height))
            r = vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "shade: cancelled");
    }
    uint64_t total = anchor_total;
    for (size_t c = 0; c < chunks; ++c)
        total += per_chunk[c];
    free(per_chunk);
    free(lobe_int);
    free(kl);
    free(korder);
    free(twin);
    vsgl__ray_targets_free(&targets);
    free(j.anchor_sample);
    free(j.anchor_light);
    free(j.anchor_d2);
    free(j.anchor_pairs);
    free(j.alist);
    free(params);
    free(normal_cos);
    vsgl__near_index_free(&near);
    if (j.plan && r == VSGL_OK)
        j.plan->colours_in = planes->diffuse_color;
    if (j.plan && !j.replay) {
        if (r == VSGL_OK && vsgl__shade_plan_complete(j.plan)) {
            vsgl__shade_plan_free(*plan);
            *plan = j.plan;
        } else {
            vsgl__shade_plan_free(j.plan);
        }
    }
    if (pairs)
        *pairs = total;
    if (counts)
        *counts = totals;
    return r;
}
