/* Internal to csrc/src/mrp: double 3-vector helpers. */
#ifndef VSGL_MRP_GEOM_H
#define VSGL_MRP_GEOM_H

#include "math/vec.h"

static inline d3 d3_add(d3 a, d3 b) { return d3_make(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline d3 d3_sub(d3 a, d3 b) { return d3_make(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline d3 d3_scale(d3 a, double s) { return d3_make(a.x * s, a.y * s, a.z * s); }
static inline d3 d3_cross(d3 a, d3 b)
{
    return d3_make(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double d3_length(d3 a) { return sqrt(d3_dot(a, a)); }
/* Normalise; zero or non-finite length gives zero. */
static inline d3 d3_normalize(d3 a)
{
    double l = d3_length(a);
    return (l > 0.0 && l < INFINITY) ? d3_scale(a, 1.0 / l) : d3_make(0.0, 0.0, 0.0);
}
static inline int d3_is_zero(d3 a) { return a.x == 0.0 && a.y == 0.0 && a.z == 0.0; }
static inline int d3_finite(d3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
static inline vsgl_vec3 d3_to_v3(d3 a) { return v3_make((float)a.x, (float)a.y, (float)a.z); }
static inline d3 d3_of_v3(vsgl_vec3 a) { return d3_make(a.x, a.y, a.z); }
/* fmax / fmin inline (libm's are calls at -O2): the same value for every
 * input, NaN included (a NaN argument gives the other one), and for equal
 * arguments the second, as glibc's maxsd/minsd-based ones. */
static inline double d_max(double a, double b) { return a > b ? a : (b != b ? a : b); }
static inline double d_min(double a, double b) { return a < b ? a : (b != b ? a : b); }
/* Orthonormal completion of unit z (Duff et al. 2017), double precision. */
static inline void d3_basis(d3 z, d3 *x, d3 *y)
{
    double s = copysign(1.0, z.z), a = -1.0 / (s + z.z), b = z.x * z.y * a;
    *x = d3_make(1.0 + s * z.x * z.x * a, s * b, -s * z.x);
    *y = d3_make(b, s + z.y * z.y * a, -z.y);
}

#endif
