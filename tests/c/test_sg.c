/* SG operators against independent double-precision references:
 * sphere quadrature (sphere_quad.h), closed forms in double, and the exact
 * 1-D reduction of the SG x clamped-cosine integral. Set VSGL_TEST_TABLES=1
 * to print the error tables quoted in docs/math.md. */
#include "harness.h"
#include "sphere_quad.h"
#include "vsgl/sg.h"
#include "math/sg_internal.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

static int quick(void) { return getenv("VSGL_TEST_QUICK") != NULL; }
static int tables(void) { return getenv("VSGL_TEST_TABLES") != NULL; }

/* ---------------------------------------------------------------- helpers */

static double d_A(double l) { return l > 0.0 ? -2.0 * SQ_PI * expm1(-2.0 * l) / l : 4.0 * SQ_PI; }
static double d_mean_length(double l)
{
    if (l < 1e-3)
        return l / 3.0 - l * l * l / 45.0;
    return 1.0 / tanh(l) - 1.0 / l;
}
static double log_uniform(vt_rng *r, double lo, double hi)
{
    return exp(log(lo) + (log(hi) - log(lo)) * vt_uniform(r));
}
static void rand_dir(vt_rng *r, double d[3])
{
    double z = 2.0 * vt_uniform(r) - 1.0, p = 2.0 * SQ_PI * vt_uniform(r), s = sqrt(1.0 - z * z);
    d[0] = s * cos(p); d[1] = s * sin(p); d[2] = z;
}
static vsgl_vec3 f3(const double d[3]) { vsgl_vec3 v = {(float)d[0], (float)d[1], (float)d[2]}; return v; }
static void d3of(vsgl_vec3 v, double d[3])
{
    double l = sqrt((double)v.x * v.x + (double)v.y * v.y + (double)v.z * v.z);
    d[0] = v.x / l; d[1] = v.y / l; d[2] = v.z / l;
}
static double ddot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
/* 1 - a.b for unit a, b without cancellation: |a - b|^2 / 2 */
static double d_omdot(const double a[3], const double b[3])
{
    double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return 0.5 * (x * x + y * y + z * z);
}

/* A direction at angle theta from unit a (in a random plane). */
static void dir_at_angle(vt_rng *r, const double a[3], double theta, double out[3])
{
    double e1[3], e2[3];
    sq_basis(a, e1, e2);
    double p = 2.0 * SQ_PI * vt_uniform(r), ct = cos(theta), st = sin(theta);
    for (int k = 0; k < 3; ++k)
        out[k] = ct * a[k] + st * (cos(p) * e1[k] + sin(p) * e2[k]);
}

/* ------------------------------------------------------- quadrature check */

typedef struct sgq { double axis[3], lam, la; } sgq;
static double f_sg(const double w[3], double omu, void *u)
{
    const sgq *g = u;
    (void)w;
    return exp(g->la - g->lam * omu);
}

VT_TEST(sg_quadrature_self_check)
{
    /* The reference quadrature integrates an SG to the closed form A(l) in
     * double (1e-12 relative) from l = 0 to 1e8. */
    double ls[] = {0.0, 1e-8, 1e-3, 0.7, 1.0, 3.0, 100.0, 1e4, 1e6, 1e8};
    for (size_t i = 0; i < sizeof ls / sizeof ls[0]; ++i) {
        sgq g = {{0.3, -0.4, sqrt(0.75)}, ls[i], 0.0};
        double q = sq_sphere(f_sg, &g, g.axis, ls[i], 24, 8);
        VT_CHECK_REL(q, d_A(ls[i]), 1e-12, "lambda=%g", ls[i]);
    }
}

/* ------------------------------------------------- the part above a plane */

typedef struct sgh { double lam, n[3]; } sgh;
static double f_sg_above(const double w[3], double omu, void *u)
{
    const sgh *g = u;
    return ddot(w, g->n) > 0.0 ? exp(-g->lam * omu) : 0.0;
}

VT_TEST(sg_fraction_above_a_plane_matches_quadrature)
{
    /* vsgl__sg_fraction_above (a glossy emitter's lobe normalised to the
     * power it sends above its surface, shade.h vsgl__vsgl_lobe_integral)
     * against sphere quadrature of the SG cut by the plane over its
     * integral: within 1e-3 absolute, exact at c = +-1 and 1/2 at c = 0. */
    vt_rng r = {71};
    const double ls[] = {0.0005, 0.05, 0.6, 2.3, 9.0, 60.0, 900.0};
    const double cs[] = {-1.0, -0.6, -0.15, 0.0, 0.05, 0.2, 0.5, 0.8, 0.97, 1.0};
    double worst = 0.0;
    for (size_t i = 0; i < sizeof ls / sizeof ls[0]; ++i)
        for (size_t j = 0; j < sizeof cs / sizeof cs[0]; ++j) {
            sgh g;
            double axis[3] = {0, 0, 1}, t[3];
            double c = cs[j], s = sqrt(fmax(1.0 - c * c, 0.0));
            rand_dir(&r, t);
            double tn = ddot(t, axis);
            for (int k = 0; k < 3; ++k)
                t[k] -= tn * axis[k];
            double tl = sqrt(ddot(t, t));
            for (int k = 0; k < 3; ++k)
                g.n[k] = c * axis[k] + s * t[k] / tl;
            g.lam = (double)(float)ls[i];
            /* polar quadrature about the axis; the step's discontinuity
             * is resolved by the azimuth's many nodes */
            double q = sq_sphere(f_sg_above, &g, axis, g.lam, 48, 2048) / d_A(g.lam);
            double got = vsgl__sg_fraction_above((float)g.lam, (float)c);
            double e = fabs(got - q);
            worst = e > worst ? e : worst;
            VT_CHECK(e < 1e-3, "lambda %g cos %g: %.6f against %.6f", ls[i], c, got, q);
            if (c == 1.0)
                VT_CHECK(fabs(got - 1.0 / (1.0 + exp(-g.lam))) < 1e-4, "c = 1: 1 / (1 + e^-l), lambda %g", ls[i]);
            if (c == 0.0)
                VT_CHECK(fabs(got - 0.5) < 1e-6, "c = 0: 1/2, lambda %g", ls[i]);
        }
    if (tables())
        printf("    SG part above a plane: max abs err %.3g\n", worst);
}

/* ------------------------------------------------------------ eval, A(l) */

VT_TEST(sg_integral_matches_quadrature)
{
    vt_rng r = {1};
    double worst = 0.0;
    for (int it = 0; it < 200; ++it) {
        double l = log_uniform(&r, 1e-9, 1e7);
        float lf = (float)l;
        sgq g = {{0, 0, 1}, (double)lf, 0.0};
        double q = sq_sphere(f_sg, &g, g.axis, lf, 16, 4);
        double got = vsgl_sg_integral(lf);
        double e = fabs(got - q) / q;
        worst = e > worst ? e : worst;
        VT_CHECK_REL(got, q, 4e-7, "lambda=%.9g", lf);
    }
    VT_CHECK_REL(vsgl_sg_integral(0.0f), 4.0 * SQ_PI, 1e-7, "lambda=0");
    VT_CHECK_REL(vsgl_sg_integral(1e30f), d_A(VSGL_SHARPNESS_MAX), 1e-6, "lambda=1e30 is clamped");
    VT_CHECK_REL(vsgl_sg_integral(INFINITY), d_A(VSGL_SHARPNESS_MAX), 1e-6, "lambda=inf is clamped");
    VT_CHECK_REL(vsgl_sg_integral(-3.0f), 4.0 * SQ_PI, 1e-7, "negative lambda is 0");
    VT_CHECK_REL(vsgl_sg_integral(NAN), 4.0 * SQ_PI, 1e-7, "NaN lambda is 0");
    if (tables())
        printf("    A(lambda): max rel err %.3g over 200 log-uniform lambda in [1e-9, 1e7]\n", worst);
}

VT_TEST(sg_eval_matches_double)
{
    vt_rng r = {2};
    for (int it = 0; it < 20000; ++it) {
        double a[3], w[3];
        rand_dir(&r, a);
        double l = log_uniform(&r, 1e-6, 1e6);
        /* directions near the lobe matter for sharp lobes */
        dir_at_angle(&r, a, vt_uniform(&r) < 0.5 ? SQ_PI * vt_uniform(&r) : 3.0 / sqrt(l) * vt_uniform(&r), w);
        double la = 20.0 * vt_uniform(&r) - 10.0;
        vsgl_sg g = {f3(a), (float)l, (float)la};
        vsgl_vec3 wf = f3(w);
        double ad[3], wd[3];
        d3of(g.axis, ad);
        d3of(wf, wd);
        double expo = (double)g.log_amplitude - (double)g.sharpness * d_omdot(wd, ad);
        double want = exp(expo);
        double got = vsgl_sg_eval(&g, &wf);
        /* float results below FLT_MIN lose relative precision: 1e-37 absolute floor */
        VT_CHECK(fabs(got - want) <= 2e-6 * (1.0 + fabs(expo)) * want + 1e-37, "lambda=%g la=%g expo=%g: %g vs %g", l, la, expo, got, want);
    }
    vsgl_sg z = {{0, 0, 0}, 1.0f, 0.0f};
    vsgl_vec3 d = {0, 0, 1};
    VT_CHECK(vsgl_sg_eval(&z, &d) == 0.0f, "zero axis gives 0");
    vsgl_sg m = {{0, 0, 1}, 1.0f, -INFINITY};
    VT_CHECK(vsgl_sg_eval(&m, &d) == 0.0f, "-inf amplitude gives 0");
    vsgl_vec3 d2 = {0, 0, 7};
    vsgl_sg one = {{0, 0, 2}, 5.0f, 0.0f};
    VT_CHECK_REL(vsgl_sg_eval(&one, &d2), 1.0, 1e-7, "unnormalised inputs are normalised");
}

VT_TEST(sg_lobe_integral_matches_quadrature)
{
    vt_rng r = {3};
    for (int it = 0; it < 100; ++it) {
        double a[3];
        rand_dir(&r, a);
        double l = log_uniform(&r, 1e-6, 1e6), la = 40.0 * vt_uniform(&r) - 30.0;
        vsgl_sg g = {f3(a), (float)l, (float)la};
        sgq q = {{a[0], a[1], a[2]}, (double)g.sharpness, (double)g.log_amplitude};
        double want = sq_sphere(f_sg, &q, q.axis, q.lam, 16, 4);
        VT_CHECK_REL(vsgl_sg_lobe_integral(&g), want, 2e-6 * (1.0 + fabs(la)), "lambda=%g la=%g", l, la);
    }
}

/* ---------------------------------------------------------------- product */

typedef struct sg2 { double a1[3], l1, la1, a2[3], l2, la2; } sg2;
static double f_sg2(const double w[3], double omu, void *u)
{
    const sg2 *p = u;
    (void)omu;
    return exp(p->la1 + p->la2 - p->l1 * d_omdot(w, p->a1) - p->l2 * d_omdot(w, p->a2));
}

/* Draw two SGs of independent log-uniform sharpness whose axes are at an
 * angle spread from 0 to pi (including exactly antipodal and equal). */
static void draw_pair(vt_rng *r, double lo, double hi, vsgl_sg *a, vsgl_sg *b)
{
    double x[3], y[3];
    rand_dir(r, x);
    double u = vt_uniform(r);
    double th = u < 0.05 ? 0.0 : (u < 0.1 ? SQ_PI : SQ_PI * vt_uniform(r) * vt_uniform(r));
    dir_at_angle(r, x, th, y);
    a->axis = f3(x); b->axis = f3(y);
    a->sharpness = (float)log_uniform(r, lo, hi);
    b->sharpness = (float)log_uniform(r, lo, hi);
    a->log_amplitude = (float)(4.0 * vt_uniform(r) - 2.0);
    b->log_amplitude = (float)(4.0 * vt_uniform(r) - 2.0);
}

static void to_sg2(const vsgl_sg *a, const vsgl_sg *b, sg2 *p)
{
    d3of(a->axis, p->a1); d3of(b->axis, p->a2);
    p->l1 = a->sharpness; p->l2 = b->sharpness;
    p->la1 = a->log_amplitude; p->la2 = b->log_amplitude;
}

/* Product axis/sharpness in double, only to place the quadrature nodes. */
static double d_product_frame(const sg2 *p, double axis[3])
{
    double s[3];
    for (int k = 0; k < 3; ++k)
        s[k] = p->l1 * p->a1[k] + p->l2 * p->a2[k];
    double lm = sqrt(ddot(s, s));
    for (int k = 0; k < 3; ++k)
        axis[k] = lm > 0 ? s[k] / lm : p->a1[k];
    return lm;
}

VT_TEST(sg_product_is_pointwise_product)
{
    vt_rng r = {4};
    for (int it = 0; it < 20000; ++it) {
        vsgl_sg a, b, m;
        draw_pair(&r, 1e-4, 1e5, &a, &b);
        vsgl_sg_product(&a, &b, &m);
        sg2 p;
        to_sg2(&a, &b, &p);
        double ax[3];
        double lm = d_product_frame(&p, ax);
        double w[3];
        dir_at_angle(&r, ax, vt_uniform(&r) < 0.5 ? SQ_PI * vt_uniform(&r) : vt_uniform(&r) * 3.0 / sqrt(lm + 1.0), w);
        vsgl_vec3 wf = f3(w);
        double wd[3], md[3];
        d3of(wf, wd);
        d3of(m.axis, md);
        double want = p.la1 + p.la2 - p.l1 * d_omdot(wd, p.a1) - p.l2 * d_omdot(wd, p.a2);
        double got = (double)m.log_amplitude - (double)m.sharpness * d_omdot(wd, md);
        /* float inputs: the exponent carries ~1e-7 (l1 + l2) absolute error */
        VT_CHECK(fabs(got - want) <= 1e-5 * (1.0 + fabs(want)) + 2e-7 * (p.l1 + p.l2),
                 "log product %.9g vs %.9g (l1=%g l2=%g angle=%g)", got, want, p.l1, p.l2, acos(fmax(-1, fmin(1, ddot(p.a1, p.a2)))));
        VT_CHECK(m.log_amplitude <= a.log_amplitude + b.log_amplitude, "log-amplitude never grows");
    }
    /* aliasing */
    vsgl_sg a = {{0, 0, 1}, 3.0f, 0.5f}, b = {{1, 0, 0}, 2.0f, -0.5f}, c;
    vsgl_sg_product(&a, &b, &c);
    vsgl_sg_product(&a, &b, &a);
    VT_CHECK(memcmp(&a, &c, sizeof a) == 0, "out may alias a");
}

VT_TEST(sg_product_integral_matches_quadrature)
{
    vt_rng r = {5};
    double worst = 0.0;
    int n = quick() ? 60 : 300;
    for (int it = 0; it < n; ++it) {
        vsgl_sg a, b;
        draw_pair(&r, 1e-5, 1e6, &a, &b);
        {
            /* keep the result representable in float: angle within the
             * product's reach (exponent >= -80) */
            double x[3], y[3];
            d3of(a.axis, x);
            double lr = (double)a.sharpness * b.sharpness / ((double)a.sharpness + b.sharpness);
            double th = acos(fmax(-1.0, fmin(1.0, ddot(x, (d3of(b.axis, y), y)))));
            if (lr * (1.0 - cos(th)) > 80.0) {
                dir_at_angle(&r, x, vt_uniform(&r) * sqrt(160.0 / lr), y);
                b.axis = f3(y);
            }
        }
        sg2 p;
        to_sg2(&a, &b, &p);
        double ax[3];
        double lm = d_product_frame(&p, ax);
        double want = sq_sphere(f_sg2, &p, ax, lm, 16, 8);
        double got = vsgl_sg_product_integral(&a, &b);
        double lw = log(want);
        double tol = 2e-6 * (1.0 + fabs(lw));
        double e = want > 1e-30 ? fabs(got - want) / want : 0.0;
        worst = e > worst ? e : worst;
        VT_CHECK(fabs(got - want) <= tol * want + 1e-37, "l1=%g l2=%g angle=%g log(want)=%g: %g vs %g", p.l1, p.l2,
                 acos(fmax(-1, fmin(1, ddot(p.a1, p.a2)))), lw, got, want);
    }
    if (tables())
        printf("    product integral: max rel err %.3g (%d pairs, l in [1e-5,1e6], any angle)\n", worst, n);
    /* Sharp antipodal lobes: exp(-2 l) far below FLT_MIN is a clean 0 or
     * denormal, never NaN; log domain keeps moderate ones. */
    vsgl_sg s1 = {{0, 0, 1}, 1e6f, 0.0f}, s2 = {{0, 0, -1}, 1e6f, 0.0f};
    float v = vsgl_sg_product_integral(&s1, &s2);
    VT_CHECK(v >= 0.0f && v < 1e-30f, "antipodal sharp: %g", v);
    vsgl_sg t1 = {{0, 0, 1}, 30.0f, 50.0f}, t2 = {{0, 0, -1}, 30.0f, 50.0f};
    double want = exp(100.0 - 60.0) * d_A(0.0);
    VT_CHECK_REL(vsgl_sg_product_integral(&t1, &t2), want, 2e-5, "antipodal equal l=30, amplitudes e^50");
}

VT_TEST(sg_product_integral_iwasaki)
{
    /* Iwasaki's approximation against the exact product integral: error
     * table by min(l1, l2); sharp lobes are accurate, broad ones are
     * over-estimated and capped by a1 a2 min(A(l1), A(l2)). */
    vt_rng r = {6};
    double bins[] = {1e-3, 0.1, 1.0, 10.0, 100.0, 1e3};
    enum { NB = 6 };
    double worst[NB] = {0};
    for (int it = 0; it < 200000; ++it) {
        vsgl_sg a, b;
        draw_pair(&r, 1e-3, 1e5, &a, &b);
        double ex = vsgl_sg_product_integral(&a, &b);
        double iw = vsgl_sg_product_integral_iwasaki(&a, &b);
        /* independent double formula of Iwasaki's approximation */
        sg2 p;
        to_sg2(&a, &b, &p);
        double s = p.l1 + p.l2, lr = p.l1 * p.l2 / s;
        double w = 2.0 * SQ_PI * exp(p.la1 + p.la2 - lr * d_omdot(p.a1, p.a2)) / s;
        double bound = exp(p.la1 + p.la2) * d_A(fmax(p.l1, p.l2));
        double want = fmin(w, bound);
        VT_CHECK(fabs(iw - want) <= 1e-5 * (1.0 + lr * d_omdot(p.a1, p.a2)) * want + 1e-37, "l1=%g l2=%g: %g vs %g", p.l1, p.l2, iw, want);
        VT_CHECK(iw >= 0.0f && isfinite(iw), "finite");
        /* error relative to the lobes' overlap scale a1 a2 min(A) */
        double e = fabs(iw - ex) / bound;
        double lmin = fmin(p.l1, p.l2);
        for (int k = NB - 1; k >= 0; --k)
            if (lmin >= bins[k]) {
                worst[k] = e > worst[k] ? e : worst[k];
                break;
            }
    }
    VT_CHECK(worst[5] < 2e-3, "l >= 1e3: max |iwasaki - exact| / (a1 a2 min A) = %g", worst[5]);
    VT_CHECK(worst[4] < 2e-2, "l >= 100: %g", worst[4]);
    if (tables())
        for (int k = 0; k < NB; ++k)
            printf("    iwasaki: min(l1,l2) >= %-6g max |err| / (a1 a2 min A) = %.3g\n", bins[k], worst[k]);
}

/* ------------------------------------------------------- SG x clamped cosine */

/* Exact reference by a 1-D reduction: about the SG axis, w.n = u c + s
 * sqrt(1-u^2) cos(phi); the azimuthal integral of max(a cos phi + b, 0) is
 * closed form, leaving  integral_{-1}^{1} exp(l (u - 1)) K(u) du, integrated
 * with Gauss-Legendre panels split at the kinks u = +-s and geometric in
 * 1 - u. */
typedef struct cref { double l, c, s; } cref;
static double cos_K(double u, double c, double s)
{
    double a = s * sqrt(fmax(0.0, (1.0 - u) * (1.0 + u))), b = u * c;
    if (b >= a)
        return 2.0 * SQ_PI * b;
    if (b <= -a)
        return 0.0;
    double p0 = acos(-b / a);
    return 2.0 * a * sin(p0) + 2.0 * b * p0;
}
static double f_cos1(double th, void *u)
{
    const cref *p = u;
    double sh = sin(0.5 * th);
    return exp(-2.0 * p->l * sh * sh) * cos_K(cos(th), p->c, p->s) * sin(th);
}
static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}
/* Integrated in theta (u = cos theta keeps every factor smooth except the
 * two kinks theta = acos(+-s), which are panel edges), panels geometric in
 * theta sqrt(l) so sharp lobes are resolved. */
static double ref_cosine(double l, double c)
{
    cref p = {l, c, sqrt(fmax(0.0, 1.0 - c * c))};
    double e[200];
    int n = 0;
    e[n++] = 0.0; e[n++] = SQ_PI; e[n++] = acos(p.s); e[n++] = acos(-p.s);
    for (double t = 0.25 / sqrt(fmax(l, 1e-300)); t < SQ_PI && n < 190; t *= 2.0)
        e[n++] = t;
    qsort(e, (size_t)n, sizeof e[0], cmp_d);
    double sum = 0.0;
    for (int i = 0; i + 1 < n; ++i)
        if (e[i + 1] > e[i])
            sum += sq_line(f_cos1, &p, e[i], e[i + 1], 1, 24);
    return sum;
}

typedef struct cq { double axis[3], n[3], l; } cq;
static double f_cos2(const double w[3], double omu, void *u)
{
    const cq *p = u;
    return exp(-p->l * omu) * fmax(0.0, ddot(w, p->n));
}

VT_TEST(sg_cosine_reference_matches_sphere_quadrature)
{
    /* Two independent references agree: the 1-D reduction and the 2-D
     * sphere quadrature of exp(l (w.xi - 1)) max(w.n, 0). */
    double ls[] = {1e-6, 0.3, 2.0, 30.0, 1000.0};
    double cs[] = {1.0, 0.7, 0.05, 0.0, -0.2, -0.9, -1.0};
    for (size_t i = 0; i < 5; ++i)
        for (size_t j = 0; j < 7; ++j) {
            cq p = {{0, 0, 1}, {sqrt(1 - cs[j] * cs[j]), 0, cs[j]}, ls[i]};
            double q2 = sq_sphere(f_cos2, &p, p.axis, ls[i], 32, 512);
            double q1 = ref_cosine(ls[i], cs[j]);
            /* the 2-D trapezoid in phi is only O(h^2) across the kink w.n = 0 */
            VT_CHECK(fabs(q1 - q2) <= 5e-6 * d_A(ls[i]), "l=%g c=%g: 1-D %.12g 2-D %.12g", ls[i], cs[j], q1, q2);
        }
}

/* Error statistics of the three modes over a (lambda, angle) grid, against
 * the exact reference. Relative error only where the reference is at least
 * `floor` times its value at c = 1 (the deep shadow tail is exponentially
 * small and only its absolute error matters); absolute error over A(l). */
typedef struct cstat { double max_rel[2], sum_rel, max_abs, sum_abs; int n_rel, n; } cstat;

static void cstat_merge(cstat *all, const cstat *s)
{
    for (int f = 0; f < 2; ++f)
        all->max_rel[f] = fmax(all->max_rel[f], s->max_rel[f]);
    all->max_abs = fmax(all->max_abs, s->max_abs);
    all->sum_rel += s->sum_rel; all->sum_abs += s->sum_abs;
    all->n_rel += s->n_rel; all->n += s->n;
}

VT_TEST(sg_cosine_modes_error_table)
{
    /* lambda log-spaced 1e-3 .. 1e5 (3 per decade), angles 0..pi. */
    static const char *names[] = {"SG (poster)", "pulled-out (FIS)", "accurate"};
    static const int32_t modes[] = {VSGL_COSINE_SG, VSGL_COSINE_PULLED_OUT, VSGL_COSINE_ACCURATE};
    int nang = quick() ? 31 : 91;
    cstat all[3];
    memset(all, 0, sizeof all);
    if (tables())
        printf("\n    %-17s %9s | %9s %9s | %10s %9s | %10s\n", "mode", "lambda", "max abs/A", "mean abs/A",
               "maxrel>1e-2", "meanrel", "maxrel>1e-4");
    for (int k = 0; k <= 24; ++k) {
        float lf = (float)pow(10.0, -3.0 + k / 3.0);
        double l = lf, A = d_A(l), peak = ref_cosine(l, 1.0);
        cstat st[3];
        memset(st, 0, sizeof st);
        for (int j = 0; j < nang; ++j) {
            double th = SQ_PI * j / (nang - 1);
            vsgl_vec3 n = {(float)sin(th), 0.0f, (float)cos(th)};
            double nd[3];
            d3of(n, nd);
            double want = ref_cosine(l, nd[2]);
            vsgl_sg g = {{0, 0, 1}, lf, 0.0f};
            for (int m = 0; m < 3; ++m) {
                double got = vsgl_sg_cosine_integral(&g, &n, modes[m]);
                double ea = fabs(got - want) / A;
                st[m].max_abs = fmax(st[m].max_abs, ea);
                st[m].sum_abs += ea;
                st[m].n++;
                double er = fabs(got - want) / want;
                if (want >= 1e-2 * peak) {
                    st[m].max_rel[0] = fmax(st[m].max_rel[0], er);
                    st[m].sum_rel += er;
                    st[m].n_rel++;
                }
                if (want >= 1e-4 * peak)
                    st[m].max_rel[1] = fmax(st[m].max_rel[1], er);
            }
        }
        for (int m = 0; m < 3; ++m) {
            cstat_merge(&all[m], &st[m]);
            if (tables() && (k % 3 == 0 || m == 2))
                printf("    %-17s %9.3g | %9.2e %9.2e | %10.2e %9.2e | %10.2e\n", names[m], l, st[m].max_abs,
                       st[m].sum_abs / st[m].n, st[m].max_rel[0], st[m].sum_rel / (st[m].n_rel ? st[m].n_rel : 1),
                       st[m].max_rel[1]);
        }
    }
    if (tables())
        for (int m = 0; m < 3; ++m)
            printf("    %-17s %9s | %9.2e %9.2e | %10.2e %9.2e | %10.2e\n", names[m], "ALL", all[m].max_abs,
                   all[m].sum_abs / all[m].n, all[m].max_rel[0], all[m].sum_rel / all[m].n_rel, all[m].max_rel[1]);
    /* The accurate mode: stated tolerances (measured values in docs/math.md). */
    VT_CHECK(all[2].max_abs < 6e-5, "accurate max abs/A %g", all[2].max_abs);
    VT_CHECK(all[2].sum_abs / all[2].n < 5e-6, "accurate mean abs/A %g", all[2].sum_abs / all[2].n);
    VT_CHECK(all[2].max_rel[0] < 6e-3, "accurate max rel (>=1e-2 peak) %g", all[2].max_rel[0]);
    /* and it beats both other modes on every statistic */
    for (int m = 0; m < 2; ++m) {
        VT_CHECK(all[2].max_abs < all[m].max_abs, "max abs: accurate %g vs mode %d %g", all[2].max_abs, m, all[m].max_abs);
        VT_CHECK(all[2].sum_abs < all[m].sum_abs, "mean abs: accurate vs mode %d", m);
        VT_CHECK(all[2].max_rel[0] < all[m].max_rel[0], "max rel: accurate %g vs mode %d %g", all[2].max_rel[0], m, all[m].max_rel[0]);
    }
}

VT_TEST(sg_cosine_random_against_reference)
{
    /* Random axes, normals, amplitudes, lambda log-uniform in [1e-6, 1e6]:
     * |accurate - exact| <= 6e-5 amplitude A(l). */
    vt_rng r = {7};
    int n = quick() ? 300 : 2000;
    for (int it = 0; it < n; ++it) {
        double a[3], nn[3];
        rand_dir(&r, a);
        rand_dir(&r, nn);
        double l = log_uniform(&r, 1e-6, 1e6), la = 6.0 * vt_uniform(&r) - 3.0;
        vsgl_sg g = {f3(a), (float)l, (float)la};
        vsgl_vec3 nf = f3(nn);
        double ad[3], nd[3];
        d3of(g.axis, ad);
        d3of(nf, nd);
        double c = ddot(ad, nd);
        double want = exp((double)g.log_amplitude) * ref_cosine(g.sharpness, c);
        double got = vsgl_sg_cosine_integral(&g, &nf, VSGL_COSINE_ACCURATE);
        double scale = exp((double)g.log_amplitude) * d_A(g.sharpness);
        VT_CHECK(fabs(got - want) <= 6e-5 * scale, "l=%g c=%.9g la=%g: got %.9g want %.9g", l, c, la, got, want);
        double po = vsgl_sg_cosine_integral(&g, &nf, VSGL_COSINE_PULLED_OUT);
        /* c from float vectors carries ~1e-7 absolute error */
        VT_CHECK(fabs(po - fmax(c, 0.0) * scale) <= 2e-6 * fmax(c, 0.0) * scale + 2e-7 * scale, "pulled-out l=%g c=%g", l, c);
        VT_CHECK(vsgl_sg_cosine_integral(&g, &nf, 17) == got, "unknown mode behaves as ACCURATE");
    }
}

VT_TEST(sg_cosine_sg_mode_is_poster_product_integral)
{
    /* Mode SG = pi / A(l_d) * integral of G(w) G(w; n, l_d), checked by 2-D quadrature. */
    vt_rng r = {8};
    double ld = vsgl_sg_cosine_sharpness();
    for (int it = 0; it < 60; ++it) {
        double a[3], nn[3];
        rand_dir(&r, a);
        rand_dir(&r, nn);
        vsgl_sg g = {f3(a), (float)log_uniform(&r, 1e-4, 1e5), 0.5f};
        vsgl_vec3 nf = f3(nn);
        sg2 p;
        d3of(g.axis, p.a1); d3of(nf, p.a2);
        p.l1 = g.sharpness; p.la1 = g.log_amplitude;
        p.l2 = (float)ld; p.la2 = log(SQ_PI / d_A((float)ld));
        double ax[3];
        double lm = d_product_frame(&p, ax);
        double want = sq_sphere(f_sg2, &p, ax, lm, 16, 16);
        VT_CHECK_REL(vsgl_sg_cosine_integral(&g, &nf, VSGL_COSINE_SG), want, 1e-5, "l=%g", p.l1);
    }
}

typedef struct ldq { double l; } ldq;
static double f_ld(double u, void *p)
{
    double l = ((const ldq *)p)->l;
    double d = fmax(u, 0.0) / SQ_PI - exp(l * (u - 1.0)) / d_A(l);
    return 2.0 * SQ_PI * d * d;
}
static double ld_objective(double l)
{
    ldq p = {l};
    return sq_line(f_ld, &p, -1.0, 0.0, 4, 32) + sq_line(f_ld, &p, 0.0, 1.0, 4, 32);
}

VT_TEST(sg_cosine_sharpness_is_least_squares)
{
    /* l_d minimises the L2 distance on the sphere between max(w.n,0)/pi and
     * G(w; n, l)/A(l): the objective is larger 1e-4 to either side. */
    double ld = vsgl_sg_cosine_sharpness();
    double j0 = ld_objective(ld), jm = ld_objective(ld - 1e-4), jp = ld_objective(ld + 1e-4);
    VT_CHECK(j0 < jm && j0 < jp, "J(%g)=%.12g J(-)=%.12g J(+)=%.12g", ld, j0, jm, jp);
    VT_CHECK(fabs(ld - 2.2925) < 1e-3, "l_d = %g", ld);
    if (tables()) {
        printf("    l_d = %.7f, L2 objective %.6g (relative L2 error %.4f); at l = 2: %.6g\n", ld, j0,
               sqrt(j0 / (2.0 * SQ_PI / (3.0 * SQ_PI * SQ_PI))), ld_objective(2.0));
    }
}

/* --------------------------------------------------------- sharpness <-> r */

VT_TEST(sg_sharpness_estimators)
{
    vt_rng r = {9};
    for (int it = 0; it < 100000; ++it) {
        float m = (float)vt_uniform(&r);
        if (it % 3 == 0)
            m = (float)(1.0 - log_uniform(&r, 1e-7, 1.0));
        double md = m;
        double t = md / (1.0 - md), b = md * (3.0 - md * md) / (1.0 - md * md);
        float gt = vsgl_sharpness_from_mean_length(m, VSGL_SHARPNESS_TOKSVIG);
        float gb = vsgl_sharpness_from_mean_length(m, VSGL_SHARPNESS_BANERJEE);
        VT_CHECK_REL(gt, fmin(t, VSGL_SHARPNESS_MAX), 1e-6, "toksvig r=%.9g", m);
        VT_CHECK_REL(gb, fmin(b, VSGL_SHARPNESS_MAX), 1e-6, "banerjee r=%.9g", m);
        /* Toksvig round trip */
        VT_CHECK(fabs(vsgl_mean_length_from_sharpness(gt, VSGL_SHARPNESS_TOKSVIG) - m) <= 2e-7, "toksvig round trip r=%.9g", m);
    }
    VT_CHECK(vsgl_sharpness_from_mean_length(0.0f, 0) == 0.0f, "r=0");
    VT_CHECK(vsgl_sharpness_from_mean_length(-1.0f, 1) == 0.0f, "r<0");
    VT_CHECK(vsgl_sharpness_from_mean_length(NAN, 1) == 0.0f, "NaN");
    VT_CHECK(vsgl_sharpness_from_mean_length(1.0f, 0) == VSGL_SHARPNESS_MAX, "r=1 toksvig");
    VT_CHECK(vsgl_sharpness_from_mean_length(1.0f, 1) == VSGL_SHARPNESS_MAX, "r=1 banerjee");
    VT_CHECK(vsgl_sharpness_from_mean_length(0.99999994f, 1) <= VSGL_SHARPNESS_MAX, "r->1");
}

typedef struct mq { double l; } mq;
static double f_mean(const double w[3], double omu, void *u)
{
    (void)w;
    double l = ((const mq *)u)->l;
    return (1.0 - omu) * exp(-l * omu);
}

VT_TEST(sg_mean_length_is_exact_vmf)
{
    /* Banerjee mode's inverse is the exact vMF mean length coth l - 1/l:
     * against quadrature of E[w.xi] and the double closed form; Banerjee's
     * estimate inverts it to within the stated error. */
    vt_rng r = {10};
    double worst_est = 0.0;
    for (int it = 0; it < 300; ++it) {
        float l = (float)log_uniform(&r, 1e-8, 1e8);
        mq p = {l};
        double ax[3] = {0, 0, 1};
        double want = sq_sphere(f_mean, &p, ax, l, 16, 2) / d_A(l);
        float got = vsgl_mean_length_from_sharpness(l, VSGL_SHARPNESS_BANERJEE);
        VT_CHECK_REL(got, want, 1e-6, "l=%.9g", l);
        VT_CHECK_REL(got, d_mean_length(l), 1e-6, "l=%.9g closed form", l);
        if (l < 1e6f) {
            double back = vsgl_sharpness_from_mean_length(got, VSGL_SHARPNESS_BANERJEE);
            double e = fabs(back - l) / l;
            worst_est = e > worst_est ? e : worst_est;
        }
    }
    VT_CHECK(worst_est < 0.06, "banerjee estimate of l from m(l): max rel err %g", worst_est);
    if (tables())
        printf("    banerjee(m(l)) vs l: max rel err %.3g for l in [1e-8, 1e6]\n", worst_est);
    VT_CHECK(vsgl_mean_length_from_sharpness(0.0f, 1) == 0.0f, "l=0");
    VT_CHECK(vsgl_mean_length_from_sharpness(1e30f, 1) <= 1.0f, "l=1e30");
    VT_CHECK(vsgl_mean_length_from_sharpness(1e30f, 0) <= 1.0f, "l=1e30 toksvig");
}

/* ------------------------------------------------- continuity at switches */

static double rel_jump(float a, float b)
{
    double d = fabs((double)a - (double)b), s = fmax(fabs((double)a), fabs((double)b));
    return s > 0 ? d / s : 0.0;
}

/* Value just below and just above a float threshold. */
#define JUMP_AT(expr_of_x, t, tol, what)                                                   \
    do {                                                                                    \
        float x_ = nextafterf((t), -INFINITY);                                              \
        float lo_ = (expr_of_x);                                                            \
        x_ = nextafterf((t), INFINITY);                                                     \
        float hi_ = (expr_of_x);                                                            \
        VT_CHECK(rel_jump(lo_, hi_) < (tol), "%s at %.9g: %.9g vs %.9g", what, (double)(t), lo_, hi_); \
    } while (0)

VT_TEST(sg_continuity_across_branches)
{
    /* Taylor <-> closed-form switches: mean length at 1, cosine at 0.5 and 1. */
    JUMP_AT(vsgl__sg_mean_length(x_), 1.0f, 1e-6, "mean length");
    for (int k = 0; k <= 20; ++k) {
        float c = -1.0f + 0.1f * (float)k;
        JUMP_AT(vsgl__sg_cosine_accurate(x_, c), 0.5f, 1e-5, "cosine accurate, l");
        JUMP_AT(vsgl__sg_cosine_accurate(x_, c), 1.0f, 1e-5, "cosine accurate, l");
    }
    /* l -> 0 limits */
    VT_CHECK(rel_jump(vsgl__sg_cosine_accurate(0.0f, 0.3f), vsgl__sg_cosine_accurate(1e-30f, 0.3f)) < 1e-6, "cosine l -> 0");
    VT_CHECK(rel_jump(vsgl_sg_integral(0.0f), vsgl_sg_integral(FLT_MIN)) < 1e-6, "A at 0");
    VT_CHECK(rel_jump(vsgl__sg_mean_length(FLT_MIN) + 1.0f, 1.0f) < 1e-6, "mean length at 0");
    /* the sharpness cap */
    JUMP_AT(vsgl_sg_integral(x_), VSGL_SHARPNESS_MAX, 1e-5, "A at the cap");
    JUMP_AT(vsgl_mean_length_from_sharpness(x_, 1), VSGL_SHARPNESS_MAX, 1e-6, "mean length at the cap");
    JUMP_AT(vsgl__sg_clamp_sharpness(x_), VSGL_SHARPNESS_MAX, 1e-6, "clamp at the cap");
    /* c = 0 (max(c, 0) branch) and the c < 0 horizon bound: sweep c finely;
     * the step must stay below the local slope bound |dI/dc| <= U(l)
     * (|d/dc integral of G max(w.n,0)| <= integral of G |w|) plus rounding. */
    for (int k = 0; k < 12; ++k) {
        float l = powf(10.0f, -3.0f + (float)k);
        float prev = vsgl__sg_cosine_accurate(l, -1.0f);
        int steps = quick() ? 4000 : 20000;
        for (int i = 1; i <= steps; ++i) {
            float c = -1.0f + 2.0f * (float)i / (float)steps;
            float v = vsgl__sg_cosine_accurate(l, c);
            double d = fabs((double)v - prev);
            VT_CHECK(d <= d_A(l) * (2.0 / steps) * 1.01 + 1e-6 * fabs(v), "sweep l=%g c=%g: %g -> %g", l, c, prev, v);
            prev = v;
        }
        JUMP_AT(vsgl__sg_cosine_accurate(l, x_), 0.0f, 1e-5, "cosine at c = 0");
    }
    /* the Iwasaki cap min(formula, bound): locate the switch by bisection */
    vsgl_sg a = {{0, 0, 1}, 1.0f, 0.0f}, b = {{0.6f, 0, 0.8f}, 1.0f, 0.0f};
    float lo = 1e-3f, hi = 1e3f;
    for (int i = 0; i < 60; ++i) {
        float mid = sqrtf(lo * hi);
        a.sharpness = b.sharpness = mid;
        double iw = vsgl_sg_product_integral_iwasaki(&a, &b);
        double s = 2.0 * mid, lr = 0.5 * mid;
        double formula = 2.0 * SQ_PI * exp(-lr * 0.2) / s;
        if (iw < formula * (1 - 1e-6))
            lo = mid;
        else
            hi = mid;
    }
    a.sharpness = b.sharpness = lo;
    float v1 = vsgl_sg_product_integral_iwasaki(&a, &b);
    a.sharpness = b.sharpness = nextafterf(hi, INFINITY);
    float v2 = vsgl_sg_product_integral_iwasaki(&a, &b);
    VT_CHECK(rel_jump(v1, v2) < 1e-5, "iwasaki cap switch near l=%g: %g vs %g", lo, v1, v2);
}

/* ---------------------------------------------------------------- extremes */

static float pick_sharpness(vt_rng *r)
{
    static const float special[] = {0.0f, 1e-30f, 1e-8f, 0.5f, 1e6f, 1e30f, INFINITY, -1.0f, NAN, VSGL_SHARPNESS_MAX, FLT_MIN};
    double u = vt_uniform(r);
    if (u < 0.3)
        return special[vt_next(r) % (sizeof special / sizeof special[0])];
    return (float)log_uniform(r, 1e-9, 1e13);
}

static vsgl_vec3 pick_axis(vt_rng *r, vsgl_vec3 other)
{
    double u = vt_uniform(r), d[3];
    if (u < 0.05) { vsgl_vec3 z = {0, 0, 0}; return z; }
    if (u < 0.08) { vsgl_vec3 z = {NAN, 0, 1}; return z; }
    if (u < 0.15) { vsgl_vec3 z = {-other.x, -other.y, -other.z}; return z; }
    if (u < 0.22) return other;
    if (u < 0.3) { vsgl_vec3 z = {other.x * 1e-20f, other.y * 1e-20f + 1e-30f, other.z * 1e20f}; return z; }
    rand_dir(r, d);
    if (u < 0.4) {
        /* nearly grazing to +Z */
        d[2] = 1e-6 * (vt_uniform(r) - 0.5);
    }
    return f3(d);
}

static float pick_log_amp(vt_rng *r)
{
    double u = vt_uniform(r);
    if (u < 0.05)
        return -INFINITY;
    return (float)(60.0 * vt_uniform(r) - 50.0);
}

static int ok_nonneg(float v) { return isfinite(v) && v >= 0.0f; }

VT_TEST(sg_extremes_never_nan_inf_or_negative)
{
    /* 10^6 draws per operator over sharpness {0, 1e-30, 1e-8, 1e6, 1e30,
     * inf, NaN, ...}, zero/NaN/antipodal/tiny/huge axes, -inf amplitudes. */
    vt_rng r = {11};
    int n = quick() ? 100000 : 1000000;
    vsgl_vec3 up = {0, 0, 1};
    for (int it = 0; it < n; ++it) {
        vsgl_sg a = {pick_axis(&r, up), pick_sharpness(&r), pick_log_amp(&r)};
        vsgl_sg b = {pick_axis(&r, a.axis), pick_sharpness(&r), pick_log_amp(&r)};
        vsgl_vec3 d = pick_axis(&r, a.axis);
        float v;
        v = vsgl_sg_eval(&a, &d);
        VT_CHECK(ok_nonneg(v), "eval l=%g ax=(%g,%g,%g) = %g", a.sharpness, a.axis.x, a.axis.y, a.axis.z, v);
        v = vsgl_sg_integral(a.sharpness);
        VT_CHECK(ok_nonneg(v) && v > 0.0f, "integral l=%g = %g", a.sharpness, v);
        v = vsgl_sg_lobe_integral(&a);
        VT_CHECK(ok_nonneg(v), "lobe integral l=%g la=%g = %g", a.sharpness, a.log_amplitude, v);
        vsgl_sg p;
        vsgl_sg_product(&a, &b, &p);
        VT_CHECK(isfinite(p.sharpness) && p.sharpness >= 0.0f && p.sharpness <= VSGL_SHARPNESS_MAX && !isnan(p.log_amplitude)
                 && p.log_amplitude < INFINITY && isfinite(p.axis.x) && isfinite(p.axis.y) && isfinite(p.axis.z),
                 "product l=%g,%g -> l=%g la=%g", a.sharpness, b.sharpness, p.sharpness, p.log_amplitude);
        v = vsgl_sg_product_integral(&a, &b);
        VT_CHECK(ok_nonneg(v), "product integral l=%g,%g = %g", a.sharpness, b.sharpness, v);
        v = vsgl_sg_product_integral_iwasaki(&a, &b);
        VT_CHECK(ok_nonneg(v), "iwasaki l=%g,%g = %g", a.sharpness, b.sharpness, v);
        for (int mode = 0; mode < 3; ++mode) {
            v = vsgl_sg_cosine_integral(&a, &d, mode);
            VT_CHECK(ok_nonneg(v), "cosine mode %d l=%g la=%g n=(%g,%g,%g) = %g", mode, a.sharpness, a.log_amplitude, d.x, d.y, d.z, v);
        }
        float m = (float)(vt_uniform(&r) * 1.2 - 0.1);
        if (it % 7 == 0)
            m = it % 2 ? NAN : 1.0f - 1e-7f * (float)vt_uniform(&r);
        for (int e = 0; e < 2; ++e) {
            v = vsgl_sharpness_from_mean_length(m, e);
            VT_CHECK(ok_nonneg(v) && v <= VSGL_SHARPNESS_MAX, "sharpness(r=%g, %d) = %g", m, e, v);
            v = vsgl_mean_length_from_sharpness(a.sharpness, e);
            VT_CHECK(ok_nonneg(v) && v <= 1.0f, "mean length(l=%g, %d) = %g", a.sharpness, e, v);
        }
    }
}
