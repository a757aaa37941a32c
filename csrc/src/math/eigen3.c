/* Cyclic Jacobi eigen-solver for symmetric 3x3 matrices (Golub & Van Loan
 * §8.5; the rotation formulas of Rutishauser's stable variant). */
#include "math/eigen3.h"

#include <math.h>

static void rotate(double a[3][3], double v[3][3], int p, int q)
{
    double apq = a[p][q];
    if (apq == 0.0)
        return;
    double theta = (a[q][q] - a[p][p]) / (2.0 * apq);
    double t;
    if (fabs(theta) > 1e150)
        t = 0.5 / theta; /* theta^2 would overflow; t ~ 1 / (2 theta) */
    else
        t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
    double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
    a[p][p] -= t * apq;
    a[q][q] += t * apq;
    a[p][q] = a[q][p] = 0.0;
    for (int r = 0; r < 3; ++r) {
        if (r != p && r != q) {
            double g = a[r][p], h = a[r][q];
            a[r][p] = a[p][r] = c * g - s * h;
            a[r][q] = a[q][r] = s * g + c * h;
        }
        double g = v[r][p], h = v[r][q];
        v[r][p] = c * g - s * h;
        v[r][q] = s * g + c * h;
    }
}

int vsgl__eigen_sym3(double a_in[3][3], double w[3], double v[3][3])
{
    double a[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j) {
            if (!isfinite(a_in[i][j])) {
                for (int k = 0; k < 3; ++k) {
                    w[k] = NAN;
                    v[k][0] = v[k][1] = v[k][2] = NAN;
                }
                return -1;
            }
            a[i][j] = a[j][i] = a_in[i][j];
        }
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            v[i][j] = i == j ? 1.0 : 0.0;
    int sweep = 0;
    for (; sweep < 32; ++sweep) {
        double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
        double diag = fabs(a[0][0]) + fabs(a[1][1]) + fabs(a[2][2]);
        /* Converged when the off-diagonal part is below rounding of the
         * diagonal (quadratic convergence: 3-6 sweeps in practice). */
        if (off == 0.0 || off <= 1e-18 * diag)
            break;
        rotate(a, v, 0, 1);
        rotate(a, v, 0, 2);
        rotate(a, v, 1, 2);
    }
    int idx[3] = {0, 1, 2};
    for (int i = 0; i < 2; ++i)
        for (int j = i + 1; j < 3; ++j)
            if (a[idx[j]][idx[j]] > a[idx[i]][idx[i]]) {
                int t = idx[i];
                idx[i] = idx[j];
                idx[j] = t;
            }
    double vv[3][3];
    for (int k = 0; k < 3; ++k) {
        w[k] = a[idx[k]][idx[k]];
        for (int r = 0; r < 3; ++r)
            vv[r][k] = v[r][idx[k]];
    }
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 2; ++k)
            v[r][k] = vv[r][k];
    /* Right-handed: third column = first x second (still a unit eigenvector). */
    v[0][2] = vv[1][0] * vv[2][1] - vv[2][0] * vv[1][1];
    v[1][2] = vv[2][0] * vv[0][1] - vv[0][0] * vv[2][1];
    v[2][2] = vv[0][0] * vv[1][1] - vv[1][0] * vv[0][1];
    return sweep;
}

/* Column k of v: the unit eigenvector of eigenvalue w of a (a well separated
 * one): the largest cross product of two rows of a - w I. 0 if too small. */
static int eigvec(double a[3][3], double w, double scale, double out[3])
{
    double r[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            r[i][j] = a[i][j] - (i == j ? w : 0.0);
    double best = -1.0;
    for (int k = 0; k < 3; ++k) {
        const double *p = r[k], *q = r[(k + 1) % 3];
        double c[3] = {p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]};
        double n = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        if (n > best) {
            best = n;
            out[0] = c[0], out[1] = c[1], out[2] = c[2];
        }
    }
    if (!(best > 1e-20 * scale * scale * scale * scale))
        return 0;
    double l = 1.0 / sqrt(best);
    out[0] *= l, out[1] *= l, out[2] *= l;
    return 1;
}

/* The closed-form eigenvalues ws[0] >= ws[1] >= ws[2] of the symmetric a
 * (copied from a_in's upper triangle) and the scale |trace/3| + sqrt(p); 0
 * when they are well separated (more than 1e-6 of the scale apart), -1
 * otherwise (not finite, repeated or nearly so: the caller's fallback). */
static int closed_form(double a_in[3][3], double a[3][3], double ws[3], double *scale_out)
{
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j) {
            if (!isfinite(a_in[i][j]))
                return -1;
            a[i][j] = a[j][i] = a_in[i][j];
        }
    /* eigenvalues in closed form (Smith 1961; Kopp 2008's dsyevc3 in the
     * trigonometric form): a = m I + K, K's eigenvalues 2 sqrt(p) cos(phi + 2 pi k / 3) */
    double m = (a[0][0] + a[1][1] + a[2][2]) / 3.0;
    double k00 = a[0][0] - m, k11 = a[1][1] - m, k22 = a[2][2] - m;
    double p = (k00 * k00 + k11 * k11 + k22 * k22 + 2.0 * (a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2])) / 6.0;
    double q = 0.5 * (k00 * (k11 * k22 - a[1][2] * a[1][2]) - a[0][1] * (a[0][1] * k22 - a[1][2] * a[0][2]) +
                      a[0][2] * (a[0][1] * a[1][2] - k11 * a[0][2]));
    double scale = fabs(m) + sqrt(p);
    *scale_out = scale;
    if (!(p > 1e-24 * scale * scale))
        return -1;
    double sp = sqrt(p), disc = p * p * p - q * q;
    double phi = atan2(sqrt(disc > 0.0 ? disc : 0.0), q) / 3.0;
    double c = cos(phi), s = sin(phi);
    double e0 = m + 2.0 * sp * c, e1 = m - sp * (c + 1.7320508075688772 * s), e2 = m - sp * (c - 1.7320508075688772 * s);
    /* sort: e0 >= e2 >= e1 for phi in [0, pi/3] */
    ws[0] = e0, ws[1] = e2 > e1 ? e2 : e1, ws[2] = e2 > e1 ? e1 : e2;
    /* well separated, or the caller's fallback (repeated eigenvalues: any basis of the eigenspace) */
    if (!(ws[0] - ws[1] > 1e-6 * scale) || !(ws[1] - ws[2] > 1e-6 * scale))
        return -1;
    return 0;
}

int vsgl__eigen_sym3_fast(double a_in[3][3], double w[3], double v[3][3])
{
    double a[3][3], ws[3], scale;
    if (closed_form(a_in, a, ws, &scale) != 0)
        return vsgl__eigen_sym3(a_in, w, v);
    double x[3], z[3];
    if (!eigvec(a, ws[0], scale, x) || !eigvec(a, ws[2], scale, z) ||
        !(fabs(x[0] * z[0] + x[1] * z[1] + x[2] * z[2]) < 1e-9))
        return vsgl__eigen_sym3(a_in, w, v);
    /* y = z x x: the frame (x, y, z) is right-handed, z = x x y */
    double y[3] = {z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]};
    for (int r = 0; r < 3; ++r) {
        w[r] = ws[r];
        v[r][0] = x[r];
        v[r][1] = y[r];
        v[r][2] = z[r];
    }
    return 0;
}

int vsgl__eigen_sym3_smallest(double a_in[3][3], double w[3], double z[3])
{
    double a[3][3], scale;
    if (closed_form(a_in, a, w, &scale) != 0 || !eigvec(a, w[2], scale, z))
        return -1;
    return 0;
}
