/* Internal: the vectorised shading kernel. One call shades a block of
 * receivers (structure of arrays, up to VSGL__KERNEL_BLOCK) with one VSGL
 * and accumulates diffuse light (irradiance / pi, before albedo) and
 * glossy radiance per channel. The same source is compiled twice: with
 * vectorisation and ISA clones (kernel.c) and as a plain scalar build
 * (kernel_scalar.c) that the benchmark and tests compare against. */
#ifndef VSGL_SHADE_KERNEL_H
#define VSGL_SHADE_KERNEL_H

#include "math/broad_lobe.h"
#include "math/fresnel.h"
#include "math/normal.h"
#include "math/vec.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#define VSGL__KERNEL_BLOCK 64

/* A diffuse cluster seen from x as a patch of its plane, not a round blob
 * (shade.h, vsgl__vsgl_incident_sg), at cosine ce = -u.n_v (u the unit
 * direction from x to the mean, n_v the mean normal, which is a diffuse
 * lobe's axis) and weight fore (vsgl__foreshortening_weight). Returns the
 * factor on the spread's sharpness; *kd gets the distance lobe's.
 *  - Foreshortening: the emission lobe pulls the product's axis along the
 *    tangent t towards -n_v, where the plane's Gaussian spans
 *    sqrt(1 - (t.n_v)^2) = ce of its round angular width: the factor is
 *    1 / (1 - fore (1 - ce^2)), at most 1 / VSGL__FORESHORTEN_MIN.
 *  - Distance: 1 / d^2 over a plane at height h is cos^2(psi) / h^2 as a
 *    function of the direction (psi from -n_v), 1 / ce^2 times its value
 *    at u at its peak: an SG about -n_v, of value 1 at u, of sharpness
 *    2 ln(1 / ce) / (1 - ce) has that peak ratio (and the slope of cos^2 at
 *    u as ce -> 1; one fitted to the slope at u instead, 2 / ce, peaks at
 *    e^{2 (1 - ce) / ce}: e^38 at ce = 0.05, and the near field's wide
 *    spreads found it). ln(1/c) / (1 - c) on [0.05, 1] as a rational fit
 *    within 1.7 %, cut at ce = 0.05 and faded in from ce = 0.
 * Branch-free, one reciprocal for both: the kernel runs it per pair. */
#define VSGL__FORESHORTEN_MIN 1e-3f
static inline __attribute__((always_inline)) float vsgl__plane_spread(float ce, float fore, float *kd)
{
    float D = fmaxf(1.0f - fore * (1.0f - ce * ce), VSGL__FORESHORTEN_MIN);
    float c = fminf(fmaxf(ce, 0.05f), 1.0f);
    float q = c + 0.10887257f;
    float r = 1.0f / (D * q);
    float g = (0.44659993f + c * (0.93112012f - 0.27423752f * c)) * (D * r);
    *kd = 2.0f * fore * g * fminf(fmaxf(20.0f * ce, 0.0f), 1.0f);
    return q * r;
}

/* The planar glossy model (shade.h, vsgl__planar_glossy) takes a lobe
 * whose axis meets the cluster's plane at least VSGL__PLANAR_NZ_MIN (its
 * cosine to the plane's normal) off it, faded in by a smoothstep over the
 * next VSGL__PLANAR_NZ_RAMP. A hard bound switched a pair on at full
 * strength where the receiver lies almost in the cluster's plane (the
 * axis then meets it within the cluster): on the glossy sphere's rim, a
 * neighbouring cluster's plane passes next to the receiver, and a pixel
 * went 0.002 -> 0.062 -> 0.002 in three frames of the camera animation as
 * the axis crossed the bound. */
#define VSGL__PLANAR_NZ_MIN 0.01f
#define VSGL__PLANAR_NZ_RAMP 0.04f

/* That fade's weight for the cosine nz = n_v.z of the axis to the plane's
 * normal (the kernel and vsgl__planar_glossy alike). */
static inline float vsgl__planar_nz_weight(float nz)
{
    return smoothstep01f((-nz - VSGL__PLANAR_NZ_MIN) * (1.0f / VSGL__PLANAR_NZ_RAMP));
}

/* The planar model's footprint at the distance where the lobe meets the
 * cluster. The model maps the lobe's directions to the plane linearly
 * about the point y0 = x + t z where its axis meets it, so the footprint
 * is a Gaussian of a size that grows with t. That holds near y0; a
 * cluster far from y0 (a floor's cell at the foot of a glossy sphere,
 * whose lobe grazes the floor and meets it metres away) lies in the
 * footprint's linear tail, which reaches back past the receiver to
 * directions the lobe does not point at: there the model lit the lower
 * half of the sphere 4-10x brighter than the brute force. Each pair
 * linearises instead at ym, the centre of the product of the cluster's
 * Gaussian and the footprint, with the lobe's argument (X.w, Y.w) taken
 * at ym's distance d_m = |ym - x| (exact in the direction of ym): the
 * footprint about y0 scales by k^2 = d_m^2 / t^2 and the result by
 * (z.w_m) / k, the lobe's cosine and the solid angle there. At ym = y0
 * this is the old model; for a cluster small against the footprint (ym
 * at its mean) it is the lobe evaluated towards the cluster, as the
 * exact integral of a point cluster. With e = ym - y0 (in the plane) and
 * g = z.e: d_m^2 = t^2 + 2 t g + |e|^2; returns k^2 and in *f the
 * factor (z.w_m)+ / k = (t (t + g))+ / d_m^2, both faded towards 1 (the
 * old model) as the cluster's variance `var` nears d_m^2 (below). */
#define VSGL__PLANAR_REACH_LO 0.25f /* sigma^2 / d_m^2 */
#define VSGL__PLANAR_REACH_HI 1.0f
static inline float vsgl__planar_reach(float t, float e1, float e2, float zu1, float zu2, float var, float *f)
{
    const float g = e1 * zu1 + e2 * zu2, tg = t * (t + g);
    float dm2 = t * t + 2.0f * t * g + e1 * e1 + e2 * e2;
    dm2 = dm2 > 1e-30f ? dm2 : 1e-30f;
    /* bounded where the axis meets the plane at the receiver (t -> 0: the
     * footprint is nil there, and a pair the kernel does not count must
     * stay finite) */
    const float t2 = t * t, k2 = fminf(dm2 / (t2 > 1e-8f ? t2 : 1e-8f), 1e12f);
    /* only for a cluster small against its distance (sigma / d_m <= 0.5,
     * faded out by 1): the lobe's argument at one distance holds across
     * the cluster there, and not for a cluster as large as its distance
     * (the preview's: the sphere's silhouette flickered 0.021 -> 0.032) */
    const float w = 1.0f - smoothstep01f((var / dm2 - VSGL__PLANAR_REACH_LO) *
                                         (1.0f / (VSGL__PLANAR_REACH_HI - VSGL__PLANAR_REACH_LO)));
    *f = 1.0f + w * ((tg > 0.0f ? tg / dm2 : 0.0f) - 1.0f);
    return 1.0f + w * (k2 - 1.0f);
}

/* The planar model across the plane's horizon. The model follows the
 * lobe's axis to the plane and spreads the lobe's whole integral about
 * that point, which holds while the lobe lies well inside the directions
 * that meet the plane. Near the horizon it does not: the part of the lobe
 * that points above the horizon meets the plane nowhere, and with the
 * axis above it none of the lobe was counted, though its lower part still
 * meets the plane (a glossy sphere's reflection of a floor ended in a
 * sharp edge where its axis crossed the floor's horizon: the pixel above
 * it had 0.14 of Cycles' glossy light, 0.92 with what follows). Along
 * e, the direction from the axis towards -n_v, the lobe's angular spread is sigma^2 = (n_v.X)^2 / 2 lambda + (n_v.Y)^2 / 2 mu over
 * 1 - (n_v.z)^2 (an ASG's Gaussian over its tangent plane), and the axis
 * lies delta = asin(-n_v.z) into the plane: a = delta / sigma. The share
 * of the lobe that meets the plane is Phi(a), and its directions there
 * centre on delta + sigma phi(a) / Phi(a) (a truncated Gaussian's mean):
 * the model takes that share, with the axis tilted by Delta = sigma phi(a)
 * / Phi(a) towards the plane, z' = (z + Delta e) / sqrt(1 + Delta^2).
 * Far into the plane Phi = 1 and Delta = 0: the model as before.
 * `a` is kept at -4 and above (Phi 3e-5; from a = -4.22 the tilted axis
 * itself leaves the plane, vsgl__planar_nz_weight). A lane's a, Phi and
 * tilt depend on its lobe and the plane alone: shade.c (tilt_lane) takes
 * them once per block for each axis plane, and the kernel and
 * vsgl__planar_glossy apply them per pair (vsgl__planar_tilt). */
#define VSGL__PLANAR_TILT_A_MIN (-4.0f)

static inline float vsgl__planar_tilt_a(float nz, float nx, float ny, float lam, float mu, float *sigma)
{
    float w2 = 1.0f - nz * nz;
    w2 = w2 > 1e-4f ? w2 : 1e-4f;
    float s2 = (nx * nx * (0.5f / lam) + ny * ny * (0.5f / mu)) / w2;
    s2 = s2 > 1e-12f ? s2 : 1e-12f;
    *sigma = sqrtf(s2);
    /* asin(-nz) by its series (exact near the horizon, 1.24 for 1.57 at
     * the pole, where Phi is 1 either way) */
    float s = -nz, d = s * (1.0f + s * s * (0.16666667f + 0.075f * s * s));
    float a = d / *sigma;
    return a > VSGL__PLANAR_TILT_A_MIN ? a : VSGL__PLANAR_TILT_A_MIN;
}

/* What a lane's tilt needs against a plane (vsgl__planar_tilt_a's a and
 * sigma, and e = exp(-a^2 / 2)): Phi(a) and D = sigma phi(a) / Phi(a),
 * the tilt at full weight. */
static inline float vsgl__planar_tilt_pre(float a, float sigma, float e, float *D)
{
    float Phi = vsgl__normal_cdf_e(a, e);
    *D = sigma * (0.39894228f * e) / Phi;
    return Phi;
}

/* The share of the lobe that meets the plane, 1 - w (1 - Phi), and the
 * axis's tilt w D as z' = p z - q n_v (e = (nz z - n_v) / sqrt(1 - nz^2)
 * towards the plane), at weight w (vsgl__planar_tilt_weight, _gate): w =
 * 0, or Phi 1 and D 0 (a lane that needs no tilt), give share 1, p 1 and
 * q 0 exactly. */
static inline float vsgl__planar_tilt(float nz, float Phi, float D, float w, float *p, float *q)
{
    float w2 = 1.0f - nz * nz;
    float iw = 1.0f / sqrtf(w2 > 1e-4f ? w2 : 1e-4f);
    float delta = w * D;
    float c = 1.0f / sqrtf(1.0f + delta * delta);
    *p = c * (1.0f + delta * nz * iw);
    *q = c * delta * iw;
    return 1.0f - w * (1.0f - Phi);
}

/* How far the horizon's share and tilt apply: to a flat surface's cluster
 * (coherence k >= 0.995, smoothstep from 0.98) seen from a receiver that
 * stands off its plane by more than its size (height hs >= 2 sigma,
 * smoothstep from 0.5). A sphere's cluster stands for a surface that
 * curves away from its plane, and receivers on the sphere lie behind that
 * plane or barely in front of it; tilted lobes on the sphere's rim met its
 * neighbours' planes where the sphere is not (a bright ring, and pixels
 * of its rim flashing 0.005 -> 0.06 from frame to frame of the camera
 * animation, where small cells of the sphere are as coherent as a plane). */
static inline float vsgl__planar_tilt_weight(float k)
{
    return smoothstep01f((k - 0.98f) * (1.0f / 0.015f));
}

/* Whether a lane needs the tilt at all: not when the axis lies at least 4
 * sigma into the plane (-nz >= 4 sigma, -nz <= delta: a >= 4), where Phi >=
 * 1 - 3e-5 and the tilt is below 1.4e-4 sigma. Those lanes take share 1
 * and no tilt exactly, and the kernel skips the tilt's arithmetic in
 * blocks where no lane needs it. nx, ny: n_v.X, n_v.Y. */
static inline int vsgl__planar_tilt_needed(float nz, float nx, float ny, float lam, float mu)
{
    float w2 = 1.0f - nz * nz;
    return !(nz < 0.0f && nz * nz * w2 >= 16.0f * (nx * nx * (0.5f / lam) + ny * ny * (0.5f / mu)));
}

/* The table (VSGL__TILT_DIRS) of a cluster's plane normal n: 2 axis +
 * (n[axis] < 0) where n is an axis (within 1e-5: a flat wall's mean
 * normal), else -1: no tilt (a plane at an angle keeps the model without
 * it, as before 2026-12-05). */
static inline int vsgl__planar_tilt_dir(float nx, float ny, float nz)
{
    const float c[3] = {nx, ny, nz};
    for (int k = 0; k < 3; ++k)
        if (fabsf(c[k]) > 1.0f - 1e-5f)
            return 2 * k + (c[k] < 0.0f);
    return -1;
}

static inline float vsgl__planar_tilt_gate(float hs)
{
    return smoothstep01f((hs - 0.5f) * (1.0f / 1.5f));
}

/* The planar glossy model's weight (coherence^2 of a diffuse cluster)
 * for a receiver facing the cluster's way, i.e. on the same surface, where
 * the surface is bumpy (1 - coherence from 0.001 to 0.005): such a
 * receiver's lobe meets the cluster's mean plane at a grazing angle, where
 * the bumps stand up into it and reflect their light; the plane gives
 * almost none. The weight fades to 0 there (n_r . n_v from 0.85 to 0.95)
 * and the SG product, which treats the cluster as a cloud, takes it: a
 * bumpy floor's glossy light near the camera (dense_floor at 80 x 60,
 * the bottom sixth of the rows) 0.39 -> 1.06 of Cycles', its glossy
 * structured error 0.00110 -> 0.00025 (balanced). Flat surfaces (coherence
 * 1) and receivers across the plane (a wall reflecting the floor) keep the
 * planar model (docs/accuracy.md, "A bumpy floor reflects itself"). */
#define VSGL__PLANAR_BUMP_LO 0.001f
#define VSGL__PLANAR_BUMP_HI 0.005f
#define VSGL__PLANAR_SAME_LO 0.85f
#define VSGL__PLANAR_SAME_HI 0.95f
static inline float vsgl__planar_bump(float c)
{
    return smoothstep01f(((1.0f - c) - VSGL__PLANAR_BUMP_LO) * (1.0f / (VSGL__PLANAR_BUMP_HI - VSGL__PLANAR_BUMP_LO)));
}
static inline float vsgl__planar_weight(float planar, float bump, float ndot)
{
    return planar * (1.0f - bump * smoothstep01f((ndot - VSGL__PLANAR_SAME_LO) *
                                                 (1.0f / (VSGL__PLANAR_SAME_HI - VSGL__PLANAR_SAME_LO))));
}

/* The emitter-hemisphere clip's constants (shade.h explains the clip). */
#define VSGL__CLIP_BEHIND 0.02f   /* the behind fade, in units of sigma */
/* A curved cluster's behind fade is wider by this many sigma times
 * sqrt(1 - coherence^2) (the spread of its normals), centred on its plane:
 * its VPLs lie on both sides of the plane through their mean (a sphere's
 * cap), and a receiver beside it crossed a 2 mm fade as the cluster's mean
 * moved 1 cm with the light (the floor under the sphere: 17x in a frame,
 * docs/accuracy.md). */
#define VSGL__CLIP_CURVED 1.0f
/* The behind fade of a cluster of variance var (per axis, m^2) and
 * coherence c: *width (m) and *start (m behind the plane). */
static inline void vsgl__clip_fade(float var, float c, float *width, float *start)
{
    float sd = sqrtf(var > 0.0f ? var : 0.0f), s = 1.0f - c * c;
    float curved = VSGL__CLIP_CURVED * (s > 0.0f ? sqrtf(s) : 0.0f) * sd;
    *width = VSGL__CLIP_BEHIND * sd + curved;
    *start = 0.5f * curved;
}
#define VSGL__CLIP_PARALLEL 0.3f  /* the parallel fade, in 1 - n.n_v */
#define VSGL__CLIP_NEAR 4.0f      /* the spread sharpness where conv is half-way */

#define VSGL__TILT_DIRS 6

/* Receivers of one block. Non-glossy receivers have camp = 0 (and any
 * frame); receivers without a diffuse lobe have diffuse = 0. */
typedef struct vsgl_kernel_block {
    float x[VSGL__KERNEL_BLOCK], y[VSGL__KERNEL_BLOCK], z[VSGL__KERNEL_BLOCK];
    float nx[VSGL__KERNEL_BLOCK], ny[VSGL__KERNEL_BLOCK], nz[VSGL__KERNEL_BLOCK];
    float ox[VSGL__KERNEL_BLOCK], oy[VSGL__KERNEL_BLOCK], oz[VSGL__KERNEL_BLOCK];
    float diffuse[VSGL__KERNEL_BLOCK];   /* 1 if the diffuse lobe is shaded, else 0 */
    /* Blender 3.x's Burley diffuse (VSGL_MATERIAL_FLAG_BURLEY): its roughness, < 0 for Lambert */
    float burley[VSGL__KERNEL_BLOCK];
    /* its convex part (scene_internal.h) as a float, -1 if none, and 1 on
     * the part's outside, 0 inside (vsgl__part_keep) */
    float part[VSGL__KERNEL_BLOCK], pouter[VSGL__KERNEL_BLOCK];
    /* warped NDF lobe: ASG frame (X, Y, Z), bandwidths, linear amplitude */
    float Xx[VSGL__KERNEL_BLOCK], Xy[VSGL__KERNEL_BLOCK], Xz[VSGL__KERNEL_BLOCK];
    float Yx[VSGL__KERNEL_BLOCK], Yy[VSGL__KERNEL_BLOCK], Yz[VSGL__KERNEL_BLOCK];
    float Zx[VSGL__KERNEL_BLOCK], Zy[VSGL__KERNEL_BLOCK], Zz[VSGL__KERNEL_BLOCK];
    float lam[VSGL__KERNEL_BLOCK], mu[VSGL__KERNEL_BLOCK], camp[VSGL__KERNEL_BLOCK];
    /* GGX's alpha for the half-vector model (VSGL__HV_*), 0 where it does
     * not apply (not glossy, anisotropic) */
    float alpha[VSGL__KERNEL_BLOCK];
    /* the smooth Fresnel/shadowing factor M(z, o) per channel at the lobe axis */
    float f0r[VSGL__KERNEL_BLOCK], f0g[VSGL__KERNEL_BLOCK], f0b[VSGL__KERNEL_BLOCK];
    /* the half-vector model's Fresnel towards each cluster over M's at the
     * axis, fa + fb F(l.h, fe) (scene/material.h vsgl__fresnel_ratio;
     * fe 0: the ratio 1) */
    float fe[VSGL__KERNEL_BLOCK], fa[VSGL__KERNEL_BLOCK], fb[VSGL__KERNEL_BLOCK];
    /* Smith's shadowing and the Fresnel towards the light over M's at the
     * axis: the lane's vsgl_smooth_lane (vsgl__shadow_lane,
     * vsgl__smooth_ratio; gw 0: the ratio 1, as for a lane without a lobe) */
    float ga2[VSGL__KERNEL_BLOCK], gso[VSGL__KERNEL_BLOCK], gco[VSGL__KERNEL_BLOCK], gia[VSGL__KERNEL_BLOCK];
    float gw[VSGL__KERNEL_BLOCK];
    /* the planar model's horizon tilt against the six planes facing +-x,
     * +-y, +-z (index 2 axis + side; kernel.h, vsgl__planar_tilt), per
     * lane: Phi and D, 1 and 0 where the lane needs no tilt
     * (vsgl__planar_tilt_needed); tany[d]: some lane needs it (shade.c,
     * tilt_table) */
    float tphi[VSGL__TILT_DIRS][VSGL__KERNEL_BLOCK], td[VSGL__TILT_DIRS][VSGL__KERNEL_BLOCK];
    int tany[VSGL__TILT_DIRS];
    /* accumulators */
    float ld[3][VSGL__KERNEL_BLOCK];     /* diffuse light: sum power * cosine integral / pi */
    float ls[3][VSGL__KERNEL_BLOCK];     /* glossy radiance */
} vsgl_kernel_block;

/* One VSGL, with the per-VSGL constants precomputed. */
typedef struct vsgl_kernel_light {
    float mx, my, mz;        /* mean position */
    float var;               /* positional variance per axis */
    float var2;              /* 2 var */
    float ivar;              /* 1 / var (FLT_MAX when var is 0) */
    float valid;             /* 1 if var > 0 (a receiver at the mean of a point-like VSGL gets nothing) */
    float ax, ay, az;        /* -axis of the radiant intensity (incident direction) */
    float lv;                /* sharpness of the radiant intensity */
    float lax, lay, laz;     /* lv times the -axis */
    float c0;                /* 1 / (2 pi A(lv)) */
    float pr, pg, pb;        /* power */
    float nx, ny, nz;        /* mean surface normal of the cluster */
    float clip;              /* emitter-hemisphere clip: coherence^2 of the normals, 0 = off (shade.h) */
    float conv;              /* 1 for a diffuse lobe: clamped-cosine emission in the far field */
    float fore;              /* vsgl__foreshortening_weight (vsgl__plane_spread) */
    float ibehind;           /* 1 / the behind fade's width (vsgl__clip_fade) */
    float boff;              /* where it starts, in its widths behind the plane (0 for a planar cluster) */
    float planar;            /* weight of the planar glossy model (coherence^2 of a diffuse lobe, clip on), else 0 */
    float bump;              /* vsgl__planar_bump of its coherence (planar > 0), else 0 */
    float pvar;              /* its positional variance (var + the fit's overlap widening) */
    float u1x, u1y, u1z, u2x, u2y, u2z; /* an orthonormal basis of the cluster's plane */
    /* A lattice cell cut by its surface's end (shade.h, vsgl__planar_glossy):
     * the fold's weight (0: none), and per in-plane axis u1, u2 and side
     * (low: the surface above the cut, high: below) the cut from the mean
     * in units of sqrt(pvar) and its weight (0: not cut there) */
    float fold, fb[2][2], fa[2][2];
    float fs[2];  /* per axis, the mean the images are built on (shade.c, fold_mean) from the mean, same units */
    float tilt;   /* the planar model's horizon share and tilt, vsgl__planar_tilt_weight (0: none) */
    uint32_t tdir; /* where tilt > 0: the block's table of the axis its normal is (VSGL__TILT_DIRS: 2 axis + side) */
    /* the cluster's convex part (vsgl_vsgl.part) as a float, -2 if none or
     * the leak correction is off, and its shares outside and inside */
    float part, pout, pin;
    float freach; /* (sqrt(50) + 2 |farthest cut| + |fs|)^2 / 2: where the fold can matter (k_shade) */
    /* vsgl_vsgl.shear (var then its shear_variance): the source a receiver
     * sees moves by sh (e - axis), e the direction from the mean to the
     * receiver, by at most about 2 sigma (ishift = 1 / (4 variance));
     * shear 1 where sh is not 0 */
    float sh[9], ishift, shear;
} vsgl_kernel_light;

/* The share of VSGL L's light that lane i of block b receives by the
 * convex parts (fit/vsgl_set.h, vsgl_vsgl.part): a receiver on the
 * cluster's part gets none of what the cluster sends from its outside,
 * and none from its inside unless it is inside too. */
static inline __attribute__((always_inline)) float vsgl__part_keep(const vsgl_kernel_block *b, size_t i,
                                                                 const vsgl_kernel_light *L)
{
    /* branch-free: as a select of two expressions the kernel's loop took
     * 1.65x the time (the sun room, balanced without rays, 960 x 540) */
    float same = b->part[i] == L->part ? 1.0f : 0.0f;
    return 1.0f - same * (L->pout + b->pouter[i] * L->pin);
}

/* Smith's height-correlated shadowing-masking as it changes with the
 * light's direction l (math.md 5.6: M = F G2 / (4 cos_o), G2 / (4 cos_o) =
 * g(cos_l) / 2 with g(c) = c / (c S(cos_o) + cos_o S(c)), S(c) = sqrt(a^2 +
 * (1 - a^2) c^2)), over its value at the lobe's axis, where M is taken.
 * The lobe's glossy light takes M at its axis for the whole lobe; a broad
 * lobe (roughness 0.7) then keeps light that arrives near the receiver's
 * horizon, where G2 takes it to 0 (a rough metal sphere's rim facing a lit
 * wall at grazing: 1.3x Cycles' Gloss). The SG and planar models take the
 * ratio at the direction their product with the light peaks towards; the
 * half-vector model has it per lobe already (k_hv_shared). One receiver's
 * constants: a2 = alpha^2, so = S(cos_o), co = cos_o, gia = 1 / g(cos of
 * the lobe's axis), w how far the ratio applies (0: the ratio 1). */
typedef struct vsgl_smooth_lane {
    float a2, so, co, gia, w;
} vsgl_smooth_lane;

/* Those of a receiver of alpha a (sqrt(ax ay)) seen at co = n.o, its lobe's
 * axis at ca = n.z; two: GGX as two lobes (the presets), which take the
 * ratio at every roughness. One ASG takes it only for broad lobes, faded
 * in as the broad-lobe tables (vsgl__broad_fade): at roughness 0.3 it made
 * the corridor's and the textured room's Gloss worse in that mode
 * (structured error +66 % / +30 %) while it made the presets' two-lobe GGX
 * better or kept it. */
static inline vsgl_smooth_lane vsgl__shadow_lane(float a, float co, float ca, int two)
{
    vsgl_smooth_lane s;
    co = co > 1e-4f ? co : 1e-4f;
    ca = ca > 1e-4f ? ca : 1e-4f;
    s.a2 = a * a;
    s.so = sqrtf(s.a2 + (1.0f - s.a2) * co * co);
    s.co = co;
    const float ga = ca / (ca * s.so + co * sqrtf(s.a2 + (1.0f - s.a2) * ca * ca));
    s.gia = 1.0f / ga;
    s.w = two ? 1.0f : vsgl__broad_fade(sqrtf(a));
    return s;
}

/* Lane k of block b takes the constants s. */
static inline void vsgl__kernel_set_smooth(vsgl_kernel_block *b, size_t k, vsgl_smooth_lane s)
{
    b->ga2[k] = s.a2;
    b->gso[k] = s.so;
    b->gco[k] = s.co;
    b->gia[k] = s.gia;
    b->gw[k] = s.w;
}

/* Lanes [0, n) of block b take their constants from their fields: |alpha|
 * (negative for an anisotropic receiver, which the half-vector model does
 * not take), n . o and n . Z (shadow4.c: vsgl__shadow_lane, four lanes at
 * a time, bit for bit). */
void vsgl__shadow_lanes(vsgl_kernel_block *b, size_t n, int two);

/* The ratio at a light direction of cosine ci to the normal (0 at and
 * below the horizon). */
static inline __attribute__((always_inline)) float vsgl__shadow_ratio(float a2, float so, float co, float gia, float ci)
{
    ci = ci > 0.0f ? ci : 0.0f;
    float s = sqrtf(a2 + (1.0f - a2) * ci * ci);
    return gia * ci / (ci * so + co * s + 1e-30f);
}

/* The same times the dielectric Fresnel towards the light over its value
 * at the axis, fa + fb F(l.h, fe) (scene/material.h vsgl__fresnel_ratio;
 * fe 0: 1), for a light direction of cosines ci to the normal and ov to
 * the view: l.h = sqrt((1 + o.l) / 2). */
static inline __attribute__((always_inline)) float vsgl__smooth_ratio(float a2, float so, float co, float gia, float w,
                                                                      float fe, float fa, float fb, float ci, float ov)
{
    float lh = 0.5f + 0.5f * ov;
    lh = sqrtf(lh > 1e-8f ? lh : 1e-8f);
    return 1.0f + w * (vsgl__shadow_ratio(a2, so, co, gia, ci) * (fa + fb * vsgl__fresnel_dielectric(lh, fe)) - 1.0f);
}

/* The same for a receiver's constants s and Fresnel ratio fres (scalar
 * callers; the kernel passes its lanes' fields). */
static inline float vsgl__smooth_ratio_of(const vsgl_smooth_lane *s, const float fres[3], float ci, float ov)
{
    return vsgl__smooth_ratio(s->a2, s->so, s->co, s->gia, s->w, fres[0], fres[1], fres[2], ci, ov);
}

/* The planar model's receiver horizon (shade.h, vsgl__planar_glossy): where
 * the lobe's axis is within asin(HI) of the receiver's tangent plane, its
 * footprint on a cluster's plane reaches past the horizon (a sphere's rim
 * reflected lit floor below it: hot dots that crawl as the camera moves);
 * there the part of the cluster x footprint below the tangent plane is
 * dropped, fully below LO. Not everywhere: a cluster's Gaussian spills
 * past its surface's end, and that spill stands for light that is there
 * (the red-wall room's glossy structured error +8 % with the cut applied
 * to every pair, docs/quality.md). But also wherever the cluster's mean
 * lies behind the tangent plane (vsgl__behind_ramp): a broad lobe's
 * footprint reaches a cluster behind the receiver whatever its axis does
 * (a rough metal sphere's side away from a lit wall and floor: 3.5x
 * Cycles' glossy light, docs/accuracy.md). */
#define VSGL__HORIZON_HI 0.3f
#define VSGL__HORIZON_LO 0.1f

/* The horizon cut's weight from where the cluster's mean lies, nd = n_r .
 * (mean - x) over the cluster's sigma: 1 a sigma or more behind the
 * receiver's tangent plane, 0 on it or in front (before the smoothstep,
 * with vsgl__graze_ramp the larger of the two). From the plane, not a
 * sigma in front of it: the rough room's glossy structured error 328x ->
 * 322x its noise (balanced), the bias the same. */
static inline float vsgl__behind_ramp(float nd)
{
    float w = -nd;
    return w < 0.0f ? 0.0f : (w > 1.0f ? 1.0f : w);
}

/* How close a lobe's axis lies to the receiver's tangent plane, from its
 * cosine zn = n.z: 0 at VSGL__HORIZON_HI and above, 1 at _LO and below
 * (before the smoothstep). One form for the kernel, the scalar path and
 * the block's VSGL__KERNEL_GRAZE bit. */
static inline float vsgl__graze_ramp(float zn)
{
    float gw = (VSGL__HORIZON_HI - zn) * (1.0f / (VSGL__HORIZON_HI - VSGL__HORIZON_LO));
    return gw < 0.0f ? 0.0f : (gw > 1.0f ? 1.0f : gw);
}

/* Lobes a block needs (skip the work for lobes no lane has). */
#define VSGL__KERNEL_DIFFUSE 1
#define VSGL__KERNEL_GLOSSY  2
/* Some glossy lane's lobe grazes its tangent plane (vsgl__graze_ramp > 0):
 * the planar model's horizon cut runs for every pair of this block (kernel.h
 * above; else for a VSGL only where some lane has its mean behind it,
 * vsgl__behind_ramp > 0: its mean behind the lane's tangent plane) */
#define VSGL__KERNEL_GRAZE  16
/* Some diffuse lane is Blender 3.x's Burley diffuse (vsgl_kernel_block.burley
 * >= 0): the diffuse stage takes its factor per pair (kernel_impl.h, k_burley) */
#define VSGL__KERNEL_BURLEY 32
/* The glossy lobe as GGX's core and tail: two ASGs of the lane's frame with
 * bandwidths x VSGL_GGX_{CORE,TAIL}_K and amplitudes x _C, fitted to GGX's
 * 1/(1 + x^2)^2, x = tan / alpha, at equal integral, minimising the relative
 * error over x in [0, 3] (tools/fit_ggx_lobes.py; tests/python/
 * test_ggx_lobes.py checks it): within 18 % of GGX up to 3 alpha, where a
 * plain least-squares fit (1.75 / 0.26) overshoots by 25-34 % at 2-3 alpha,
 * which lit the floor around a reflected wall; beyond 3 alpha both fall
 * below GGX. The tail carries 40 % of the energy, which one ASG puts in its
 * core. */
#define VSGL__KERNEL_GGX_TAIL 4
#define VSGL__GGX_CORE_K 1.454f
#define VSGL__GGX_CORE_C 0.8663f
#define VSGL__GGX_TAIL_K 0.2759f
#define VSGL__GGX_TAIL_C 0.1116f
/* A specular lattice cluster (an emitter: a metal floor's reflection of a
 * lit wall; fit/lattice.c split_specular) as GGX's core (the receivers',
 * above), a tail and a far tail: within 16 % of GGX up to six alphas
 * (0.84 at 1.75, 1.13 at 3.1), where the two lobes fall to 0.39 at four
 * and 0.08 at five, and a wall facing a metal floor got 9 % too little of
 * its reflection on its upper part (tools/fit_ggx_lobes.py --emitter;
 * tests/python/test_ggx_lobes.py). */
#define VSGL__GGX_EMIT_TAIL_K 0.2884f
#define VSGL__GGX_EMIT_TAIL_C 0.08456f
#define VSGL__GGX_EMIT_FAR_K 0.06446f
#define VSGL__GGX_EMIT_FAR_C 0.007166f

/* The half-vector model of a planar cluster's glossy light (with
 * VSGL__KERNEL_GGX_TAIL; shade/halfvec.h): the cluster seen from the
 * receiver as a Gaussian of directions, mapped through the half vector
 * into the receiver's slope space and convolved there with GGX as four
 * Gaussian lobes c exp(-k x^2) (five with vsgl_render_settings.glossy_lobes
 * 5: VSGL__HV5_*, VSGL__KERNEL_HV5), x = |slope| / alpha, fitted at equal
 * integral to GGX's 1/(1 + x^2)^2 by the relative error over x in [0, 10]
 * (tools/fit_ggx_lobes.py --lobes 4; within 15 % of GGX up to 10 alpha: 0.85
 * of its peak, 1.09 at one alpha, within 4 % from 2 to 10 alpha, where the two lobes above hold 3.4 % of the energy
 * beyond 3 alpha against GGX's 10 %: the haze around a reflected wall). It
 * replaces the planar model where the cluster subtends little (angular
 * variance per axis var / d^2 below VSGL__HV_SPREAD_LO, blended out by
 * _HI) and the half vector is well above the horizon (n.h above
 * VSGL__HV_HN_HI, blended out by _LO: below it the slope mapping is too
 * curved to linearise). */
#define VSGL__HV_LOBES 4
#define VSGL__HV_K_LIST {1.3917f, 0.35132f, 0.099116f, 0.022969f}
#define VSGL__HV_C_LIST {0.72905f, 0.1126f, 0.011354f, 0.00094364f}
/* Five lobes (tools/fit_ggx_lobes.py --lobes 5): 0.96 of GGX's peak, within
 * 1 % from one alpha to ten; one lobe more per pair of the model. */
#define VSGL__HV5_LOBES 5
#define VSGL__HV5_K_LIST {2.0583f, 0.6556f, 0.2263f, 0.077476f, 0.019603f}
#define VSGL__HV5_C_LIST {0.6639f, 0.24442f, 0.042696f, 0.0063297f, 0.0006717f}
#define VSGL__KERNEL_HV5 8 /* the half-vector model with five lobes */
/* The half-vector model's lobes (k, c), `count` 4 or 5 (VSGL__HV_*,
 * VSGL__HV5_*): returns how many, for the kernel and halfvec.c alike. */
static inline int vsgl__hv_lobe_set(int count, const float **k, const float **c)
{
    static const float k4[VSGL__HV_LOBES] = VSGL__HV_K_LIST, c4[VSGL__HV_LOBES] = VSGL__HV_C_LIST;
    static const float k5[VSGL__HV5_LOBES] = VSGL__HV5_K_LIST, c5[VSGL__HV5_LOBES] = VSGL__HV5_C_LIST;
    const int five = count == VSGL__HV5_LOBES;
    *k = five ? k5 : k4;
    *c = five ? c5 : c4;
    return five ? VSGL__HV5_LOBES : VSGL__HV_LOBES;
}
/* The lobes (the first, sharpest, of either set) that the model linearises
 * again where each one's product with the cluster peaks (halfvec.c); the
 * broader ones keep the linearisation at the cluster's direction. Two of
 * four: the half-vector light at the corridor's grazing floor pixel is
 * 10 % over quadrature (all four: 2 %; none: 111 %) for half the cost of
 * all four (docs/accuracy.md). */
#define VSGL__HV_RELIN 2
#define VSGL__HV_SPREAD_LO 0.003f
#define VSGL__HV_SPREAD_HI 0.01f
#define VSGL__HV_HN_LO 0.3f
#define VSGL__HV_HN_HI 0.5f

/* Accumulate VSGLs lights[0, count) into all VSGL__KERNEL_BLOCK receivers
 * of b (a fixed trip count: the caller fills unused lanes with any finite
 * receiver and ignores their sums), in that order. Diffuse modes as in
 * vsgl/sg.h (VSGL_COSINE_*); the glossy lobe is the block's ASG.
 * visibility: NULL or count x VSGL__KERNEL_BLOCK factors in [0, 1]
 * (VSGL-major). faint in (0, 1): a VSGL (not a planar cluster) whose
 * radiant intensity towards every lane is below that share of its peak
 * adds nothing to the block (kernel_impl.h, k_faint); 0: every pair is
 * shaded. Returns how many of the VSGLs were faint. The renderer passes
 * VSGL__FAINT: in the bundled rooms at 960 x 540 it skips most of the
 * specular VSGLs' pairs and changes the image by a relative RMS of
 * ~4e-6 (docs/pipeline.md, "Faint pairs"). */
#define VSGL__FAINT 1e-4f
size_t vsgl__kernel_shade(vsgl_kernel_block *b, const vsgl_kernel_light *lights, size_t count,
                          const float *visibility, int32_t diffuse_mode, int32_t lobes, float faint);
size_t vsgl__kernel_shade_scalar(vsgl_kernel_block *b, const vsgl_kernel_light *lights, size_t count,
                                 const float *visibility, int32_t diffuse_mode, int32_t lobes, float faint);

/* The visibility budget's order of importance (shade.c): the light of each
 * of lights[0, count) at the block's receivers (every lane; padding lanes
 * are finite), its radiant intensity towards the receiver over the squared
 * distance (plus its variance), times what the receiver makes of it: the
 * diffuse lobe's cosine (plus 0.05) / pi where it is shaded, plus the
 * warped GGX lobe's ASG towards the VSGL, widened by the VSGL's extent as
 * seen from the receiver (a sharp lobe's light comes from the few VSGLs in
 * its mirror direction, which the cosine alone would rank low). w: count x VSGL__KERNEL_BLOCK
 * (VSGL-major); total[k] += each receiver's sum. */
void vsgl__kernel_pair_weights(const vsgl_kernel_block *b, const vsgl_kernel_light *lights, size_t count, float *w,
                               float *total);
/* The budget's cut: the candidate cuts are total[k] x 2^-(VSGL__VIS_LEVEL0
 * + l), l < VSGL__VIS_LEVELS; cut[k] receives receiver k's highest one
 * whose weights at or below it sum to at most budget x total[k], or -1 if
 * none does (nothing skipped). */
#define VSGL__VIS_LEVELS 12
#define VSGL__VIS_LEVEL0 4
void vsgl__kernel_weight_cut(const float *w, size_t count, const float *total, float budget, float *cut);

/* The budget's per-VSGL bookkeeping over a block's VSGL__KERNEL_BLOCK lanes
 * (shade.c), as lane masks (bit k: lane k), vectorised:
 *  - lanes_within: the lanes whose cut[k] >= 0 and w[k] <= cut[k];
 *  - vis_accumulate: seen[k] += w[k] on the traced lanes, lit[k] += w[k]
 *    on those that are visible (the same sums as lane by lane);
 *  - vis_fill: out[k] = share[k] on the skipped lanes, else 1 or 0 as the
 *    lane is visible. */
uint64_t vsgl__kernel_lanes_within(const float *w, const float *cut);
void vsgl__kernel_vis_accumulate(const float *w, uint64_t traced, uint64_t visible, double *seen, double *lit);
void vsgl__kernel_vis_fill(uint64_t skipped, uint64_t visible, const float *share, float *out);

/* One side of the near field's specular footprint (near_field.c,
 * tent_mass): its Gauss-Legendre nodes u (weights w, 0 for unused ones)
 * and what they share; vsgl__kernel_tent_nodes returns sum_k w_k x the
 * integrand at u_k, vectorised. */
#define VSGL__TENT_NODES 8
typedef struct vsgl_tent_nodes {
    float u[VSGL__TENT_NODES], w[VSGL__TENT_NODES];
    float pu, pv, isu, slope, sv, isv; /* the footprint: mean, 1 / sd in u, v's regression on u, v's sd */
    float ih;                          /* 1 / the lattice spacing */
    float vb[3];                       /* the tent's support in v: low end, peak (clamped), high end */
    float side[2];                     /* 1 where the tent in v has that side ([vb0, vb1], [vb1, vb2]), else 0 */
    float cu, cv, g[2];                /* the irradiance's centroid and gradient */
} vsgl_tent_nodes;
float vsgl__kernel_tent_nodes(const vsgl_tent_nodes *t);

#endif
