/* ASG operator error tables (docs/math_asg.md, "Measured errors").
 *
 * Build and run (links only the ASG sources, nothing else of libvsgl):
 *   mkdir -p build && cc -O2 -std=c11 -Icsrc/include -Icsrc/src \
 *     tools/asg_error_table.c csrc/src/math/asg.c csrc/src/math/bessel.c \
 *     csrc/src/math/eigen3.c -lm -o build/asg_error_table
 *   build/asg_error_table [integral|conv|product|sg|pint|all] [quick]
 *   build/asg_error_table conv full FIRST_ROW STEP   (rows of lambda = 1, 2, 3, 5, 10, 30, 100
 *                                                     in that order; e.g. "6 -1" runs them backwards)
 *
 * References are the double-precision quadratures of tools/asg_error_table.h
 * (tolerances 1e-9 relative or better, three orders below the smallest
 * error reported here). */
#include "asg_error_table.h"
#include "math/asg_internal.h"
#include "math/bessel.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int quick;
static int conv_first = 0, conv_step = 1; /* row order of the conv table (to split it over processes) */

/* ------------------------------------------------------------- integral */

static void table_integral(void)
{
    const double lo[3] = {5.0, 3.0, 1.0};
    const int n = quick ? 40 : 160;
    printf("\n== Integral of a unit ASG: max relative error over lambda, mu in (lo, 1e4] ==\n");
    printf("   (%d x %d log-spaced grid per class; reference: Eq. 6 by adaptive quadrature)\n", n, n);
    printf("%-14s %-24s %-24s %-24s\n", "class", "Eq. 10 (paper: F exact)", "Eq. 11", "vsgl_asg_integral");
    for (int c = 0; c < 3; ++c) {
        double e10 = 0, e11 = 0, elib = 0, at10[2] = {0, 0}, at11[2] = {0, 0};
        for (int i = 0; i < n; ++i)
            for (int j = 0; j <= i; ++j) {
                double l = lo[c] * pow(1e4 / lo[c], (i + 0.5) / n), m = lo[c] * pow(1e4 / lo[c], (j + 0.5) / n);
                if (j == 0)
                    m = lo[c] * (1.0 + 1e-9);
                double r = aq_asg_integral_ref(l, m);
                double a = fabs(vsgl__asg_integral_eq10(l, m) - r) / r;
                double b = fabs(AQ_PI / sqrt(l * m) - r) / r;
                double d = fabs(vsgl__asg_integral_unit(l, m) - r) / r;
                if (a > e10) e10 = a, at10[0] = l, at10[1] = m;
                if (b > e11) e11 = b, at11[0] = l, at11[1] = m;
                if (d > elib) elib = d;
            }
        printf("lam,mu > %-5g %.3e%% (%g,%g)   %.3e%% (%g,%g)   %.1e%%\n", lo[c], 100 * e10, at10[0], at10[1],
               100 * e11, at11[0], at11[1], 100 * elib);
    }
    /* the library over the whole range, including the extremes */
    double elib = 0;

    unsigned long long s = 12345;
    for (int k = 0; k < (quick ? 2000 : 20000); ++k) {
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        double u1 = (double)(s >> 11) * 0x1.0p-53;
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        double u2 = (double)(s >> 11) * 0x1.0p-53;
        double l = k % 7 == 0 ? 0.0 : pow(10.0, -9 + 21.3 * u1), m = k % 5 == 0 ? 0.0 : pow(10.0, -9 + 21.3 * u2);
        double r = aq_asg_integral_ref(l, m), d = fabs(vsgl__asg_integral_unit(l, m) - r) / r;
        if (d > elib)
            elib = d;
    }
    printf("vsgl_asg_integral (double core) over lambda, mu in {0} U [1e-9, 2e12]: max rel error %.1e\n", elib);
}

/* ---------------------------------------------------------- convolution */

typedef struct conv_ctx { aq_asg a; double nu, p[3]; } conv_ctx;

static double conv_integrand(const double v[3], void *u)
{
    conv_ctx *c = u;
    double vp = v[0] * c->p[0] + v[1] * c->p[1] + v[2] * c->p[2];
    double g = aq_asg_eval(&c->a, v);
    return g == 0.0 ? 0.0 : g * exp(2.0 * c->nu * (vp - 1.0));
}

/* Direction maximising -lam vx^2 - mu vy^2 + 2 nu v.p (ASG frame = world
 * axes): v_i = nu p_i / (a_i + eta), |v| = 1, a = (lam, mu, 0), eta in (0, nu]
 * by bisection; pulled onto the upper hemisphere's rim if below it. */
static void conv_peak(double lam, double mu, double nu, const double p[3], double out[3])
{
    double a[3] = {lam, mu, 0.0};
    if (nu <= 0.0 || fabs(p[2]) < 1e-12) {
        out[0] = 0, out[1] = 0, out[2] = 1;
        if (nu > 0.0 && fabs(p[2]) < 1e-12) {
            double t[3] = {p[0], p[1], 0.3};
            double l = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
            out[0] = t[0] / l, out[1] = t[1] / l, out[2] = t[2] / l;
        }
        return;
    }
    double lo = log(1e-300), hi = log(nu);
    for (int it = 0; it < 200; ++it) {
        double mid = 0.5 * (lo + hi), eta = exp(mid), h = -1.0;
        for (int i = 0; i < 3; ++i) {
            double t = nu * p[i] / (a[i] + eta);
            h += t * t;
        }
        if (h > 0.0)
            lo = mid;
        else
            hi = mid;
    }
    double eta = exp(0.5 * (lo + hi)), l = 0.0;
    for (int i = 0; i < 3; ++i) {
        out[i] = nu * p[i] / (a[i] + eta);
        l += out[i] * out[i];
    }
    l = sqrt(l);
    for (int i = 0; i < 3; ++i)
        out[i] /= l;
    if (out[2] < 0.02) { /* the ASG's smooth term cuts at the equator */
        out[2] = 0.02;
        l = sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
        for (int i = 0; i < 3; ++i)
            out[i] /= l;
    }
}

/* Exact C(p) = int ASG(v) exp(2 nu (v.p - 1)) dv, unit ASG on world axes. */
static double conv_exact(double lam, double mu, double nu, const double p[3], double scale)
{
    conv_ctx c;
    memset(&c, 0, sizeof c);
    c.a.x[0] = 1, c.a.y[1] = 1, c.a.z[2] = 1;
    c.a.lam = lam, c.a.mu = mu, c.a.logc = 0.0;
    c.nu = nu;
    memcpy(c.p, p, sizeof c.p);
    double pole[3];
    conv_peak(lam, mu, nu, p, pole);
    double w = 0.5 / sqrt(fmax(lam, mu) + 2.0 * nu + 1.0);
    return aq_sphere(conv_integrand, &c, pole, w, 1e-8 * scale, 1e-7);
}

typedef struct conv_err { double rel_paper, rel_ours, abs_norm_paper, abs_norm_ours, peak_paper, peak_ours; } conv_err;

/* L2 errors over p in S^2 (see docs): relative = ||Ca - Ce|| / ||Ce||;
 * abs_norm = ||Ca - Ce|| with both inputs normalised to integral 1.
 * p grid: theta about z in geometrically graded 15-point Kronrod panels,
 * phi by the midpoint rule on [0, pi/2] (C is even in px and in py). */
static conv_err conv_l2(double lam, double mu, double nu, int nphi)
{
    vsgl_asg a = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, (float)lam, (float)mu, 0.0f};
    vsgl_sg k = {{0, 0, 1}, (float)(2.0 * nu), 0.0f};
    vsgl_asg cp, co;
    vsgl__asg_convolve_sg_mode(&a, &k, &cp, VSGL__CONV_PAPER);
    vsgl__asg_convolve_sg_mode(&a, &k, &co, VSGL__CONV_EXACT_INTEGRAL);
    double lp = nu * fmax(lam, mu) / (nu + fmax(lam, mu));
    double wp = 0.5 / sqrt(lp + 1.0);
    double scale = vsgl__asg_integral_unit(lam + nu, mu + nu);
    double num_p = 0, num_o = 0, den = 0;
    double edges[80];
    int ne = 0;
    edges[ne++] = 0.0;
    for (double t = wp; t < 0.5 * AQ_PI - 1e-9; t = fmin(2.0 * t, edges[ne - 1] + 0.4))
        edges[ne++] = t;
    edges[ne++] = 0.5 * AQ_PI;
    for (double t = 0.5 * AQ_PI + 0.5; t < AQ_PI; t += 0.5)
        edges[ne++] = t;
    edges[ne++] = AQ_PI;
    for (int e = 0; e + 1 < ne; ++e) {
        double c = 0.5 * (edges[e] + edges[e + 1]), h = 0.5 * (edges[e + 1] - edges[e]);
        for (int j = 0; j < 15; ++j) {
            double xk = j < 7 ? -aq_xgk[j] : (j == 7 ? 0.0 : aq_xgk[14 - j]);
            double wk = aq_wgk[j < 8 ? j : 14 - j];
            double th = c + h * xk, st = sin(th), ct = cos(th);
            for (int i = 0; i < nphi; ++i) {
                double ph = (i + 0.5) * 0.5 * AQ_PI / nphi;
                double p[3] = {st * cos(ph), st * sin(ph), ct};
                vsgl_vec3 pv = {(float)p[0], (float)p[1], (float)p[2]};
                double ce = conv_exact(lam, mu, nu, p, scale);
                double ap = vsgl_asg_eval(&cp, &pv), ao = vsgl_asg_eval(&co, &pv);
                double wt = wk * h * st * (2.0 * AQ_PI / nphi);
                num_p += wt * (ap - ce) * (ap - ce);
                num_o += wt * (ao - ce) * (ao - ce);
                den += wt * ce * ce;
            }
        }
    }
    conv_err r;
    r.rel_paper = sqrt(num_p / den);
    r.rel_ours = sqrt(num_o / den);
    double norm = vsgl__asg_integral_unit(lam, mu) * (-AQ_PI * expm1(-4.0 * nu) / nu);
    r.abs_norm_paper = sqrt(num_p) / norm;
    r.abs_norm_ours = sqrt(num_o) / norm;
    double z[3] = {0, 0, 1};
    vsgl_vec3 zv = {0, 0, 1};
    double cz = conv_exact(lam, mu, nu, z, scale);
    r.peak_paper = fabs(vsgl_asg_eval(&cp, &zv) - cz) / cz;
    r.peak_ours = fabs(vsgl_asg_eval(&co, &zv) - cz) / cz;
    return r;
}

static void table_conv(void)
{
    const double bw[] = {1, 2, 3, 5, 10, 30, 100};
    const double nus[] = {0.1, 1, 10, 100, 1000};
    const int nb = quick ? 4 : 7, nn = quick ? 3 : 5;
    const double quick_nus[] = {1, 10, 100};
    printf("\n== Convolution ASG * SG (Eq. 18): relative L2 error over p in S^2 ==\n");
    printf("%6s %6s %8s | %-10s %-10s | %-10s %-10s | %-10s %-10s\n", "lam", "mu", "nu", "relL2 pap", "relL2 ours",
           "absL2n pap", "absL2n ours", "peak pap", "peak ours");
    double worst[3][2] = {{0, 0}, {0, 0}, {0, 0}}; /* class >3, >1 (all nu); >3 with nu >= 1 */
    for (int i = conv_first; i >= 0 && i < nb; i += conv_step)
        for (int j = 0; j <= i; ++j)
            for (int k = 0; k < nn; ++k) {
                double lam = bw[i], mu = bw[j], nu = quick ? quick_nus[k] : nus[k];
                conv_err e = conv_l2(lam, mu, nu, quick ? 8 : 12);
                printf("%6g %6g %8g | %9.4f%% %9.4f%% | %9.5f  %9.5f  | %9.4f%% %9.4f%%\n", lam, mu, nu,
                       100 * e.rel_paper, 100 * e.rel_ours, e.abs_norm_paper, e.abs_norm_ours, 100 * e.peak_paper,
                       100 * e.peak_ours);
                fflush(stdout);
                if (mu >= 3) {
                    worst[0][0] = fmax(worst[0][0], e.rel_paper);
                    worst[0][1] = fmax(worst[0][1], e.rel_ours);
                    if (nu >= 1) {
                        worst[2][0] = fmax(worst[2][0], e.rel_paper);
                        worst[2][1] = fmax(worst[2][1], e.rel_ours);
                    }
                }
                worst[1][0] = fmax(worst[1][0], e.rel_paper);
                worst[1][1] = fmax(worst[1][1], e.rel_ours);
            }
    printf("max relative L2: lam,mu >= 3: paper %.3f%%, ours %.3f%%; lam,mu >= 3, nu >= 1: paper %.3f%%, ours %.3f%%;"
           " lam,mu >= 1: paper %.3f%%, ours %.3f%%\n",
           100 * worst[0][0], 100 * worst[0][1], 100 * worst[2][0], 100 * worst[2][1], 100 * worst[1][0],
           100 * worst[1][1]);
}

/* -------------------------------------------------------------- product */

typedef struct prod_ctx { aq_asg a, b, c; int which; } prod_ctx;

static double prod_integrand(const double v[3], void *u)
{
    prod_ctx *p = u;
    double e = aq_asg_eval(&p->a, v) * aq_asg_eval(&p->b, v), ap = aq_asg_eval(&p->c, v);
    switch (p->which) {
    case 0: return e;
    case 1: return fabs(e - ap);
    case 2: return e * e;
    default: return (e - ap) * (e - ap);
    }
}

static void to_aq(const vsgl_asg *a, aq_asg *o)
{
    vsgl__frame f;
    vsgl__asg_frame(a, &f);
    memcpy(o->x, f.x, sizeof o->x);
    memcpy(o->y, f.y, sizeof o->y);
    memcpy(o->z, f.z, sizeof o->z);
    o->lam = vsgl__asg_clamp_bw(a->lambda);
    o->mu = vsgl__asg_clamp_bw(a->mu);
    o->logc = a->log_amplitude;
}

/* Relative L1 and L2 error of the Eq. 13 product, z2 tilted by alpha from z1
 * about the world x axis, x2 turned by beta about z2. */
static void prod_error(double l1, double m1, double l2, double m2, double alpha, double beta, double *l1err, double *l2err)
{
    vsgl_asg a = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, (float)l1, (float)m1, 0.0f};
    double ca = cos(alpha), sa = sin(alpha), cb = cos(beta), sb = sin(beta);
    /* frame of b: rotate world frame by beta about z, then by alpha about x */
    double bx[3] = {cb, sb * ca, sb * sa}, by[3] = {-sb, cb * ca, cb * sa}, bz[3] = {0, -sa, ca};
    vsgl_asg b = {{(float)bx[0], (float)bx[1], (float)bx[2]}, {(float)by[0], (float)by[1], (float)by[2]},
                  {(float)bz[0], (float)bz[1], (float)bz[2]}, (float)l2, (float)m2, 0.0f};
    vsgl_asg c;
    vsgl_asg_product(&a, &b, &c);
    prod_ctx p;
    to_aq(&a, &p.a);
    to_aq(&b, &p.b);
    to_aq(&c, &p.c);
    if (c.log_amplitude == -INFINITY)
        p.c.logc = -INFINITY;
    double w = 0.5 / sqrt(fmax(c.lambda, c.mu) + 1.0);
    double r[4], peak = exp((double)c.log_amplitude);
    double est = c.log_amplitude == -INFINITY ? 1e-300 : vsgl__asg_integral_unit(c.lambda, c.mu) * peak;
    for (int k = 0; k < 4; ++k) {
        /* absolute tolerances from the approximation's own size: kinks of
         * the smooth terms would otherwise be refined to the depth limit */
        double abs_tol = k == 0 ? 1e-7 * est : (k == 1 ? 1e-5 * r[0] : (k == 2 ? 1e-7 * est * peak : 1e-5 * r[2]));
        p.which = k;
        r[k] = aq_sphere(prod_integrand, &p, p.c.z, w, abs_tol, 1e-6);
    }
    *l1err = r[1] / r[0];
    *l2err = sqrt(r[3] / r[2]);
}

static void table_product(void)
{
    const double ex[3][4] = {{3, 3, 100, 5}, {10, 1, 100, 10}, {10, 1, 1000, 10}};
    const double dots[] = {1.0, 0.99, 0.95, 0.9, 0.8, 0.7, 0.5, 0.3, 0.1, 0.01};
    const int nd = sizeof dots / sizeof dots[0];
    printf("\n== Product of two ASGs (Eq. 13), Fig. 4 examples, z2 tilted about x1 so z1.z2 = d ==\n");
    printf("   relative L1 = int|G1G2 - G3| / int G1G2 (first), relative L2 = ||G1G2 - G3|| / ||G1G2|| (second)\n");
    printf("%-34s", "example / d");
    for (int i = 0; i < nd; ++i)
        printf(" %13g", dots[i]);
    printf("\n");
    for (int e = 0; e < 3; ++e)
        for (int b = 0; b < 2; ++b) {
            char name[96];
            snprintf(name, sizeof name, "Ex.%d (%g,%g)x(%g,%g) x2 %s", e + 1, ex[e][0], ex[e][1], ex[e][2], ex[e][3],
                     b ? "+45deg" : "+0deg");
            printf("%-34s", name);
            for (int i = 0; i < nd; ++i) {
                double e1, e2;
                prod_error(ex[e][0], ex[e][1], ex[e][2], ex[e][3], acos(dots[i]), b ? 0.25 * AQ_PI : 0.0, &e1, &e2);
                printf(" %6.2f/%5.2f%%", 100 * e1, 100 * e2);
                fflush(stdout);
            }
            printf("\n");
        }
}

/* ------------------------------------------------------------ SG -> ASG */

typedef struct sg_ctx { double s; int which; } sg_ctx;

/* t = cos(angle to the axis); SG e^{s(t-1)}, ASG t e^{-(s/2)(1-t^2)} for t > 0 */
static double sg_integrand(double t, void *u)
{
    sg_ctx *c = u;
    double g = exp(c->s * (t - 1.0)), a = t > 0.0 ? t * exp(-0.5 * c->s * (1.0 - t) * (1.0 + t)) : 0.0;
    double v = c->which == 0 ? g : (c->which == 1 ? fabs(g - a) : (c->which == 2 ? g * g : (g - a) * (g - a)));
    return 2.0 * AQ_PI * v;
}

static void table_sg(void)
{
    const double ss[] = {0.1, 0.5, 1, 2, 2.2925, 5, 10, 20, 50, 100, 1000, 1e4, 1e6};
    printf("\n== SG -> ASG (Eq. 3): exp(s (v.p - 1)) vs ASG [s/2, s/2] ==\n");
    printf("%10s %12s %12s %14s\n", "s", "rel L1", "rel L2", "integral ratio");
    for (unsigned i = 0; i < sizeof ss / sizeof ss[0]; ++i) {
        double r[4];
        for (int k = 0; k < 4; ++k) {
            sg_ctx c = {ss[i], k};
            /* panels graded towards t = 1 at the lobe's scale 1/s */
            double s = 0.0, hi = 1.0, w = fmin(1.0 / ss[i], 0.5);
            while (hi > -1.0) {
                double lo = fmax(hi - w, -1.0);
                if (hi > 0.0 && lo < 0.0)
                    lo = 0.0; /* kink of the ASG at t = 0 */
                s += aq_integrate(sg_integrand, &c, lo, hi, 1, 1e-13 * 2.0 * AQ_PI / (ss[i] + 1.0), 1e-10);
                hi = lo;
                w *= 2.0;
            }
            r[k] = s;
        }
        vsgl_sg g = {{0, 0, 1}, (float)ss[i], 0.0f};
        vsgl_asg a;
        vsgl_sg_to_asg(&g, &a);
        double ratio = vsgl__asg_integral_unit(a.lambda, a.mu) / r[0];
        printf("%10g %11.4f%% %11.4f%% %14.6f\n", ss[i], 100 * r[1] / r[0], 100 * sqrt(r[3] / r[2]), ratio);
    }
}

/* ---------------------------------------- product integral (VSGL glossy) */

/* vsgl_asg_sg_product_integral vs quadrature as a function of the angle
 * between the SG axis and the ASG axis (tilted in the x-z plane, the sharp
 * direction, and in the y-z plane), for glossy-lobe-like ASGs. */
/* ------------------------------ EXPERIMENT: Laplace product integral */
/* Not in the library (docs/math_asg.md, "Recommended next step"): steep
 * near the horizon of z where the maximiser hits the disk's rim, and the
 * p.z < 0 model can over-estimate for nearly flat ASGs. */

/* F(u, w) = -lam u^2 - mu w^2 + 2 nu (px u + py w + pz s), s = sqrt(1 - u^2 - w^2),
 * on the unit disk of (u, w) = (v.x, v.y): int ASG * SG = c e^{-2nu} int_disk e^F
 * exactly (dA = du dw / s cancels the smooth term s). */
typedef struct lap_f { double f, gu, gw, huu, hww, huw; } lap_f;

static lap_f lap_eval(double lam, double mu, double nu, const double p[3], double u, double w)
{
    lap_f r;
    double s2 = 1.0 - u * u - w * w;
    double s = sqrt(s2 > 1e-12 ? s2 : 1e-12), s3 = s * s * s;
    r.f = -lam * u * u - mu * w * w + 2.0 * nu * (p[0] * u + p[1] * w + p[2] * sqrt(s2 > 0.0 ? s2 : 0.0));
    r.gu = -2.0 * lam * u + 2.0 * nu * (p[0] - p[2] * u / s);
    r.gw = -2.0 * mu * w + 2.0 * nu * (p[1] - p[2] * w / s);
    r.huu = -2.0 * lam - 2.0 * nu * p[2] * (1.0 / s + u * u / s3);
    r.hww = -2.0 * mu - 2.0 * nu * p[2] * (1.0 / s + w * w / s3);
    r.huw = -2.0 * nu * p[2] * u * w / s3;
    return r;
}

/* Radial clamp into the disk (continuous). */
static void lap_clamp(double *u, double *w)
{
    const double rmax = 0.999;
    double r = sqrt(*u * *u + *w * *w);
    if (r > rmax) {
        *u *= rmax / r;
        *w *= rmax / r;
    }
}

static float laplace_product_integral(const vsgl_asg *a, const vsgl_sg *g)
{
    vsgl__frame f;
    if (!vsgl__asg_frame(a, &f) || a->log_amplitude == -INFINITY || g->log_amplitude == -INFINITY)
        return 0.0f;
    double q[3];
    q[0] = g->axis.x, q[1] = g->axis.y, q[2] = g->axis.z;
    double ql = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    if (!(ql > 0.0))
        return 0.0f;
    q[0] /= ql, q[1] /= ql, q[2] /= ql;
    double p[3] = {q[0] * f.x[0] + q[1] * f.x[1] + q[2] * f.x[2], q[0] * f.y[0] + q[1] * f.y[1] + q[2] * f.y[2],
                   q[0] * f.z[0] + q[1] * f.z[1] + q[2] * f.z[2]};
    double lam = vsgl__asg_clamp_bw(a->lambda), mu = vsgl__asg_clamp_bw(a->mu);
    double nu = 0.5 * vsgl__asg_clamp_bw(g->sharpness);
    if (isnan(lam) || isnan(mu) || isnan(nu))
        return NAN;
    /* keeps every Newton system regular; far below any bandwidth that matters */
    double eps = 1e-9 * (lam + mu + nu) + 1e-30;
    double u, w;
    if (p[2] >= 0.0) {
        /* F is concave: Newton from Eq. 16's centre, a fixed number of steps
         * (no data-dependent exit, so the result is continuous) */
        u = nu * p[0] / (lam + nu + eps);
        w = nu * p[1] / (mu + nu + eps);
        lap_clamp(&u, &w);
        for (int it = 0; it < 12; ++it) {
            lap_f r = lap_eval(lam, mu, nu, p, u, w);
            double huu = fmin(r.huu, -eps), hww = fmin(r.hww, -eps), huw = r.huw;
            double det = huu * hww - huw * huw;
            if (!(det > 0.0))
                break; /* cannot happen for p.z >= 0 (concave); defensive */
            double du = (hww * r.gu - huw * r.gw) / det, dw = (huu * r.gw - huw * r.gu) / det;
            /* step length at most 0.25 (continuous scaling): no overshoot
             * across the disk for sharp, separated lobes */
            double len = sqrt(du * du + dw * dw), k = len > 0.25 ? 0.25 / len : 1.0;
            u -= k * du;
            w -= k * dw;
            lap_clamp(&u, &w);
        }
    } else {
        /* p.z < 0: the exact F is not concave near the rim; centre of its
         * quadratic expansion about z (identical to the branch above at
         * p.z = 0), curvatures floored, clamped into the disk */
        u = nu * p[0] / fmax(lam + nu * p[2], eps);
        w = nu * p[1] / fmax(mu + nu * p[2], eps);
        lap_clamp(&u, &w);
    }
    /* exact exponent at the point (so the value never exceeds the true
     * maximum: F - 2 nu <= 0), Gaussian width from the Hessian there with
     * its half-eigenvalues floored at 0, normalised by the exact disk
     * integral (= ASG integral) so broad lobes keep their limits */
    lap_f r = lap_eval(lam, mu, nu, p, u, w);
    double a11 = -0.5 * r.huu, a22 = -0.5 * r.hww, a12 = -0.5 * r.huw;
    double fz = r.f;
    if (p[2] < 0.0) {
        /* quadratic model throughout (equal to the exact F at p.z = 0): its
         * exponent is below the exact one (s <= 1 - r^2/2), which damps the
         * rim maxima of sharp SGs below the horizon, where the Gaussian
         * model is poor; curvatures of the model */
        double rr = u * u + w * w;
        fz = -lam * u * u - mu * w * w + 2.0 * nu * (p[0] * u + p[1] * w + p[2] * (1.0 - 0.5 * rr));
        a11 = lam + nu * p[2];
        a22 = mu + nu * p[2];
        a12 = 0.0;
    }
    double tr = 0.5 * (a11 + a22), disc = sqrt(0.25 * (a11 - a22) * (a11 - a22) + a12 * a12);
    double e1 = fmax(tr + disc, 0.0), e2 = fmax(tr - disc, 0.0);
    double e = (double)a->log_amplitude + (double)g->log_amplitude + fmin(fz - 2.0 * nu, 0.0);
    return (float)(exp(e) * vsgl__asg_integral_unit(e1, e2));
}

static void table_pint(void)
{
    const double asgs[3][2] = {{10, 3}, {50, 10}, {300, 30}};
    const double lins[] = {1, 4, 16, 64, 256, 1024};
    const double angs[] = {0, 10, 20, 30, 45, 60, 80, 100, 130, 180};
    enum { NA = sizeof angs / sizeof angs[0] };
    for (int mode = 0; mode < 4; ++mode) {
        int peak_rel = mode & 1, lap = mode >> 1;
        printf("\n== ASG x SG product integral (%s) vs quadrature: %s ==\n",
               lap ? "EXPERIMENT: Laplace on the exact disk form" : "Eq. 18 at the SG axis",
               peak_rel ? "(approx - exact) / exact value at 0 deg (error relative to the peak)"
                        : "approx / exact - 1");
        printf("   SG exp(lam_in (v.xi - 1)); xi tilted from z by the angle in the x-z plane (lambda) / y-z plane (mu)\n");
        printf("%-10s %-8s", "asg", "lam_in");
        for (int i = 0; i < NA; ++i)
            printf(" %14.0f deg", angs[i]);
        printf("\n");
        for (int a = 0; a < 3; ++a)
            for (unsigned l = 0; l < sizeof lins / sizeof lins[0]; ++l) {
                printf("(%g,%g)%*s %-8g", asgs[a][0], asgs[a][1], (int)(4 - (asgs[a][0] >= 100) - (asgs[a][1] >= 10)), "", lins[l]);
                double peak = 0.0;
                for (int i = 0; i < NA; ++i) {
                    double e[2];
                    for (int plane = 0; plane < 2; ++plane) {
                        double t = angs[i] * AQ_PI / 180.0;
                        double p[3] = {plane ? 0.0 : sin(t), plane ? sin(t) : 0.0, cos(t)};
                        vsgl_asg g = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, (float)asgs[a][0], (float)asgs[a][1], 0.0f};
                        vsgl_sg k = {{(float)p[0], (float)p[1], (float)p[2]}, (float)lins[l], 0.0f};
                        double scale = vsgl__asg_integral_unit(asgs[a][0] + 0.5 * lins[l], asgs[a][1] + 0.5 * lins[l]);
                        double ex = conv_exact(asgs[a][0], asgs[a][1], 0.5 * lins[l], p, scale * 1e-3);
                        if (i == 0)
                            peak = ex;
                        double ap = lap ? laplace_product_integral(&g, &k)
                                        : vsgl_asg_sg_product_integral(&g, &k);
                        e[plane] = peak_rel ? (ap - ex) / peak : ap / ex - 1.0;
                    }
                    if (peak_rel)
                        printf(" %+7.2f/%+6.2f%%", 100 * e[0], 100 * e[1]);
                    else if (fabs(e[0]) < 1e4 && fabs(e[1]) < 1e4)
                        printf(" %+7.1f/%+6.1f%%", 100 * e[0], 100 * e[1]);
                    else
                        printf(" %7.0e/%6.0e ", e[0], e[1]);
                    fflush(stdout);
                }
                printf("\n");
            }
    }
}

int main(int argc, char **argv)
{
    const char *what = argc > 1 ? argv[1] : "all";
    quick = argc > 2 && strcmp(argv[2], "quick") == 0;
    if (argc > 4 && strcmp(what, "conv") == 0) { /* conv full|quick FIRST_ROW STEP */
        conv_first = atoi(argv[3]);
        conv_step = atoi(argv[4]);
    }
    int all = strcmp(what, "all") == 0;
    if (all || strcmp(what, "integral") == 0)
        table_integral();
    if (all || strcmp(what, "sg") == 0)
        table_sg();
    if (all || strcmp(what, "product") == 0)
        table_product();
    if (all || strcmp(what, "pint") == 0)
        table_pint();
    if (all || strcmp(what, "conv") == 0)
        table_conv();
    if (strcmp(what, "conv1") == 0 && argc > 5) {
        double l = atof(argv[3]), m = atof(argv[4]), n = atof(argv[5]);
        conv_err e = conv_l2(l, m, n, argc > 6 ? atoi(argv[6]) : 32);
        printf("lam %g mu %g nu %g: relL2 paper %.5f%% ours %.5f%%, absL2n paper %.6f ours %.6f, peak paper %.5f%% ours %.5f%%\n",
               l, m, n, 100 * e.rel_paper, 100 * e.rel_ours, e.abs_norm_paper, e.abs_norm_ours, 100 * e.peak_paper, 100 * e.peak_ours);
    }
    return 0;
}
