/* The MRP paper's equations (csrc/src/mrp, docs/mrp.md), each against
 * double-precision quadrature of the quantity it approximates
 * (tools/asg_error_table.h's adaptive Gauss-Kronrod; independent of the
 * library), the degenerate cases the paper leaves open, and 10^6 seeded
 * extreme draws (10^5 with VSGL_TEST_QUICK=1). VSGL_TEST_TABLES=1 prints
 * the tables of docs/mrp.md:
 *
 *   make build/tests/vsgl_tests && VSGL_TEST_TABLES=1 build/tests/vsgl_tests mrp_ */
#include "harness.h"
#include "../../tools/asg_error_table.h"
#include "mrp/mrp.h"
#include "mrp/geom.h"
#include "math/asg_internal.h"

#include <stdlib.h>
#include <string.h>

static int tables(void) { return getenv("VSGL_TEST_TABLES") != NULL; }
static int quick(void)
{
    const char *q = getenv("VSGL_TEST_QUICK");
    return q && *q && strcmp(q, "0") != 0;
}

static d3 rand_dir(vt_rng *r)
{
    double z = 2.0 * vt_uniform(r) - 1.0, ph = 2.0 * AQ_PI * vt_uniform(r), s = sqrt(fmax(0.0, 1.0 - z * z));
    return d3_make(s * cos(ph), s * sin(ph), z);
}

static double ggx_d(double cos_h, double m)
{
    double m2 = m * m, c2 = cos_h * cos_h, den = m2 * c2 + (1.0 - c2);
    return m2 / (AQ_PI * den * den);
}

/* A unit-ish rectangle in the z = 0 plane facing +z. */
static vsgl__mrp_rect rect_xy(double half_u, double half_v)
{
    vsgl__mrp_rect rc;
    vsgl__mrp_rect_make(d3_make(0, 0, 0), d3_make(0, 0, 1), d3_make(1, 0, 0), half_u, half_v, &rc);
    return rc;
}

/* geom.h's inline d_max / d_min: libm's fmax / fmin for every pair of
 * special and random values (NaN gives the other argument; equal values
 * compare equal, zeros of either sign included). */
VT_TEST(mrp_inline_fmax_fmin_are_libms)
{
    const double sp[9] = {0.0, -0.0, 1.0, -1.0, 1e-310, -3.5e300, INFINITY, -INFINITY, NAN};
    vt_rng r = {1416u};
    for (int t = 0; t < 20000; ++t) {
        double a = t < 81 ? sp[t % 9] : (vt_uniform(&r) - 0.5) * 1e3;
        double b = t < 81 ? sp[t / 9] : (t % 5 == 0 ? a : (vt_uniform(&r) - 0.5) * 1e3);
        double m[4] = {d_max(a, b), fmax(a, b), d_min(a, b), fmin(a, b)};
        for (int k = 0; k < 4; k += 2)
            VT_CHECK((isnan(m[k]) && isnan(m[k + 1])) || m[k] == m[k + 1], "%s(%g, %g): %g vs libm %g",
                     k ? "min" : "max", a, b, m[k], m[k + 1]);
    }
}

/* ---------------------------------------------------------------- Eq. 12 */

VT_TEST(mrp_peak_eq12_is_the_mirror_point)
{
    vt_rng r = {12};
    int checked = 0;
    for (int it = 0; it < 20000; ++it) {
        vsgl__mrp_rect rc;
        d3 c = d3_make(20 * vt_uniform(&r) - 10, 20 * vt_uniform(&r) - 10, 20 * vt_uniform(&r) - 10);
        vsgl__mrp_rect_make(c, rand_dir(&r), rand_dir(&r), 1.0, 0.5, &rc);
        d3 x = d3_add(c, d3_scale(rand_dir(&r), 5.0 * vt_uniform(&r)));
        d3 i = rand_dir(&r), y;
        d3 rr = vsgl__mrp_reflect(i, rc.normal);
        double h = d3_dot(d3_sub(x, c), rc.normal), in = d3_dot(i, rc.normal);
        int ok = vsgl__mrp_peak(&rc, x, rr, &y);
        VT_CHECK(ok == (h > 0.0 && in > 0.0), "ok %d h %g i.n %g", ok, h, in);
        if (!ok || in < 1e-3)
            continue;
        ++checked;
        /* on the plane, and the half vector of (i, y->x) is the normal */
        double off = d3_dot(d3_sub(y, c), rc.normal);
        d3 w = d3_normalize(d3_sub(x, y)), hv = d3_normalize(d3_add(i, w));
        VT_CHECK(fabs(off) <= 1e-9 * (1.0 + d3_length(d3_sub(y, c))), "plane offset %g", off);
        VT_CHECK(d3_dot(hv, rc.normal) > 1.0 - 1e-9, "h.n %.15g (i.n %g)", d3_dot(hv, rc.normal), in);
    }
    VT_CHECK(checked > 4000, "%d", checked);
}

VT_TEST(mrp_peak_degenerate_cases)
{
    vsgl__mrp_rect rc = rect_xy(1, 1);
    d3 y, i = d3_normalize(d3_make(0.3, 0.2, 1.0));
    /* on the plane, behind it, light behind, light in the plane */
    VT_CHECK(!vsgl__mrp_peak(&rc, d3_make(0.2, 0, 0), vsgl__mrp_reflect(i, rc.normal), &y), "on");
    VT_CHECK(!vsgl__mrp_peak(&rc, d3_make(0.2, 0, -1), vsgl__mrp_reflect(i, rc.normal), &y), "behind");
    VT_CHECK(!vsgl__mrp_peak(&rc, d3_make(0, 0, 1), d3_make(0, 0, -1), &y), "i.n < 0");
    VT_CHECK(!vsgl__mrp_peak(&rc, d3_make(0, 0, 1), d3_make(1, 0, 0), &y), "i.n = 0");
    /* grazing: finite or refused, never inf */
    int ok = vsgl__mrp_peak(&rc, d3_make(0, 0, 1), d3_normalize(d3_make(1, 0, 1e-300)), &y);
    VT_CHECK(!ok || d3_finite(y), "grazing");
    ok = vsgl__mrp_peak(&rc, d3_make(0, 0, 1e300), d3_normalize(d3_make(1, 0, 1e-10)), &y);
    VT_CHECK(!ok && d3_finite(y), "grazing far: overflow refused");
}

/* ----------------------------------------------------------- Eq. 24, 25 */

VT_TEST(mrp_psi_eq24_against_the_exact_half_vector_angle)
{
    /* In the plane of incidence the half vector at the disk point seen at
     * angle theta from x turns by exactly theta/2; Eq. 24 agrees to first
     * order (its d ~ tan(theta)/cos(sigma) is the small-theta distance). */
    double worst[3] = {0, 0, 0};
    const double sigmas[3] = {0.0, AQ_PI / 6, 2 * AQ_PI / 5};
    for (int s = 0; s < 3; ++s)
        for (int k = 1; k <= 300; ++k) {
            double th = k * (AQ_PI / 6) / 300; /* up to 30 degrees */
            double e = fabs(vsgl__mrp_psi(th, sigmas[s]) - 0.5 * th);
            worst[s] = fmax(worst[s], e / th);
            if (th < 0.01)
                VT_CHECK(e <= 0.02 * th * (1.0 + tan(sigmas[s])), "theta %g sigma %g: %g", th, sigmas[s], e);
        }
    if (tables())
        printf("    Eq. 24 vs exact theta/2, theta <= 30 deg: max |err|/theta = %.3f (sigma 0), %.3f (30 deg), "
               "%.3f (72 deg)\n", worst[0], worst[1], worst[2]);
    VT_CHECK(worst[0] < 0.06, "sigma 0: %g", worst[0]);
}

/* Least-squares k of exp(-k sin^2) cos against Eq. 23 (weight sin theta),
 * as tools/mrp_fit_k.py computes it. */
static double fit_err(double k, double sigma, double m)
{
    double s = 0.0;
    for (int j = 0; j < 2000; ++j) {
        double th = (j + 0.5) * (AQ_PI / 2) / 2000, d = vsgl__mrp_f_fit(th, k) - vsgl__mrp_f_ggx(th, sigma, m);
        s += sin(th) * d * d;
    }
    return s;
}

static double best_k(double sigma, double m)
{
    double lo = -20.0, hi = 2000.0;
    for (int it = 0; it < 200; ++it) {
        double a = hi - 0.618 * (hi - lo), b = lo + 0.618 * (hi - lo);
        if (fit_err(a, sigma, m) < fit_err(b, sigma, m))
            hi = b;
        else
            lo = a;
    }
    return 0.5 * (lo + hi);
}

VT_TEST(mrp_fit_eq25_error_like_fig4)
{
    /* The paper's Fig. 4 configurations. Eq. 25 with the printed k against
     * Eq. 23 (with Eq. 24): max abs error over theta in [0, 90) degrees and
     * over the region that matters (f > 0.05). A wrong k (e.g. 1/m^2) fails
     * the first configuration's bound. */
    const double cfg[4][2] = {{AQ_PI / 6, 0.1}, {2 * AQ_PI / 5, 0.1}, {AQ_PI / 6, 0.7}, {2 * AQ_PI / 5, 0.7}};
    if (tables())
        printf("    | sigma | m | k (Eq. 25) | k least squares | max |err| | max |err| where f > 0.05 |\n");
    for (int c = 0; c < 4; ++c) {
        double s = cfg[c][0], m = cfg[c][1], k = vsgl__mrp_k(cos(s), m), e_all = 0.0, e_sig = 0.0;
        for (int j = 0; j < 4000; ++j) {
            double th = j * (AQ_PI / 2) / 4000, f = vsgl__mrp_f_ggx(th, s, m);
            double e = fabs(vsgl__mrp_f_fit(th, k) - f);
            e_all = fmax(e_all, e);
            if (f > 0.05)
                e_sig = fmax(e_sig, e);
        }
        double kb = best_k(s, m);
        if (tables())
            printf("    | %.0f deg | %.1f | %.3f | %.3f | %.3f | %.3f |\n", s * 180 / AQ_PI, m, k, kb, e_all, e_sig);
        if (c == 0) {
            VT_CHECK(e_sig < 0.13, "sigma 30 m 0.1: %g", e_sig);
            VT_CHECK(fabs(k - kb) < 0.1 * kb, "printed k %g vs least squares %g", k, kb);
            double wrong = 0.0;
            for (int j = 0; j < 4000; ++j) {
                double th = j * (AQ_PI / 2) / 4000, f = vsgl__mrp_f_ggx(th, s, m);
                if (f > 0.05)
                    wrong = fmax(wrong, fabs(vsgl__mrp_f_fit(th, 1.0 / (m * m)) - f));
            }
            VT_CHECK(wrong > 0.13, "a wrong k passes: %g", wrong);
        }
    }
    /* k <= 0 where the printed formula says so */
    VT_CHECK(vsgl__mrp_k(1.0, 0.7) < 0.0 && vsgl__mrp_k(0.05, 0.2) < 0.0 && vsgl__mrp_k(1.0, 0.3) > 0.0, "signs");
}

/* ------------------------------------------------------------ Eq. 26, 27 */

typedef struct cap_args { double k; } cap_args;
static double cap_fn(double th, void *u)
{
    const cap_args *a = u;
    return 2.0 * AQ_PI * vsgl__mrp_f_fit(th, a->k) * sin(th);
}

VT_TEST(mrp_disk_integral_eq26_closed_form_is_the_cap_integral)
{
    const double ks[] = {1e-12, 1e-6, 0.01, 1.0, 10.0, 300.0, 1e5};
    const double ls[] = {1e-4, 0.1, 0.5, 1.0, 3.0, 100.0};
    for (size_t a = 0; a < sizeof ks / sizeof ks[0]; ++a)
        for (size_t b = 0; b < sizeof ls / sizeof ls[0]; ++b) {
            double t = vsgl__mrp_cap_t(ls[b], 0.8), alpha = asin(sqrt(t));
            cap_args ca = {ks[a]};
            double ref = aq_integrate(cap_fn, &ca, 0.0, alpha, 16, 1e-15, 1e-12);
            double got = vsgl__mrp_disk_integral(ks[a], t);
            VT_CHECK_REL(got, ref, 1e-7, "k %g l %g", ks[a], ls[b]);
        }
    /* k <= 0 is clamped to 0: f = cos(theta), E = pi t; never above it */
    double t = vsgl__mrp_cap_t(1.0, 1.0);
    VT_CHECK_REL(vsgl__mrp_disk_integral(-5.0, t), AQ_PI * t, 1e-12, "k < 0");
    VT_CHECK_REL(vsgl__mrp_disk_integral(0.0, t), AQ_PI * t, 1e-12, "k = 0");
    VT_CHECK(vsgl__mrp_disk_integral(-1e300, t) <= AQ_PI * t, "k -> -inf");
    VT_CHECK(vsgl__mrp_disk_integral(1e300, t) >= 0.0 && vsgl__mrp_disk_integral(INFINITY, t) == 0.0, "k inf");
    /* t from Eq. 27 = sin^2 atan(l cos sigma) */
    for (double l = 1e-3; l < 1e3; l *= 3.7)
        VT_CHECK_REL(vsgl__mrp_cap_t(l, 0.6), pow(sin(atan(l * 0.6)), 2), 1e-12, "l %g", l);
}

/* The quantity Eq. 27 approximates (per unit L_y, A = 1): the solid-angle
 * integral over the real tilted disk of radius l (distance 1) around the
 * peak of D(h(y'))/D(n_r), the GGX reflector lit by a distant light. */
typedef struct disk_q { d3 x, i; double m, l, rho; } disk_q;
static double disk_phi(double ph, void *u)
{
    disk_q *q = u;
    d3 p = d3_make(q->rho * cos(ph), q->rho * sin(ph), 0.0), w = d3_sub(q->x, p);
    double d2 = d3_dot(w, w), dl = sqrt(d2);
    w = d3_scale(w, 1.0 / dl);
    d3 h = d3_normalize(d3_add(q->i, w));
    return ggx_d(h.z, q->m) / ggx_d(1.0, q->m) * w.z / d2 * q->rho;
}
static double disk_rho(double rho, void *u)
{
    disk_q *q = u;
    q->rho = rho;
    return aq_integrate(disk_phi, q, 0.0, 2.0 * AQ_PI, 8, 1e-13, 1e-9);
}
static double disk_reference(double sigma, double m, double l)
{
    disk_q q;
    q.x = d3_make(sin(sigma), 0.0, cos(sigma)); /* |x - y| = 1, y at the origin */
    q.i = d3_make(-sin(sigma), 0.0, cos(sigma));
    q.m = m;
    q.l = l;
    double sum = 0.0, lo = 0.0;
    for (double hi = fmin(l, m * 0.05); lo < l; hi = fmin(l, 2.0 * hi)) {
        sum += aq_integrate(disk_rho, &q, lo, hi, 2, 1e-12, 1e-8);
        lo = hi;
    }
    return sum;
}

VT_TEST(mrp_disk_eq27_against_quadrature_over_the_disk)
{
    /* Rows: sigma, m; columns: l = r_d / |x - y|. The paper's Eq. 27 with
     * the printed k (k <= 0 clamped), A = 1, against the exact integral. */
    const double sig[] = {0.0, AQ_PI / 6, AQ_PI / 3, 2 * AQ_PI / 5};
    const double ms[] = {0.1, 0.2, 0.3, 0.5};
    const double ls[] = {0.05, 0.2, 0.5, 1.0};
    if (tables())
        printf("    Eq. 27 relative error, columns l = r_d/|x-y| = 0.05, 0.2, 0.5, 1\n");
    double worst_small = 0.0;
    for (int s = 0; s < 4; ++s)
        for (int mi = 0; mi < 4; ++mi) {
            if (tables())
                printf("    | sigma %2.0f | m %.1f |", sig[s] * 180 / AQ_PI, ms[mi]);
            for (int li = 0; li < 4; ++li) {
                double ref = disk_reference(sig[s], ms[mi], ls[li]);
                double cs = cos(sig[s]);
                double got = vsgl__mrp_disk_radiance(1.0, vsgl__mrp_k(cs, ms[mi]), vsgl__mrp_cap_t(ls[li], cs), 1.0);
                double e = (got - ref) / ref;
                VT_CHECK(isfinite(got) && got > 0.0, "got %g", got);
                if (s <= 1 && ls[li] <= 0.5)
                    worst_small = fmax(worst_small, fabs(e));
                if (tables())
                    printf(" %+6.1f %% |", 100 * e);
            }
            if (tables())
                printf("\n");
        }
    if (tables())
        printf("    worst |err|, sigma <= 30 deg, l <= 0.5: %.1f %%\n", 100 * worst_small);
    /* measured up to 38 % in this region (docs/mrp.md); a factor 2 or a
     * missing pi in Eq. 27 exceeds the bound */
    VT_CHECK(worst_small < 0.40, "%g", worst_small);
}

/* ---------------------------------------------------------------- Eq. 36 */

typedef struct ov_q { double cu, cv, r, a, b; } ov_q;
/* chord(x) dx with x = cu + r sin(phi): no square-root end points */
static double chord(double phi, void *u)
{
    const ov_q *q = u;
    double dx = q->r * sin(phi);
    if (fabs(dx) >= q->r)
        return 0.0;
    double s = sqrt(q->r * q->r - dx * dx);
    double top = fmin(q->b, q->cv + s), bot = fmax(-q->b, q->cv - s);
    return top > bot ? (top - bot) * q->r * cos(phi) : 0.0;
}

VT_TEST(mrp_overlap_eq36_and_exact_against_quadrature)
{
    vt_rng r = {36};
    double worst_bbox = 0.0, worst_exact = 0.0;
    for (int it = 0; it < 3000; ++it) {
        double a = pow(10.0, 2 * vt_uniform(&r) - 1), b = pow(10.0, 2 * vt_uniform(&r) - 1);
        double rd = pow(10.0, 2 * vt_uniform(&r) - 1);
        double cu = (2 * vt_uniform(&r) - 1) * (a + rd), cv = (2 * vt_uniform(&r) - 1) * (b + rd);
        vsgl__mrp_rect rc = rect_xy(a, b);
        d3 y = d3_make(cu, cv, 0.0);
        ov_q q = {cu, cv, rd, a, b};
        double p0 = asin(fmax(-1.0, fmin(1.0, (-a - cu) / rd))), p1 = asin(fmax(-1.0, fmin(1.0, (a - cu) / rd)));
        double ref = p1 > p0 ? aq_integrate(chord, &q, p0, p1, 64, 1e-13 * rd * rd, 1e-11) / (AQ_PI * rd * rd) : 0.0;
        double ex = vsgl__mrp_overlap_exact(&rc, y, rd), bb = vsgl__mrp_overlap_bbox(&rc, y, rd);
        VT_CHECK_ABS(ex, ref, 1e-7, "a %g b %g r %g c %g %g", a, b, rd, cu, cv);
        VT_CHECK(bb >= ex - 1e-12 && bb <= 4.0 / AQ_PI + 1e-12, "bbox %g exact %g", bb, ex);
        worst_exact = fmax(worst_exact, fabs(ex - ref));
        if (ref > 0.01)
            worst_bbox = fmax(worst_bbox, bb / ref - 1.0);
    }
    /* wholly inside: exact 1, Eq. 36 4/pi; wholly outside: 0 */
    vsgl__mrp_rect rc = rect_xy(2, 2);
    VT_CHECK_REL(vsgl__mrp_overlap_exact(&rc, d3_make(0.1, 0, 0), 0.5), 1.0, 1e-12, "inside");
    VT_CHECK_REL(vsgl__mrp_overlap_bbox(&rc, d3_make(0.1, 0, 0), 0.5), 4.0 / AQ_PI, 1e-12, "inside");
    VT_CHECK(vsgl__mrp_overlap_exact(&rc, d3_make(3, 0, 0), 0.5) == 0.0, "outside");
    VT_CHECK(vsgl__mrp_overlap_bbox(&rc, d3_make(2.4, 2.4, 0), 0.5) == 0.0, "outside the corner");
    /* a disk much larger than the rectangle: area ratio */
    VT_CHECK_REL(vsgl__mrp_overlap_exact(&rc, d3_make(0, 0, 0), 100.0), 16.0 / (AQ_PI * 1e4), 1e-9, "huge disk");
    VT_CHECK_REL(vsgl__mrp_overlap_bbox(&rc, d3_make(0, 0, 0), 100.0), 16.0 / (AQ_PI * 1e4), 1e-9, "huge disk");
    if (tables())
        printf("    overlap: exact max abs err %.2g; Eq. 36 (bbox) over-estimates by up to %.1f %% (4/pi - 1 = 27.3 %%)\n",
               worst_exact, 100 * worst_bbox);
}

/* ------------------------------------------------------------ Eq. 28-35 */

VT_TEST(mrp_bandwidth_eq32_solves_eq31)
{
    for (double l = 1e-3; l < 19.9; l *= 1.2) {
        double lam = vsgl__mrp_bandwidth(l), th = atan(l);
        /* Gp(arctan l, pi/2 - arctan l, pi/2) = cos(theta) e^{-lambda cos^2(pi/2 - theta)} */
        double g = cos(th) * exp(-lam * sin(th) * sin(th));
        VT_CHECK_REL(g, 0.05, 3e-4, "l %g lambda %g", l, lam); /* 2.996 is ln 20 = 2.99573 rounded */
    }
    VT_CHECK(vsgl__mrp_bandwidth(25.0) == 0.0 && vsgl__mrp_bandwidth(INFINITY) == 0.0, "huge disk");
    VT_CHECK(vsgl__mrp_bandwidth(0.0) == VSGL_SHARPNESS_MAX && vsgl__mrp_bandwidth(1e-30) == VSGL_SHARPNESS_MAX,
             "point disk");
    VT_CHECK(vsgl__mrp_bandwidth(NAN) == VSGL_SHARPNESS_MAX, "nan: a point");
}

typedef struct asg_q { aq_asg a; } asg_q;
static double asg_fn(const double v[3], void *u) { return aq_asg_eval(&((asg_q *)u)->a, v); }
static aq_asg to_aq(const vsgl_asg *a)
{
    vsgl__frame f;
    vsgl__asg_frame(a, &f);
    aq_asg q;
    memcpy(q.x, f.x, sizeof q.x);
    memcpy(q.y, f.y, sizeof q.y);
    memcpy(q.z, f.z, sizeof q.z);
    q.lam = a->lambda;
    q.mu = a->mu;
    q.logc = a->log_amplitude;
    return q;
}

/* The MRP pass's unit ASG integral (polynomial Bessel in Eq. 10's second
 * term, none where it cannot change the double) against the library's:
 * within 1e-9 everywhere, the same double once min >= 40 and max <= 100 min. */
VT_TEST(mrp_asg_integral_unit_matches_the_library)
{
    vt_rng r = {1414u};
    double worst = 0.0;
    int same = 0, big = 0;
    for (int i = 0; i < 200000; ++i) {
        double lo = exp(log(1e-3) + (log(1e7) - log(1e-3)) * vt_uniform(&r));
        double hi = lo * exp(log(1e6) * vt_uniform(&r));
        if (i % 7 == 0)
            hi = lo; /* isotropic */
        double a = vsgl__mrp_asg_integral_unit(hi, lo), b = vsgl__asg_integral_unit(hi, lo);
        double c = vsgl__mrp_asg_integral_unit(lo, hi); /* either order */
        VT_CHECK(a == c, "order: %.17g %.17g (%g, %g)", a, c, hi, lo);
        double e = fabs(a - b) / b;
        worst = e > worst ? e : worst;
        VT_CHECK(e <= 1e-9, "lambda %g mu %g: %.17g against %.17g (%g)", hi, lo, a, b, e);
        if (lo >= 40.0 && hi <= 100.0 * lo) {
            ++big;
            same += a == b;
        }
    }
    VT_CHECK(big > 1000 && same == big, "bit-identical for large bandwidths: %d of %d", same, big);
    /* the ends: NaN stays NaN, 0 and infinite bandwidths as the library */
    VT_CHECK(isnan(vsgl__mrp_asg_integral_unit(NAN, 20.0)), "NaN");
    VT_CHECK(vsgl__mrp_asg_integral_unit(0.0, 0.0) == vsgl__asg_integral_unit(0.0, 0.0), "0, 0");
    double ai = vsgl__mrp_asg_integral_unit(INFINITY, 20.0), bi = vsgl__asg_integral_unit(INFINITY, 20.0);
    VT_CHECK(ai == bi || (isnan(ai) && isnan(bi)), "inf: %g %g", ai, bi);
    if (tables())
        printf("mrp unit ASG integral against the library's: worst relative difference %.3g\n", worst);
}

/* The receiver's lobe terms through the double-precision ASG product
 * (product_integral in glossy.c: the frames the receiver and the light
 * already hold) against the library's float vsgl_asg_product (the same
 * receiver without its double frames): within 1e-3 relative, 0 alike. The
 * float path is the less precise one: its bandwidths (up to ~1e4 in the
 * summed form's eigenvalues) and log amplitude rounded to float move the
 * exponent by up to ~1e-4 (the worst differences are on terms of 1e-9 and
 * below); the quality scenes' glossy planes moved by relMSE <= 1.1e-15. */
VT_TEST(mrp_lobe_terms_double_product_matches_the_float_one)
{
    vt_rng r = {1415u};
    const vsgl__mrp_options opt = vsgl__mrp_options_default();
    double worst = 0.0;
    int nonzero = 0;
    for (int t = 0; t < 20000; ++t) {
        vsgl__mrp_rect rc = rect_xy(0.05 + 2.0 * vt_uniform(&r), 0.05 + 2.0 * vt_uniform(&r));
        d3 x = d3_make(4.0 * vt_uniform(&r) - 2.0, 4.0 * vt_uniform(&r) - 2.0, 0.02 + 3.0 * vt_uniform(&r));
        d3 n = rand_dir(&r), o = rand_dir(&r);
        if (d3_dot(o, n) < 0.0)
            o = d3_scale(o, -1.0);
        double alpha = 0.05 + 0.45 * vt_uniform(&r);
        vsgl__mrp_receiver a, b;
        vsgl__mrp_receiver_make(n, o, alpha, &opt, &a);
        b = a;
        b.framed[0] = b.framed[1] = 0; /* the float path */
        VT_CHECK(a.framed[0] && a.framed[1], "draw %d: no double frame", t);
        double va[2], vb[2];
        d3 xa[2], xb[2];
        vsgl__mrp_glossy_parts_at(&rc, x, &a, &opt, 0u, va, xa);
        vsgl__mrp_glossy_parts_at(&rc, x, &b, &opt, 0u, vb, xb);
        for (int q = 0; q < 2; ++q) {
            VT_CHECK((va[q] > 0.0) == (vb[q] > 0.0) || fabs(va[q] - vb[q]) <= 1e-30, "draw %d part %d: %g vs %g", t,
                     q, va[q], vb[q]);
            if (vb[q] > 1e-30) {
                double e = fabs(va[q] - vb[q]) / vb[q];
                worst = e > worst ? e : worst;
                ++nonzero;
                VT_CHECK(e <= 1e-3, "draw %d part %d: %.9g vs %.9g (%g)", t, q, va[q], vb[q], e);
            }
        }
    }
    VT_CHECK(nonzero > 5000, "only %d terms above 0", nonzero);
    if (tables())
        printf("mrp lobe terms, double ASG product against the float one: worst relative difference %.3g (%d terms)\n",
               worst, nonzero);
}

VT_TEST(mrp_asg_light_eq35_keeps_the_energy)
{
    /* integral of the ASG light over the sphere = C: exactly with the exact
     * normalisation, within Eq. 34's error with the paper's */
    const double sig[] = {0.0, 0.5, 1.2, 1.5};
    const double ls[] = {0.01, 0.1, 0.5, 1.0, 3.0};
    double worst_paper = 0.0;
    for (int s = 0; s < 4; ++s)
        for (int li = 0; li < 5; ++li) {
            d3 y = d3_make(0, 0, 0), n = d3_make(0, 0, 1), x = d3_make(2 * sin(sig[s]), 0, 2 * cos(sig[s]));
            double C = 0.37;
            vsgl_asg a;
            for (int norm = 0; norm < 2; ++norm) {
                VT_REQUIRE(vsgl__mrp_asg_light(x, y, n, 2.0 * ls[li], C, norm, &a), "sigma %g l %g", sig[s], ls[li]);
                asg_q q = {to_aq(&a)};
                double w = 1.0 / sqrt(fmax(1.0, fmin(q.a.lam, q.a.mu)));
                double I = aq_sphere(asg_fn, &q, q.a.z, w, 1e-9, 1e-9);
                if (norm == VSGL__MRP_NORM_EXACT)
                    VT_CHECK_REL(I, C, 2e-6, "sigma %g l %g lam %g mu %g", sig[s], ls[li], a.lambda, a.mu);
                else
                    worst_paper = fmax(worst_paper, fabs(I / C - 1.0));
            }
            /* frame: z towards the disk, x across the plane of incidence */
            VT_CHECK(fabs(a.z.z + (float)cos(sig[s])) < 1e-6, "z %g", a.z.z);
            if (sig[s] > 0.0)
                VT_CHECK(fabs(a.x.y) > 0.999f, "x %g %g %g", a.x.x, a.x.y, a.x.z);
        }
    if (tables())
        printf("    Eq. 34-35 (paper normalisation): energy off by up to %.1f %% for l in [0.01, 3]\n", 100 * worst_paper);
}

VT_TEST(mrp_asg_light_reaches_epsilon_at_the_disk_edge)
{
    /* Eq. 29-32's intent: the ASG is 0.05 of its peak at the projected
     * disk's edge; exact across the plane of incidence (m), within the
     * small-disk approximation along it (n, foreshortened by cos sigma). */
    const double sig[] = {0.0, 0.6, 1.2};
    for (int s = 0; s < 3; ++s)
        for (double l = 0.02; l < 1.0; l *= 2.0) {
            d3 y = d3_make(0, 0, 0), n = d3_make(0, 0, 1), x = d3_make(sin(sig[s]), 0, cos(sig[s]));
            vsgl_asg a;
            VT_REQUIRE(vsgl__mrp_asg_light(x, y, n, l, 1.0, VSGL__MRP_NORM_EXACT, &a), "l %g", l);
            a.log_amplitude = 0.0f;
            vsgl_vec3 e_m = d3_to_v3(d3_sub(d3_make(0, l, 0), x));  /* across */
            vsgl_vec3 e_n = d3_to_v3(d3_sub(d3_make(-l, 0, 0), x)); /* along (far side) */
            vsgl_vec3 e_n2 = d3_to_v3(d3_sub(d3_make(l, 0, 0), x)); /* along (near side) */
            double gm = vsgl_asg_eval(&a, &e_m), gn = 0.5 * (vsgl_asg_eval(&a, &e_n) + vsgl_asg_eval(&a, &e_n2));
            VT_CHECK_REL(gm, 0.05, 1e-3, "across: sigma %g l %g", sig[s], l);
            if (l < 0.1)
                VT_CHECK_REL(gn, 0.05, 0.2, "along: sigma %g l %g", sig[s], l);
            if (tables())
                printf("    edge value (want 0.05): sigma %.1f l %.2f: across %.4f, along %.4f\n", sig[s], l, gm, gn);
        }
}

/* ---------------------------------------------------------- Eq. 11, 37 */

typedef struct prod_q { aq_asg a; double p[3], lsg; } prod_q;
static double prod_fn(const double v[3], void *u)
{
    const prod_q *q = u;
    double c = v[0] * q->p[0] + v[1] * q->p[1] + v[2] * q->p[2];
    return aq_asg_eval(&q->a, v) * exp(q->lsg * (c - 1.0));
}

static double product_reference(const vsgl_asg *a, const vsgl_sg *g)
{
    prod_q q;
    q.a = to_aq(a);
    q.p[0] = g->axis.x, q.p[1] = g->axis.y, q.p[2] = g->axis.z;
    q.lsg = g->sharpness;
    double w = 1.0 / sqrt(fmax(1.0, fmin(fmin(q.a.lam, q.a.mu), g->sharpness)));
    return exp(g->log_amplitude) * aq_sphere(prod_fn, &q, q.a.z, w, 1e-10, 1e-9);
}

/* An ASG around +z (x = +x) and an SG whose axis is tilted by `off` times
 * the pair's combined width towards (cos b, sin b, 0). */
static void eq11_pair(double lam, double mu, double sgs, double off, double b, vsgl_asg *a, vsgl_sg *g)
{
    a->x = v3_make(1, 0, 0);
    a->y = v3_make(0, 1, 0);
    a->z = v3_make(0, 0, 1);
    a->lambda = (float)lam;
    a->mu = (float)mu;
    a->log_amplitude = 0.0f;
    double nu = 0.5 * sgs, t = off * sqrt(1.0 / fmin(lam, mu) + 1.0 / nu);
    t = fmin(t, 1.2);
    g->axis = v3_make((float)(sin(t) * cos(b)), (float)(sin(t) * sin(b)), (float)cos(t));
    g->sharpness = (float)sgs;
    g->log_amplitude = 0.0f;
}

VT_TEST(mrp_convolution_eq11_failure_region)
{
    /* Error of Eq. 11 (convolution at the SG's axis, pi / sqrt normalisation)
     * against quadrature of the ASG x SG product, relative to the on-axis
     * exact value, worst over axis offsets 0, 0.5, 1, 2 combined widths and
     * two azimuths. Rows: ASG bandwidth (mu = lambda and mu = lambda / 4);
     * columns: the receiver SG sharpness of roughness 0.1 (alpha 0.01:
     * 2/(4 alpha^2) = 5000), 0.2 (313), 0.3 (62) and broad lobes (10, 2). */
    const double lams[] = {2, 5, 10, 20, 50, 100, 300, 1000};
    const double sgs[] = {5000, 312.5, 61.7, 10, 2};
    const double offs[] = {0.0, 0.5, 1.0, 2.0};
    double worst_ge50 = 0.0, worst_lt50 = 0.0, worst_broad = 0.0;
    if (tables())
        printf("    Eq. 11 error | SG sharpness 5000, 313, 62, 10, 2\n");
    for (int an = 0; an < 2; ++an)
        for (size_t li = 0; li < sizeof lams / sizeof lams[0]; ++li) {
            double lam = lams[li], mu = an ? lam / 4 : lam;
            if (tables())
                printf("    | lambda %5.0f mu %6.1f |", lam, mu);
            for (size_t si = 0; si < sizeof sgs / sizeof sgs[0]; ++si) {
                double worst = 0.0, peak = 0.0;
                for (size_t oi = 0; oi < 4; ++oi)
                    for (int bi = 0; bi < 2; ++bi) {
                        vsgl_asg a;
                        vsgl_sg g;
                        eq11_pair(lam, mu, sgs[si], offs[oi], bi * AQ_PI / 2, &a, &g);
                        double ref = product_reference(&a, &g), got = vsgl__mrp_convolve(&a, &g);
                        if (oi == 0 && bi == 0)
                            peak = ref;
                        worst = fmax(worst, fabs(got - ref) / peak);
                    }
                if (sgs[si] >= 60) { /* receivers of roughness <= 0.3 */
                    if (fmin(lam, mu) >= 50)
                        worst_ge50 = fmax(worst_ge50, worst);
                    else
                        worst_lt50 = fmax(worst_lt50, worst);
                } else {
                    worst_broad = fmax(worst_broad, worst);
                }
                if (tables())
                    printf(" %7.2f %% |", 100 * worst);
            }
            if (tables())
                printf("\n");
        }
    if (tables())
        printf("    worst, receiver SG sharpness >= 62: ASG min(lambda, mu) >= 50: %.2f %%, < 50: %.2f %%; "
               "receiver sharpness 2-10: %.1f %%\n", 100 * worst_ge50, 100 * worst_lt50, 100 * worst_broad);
    /* The error follows the sum of the bandwidths: receivers of roughness
     * <= 0.3 keep Eq. 11 within 2 % for every ASG bandwidth (measured
     * 1.5 %); the paper's failure region needs a broad receiver too. */
    VT_CHECK(worst_ge50 < 0.01 && worst_lt50 < 0.02, "%g %g", worst_ge50, worst_lt50);
    VT_CHECK(worst_broad > 0.1, "%g", worst_broad);
}

VT_TEST(mrp_sg_only_eq37_against_the_asg_product)
{
    /* Eq. 37: the ASG light as one SG and Iwasaki's product integral,
     * against the quadrature of ASG x SG on axis. As printed (sharpness
     * 2 max(lambda, mu), amplitude kept) the peak is kept and the energy
     * falls to sqrt(min/max); the geometric-mean variant (2 sqrt(lambda mu),
     * energy kept) keeps both for large bandwidths. */
    const double lams[] = {5, 20, 50, 200, 1000};
    const double ratios[] = {1.0, 0.5, 0.25};
    const double sgs[] = {5000, 312.5, 61.7};
    double worst_iso = 0.0, worst_printed = 0.0, worst_mean = 0.0;
    for (size_t li = 0; li < 5; ++li)
        for (size_t ri = 0; ri < 3; ++ri)
            for (size_t si = 0; si < 3; ++si) {
                vsgl_asg a;
                vsgl_sg g, s_printed, s_mean;
                eq11_pair(lams[li], lams[li] * ratios[ri], sgs[si], 0.0, 0.0, &a, &g);
                double ref = product_reference(&a, &g);
                vsgl__mrp_asg_to_sg(&a, 0, &s_printed);
                vsgl__mrp_asg_to_sg(&a, 1, &s_mean);
                double e0 = fabs(vsgl__mrp_convolve_sg(&s_printed, &g) / ref - 1.0);
                double e1 = fabs(vsgl__mrp_convolve_sg(&s_mean, &g) / ref - 1.0);
                if (ratios[ri] == 1.0) {
                    worst_iso = fmax(worst_iso, fmax(e0, e1));
                    if (lams[li] >= 50)
                        VT_CHECK(e0 < 0.03 && e1 < 0.03, "lambda %g sg %g: %g %g", lams[li], sgs[si], e0, e1);
                } else {
                    worst_printed = fmax(worst_printed, e0);
                    worst_mean = fmax(worst_mean, e1);
                }
                if (lams[li] >= 50) /* the printed form's energy: sqrt(min/max) of the ASG's */
                    VT_CHECK_REL(exp(s_printed.log_amplitude) * vsgl_sg_integral(s_printed.sharpness),
                                 sqrt(ratios[ri]) * vsgl_asg_integral(&a), 0.03, "lambda %g r %g", lams[li], ratios[ri]);
            }
    if (tables())
        printf("    Eq. 37 on-axis error: isotropic %.1f %%; mu/lambda 0.25-0.5: printed %.1f %%, geometric mean %.1f %%\n",
               100 * worst_iso, 100 * worst_printed, 100 * worst_mean);
}

/* ---------------------------------------------------- degenerate, extreme */

VT_TEST(mrp_degenerate_cases_are_finite_and_sensible)
{
    vsgl__mrp_rect rc = rect_xy(1, 1);
    vsgl__mrp_options opts[2] = {vsgl__mrp_options_default(), vsgl__mrp_options_paper()};
    d3 ax, n = d3_make(0, 0, -1); /* a receiver facing the rectangle from above: a ceiling */
    for (int k = 0; k < 2; ++k) {
        const vsgl__mrp_options *o = &opts[k];
        /* on the plane, behind it */
        VT_CHECK(vsgl__mrp_glossy_uniform(&rc, d3_make(0, 0, 0), n, d3_make(0, 0, -1), 0.1, o, &ax) == 0.0, "on");
        VT_CHECK(vsgl__mrp_glossy_uniform(&rc, d3_make(0, 0, -1), n, d3_make(0, 0, -1), 0.1, o, &ax) == 0.0, "behind");
        /* lobe axis away from the plane (view from the other side) */
        VT_CHECK(vsgl__mrp_glossy_uniform(&rc, d3_make(0, 0, 1), d3_make(0, 0, 1), d3_make(0, 0, 1), 0.1, o, &ax)
                 == 0.0, "away");
        /* facing it: positive; the limit of a mirror facing a huge emitter is 1 (times M) */
        double v = vsgl__mrp_glossy_uniform(&rc, d3_make(0, 0, 1), n, d3_make(0, 0, -1), 0.1, o, &ax);
        VT_CHECK(v > 0.0 && isfinite(v), "facing %g", v);
        vsgl__mrp_rect big = rect_xy(1e6, 1e6), tiny = rect_xy(1e-7, 1e-7);
        v = vsgl__mrp_glossy_uniform(&big, d3_make(0, 0, 1), n, d3_make(0, 0, -1), 0.1, o, &ax);
        VT_CHECK(v > 0.1 && v < 10.0, "huge rectangle %g", v);
        v = vsgl__mrp_glossy_uniform(&tiny, d3_make(0, 0, 1), n, d3_make(0, 0, -1), 0.1, o, &ax);
        VT_CHECK(v >= 0.0 && v < 1e-6, "tiny rectangle %g", v);
        /* grazing views and grazing lobes */
        for (double c = 1e-1; c > 1e-12; c *= 0.01) {
            d3 view = d3_normalize(d3_make(sqrt(1 - c * c), 0, -c));
            v = vsgl__mrp_glossy_uniform(&rc, d3_make(0, 0, 1), n, view, 0.1, o, &ax);
            VT_CHECK(v >= 0.0 && isfinite(v) && d3_finite(ax), "grazing view %g: %g", c, v);
        }
        /* mirror-sharp and fully rough receivers */
        const double alphas[] = {0.0, 4.7e-10, 1e-5, 1.0, 2.0};
        for (int a = 0; a < 5; ++a) {
            v = vsgl__mrp_glossy_uniform(&rc, d3_make(0.2, 0.1, 0.5), n, d3_normalize(d3_make(0.3, 0, -1)),
                                         alphas[a], o, &ax);
            VT_CHECK(v >= 0.0 && isfinite(v), "alpha %g: %g", alphas[a], v);
        }
        /* disk larger than the rectangle: the energy is the rectangle's */
        v = vsgl__mrp_glossy_uniform(&tiny, d3_make(0, 0, 1e-6), n, d3_make(0, 0, -1), 1.0, o, &ax);
        VT_CHECK(v >= 0.0 && isfinite(v), "disk >> rectangle %g", v);
    }
    /* ASG light: x on the disk plane, behind it, at y, C <= 0 */
    vsgl_asg a;
    VT_CHECK(!vsgl__mrp_asg_light(d3_make(1, 0, 0), d3_make(0, 0, 0), d3_make(0, 0, 1), 0.1, 1, 1, &a), "on plane");
    VT_CHECK(!vsgl__mrp_asg_light(d3_make(0, 0, -1), d3_make(0, 0, 0), d3_make(0, 0, 1), 0.1, 1, 1, &a), "behind");
    VT_CHECK(!vsgl__mrp_asg_light(d3_make(0, 0, 0), d3_make(0, 0, 0), d3_make(0, 0, 1), 0.1, 1, 1, &a), "x = y");
    VT_CHECK(!vsgl__mrp_asg_light(d3_make(0, 0, 1), d3_make(0, 0, 0), d3_make(0, 0, 1), 0.1, 0, 1, &a), "C = 0");
    VT_CHECK(a.log_amplitude == -INFINITY, "zero lobe");
    /* a disk subtending > 87 degrees: bandwidth 0; the paper's norm has no
     * finite amplitude (refused), the exact one does */
    VT_CHECK(!vsgl__mrp_asg_light(d3_make(0, 0, 1), d3_make(0, 0, 0), d3_make(0, 0, 1), 30, 1, 0, &a), "paper");
    VT_CHECK(vsgl__mrp_asg_light(d3_make(0, 0, 1), d3_make(0, 0, 0), d3_make(0, 0, 1), 30, 1, 1, &a) &&
             isfinite(a.log_amplitude), "exact");
}

static double extreme(vt_rng *r)
{
    switch (vt_next(r) % 8) {
    case 0: return 0.0;
    case 1: return -pow(10.0, 60 * vt_uniform(r) - 30);
    case 2: return 1e-300;
    case 3: return 1e300;
    default: return pow(10.0, 60 * vt_uniform(r) - 30);
    }
}

static d3 extreme_point(vt_rng *r)
{
    double s = pow(10.0, 16 * vt_uniform(r) - 8);
    return d3_scale(rand_dir(r), vt_next(r) % 5 == 0 ? 0.0 : s);
}

VT_TEST(mrp_extreme_draws_give_no_nan)
{
    vt_rng r = {1000000};
    long draws = quick() ? 100000 : 1000000, bad = 0;
    for (long it = 0; it < draws; ++it) {
        vsgl__mrp_rect rc;
        d3 c = extreme_point(&r), nr = rand_dir(&r);
        if (vt_next(&r) % 16 == 0)
            nr = d3_make(0, 0, 0);
        vsgl__mrp_rect_make(c, nr, rand_dir(&r), fabs(extreme(&r)), fabs(extreme(&r)), &rc);
        d3 x = d3_add(c, extreme_point(&r)), n = rand_dir(&r), o = rand_dir(&r);
        if (vt_next(&r) % 4 == 0) /* grazing */
            o = d3_normalize(d3_add(d3_sub(o, d3_scale(n, d3_dot(o, n))), d3_scale(n, 1e-7)));
        double alpha = vt_next(&r) % 8 == 0 ? extreme(&r) : pow(2.0, -31.0 * vt_uniform(&r));
        vsgl__mrp_options opt = vsgl__mrp_options_default();
        opt.norm = (int)(vt_next(&r) % 2);
        opt.overlap = (int)(vt_next(&r) % 2);
        opt.centred = (int)(vt_next(&r) % 2);
        opt.sg_only = (int)(vt_next(&r) % 2);
        opt.solid_angle = (int)(vt_next(&r) % 2);
        opt.lobes = 1 + (int)(vt_next(&r) % 2);
        opt.rd_scale = vt_next(&r) % 8 == 0 ? fabs(extreme(&r)) : opt.rd_scale;
        d3 ax, y;
        double v = vsgl__mrp_glossy_uniform(&rc, x, n, o, alpha, &opt, &ax);
        int ok = isfinite(v) && v >= 0.0 && d3_finite(ax), why = ok ? 0 : 1;
        /* the pieces with raw extreme arguments */
        double th = 1.6 * vt_uniform(&r), s = 1.6 * vt_uniform(&r), m = fabs(extreme(&r)) + 1e-30;
        double k = (vt_next(&r) % 2 ? -1 : 1) * extreme(&r), t = vsgl__mrp_cap_t(fabs(extreme(&r)), cos(s));
        double l = fabs(extreme(&r)), C = extreme(&r);
        ok &= isfinite(vsgl__mrp_f_ggx(th, fmin(s, 1.57), fmin(m, 1e150))) || m > 1e150;
        why |= ok ? 0 : 2;
        ok &= isfinite(t) && t >= 0.0 && t <= 1.0;
        why |= ok ? 0 : 4;
        double e = vsgl__mrp_disk_integral(k, t);
        ok &= isfinite(e) && e >= 0.0 && e <= AQ_PI * t * (1.0 + 1e-12);
        why |= ok ? 0 : 8;
        double b = vsgl__mrp_bandwidth(l);
        ok &= isfinite(b) && b >= 0.0;
        why |= ok ? 0 : 16;
        vsgl_asg a;
        if (vsgl__mrp_asg_light(x, c, nr, l, C, opt.norm, &a))
            ok &= isfinite(a.log_amplitude) && isfinite(a.lambda) && isfinite(a.mu);
        why |= ok ? 0 : 32;
        double ov1 = vsgl__mrp_overlap_exact(&rc, x, l), ov2 = vsgl__mrp_overlap_bbox(&rc, x, l);
        ok &= ov1 >= 0.0 && ov1 <= 1.0 && ov2 >= 0.0 && ov2 <= 4.0 / AQ_PI + 1e-12;
        why |= ok ? 0 : 64;
        if (vsgl__mrp_peak(&rc, x, o, &y))
            ok &= d3_finite(y);
        why |= ok ? 0 : 128;
        if (!ok) {
            ++bad;
            if (bad <= 5)
                VT_CHECK(0, "draw %ld (why %d): v %g alpha %g l %g k %g t %g e %g b %g", it, why, v, alpha, l, k, t, e, b);
        }
    }
    VT_CHECK(bad == 0, "%ld of %ld draws not finite / out of range", bad, draws);
}
