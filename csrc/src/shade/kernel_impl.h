/* Body of the shading kernel, included by kernel.c (vectorised, ISA clones)
 * and kernel_scalar.c (scalar reference build). Define KERNEL_NAME and
 * KERNEL_ATTR before including. Branch-free per lane so that GCC can
 * vectorise the loop over receivers; the formulas are those of
 * vsgl_sg_product (Eq. 7), vsgl_sg_cosine_integral (three modes) and the
 * ASG x SG product integral (Xu et al. Eq. 18 with Eq. 11's normalisation)
 * with vsgl_specular_factor at the integrand's axis (docs/math.md). */
#include "shade/kernel.h"
#include "math/constants.h"
#include "vsgl/sg.h"
#include "math/sg_internal.h" /* the accurate cosine form's fitted constants */
#include "scene/material.h"     /* vsgl__burley_factor */

#include <math.h>
#include <string.h>

#define K_SHARP_MAX 2199023255552.0f       /* 2^41 */
/* A(2.29) / pi: the clamped cosine over the diffuse lobe's SG at the axis */
#define K_CLIP_RHO ((float)(VSGL__COSINE_A_LD / VSGL__PI_D))

/* e^x, 0 below -87 and e^88 above 88: Cephes-style degree-5 polynomial
 * after rintf range reduction (not the 1.5*2^23 trick, which the
 * unsafe-math flags of kernel.c would delete). The exponent bits come from
 * a float product: an int conversion of the clamped value gets narrowed by
 * value-range propagation and then cannot be vectorised (GCC 12). The
 * tests check this exp against libm. */
static inline __attribute__((always_inline)) float k_exp(float x)
{
    float xc = x < -87.0f ? -87.0f : x;
    xc = xc > 88.0f ? 88.0f : xc;
    float t = xc * 1.44269504088896341f;
    float k = rintf(t);
    float r = xc - k * 0.693359375f + k * 2.12194440e-4f;
    float p = 1.9875691500e-4f;
    p = p * r + 1.3981999507e-3f;
    p = p * r + 8.3334519073e-3f;
    p = p * r + 4.1665795894e-2f;
    p = p * r + 1.6666665459e-1f;
    p = p * r + 5.0000001201e-1f;
    p = p * r * r + r + 1.0f;
    int32_t bits = (int32_t)((k + 127.0f) * 8388608.0f);
    float scale;
    memcpy(&scale, &bits, sizeof scale);
    return x < -87.0f ? 0.0f : p * scale;
}

/* 1 - erf(x) = P(x) e^{-x^2}: returns P (Abramowitz & Stegun 7.1.26). */
static inline __attribute__((always_inline)) float k_erfc_poly(float x)
{
    float k = 1.0f / (1.0f + 0.3275911f * x);
    return k * (0.254829592f + k * (-0.284496736f + k * (1.421413741f + k * (-1.453152027f + k * 1.061405429f))));
}

/* Reciprocal square root of a positive normal float: a bit-level first
 * guess and one Newton step (relative error below 1.8e-3): enough for the
 * leak correction's smoothstep fade, a heuristic weight (the kernel is 4 %
 * faster than with two steps there). */
static inline __attribute__((always_inline)) float k_rsqrt_coarse(float x)
{
    int32_t i;
    memcpy(&i, &x, sizeof i);
    i = 0x5f375a86 - (i >> 1);
    float y;
    memcpy(&y, &i, sizeof y);
    return y * (1.5f - 0.5f * x * y * y);
}

/* With a second Newton step (relative error below 4.7e-6; each step
 * squares it). GCC has no 16-lane reciprocal-square-root pattern for
 * 1/sqrtf: it emits a square root and then a reciprocal, both refined,
 * twice the work and the latency. */
static inline __attribute__((always_inline)) float k_rsqrt(float x)
{
    float y = k_rsqrt_coarse(x);
    return y * (1.5f - 0.5f * x * y * y);
}

/* The same with a third Newton step (~2e-7), where the erfc terms of the
 * accurate cosine amplify the error of t. */
static inline __attribute__((always_inline)) float k_rsqrt_fine(float x)
{
    float y = k_rsqrt(x);
    return y * (1.5f - 0.5f * x * y * y);
}

/* The ACCURATE SG x clamped-cosine integral of a unit-amplitude SG
 * (lambda l, cosine c between its axis and the normal); see sg_cosine.c.
 * Split in two so the kernel can run them as separate stages: what depends
 * on l alone, then the cosine's part. */
typedef struct k_cos_l {
    float low, u;   /* 2 pi times the integral below the horizon-free part, and the blend weight */
    float t, it;    /* the erf scale and 1/sqrt(pi)/t */
    float kappa;    /* the constrained correction's weight */
    float ct;       /* every c-independent term of s */
} k_cos_l;

static inline __attribute__((always_inline)) k_cos_l k_cosine_lpart(float l)
{
    k_cos_l o;
    l = l < K_SHARP_MAX ? l : K_SHARP_MAX;
    float small = l < 0.5f ? 1.0f : 0.0f;
    float ls = l > VSGL__TINY ? l : VSGL__TINY;
    float inv = 1.0f / ls;
    float e1 = k_exp(-l);
    /* expm1(-l): Taylor below 0.5 */
    float em_t = -l * (1.0f - l * 0.5f * (1.0f - l * (1.0f / 3.0f) * (1.0f - l * 0.25f * (1.0f - l * 0.2f * (1.0f - l * (1.0f / 6.0f))))));
    float em = small > 0.0f ? em_t : e1 - 1.0f;
    e1 = 1.0f + em;
    float q_t = 0.5f + l * (-1.0f / 3.0f + l * (1.0f / 8.0f + l * (-1.0f / 30.0f + l * (1.0f / 144.0f + l * (-1.0f / 840.0f + l * (1.0f / 5760.0f))))));
    float q = small > 0.0f ? q_t : (-em - l * e1) * (inv * inv);
    /* vMF mean length coth(l) - 1/l = (1 - 1/l) + 2 e^{-2l} / (1 - e^{-2l}); series below 1
     * (vsgl__sg_mean_length) */
    float below1 = l < 1.0f ? 1.0f : 0.0f;
    float e2 = e1 * e1;
    float ml_c = (1.0f - inv) + 2.0f * e2 / (1.0f - e2 + below1);
    float l2 = l * l;
    float ml_t = l * (1.0f / 3.0f + l2 * (-1.0f / 45.0f + l2 * (2.0f / 945.0f + l2 * (-1.0f / 4725.0f
               + l2 * (2.0f / 93555.0f + l2 * (-1382.0f / 638512875.0f + l2 * (4.0f / 18243225.0f
               + l2 * (-3617.0f / 162820783125.0f + l2 * (87734.0f / 38979295480125.0f)))))))));
    float ml = below1 > 0.0f ? ml_t : ml_c;
    o.low = VSGL__2PI * e1 * q;
    o.u = VSGL__2PI * (-em * (2.0f + em) * inv) * ml;
    /* t = l sqrt(h), h = 0.5 N(l) / D(l): one reciprocal square root gives t and 1/t */
    float h = 0.5f * ((l + VSGL__COS_T_A) * l + VSGL__COS_T_B) /
              (((l + VSGL__COS_T_C) * l + VSGL__COS_T_D) * l + VSGL__COS_T_E);
    float rh = k_rsqrt_fine(h);
    float t = l * h * rh;
    t = t > VSGL__TINY ? t : VSGL__TINY;
    float it = rh * inv;
    it = t > VSGL__TINY ? it : 1e30f;
    float et = k_exp(-t * t);
    o.kappa = -((VSGL__COS_K_A1 + VSGL__COS_K_A2 * l) / (1.0f + l * (VSGL__COS_K_B1 + VSGL__COS_K_B2 * l))) * it;
    o.it = 0.28209479177387814f * it;
    o.t = t;
    o.ct = 0.5f * k_erfc_poly(t) * et - et * o.it - o.kappa * (t * t - VSGL__COS_K_PSI) * et;
    return o;
}

/* The same for sharp lobes, l >= K_SHARP_COSINE: e^{-l} < 1.3e-14 and
 * e^{-t^2} < 2.7e-7 drop out, which leaves no exp and no series (the
 * c-independent terms are below 1e-7 of A(l); tests/c/test_kernel.c). */
#define K_SHARP_COSINE 32.0f
/* the diffuse forms' short versions for blocks of sharp lobes */
#define K_COSINE_PULLED_OUT_SHARP 100 /* e^{-2 lin} drops out */
#define K_COSINE_ACCURATE_SHARP 101   /* no bound below the horizon */
#define K_COSINE_SG_SHARP 102         /* e^{-2 lm} drops out of A(lm), lm >= lin - 2.3 */
static inline __attribute__((always_inline)) k_cos_l k_cosine_lpart_sharp(float l)
{
    k_cos_l o;
    l = l < K_SHARP_MAX ? l : K_SHARP_MAX;
    float inv = 1.0f / l;
    o.low = 0.0f;
    o.u = VSGL__2PI * inv * (1.0f - inv);
    float h = 0.5f * ((l + VSGL__COS_T_A) * l + VSGL__COS_T_B) /
              (((l + VSGL__COS_T_C) * l + VSGL__COS_T_D) * l + VSGL__COS_T_E);
    float rh = k_rsqrt_fine(h);
    o.t = l * h * rh;
    float it = rh * inv;
    o.kappa = -((VSGL__COS_K_A1 + VSGL__COS_K_A2 * l) / (1.0f + l * (VSGL__COS_K_B1 + VSGL__COS_K_B2 * l))) * it;
    o.it = 0.28209479177387814f * it;
    o.ct = 0.0f;
    return o;
}

/* The part that depends on the cosine c. The bound below the horizon
 * (c < 0) is never active for sharp lobes (l >= K_SHARP_COSINE: it changes
 * the result by < 2e-8 of A(l)), so the short form leaves it out. */
static inline __attribute__((always_inline)) float k_cosine_cpart_s(float l, float c, k_cos_l o, int sharp)
{
    l = l < K_SHARP_MAX ? l : K_SHARP_MAX;
    float ac = fabsf(c);
    float x = o.t * ac;
    float ex = k_exp(-x * x);
    float s = (c > 0.0f ? c : 0.0f) - 0.5f * ac * k_erfc_poly(x) * ex + ex * o.it
            + o.kappa * (x * x - VSGL__COS_K_PSI) * ex + o.ct;
    s = s > 0.0f ? (s < 1.0f ? s : 1.0f) : 0.0f;
    float r = o.low + o.u * s;
    if (sharp)
        return r;
    float omc2 = (1.0f - ac) * (1.0f + ac);
    float bound = VSGL__PI * k_exp(-l * c * c / (1.0f + sqrtf(omc2)));
    float rb = bound < r ? bound : r;
    r = c < 0.0f ? rb : r; /* no && : a combined mask does not vectorise (GCC 12) */
    return l > 0.0f ? r : VSGL__PI;
}

static inline __attribute__((always_inline)) float k_cosine_cpart(float l, float c, k_cos_l o)
{
    return k_cosine_cpart_s(l, c, o, 0);
}

static inline __attribute__((always_inline)) float k_cosine_accurate(float l, float c)
{
    return k_cosine_cpart(l, c, k_cosine_lpart(l));
}

/* A(l) = 2 pi (1 - e^{-2l}) / l, 4 pi at 0. */
static inline __attribute__((always_inline)) float k_sg_integral(float l)
{
    float e = k_exp(-2.0f * l);
    float taylor = 4.0f * VSGL__PI * (1.0f - l * (1.0f - l * (2.0f / 3.0f)));
    return l < 1e-3f ? taylor : VSGL__2PI * (1.0f - e) / l;
}


/* The kernel runs in stages, each a loop over the block's receivers that
 * leaves its results in a small scratch block (L1-resident). One fused loop
 * is one long chain of dependent operations per vector of receivers, more
 * than the core's scheduler can overlap across vectors; the stages' short
 * loops keep it busy (the ASG lobe alone: 2.9 -> 2.4 ns per pair when split
 * in two stages; docs/performance.md has the whole history). */
typedef struct k_scratch {
    float mx[VSGL__KERNEL_BLOCK], my[VSGL__KERNEL_BLOCK], mz[VSGL__KERNEL_BLOCK]; /* lin times the incident axis */
    float lin[VSGL__KERNEL_BLOCK], ilin[VSGL__KERNEL_BLOCK];                    /* its sharpness and 1/it */
    float amp[VSGL__KERNEL_BLOCK];                                             /* its amplitude */
    float bfac[VSGL__KERNEL_BLOCK];                                            /* Burley's factor (k_burley) */
    float expo[VSGL__KERNEL_BLOCK];                                            /* an exp's argument */
    float gpre[VSGL__KERNEL_BLOCK];                                            /* the glossy integral's factor */
    float r[VSGL__KERNEL_BLOCK], d2[VSGL__KERNEL_BLOCK], ls[VSGL__KERNEL_BLOCK];
    float lden[VSGL__KERNEL_BLOCK], xnum[VSGL__KERNEL_BLOCK]; /* the exponent's denominator, its distance-lobe terms */
    /* the accurate cosine's part that depends on lin alone (k_cos_l) */
    float low[VSGL__KERNEL_BLOCK], u[VSGL__KERNEL_BLOCK], t[VSGL__KERNEL_BLOCK], it[VSGL__KERNEL_BLOCK];
    float h[VSGL__KERNEL_BLOCK];                                               /* height above the cluster's plane */
    float vis[VSGL__KERNEL_BLOCK];                                             /* visibility x validity */
    float pexpo[VSGL__KERNEL_BLOCK], ppre[VSGL__KERNEL_BLOCK];                  /* the planar glossy's exp argument, factor */
    float kappa[VSGL__KERNEL_BLOCK], ct[VSGL__KERNEL_BLOCK];
    /* the planar glossy's lobe-independent part (k_planar_geom): the footprint's frame on the plane
     * (sigma units), 1/sigma, and its factor ok x visibility x camp / sigma^2 */
    float pa1[VSGL__KERNEL_BLOCK], pa2[VSGL__KERNEL_BLOCK], pb1[VSGL__KERNEL_BLOCK], pb2[VSGL__KERNEL_BLOCK];
    float pis[VSGL__KERNEL_BLOCK], pok[VSGL__KERNEL_BLOCK];
    /* where the axis meets the plane (t, sigma units) and the axis's components along u1, u2, for
     * the footprint's reach (kernel.h, vsgl__planar_reach) */
    float pt[VSGL__KERNEL_BLOCK], pz1[VSGL__KERNEL_BLOCK], pz2[VSGL__KERNEL_BLOCK];
    /* the planar glossy's offsets and covariance (sigma units), for a fold */
    float pd1[VSGL__KERNEL_BLOCK], pd2[VSGL__KERNEL_BLOCK], ps11[VSGL__KERNEL_BLOCK], ps22[VSGL__KERNEL_BLOCK],
        ps12[VSGL__KERNEL_BLOCK], pidet[VSGL__KERNEL_BLOCK];
    /* the half-vector model: its weight, the slope of the half vector, the
     * cluster's slope covariance, and the factor common to its lobes */
    float hvw[VSGL__KERNEL_BLOCK], hs1[VSGL__KERNEL_BLOCK], hs2[VSGL__KERNEL_BLOCK];
    float pw[VSGL__KERNEL_BLOCK]; /* the planar model's weight per lane (kernel.h vsgl__planar_weight) */
    float hc11[VSGL__KERNEL_BLOCK], hc12[VSGL__KERNEL_BLOCK], hc22[VSGL__KERNEL_BLOCK], hpre[VSGL__KERNEL_BLOCK];
    /* D's 1 / h.n^4 x G x F at w (a lobe linearised there), Smith's view term */
    float hfw[VSGL__KERNEL_BLOCK], hso[VSGL__KERNEL_BLOCK];
    /* w, the cluster's projected normal p and the view o in the frame (t, u, n), the spread var/d^2 */
    float hwt[VSGL__KERNEL_BLOCK], hwu[VSGL__KERNEL_BLOCK], hwn[VSGL__KERNEL_BLOCK], hpt[VSGL__KERNEL_BLOCK],
        hpu[VSGL__KERNEL_BLOCK], hpn[VSGL__KERNEL_BLOCK], hot[VSGL__KERNEL_BLOCK], hou[VSGL__KERNEL_BLOCK],
        hon[VSGL__KERNEL_BLOCK], hsv[VSGL__KERNEL_BLOCK];
    /* a sheared cluster's shift of its mean towards the lane, and 1 / the lane's distance from the mean (k_shift) */
    float sx[VSGL__KERNEL_BLOCK], sy[VSGL__KERNEL_BLOCK], sz[VSGL__KERNEL_BLOCK], sr[VSGL__KERNEL_BLOCK];
} k_scratch;

/* Stage 0 (sheared clusters, vsgl_vsgl.shear): where the part of the
 * cluster that sends towards the lane lies, as a shift of its mean: sh (e
 * - axis), e the unit direction from the mean to the lane, kept within
 * about 2 sigma (|y| / sqrt(1 + |y|^2 / 4 var): the linear model holds
 * near the lobe's axis, and far from it the lobe sends little). */
static inline __attribute__((always_inline)) void
k_shift(const vsgl_kernel_block *restrict b, size_t i, const vsgl_kernel_light *restrict L, k_scratch *restrict t)
{
    float dx = L->mx - b->x[i], dy = L->my - b->y[i], dz = L->mz - b->z[i];
    float d2 = dx * dx + dy * dy + dz * dz;
    float r = k_rsqrt(d2 > 1e-24f ? d2 : 1e-24f);
    /* e - axis = -d r + L->a (L->a is -axis) */
    float ex = L->ax - dx * r, ey = L->ay - dy * r, ez = L->az - dz * r;
    float yx = L->sh[0] * ex + L->sh[1] * ey + L->sh[2] * ez;
    float yy = L->sh[3] * ex + L->sh[4] * ey + L->sh[5] * ez;
    float yz = L->sh[6] * ex + L->sh[7] * ey + L->sh[8] * ez;
    float c = k_rsqrt(1.0f + (yx * yx + yy * yy + yz * yz) * L->ishift);
    t->sr[i] = r;
    t->sx[i] = yx * c;
    t->sy[i] = yy * c;
    t->sz[i] = yz * c;
}

/* The vector from lane i to the source it sees: the mean, shifted where
 * the call has sheared clusters (`shear` a constant). */
#define K_SOURCE(shear)                                                                \
    float dx = L->mx - b->x[i], dy = L->my - b->y[i], dz = L->mz - b->z[i];            \
    if (shear) {                                                                       \
        dx += t->sx[i];                                                                \
        dy += t->sy[i];                                                                \
        dz += t->sz[i];                                                                \
    }

/* Stage 1: the incident radiance as one SG (Eq. 7), all but the exp.
 * Written with the fewest reciprocals (three square-root reciprocals and
 * one reciprocal per pair; every select is on a value, never on a
 * division):
 *   r = 1/|d|, var' = max(var, d^2 2^-41) so 1/var' = min(1/var, 2^41 r^2),
 *   ls = d^2 / var', the product axis m = ls u + lv a = (|d|/var') d + lv a,
 *   lin = |m|, and the amplitude's exponent -lv ls |a - u|^2 / (lin + lv + ls). */
/* conv: a constant, 0 where no light of the call has the far-field
 * falloff (L->conv 0: specular lobes), which then leave its exp out */
static inline __attribute__((always_inline)) void
k_geometry(const vsgl_kernel_block *restrict b, size_t i, const vsgl_kernel_light *restrict L, float vis,
           k_scratch *restrict t, const int conv, const int shear)
{
    K_SOURCE(shear);
    float d2 = dx * dx + dy * dy + dz * dz;
    float r = k_rsqrt(d2 > 1e-24f ? d2 : 1e-24f);
    t->r[i] = r;
    t->d2[i] = d2;
    /* Emitter-hemisphere clip (shade.h, vsgl__emitter_clip): nothing behind
     * or in the cluster's plane, nothing for a receiver facing the same way,
     * the clamped cosine's far-field falloff for diffuse lobes. */
    float h = -(dx * L->nx + dy * L->ny + dz * L->nz);
    t->h[i] = h;
    float sb = h * L->ibehind + L->boff;
    sb = sb < 0.0f ? 0.0f : (sb > 1.0f ? 1.0f : sb);
    float sp = (1.0f - (b->nx[i] * L->nx + b->ny[i] * L->ny + b->nz[i] * L->nz)) * (1.0f / VSGL__CLIP_PARALLEL);
    sp = sp > 1.0f ? 1.0f : sp;
    float s = d2 * L->ivar;
    float wn = s / (s + VSGL__CLIP_NEAR);
    /* the parallel clip in the near field only: far away the receiver's own cosine does it */
    float par = 1.0f - (1.0f - sp * sp * (3.0f - 2.0f * sp)) * (1.0f - wn);
    float e = sb * sb * (3.0f - 2.0f * sb) * par;
    if (conv) {
        float c = h * r;
        c = c < 0.0f ? 0.0f : (c > 1.0f ? 1.0f : c);
        float rho = K_CLIP_RHO * c * k_exp(VSGL__COSINE_SHARPNESS * (1.0f - c));
        float w = wn * L->conv;
        e *= (1.0f - w) + w * rho;
    }
    float valid = (d2 > 0.0f ? 1.0f : L->valid) * vis * vsgl__part_keep(b, i, L);
    t->vis[i] = valid;
    t->amp[i] = valid * L->c0 * (1.0f - L->clip * (1.0f - e));
}

/* plane: a constant, 0 where no light of the call has a plane spread
 * (fore 0: specular lobes), which then take the round product alone */
static inline __attribute__((always_inline)) void
k_axis(const vsgl_kernel_block *restrict b, size_t i, const vsgl_kernel_light *restrict L, k_scratch *restrict t,
       const int plane, const int shear)
{
    K_SOURCE(shear);
    float r = t->r[i], d2 = t->d2[i];
    float rfloor = K_SHARP_MAX * r * r;
    float ivar = L->ivar < rfloor ? L->ivar : rfloor;
    float ls = d2 * ivar;
    float w = ls * r; /* |d| / var' */
    float mx = w * dx + L->lax, my = w * dy + L->lay, mz = w * dz + L->laz;
    float lin2 = mx * mx + my * my + mz * mz;
    float ilin = lin2 > VSGL__TINY ? k_rsqrt(lin2 > VSGL__TINY ? lin2 : 1.0f) : 0.0f;
    float lin = lin2 * ilin;
    t->amp[i] *= ivar;
    t->lin[i] = lin; t->ilin[i] = ilin;
    if (!plane) {
        t->ls[i] = ls;
        t->lden[i] = lin + L->lv + ls;
        t->xnum[i] = 0.0f;
        t->mx[i] = mx; t->my[i] = my; t->mz[i] = mz;
        return;
    }
    /* the product with the spread foreshortened and the distance lobe
     * (kernel.h, vsgl__plane_spread): m' = lf u + lv a - kd n_v; m keeps
     * m''s direction and the round |m|. The amplitude's exponent
     * |m'| - lf - lv - kd ce in the stable form (a = -n_v where kd > 0)
     * (kd^2 (1 - ce^2) + 2 lv kd (1 - ce) - lf lv |a - u|^2) / (|m'| + lf + lv + kd ce) */
    float ce = t->h[i] * r; /* k_geometry's height over the cluster's plane, h = -d.n_v */
    float kd;
    float lf = ls * vsgl__plane_spread(ce, L->fore, &kd);
    float wf = lf * r;
    float fx = wf * dx + L->lax - kd * L->nx, fy = wf * dy + L->lay - kd * L->ny, fz = wf * dz + L->laz - kd * L->nz;
    float lf2 = fx * fx + fy * fy + fz * fz;
    float ilf = lf2 > VSGL__TINY ? k_rsqrt(lf2 > VSGL__TINY ? lf2 : 1.0f) : 0.0f;
    float sc = lin * ilf;
    t->ls[i] = lf;
    t->lden[i] = lf2 * ilf + L->lv + lf + kd * ce;
    t->xnum[i] = kd * (kd * (1.0f - ce * ce) + 2.0f * L->lv * (1.0f - ce));
    t->mx[i] = fx * sc; t->my[i] = fy * sc; t->mz[i] = fz * sc;
}

static inline __attribute__((always_inline)) void
k_exponent(const vsgl_kernel_block *restrict b, size_t i, const vsgl_kernel_light *restrict L, k_scratch *restrict t,
           const int shear)
{
    /* the radiant intensity towards the lane: the lobe's, from the mean
     * (a sheared cluster's shifted source is where that light comes from) */
    float dx = L->mx - b->x[i], dy = L->my - b->y[i], dz = L->mz - b->z[i];
    float r = shear ? t->sr[i] : t->r[i], ls = t->ls[i];
    float ddx = L->ax - dx * r, ddy = L->ay - dy * r, ddz = L->az - dz * r;
    float diff2 = ddx * ddx + ddy * ddy + ddz * ddz;
    t->expo[i] = (t->xnum[i] - L->lv * ls * diff2) / (t->lden[i] + VSGL__TINY);
}

/* Stage 2: the amplitude's exp. */
static inline __attribute__((always_inline)) void k_amplitude(size_t i, k_scratch *restrict t)
{
    t->amp[i] *= k_exp(t->expo[i]);
}

/* Stage 3a (accurate cosine only): the part of the cosine integral that
 * depends on the incident sharpness alone. */
static inline __attribute__((always_inline)) void k_cosine_stage(size_t i, k_scratch *restrict t)
{
    k_cos_l o = k_cosine_lpart(t->lin[i]);
    t->low[i] = o.low; t->u[i] = o.u; t->t[i] = o.t; t->it[i] = o.it; t->kappa[i] = o.kappa; t->ct[i] = o.ct;
}

static inline __attribute__((always_inline)) void k_cosine_stage_sharp(size_t i, k_scratch *restrict t)
{
    k_cos_l o = k_cosine_lpart_sharp(t->lin[i]);
    t->low[i] = o.low; t->u[i] = o.u; t->t[i] = o.t; t->it[i] = o.it; t->kappa[i] = o.kappa; t->ct[i] = o.ct;
}

/* Stage 3a (VSGL__KERNEL_BURLEY blocks): Blender 3.x's Burley diffuse over
 * Lambert's for the pair, at the incident SG's mean direction l and the
 * lane's view o (scene/material.h vsgl__burley_factor): (1 + k FL)(1 + k FV),
 * k = r (1 + l.o) - 1/2, F = (1 - cos)^5; 1 for Lambert lanes. Taken per
 * pair, it follows where the light comes from: the hemisphere's mean
 * (vsgl__burley_albedo) overstated the retro-reflection of light arriving
 * from in front of a receiver seen from behind it (docs/units.md). */
static inline __attribute__((always_inline)) void
k_burley(const vsgl_kernel_block *restrict b, size_t i, k_scratch *restrict t)
{
    const float ilin = t->ilin[i], mx = t->mx[i], my = t->my[i], mz = t->mz[i];
    const float ox = b->ox[i], oy = b->oy[i], oz = b->oz[i];
    const float cl = (mx * b->nx[i] + my * b->ny[i] + mz * b->nz[i]) * ilin;
    const float cv = b->nx[i] * ox + b->ny[i] * oy + b->nz[i] * oz;
    const float s = (mx * ox + my * oy + mz * oz) * ilin;
    const float r = b->burley[i];
    const float f = vsgl__burley_factor(r, cl, cv, s);
    t->bfac[i] = r >= 0.0f ? f : 1.0f;
}

/* Stage 3: diffuse, the integral of the incident SG times max(w.n, 0), / pi,
 * times Burley's factor (1 unless k_burley ran: the kernel's entry sets it). */
static inline __attribute__((always_inline)) void
k_diffuse(vsgl_kernel_block *restrict b, size_t i, const vsgl_kernel_light *restrict L, int32_t mode,
          const k_scratch *restrict t, float ld_sharp, float ld_norm)
{
    float mx = t->mx[i], my = t->my[i], mz = t->mz[i], lin = t->lin[i], ilin = t->ilin[i];
    float mn = mx * b->nx[i] + my * b->ny[i] + mz * b->nz[i];
    float cosint;
    if (mode == K_COSINE_PULLED_OUT_SHARP) {
        /* every lobe of the block has lin >= K_SHARP_COSINE: e^{-2 lin} < 2e-28 */
        cosint = (mn > 0.0f ? mn : 0.0f) * (VSGL__2PI * ilin * ilin);
    } else if (mode == VSGL_COSINE_PULLED_OUT) {
        /* max(c, 0) A(lin) with c = m.n / lin, A(l) = 2 pi (1 - e^{-2l}) / l */
        float e = k_exp(-2.0f * lin);
        float big = VSGL__2PI * (1.0f - e) * ilin * ilin;
        float taylor = 4.0f * VSGL__PI * (1.0f - lin * (1.0f - lin * (2.0f / 3.0f))) * ilin;
        cosint = (mn > 0.0f ? mn : 0.0f) * (lin < 1e-3f ? taylor : big);
    } else if (mode == VSGL_COSINE_SG || mode == K_COSINE_SG_SHARP) {
        float qx = mx + ld_sharp * b->nx[i], qy = my + ld_sharp * b->ny[i], qz = mz + ld_sharp * b->nz[i];
        float lm2 = qx * qx + qy * qy + qz * qz;
        float ilm = k_rsqrt(lm2 > VSGL__TINY ? lm2 : VSGL__TINY);
        float lm = lm2 * ilm;
        float ex = mx * ilin - b->nx[i], ey = my * ilin - b->ny[i], ez = mz * ilin - b->nz[i];
        float dd = ex * ex + ey * ey + ez * ez;
        float alm = mode == K_COSINE_SG_SHARP ? VSGL__2PI * ilm : k_sg_integral(lm);
        cosint = k_exp(-lin * ld_sharp * dd / (lm + lin + ld_sharp)) * alm * ld_norm;
    } else {
        float c = mn * ilin;
        c = c > 1.0f ? 1.0f : (c < -1.0f ? -1.0f : c);
        k_cos_l o = {t->low[i], t->u[i], t->t[i], t->it[i], t->kappa[i], t->ct[i]};
        cosint = k_cosine_cpart_s(lin, c, o, mode == K_COSINE_ACCURATE_SHARP);
    }
    float ed = t->amp[i] * cosint * (1.0f / VSGL__PI) * b->diffuse[i] * t->bfac[i];
    b->ld[0][i] += L->pr * ed;
    b->ld[1][i] += L->pg * ed;
    b->ld[2][i] += L->pb * ed;
}

/* Stage 4: glossy, the ASG x SG product integral (Eq. 18), nu = lambda_in / 2:
 * h_x = nu lam / (nu + lam), h_y = nu mu / (nu + mu), norm = pi / sqrt((lam + nu)(mu + nu)),
 * all from one reciprocal square root of the product. */
static inline __attribute__((always_inline)) void
k_glossy(const vsgl_kernel_block *restrict b, size_t i, k_scratch *restrict t, float kb, float kc)
{
    float mx = t->mx[i], my = t->my[i], mz = t->mz[i], ilin = t->ilin[i];
    float nu = 0.5f * t->lin[i];
    float lam = b->lam[i] * kb, mu = b->mu[i] * kb;
    /* the incident axis in the lobe's frame, unnormalised (m = lin p) */
    float gx = mx * b->Xx[i] + my * b->Xy[i] + mz * b->Xz[i];
    float gy = mx * b->Yx[i] + my * b->Yy[i] + mz * b->Yz[i];
    float gz = mx * b->Zx[i] + my * b->Zy[i] + mz * b->Zz[i];
    float lamn = lam + nu, mun = mu + nu;
    float rp = k_rsqrt(lamn * mun + VSGL__TINY);
    float w2 = rp * rp * nu * ilin * ilin;
    float hx = lam * mun * w2;
    float hy = mu * lamn * w2;
    t->expo[i] = -hx * gx * gx - hy * gy * gy;
    /* the smooth-factor ratio (kernel.h, vsgl__smooth_ratio) towards where
     * the product peaks: the lobe's axis weighted by its sharpness (an ASG is
     * an SG of sharpness lam + mu about its axis, on average) and the
     * light's by its own, m = lin p */
    float lr = lam + mu;
    float qx = lr * b->Zx[i] + mx, qy = lr * b->Zy[i] + my, qz = lr * b->Zz[i] + mz;
    float ql = k_rsqrt(qx * qx + qy * qy + qz * qz + VSGL__TINY);
    float qn = (b->nx[i] * qx + b->ny[i] * qy + b->nz[i] * qz) * ql;
    float qo = (b->ox[i] * qx + b->oy[i] * qy + b->oz[i] * qz) * ql;
    float sh = vsgl__smooth_ratio(b->ga2[i], b->gso[i], b->gco[i], b->gia[i], b->gw[i], b->fe[i], b->fa[i], b->fb[i],
                                  qn, qo);
    t->gpre[i] = kc * b->camp[i] * (gz > 0.0f ? gz : 0.0f) * (VSGL__PI * rp * ilin) * t->amp[i] * sh;
}

/* Phi(z), the standard normal CDF, from k_erfc_poly (within 1.5e-7). */
static inline __attribute__((always_inline)) float k_ncdf(float z)
{
    float x = (z < 0.0f ? -z : z) * 0.70710678118654752f;
    float e = 0.5f * k_erfc_poly(x) * k_exp(-x * x);
    return z < 0.0f ? e : 1.0f - e;
}

/* The share of a planar cluster x footprint product above the receiver's
 * tangent plane (k_planar): d = mean - x, d1, e2 the footprint's offset and
 * s11.. idet its covariance S, all in sigma units; weighted in by how
 * close the lobe's axis is to the tangent plane or how far the cluster's
 * mean lies behind it (kernel.h VSGL__HORIZON_*, vsgl__behind_ramp). */
static inline __attribute__((always_inline)) float
k_horizon(const vsgl_kernel_block *restrict b, size_t i, const vsgl_kernel_light *restrict L, float dx, float dy,
          float dz, float d1, float e2, float s11, float s22, float s12, float idet)
{
    float nu1 = b->nx[i] * L->u1x + b->ny[i] * L->u1y + b->nz[i] * L->u1z;
    float nu2 = b->nx[i] * L->u2x + b->ny[i] * L->u2y + b->nz[i] * L->u2z;
    float g0 = (b->nx[i] * dx + b->ny[i] * dy + b->nz[i] * dz) +
               (nu1 * (s22 * d1 - s12 * e2) + nu2 * (s11 * e2 - s12 * d1)) * idet;
    float gv = nu1 * nu1 + nu2 * nu2 - (s22 * nu1 * nu1 - 2.0f * s12 * nu1 * nu2 + s11 * nu2 * nu2) * idet;
    gv = gv > 1e-12f ? gv : 1e-12f;
    float gw = vsgl__graze_ramp(b->Zx[i] * b->nx[i] + b->Zy[i] * b->ny[i] + b->Zz[i] * b->nz[i]);
    float gb = vsgl__behind_ramp(b->nx[i] * dx + b->ny[i] * dy + b->nz[i] * dz);
    gw = gw > gb ? gw : gb;
    return 1.0f - (1.0f - k_ncdf(g0 * k_rsqrt(gv))) * gw * gw * (3.0f - 2.0f * gw);
}

/* Stage 4b: glossy light from a planar cluster (shade.h, vsgl__planar_glossy):
 * the radiance of the cluster's plane where the lobe's axis meets it,
 * blurred by the lobe's footprint there. First what every lobe of the lane
 * shares (the axis's hit on the plane and the footprint's frame there),
 * then per lobe (k_planar_lobe) all but the exp. */
static inline __attribute__((always_inline)) void
k_planar_geom(const vsgl_kernel_block *restrict b, size_t i, const vsgl_kernel_light *restrict L, k_scratch *restrict t,
              int tilt, const float *restrict tphi, const float *restrict td)
{
    /* lengths in units of the cluster's sigma, so that nothing overflows:
     * the axis must meet the plane at t <= 1e4 sigma and >= 0.6 degrees
     * off it, faded in up to 2.9 degrees (kernel.h VSGL__PLANAR_NZ_*) */
    float dx = L->mx - b->x[i], dy = L->my - b->y[i], dz = L->mz - b->z[i];
    float d2 = t->d2[i];
    float var = L->pvar > d2 * 4.547473508864641e-13f ? L->pvar : d2 * 4.547473508864641e-13f;
    var = var > VSGL__TINY ? var : VSGL__TINY;
    float is = k_rsqrt_fine(var); /* the offsets scale with it and q amplifies their error */
    float h = t->h[i] * is;
    float nxd = b->Xx[i] * L->nx + b->Xy[i] * L->ny + b->Xz[i] * L->nz;
    float nyd = b->Yx[i] * L->nx + b->Yy[i] * L->ny + b->Yz[i] * L->nz;
    /* at the plane's horizon the lobe's share that meets it, about an axis
     * tilted towards it (kernel.h, vsgl__planar_tilt; the lane's part from
     * the block's table of the plane's axis); `tilt` 0: no lane of the
     * block needs it */
    float nz0 = b->Zx[i] * L->nx + b->Zy[i] * L->ny + b->Zz[i] * L->nz;
    float zx = b->Zx[i], zy = b->Zy[i], zz = b->Zz[i], nz = nz0, share = 1.0f;
    if (tilt) {
        float tp, tq;
        share = vsgl__planar_tilt(nz0, tphi[i], td[i], L->tilt * vsgl__planar_tilt_gate(h), &tp, &tq);
        zx = tp * zx - tq * L->nx;
        zy = tp * zy - tq * L->ny;
        zz = tp * zz - tq * L->nz;
        nz = tp * nz0 - tq;
    }
    float ok = (h > 0.0f ? 1.0f : 0.0f) * vsgl__planar_nz_weight(nz) * share;
    float inz = 1.0f / (nz < -VSGL__PLANAR_NZ_MIN ? nz : -VSGL__PLANAR_NZ_MIN);
    float tt = -h * inz;
    tt = tt < 1e4f ? (tt > 0.0f ? tt : 0.0f) : 1e4f;
    float zu1 = zx * L->u1x + zy * L->u1y + zz * L->u1z, zu2 = zx * L->u2x + zy * L->u2y + zz * L->u2z;
    float xu1 = b->Xx[i] * L->u1x + b->Xy[i] * L->u1y + b->Xz[i] * L->u1z;
    float xu2 = b->Xx[i] * L->u2x + b->Xy[i] * L->u2y + b->Xz[i] * L->u2z;
    float yu1 = b->Yx[i] * L->u1x + b->Yy[i] * L->u1y + b->Yz[i] * L->u1z;
    float yu2 = b->Yx[i] * L->u2x + b->Yy[i] * L->u2y + b->Yz[i] * L->u2z;
    float fx = nxd * inz, fy = nyd * inz;
    t->pa1[i] = tt * (xu1 - zu1 * fx);
    t->pa2[i] = tt * (xu2 - zu2 * fx);
    t->pb1[i] = tt * (yu1 - zu1 * fy);
    t->pb2[i] = tt * (yu2 - zu2 * fy);
    /* the offset from the cluster's mean to where the axis meets its plane: t z - (mean - x) */
    float ox = tt * zx - dx * is, oy = tt * zy - dy * is, oz = tt * zz - dz * is;
    t->pd1[i] = ox * L->u1x + oy * L->u1y + oz * L->u1z;
    t->pd2[i] = ox * L->u2x + oy * L->u2y + oz * L->u2z;
    t->pis[i] = is;
    t->pok[i] = ok * t->vis[i] * b->camp[i] * (is * is);
    t->pt[i] = tt;
    t->pz1[i] = zu1;
    t->pz2[i] = zu2;
}

/* One lobe (kb, kc) of k_planar_geom's lane: the footprint's covariance,
 * the density's exponent into pexpo and its factor into ppre. */
static inline __attribute__((always_inline)) void
k_planar_lobe(const vsgl_kernel_block *restrict b, size_t i, const vsgl_kernel_light *restrict L,
              k_scratch *restrict t, float kb, float kc, int graze)
{
    const float a1 = t->pa1[i], a2 = t->pa2[i], b1 = t->pb1[i], b2 = t->pb2[i], d1 = t->pd1[i], e2 = t->pd2[i];
    float lam = b->lam[i] * kb, mu = b->mu[i] * kb;
    lam = lam > 0.01f ? lam : 0.01f;
    mu = mu > 0.01f ? mu : 0.01f;
    float il = 0.5f / lam, im = 0.5f / mu;
    float s11 = 1.0f + a1 * a1 * il + b1 * b1 * im;
    float s22 = 1.0f + a2 * a2 * il + b2 * b2 * im;
    float s12 = a1 * a2 * il + b1 * b2 * im;
    /* det = 1 + tr(A) + det(A), A the footprint: no cancellation */
    float cr = a1 * b2 - a2 * b1;
    float fd = cr * cr * il * im;
    float det = s11 + s22 - 1.0f + fd;
    float idet = 1.0f / det;
    /* the footprint at the distance where the lobe meets the cluster
     * (kernel.h, vsgl__planar_reach): ym - mean = S^-1 d, r = ym - y0 */
    float reach;
    {
        const float r1 = (s22 * d1 - s12 * e2) * idet - d1, r2 = (s11 * e2 - s12 * d1) * idet - e2;
        const float k2 = vsgl__planar_reach(t->pt[i], r1, r2, t->pz1[i], t->pz2[i], 1.0f, &reach);
        s11 = 1.0f + k2 * (s11 - 1.0f);
        s22 = 1.0f + k2 * (s22 - 1.0f);
        s12 *= k2;
        det = s11 + s22 - 1.0f + k2 * k2 * fd;
        idet = 1.0f / det;
    }
    float qf = (s22 * d1 * d1 - 2.0f * s12 * d1 * e2 + s11 * e2 * e2) * idet;
    t->pexpo[i] = qf > 0.0f ? -0.5f * qf : 0.0f;
    /* the receiver's horizon where its lobe grazes it (kernel.h,
     * VSGL__HORIZON_*): the share of the cluster x footprint product (mean
     * S^-1 d, covariance I - S^-1 in sigma units) above the receiver's
     * tangent plane, along nu, the normal's part in the cluster's plane;
     * `graze` 0 (no lane of the block grazes: VSGL__KERNEL_GRAZE): 1 */
    float hz = 1.0f;
    float is = t->pis[i];
    float dx = (L->mx - b->x[i]) * is, dy = (L->my - b->y[i]) * is, dz = (L->mz - b->z[i]) * is;
    if (graze)
        hz = k_horizon(b, i, L, dx, dy, dz, d1, e2, s11, s22, s12, idet);
    /* the smooth-factor ratio (kernel.h, vsgl__smooth_ratio) towards the
     * product's mean on the plane, mean + S^-1 d (sigma units) */
    float pm1 = (s22 * d1 - s12 * e2) * idet, pm2 = (s11 * e2 - s12 * d1) * idet;
    float yx = dx + pm1 * L->u1x + pm2 * L->u2x, yy = dy + pm1 * L->u1y + pm2 * L->u2y,
          yz = dz + pm1 * L->u1z + pm2 * L->u2z;
    float yl = k_rsqrt(yx * yx + yy * yy + yz * yz + 1e-30f);
    float yn = (b->nx[i] * yx + b->ny[i] * yy + b->nz[i] * yz) * yl;
    float yo = (b->ox[i] * yx + b->oy[i] * yy + b->oz[i] * yz) * yl;
    float sh = vsgl__smooth_ratio(b->ga2[i], b->gso[i], b->gco[i], b->gia[i], b->gw[i], b->fe[i], b->fa[i], b->fb[i],
                                  yn, yo);
    t->ppre[i] = t->pok[i] * reach * hz * sh * kc * (1.0f / VSGL__2PI) * k_rsqrt(det * lam * mu);
    t->ps11[i] = s11;
    t->ps22[i] = s22;
    t->ps12[i] = s12;
    t->pidet[i] = idet;
}

/* Stage 4d (planar clusters, GGX as lobes; kernel.h VSGL__HV_*, shade/
 * halfvec.c has the same in scalar form and the derivation): the
 * half-vector model's weight and what its lobes share. The cluster is a
 * Gaussian of directions about w = (mean - x) / d, covariance var/d^2 (P -
 * p p^T) (P the projection off w, p the cluster's normal projected off w);
 * the half vector h = (o + w) / |o + w| has slope s = (h.t, h.u) / h.n in
 * the receiver's frame (t, u, n), and a change dl of the light's direction
 * moves it by J dl, J's rows (I - h h^T)(e - s_e n) / (h.n |o + w|). */
static inline __attribute__((always_inline)) void
k_hv_shared(const vsgl_kernel_block *restrict b, size_t i, const vsgl_kernel_light *restrict L, k_scratch *restrict t)
{
    float r = t->r[i];
    float wx = (L->mx - b->x[i]) * r, wy = (L->my - b->y[i]) * r, wz = (L->mz - b->z[i]) * r;
    float nx = b->nx[i], ny = b->ny[i], nz = b->nz[i];
    /* a tangent frame of the normal: the lobe's X made perpendicular to it */
    float xd = b->Xx[i] * nx + b->Xy[i] * ny + b->Xz[i] * nz;
    float tx = b->Xx[i] - xd * nx, ty = b->Xy[i] - xd * ny, tz = b->Xz[i] - xd * nz;
    float tl = k_rsqrt(tx * tx + ty * ty + tz * tz + 1e-24f);
    tx *= tl; ty *= tl; tz *= tl;
    float ux = ny * tz - nz * ty, uy = nz * tx - nx * tz, uz = nx * ty - ny * tx;
    float hx = b->ox[i] + wx, hy = b->oy[i] + wy, hz = b->oz[i] + wz;
    float im = k_rsqrt(hx * hx + hy * hy + hz * hz + 1e-24f);
    hx *= im; hy *= im; hz *= im;
    float hn = hx * nx + hy * ny + hz * nz;
    float hnc = hn > 0.1f ? hn : 0.1f; /* below VSGL__HV_HN_LO the weight is 0 anyway */
    float ihn = 1.0f / hnc;
    float s1 = (hx * tx + hy * ty + hz * tz) * ihn, s2 = (hx * ux + hy * uy + hz * uz) * ihn;
    float e1x = tx - s1 * nx, e1y = ty - s1 * ny, e1z = tz - s1 * nz;
    float e2x = ux - s2 * nx, e2y = uy - s2 * ny, e2z = uz - s2 * nz;
    float he1 = hx * e1x + hy * e1y + hz * e1z, he2 = hx * e2x + hy * e2y + hz * e2z;
    float sc = ihn * im;
    float a1x = (e1x - he1 * hx) * sc, a1y = (e1y - he1 * hy) * sc, a1z = (e1z - he1 * hz) * sc;
    float a2x = (e2x - he2 * hx) * sc, a2y = (e2y - he2 * hy) * sc, a2z = (e2z - he2 * hz) * sc;
    float nc = wx * L->nx + wy * L->ny + wz * L->nz;
    float px = L->nx - nc * wx, py = L->ny - nc * wy, pz = L->nz - nc * wz;
    float a1w = a1x * wx + a1y * wy + a1z * wz, a2w = a2x * wx + a2y * wy + a2z * wz;
    float a1p = a1x * px + a1y * py + a1z * pz, a2p = a2x * px + a2y * py + a2z * pz;
    /* clamped far past VSGL__HV_SPREAD_HI (the weight is 0 there anyway):
     * a receiver within ~1e-6 of the mean (a scene 1e5 from the origin
     * quantises positions to 8 mm) made var r^2 ~1e23, k_hv_lobe's
     * determinant overflowed to inf and its rsqrt gave 0 x NaN = NaN */
    float sv = L->var * r * r;
    sv = sv < 1e3f * VSGL__HV_SPREAD_HI ? sv : 1e3f * VSGL__HV_SPREAD_HI;
    t->hc11[i] = sv * (a1x * a1x + a1y * a1y + a1z * a1z - a1w * a1w - a1p * a1p);
    t->hc22[i] = sv * (a2x * a2x + a2y * a2y + a2z * a2z - a2w * a2w - a2p * a2p);
    t->hc12[i] = sv * (a1x * a2x + a1y * a2y + a1z * a2z - a1w * a2w - a1p * a2p);
    t->hs1[i] = s1;
    t->hs2[i] = s2;
    /* w, p and o in the frame (t, u, n), and the spread, for k_hv_lobe */
    t->hwt[i] = wx * tx + wy * ty + wz * tz;
    t->hwu[i] = wx * ux + wy * uy + wz * uz;
    t->hwn[i] = wx * nx + wy * ny + wz * nz;
    t->hpt[i] = px * tx + py * ty + pz * tz;
    t->hpu[i] = px * ux + py * uy + pz * uz;
    t->hpn[i] = px * nx + py * ny + pz * nz;
    t->hot[i] = b->ox[i] * tx + b->oy[i] * ty + b->oz[i] * tz;
    t->hou[i] = b->ox[i] * ux + b->oy[i] * uy + b->oz[i] * uz;
    t->hon[i] = b->ox[i] * nx + b->oy[i] * ny + b->oz[i] * nz;
    t->hsv[i] = sv;
    /* the weight: small spread, half vector well above the horizon, a lane with alpha */
    float ws = (VSGL__HV_SPREAD_HI - sv) * (1.0f / (VSGL__HV_SPREAD_HI - VSGL__HV_SPREAD_LO));
    ws = ws < 0.0f ? 0.0f : (ws > 1.0f ? 1.0f : ws);
    float wh = (hn - VSGL__HV_HN_LO) * (1.0f / (VSGL__HV_HN_HI - VSGL__HV_HN_LO));
    wh = wh < 0.0f ? 0.0f : (wh > 1.0f ? 1.0f : wh);
    float w = ws * ws * (3.0f - 2.0f * ws) * wh * wh * (3.0f - 2.0f * wh);
    float a = b->alpha[i];
    float h = t->h[i];
    w = a > 0.0f && h > 0.0f ? w : 0.0f;
    t->hvw[i] = w;
    /* Smith's shadowing-masking with the light's direction over the one
     * with the lobe's axis, where M (f0r..) is taken: here at w (a lobe
     * that linearises elsewhere takes its own, k_hv_lobe) */
    float a2 = a * a;
    float co = b->ox[i] * nx + b->oy[i] * ny + b->oz[i] * nz;
    co = co > 1e-4f ? co : 1e-4f;
    float ci = wx * nx + wy * ny + wz * nz;
    ci = ci > 0.0f ? ci : 0.0f;
    float ca = b->Zx[i] * nx + b->Zy[i] * ny + b->Zz[i] * nz;
    ca = ca > 1e-4f ? ca : 1e-4f;
    float so = sqrtf(a2 + (1.0f - a2) * co * co);
    float gc = ci / (ci * so + co * sqrtf(a2 + (1.0f - a2) * ci * ci));
    float ga = ca / (ca * so + co * sqrtf(a2 + (1.0f - a2) * ca * ca));
    float ih2 = ihn * ihn;
    /* D's 1 / h.n^4, G and the dielectric Fresnel towards w over M's at the axis */
    float fr = b->fa[i] + b->fb[i] * vsgl__fresnel_dielectric(wx * hx + wy * hy + wz * hz, b->fe[i]);
    t->hfw[i] = ih2 * ih2 * gc * fr;
    t->hso[i] = so;
    /* radiance N / pi, the emitter's cos / d^2 = h r^3, over G at the axis */
    float pre = w * t->vis[i] * h * r * r * r * (1.0f / VSGL__PI) / ga;
    t->hpre[i] = w > 0.0f ? pre : 0.0f; /* a select: r^3 overflows where w is 0 (a receiver at the mean) */
}

/* One lobe (k, c) of the half-vector model: the lobe's slope covariance
 * alpha^2 / 2k plus the cluster's, evaluated at s: into ppre, pexpo.
 * Linearised at w alone, a wide cluster seen at a grazing view was wrong
 * by orders of magnitude (the slope (o + l).t / (o + l).n changes fast and
 * not linearly across it where (o + l).n is small: halfvec.c). The lobe
 * linearises again where its product with the cluster's slope Gaussian
 * peaks: slope q = al2 (al2 I + C)^-1 s, half vector g = (n + q1 t + q2
 * u) / |.|, light direction le = 2 (o.g) g - o. The Jacobian's rows there
 * are (t - q1 n) and (u - q2 n) over g.n |o + le| = 2 (o.g) / |n + q1 t +
 * q2 u|^2 (g is orthogonal to both), so everything is a dot product in the
 * frame (t, u, n) that k_hv_shared stored: w's slope through it q + J (w -
 * le) (a row e's dot product with le is q_e o.n - o.e, over g.n |o + le|),
 * the cluster's covariance, and D's 1 / g.n^4 = |n + q1 t + q2 u|^4, G and
 * F at le (le.n = 2 (o.g) g.n - o.n, le.g = o.g). Where o.g is not positive (no such mirror direction),
 * w's stand, as they do for the broad lobes past VSGL__HV_RELIN (relin 0):
 * their product peaks near w but for the widest clusters, and they hold
 * a sixth of GGX's energy. */
static inline __attribute__((always_inline)) void
k_hv_lobe(const vsgl_kernel_block *restrict b, size_t i, k_scratch *restrict t, float kb, float kc, const int relin)
{
    float a = b->alpha[i];
    float al2 = a * a * (0.5f / kb);
    float s1 = t->hs1[i], s2 = t->hs2[i], c11 = t->hc11[i], c22 = t->hc22[i], c12 = t->hc12[i];
    float m11 = al2 + c11, m22 = al2 + c22, md = m11 * m22 - c12 * c12;
    float imd = al2 / (md > 1e-30f ? md : 1e-30f);
    float q1 = (m22 * s1 - c12 * s2) * imd, q2 = (m11 * s2 - c12 * s1) * imd;
    float gg = 1.0f + q1 * q1 + q2 * q2, ig = k_rsqrt(gg); /* |n + q1 t + q2 u|^2, g.n */
    float ot = t->hot[i], ou = t->hou[i], on = t->hon[i];
    float oh = (on + q1 * ot + q2 * ou) * ig;
    int moved = relin & (oh > 1e-4f) & (md > 1e-30f);
    float ohc = oh > 1e-4f ? oh : 1e-4f;
    float k2 = 2.0f * ohc * ig; /* g.n |o + le| */
    float sce = 1.0f / k2;
    float wn = t->hwn[i], pn = t->hpn[i];
    float bw1 = (t->hwt[i] - q1 * wn) * sce, bw2 = (t->hwu[i] - q2 * wn) * sce;
    float bp1 = (t->hpt[i] - q1 * pn) * sce, bp2 = (t->hpu[i] - q2 * pn) * sce;
    float bl1 = (q1 * on - ot) * sce, bl2 = (q2 * on - ou) * sce;
    float sv = t->hsv[i], sc2 = sce * sce;
    c11 = moved ? sv * (sc2 * (1.0f + q1 * q1) - bw1 * bw1 - bp1 * bp1) : c11;
    c22 = moved ? sv * (sc2 * (1.0f + q2 * q2) - bw2 * bw2 - bp2 * bp2) : c22;
    c12 = moved ? sv * (sc2 * q1 * q2 - bw1 * bw2 - bp1 * bp2) : c12;
    s1 = moved ? q1 + bw1 - bl1 : s1;
    s2 = moved ? q2 + bw2 - bl2 : s2;
    /* D's 1 / g.n^4, G and F at le (k_hv_shared's at w where not moved) */
    float co = on > 1e-4f ? on : 1e-4f;
    float ci = k2 - on;
    ci = ci > 0.0f ? ci : 0.0f;
    float a2 = a * a;
    float gc = ci / (ci * t->hso[i] + co * sqrtf(a2 + (1.0f - a2) * ci * ci));
    float fr = b->fa[i] + b->fb[i] * vsgl__fresnel_dielectric(ohc, b->fe[i]);
    float fw = t->hfw[i]; /* loaded unconditionally: a load in a select stops GCC's if-conversion */
    float f = moved ? gg * gg * gc * fr : fw;
    c11 += al2;
    c22 += al2;
    float det = c11 * c22 - c12 * c12;
    det = det > 1e-30f ? det : 1e-30f;
    float q = (c22 * s1 * s1 - 2.0f * c12 * s1 * s2 + c11 * s2 * s2) / det;
    t->pexpo[i] = q > 0.0f ? -0.5f * q : 0.0f;
    float pp = t->hpre[i] * f * (kc / kb) * (0.5f / VSGL__PI) * k_rsqrt(det);
    t->ppre[i] = t->hpre[i] > 0.0f ? pp : 0.0f; /* a select: lanes of weight 0 may hold inf (k_hv_shared) */
}

/* The planar model's share where the half-vector model takes over. */
static inline __attribute__((always_inline)) void k_hv_rest(size_t i, k_scratch *restrict t)
{
    t->ppre[i] *= 1.0f - t->hvw[i];
}

/* Along one axis of a cut cell (sigma units, the cluster's mean at 0 and
 * its variance 1): the weight of the image of mean m (fs: the mean the
 * images are built on, 2 lo - fs: mirrored across the low cut lo, 2 hi -
 * fs: across the high cut hi,
 * `which` 0, 1, 2), its footprint-blurred density's share on the
 * surface's side of each cut, weighted by the cuts' weights al, ah
 * (shade.c, fold_image: the product of the cluster's Gaussian and the
 * footprint's about y, variance f2, is a Gaussian of mean (m f2 + y) / (1
 * + f2) and variance f2 / (1 + f2)). Branch-free: the lane loop vectorises. */
static inline __attribute__((always_inline)) float k_fold_weight(float lo, float hi, float al, float ah, float m,
                                                                 int which, float y, float f2, float i1, float isp)
{
    float mp = (m * f2 + y) * i1;
    float tl = k_ncdf((mp - lo) * isp), th = k_ncdf((hi - mp) * isp);
    float wl = 1.0f - al + al * tl, wh = 1.0f - ah + ah * th;
    return which == 0 ? wl * wh : which == 1 ? al * tl * wh : ah * th * wl;
}

/* Stage 4c (a lattice cell cut by its surface's end, L->fold > 0): the
 * planar model's density with the cluster's Gaussian folded back at each
 * cut (an image mirrored across it), every image kept to the surface's
 * side (shade.c, vsgl__planar_glossy), blended in by L->fold; into ppre,
 * with pexpo 0. Images of a side without a cut have weight 0.
 * cuts: the light's cut sides as bits (1, 2: axis u1's low and high side,
 * 4, 8: u2's; k_fold_cuts), a constant in each caller's loop: a side
 * without a cut has al or ah 0, so its image's weight is 0 and the others'
 * factor for it 1, and neither is computed (a junction's cell is cut on
 * one side: 2 images of 9, 4 exps of 21). */
#define K_FOLD_ALL 15

static inline __attribute__((always_inline)) int k_fold_cuts(const vsgl_kernel_light *L)
{
    return (L->fa[0][0] > 0.0f ? 1 : 0) | (L->fa[0][1] > 0.0f ? 2 : 0) | (L->fa[1][0] > 0.0f ? 4 : 0) |
           (L->fa[1][1] > 0.0f ? 8 : 0);
}

/* Along one axis (ax) with cut sides lo, hi (constants): the images'
 * weights w[3] (k_fold_weight), those of an uncut side's image 0. */
static inline __attribute__((always_inline)) void
k_fold_axis(const vsgl_kernel_light *restrict L, int ax, int lo, int hi, float y, float f, float *m, float *w)
{
    m[0] = L->fs[ax];
    m[1] = 2.0f * L->fb[ax][0] - L->fs[ax];
    m[2] = 2.0f * L->fb[ax][1] - L->fs[ax];
    w[0] = 1.0f;
    w[1] = w[2] = 0.0f;
    if (!lo && !hi)
        return;
    const float i1 = 1.0f / (1.0f + f), isp = k_rsqrt_fine(f * i1);
    const float bl = L->fb[ax][0], bh = L->fb[ax][1], al = L->fa[ax][0], ah = L->fa[ax][1];
    if (lo && hi) { /* (no loop: a loop inside the lanes' loop stops its vectorisation) */
        w[0] = k_fold_weight(bl, bh, al, ah, m[0], 0, y, f, i1, isp);
        w[1] = k_fold_weight(bl, bh, al, ah, m[1], 1, y, f, i1, isp);
        w[2] = k_fold_weight(bl, bh, al, ah, m[2], 2, y, f, i1, isp);
    } else if (lo) { /* ah = 0: wh = 1 */
        float tl0 = k_ncdf(((m[0] * f + y) * i1 - bl) * isp), tl1 = k_ncdf(((m[1] * f + y) * i1 - bl) * isp);
        w[0] = 1.0f - al + al * tl0;
        w[1] = al * tl1;
    } else { /* al = 0: wl = 1 */
        float th0 = k_ncdf((bh - (m[0] * f + y) * i1) * isp), th2 = k_ncdf((bh - (m[2] * f + y) * i1) * isp);
        w[0] = 1.0f - ah + ah * th0;
        w[2] = ah * th2;
    }
}

static inline __attribute__((always_inline)) void
k_fold(size_t i, const vsgl_kernel_light *restrict L, k_scratch *restrict t, const int cuts)
{
    const float d1 = t->pd1[i], d2 = t->pd2[i], s11 = t->ps11[i], s22 = t->ps22[i], s12 = t->ps12[i];
    const float idet = t->pidet[i];
    float f1 = s11 - 1.0f, f2 = s22 - 1.0f;
    f1 = f1 > 1e-12f ? f1 : 1e-12f;
    f2 = f2 > 1e-12f ? f2 : 1e-12f;
    float m1[3], m2[3], w1[3], w2[3];
    k_fold_axis(L, 0, cuts & 1, cuts & 2, d1, f1, m1, w1);
    k_fold_axis(L, 1, cuts & 4, cuts & 8, d2, f2, m2, w2);
    /* the images of a side with a cut: 0 always, 1 below a low cut, 2 above
     * a high one; the terms unrolled, each under a constant condition */
    float sum = 0.0f;
#define K_FOLD_ON(ax, a) ((a) == 0 || (cuts & (((a) == 1 ? 1 : 2) << (2 * (ax)))))
#define K_FOLD_TERM(a, c)                                                                                       \
    do {                                                                                                        \
        if (K_FOLD_ON(0, a) && K_FOLD_ON(1, c)) {                                                               \
            float e1 = d1 - m1[a], e2 = d2 - m2[c];                                                             \
            float q = (s22 * e1 * e1 - 2.0f * s12 * e1 * e2 + s11 * e2 * e2) * idet;                            \
            sum += w1[a] * w2[c] * k_exp(q > 0.0f ? -0.5f * q : 0.0f);                                         \
        }                                                                                                       \
    } while (0)
    K_FOLD_TERM(0, 0);
    K_FOLD_TERM(1, 0);
    K_FOLD_TERM(2, 0);
    K_FOLD_TERM(0, 1);
    K_FOLD_TERM(1, 1);
    K_FOLD_TERM(2, 1);
    K_FOLD_TERM(0, 2);
    K_FOLD_TERM(1, 2);
    K_FOLD_TERM(2, 2);
#undef K_FOLD_TERM
#undef K_FOLD_ON
    t->ppre[i] *= (1.0f - L->fold) * k_exp(t->pexpo[i]) + L->fold * sum;
    t->pexpo[i] = 0.0f;
}

/* Stage 5: the glossy lobe's exp and the accumulation, with the smooth
 * Fresnel/shadowing factor per receiver at its lobe axis (Xu et al. Eq. 30:
 * M(z, o)), precomputed per lane and channel. */
static inline __attribute__((always_inline)) void
k_glossy_sum(vsgl_kernel_block *restrict b, size_t i, const vsgl_kernel_light *restrict L, const k_scratch *restrict t,
             int form)
{
    float gint;
    if (form == 0)       /* the SG model alone */
        gint = t->gpre[i] * k_exp(t->expo[i]);
    else if (form == 1)  /* the planar model alone */
        gint = t->ppre[i] * k_exp(t->pexpo[i]);
    else if (form == 3) /* the half-vector model (its weight in ppre) */
        gint = t->pw[i] * t->ppre[i] * k_exp(t->pexpo[i]);
    else
        gint = (1.0f - t->pw[i]) * t->gpre[i] * k_exp(t->expo[i]) + t->pw[i] * t->ppre[i] * k_exp(t->pexpo[i]);
    b->ls[0][i] += L->pr * gint * b->f0r[i];
    b->ls[1][i] += L->pg * gint * b->f0g[i];
    b->ls[2][i] += L->pb * gint * b->f0b[i];
}

/* Each stage is one loop over the block's receivers; with NL = 2 VSGLs per
 * pass (the j loop is unrolled before vectorisation), every loop body holds
 * two independent chains, which the core overlaps. Sums are added in VSGL
 * order, as one VSGL at a time would. */
/* one VSGL's stage: lanes i */
#define K_FORI(STMT)                                   \
    for (size_t i = 0; i < VSGL__KERNEL_BLOCK; ++i) \
        STMT

#define K_FORN(STMT)                                   \
    for (size_t i = 0; i < VSGL__KERNEL_BLOCK; ++i) \
        for (int j = 0; j < NL; ++j)                   \
            STMT

/* A VSGL that is faint at every lane of the block: its radiant intensity
 * towards each lane (the amplitude's exponent, k_exponent) below e^lcut of
 * its peak. The stages after the amplitude then add less than that share
 * of what it would add in its lobe's direction, and are skipped: an SG's
 * light beyond where it falls to e^lcut is about that share of all of it
 * (docs/pipeline.md, "Faint pairs"). Only where every term scales with
 * the amplitude: not for planar clusters (L->planar > 0), whose planar
 * and half-vector models take the cluster's plane. */
static inline __attribute__((always_inline)) int k_faint(const vsgl_kernel_light *restrict L,
                                                         const k_scratch *restrict t, float lcut)
{
    if (L->planar > 0.0f)
        return 0;
    float m = -1e30f;
    for (size_t i = 0; i < VSGL__KERNEL_BLOCK; ++i)
        m = t->expo[i] > m ? t->expo[i] : m;
    return m < lcut;
}

/* The diffuse stages of VSGLs L[0, NL) (k_shade). */
static inline __attribute__((always_inline)) void
k_diffuse_lights(vsgl_kernel_block *restrict b, const vsgl_kernel_light *restrict L, const int NL, int32_t mode,
                 k_scratch *restrict t, const int burley)
{
    if (burley)
        K_FORN(k_burley(b, i, t + j));
    /* the poster's SG-cosine lobe: constants (no call on the hot path) */
    const float ld_sharp = VSGL__COSINE_SHARPNESS;
    const float ld_norm = VSGL__PI / k_sg_integral(VSGL__COSINE_SHARPNESS);
    /* blocks where every incident lobe is sharp take short forms */
    float lmin = K_SHARP_MAX;
    K_FORN(lmin = t[j].lin[i] < lmin ? t[j].lin[i] : lmin);
    int sharp = lmin >= K_SHARP_COSINE;
    /* one loop per form, the form a constant in each */
#define K_DIFFUSE(FORM) K_FORN(k_diffuse(b, i, L + j, (FORM), t + j, ld_sharp, ld_norm))
    switch (mode) {
    case VSGL_COSINE_SG:
        if (sharp) K_DIFFUSE(K_COSINE_SG_SHARP); else K_DIFFUSE(VSGL_COSINE_SG);
        break;
    case VSGL_COSINE_PULLED_OUT:
        if (sharp) K_DIFFUSE(K_COSINE_PULLED_OUT_SHARP); else K_DIFFUSE(VSGL_COSINE_PULLED_OUT);
        break;
    default:
        if (sharp) {
            K_FORN(k_cosine_stage_sharp(i, t + j));
            K_DIFFUSE(K_COSINE_ACCURATE_SHARP);
        } else {
            K_FORN(k_cosine_stage(i, t + j));
            K_DIFFUSE(VSGL_COSINE_ACCURATE);
        }
        break;
    }
#undef K_DIFFUSE
}

/* The glossy stages of VSGLs L[0, NL) (k_shade). */
static inline __attribute__((always_inline)) void
k_glossy_lights(vsgl_kernel_block *restrict b, const vsgl_kernel_light *restrict L, const int NL, int32_t lobes,
                k_scratch *restrict t)
{
    /* the SG model, the planar one (coherent diffuse clusters) or a blend */
    int all_planar = 1, none_planar = 1;
    for (int j = 0; j < NL; ++j) {
        all_planar &= L[j].planar == 1.0f;
        none_planar &= L[j].planar == 0.0f;
    }
    /* one ASG, or GGX's core and tail as two (kernel.h, VSGL__KERNEL_GGX_TAIL) */
    const int two = (lobes & VSGL__KERNEL_GGX_TAIL) != 0;
    /* with GGX as lobes, planar clusters that subtend little are taken
     * by the half-vector model (kernel.h VSGL__HV_*) */
    int hv = 0, hv_all = 1;
    if (two && !none_planar) {
        K_FORN(k_hv_shared(b, i, L + j, t + j));
        for (int j = 0; j < NL; ++j)
            for (size_t i = 0; i < VSGL__KERNEL_BLOCK; ++i) {
                hv |= t[j].hvw[i] > 0.0f;
                hv_all &= t[j].hvw[i] == 1.0f;
            }
    }
    /* the planar model's weight per lane, once per block and VSGL: the
     * cluster's own (coherence^2) but on a bumpy surface's own receivers */
    if (!none_planar)
        for (int j = 0; j < NL; ++j) {
            if (L[j].bump > 0.0f)
                K_FORI(t[j].pw[i] = vsgl__planar_weight(L[j].planar, L[j].bump,
                                                        b->nx[i] * L[j].nx + b->ny[i] * L[j].ny + b->nz[i] * L[j].nz));
            else
                K_FORI(t[j].pw[i] = L[j].planar);
        }
    /* planar clusters that every lane sees through the half-vector
     * model alone: the lobes' pass would add zeros */
    const int skip_lobes = hv && hv_all && all_planar;
    /* the receiver's horizon only in blocks where some lane's lobe grazes it */
    const int graze = (lobes & VSGL__KERNEL_GRAZE) != 0;
    if (!skip_lobes && !none_planar) {
        /* the horizon's tilt only in blocks where some lane's lobe nears a
         * flat cluster's horizon (kernel.h, vsgl__planar_tilt_needed) */
        int tilt = 0;
        for (int j = 0; j < NL; ++j)
            tilt |= L[j].tilt > 0.0f && b->tany[L[j].tdir];
        if (tilt) {
            for (int j = 0; j < NL; ++j) { /* each VSGL that tilts with the rows of its plane in the block's tables */
                if (L[j].tilt > 0.0f && b->tany[L[j].tdir]) {
                    const float *restrict tphi = b->tphi[L[j].tdir], *restrict td = b->td[L[j].tdir];
                    K_FORI(k_planar_geom(b, i, L + j, t + j, 1, tphi, td));
                } else {
                    K_FORI(k_planar_geom(b, i, L + j, t + j, 0, NULL, NULL));
                }
            }
        } else {
            K_FORN(k_planar_geom(b, i, L + j, t + j, 0, NULL, NULL));
        }
    }
    /* and for a VSGL whose mean lies behind some lane's tangent plane
     * (vsgl__behind_ramp > 0: n . (mean - x) < 0) */
    int graze_of[2]; /* NL <= 2 (vsgl__kernel_run: k_scratch t[2]) */
    for (int j = 0; j < NL; ++j) {
        int any = graze;
        for (size_t i = 0; !any && !none_planar && !skip_lobes && i < VSGL__KERNEL_BLOCK; ++i)
            any = (b->nx[i] * (L[j].mx - b->x[i]) + b->ny[i] * (L[j].my - b->y[i]) +
                   b->nz[i] * (L[j].mz - b->z[i])) < 0.0f;
        graze_of[j] = any;
    }
    for (int q = 0; q < (skip_lobes ? 0 : 1 + two); ++q) {
        const float kb = two ? (q ? VSGL__GGX_TAIL_K : VSGL__GGX_CORE_K) : 1.0f;
        const float kc = two ? (q ? VSGL__GGX_TAIL_C : VSGL__GGX_CORE_C) : 1.0f;
        const int sg_only = none_planar;
        if (!all_planar)
            K_FORN(k_glossy(b, i, t + j, kb, kc));
        if (!sg_only) {
            if (graze)
                K_FORN(k_planar_lobe(b, i, L + j, t + j, kb, kc, 1));
            else
                for (int j = 0; j < NL; ++j) {
                    if (graze_of[j])
                        K_FORI(k_planar_lobe(b, i, L + j, t + j, kb, kc, 1));
                    else
                        K_FORI(k_planar_lobe(b, i, L + j, t + j, kb, kc, 0));
                }
            /* the fold only where some lane sees the cell: an image lies
             * at most 2 |b| + |fs| (sigma units) from the mean, so where
             * every lane's planar exponent is below -freach = -(sqrt(50)
             * + 2 |b| + |fs|)^2 / 2, every image's is below -25 (nil) */
            for (int j = 0; j < NL; ++j) {
                if (!(L[j].fold > 0.0f))
                    continue;
                float near = -1e30f;
                for (size_t i = 0; i < VSGL__KERNEL_BLOCK; ++i) {
                    float e = t[j].ppre[i] > 0.0f ? t[j].pexpo[i] : -1e30f;
                    near = e > near ? e : near;
                }
                if (!(near >= -L[j].freach))
                    continue;
                /* one loop per kind of cut, the cuts a constant in each */
#define K_FOLD(CUTS)                                      \
    for (size_t i = 0; i < VSGL__KERNEL_BLOCK; ++i)       \
        k_fold(i, L + j, t + j, (CUTS))
                switch (k_fold_cuts(L + j)) {
                case 1: K_FOLD(1); break;
                case 2: K_FOLD(2); break;
                case 4: K_FOLD(4); break;
                case 8: K_FOLD(8); break;
                case 3: K_FOLD(3); break;
                case 12: K_FOLD(12); break;
                default: K_FOLD(K_FOLD_ALL); break;
                }
#undef K_FOLD
            }
            if (hv)
                K_FORN(k_hv_rest(i, t + j));
        }
        if (sg_only)
            K_FORN(k_glossy_sum(b, i, L + j, t + j, 0));
        else if (all_planar)
            K_FORN(k_glossy_sum(b, i, L + j, t + j, 1));
        else
            K_FORN(k_glossy_sum(b, i, L + j, t + j, 2));
    }
    if (hv) {
        const float *hk, *hc;
        const int nhv = vsgl__hv_lobe_set(lobes & VSGL__KERNEL_HV5 ? VSGL__HV5_LOBES : VSGL__HV_LOBES, &hk, &hc);
        for (int q = 0; q < nhv; ++q) {
            if (q < VSGL__HV_RELIN)
                K_FORN(k_hv_lobe(b, i, t + j, hk[q], hc[q], 1));
            else
                K_FORN(k_hv_lobe(b, i, t + j, hk[q], hc[q], 0));
            K_FORN(k_glossy_sum(b, i, L + j, t + j, 3));
        }
    }
}

/* Stages 0-3 of VSGLs L[0, NL): the source each lane sees (k_shift, with
 * `shear`, a constant: some VSGL of the pass is sheared), the geometry,
 * the incident SG's axis and its amplitude's exponent; one loop per form,
 * each flag a constant in it. */
static inline __attribute__((always_inline)) void
k_source(const vsgl_kernel_block *restrict b, const vsgl_kernel_light *restrict L, const int NL,
         const float *restrict visibility, int conv, int plane, k_scratch *restrict t, const int shear)
{
    if (shear)
        K_FORN(k_shift(b, i, L + j, t + j));
    if (visibility && conv)
        K_FORN(k_geometry(b, i, L + j, visibility[(size_t)j * VSGL__KERNEL_BLOCK + i], t + j, 1, shear));
    else if (visibility)
        K_FORN(k_geometry(b, i, L + j, visibility[(size_t)j * VSGL__KERNEL_BLOCK + i], t + j, 0, shear));
    else if (conv)
        K_FORN(k_geometry(b, i, L + j, 1.0f, t + j, 1, shear));
    else
        K_FORN(k_geometry(b, i, L + j, 1.0f, t + j, 0, shear));
    if (plane)
        K_FORN(k_axis(b, i, L + j, t + j, 1, shear));
    else
        K_FORN(k_axis(b, i, L + j, t + j, 0, shear));
    K_FORN(k_exponent(b, i, L + j, t + j, shear));
}

static inline __attribute__((always_inline)) int
k_shade(vsgl_kernel_block *restrict b, const vsgl_kernel_light *restrict L, const int NL,
        const float *restrict visibility, int32_t mode, int32_t lobes, float lcut, k_scratch *restrict t)
{
    int plane = 0, conv = 0, shear = 0;
    for (int j = 0; j < NL; ++j) {
        plane |= L[j].fore > 0.0f;
        conv |= L[j].conv > 0.0f;
        shear |= L[j].shear > 0.0f;
    }
    /* one loop per form, each flag a constant in it */
    if (shear)
        k_source(b, L, NL, visibility, conv, plane, t, 1);
    else
        k_source(b, L, NL, visibility, conv, plane, t, 0);
    K_FORN(k_amplitude(i, t + j));
    /* VSGLs whose light is negligible at every lane of the block (k_faint)
     * skip the stages after this; the others take them one or two at a
     * time, as they come */
    int live = 0;
    for (int j = 0; j < NL; ++j)
        live |= !(lcut < 0.0f && k_faint(L + j, t + j, lcut)) << j;
    const int nlive = (live & 1) + (live >> 1);
    if (nlive == 0)
        return NL;
    const int off = live == 2; /* the one live VSGL of a pass */
    if (nlive == 2) {
        if (lobes & VSGL__KERNEL_DIFFUSE)
            k_diffuse_lights(b, L, 2, mode, t, (lobes & VSGL__KERNEL_BURLEY) != 0);
        if (lobes & VSGL__KERNEL_GLOSSY)
            k_glossy_lights(b, L, 2, lobes, t);
    } else {
        if (lobes & VSGL__KERNEL_DIFFUSE)
            k_diffuse_lights(b, L + off, 1, mode, t + off, (lobes & VSGL__KERNEL_BURLEY) != 0);
        if (lobes & VSGL__KERNEL_GLOSSY)
            k_glossy_lights(b, L + off, 1, lobes, t + off);
    }
    return NL - nlive;
}

KERNEL_ATTR size_t KERNEL_NAME(vsgl_kernel_block *restrict b, const vsgl_kernel_light *lights, size_t count,
                               const float *restrict visibility, int32_t mode, int32_t lobes, float faint)
{
    const float lcut = faint > 0.0f ? logf(faint) : 0.0f;
    size_t skipped = 0;
    k_scratch t[2];
    /* Burley's factor: 1 unless a VSGL__KERNEL_BURLEY block's k_burley sets it per pair */
    for (int j = 0; j < 2; ++j)
        for (size_t i = 0; i < VSGL__KERNEL_BLOCK; ++i)
            t[j].bfac[i] = 1.0f;
    vsgl_kernel_light local[2]; /* copies: no aliasing with the block */
    size_t v = 0;
    for (; v + 2 <= count; v += 2) {
        local[0] = lights[v];
        local[1] = lights[v + 1];
        skipped += (size_t)k_shade(b, local, 2, visibility ? visibility + v * VSGL__KERNEL_BLOCK : NULL, mode, lobes,
                                      lcut, t);
    }
    if (v < count) {
        local[0] = lights[v];
        skipped += (size_t)k_shade(b, local, 1, visibility ? visibility + v * VSGL__KERNEL_BLOCK : NULL, mode, lobes,
                                      lcut, t);
    }
    return skipped;
}
