/**
 * @file vsgl/sg.h
 * @brief Spherical Gaussians (SG): evaluation, integral, product, product
 * integrals, SG x clamped cosine, and sharpness estimators.
 *
 * An SG is  G(w) = exp(log_amplitude + sharpness * (dot(w, axis) - 1)).
 * (docs/math.md gives every formula, its source and measured error.)
 * All functions are pure, thread-safe and cannot fail: sharpness is
 * clamped to [0, VSGL_SHARPNESS_MAX], a zero axis gives a zero-lobe result,
 * and -inf log_amplitude is an exact zero lobe.
 */
#ifndef VSGL_SG_H
#define VSGL_SG_H

#include "base.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Largest sharpness the operators use (2^41); larger inputs are clamped. */
#define VSGL_SHARPNESS_MAX 2199023255552.0f

/** A spherical Gaussian. Axis unit length; sharpness >= 0 (1/steradian-ish). */
typedef struct vsgl_sg {
    vsgl_vec3 axis;        /**< lobe axis, unit vector */
    float sharpness;       /**< lambda >= 0 */
    float log_amplitude;   /**< natural log of the peak value; -inf = zero lobe */
} vsgl_sg;

/** @brief G(dir). @p dir need not be normalised (it is). */
VSGL_API float vsgl_sg_eval(const vsgl_sg *g, const vsgl_vec3 *dir);

/**
 * @brief Integral of exp(lambda (w.xi - 1)) over the sphere:
 * A(lambda) = 2 pi (1 - exp(-2 lambda)) / lambda, computed as
 * -2 pi expm1(-2 lambda) / lambda (4 pi at lambda = 0). In steradians.
 */
VSGL_API float vsgl_sg_integral(float sharpness);

/** @brief Integral of the whole lobe: exp(log_amplitude) * A(sharpness). */
VSGL_API float vsgl_sg_lobe_integral(const vsgl_sg *g);

/**
 * @brief Product of two SGs, itself an SG: axis along l1 xi1 + l2 xi2,
 * sharpness its length, log-amplitude la1 + la2 - l1 l2 |xi1 - xi2|^2 /
 * (lm + l1 + l2) (the cancellation-free form). The product's sharpness is
 * clamped to ::VSGL_SHARPNESS_MAX like any other (two lobes at the cap give
 * twice the exact product integral).
 * @param[out] out may alias @p a or @p b.
 */
VSGL_API void vsgl_sg_product(const vsgl_sg *a, const vsgl_sg *b, vsgl_sg *out);

/** @brief Exact integral over the sphere of the product of two SGs. */
VSGL_API float vsgl_sg_product_integral(const vsgl_sg *a, const vsgl_sg *b);

/**
 * @brief Iwasaki et al. 2012 approximation of the product integral:
 * 2 pi a1 a2 G(xi1; xi2, l1 l2 / (l1 + l2)) / (l1 + l2). Accurate for sharp
 * lobes, over-estimates broad ones (docs/math.md); capped at the exact bound
 * a1 a2 min(A(l1), A(l2)) so it stays finite as the sharpness goes to 0.
 */
VSGL_API float vsgl_sg_product_integral_iwasaki(const vsgl_sg *a, const vsgl_sg *b);

/** How ::vsgl_sg_cosine_integral treats the clamped cosine max(w.n, 0). */
#define VSGL_COSINE_ACCURATE    0  /**< accurate fitted form (docs/math.md gives the error); the default */
#define VSGL_COSINE_SG          1  /**< poster: cosine ~ pi G(w; n, lambda_d) / A(lambda_d), SG product integral */
#define VSGL_COSINE_PULLED_OUT  2  /**< FIS supplement: max(xi.n, 0) * integral of the SG */

/** Least-squares sharpness lambda_d of the poster's SG-cosine (docs/math.md). */
VSGL_API float vsgl_sg_cosine_sharpness(void);

/**
 * @brief Integral over the sphere of G(w) * max(dot(w, n), 0) in the chosen
 * @p mode (one of VSGL_COSINE_*; unknown modes behave as ACCURATE).
 * Always finite and >= 0 for finite input.
 */
VSGL_API float vsgl_sg_cosine_integral(const vsgl_sg *g, const vsgl_vec3 *n, int32_t mode);

/** Estimators of sharpness from a mean resultant length r in [0, 1). */
#define VSGL_SHARPNESS_TOKSVIG  0  /**< lambda = r / (1 - r) */
#define VSGL_SHARPNESS_BANERJEE 1  /**< lambda = r (3 - r^2) / (1 - r^2) */

/**
 * @brief Sharpness of the vMF whose mean resultant length is about @p r.
 * r <= 0 gives 0; r -> 1 gives at most ::VSGL_SHARPNESS_MAX; NaN gives 0.
 */
VSGL_API float vsgl_sharpness_from_mean_length(float r, int32_t estimator);

/**
 * @brief Mean resultant length of a normalised SG (inverse of Toksvig's
 * estimate): lambda / (lambda + 1) for TOKSVIG, and the exact
 * coth(lambda) - 1/lambda for BANERJEE (the vMF's true mean length).
 */
VSGL_API float vsgl_mean_length_from_sharpness(float sharpness, int32_t estimator);

#ifdef __cplusplus
}
#endif
#endif /* VSGL_SG_H */
