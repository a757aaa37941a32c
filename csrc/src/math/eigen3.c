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
