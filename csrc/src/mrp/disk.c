/* The MRP sampling-disk integral (Eq. 23-27): the attenuation of the
 * reflected radiance around the peak, its fit (Eq. 25) and the closed-form
 * cap integral. docs/mrp.md measures each against quadrature;
 * tools/mrp_fit_k.py reproduces Eq. 25's constants. */
#include "mrp/mrp.h"
#include "math/constants.h"

double vsgl__mrp_psi(double theta, double sigma)
{
    double c = cos(sigma);
    return -0.5 * sigma + 0.5 * atan(tan(theta) / (c * c) + tan(sigma));
}

double vsgl__mrp_f_ggx(double theta, double sigma, double m)
{
    double m2 = m * m, c = cos(vsgl__mrp_psi(theta, sigma));
    /* 1 - (1 - m^2) c^2 = m^2 c^2 + s^2: no cancellation for small m */
    double den = m2 * c * c + (1.0 - c * c);
    return den > 0.0 ? (m2 / den) * (m2 / den) : 1.0;
}

double vsgl__mrp_k(double cos_sigma, double m) { return 0.288 * cos_sigma / (m * m) - 0.673; }

double vsgl__mrp_f_fit(double theta, double k)
{
    double s = sin(theta);
    return exp(-k * s * s) * cos(theta);
}

double vsgl__mrp_cap_t(double l, double cos_sigma)
{
    double q = l * cos_sigma;
    q *= q;
    if (!(q >= 0.0))
        return 0.0;
    return q < INFINITY ? q / (1.0 + q) : 1.0;
}

double vsgl__mrp_disk_integral(double k, double t)
{
    if (!(t > 0.0))
        return 0.0;
    t = t < 1.0 ? t : 1.0;
    double kt = k > 0.0 ? (k < INFINITY ? k * t : INFINITY) : 0.0;
    /* (1 - e^{-x}) / x, -> 1 as x -> 0, -> 1/x as x -> inf */
    double g = kt > 1e-8 ? -expm1(-kt) / kt : 1.0 - 0.5 * kt;
    return VSGL__PI_D * t * g;
}

double vsgl__mrp_disk_radiance(double overlap, double k, double t, double L_y)
{
    double e = vsgl__mrp_disk_integral(k, t);
    double c = overlap * e * L_y;
    return c > 0.0 && c < INFINITY ? c : 0.0;
}
