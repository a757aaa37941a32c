/* Internal: small inline vector helpers shared by every stage (float and double). */
#ifndef VSGL_MATH_VEC_H
#define VSGL_MATH_VEC_H

#include <math.h>
#include "vsgl/base.h"

typedef vsgl_vec3 v3;

static inline v3 v3_make(float x, float y, float z) { v3 r = {x, y, z}; return r; }
static inline v3 v3_add(v3 a, v3 b) { return v3_make(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline v3 v3_sub(v3 a, v3 b) { return v3_make(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline v3 v3_scale(v3 a, float s) { return v3_make(a.x * s, a.y * s, a.z * s); }
static inline v3 v3_neg(v3 a) { return v3_make(-a.x, -a.y, -a.z); }
static inline float v3_dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline v3 v3_cross(v3 a, v3 b)
{
    return v3_make(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float v3_length(v3 a) { return sqrtf(v3_dot(a, a)); }
/* Normalise; a zero (or non-finite-length) vector gives zero. */
static inline v3 v3_normalize(v3 a)
{
    float l = v3_length(a);
    return (l > 0.0f && l < INFINITY) ? v3_scale(a, 1.0f / l) : v3_make(0.0f, 0.0f, 0.0f);
}
static inline float clampf(float x, float lo, float hi) { return x < lo ? lo : (x > hi ? hi : x); }
/* 3t^2 - 2t^3 of t clamped to [0, 1]: the smooth blend weights of shade/. */
static inline float smoothstep01f(float t)
{
    t = clampf(t, 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

/* Orthonormal basis (x, y) completing unit z, continuous except at one
 * point (Duff et al. 2017, "Building an orthonormal basis, revisited"). */
static inline void v3_basis(v3 z, v3 *x, v3 *y)
{
    float s = copysignf(1.0f, z.z);
    float a = -1.0f / (s + z.z);
    float b = z.x * z.y * a;
    *x = v3_make(1.0f + s * z.x * z.x * a, s * b, -s * z.x);
    *y = v3_make(b, s + z.y * z.y * a, -z.y);
}

/* Reflect unit v about unit n: 2 (v.n) n - v. */
static inline v3 v3_reflect(v3 v, v3 n) { return v3_sub(v3_scale(n, 2.0f * v3_dot(v, n)), v); }

/* Double-precision 3-vectors for references and accumulations. */
typedef struct d3 { double x, y, z; } d3;
static inline d3 d3_make(double x, double y, double z) { d3 r = {x, y, z}; return r; }
static inline double d3_dot(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

#endif
