/* The near field of specular lattice cells (shade/near_field.c): a plane
 * of uniform irradiance reflecting through one lobe, as lattice cells, seen
 * from receivers just above it, against quadrature of the same radiance. */
#include "harness.h"
#include "shade/near_field.h"
#include "vsgl/sg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SPEC_H 0.25f
#define PI_D 3.14159265358979323846

/* Cell (i, j) on z = 0 (facing +z) of a plane of exitance 1 + slope (x -
 * x_end) W/m^2 in x >= x_end (a wall rises there), its specular lobe
 * `axis`, sharpness `lambda`: power and mean by quadrature of its tent. */
static int spec_cell(int i, int j, v3 axis, float lambda, float x_end, float slope, vsgl_vsgl *v)
{
    const double cx = i * SPEC_H, cy = j * SPEC_H, lo = fmax(cx - SPEC_H, x_end);
    if (!(cx + SPEC_H > lo))
        return 0;
    const int n = 32;
    double w = 0.0, sx = 0.0, sy = 0.0;
    for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
            double x = lo + (a + 0.5) * (cx + SPEC_H - lo) / n, y = cy - SPEC_H + (b + 0.5) * 2.0 * SPEC_H / n;
            double t = (1.0 - fabs(x - cx) / SPEC_H) * (1.0 - fabs(y - cy) / SPEC_H) * (cx + SPEC_H - lo) / n *
                       2.0 * SPEC_H / n * (1.0 + slope * (x - x_end));
            w += t;
            sx += t * x;
            sy += t * y;
        }
    memset(v, 0, sizeof *v);
    v->mean = v3_make((float)(sx / w), (float)(sy / w), 0.0f);
    v->normal = v3_make(0.0f, 0.0f, 1.0f);
    v->coherence = 1.0f;
    v->axis = axis;
    v->sharpness = lambda;
    v->power[0] = v->power[1] = v->power[2] = (float)w;
    v->lobe = VSGL__LOBE_SPECULAR;
    v->cell_h = SPEC_H;
    v->cell_axis = 2;
    v->cell_centre[0] = (float)cx;
    v->cell_centre[1] = (float)cy;
    v->cell_lo[0] = (float)lo;
    v->cell_hi[0] = (float)(cx + SPEC_H);
    v->cell_lo[1] = (float)(cy - SPEC_H);
    v->cell_hi[1] = (float)(cy + SPEC_H);
    return 1;
}

/* The model: irradiance / pi at x (normal n) from every cell (no blend). */
static double model(v3 x, v3 n, v3 axis, float lambda, float x_end, float slope)
{
    double sum = 0.0;
    for (int i = -20; i <= 20; ++i)
        for (int j = -20; j <= 20; ++j) {
            vsgl_vsgl v;
            vsgl_near_cell c;
            float w;
            if (spec_cell(i, j, axis, lambda, x_end, slope, &v) && vsgl__near_cell(&v, 0, &c))
                sum += v.power[0] * vsgl__near_diffuse(&c, x, n, &w);
        }
    return sum;
}

/* The truth: radiance G(w) / int G cos over x >= x_end, its irradiance / pi
 * at x by quadrature over the plane around where the axis through x meets it. */
static double truth(v3 x, v3 n, v3 axis, float lambda, float x_end, float slope)
{
    /* int G cos dw over the hemisphere, by quadrature in (theta, phi) */
    double norm = 0.0;
    const int nt = 2000, np = 400;
    for (int a = 0; a < nt; ++a) {
        double th = (a + 0.5) * (PI_D / 2) / nt;
        for (int b = 0; b < np; ++b) {
            double ph = (b + 0.5) * 2.0 * PI_D / np;
            double d[3] = {sin(th) * cos(ph), sin(th) * sin(ph), cos(th)};
            double c = d[0] * axis.x + d[1] * axis.y + d[2] * axis.z;
            norm += exp(lambda * (c - 1.0)) * cos(th) * sin(th) * (PI_D / 2 / nt) * (2.0 * PI_D / np);
        }
    }
    double t = x.z / axis.z;
    double px = x.x - t * axis.x, py = x.y - t * axis.y, reach = 8.0 * t / sqrt(lambda) / axis.z + 0.05;
    const int m = 600;
    double step = 2.0 * reach / m, e = 0.0;
    for (int a = 0; a < m; ++a)
        for (int b = 0; b < m; ++b) {
            double qx = px - reach + (a + 0.5) * step, qy = py - reach + (b + 0.5) * step;
            if (qx < x_end)
                continue;
            double d[3] = {x.x - qx, x.y - qy, x.z}, r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], r = sqrt(r2);
            double c = (d[0] * axis.x + d[1] * axis.y + d[2] * axis.z) / r;
            double cx = -(d[0] * n.x + d[1] * n.y + d[2] * n.z) / r;
            if (cx <= 0.0)
                continue;
            e += (1.0 + slope * (qx - x_end)) * exp(lambda * (c - 1.0)) / norm * cx * (x.z / r) / r2 * step * step;
        }
    return e / PI_D;
}

VT_TEST(near_field_specular_cells_against_quadrature)
{
    /* uniform, and falling 5x over the 0.5 m beside the wall (a spot's
     * spill): measured within 6.0 % (2.7 % uniform); with each cell's
     * irradiance uniform over its steps, the falling one came out 6-16 %
     * dark at the wall's foot */
    const float lambdas[2] = {60.0f, 400.0f}, slopes[2] = {0.0f, -1.6f};
    const v3 axis = v3_normalize(v3_make(-0.45f, 0.1f, 1.0f));
    double worst = 0.0;
    int tested = 0;
    for (int sl = 0; sl < 2; ++sl)
        for (int l = 0; l < 2; ++l)
            for (int k = 0; k < 4; ++k) {
                /* a wall rising at x = -0.6 (normal +x), receivers on it at heights 2-20 cm */
                const float z[4] = {0.02f, 0.05f, 0.1f, 0.2f};
                v3 x = v3_make(-0.6f + 1e-4f, 0.05f, z[k]), n = v3_make(1.0f, 0.0f, 0.0f);
                double got = model(x, n, axis, lambdas[l], -0.6f, slopes[sl]);
                double want = truth(x, n, axis, lambdas[l], -0.6f, slopes[sl]);
                double rel = fabs(got / want - 1.0);
                if (getenv("VSGL_TEST_VERBOSE"))
                    printf("    slope %g, lambda %g, height %.2f m: quadrature %.5f, model %.5f (%+.1f %%)\n", slopes[sl],
                           lambdas[l], z[k], want, got, 100.0 * (got / want - 1.0));
                if (want > 1e-4) {
                    ++tested;
                    worst = rel > worst ? rel : worst;
                }
            }
    VT_CHECK(tested >= 12 && worst < 0.08, "%d receivers, worst relative error %.3f", tested, worst);
}
