/* Internal: the half-vector model of a planar cluster's glossy light
 * (kernel.h VSGL__HV_*; the kernel computes the same inline). */
#ifndef VSGL_SHADE_HALFVEC_H
#define VSGL_SHADE_HALFVEC_H

#include "fit/vsgl_set.h"
#include "math/vec.h"

/* Glossy light per watt of planar Lambertian cluster v (radiance N(y)/pi
 * on its plane, N its Gaussian of variance v->variance per axis) at a
 * receiver at x with unit normal n, view o, isotropic GGX of roughness
 * alpha, GGX as `lobes` Gaussian lobes (4, or 5: kernel.h VSGL__HV_*,
 * VSGL__HV5_*), through the BRDF's D and shadowing-masking relative to those at
 * the lobe's axis `axis` (the caller multiplies by the smooth factor M
 * there, as for the ASG models); *weight receives the model's weight in
 * [0, 1] (0: not applicable, the planar model stands).
 *
 * The cluster seen from x is a Gaussian of directions about w = (mean -
 * x)/d with covariance var/d^2 (P - p p^T) (P projects off w, p is the
 * cluster's normal projected off w). Reflection maps a direction l to the
 * half vector h = (o + l)/|o + l| and its slope s = (h.t, h.u)/h.n; near w
 * that map is linear, ds = J dl with rows (I - h h^T)(e - s_e n) / (h.n |o +
 * w|), e = t, u. GGX as four lobes c exp(-|s|^2 k / alpha^2) (each a
 * Gaussian of slopes of variance alpha^2/2k per axis times pi alpha^2 c/k)
 * convolves with the cluster's slope Gaussian in closed form: D's
 * expectation is sum c/k N(s; 0, alpha^2/2k I + J C J^T) / h.n^4. The
 * light is then N/pi x the emitter's cos/d^2 x E[D] x G(w)/G(axis) (Smith's
 * height-correlated G over the view term; M carries Fresnel, G(axis) and
 * 1/4 cos o) x F(w)/F(axis), the dielectric Fresnel ratio fres (scene/
 * material.h vsgl__fresnel_ratio: {eta, A, B}, the ratio A + B F(w.h, eta);
 * {0, 1, 0} for none). At a grazing view the Fresnel at the axis is
 * several times that of the directions out in GGX's tail: without the
 * ratio, a glossy sphere's lower rim reflected the lit floor beside it 36 %
 * too brightly. Unlike the ASG lobes (a warped NDF, exact at its peak only)
 * it keeps GGX's tail, where a metal floor shows the haze around a
 * reflected wall. Valid where the cluster subtends little and the half
 * vector stands well above the horizon: the weight blends it out beyond
 * (kernel.h). Each sharp lobe (the first VSGL__HV_RELIN) linearises the
 * map again where its product with the cluster's slope Gaussian peaks (w
 * for a cluster small against the lobe, the mirror direction for a wide
 * one) and takes D's 1/h.n^4, G and F there: at a grazing view (o + l).n
 * is small and the slope's change across a wide cluster is far from
 * linear. */
float vsgl__halfvec_glossy(const vsgl_vsgl *v, v3 x, v3 n, v3 o, v3 axis, float alpha, int lobes,
                           const float fres[3], float *weight);

#endif
