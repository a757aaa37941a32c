/* Spherical Gaussians: evaluation, integral, product, product integrals,
 * sharpness estimators. docs/math.md gives every formula, its source and
 * its measured error. The SG x clamped-cosine integral is in sg_cosine.c. */
#include "vsgl/sg.h"
#include "math/sg_internal.h"

#include <float.h>

float vsgl__sg_clamp_sharpness(float lambda)
{
    /* NaN and negatives -> 0, +inf and huge -> the cap. */
    if (!(lambda > 0.0f))
        return 0.0f;
    return lambda < VSGL_SHARPNESS_MAX ? lambda : VSGL_SHARPNESS_MAX;
}

/* A(lambda) / (2 pi) = (1 - exp(-2 lambda)) / lambda; 2 at lambda = 0. */
float vsgl__sg_integral_over_2pi(float lambda)
{
    return lambda > 0.0f ? -expm1f(-2.0f * lambda) / lambda : 2.0f;
}

float vsgl__sg_log_integral(float lambda)
{
    /* log A = log(2 pi) + log((1 - e^{-2l}) / l); the second factor is in
     * (0, 2] for every l >= 0 and >= 2^-41 at the cap: no overflow. */
    return VSGL__LOG_2PI + logf(vsgl__sg_integral_over_2pi(lambda));
}

/* Mean resultant length of a vMF: coth(l) - 1/l. Below 1 a Taylor series
 * (9 terms, truncation < 3e-9 relative at l = 1); above it
 * 1 - 1/l + 2 e^{-2l} / (1 - e^{-2l}), which has no cancellation for l >= 1. */
float vsgl__sg_mean_length(float l)
{
    if (l < 1.0f) {
        float l2 = l * l;
        return l * (1.0f / 3.0f + l2 * (-1.0f / 45.0f + l2 * (2.0f / 945.0f + l2 * (-1.0f / 4725.0f
               + l2 * (2.0f / 93555.0f + l2 * (-1382.0f / 638512875.0f + l2 * (4.0f / 18243225.0f
               + l2 * (-3617.0f / 162820783125.0f + l2 * (87734.0f / 38979295480125.0f)))))))));
    }
    float em = -expm1f(-2.0f * l); /* 1 - e^{-2l} */
    return (1.0f - 1.0f / l) + 2.0f * (1.0f - em) / em;
}

float vsgl__sg_fraction_above(float l, float c)
{
    enum { N = 24 };
    c = c < -1.0f ? -1.0f : c > 1.0f ? 1.0f : c;
    if (!(l > 1e-3f))
        return 0.5f + 0.25f * c * (l > 0.0f ? l : 0.0f); /* density ~ (1 + l w.axis) / 4 pi */
    /* a sharp lobe 4.5 of its spreads above (below) the plane: 1 (0) within 1e-5 */
    if (l > 20.0f && fabsf(asinf(c)) * sqrtf(l) > 4.5f)
        return c > 0.0f ? 1.0f : 0.0f;
    /* f(-c) = 1 - f(c): with c >= 0, in t = w.axis the rings t > s (s the
     * sine of the axis's angle to the normal) lie wholly above the plane,
     * t < -s wholly below, and between a ring's part above is
     * acos(-t c / (sqrt(1 - t^2) s)) / pi. Over u = exp(l (t - 1)), uniform
     * in the lobe's density, the rings above are 1 - u(s) of 1 - e^-2l;
     * the band between is integrated in u = u(-s) .. u(s) clustered at its
     * ends, where the ring's part has a square-root corner (a midpoint rule
     * in cos on 24 nodes, its weights normalised). */
    double cd = fabs((double)c), sd = sqrt(fmax(1.0 - cd * cd, 0.0)), ld = l;
    double lo = exp(-2.0 * ld), ua = exp(-ld * (1.0 + sd)), ub = exp(-ld * (1.0 - sd)), acc = 1.0 - ub;
    if (sd > 1e-7) {
        double band = 0.0, weights = 0.0;
        for (int j = 0; j < N; ++j) {
            double ph = (j + 0.5) * (3.141592653589793 / N), u = ua + 0.5 * (ub - ua) * (1.0 - cos(ph));
            double t = 1.0 + log(u) / ld, r = sqrt(fmax(1.0 - t * t, 0.0));
            double x = r > 0.0 ? -t * cd / (r * sd) : (t > 0.0 ? -1.0 : 1.0);
            double q = x <= -1.0 ? 1.0 : x >= 1.0 ? 0.0 : acos(x) * 0.3183098861837907;
            band += q * sin(ph);
            weights += sin(ph);
        }
        acc += (ub - ua) * band / weights; /* the weights sum to the band's mass: 1/2 at c = 0 exactly */
    }
    double f = acc / (1.0 - lo);
    f = f < 0.0 ? 0.0 : f > 1.0 ? 1.0 : f;
    return (float)(c < 0.0f ? 1.0 - f : f);
}

/* Unit axis of an SG, or zero if the axis is zero/non-finite. */
static v3 sg_axis(const vsgl_sg *g)
{
    return v3_normalize(g->axis);
}

static int sg_is_zero(const vsgl_sg *g, v3 axis)
{
    return (axis.x == 0.0f && axis.y == 0.0f && axis.z == 0.0f) || g->log_amplitude == -INFINITY;
}

float vsgl_sg_eval(const vsgl_sg *g, const vsgl_vec3 *dir)
{
    v3 a = sg_axis(g);
    if (sg_is_zero(g, a))
        return 0.0f;
    /* In double: w.xi - 1 = -|w - xi|^2 / 2 with w and xi normalised in
     * double, so a sharp lobe keeps every digit of the float inputs. */
    double ax = g->axis.x, ay = g->axis.y, az = g->axis.z;
    double wx = dir->x, wy = dir->y, wz = dir->z;
    double la = sqrt(ax * ax + ay * ay + az * az), lw = sqrt(wx * wx + wy * wy + wz * wz);
    if (!(lw > 0.0) || !(lw < INFINITY))
        return 0.0f;
    double dx = wx / lw - ax / la, dy = wy / lw - ay / la, dz = wz / lw - az / la;
    double lambda = vsgl__sg_clamp_sharpness(g->sharpness);
    return (float)exp((double)g->log_amplitude - 0.5 * lambda * (dx * dx + dy * dy + dz * dz));
}

float vsgl_sg_integral(float sharpness)
{
    return VSGL__2PI * vsgl__sg_integral_over_2pi(vsgl__sg_clamp_sharpness(sharpness));
}

float vsgl_sg_lobe_integral(const vsgl_sg *g)
{
    v3 a = sg_axis(g);
    if (sg_is_zero(g, a))
        return 0.0f;
    return expf(g->log_amplitude + vsgl__sg_log_integral(vsgl__sg_clamp_sharpness(g->sharpness)));
}

void vsgl_sg_product(const vsgl_sg *a, const vsgl_sg *b, vsgl_sg *out)
{
    v3 xa = sg_axis(a), xb = sg_axis(b);
    float la = vsgl__sg_clamp_sharpness(a->sharpness), lb = vsgl__sg_clamp_sharpness(b->sharpness);
    vsgl_sg r;
    if (sg_is_zero(a, xa) || sg_is_zero(b, xb)) {
        r.axis = sg_is_zero(a, xa) ? xb : xa;
        r.sharpness = 0.0f;
        r.log_amplitude = -INFINITY;
        *out = r;
        return;
    }
    v3 s = v3_add(v3_scale(xa, la), v3_scale(xb, lb));
    float lm = v3_length(s);
    v3 d = v3_sub(xa, xb);
    float den = lm + la + lb;
    float expo = den > 0.0f ? -(la * lb) * v3_dot(d, d) / den : 0.0f;
    r.axis = lm > 0.0f ? v3_scale(s, 1.0f / lm) : xa;
    r.sharpness = vsgl__sg_clamp_sharpness(lm);
    r.log_amplitude = a->log_amplitude + b->log_amplitude + expo;
    *out = r;
}

float vsgl_sg_product_integral(const vsgl_sg *a, const vsgl_sg *b)
{
    vsgl_sg p;
    vsgl_sg_product(a, b, &p);
    if (p.log_amplitude == -INFINITY)
        return 0.0f;
    return expf(p.log_amplitude + vsgl__sg_log_integral(p.sharpness));
}

float vsgl_sg_product_integral_iwasaki(const vsgl_sg *a, const vsgl_sg *b)
{
    v3 xa = sg_axis(a), xb = sg_axis(b);
    if (sg_is_zero(a, xa) || sg_is_zero(b, xb))
        return 0.0f;
    float la = vsgl__sg_clamp_sharpness(a->sharpness), lb = vsgl__sg_clamp_sharpness(b->sharpness);
    float sum = la + lb;
    /* 2 pi a1 a2 exp(l1 l2 / (l1 + l2) (xi1.xi2 - 1)) / (l1 + l2), with
     * xi1.xi2 - 1 = -|xi1 - xi2|^2 / 2. The formula diverges as l1 + l2 -> 0;
     * it is capped by the exact bound a1 a2 min(A(l1), A(l2)) (docs/math.md). */
    v3 d = v3_sub(xa, xb);
    float lr = sum > 0.0f ? (la / sum) * lb : 0.0f;
    float log_iw = VSGL__LOG_2PI - 0.5f * lr * v3_dot(d, d) - logf(sum > FLT_MIN ? sum : FLT_MIN);
    float log_bound = vsgl__sg_log_integral(la > lb ? la : lb);
    float l = log_iw < log_bound ? log_iw : log_bound;
    return expf(a->log_amplitude + b->log_amplitude + l);
}

float vsgl_sharpness_from_mean_length(float r, int32_t estimator)
{
    if (!(r > 0.0f))
        return 0.0f;
    if (!(r < 1.0f))
        return VSGL_SHARPNESS_MAX;
    float l;
    if (estimator == VSGL_SHARPNESS_TOKSVIG)
        l = r / (1.0f - r);
    else
        l = r * (3.0f - r * r) / ((1.0f - r) * (1.0f + r));
    return l < VSGL_SHARPNESS_MAX ? l : VSGL_SHARPNESS_MAX;
}

float vsgl_mean_length_from_sharpness(float sharpness, int32_t estimator)
{
    float l = vsgl__sg_clamp_sharpness(sharpness);
    if (estimator == VSGL_SHARPNESS_TOKSVIG)
        return l / (l + 1.0f);
    return vsgl__sg_mean_length(l);
}
