/* The MRP ASG light (Eq. 28-35), its convolution with the receiver's
 * warped-NDF SG (Eq. 8-11) and the SG-only variant (Eq. 37). The SG/ASG
 * operators are the library's (csrc/src/math). docs/mrp.md. */
#include "mrp/mrp.h"
#include "mrp/geom.h"
#include "math/asg_internal.h"
#include "math/constants.h"
#include "vsgl/lobes.h"

double vsgl__mrp_asg_integral_unit(double lambda, double mu)
{
    double hi = lambda >= mu ? lambda : mu, lo = lambda >= mu ? mu : lambda;
    if (!(lo >= VSGL__ASG_EQ10_MIN_MU) || !(hi < INFINITY))
        return vsgl__asg_integral_unit(lambda, mu); /* NaN, small or infinite bandwidths */
    return vsgl__asg_integral_eq10_fast(hi, lo);
}

double vsgl__mrp_bandwidth(double l)
{
    if (!(l > 0.0))
        return VSGL_SHARPNESS_MAX;
    if (!(l < INFINITY))
        return 0.0;
    double b = (1.0 + 1.0 / (l * l)) * (2.996 - 0.5 * log1p(l * l));
    return b > 0.0 ? (b < VSGL_SHARPNESS_MAX ? b : VSGL_SHARPNESS_MAX) : 0.0;
}

static void zero_asg(vsgl_asg *out)
{
    out->x = v3_make(1.0f, 0.0f, 0.0f);
    out->y = v3_make(0.0f, 1.0f, 0.0f);
    out->z = v3_make(0.0f, 0.0f, 1.0f);
    out->lambda = out->mu = 0.0f;
    out->log_amplitude = -INFINITY;
}

int vsgl__mrp_asg_light_d(d3 x, d3 y, d3 n_d, double rd, double C, int norm, double frame[3][3], double *lambda,
                          double *mu, double *log_amplitude)
{
    d3 xy = d3_sub(y, x);
    double d = d3_length(xy);
    if (!(d > 0.0) || !(d < INFINITY) || !(C > 0.0) || !(C < INFINITY) || !(rd > 0.0))
        return 0;
    d3 z = d3_scale(xy, 1.0 / d), yx = d3_scale(z, -1.0);
    double cs = d3_dot(n_d, yx);
    if (!(cs > 0.0))
        return 0;
    d3 u, v;
    vsgl__mrp_disk_axes(yx, n_d, &u, &v);
    double lm = rd / d, ln = lm * (cs < 1.0 ? cs : 1.0);      /* Eq. 29 at distance d */
    double lam = vsgl__mrp_bandwidth(lm), m = vsgl__mrp_bandwidth(ln); /* Eq. 32 */
    double integral;                                           /* of the unit ASG */
    if (norm == VSGL__MRP_NORM_PAPER)
        integral = lam > 0.0 && m > 0.0 ? VSGL__PI_D / sqrt(lam * m) : INFINITY; /* Eq. 34 */
    else
        integral = vsgl__mrp_asg_integral_unit(lam, m);
    if (!(integral > 0.0) || !(integral < INFINITY))
        return 0;
    d3 w = d3_cross(z, v); /* n = yx x v up to sign; the ASG is even in it */
    const d3 axes[3] = {v, w, z}; /* m = v, Eq. 28 */
    for (int k = 0; k < 3; ++k)
        frame[k][0] = axes[k].x, frame[k][1] = axes[k].y, frame[k][2] = axes[k].z;
    *lambda = lam;
    *mu = m;
    *log_amplitude = log(C) - log(integral); /* Eq. 35: t = C / integral */
    return 1;
}

int vsgl__mrp_asg_light(d3 x, d3 y, d3 n_d, double rd, double C, int norm, vsgl_asg *out)
{
    zero_asg(out);
    double f[3][3], lam, mu, la;
    if (!vsgl__mrp_asg_light_d(x, y, n_d, rd, C, norm, f, &lam, &mu, &la))
        return 0;
    out->z = v3_make((float)f[2][0], (float)f[2][1], (float)f[2][2]);
    out->x = v3_make((float)f[0][0], (float)f[0][1], (float)f[0][2]);
    out->y = v3_make((float)f[1][0], (float)f[1][1], (float)f[1][2]);
    out->lambda = (float)lam;
    out->mu = (float)mu;
    out->log_amplitude = (float)la;
    return 1;
}

void vsgl__mrp_receiver_sg(d3 n, d3 o, double alpha, vsgl_sg *out)
{
    vsgl_vec3 nf = d3_to_v3(n), of = d3_to_v3(o);
    vsgl_sg ndf;
    vsgl_ndf_to_sg(&nf, (float)alpha, VSGL_NDF_GGX, &ndf);
    vsgl_warp_ndf_sg(&ndf, &of, out);
}

double vsgl__mrp_convolve(const vsgl_asg *light, const vsgl_sg *g)
{
    vsgl_asg conv;
    vsgl__asg_convolve_sg_mode(light, g, &conv, VSGL__CONV_PAPER);
    double v = vsgl_asg_eval(&conv, &g->axis);
    return v > 0.0 && v < INFINITY ? v : 0.0;
}

void vsgl__mrp_asg_to_sg(const vsgl_asg *a, int geometric_mean, vsgl_sg *out)
{
    double lam = vsgl__asg_clamp_bw(a->lambda), mu = vsgl__asg_clamp_bw(a->mu);
    double big = lam >= mu ? lam : mu, small = lam >= mu ? mu : lam;
    double s = geometric_mean ? 2.0 * sqrt(big * small) : 2.0 * big;
    out->axis = a->z;
    out->sharpness = (float)(s < VSGL_SHARPNESS_MAX ? s : VSGL_SHARPNESS_MAX);
    double la = a->log_amplitude;
    if (geometric_mean && la > -INFINITY) {
        /* energy kept: the ASG's integral over that of the SG */
        double ia = vsgl__asg_integral_unit(big, small), is = vsgl_sg_integral(out->sharpness);
        if (ia > 0.0 && is > 0.0)
            la += log(ia) - log(is);
    }
    out->log_amplitude = (float)la;
}

double vsgl__mrp_convolve_sg(const vsgl_sg *light, const vsgl_sg *g)
{
    double v = vsgl_sg_product_integral_iwasaki(light, g);
    return v > 0.0 && v < INFINITY ? v : 0.0;
}
