/* Anisotropic spherical Gaussians (Xu et al. 2013): evaluation, integral
 * (Eq. 10/11), product (Eq. 13), convolution with an SG (Eq. 18), ASG x SG
 * product integral and SG -> ASG (Eq. 3). Formulas, sources, measured
 * errors and the treatment of every extreme: docs/math_asg.md. All internal
 * arithmetic is double; results are rounded to float once. */
#include "math/asg_internal.h"
#include "math/constants.h"
#include "math/bessel.h"
#include "math/eigen3.h"
#include "math/vec.h"

#include <float.h>
#include <math.h>


/* ---------------------------------------------------------------- frames */

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void cross3(const double a[3], const double b[3], double out[3])
{
    double r0 = a[1] * b[2] - a[2] * b[1], r1 = a[2] * b[0] - a[0] * b[2], r2 = a[0] * b[1] - a[1] * b[0];
    out[0] = r0;
    out[1] = r1;
    out[2] = r2;
}

/* Normalise in place; returns 0 (and leaves v alone) when |v| is 0, tiny
 * relative to @p ref, or not finite. */
static int normalize3(double v[3], double ref)
{
    double l = sqrt(dot3(v, v));
    if (!(l > 1e-7 * ref) || !(l < INFINITY))
        return 0;
    v[0] /= l;
    v[1] /= l;
    v[2] /= l;
    return 1;
}

static void to_d3(const vsgl_vec3 *v, double out[3])
{
    out[0] = v->x;
    out[1] = v->y;
    out[2] = v->z;
}

static vsgl_vec3 to_v3(const double v[3]) { return v3_make((float)v[0], (float)v[1], (float)v[2]); }

int vsgl__asg_frame(const vsgl_asg *a, vsgl__frame *f)
{
    to_d3(&a->z, f->z);
    double zl = sqrt(dot3(f->z, f->z));
    if (!(zl > 0.0) || !(zl < INFINITY) || !normalize3(f->z, 0.0)) {
        f->x[0] = 1, f->x[1] = 0, f->x[2] = 0;
        f->y[0] = 0, f->y[1] = 1, f->y[2] = 0;
        f->z[0] = 0, f->z[1] = 0, f->z[2] = 1;
        return 0;
    }
    double x[3], y[3];
    to_d3(&a->x, x);
    double xl = sqrt(dot3(x, x)), xz = dot3(x, f->z);
    x[0] -= xz * f->z[0], x[1] -= xz * f->z[1], x[2] -= xz * f->z[2];
    if (xl < INFINITY && normalize3(x, xl)) {
        cross3(f->z, x, f->y);
        f->x[0] = x[0], f->x[1] = x[1], f->x[2] = x[2];
        return 1;
    }
    to_d3(&a->y, y);
    double yl = sqrt(dot3(y, y)), yz = dot3(y, f->z);
    y[0] -= yz * f->z[0], y[1] -= yz * f->z[1], y[2] -= yz * f->z[2];
    if (yl < INFINITY && normalize3(y, yl)) {
        cross3(y, f->z, f->x);
        f->y[0] = y[0], f->y[1] = y[1], f->y[2] = y[2];
        return 1;
    }
    /* Duff et al. 2017 completion in double. */
    double s = copysign(1.0, f->z[2]), q = -1.0 / (s + f->z[2]), b = f->z[0] * f->z[1] * q;
    f->x[0] = 1.0 + s * f->z[0] * f->z[0] * q, f->x[1] = s * b, f->x[2] = -s * f->z[0];
    f->y[0] = b, f->y[1] = s + f->z[1] * f->z[1] * q, f->y[2] = -f->z[1];
    return 1;
}

double vsgl__asg_clamp_bw(float b)
{
    double d = b;
    return d < 0.0 ? 0.0 : (d > (double)VSGL_SHARPNESS_MAX ? (double)VSGL_SHARPNESS_MAX : d);
}

static void zero_lobe(const vsgl__frame *f, vsgl_asg *out)
{
    out->x = to_v3(f->x);
    out->y = to_v3(f->y);
    out->z = to_v3(f->z);
    out->lambda = 0.0f;
    out->mu = 0.0f;
    out->log_amplitude = -INFINITY;
}

/* ------------------------------------------------------------ evaluation */

float vsgl_asg_eval(const vsgl_asg *a, const vsgl_vec3 *dir)
{
    vsgl__frame f;
    if (!vsgl__asg_frame(a, &f) || a->log_amplitude == -INFINITY)
        return 0.0f;
    double v[3];
    to_d3(dir, v);
    if (!normalize3(v, 0.0))
        return 0.0f;
    double vz = dot3(v, f.z);
    if (!(vz > 0.0))
        return 0.0f;
    double vx = dot3(v, f.x), vy = dot3(v, f.y);
    double e = (double)a->log_amplitude - vsgl__asg_clamp_bw(a->lambda) * vx * vx
             - vsgl__asg_clamp_bw(a->mu) * vy * vy;
    return (float)(vz * exp(e));
}

float vsgl_asg_bessel_f(float a)
{
    return (float)vsgl__bessel_f(fabs((double)a));
}

/* -------------------------------------------------------------- integral */

double vsgl__asg_integral_eq10(double lambda, double mu)
{
    if (lambda < mu) {
        double t = lambda;
        lambda = mu;
        mu = t;
    }
    if (!(mu > 0.0))
        return lambda > 0.0 ? INFINITY : VSGL__PI_D;
    double nu = lambda - mu;
    double second = exp(-mu) / (2.0 * lambda) * (vsgl__bessel_f(nu) + nu / mu * vsgl__bessel_f(nu + nu / mu));
    return VSGL__PI_D / sqrt(lambda * mu) - second;
}

/* 10-point Gauss-Legendre on [-1, 1]. */
static const double gl_x[5] = {0.1488743389816312108848260, 0.4333953941292471907992659,
                                0.6794095682990244062343274, 0.8650633666889845107320967,
                                0.9739065285171717200779640};
static const double gl_w[5] = {0.2955242247147528701738930, 0.2692667193099963550912269,
                               0.2190863625159820439955349, 0.1494513491505805931457763,
                               0.0666713443086881375935688};

/* int_{u0}^{u1} 2u e^{-u^2 mu} I0e(u^2 d) du by 10-point Gauss-Legendre. */
static double panel(double u0, double u1, double mu, double d)
{
    double c = 0.5 * (u0 + u1), h = 0.5 * (u1 - u0), s = 0.0;
    for (int i = 0; i < 5; ++i)
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            double u = c + sgn * h * gl_x[i], uu = u * u;
            s += gl_w[i] * 2.0 * u * exp(-uu * mu) * vsgl__i0e(uu * d);
        }
    return s * h;
}

double vsgl__asg_integral_exact(double lambda, double mu)
{
    if (lambda < mu) {
        double t = lambda;
        lambda = mu;
        mu = t;
    }
    /* I = pi int_0^1 e^{-s mu} I0e(s d) ds, d = (lambda - mu)/2 (from
     * Eq. 4: the phi integral of e^{-s(lambda cos^2 + mu sin^2)} is
     * e^{-s mu} F(s (lambda - mu)), s = sin^2 theta). With s = u^2 the
     * integrand 2u e^{-u^2 mu} I0e(u^2 d) is smooth; its only feature for
     * large d sits at u ~ 1/sqrt(d), so the panels grow geometrically (x4)
     * from there, and no panel is wider than 1/2 (e^{-u^2 mu}, mu < 12). */
    double d = 0.5 * (lambda - mu);
    double u0 = 0.0, sum = 0.0;
    double u1 = d > 1.0 ? 1.0 / sqrt(d) : 0.5;
    while (u0 < 1.0) {
        double hi = u1 < 1.0 ? u1 : 1.0;
        if (hi - u0 > 0.5)
            hi = u0 + 0.5 < 1.0 ? u0 + 0.5 : 1.0;
        sum += panel(u0, hi, mu, d);
        u0 = hi;
        u1 = 4.0 * hi;
    }
    return VSGL__PI_D * sum;
}

double vsgl__asg_integral_unit(double lambda, double mu)
{
    double lo = lambda < mu ? lambda : mu;
    if (isnan(lambda) || isnan(mu))
        return NAN;
    return lo >= VSGL__ASG_EQ10_MIN_MU ? vsgl__asg_integral_eq10(lambda, mu)
                                       : vsgl__asg_integral_exact(lambda, mu);
}

double vsgl__asg_integral_eq10_fast(double lambda, double mu)
{
    double hi = lambda >= mu ? lambda : mu, lo = lambda >= mu ? mu : lambda;
    /* pi / sqrt(hi lo) - e^{-lo} / (2 hi) (F(nu) + nu / lo F(nu + nu / lo)), nu = hi - lo,
     * F(a) = 2 pi I0e(a / 2) <= 2 pi: the second term is at most e^{-lo} sqrt(hi / lo) of the
     * first; below 2^-54 it does not change the double (rounding to nearest) */
    double first = VSGL__PI_D / sqrt(hi * lo), r = exp(-lo) * sqrt(hi / lo);
    if (r < 0x1p-54)
        return first;
    double nu = hi - lo, nl = nu / lo;
    double second = exp(-lo) / (2.0 * hi) * 2.0 * VSGL__PI_D *
                    (vsgl__i0e_poly(0.5 * nu) + nl * vsgl__i0e_poly(0.5 * (nu + nl)));
    return first - second;
}

double vsgl__asg_integral_unit_fast(double lambda, double mu)
{
    double hi = lambda >= mu ? lambda : mu, lo = lambda >= mu ? mu : lambda;
    if (!(lo >= 0.0) || !(hi < INFINITY))
        return vsgl__asg_integral_unit(lambda, mu); /* NaN, negative or infinite bandwidths */
    if (lo >= VSGL__ASG_EQ10_MIN_MU)
        return vsgl__asg_integral_eq10_fast(hi, lo);
    /* the table's coordinates (tools/gen_asg_table.py): x from 1/sqrt(13) to 1, y from 0 to 1 */
    const double x0 = 0.27735009811261456; /* 1 / sqrt(1 + VSGL__ASG_EQ10_MIN_MU) */
    double slo = sqrt(1.0 + lo), shi = sqrt(1.0 + hi);
    double fx = (1.0 / slo - x0) / (1.0 - x0) * (VSGL__ASG_TABLE_NX - 1);
    double fy = 1.0 / shi * (VSGL__ASG_TABLE_NY - 1);
    int ix = (int)fx, iy = (int)fy;
    ix = ix < 0 ? 0 : (ix > VSGL__ASG_TABLE_NX - 2 ? VSGL__ASG_TABLE_NX - 2 : ix);
    iy = iy < 0 ? 0 : (iy > VSGL__ASG_TABLE_NY - 2 ? VSGL__ASG_TABLE_NY - 2 : iy);
    double tx = fx - ix, ty = fy - iy;
    const float *r0 = vsgl__asg_table[ix], *r1 = vsgl__asg_table[ix + 1];
    double g = (1.0 - tx) * ((1.0 - ty) * r0[iy] + ty * r0[iy + 1]) + tx * ((1.0 - ty) * r1[iy] + ty * r1[iy + 1]);
    return VSGL__PI_D * g / (slo * shi);
}

float vsgl_asg_integral(const vsgl_asg *a)
{
    vsgl__frame f;
    if (!vsgl__asg_frame(a, &f) || a->log_amplitude == -INFINITY)
        return 0.0f;
    double i = vsgl__asg_integral_unit(vsgl__asg_clamp_bw(a->lambda), vsgl__asg_clamp_bw(a->mu));
    return (float)(exp((double)a->log_amplitude) * i);
}

float vsgl_asg_integral_approx(const vsgl_asg *a)
{
    vsgl__frame f;
    if (!vsgl__asg_frame(a, &f) || a->log_amplitude == -INFINITY)
        return 0.0f;
    double lm = vsgl__asg_clamp_bw(a->lambda) * vsgl__asg_clamp_bw(a->mu);
    /* Eq. 11, capped at the bound c pi (the integral of c max(v.z, 0)),
     * which it exceeds only for lambda mu < 1 where Eq. 11 is meaningless. */
    double i = lm > 1.0 ? VSGL__PI_D / sqrt(lm) : (isnan(lm) ? NAN : VSGL__PI_D);
    return (float)(exp((double)a->log_amplitude) * i);
}

/* --------------------------------------------------------------- product */

void vsgl_asg_product(const vsgl_asg *a, const vsgl_asg *b, vsgl_asg *out)
{
    vsgl__frame fa, fb;
    int va = vsgl__asg_frame(a, &fa), vb = vsgl__asg_frame(b, &fb);
    double la = (double)a->log_amplitude + (double)b->log_amplitude;
    if (!va || !vb || a->log_amplitude == -INFINITY || b->log_amplitude == -INFINITY) {
        zero_lobe(va ? &fa : &fb, out);
        return;
    }
    /* A3 = A1 + A2 with A = lambda x x^T + mu y y^T (algebraic form, Eq. 2). */
    double l1 = vsgl__asg_clamp_bw(a->lambda), m1 = vsgl__asg_clamp_bw(a->mu);
    double l2 = vsgl__asg_clamp_bw(b->lambda), m2 = vsgl__asg_clamp_bw(b->mu);
    double m[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            m[i][j] = l1 * fa.x[i] * fa.x[j] + m1 * fa.y[i] * fa.y[j]
                    + l2 * fb.x[i] * fb.x[j] + m2 * fb.y[i] * fb.y[j];
    double w[3], v[3][3];
    if (vsgl__eigen_sym3_fast(m, w, v) < 0) { /* NaN bandwidths */
        zero_lobe(&fa, out);
        out->lambda = out->mu = out->log_amplitude = NAN;
        return;
    }
    double zs[3] = {fa.z[0] + fb.z[0], fa.z[1] + fb.z[1], fa.z[2] + fb.z[2]};
    double x3[3] = {v[0][0], v[1][0], v[2][0]};
    double z3[3] = {v[0][2], v[1][2], v[2][2]};
    /* Smallest eigenvalue repeated (within rounding): z3 is any unit vector
     * of that eigenspace; take the one closest to z1 + z2 (its projection),
     * which maximises the smooth term's chance to be large and is what the
     * exact product peaks towards. */
    double tol = 1e-12 * (w[0] > 0.0 ? w[0] : 0.0);
    int nsmall = (w[1] - w[2] <= tol) ? ((w[0] - w[2] <= tol) ? 3 : 2) : 1;
    if (nsmall > 1) {
        double p[3] = {0.0, 0.0, 0.0};
        for (int k = 3 - nsmall; k < 3; ++k) {
            double c = zs[0] * v[0][k] + zs[1] * v[1][k] + zs[2] * v[2][k];
            for (int r = 0; r < 3; ++r)
                p[r] += c * v[r][k];
        }
        if (normalize3(p, 1e-9)) {
            z3[0] = p[0], z3[1] = p[1], z3[2] = p[2];
            if (nsmall == 3) {
                /* any x orthogonal to z3: Gram-Schmidt of the first eigenvector,
                 * or of the second if the first is parallel to z3 */
                double c = dot3(x3, z3);
                double t[3] = {x3[0] - c * z3[0], x3[1] - c * z3[1], x3[2] - c * z3[2]};
                if (!normalize3(t, 1e-3)) {
                    double y0[3] = {v[0][1], v[1][1], v[2][1]};
                    c = dot3(y0, z3);
                    t[0] = y0[0] - c * z3[0], t[1] = y0[1] - c * z3[1], t[2] = y0[2] - c * z3[2];
                    normalize3(t, 0.0);
                }
                x3[0] = t[0], x3[1] = t[1], x3[2] = t[2];
            }
        }
    }
    /* z3's sign: the hemisphere of z1 + z2 (the other one has S = 0 at
     * its peak). Flipping x3 with it keeps the frame right-handed. */
    if (dot3(z3, zs) < 0.0)
        for (int r = 0; r < 3; ++r) {
            z3[r] = -z3[r];
            x3[r] = -x3[r];
        }
    double y3[3];
    cross3(z3, x3, y3);
    vsgl__frame f3;
    for (int r = 0; r < 3; ++r) {
        f3.x[r] = x3[r];
        f3.y[r] = y3[r];
        f3.z[r] = z3[r];
    }
    double s = dot3(z3, fa.z) * dot3(z3, fb.z);
    if (!(dot3(z3, fa.z) > 0.0) || !(dot3(z3, fb.z) > 0.0) || !(s > 0.0)) {
        zero_lobe(&f3, out);
        return;
    }
    double lam = w[0] - w[2], mu = w[1] - w[2];
    out->x = to_v3(f3.x);
    out->y = to_v3(f3.y);
    out->z = to_v3(f3.z);
    out->lambda = (float)(lam < (double)VSGL_SHARPNESS_MAX ? (lam > 0.0 ? lam : 0.0) : (double)VSGL_SHARPNESS_MAX);
    out->mu = (float)(mu < (double)VSGL_SHARPNESS_MAX ? (mu > 0.0 ? mu : 0.0) : (double)VSGL_SHARPNESS_MAX);
    out->log_amplitude = (float)(la - w[2] + log(s));
}

/* ----------------------------------------------------------- convolution */

static double conv_norm(double lam, double mu, double nu, int mode)
{
    if (mode == VSGL__CONV_PAPER)
        return VSGL__PI_D / sqrt((lam + nu) * (mu + nu));
    return vsgl__asg_integral_unit(lam + nu, mu + nu);
}

static double harmonic(double a, double b)
{
    double s = a + b;
    return s > 0.0 ? a * b / s : 0.0;
}

void vsgl__asg_convolve_sg_mode(const vsgl_asg *a, const vsgl_sg *kernel, vsgl_asg *out, int mode)
{
    vsgl__frame f;
    int valid = vsgl__asg_frame(a, &f);
    if (!valid || a->log_amplitude == -INFINITY || kernel->log_amplitude == -INFINITY) {
        zero_lobe(&f, out);
        return;
    }
    double lam = vsgl__asg_clamp_bw(a->lambda), mu = vsgl__asg_clamp_bw(a->mu);
    double nu = 0.5 * vsgl__asg_clamp_bw(kernel->sharpness);
    double la = (double)a->log_amplitude + (double)kernel->log_amplitude + log(conv_norm(lam, mu, nu, mode));
    out->x = to_v3(f.x);
    out->y = to_v3(f.y);
    out->z = to_v3(f.z);
    out->lambda = (float)harmonic(nu, lam);
    out->mu = (float)harmonic(nu, mu);
    out->log_amplitude = (float)la;
}

void vsgl_asg_convolve_sg(const vsgl_asg *a, const vsgl_sg *kernel, vsgl_asg *out)
{
    vsgl__asg_convolve_sg_mode(a, kernel, out, VSGL__CONV_EXACT_INTEGRAL);
}

float vsgl_asg_sg_product_integral(const vsgl_asg *a, const vsgl_sg *g)
{
    vsgl__frame f;
    if (!vsgl__asg_frame(a, &f) || a->log_amplitude == -INFINITY || g->log_amplitude == -INFINITY)
        return 0.0f;
    double p[3];
    to_d3(&g->axis, p);
    if (!normalize3(p, 0.0))
        return 0.0f;
    double pz = dot3(p, f.z);
    if (!(pz > 0.0))
        return 0.0f;
    double lam = vsgl__asg_clamp_bw(a->lambda), mu = vsgl__asg_clamp_bw(a->mu);
    double nu = 0.5 * vsgl__asg_clamp_bw(g->sharpness);
    double px = dot3(p, f.x), py = dot3(p, f.y);
    double e = (double)a->log_amplitude + (double)g->log_amplitude
             - harmonic(nu, lam) * px * px - harmonic(nu, mu) * py * py;
    return (float)(pz * exp(e) * conv_norm(lam, mu, nu, VSGL__CONV_EXACT_INTEGRAL));
}

/* ----------------------------------------------------------- SG -> ASG */

void vsgl_sg_to_asg(const vsgl_sg *g, vsgl_asg *out)
{
    double z[3];
    to_d3(&g->axis, z);
    vsgl_asg tmp;
    tmp.z = g->axis;
    tmp.x = v3_make(0.0f, 0.0f, 0.0f);
    tmp.y = tmp.x;
    vsgl__frame f;
    if (!normalize3(z, 0.0) || !vsgl__asg_frame(&tmp, &f)) {
        vsgl__asg_frame(&tmp, &f); /* canonical frame */
        zero_lobe(&f, out);
        return;
    }
    double half = 0.5 * vsgl__asg_clamp_bw(g->sharpness);
    out->x = to_v3(f.x);
    out->y = to_v3(f.y);
    out->z = to_v3(f.z);
    out->lambda = (float)half;
    out->mu = (float)half;
    out->log_amplitude = g->log_amplitude;
}
