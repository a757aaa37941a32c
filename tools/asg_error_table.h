/* Reference quadrature for the ASG operators, double precision, shared by
 * tests/c/test_asg.c (bounds on a seeded subset) and tools/asg_error_table.c
 * (the full sweeps). Independent of the code under test: no Bessel function,
 * no closed form; adaptive Gauss-Kronrod (7/15, QUADPACK's qk15 nodes) in 1-D
 * and nested 1-D rules on the sphere.
 *
 * Sphere rule: spherical coordinates (theta, phi) about a pole; theta split
 * geometrically from the pole at the lobe's angular scale w (w, 2w, 4w ...),
 * so a lobe of any sharpness centred on the pole is resolved; phi in 8 equal
 * panels; both levels adaptive (bisection until |K15 - G7| <= max(abs, rel |I|)). */
#ifndef VSGL_TOOLS_ASG_ERROR_TABLE_H
#define VSGL_TOOLS_ASG_ERROR_TABLE_H

#include <math.h>

#define AQ_PI 3.14159265358979323846

typedef double (*aq_fn)(double x, void *user);

static const double aq_xgk[8] = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
static const double aq_wgk[8] = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
static const double aq_wg[4] = {
    0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
    0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

static inline double aq_gk15(aq_fn f, void *u, double a, double b, double *err)
{
    double c = 0.5 * (a + b), h = 0.5 * (b - a);
    double fc = f(c, u);
    double k = fc * aq_wgk[7], g = fc * aq_wg[3];
    for (int j = 0; j < 7; ++j) {
        double dx = h * aq_xgk[j];
        double s = f(c - dx, u) + f(c + dx, u);
        k += aq_wgk[j] * s;
        if (j & 1)
            g += aq_wg[j / 2] * s;
    }
    *err = fabs((k - g) * h);
    return k * h;
}

/* abs_density: absolute tolerance per unit length of x. */
static inline double aq_rec(aq_fn f, void *u, double a, double b, double abs_density, double rel, int depth)
{
    double err, r = aq_gk15(f, u, a, b, &err);
    double tol = fmax(abs_density * (b - a), rel * fabs(r));
    if (err <= tol || depth >= 24 || !(b - a > 1e-15 * fabs(a + b)))
        return r;
    double m = 0.5 * (a + b);
    return aq_rec(f, u, a, m, abs_density, rel, depth + 1) + aq_rec(f, u, m, b, abs_density, rel, depth + 1);
}

/* Adaptive integral of f over [a, b] split first into n equal panels. */
static inline double aq_integrate(aq_fn f, void *u, double a, double b, int n, double abs_tol, double rel)
{
    double s = 0.0, h = (b - a) / n;
    for (int i = 0; i < n; ++i)
        s += aq_rec(f, u, a + i * h, i == n - 1 ? b : a + (i + 1) * h, abs_tol / (b - a), rel, 0);
    return s;
}

/* ---------------------------------------------------------------- sphere */

typedef double (*aq_sph_fn)(const double v[3], void *user);

typedef struct aq_sph {
    aq_sph_fn f;
    void *user;
    double e1[3], e2[3], pole[3];
    double theta, sin_t, cos_t;
    double abs_phi, rel;
    int nphi;
} aq_sph;

static inline double aq_sph_phi(double phi, void *u)
{
    aq_sph *s = u;
    double cp = cos(phi), sp = sin(phi), v[3];
    for (int i = 0; i < 3; ++i)
        v[i] = s->sin_t * (cp * s->e1[i] + sp * s->e2[i]) + s->cos_t * s->pole[i];
    return s->f(v, s->user);
}

static inline double aq_sph_theta(double theta, void *u)
{
    aq_sph *s = u;
    s->theta = theta;
    s->sin_t = sin(theta);
    s->cos_t = cos(theta);
    if (s->sin_t == 0.0)
        return 0.0;
    return s->sin_t * aq_integrate(aq_sph_phi, s, 0.0, 2.0 * AQ_PI, s->nphi, s->abs_phi, s->rel);
}

/* Integral of f over the unit sphere. pole: unit vector where f peaks;
 * w: angular width of the peak (radians, e.g. 1/sqrt(sharpness)); abs_tol:
 * absolute tolerance of the whole integral; rel: relative tolerance per
 * panel. */
static inline double aq_sphere(aq_sph_fn f, void *user, const double pole[3], double w, double abs_tol, double rel)
{
    aq_sph s;
    s.f = f;
    s.user = user;
    for (int i = 0; i < 3; ++i)
        s.pole[i] = pole[i];
    /* e1 orthogonal to the pole (Duff et al.), e2 = pole x e1 */
    double sg = copysign(1.0, pole[2]), q = -1.0 / (sg + pole[2]), b = pole[0] * pole[1] * q;
    s.e1[0] = 1.0 + sg * pole[0] * pole[0] * q, s.e1[1] = sg * b, s.e1[2] = -sg * pole[0];
    s.e2[0] = b, s.e2[1] = sg + pole[1] * pole[1] * q, s.e2[2] = -pole[1];
    s.abs_phi = abs_tol / (2.0 * AQ_PI * AQ_PI);
    s.rel = rel;
    s.nphi = w < 0.1 ? 4 : 8;
    if (!(w > 0.0) || w > 0.5)
        w = 0.5;
    double t0 = 0.0, t1 = w, sum = 0.0;
    while (t0 < AQ_PI) {
        double hi = t1 < AQ_PI ? t1 : AQ_PI;
        if (hi - t0 > 0.5)
            hi = t0 + 0.5 < AQ_PI ? t0 + 0.5 : AQ_PI;
        sum += aq_rec(aq_sph_theta, &s, t0, hi, abs_tol / AQ_PI, rel, 0);
        t0 = hi;
        t1 = 2.0 * hi;
    }
    return sum;
}

/* ------------------------------------------------------- ASG references */

/* Unit ASG in its own frame: max(vz, 0) exp(-lam vx^2 - mu vy^2). */
typedef struct aq_asg { double x[3], y[3], z[3], lam, mu, logc; } aq_asg;

static inline double aq_asg_eval(const aq_asg *a, const double v[3])
{
    double vz = v[0] * a->z[0] + v[1] * a->z[1] + v[2] * a->z[2];
    if (vz <= 0.0)
        return 0.0;
    double vx = v[0] * a->x[0] + v[1] * a->x[1] + v[2] * a->x[2];
    double vy = v[0] * a->y[0] + v[1] * a->y[1] + v[2] * a->y[2];
    return vz * exp(a->logc - a->lam * vx * vx - a->mu * vy * vy);
}

/* Exact integral of the unit ASG through Eq. 6 (exact: the theta integral
 * of Eq. 4 done in closed form, Eq. 5):  1/2 int_0^{2pi} (1 - e^{-k}) / k dphi,
 * k = lam cos^2 phi + mu sin^2 phi, by the adaptive rule above. */
typedef struct aq_int_args { double lam, mu; } aq_int_args;
static inline double aq_int_phi(double phi, void *u)
{
    aq_int_args *a = u;
    double c = cos(phi), sn = sin(phi), k = a->lam * c * c + a->mu * sn * sn;
    return k < 1e-300 ? 0.5 : -0.5 * expm1(-k) / k;
}
static inline double aq_asg_integral_ref(double lam, double mu)
{
    aq_int_args a = {lam, mu};
    /* 4-fold symmetry: phi in [0, pi/2]. The 1/k peak (at phi = pi/2 if
     * lam >= mu, else at 0) has width sqrt(min/max): panels graded
     * geometrically towards it. Absolute tolerance from a first estimate. */
    double lmax = fmax(lam, mu), lmin = fmin(lam, mu);
    double w = lmax > 0.0 ? sqrt(fmax(lmin, 1e-300) / lmax) : 1.0;
    int at_end = lam >= mu;
    double pts[80];
    int n = 0;
    pts[n++] = 0.0;
    for (double edge = w < 1e-12 ? 1e-12 : w; edge < 0.5 * AQ_PI && n < 70; edge *= 2.0)
        pts[n++] = edge;
    pts[n++] = 0.5 * AQ_PI;
    double total = 0.0;
    for (int pass = 0; pass < 2; ++pass) {
        double s = 0.0, abs_tol = pass == 0 ? INFINITY : 1e-14 * total;
        for (int i = 0; i + 1 < n; ++i) {
            double a0 = at_end ? 0.5 * AQ_PI - pts[i + 1] : pts[i];
            double a1 = at_end ? 0.5 * AQ_PI - pts[i] : pts[i + 1];
            s += aq_integrate(aq_int_phi, &a, a0, a1, 1, abs_tol * (a1 - a0) / (0.5 * AQ_PI), pass == 0 ? 1.0 : 1e-13);
        }
        total = s;
    }
    return 4.0 * total;
}

#endif
