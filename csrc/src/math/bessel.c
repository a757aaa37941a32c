/* Exponentially scaled I0 without tables (docs/math_asg.md, "F(a)"). */
#include "math/bessel.h"
#include "math/constants.h"

#include <math.h>

double vsgl__i0e(double x)
{
    double ax = fabs(x);
    if (isnan(x))
        return x;
    if (ax <= 20.0) {
        /* I0(x) = sum_k (x^2/4)^k / (k!)^2: positive terms, no cancellation;
         * I0(20) = 4.4e7, so the sum cannot overflow. <= 45 terms. */
        double q = 0.25 * ax * ax, term = 1.0, sum = 1.0;
        for (int k = 1; k < 80; ++k) {
            term *= q / ((double)k * (double)k);
            sum += term;
            if (term < 1e-17 * sum)
                break;
        }
        return sum * exp(-ax);
    }
    if (ax == INFINITY)
        return 0.0;
    /* Hankel: I0e(x) ~ (2 pi x)^{-1/2} sum_k ((2k-1)!!)^2 / (k! (8x)^k).
     * For x > 20 the terms fall below 1e-17 long before they start to
     * grow again (the smallest term is about e^{-2x}). */
    double inv8x = 1.0 / (8.0 * ax), term = 1.0, sum = 1.0;
    for (int k = 1; k < 60; ++k) {
        double odd = 2.0 * k - 1.0;
        term *= odd * odd * inv8x / (double)k;
        sum += term;
        if (term < 1e-17 * sum)
            break;
    }
    return sum / sqrt(2.0 * VSGL__PI_D * ax);
}

double vsgl__bessel_f(double a)
{
    return 2.0 * VSGL__PI_D * vsgl__i0e(0.5 * a);
}

double vsgl__i0e_poly(double x)
{
    if (x <= 3.75) {
        double t = x / 3.75;
        t *= t;
        double i0 = 1.0 + t * (3.5156229 + t * (3.0899424 + t * (1.2067492 + t * (0.2659732 + t * (0.0360768 +
                    t * 0.0045813)))));
        return i0 * exp(-x);
    }
    double t = 3.75 / x;
    double p = 0.39894228 + t * (0.01328592 + t * (0.00225319 + t * (-0.00157565 + t * (0.00916281 + t * (-0.02057706 +
               t * (0.02635537 + t * (-0.01647633 + t * 0.00392377)))))));
    return p / sqrt(x);
}
