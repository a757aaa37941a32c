/**
 * @file vsgl/asg.h
 * @brief Anisotropic spherical Gaussians (Xu et al. 2013): evaluation,
 * integral (Eq. 10 and 11), product (Eq. 13), convolution with an SG
 * (Eq. 18), SG -> ASG (Eq. 3), and the ASG x SG product integral used for
 * glossy shading.
 *
 * An ASG is  exp(log_amplitude) * max(v.z, 0) * exp(-lambda (v.x)^2 - mu (v.y)^2)
 * with [x, y, z] an orthonormal right-handed frame and lambda, mu >= 0
 * (Xu's bandwidths: an SG of sharpness s corresponds to lambda = mu = s/2).
 * Pure, thread-safe, never fails; bandwidths clamped to [0, VSGL_SHARPNESS_MAX].
 */
#ifndef VSGL_ASG_H
#define VSGL_ASG_H

#include "sg.h"

#ifdef __cplusplus
extern "C" {
#endif

/** An anisotropic spherical Gaussian. The operators re-orthonormalise the
 * frame (x projected off z, y = z x x). */
typedef struct vsgl_asg {
    vsgl_vec3 x;           /**< tangent axis (bandwidth lambda) */
    vsgl_vec3 y;           /**< bitangent axis (bandwidth mu) */
    vsgl_vec3 z;           /**< lobe axis */
    float lambda;          /**< bandwidth along x, >= 0 */
    float mu;              /**< bandwidth along y, >= 0 */
    float log_amplitude;   /**< natural log of c; -inf = zero lobe */
} vsgl_asg;

/** @brief Value of the ASG in direction @p dir (normalised internally). */
VSGL_API float vsgl_asg_eval(const vsgl_asg *a, const vsgl_vec3 *dir);

/**
 * @brief F(a) = integral_0^{2pi} exp(-a cos^2 phi) dphi = 2 pi e^{-a/2} I0(a/2),
 * evaluated with an exponentially scaled I0 (no table). a >= 0.
 */
VSGL_API float vsgl_asg_bessel_f(float a);

/**
 * @brief Integral over the sphere: Xu et al. Eq. 10 (with exact F) for
 * min(lambda, mu) >= 12; below, an exact 1-D quadrature (Eq. 10 diverges as
 * mu -> 0). Max relative error 1.7e-9 (docs/math_asg.md).
 */
VSGL_API float vsgl_asg_integral(const vsgl_asg *a);

/** @brief Integral over the sphere by Xu et al. Eq. 11: c pi / sqrt(lambda mu), capped at c pi. */
VSGL_API float vsgl_asg_integral_approx(const vsgl_asg *a);

/**
 * @brief Product of two ASGs as one ASG (Eq. 13): A3 = A1 + A2 decomposed
 * by a symmetric 3x3 eigen-solver; the smooth term evaluated at the peak.
 * @param[out] out may alias an input.
 */
VSGL_API void vsgl_asg_product(const vsgl_asg *a, const vsgl_asg *b, vsgl_asg *out);

/**
 * @brief Convolution of an ASG with the SG kernel exp(2 nu (v.p - 1)),
 * nu = sg->sharpness / 2, as an ASG over p (Eq. 18): bandwidths
 * nu lambda / (nu + lambda), nu mu / (nu + mu), amplitude multiplied by
 * the exact integral of a unit ASG of bandwidths (lambda + nu, mu + nu)
 * (equal to Eq. 18's pi / sqrt((lambda + nu)(mu + nu)) within 1e-7 when
 * min(lambda, mu) + nu >= 12, finite at zero bandwidths) and by the
 * kernel's own amplitude.
 * The kernel's axis is ignored (the result is a function of it).
 */
VSGL_API void vsgl_asg_convolve_sg(const vsgl_asg *a, const vsgl_sg *kernel, vsgl_asg *out);

/**
 * @brief Integral over the sphere of ASG(w) * SG(w): the convolution of
 * Eq. 18 evaluated at the SG's axis (the poster's glossy shading form),
 * both amplitudes included. Broad SGs (sharpness < ~16) off the ASG's axis
 * lose up to 40 % of the peak value (docs/math_asg.md).
 */
VSGL_API float vsgl_asg_sg_product_integral(const vsgl_asg *a, const vsgl_sg *g);

/**
 * @brief SG -> ASG of equal bandwidths (Eq. 3): lambda = mu = sharpness/2,
 * same axis and amplitude, x and y any orthonormal completion.
 */
VSGL_API void vsgl_sg_to_asg(const vsgl_sg *g, vsgl_asg *out);

#ifdef __cplusplus
}
#endif
#endif /* VSGL_ASG_H */
