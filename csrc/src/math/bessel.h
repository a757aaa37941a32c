/* Internal: exponentially scaled modified Bessel function I0e(x) = e^{-|x|} I0(x)
 * and the ASG paper's F(a) = int_0^{2pi} exp(-a cos^2 phi) dphi = 2 pi I0e(a/2). */
#ifndef VSGL_MATH_BESSEL_H
#define VSGL_MATH_BESSEL_H

/* e^{-|x|} I0(x) in double precision (relative error < 1e-15, tests/c/test_asg.c).
 * Power series for |x| <= 20, Hankel's asymptotic series above. Finite for
 * every finite x; I0e(+-inf) = 0; NaN gives NaN. */
double vsgl__i0e(double x);

/* e^{-x} I0(x) for x >= 0 by Abramowitz & Stegun 9.8.1 / 9.8.2 (relative
 * error < 6e-7): for terms that are small beside others (Eq. 10's second). */
double vsgl__i0e_poly(double x);

/* F(a) = 2 pi e^{-a/2} I0(a/2) for a >= 0 (negative a is treated as |a|:
 * callers never pass it). F(0) = 2 pi, F(a) ~ 2 sqrt(pi / a) for large a. */
double vsgl__bessel_f(double a);

#endif
