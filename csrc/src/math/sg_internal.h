/* Internal SG helpers shared by sg.c, sg_cosine.c, lobes.c and the shading
 * kernels. Owner: csrc/src/math (sg.c). Formulas: docs/math.md. */
#ifndef VSGL_MATH_SG_INTERNAL_H
#define VSGL_MATH_SG_INTERNAL_H

#include "vsgl/sg.h"
#include "vsgl/asg.h"
#include "math/constants.h"
#include "math/vec.h"


/* Least-squares sharpness of the poster's SG cosine lobe (docs/math.md):
 * argmin over l of the L2 norm on the sphere of max(w.n,0)/pi - G(w;n,l)/A(l). */
#define VSGL__COSINE_SHARPNESS 2.29250405f
#define VSGL__COSINE_A_LD 2.7127863856 /* A(VSGL__COSINE_SHARPNESS) */

/* Fitted constants of the ACCURATE SG x clamped-cosine form (docs/math.md
 * 3.2, tools/fit_cosine_sharpness.py), shared with the shading kernel:
 *   t(l)     = l sqrt(0.5 (l^2 + T_A l + T_B) / (l^3 + T_C l^2 + T_D l + T_E))
 *   kappa(l) = -((K_A1 + K_A2 l) / (1 + K_B1 l + K_B2 l^2)) / t(l)
 *   s(c)    += kappa(l) (psi(t c) - psi(t)),  psi(x) = (x^2 - K_PSI) e^{-x^2} */
#define VSGL__COS_T_A 2.8147853f
#define VSGL__COS_T_B 3.33731626f
#define VSGL__COS_T_C 4.48710224f
#define VSGL__COS_T_D 13.6221047f
#define VSGL__COS_T_E 15.3642132f
#define VSGL__COS_K_A1 0.0124395234f
#define VSGL__COS_K_A2 0.00415145935f
#define VSGL__COS_K_B1 (-0.184176817f)
#define VSGL__COS_K_B2 0.081110396f
#define VSGL__COS_K_PSI (-1.2510562f)

/* NaN/negative -> 0; +inf and > VSGL_SHARPNESS_MAX -> VSGL_SHARPNESS_MAX. */
float vsgl__sg_clamp_sharpness(float lambda);
/* A(lambda) / (2 pi) = (1 - e^{-2 lambda}) / lambda (2 at 0); lambda >= 0. */
float vsgl__sg_integral_over_2pi(float lambda);
/* The part of a unit-integral SG of sharpness l whose axis is at cosine c to
 * a plane's normal that lies above the plane (1/2 at c = 0, 1 / (1 + e^-l)
 * at c = 1, 1 - f(l, -c) below); quadrature in the lobe's own density,
 * |error| < 3e-4 (tests/c/test_sg.c). */
float vsgl__sg_fraction_above(float l, float c);
/* log A(lambda); lambda >= 0. */
float vsgl__sg_log_integral(float lambda);
/* Exact vMF mean resultant length coth(l) - 1/l (Taylor below 0.5); l >= 0. */
float vsgl__sg_mean_length(float l);

/* Integral over the sphere of exp(lambda (w.xi - 1)) max(w.n, 0) for
 * unit-amplitude SGs, given lambda >= 0 (already clamped) and c = xi.n in
 * [-1, 1]: the ACCURATE mode of vsgl_sg_cosine_integral. */
float vsgl__sg_cosine_accurate(float lambda, float c);

/* The SG of the light reflected by an NDF SG from `view` (the direction to
 * the light): the in-plane profile of the warp with its Jacobian, cut at
 * the horizon (lobes.c, docs/math.md §5.4.1). Same amplitude as
 * vsgl_warp_ndf_sg. */
void vsgl__warp_ndf_sg_emitted(const vsgl_sg *ndf, const vsgl_vec3 *view, vsgl_sg *out);
/* The same with the Fresnel of a Principled dielectric layer along the
 * profile: the blend f0 + (1 - f0) FH(o.h) (FH Cycles 3.x's normalised
 * dielectric curve for `eta`), which sends a rough dielectric's light
 * towards grazing. eta <= 1 or f0 >= 1: the constant f0 (the call above). */
void vsgl__warp_ndf_sg_emitted_fresnel(const vsgl_sg *ndf, const vsgl_vec3 *view, float eta, float f0,
                                       vsgl_sg *out);

/* A receiver's reflection ASG cut at the horizon of `normal`: its part
 * above n.i > 0 as one ASG of the same moments and integral (lobes.c,
 * docs/math.md §5.4.2), and with the `view` it reflects (NULL: none) that
 * part's fan across the plane of incidence (§5.4.3). Unchanged where under
 * 3e-5 of it lies below. */
void vsgl__asg_cut_at_horizon(vsgl_asg *a, const vsgl_vec3 *normal, const vsgl_vec3 *view);

#endif
