/* The upper hemisphere (normal +z) by the midpoint rule in nt theta rows
 * crowded at the horizon, where a grazing view's lobe lies (theta = (pi /
 * 2) (1 - (1 - u)^2), u in nt midpoint rows), and np phi columns: the sum
 * of f(l) dl. For test references and tools/gen_broad_lobe.c. Header-only. */
#ifndef VSGL_TEST_HEMI_QUAD_H
#define VSGL_TEST_HEMI_QUAD_H

#include "math/vec.h"

#include <math.h>

typedef double (*hemi_fn)(const void *user, v3 l);

static inline double hemi_quad(hemi_fn f, const void *user, int nt, int np)
{
    const double pi = 3.14159265358979323846;
    double sum = 0.0;
    for (int i = 0; i < nt; ++i) {
        double u = (i + 0.5) / nt, th = 0.5 * pi * (1.0 - (1.0 - u) * (1.0 - u));
        double dth = pi * (1.0 - u) / nt;
        for (int k = 0; k < np; ++k) {
            double ph = 2.0 * pi * (k + 0.5) / np;
            v3 l = v3_make((float)(sin(th) * cos(ph)), (float)(sin(th) * sin(ph)), (float)cos(th));
            sum += f(user, l) * sin(th) * dth * (2.0 * pi / np);
        }
    }
    return sum;
}

#endif
