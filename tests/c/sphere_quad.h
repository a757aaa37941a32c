/* Double-precision quadrature on the sphere for test references.
 *
 *   double f(const double w[3], double omu, void *user);   // omu = 1 - w.axis (exact)
 *   double I = sq_sphere(f, user, axis, lam, 24, 256);
 *
 * sq_sphere integrates in polar coordinates (theta, phi) about a unit axis.
 * The polar part uses the substitution t = lam (1 - cos theta), split into
 * geometric panels [0, 1/2], [1/2, 1], [1, 2], ... up to 2 lam, each with an
 * n_gl-point Gauss-Legendre rule, so a lobe exp(lam (w.axis - 1)) of any
 * sharpness is resolved; lam <= 1 uses 8 uniform panels in cos theta. The
 * azimuth uses the n_phi-point trapezoid rule (spectral for smooth periodic
 * integrands). The integrand gets 1 - w.axis without cancellation.
 * sq_line integrates a 1-D function with composite Gauss-Legendre.
 * Independent of the library: only <math.h>. Header-only, static inline functions. */
#ifndef VSGL_TEST_SPHERE_QUAD_H
#define VSGL_TEST_SPHERE_QUAD_H

#include <math.h>

#define SQ_MAX_GL 64
#define SQ_PI 3.14159265358979323846

typedef double (*sq_fn)(const double w[3], double omu, void *user);
typedef double (*sq_fn1)(double x, void *user);

/* Gauss-Legendre nodes/weights on [-1, 1] (Newton on P_n), n <= SQ_MAX_GL. */
static inline void sq_gauss_legendre(int n, double *x, double *w)
{
    for (int i = 0; i < n; ++i) {
        double z = cos(SQ_PI * (i + 0.75) / (n + 0.5)), pp = 1.0;
        for (int it = 0; it < 100; ++it) {
            double p1 = 1.0, p2 = 0.0;
            for (int j = 1; j <= n; ++j) {
                double p3 = p2;
                p2 = p1;
                p1 = ((2.0 * j - 1.0) * z * p2 - (j - 1.0) * p3) / j;
            }
            pp = n * (z * p1 - p2) / (z * z - 1.0);
            double dz = p1 / pp;
            z -= dz;
            if (fabs(dz) < 1e-16)
                break;
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * pp * pp);
    }
}

/* Orthonormal e1, e2 completing unit a. */
static inline void sq_basis(const double a[3], double e1[3], double e2[3])
{
    double s = a[2] >= 0.0 ? 1.0 : -1.0;
    double p = -1.0 / (s + a[2]);
    double q = a[0] * a[1] * p;
    e1[0] = 1.0 + s * a[0] * a[0] * p; e1[1] = s * q; e1[2] = -s * a[0];
    e2[0] = q; e2[1] = s + a[1] * a[1] * p; e2[2] = -a[1];
}

static inline double sq_line(sq_fn1 g, void *user, double a, double b, int panels, int n_gl)
{
    double x[SQ_MAX_GL], w[SQ_MAX_GL], sum = 0.0;
    sq_gauss_legendre(n_gl, x, w);
    double h = (b - a) / panels;
    for (int p = 0; p < panels; ++p) {
        double c = a + (p + 0.5) * h, s = 0.0;
        for (int i = 0; i < n_gl; ++i)
            s += w[i] * g(c + 0.5 * h * x[i], user);
        sum += 0.5 * h * s;
    }
    return sum;
}

static inline double sq_sphere(sq_fn f, void *user, const double axis_in[3], double lam, int n_gl, int n_phi)
{
    double x[SQ_MAX_GL], wt[SQ_MAX_GL];
    sq_gauss_legendre(n_gl, x, wt);
    double l = sqrt(axis_in[0] * axis_in[0] + axis_in[1] * axis_in[1] + axis_in[2] * axis_in[2]);
    double a[3] = {axis_in[0] / l, axis_in[1] / l, axis_in[2] / l}, e1[3], e2[3];
    sq_basis(a, e1, e2);
    /* Panels in omu = 1 - cos theta in [0, 2]. */
    double edges[200];
    int ne = 0;
    if (!(lam > 1.0)) {
        for (int k = 0; k <= 8; ++k)
            edges[ne++] = 0.25 * k;
    } else {
        edges[ne++] = 0.0;
        double t = 0.5;
        while (t < 2.0 * lam && ne < 190) {
            edges[ne++] = t / lam;
            t *= 2.0;
        }
        edges[ne++] = 2.0;
    }
    double total = 0.0;
    for (int p = 0; p + 1 < ne; ++p) {
        double o0 = edges[p], o1 = edges[p + 1], h = o1 - o0;
        for (int i = 0; i < n_gl; ++i) {
            double omu = o0 + 0.5 * h * (x[i] + 1.0);
            double u = 1.0 - omu;
            double st = sqrt(omu * (2.0 - omu));
            double ring = 0.0;
            for (int j = 0; j < n_phi; ++j) {
                double ph = 2.0 * SQ_PI * (j + 0.5) / n_phi, cp = cos(ph), sp = sin(ph);
                double w[3];
                for (int k = 0; k < 3; ++k)
                    w[k] = u * a[k] + st * (cp * e1[k] + sp * e2[k]);
                ring += f(w, omu, user);
            }
            total += 0.5 * h * wt[i] * ring * (2.0 * SQ_PI / n_phi);
        }
    }
    return total;
}

#endif
