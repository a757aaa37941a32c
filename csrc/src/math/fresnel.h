/* Internal: the unpolarised Fresnel reflectance of a dielectric interface. */
#ifndef VSGL_MATH_FRESNEL_H
#define VSGL_MATH_FRESNEL_H

#include <math.h>

/* Cycles' fresnel_dielectric_cos at cosine c >= 0 for relative IOR eta; 1
 * under total internal reflection (eta^2 - 1 + c^2 <= 0, also eta 0).
 * Without branches, so that the kernel's loops vectorise (kernel.h: the
 * half-vector model's Fresnel ratio); scene/material.c's BRDF takes the
 * same. */
static inline float vsgl__fresnel_dielectric(float c, float eta)
{
    float g2 = eta * eta - 1.0f + c * c;
    float g = sqrtf(g2 > 0.0f ? g2 : 1.0f); /* 1: a placeholder where the result is 1 */
    float a = (g - c) / (g + c), b = (c * (g + c) - 1.0f) / (c * (g - c) + 1.0f);
    float f = 0.5f * a * a * (1.0f + b * b);
    return g2 > 0.0f ? f : 1.0f;
}

#endif
