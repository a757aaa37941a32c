/* Internal: erfc and the standard normal CDF for float code outside the
 * kernel (which has its own vectorisable copies, shade/kernel_impl.h). */
#ifndef VSGL_MATH_NORMAL_H
#define VSGL_MATH_NORMAL_H
#include <math.h>

/* erf(x) = 1 - P(x) exp(-x^2) for x >= 0 (Abramowitz & Stegun 7.1.26,
 * |error| <= 1.5e-7): returns P so the caller shares the exponential. */
static inline float vsgl__erfc_poly(float x)
{
    float k = 1.0f / (1.0f + 0.3275911f * x);
    return k * (0.254829592f + k * (-0.284496736f + k * (1.421413741f + k * (-1.453152027f + k * 1.061405429f))));
}

/* Phi(z), the standard normal CDF, given e = e^{-z^2 / 2} (which the
 * normal density at z shares); within 1.5e-7. */
static inline float vsgl__normal_cdf_e(float z, float e)
{
    float tail = 0.5f * e * vsgl__erfc_poly(fabsf(z) * 0.70710678f);
    return z < 0.0f ? tail : 1.0f - tail;
}

static inline float vsgl__normal_cdf(float z)
{
    return vsgl__normal_cdf_e(z, expf(-0.5f * z * z));
}
#endif
