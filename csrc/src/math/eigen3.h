/* Internal: eigen-decomposition of a real symmetric 3x3 matrix (cyclic Jacobi). */
#ifndef VSGL_MATH_EIGEN3_H
#define VSGL_MATH_EIGEN3_H

/* Eigenvalues w[0] >= w[1] >= w[2] of the symmetric matrix a (only its
 * upper triangle is read; a is not modified) and orthonormal eigenvectors: column k of v,
 * i.e. (v[0][k], v[1][k], v[2][k]), belongs to w[k]; the columns form a
 * right-handed frame (v2 = v0 x v1). Repeated eigenvalues are no special
 * case: Jacobi rotations keep v orthonormal and return some orthonormal
 * basis of the repeated eigenspace. Returns the number of sweeps used
 * (<= 32), or -1 if an entry is not finite (then w and v are NaN). */
int vsgl__eigen_sym3(double a[3][3], double w[3], double v[3][3]);

/* The same contract in closed form (eigenvalues by Smith's trigonometric
 * formula, eigenvectors as cross products of rows of a - w I) when the
 * eigenvalues are apart by more than 1e-6 of |trace/3| + sqrt(p) (p the
 * spread of a's eigenvalues), else vsgl__eigen_sym3. Returns 0 in the
 * closed-form case, else vsgl__eigen_sym3's result. About 5x cheaper;
 * eigenvalues agree with it to 1e-10 of the scale (tests/c/test_asg.c). */
int vsgl__eigen_sym3_fast(double a[3][3], double w[3], double v[3][3]);

/* vsgl__eigen_sym3_fast's closed form for the eigenvalues w[0] >= w[1] >=
 * w[2] and the unit eigenvector z of the smallest only (the same values, bit
 * for bit, and z = its column 2 up to sign). Returns 0, or -1 where
 * vsgl__eigen_sym3_fast would fall back to Jacobi (not finite, eigenvalues
 * within 1e-6 of the scale): then w and z are unspecified. */
int vsgl__eigen_sym3_smallest(double a[3][3], double w[3], double z[3]);

#endif
