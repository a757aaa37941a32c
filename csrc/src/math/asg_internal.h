/* Internal: double-precision ASG kernels shared by asg.c, the tests and
 * tools/asg_error_table.c (docs/math_asg.md gives every formula). */
#ifndef VSGL_MATH_ASG_INTERNAL_H
#define VSGL_MATH_ASG_INTERNAL_H

#include "vsgl/asg.h"

/* Below this smaller bandwidth vsgl_asg_integral leaves Eq. 10 for the
 * exact 1-D quadrature (Eq. 10's own error there is < e^{-mu}/sqrt(pi mu)
 * < 1e-6 relative, so the switch is continuous to that level). */
#define VSGL__ASG_EQ10_MIN_MU 12.0

/* Orthonormal right-handed frame of an ASG in double precision:
 * z normalised; x = the part of a->x orthogonal to z, normalised; y = z x x.
 * If a->x is (nearly) parallel to z or zero, x comes from y: x = y' x z with
 * y' the normalised part of a->y orthogonal to z; if both are degenerate, an
 * arbitrary completion (Duff et al.). Returns 0 when z is zero or not
 * finite (the lobe is then treated as zero), 1 otherwise. */
typedef struct vsgl__frame { double x[3], y[3], z[3]; } vsgl__frame;
int vsgl__asg_frame(const vsgl_asg *a, vsgl__frame *f);

/* Bandwidth clamped to [0, VSGL_SHARPNESS_MAX] (NaN stays NaN). */
double vsgl__asg_clamp_bw(float b);

/* Xu et al. Eq. 10 exactly as printed (F exact), unit amplitude; the
 * arguments are sorted so lambda >= mu. lambda = mu gives the exact
 * pi (1 - e^{-lambda}) / lambda; mu = 0 < lambda gives +inf (Eq. 10
 * diverges like (pi - sqrt(pi)) / sqrt(lambda mu)); 0, 0 gives pi. */
double vsgl__asg_integral_eq10(double lambda, double mu);

/* Exact integral (1-D Gauss-Legendre, relative error < 1e-9) of the unit
 * ASG: pi * int_0^1 e^{-s mu} I0e(s (lambda - mu)/2) ds, lambda >= mu. Any mu
 * works; used below VSGL__ASG_EQ10_MIN_MU. */
double vsgl__asg_integral_exact(double lambda, double mu);

/* What vsgl_asg_integral computes for unit amplitude: Eq. 10 for
 * min(lambda, mu) >= VSGL__ASG_EQ10_MIN_MU, the exact quadrature below. */
double vsgl__asg_integral_unit(double lambda, double mu);

/* Eq. 10 for min(lambda, mu) >= VSGL__ASG_EQ10_MIN_MU (both finite) within
 * 1e-9 of vsgl__asg_integral_unit, faster: its small second term (at most
 * e^{-min} sqrt(max / min) of the first) with the polynomial I0e
 * (vsgl__i0e_poly), and none where it is below 2^-54 of the first (the
 * same double). */
double vsgl__asg_integral_eq10_fast(double lambda, double mu);

/* vsgl__asg_integral_unit within 5e-5 (relative), for work per receiver
 * (the horizon cut of a glossy receiver's lobe, lobes.c): below
 * VSGL__ASG_EQ10_MIN_MU bilinear in vsgl__asg_table (asg_table.c, generated
 * by tools/gen_asg_table.py; 4.2e-5 at most, tests/c/test_asg.c), above it
 * vsgl__asg_integral_eq10_fast; NaN, negative or infinite bandwidths take
 * vsgl__asg_integral_unit. The exact quadrature costs ~1 us per call: two
 * calls per glossy receiver were a quarter of a live camera edit's CPU
 * time. */
#define VSGL__ASG_TABLE_NX 65
#define VSGL__ASG_TABLE_NY 129
extern const float vsgl__asg_table[VSGL__ASG_TABLE_NX][VSGL__ASG_TABLE_NY];
double vsgl__asg_integral_unit_fast(double lambda, double mu);

/* Normalisation of the convolution / ASG x SG product integral:
 * VSGL__CONV_PAPER = pi / sqrt((lambda + nu)(mu + nu)) (Eq. 18 as printed;
 * infinite at lambda + nu = 0), VSGL__CONV_EXACT_INTEGRAL = the ASG integral
 * of bandwidths lambda + nu, mu + nu (equal to the former up to
 * e^{-(mu + nu)}, finite everywhere; what the library uses). */
#define VSGL__CONV_PAPER 0
#define VSGL__CONV_EXACT_INTEGRAL 1
void vsgl__asg_convolve_sg_mode(const vsgl_asg *a, const vsgl_sg *kernel, vsgl_asg *out, int mode);

#endif
