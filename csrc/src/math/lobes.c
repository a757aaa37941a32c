/* Reflection lobes as SGs/ASGs: Lambert, NDFs, spherical warping (SG and
 * ASG, the ASG Hessian derived in docs/math.md), the smooth microfacet
 * factor, Ward and Ashikhmin-Shirley. */
#include "vsgl/lobes.h"
#include "math/normal.h"
#include "math/fresnel.h"
#include "math/sg_internal.h"
#include "math/asg_internal.h"

#include <float.h>

static float clamp_alpha(float a)
{
    if (!(a > VSGL_ALPHA_MIN)) /* NaN, negatives, tiny */
        return a != a ? 1.0f : VSGL_ALPHA_MIN;
    return a < 1.0f ? a : 1.0f;
}

/* Non-negative finite bandwidth, capped. */
static float clamp_band(float b)
{
    return vsgl__sg_clamp_sharpness(b);
}

static int is_zero(v3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }

/* is_zero(v3_normalize(a)) without the square root and division: a is
 * zero or not finite. */
static int is_null(v3 a)
{
    const float l2 = v3_dot(a, a);
    return !(l2 > 0.0f && l2 < INFINITY);
}

/* a is unit to float precision (a G-buffer normal, tangent or view: a few
 * ulps apart). */
static int is_unit(v3 a) { return fabsf(v3_dot(a, a) - 1.0f) < 1e-6f; }

/* v3_normalize(a), with a returned as it is where it is already unit. */
static v3 unit_of(v3 a) { return is_unit(a) ? a : v3_normalize(a); }

/* Right-handed orthonormal frame [x, y, z] with z = normalize(n) and x the
 * tangent made orthogonal to z (any completion if t is degenerate). A zero
 * n gives z = +Z. */
static void make_frame(v3 n, v3 t, v3 *x, v3 *y, v3 *z)
{
    /* n and t already unit and orthogonal to float precision (the
     * G-buffer's normal and tangent, a frame this file made): they are the
     * frame, and y = n x t. A lobe is built from such a pair twice
     * (vsgl_ndf_aniso_to_asg, vsgl_warp_ndf_asg), and re-normalising it
     * cost 10 % of a 1080p frame's per-receiver work for a change of a few
     * ulps when the shade stage's receivers still took this path (they now
     * warp in math/warp_lanes.c). */
    if (is_unit(n) && is_unit(t) && fabsf(v3_dot(n, t)) < 1e-6f) {
        *x = t;
        *y = v3_cross(n, t);
        *z = n;
        return;
    }
    v3 zz = v3_normalize(n);
    if (is_zero(zz))
        zz = v3_make(0.0f, 0.0f, 1.0f);
    v3 tt = v3_sub(t, v3_scale(zz, v3_dot(t, zz)));
    float tl = v3_length(tt);
    v3 xx, yy;
    if (tl > 1e-6f * v3_length(t) && tl > 0.0f && tl < INFINITY) {
        xx = v3_scale(tt, 1.0f / tl);
        yy = v3_normalize(v3_cross(zz, xx));
        xx = v3_cross(yy, zz); /* re-orthogonalise */
    } else {
        v3_basis(zz, &xx, &yy);
    }
    *x = xx;
    *y = yy;
    *z = zz;
}

void vsgl_lambert_to_sg(const vsgl_vec3 *n, vsgl_sg *out)
{
    vsgl_sg r;
    r.axis = v3_normalize(*n);
    r.sharpness = VSGL__COSINE_SHARPNESS;
    r.log_amplitude = is_zero(r.axis) ? -INFINITY : -vsgl__sg_log_integral(VSGL__COSINE_SHARPNESS);
    *out = r;
}

float vsgl_ndf_sharpness(float alpha)
{
    float a = clamp_alpha(alpha);
    return clamp_band(2.0f / (a * a));
}

void vsgl_ndf_to_sg(const vsgl_vec3 *n, float alpha, int32_t ndf, vsgl_sg *out)
{
    (void)ndf; /* GGX and Beckmann share lambda_h = 2/alpha^2 (Wang et al. 2009) */
    float a = clamp_alpha(alpha);
    vsgl_sg r;
    r.axis = v3_normalize(*n);
    r.sharpness = vsgl_ndf_sharpness(a);
    r.log_amplitude = is_zero(r.axis) ? -INFINITY : -VSGL__LOG_PI - 2.0f * logf(a);
    *out = r;
}

void vsgl_ndf_aniso_to_asg(const vsgl_vec3 *n, const vsgl_vec3 *tangent,
                           float alpha_x, float alpha_y, vsgl_asg *out)
{
    float ax = clamp_alpha(alpha_x), ay = clamp_alpha(alpha_y);
    vsgl_asg r;
    make_frame(*n, *tangent, &r.x, &r.y, &r.z);
    r.lambda = clamp_band(1.0f / (ax * ax));
    r.mu = clamp_band(1.0f / (ay * ay));
    r.log_amplitude = is_null(*n) ? -INFINITY : -VSGL__LOG_PI - logf(ax) - logf(ay);
    *out = r;
}

/* Unit view, or the fallback if the view is zero/non-finite. */
static v3 unit_or(v3 v, v3 fallback)
{
    v3 u = unit_of(v);
    return is_zero(u) ? fallback : u;
}

void vsgl_warp_ndf_sg(const vsgl_sg *ndf, const vsgl_vec3 *view, vsgl_sg *out)
{
    v3 n = v3_normalize(ndf->axis);
    vsgl_sg r;
    if (is_zero(n)) {
        r.axis = n;
        r.sharpness = 0.0f;
        r.log_amplitude = -INFINITY;
        *out = r;
        return;
    }
    v3 o = unit_or(*view, n);
    float on = v3_dot(o, n);
    r.axis = v3_normalize(v3_reflect(o, n));
    if (is_zero(r.axis))
        r.axis = n;
    float d = fabsf(on);
    d = d > 1e-6f ? d : 1e-6f;
    r.sharpness = clamp_band(vsgl__sg_clamp_sharpness(ndf->sharpness) / (4.0f * d));
    r.log_amplitude = ndf->log_amplitude;
    *out = r;
}

/* The light a mirror-like VPL sends out, as one isotropic SG (docs/math.md
 * §5.4.1). In the plane of incidence a tilt d of the half vector turns the
 * reflection by exactly 2 d, so the outgoing elevation phi above the
 * surface is Gaussian about phi0 = asin(o.n) with twice the NDF's spread;
 * the intensity per solid angle carries the warp's Jacobian o.h =
 * sin(phi0 + s / 2) (s = phi - phi0), taken to first order in s, and stops
 * at the horizon. The SG takes that profile's mean elevation and its
 * variance: the lobe's wider axis. The plain warp (vsgl_warp_ndf_sg) keeps
 * the reflection as the axis and the geometric mean of the two axes'
 * widths, which at grazing incidence is several times too narrow in
 * elevation and points into the horizon. */
void vsgl__warp_ndf_sg_emitted(const vsgl_sg *ndf, const vsgl_vec3 *view, vsgl_sg *out)
{
    vsgl__warp_ndf_sg_emitted_fresnel(ndf, view, 1.0f, 1.0f, out);
}

/* The profile's mean and second moment (in units of its spread) with the
 * Fresnel weight taken along: f(x) = phi(x) (1 + k x) R(x) on lo < x < hi,
 * R the blend f0 + (1 - f0) FH(o.h) (up to a constant), o.h =
 * sin(phi0 + se x / 2) in the plane of incidence (phi0 the mirror
 * direction's elevation; past the normal it falls again, up to the far
 * horizon at x = (pi - phi0) / se). Midpoint rule on 16 nodes, the
 * Gaussian and the sine stepped by recurrence (six sines or cosines and
 * three exps a texel, not sixteen of each). Returns 0 (moments untouched)
 * where o.h stays above 0.9 over the profile: there the curve is flat to
 * 1e-4 of F0. */
static int fresnel_profile(float phi0, float se, float lo, float k, float eta, float f0,
                           float *mu, float *second)
{
    enum { N = 16 };
    float hi = fminf(5.0f, (3.14159265f - phi0) / se);
    if (!(hi > lo))
        return 0;
    float h = (hi - lo) / N, x = lo + 0.5f * h;
    /* sin is concave on [0, pi]: its least value over the range at an end */
    if (fminf(sinf(phi0 + 0.5f * se * lo), sinf(phi0 + 0.5f * se * hi)) > 0.9f)
        return 0;
    float t0 = phi0 + 0.5f * se * x, s = sinf(t0), c = cosf(t0), ds = sinf(0.5f * se * h), dc = cosf(0.5f * se * h);
    float F0 = vsgl__fresnel_dielectric(1.0f, eta), scale = (1.0f - f0) / (1.0f - F0);
    /* g = exp(-x^2 / 2) stepped by r = exp(-x h - h^2 / 2), r by exp(-h^2) */
    float g = expf(-0.5f * x * x), r = expf(-x * h - 0.5f * h * h), rr = expf(-h * h);
    float w0 = 0.0f, w1 = 0.0f, w2 = 0.0f;
    for (int j = 0; j < N; ++j) {
        float fh = fmaxf(vsgl__fresnel_dielectric(fmaxf(s, 0.0f), eta) - F0, 0.0f);
        float w = g * fmaxf(1.0f + k * x, 0.0f) * (f0 + scale * fh);
        w0 += w;
        w1 += w * x;
        w2 += w * x * x;
        float sn = s * dc + c * ds;
        c = c * dc - s * ds;
        s = sn;
        g *= r;
        r *= rr;
        x += h;
    }
    if (!(w0 > 0.0f))
        return 0;
    *mu = w1 / w0;
    *second = w2 / w0;
    return 1;
}

void vsgl__warp_ndf_sg_emitted_fresnel(const vsgl_sg *ndf, const vsgl_vec3 *view, float eta, float f0,
                                       vsgl_sg *out)
{
    vsgl_warp_ndf_sg(ndf, view, out);
    v3 n = v3_normalize(ndf->axis);
    float lam = vsgl__sg_clamp_sharpness(ndf->sharpness);
    if (is_zero(n) || !(lam > 0.0f))
        return;
    float cn = v3_dot(out->axis, n);
    if (cn < 0.0f) {
        n = v3_neg(n);
        cn = -cn;
    }
    /* the elevation from the tangent part, not asin(o.n): asin loses the
     * angle near normal incidence in float and would jitter as a light moves */
    v3 u = v3_sub(out->axis, v3_scale(n, cn));
    float ul = v3_length(u);
    float var = 4.0f / lam, se = sqrtf(var);
    float phi0 = atan2f(cn, ul), a = -phi0 / se;
    float k = 0.5f * se * fminf(ul, 1.0f) / fmaxf(cn, 1e-6f);
    if (!(ul > 1e-6f)) { /* normal incidence: any tangent (phi stays at the normal) */
        v3 u2;
        v3_basis(n, &u, &u2);
        ul = 1.0f;
    }
    /* standard-normal moments over x > a, weighted by 1 + k x (far from the
     * horizon e underflows to 0: the Jacobian's shift k alone) */
    float e = expf(-0.5f * a * a), pdf = 0.39894228f * e;
    float z = 1.0f - vsgl__normal_cdf_e(a, e);
    float m1 = pdf, m2 = z + a * pdf, m3 = (a * a + 2.0f) * pdf;
    float w0 = z + k * m1, w1 = m1 + k * m2, w2 = m2 + k * m3;
    float mu = w1 / w0, second = w2 / w0;
    if (eta > 1.0f && f0 < 1.0f)
        fresnel_profile(phi0, se, fmaxf(a, -5.0f), k, eta, f0, &mu, &second);
    var *= fmaxf(second - mu * mu, 1e-4f);
    float phi = fminf(phi0 + se * mu, 1.5707963f);
    out->axis = v3_normalize(v3_add(v3_scale(u, cosf(phi) / ul), v3_scale(n, sinf(phi))));
    out->sharpness = clamp_band(1.0f / var);
}

/* Double-precision helpers for the warp (2x2 eigen-problem). */
typedef struct dv { double x, y, z; } dv;
static dv dv_of(v3 a) { dv r = {a.x, a.y, a.z}; return r; }
static double dv_dot(dv a, dv b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static dv dv_lin(dv a, double sa, dv b, double sb)
{
    dv r = {a.x * sa + b.x * sb, a.y * sa + b.y * sb, a.z * sa + b.z * sb};
    return r;
}
static dv dv_cross(dv a, dv b)
{
    dv r = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    return r;
}
static dv dv_unit(dv a)
{
    double il = 1.0 / sqrt(dv_dot(a, a)); /* one division, not three */
    dv r = {a.x * il, a.y * il, a.z * il};
    return r;
}
static v3 v3_of(dv a) { return v3_make((float)a.x, (float)a.y, (float)a.z); }

void vsgl_warp_ndf_asg(const vsgl_asg *ndf, const vsgl_vec3 *view, vsgl_asg *out)
{
    v3 fx, fy, fz;
    make_frame(ndf->z, ndf->x, &fx, &fy, &fz);
    vsgl_asg r;
    if (is_null(ndf->z)) {
        r.x = fx; r.y = fy; r.z = fz;
        r.lambda = r.mu = 0.0f;
        r.log_amplitude = -INFINITY;
        *out = r;
        return;
    }
    dv xh = dv_of(fx), yh = dv_of(fy), zh = dv_of(fz);
    dv o = dv_of(unit_or(*view, fz));
    double c = dv_dot(o, zh);
    /* Lobe axis: the reflection of o about z_h. */
    dv zi = dv_unit(dv_lin(zh, 2.0 * c, o, -1.0));
    /* Default tangent frame at z_i: x' perpendicular to o (and z_i). */
    dv xp = dv_cross(o, zi);
    double xl = sqrt(dv_dot(xp, xp));
    if (xl > 1e-9) {
        xp = dv_lin(xp, 1.0 / xl, xp, 0.0);
    } else { /* o = z_i = z_h: any tangent; the frame below is re-derived */
        v3 bx, by;
        v3_basis(v3_of(zi), &bx, &by);
        xp = dv_of(bx);
    }
    dv yp = dv_cross(zi, xp);
    /* Half-vector Jacobian at the peak: dh = (t - z_h (z_h.t)) / |i + o| with
     * |i + o| = 2 (o.z_h). The warped exponent g = l (h.x_h)^2 + m (h.y_h)^2
     * has zero gradient there, so its quadratic form in the tangent
     * coordinates (a, b) of i = z_i + a x' + b y' is Q = P^T diag(l, m) P /
     * (4 c^2), P = [[x_h.x', x_h.y'], [y_h.x', y_h.y']] (docs/math.md). */
    double cc = fabs(c) > 1e-6 ? fabs(c) : 1e-6;
    double k = 1.0 / (4.0 * cc * cc);
    double l = clamp_band(ndf->lambda), m = clamp_band(ndf->mu);
    double p11 = dv_dot(xh, xp), p12 = dv_dot(xh, yp), p21 = dv_dot(yh, xp), p22 = dv_dot(yh, yp);
    double q11 = k * (l * p11 * p11 + m * p21 * p21);
    double q12 = k * (l * p11 * p12 + m * p21 * p22);
    double q22 = k * (l * p12 * p12 + m * p22 * p22);
    /* Symmetric 2x2 eigen-decomposition; x_i takes the larger eigenvalue. */
    double half_diff = 0.5 * (q11 - q22), mean = 0.5 * (q11 + q22);
    double rad = sqrt(half_diff * half_diff + q12 * q12);
    /* the larger eigenvalue's eigenvector (cos th, sin th), th = atan2(2
     * q12, q11 - q22) / 2 in (-pi/2, pi/2], by the half-angle formulas:
     * cos 2th = half_diff / rad, sin 2th = q12 / rad (th = 0 where the
     * form is round) */
    double c2 = rad > 0.0 ? half_diff / rad : 1.0;
    double cs = sqrt(fmax(0.5 * (1.0 + c2), 0.0)), sn = copysign(sqrt(fmax(0.5 * (1.0 - c2), 0.0)), q12);
    dv xi = dv_lin(xp, cs, yp, sn);
    dv yi = dv_lin(xp, -sn, yp, cs);
    double e1 = mean + rad, e2 = mean - rad;
    r.x = v3_of(xi);
    r.y = v3_of(yi);
    r.z = v3_of(zi);
    r.lambda = clamp_band((float)(e1 > 0.0 ? e1 : 0.0));
    r.mu = clamp_band((float)(e2 > 0.0 ? e2 : 0.0));
    r.log_amplitude = ndf->log_amplitude;
    *out = r;
}

/* The fan of a reflection lobe about axis z0 seen from view o: the
 * relative growth of c = o.h (h the half vector of o and a direction) from
 * z0 to z1, a direction one sd above it across the horizon; 0 where c does
 * not grow (vsgl__asg_cut_at_horizon, below). */
#define VSGL__FAN_MAX 8.0f
static float asg_fan_slope(v3 z0, v3 z1, v3 view)
{
    v3 o = unit_of(view);
    v3 h0 = v3_add(o, z0), h1 = v3_add(o, v3_normalize(z1));
    float l0 = v3_length(h0), l1 = v3_length(h1);
    if (!(l0 > 1e-6f) || !(l1 > 1e-6f))
        return 0.0f;
    float c0 = v3_dot(o, h0) / l0, c1 = v3_dot(o, h1) / l1;
    if (!(c0 > 0.0f) || !(c1 > c0))
        return 0.0f;
    return (c1 - c0) / c0;
}

/* A receiver's reflection lobe cut at its surface's horizon (docs/math.md
 * §5.4.2). In the gnomonic coordinates of the lobe's frame, (a, b) =
 * (i.x, i.y) / (i.z), the ASG is about a Gaussian of variances 1 / (2
 * lambda), 1 / (2 mu), and the horizon n.i > 0 is exactly the half-plane
 * n.z + a n.x + b n.y > 0. Where the lobe reaches below it (a grazing view:
 * a glossy sphere's rim, whose reflection points along its tangent plane),
 * the Gaussian is replaced by the moments of its part above: the mean moves
 * up, the spread across the horizon shrinks, and the amplitude keeps the
 * part's integral. Without it, half of a grazing lobe gathers light from
 * below the surface: a ring along a glossy sphere's silhouette lit by the
 * sphere's own clusters, which no path can reach.
 *
 * With the view o (NULL: none), the part's fan (docs/math.md §5.4.3): the
 * warp's width across the plane of incidence is proportional to c = o.h at
 * the lobe's axis (its sharpness there l_h / (4 c^2)), and c grows with the
 * direction's elevation. Taken at the mirror direction it is the width at
 * the bottom of the part, the narrowest: a view at cos_o = 0.05 (roughness
 * 0.3, dielectric) kept 0.58 of GGX's light over a uniform sky, 0.19 at
 * 0.02 (tests/c/test_lobe_fan.c). The part is stretched across the plane
 * by c at its mean axis over c at the mirror direction, its integral with
 * it (exact for c linear in the elevation): 0.99 and 0.92. */
void vsgl__asg_cut_at_horizon(vsgl_asg *a, const vsgl_vec3 *normal, const vsgl_vec3 *view)
{
    v3 n = unit_of(*normal);
    float lam = clamp_band(a->lambda), mu = clamp_band(a->mu);
    if (is_zero(n) || !(lam > 0.0f) || !(mu > 0.0f) || !(a->log_amplitude > -INFINITY))
        return;
    float c = v3_dot(n, a->z), gx = v3_dot(n, a->x), gy = v3_dot(n, a->y);
    /* most lobes are clear of the horizon (t < -4 below): c > 4 sd, i.e.
     * c^2 l m > 8 (gx^2 m + gy^2 l), without the three divisions and the
     * square root; with a margin of 0.1 %, so that where this returns the
     * test below would have returned too (the lobe as it was, bit for bit) */
    if (c > 0.0f && c * c * lam * mu > 8.008f * (gx * gx * mu + gy * gy * lam))
        return;
    float va = 0.5f / lam, vb = 0.5f / mu;
    float vs = gx * gx * va + gy * gy * vb; /* variance of s = a n.x + b n.y */
    if (!(vs > 1e-12f))
        return;
    float sd = sqrtf(vs), t = -c / sd; /* the cut at s > -c, in sds */
    /* the conditional mean and covariance of (a, b): Sigma g carries them */
    float ka = gx * va / vs, kb = gy * vb / vs;
    if (t < -4.0f) /* less than 3e-5 of the lobe below the horizon */
        return;
    /* the fan: c = o.h grows as 1 + k x with x = s / sd; faded in from
     * t = -4 to -2 (a lobe clear of the horizon is left as it was) */
    float k = view ? asg_fan_slope(a->z, v3_add(a->z, v3_add(v3_scale(a->x, ka * sd), v3_scale(a->y, kb * sd))),
                                   *view) * fminf(0.5f * (t + 4.0f), 1.0f)
                   : 0.0f;
    t = fminf(t, 4.0f);
    float e = expf(-0.5f * t * t), pdf = 0.39894228f * e;
    float w0 = fmaxf(1.0f - vsgl__normal_cdf_e(t, e), 1e-6f);
    float r = pdf / w0;                            /* inverse Mills ratio: E[x | x > t] */
    float ms = sd * r;                             /* E[s | s > -c] */
    float shrink = fminf(fmaxf(r * (r - t), 0.0f), 0.999f); /* 1 - Var[s | cut] / Var[s] */
    /* the fan's width across the plane at the part's mean, and its growth of the integral (c linear in x) */
    float fan = fminf(1.0f + k * r, VSGL__FAN_MAX);
    float da = ka * ms, db = kb * ms;
    float s11 = va - gx * va * ka * shrink, s22 = vb - gy * vb * kb * shrink, s12 = -gx * va * kb * shrink;
    v3 z = v3_normalize(v3_add(a->z, v3_add(v3_scale(a->x, da), v3_scale(a->y, db))));
    if (fan > 1.0f) { /* stretch by fan along u, across the plane: S' = A S A^T, A = I + (fan - 1) u u^T */
        float gl = sqrtf(gx * gx + gy * gy), ux = -gy / gl, uy = gx / gl, f = fan - 1.0f;
        float a11 = 1.0f + f * ux * ux, a12 = f * ux * uy, a22 = 1.0f + f * uy * uy;
        float t11 = a11 * s11 + a12 * s12, t12 = a11 * s12 + a12 * s22; /* A S */
        float t21 = a12 * s11 + a22 * s12, t22 = a12 * s12 + a22 * s22;
        s11 = t11 * a11 + t12 * a12;
        s12 = t11 * a12 + t12 * a22;
        s22 = t21 * a12 + t22 * a22;
    }
    float det = s11 * s22 - s12 * s12;
    if (!(det > 0.0f))
        return;
    /* eigenvectors of the new covariance: x takes the smaller variance (the larger bandwidth) */
    float th = 0.5f * atan2f(2.0f * s12, s11 - s22);
    float cs = cosf(th), sn = sinf(th);
    float mean = 0.5f * (s11 + s22), rad = sqrtf(0.25f * (s11 - s22) * (s11 - s22) + s12 * s12);
    float v1 = mean + rad, v2 = fmaxf(mean - rad, 1e-12f); /* along (cs, sn) and (-sn, cs) */
    v3 e1 = v3_add(v3_scale(a->x, cs), v3_scale(a->y, sn)), e2 = v3_add(v3_scale(a->x, -sn), v3_scale(a->y, cs));
    v3 xs = v2 <= v1 ? e2 : e1, ys = v2 <= v1 ? e1 : e2;
    float vx = fminf(v1, v2), vy = fmaxf(v1, v2);
    /* the frame made orthogonal to the moved axis */
    xs = v3_normalize(v3_sub(xs, v3_scale(z, v3_dot(xs, z))));
    ys = v3_cross(z, xs);
    if (!(fabsf(xs.x) + fabsf(xs.y) + fabsf(xs.z) < INFINITY) || !(fabsf(z.x) + fabsf(z.y) + fabsf(z.z) < INFINITY))
        return; /* a degenerate frame: the lobe as it is */
    a->z = z;
    a->x = xs;
    a->y = ys;
    float l0 = a->lambda, m0 = a->mu;
    a->lambda = clamp_band(0.5f / vx);
    a->mu = clamp_band(0.5f / vy);
    /* the part's integral: w0 of the whole lobe's (the ASG's own integral:
     * the Gaussians' determinants overshoot it by up to 13 % for wide lobes) */
    a->log_amplitude += logf(w0 * fan) +
                        (float)log(vsgl__asg_integral_unit_fast(l0, m0) / vsgl__asg_integral_unit_fast(a->lambda, a->mu));
}

float vsgl_specular_factor(const vsgl_vec3 *n, const vsgl_vec3 *view,
                           const vsgl_vec3 *light, float alpha, float f0)
{
    v3 nn = v3_normalize(*n), o = v3_normalize(*view), i = v3_normalize(*light);
    float co = v3_dot(nn, o), ci = v3_dot(nn, i);
    if (!(co > 0.0f) || !(ci > 0.0f))
        return 0.0f;
    co = co < 1.0f ? co : 1.0f;
    ci = ci < 1.0f ? ci : 1.0f;
    float a = clamp_alpha(alpha);
    float a2 = a * a;
    float f = f0 > 0.0f ? (f0 < 1.0f ? f0 : 1.0f) : 0.0f;
    /* Schlick Fresnel at i.h; h = (i + o)/|i + o|, |i + o| > 0 since both
     * are above the surface. */
    v3 h = v3_normalize(v3_add(i, o));
    float ih = clampf(v3_dot(i, h), 0.0f, 1.0f);
    float w = 1.0f - ih, w2 = w * w;
    float fr = f + (1.0f - f) * (w2 * w2 * w);
    /* Height-correlated Smith GGX: G2 = 2 ci co / (ci So + co Si) with
     * Sx = sqrt(a^2 + (1 - a^2) cx^2); M = F G2 / (4 co) = F ci / (2 (ci So + co Si)). */
    float so = sqrtf(a2 + (1.0f - a2) * co * co), si = sqrtf(a2 + (1.0f - a2) * ci * ci);
    return fr * ci / (2.0f * (ci * so + co * si));
}

void vsgl_ward_to_asg(const vsgl_vec3 *n, const vsgl_vec3 *x,
                      float alpha_x, float alpha_y, vsgl_asg *out)
{
    float ax = clamp_alpha(alpha_x), ay = clamp_alpha(alpha_y);
    vsgl_asg r;
    make_frame(*n, *x, &r.x, &r.y, &r.z);
    r.lambda = clamp_band(1.0f / (ax * ax));
    r.mu = clamp_band(1.0f / (ay * ay));
    r.log_amplitude = is_null(*n) ? -INFINITY : 0.0f;
    *out = r;
}

void vsgl_ashikhmin_shirley_to_asg(const vsgl_vec3 *n, const vsgl_vec3 *u,
                                   float n_u, float n_v, vsgl_asg *out)
{
    vsgl_asg r;
    make_frame(*n, *u, &r.x, &r.y, &r.z);
    r.lambda = clamp_band(0.5f * n_u);
    r.mu = clamp_band(0.5f * n_v);
    r.log_amplitude = is_null(*n) ? -INFINITY : 0.0f;
    *out = r;
}
