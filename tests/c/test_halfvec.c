/* The half-vector model of a planar cluster's glossy light (shade/
 * halfvec.c) against quadrature of the same radiance through GGX itself:
 * a small lit patch on a wall seen by a glossy floor, at the mirror
 * direction and out in GGX's tail, where the ASG lobes (the planar model
 * with GGX's core and tail) lose the haze. */
#include "harness.h"
#include "shade/halfvec.h"
#include "shade/kernel.h"
#include "shade/shade.h"
#include "vsgl/asg.h"
#include "vsgl/lobes.h"
#include "vsgl/sg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI_D 3.14159265358979323846

/* GGX's f cos (Fresnel 1, height-correlated Smith) from l to o at normal +z. */
static double ggx_fcos(double alpha, const double o[3], const double l[3])
{
    if (!(o[2] > 0.0) || !(l[2] > 0.0))
        return 0.0;
    double h[3] = {o[0] + l[0], o[1] + l[1], o[2] + l[2]};
    double hl = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    double hz = h[2] / hl, t2 = (1.0 - hz * hz) / (hz * hz), a2 = alpha * alpha;
    double D = 1.0 / (PI_D * a2 * hz * hz * hz * hz * (1.0 + t2 / a2) * (1.0 + t2 / a2));
    double so = sqrt(a2 + (1.0 - a2) * o[2] * o[2]), si = sqrt(a2 + (1.0 - a2) * l[2] * l[2]);
    double g2 = 2.0 * o[2] * l[2] / (l[2] * so + o[2] * si);
    return D * g2 / (4.0 * o[2]);
}

/* The cluster: a Gaussian of variance var per axis on the wall y = wy
 * (normal -y) about (mx, wy, mz), radiance N / pi per watt. */
static double quadrature(double alpha, const double x[3], const double o[3], double mx, double wy, double mz, double var)
{
    double s = sqrt(var), step = s / 24.0, sum = 0.0;
    for (int a = -144; a < 144; ++a)
        for (int b = -144; b < 144; ++b) {
            double px = mx + (a + 0.5) * step, pz = mz + (b + 0.5) * step;
            double u = (px - mx) * (px - mx) + (pz - mz) * (pz - mz);
            double N = exp(-0.5 * u / var) / (2.0 * PI_D * var);
            double d[3] = {px - x[0], wy - x[1], pz - x[2]};
            double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], r = sqrt(r2);
            double l[3] = {d[0] / r, d[1] / r, d[2] / r};
            double cosp = d[1] / r; /* the wall faces -y: its cosine towards x */
            sum += N / PI_D * ggx_fcos(alpha, o, l) * cosp / r2 * step * step;
        }
    return sum;
}

VT_TEST(halfvec_glossy_follows_ggx_into_its_tail)
{
    const float alphas[2] = {0.04f, 0.09f};
    /* view elevations: the mirror direction's offset from the patch in alphas */
    const float offs[5] = {0.0f, 1.5f, 3.0f, 5.0f, 7.0f};
    double worst_hv = 0.0, worst_asg_tail = 0.0;
    for (int ai = 0; ai < 2; ++ai)
        for (int k = 0; k < 5; ++k) {
            const double alpha = alphas[ai], wy = 3.0, mz = 0.8, var = 0.03 * 0.03;
            const double x[3] = {0.0, 0.0, 0.0};
            /* the direction to the patch, and a view whose mirror direction
             * sits offs alphas above it (in half-vector terms: 2 offs alpha in l) */
            double el = atan2(mz, wy) + 2.0 * offs[k] * alpha;
            double o[3] = {0.0, -cos(el), sin(el)};
            vsgl_vsgl v;
            memset(&v, 0, sizeof v);
            v.mean = v3_make(0.0f, (float)wy, (float)mz);
            v.variance = (float)var;
            v.normal = v3_make(0.0f, -1.0f, 0.0f);
            v.coherence = 1.0f;
            v.power[0] = v.power[1] = v.power[2] = 1.0f;
            v.lobe = VSGL__LOBE_DIFFUSE;
            vsgl_vec3 n = {0.0f, 0.0f, 1.0f}, t = {1.0f, 0.0f, 0.0f}, ov = {(float)o[0], (float)o[1], (float)o[2]};
            vsgl_asg ndf, lobe;
            vsgl_ndf_aniso_to_asg(&n, &t, (float)alpha, (float)alpha, &ndf);
            vsgl_warp_ndf_asg(&ndf, &ov, &lobe);
            v3 axis = v3_make(lobe.z.x, lobe.z.y, lobe.z.z);
            float M = vsgl_specular_factor(&n, &ov, &lobe.z, (float)alpha, 1.0f);
            float w;
            double hv = vsgl__halfvec_glossy(&v, v3_make(0, 0, 0), v3_make(0, 0, 1), v3_make(ov.x, ov.y, ov.z), axis,
                                             (float)alpha, VSGL__HV_LOBES, &w) * M;
            /* the planar model with GGX's core and tail (kernel.h VSGL__GGX_*) */
            double asg = 0.0;
            const float K[2] = {VSGL__GGX_CORE_K, VSGL__GGX_TAIL_K}, C[2] = {VSGL__GGX_CORE_C, VSGL__GGX_TAIL_C};
            for (int q = 0; q < 2; ++q) {
                vsgl_asg part = lobe;
                part.lambda *= K[q];
                part.mu *= K[q];
                part.log_amplitude += logf(C[q]);
                asg += vsgl__planar_glossy(&v, v3_make(0, 0, 0), v3_make(0, 0, 1), &part) * M;
            }
            double want = quadrature(alpha, x, o, 0.0, wy, mz, var);
            double e = fabs(hv / want - 1.0), ea = fabs(asg / want - 1.0);
            if (getenv("VSGL_TEST_VERBOSE"))
                printf("    alpha %.2f, %4.1f alpha off the mirror direction: quadrature %.4g, half-vector %.4g (%+.1f %%, "
                       "weight %.2f), ASG core + tail %.4g (%+.1f %%)\n",
                       alpha, offs[k], want, hv, 100.0 * (hv / want - 1.0), w, asg, 100.0 * (asg / want - 1.0));
            VT_CHECK(w == 1.0f, "alpha %g, %g off: the model's weight %g (a small patch, well above the horizon)", alpha,
                     offs[k], w);
            worst_hv = e > worst_hv ? e : worst_hv;
            if (offs[k] >= 5.0f)
                worst_asg_tail = ea > worst_asg_tail ? ea : worst_asg_tail;
        }
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    worst: half-vector %.3f; ASG lobes %.3f at 5-7 alpha\n", worst_hv, worst_asg_tail);
    /* measured 0.122: -12 % at the mirror direction, where the four lobes
     * are 0.85 of GGX's peak (the fit's relative error over 10 alpha), within
     * 2 % from 1.5 alpha on; the ASG lobes -78 % to +127 % at 5-7 alpha */
    VT_CHECK(worst_hv < 0.15, "half-vector model off GGX by %.3f", worst_hv);
    VT_CHECK(worst_asg_tail > 0.5, "the ASG lobes in GGX's tail: off by only %.3f (the test lost its point)", worst_asg_tail);
}
