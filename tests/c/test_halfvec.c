/* The half-vector model of a planar cluster's glossy light (shade/
 * halfvec.c) against quadrature of the same radiance through GGX itself:
 * a small lit patch on a wall seen by a glossy floor, at the mirror
 * direction and out in GGX's tail, where the ASG lobes (the planar model
 * with GGX's core and tail) lose the haze. */
#include "harness.h"
#include "shade/halfvec.h"
#include "shade/kernel.h"
#include "math/sg_internal.h"
#include "scene/material.h"
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

/* A planar diffuse cluster of unit power: a Gaussian patch about mean
 * (variance var per axis) on the plane of the given normal. */
static vsgl_vsgl patch(v3 mean, v3 normal, float var)
{
    vsgl_vsgl v;
    memset(&v, 0, sizeof v);
    v.mean = mean;
    v.variance = var;
    v.normal = normal;
    v.coherence = 1.0f;
    v.power[0] = v.power[1] = v.power[2] = 1.0f;
    v.lobe = VSGL__LOBE_DIFFUSE;
    return v;
}

/* An isotropic GGX receiver of roughness alpha at the origin, normal +z,
 * seen from ov: its warped lobe and the lobe's axis, and M there with
 * Fresnel 1 (returned). */
static float receiver_lobe(float alpha, vsgl_vec3 ov, vsgl_asg *lobe, v3 *axis)
{
    vsgl_vec3 n = {0.0f, 0.0f, 1.0f}, t = {1.0f, 0.0f, 0.0f};
    vsgl_asg ndf;
    vsgl_ndf_aniso_to_asg(&n, &t, alpha, alpha, &ndf);
    vsgl_warp_ndf_asg(&ndf, &ov, lobe);
    *axis = v3_make(lobe->z.x, lobe->z.y, lobe->z.z);
    return vsgl_specular_factor(&n, &ov, &lobe->z, alpha, 1.0f);
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
            vsgl_vsgl v = patch(v3_make(0.0f, (float)wy, (float)mz), v3_make(0.0f, -1.0f, 0.0f), (float)var);
            vsgl_vec3 ov = {(float)o[0], (float)o[1], (float)o[2]};
            vsgl_asg lobe;
            v3 axis;
            float M = receiver_lobe((float)alpha, ov, &lobe, &axis);
            float w;
            const float none[3] = {0.0f, 1.0f, 0.0f}; /* no Fresnel ratio: M's Fresnel is 1 here */
            double hv = vsgl__halfvec_glossy(&v, v3_make(0, 0, 0), v3_make(0, 0, 1), v3_make(ov.x, ov.y, ov.z), axis,
                                             (float)alpha, VSGL__HV_LOBES, none, &w) * M;
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

/* A grazing view of a dielectric (F0 0.04, Cycles' dielectric-shaped
 * Fresnel): a glossy sphere's lower rim, whose lobe grazes its tangent
 * plane, seeing a small lit patch 2-6 alphas (in half-vector slope) off the
 * mirror direction, towards the normal (where the lit floor lies for the
 * rim). There the half vector is 20-30 degrees from the view, and the
 * Fresnel term a fraction of its value at the lobe's axis, the mirror
 * direction near grazing. Quadrature of the exact BRDF (vsgl__brdf_eval:
 * GGX, Fresnel and shadowing per direction) over the patch's radiance,
 * against the half-vector model times M at the axis. */
static double quadrature_brdf(const vsgl_brdf_params *P, const double o[3], const double c[3], const double l[3],
                              double var)
{
    /* the patch faces the receiver (at the origin): normal -l, axes e1, e2 */
    double e1[3] = {-l[1], l[0], 0.0}, el = sqrt(e1[0] * e1[0] + e1[1] * e1[1]);
    e1[0] /= el;
    e1[1] /= el;
    double e2[3] = {l[1] * e1[2] - l[2] * e1[1], l[2] * e1[0] - l[0] * e1[2], l[0] * e1[1] - l[1] * e1[0]};
    double s = sqrt(var), step = s / 24.0, sum = 0.0;
    v3 wo = v3_make((float)o[0], (float)o[1], (float)o[2]);
    for (int a = -144; a < 144; ++a)
        for (int b = -144; b < 144; ++b) {
            double u = (a + 0.5) * step, v = (b + 0.5) * step;
            double N = exp(-0.5 * (u * u + v * v) / var) / (2.0 * PI_D * var);
            double d[3];
            for (int k = 0; k < 3; ++k)
                d[k] = c[k] + u * e1[k] + v * e2[k];
            double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], r = sqrt(r2);
            double cosp = (d[0] * l[0] + d[1] * l[1] + d[2] * l[2]) / r; /* the patch's cosine towards the origin */
            float fd[3], fg[3];
            vsgl__brdf_eval(P, v3_make(0, 0, 1), v3_make(1, 0, 0),
                            v3_make((float)(d[0] / r), (float)(d[1] / r), (float)(d[2] / r)), wo, fd, fg);
            sum += N / PI_D * fg[0] * cosp / r2 * step * step; /* f cos at the receiver, the patch's cos, 1/r^2 */
        }
    return sum;
}

static void grazing_case(uint32_t flags, double *worst_out, double *worst_without_out)
{
    vsgl_material m;
    memset(&m, 0, sizeof m);
    m.base_color[0] = m.base_color[1] = m.base_color[2] = 0.8f;
    m.roughness = 0.3f;
    m.specular_f0 = 0.04f;
    m.flags = flags;
    vsgl_brdf_params P;
    vsgl__material_params(&m, &P);
    VT_CHECK(P.eta > 1.0f, "a dielectric's Fresnel curve (eta %g)", P.eta);
    const float alpha = sqrtf(P.alpha_x * P.alpha_y);
    const double cos_views[3] = {0.1, 0.15, 0.25}, offs[3] = {2.0, 4.0, 6.0}, dist = 0.3, var = 1e-4;
    double worst = 0.0, worst_without = 0.0;
    for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k) {
            double co = cos_views[c], o[3] = {-sqrt(1.0 - co * co), 0.0, co};
            /* the half vector tilted from the normal towards the view by offs alphas of slope, a little sideways */
            double th = atan(offs[k] * alpha), hs[3] = {-sin(th) * 0.96, sin(th) * 0.28, cos(th)};
            double oh = o[0] * hs[0] + o[1] * hs[1] + o[2] * hs[2], l[3], cen[3];
            for (int q = 0; q < 3; ++q) {
                l[q] = 2.0 * oh * hs[q] - o[q];
                cen[q] = dist * l[q];
            }
            vsgl_vsgl v = patch(v3_make((float)cen[0], (float)cen[1], (float)cen[2]),
                                v3_make((float)-l[0], (float)-l[1], (float)-l[2]), (float)var);
            v3 n = v3_make(0, 0, 1), ov = v3_make((float)o[0], (float)o[1], (float)o[2]);
            vsgl_vec3 nn = {0, 0, 1}, t = {1, 0, 0}, ovv = {ov.x, ov.y, ov.z};
            vsgl_asg ndf, lobe;
            vsgl_ndf_aniso_to_asg(&nn, &t, P.alpha_x, P.alpha_y, &ndf);
            vsgl_warp_ndf_asg(&ndf, &ovv, &lobe);
            vsgl__asg_cut_at_horizon(&lobe, &nn, &ovv);
            v3 axis = v3_make(lobe.z.x, lobe.z.y, lobe.z.z);
            float M[3], fres[3];
            vsgl__specular_factor(&P, n, ov, axis, alpha, M);
            vsgl__fresnel_ratio(&P, n, ov, axis, fres);
            const float none[3] = {0.0f, 1.0f, 0.0f};
            float w, w2;
            double hv = vsgl__halfvec_glossy(&v, v3_make(0, 0, 0), n, ov, axis, alpha, VSGL__HV_LOBES, fres, &w) * M[0];
            double hv0 = vsgl__halfvec_glossy(&v, v3_make(0, 0, 0), n, ov, axis, alpha, VSGL__HV_LOBES, none, &w2) * M[0];
            double want = quadrature_brdf(&P, o, cen, l, var);
            double e = fabs(hv / want - 1.0), e0 = fabs(hv0 / want - 1.0);
            if (getenv("VSGL_TEST_VERBOSE"))
                printf("    cos view %.2f, %.0f alpha off, l.z %.2f: quadrature %.4g, half-vector %.4g (%+.1f %%, weight "
                       "%.2f), with the axis's Fresnel %+.1f %%\n", co, offs[k], l[2], want, hv,
                       100.0 * (hv / want - 1.0), w, 100.0 * (hv0 / want - 1.0));
            if (w < 1.0f)
                continue; /* the planar model's share */
            worst = e > worst ? e : worst;
            worst_without = e0 > worst_without ? e0 : worst_without;
        }
    *worst_out = worst;
    *worst_without_out = worst_without;
}

VT_TEST(halfvec_glossy_takes_fresnel_per_direction_at_grazing_views)
{
    for (int b4 = 0; b4 < 2; ++b4) {
        double worst, worst_without;
        grazing_case(b4 ? VSGL_MATERIAL_FLAG_BLENDER_4 : 0u, &worst, &worst_without);
        if (getenv("VSGL_TEST_VERBOSE"))
            printf("    %s: worst %.3f (with the axis's Fresnel: %.3f)\n", b4 ? "Blender 4" : "Blender 3", worst,
                   worst_without);
        VT_CHECK(worst < 0.15, "Blender %d: half-vector model off the exact BRDF by %.3f at grazing views", 3 + b4, worst);
        VT_CHECK(worst_without > 0.3, "Blender %d: the axis's Fresnel off by only %.3f (the test lost its point)", 3 + b4,
                 worst_without);
    }
}

/* A polished corridor floor seen from 0.6 m at 15 m (cos_o 0.04) reflects
 * the lit end wall 4.4 m away: wall clusters as wide as a preview lattice
 * makes them (variance 0.06-0.09 m^2, sigma 0.25-0.3 m) side by side
 * across the wall. At this view the half vector's slope (o + l).t / (o +
 * l).n changes fast and not linearly across such a cluster, and
 * linearised at the cluster's centre the model gave a cluster 0.75 m to
 * the side 100-700x the light quadrature gives it (the corridor preview's
 * floor row before the wall twice Cycles'). Each cluster's error is taken
 * against the light of the one straight ahead at its height. */
VT_TEST(halfvec_glossy_holds_wide_clusters_at_grazing_views)
{
    const double alpha = 0.09, wy = 4.44, co = 0.04;
    const double x[3] = {0.0, 0.0, 0.0}, o[3] = {0.0, -sqrt(1.0 - co * co), co};
    const double mzs[3] = {0.5, 0.76, 1.49}, mxs[5] = {0.0, 0.37, -0.55, 0.74, -0.92}, vars[2] = {0.061, 0.09};
    vsgl_vec3 ov = {(float)o[0], (float)o[1], (float)o[2]};
    vsgl_asg lobe;
    v3 axis;
    const float M = receiver_lobe((float)alpha, ov, &lobe, &axis);
    const float none[3] = {0.0f, 1.0f, 0.0f};
    double worst = 0.0, worst_sum = 0.0;
    for (int vi = 0; vi < 2; ++vi)
        for (int zi = 0; zi < 3; ++zi) {
            double centre = 0.0, sum_hv = 0.0, sum_q = 0.0;
            for (int xi = 0; xi < 5; ++xi) {
                vsgl_vsgl v = patch(v3_make((float)mxs[xi], (float)wy, (float)mzs[zi]), v3_make(0.0f, -1.0f, 0.0f),
                                    (float)vars[vi]);
                float w;
                double hv = vsgl__halfvec_glossy(&v, v3_make(0, 0, 0), v3_make(0, 0, 1), v3_make(ov.x, ov.y, ov.z),
                                                 axis, (float)alpha, VSGL__HV_LOBES, none, &w) * M;
                double want = quadrature(alpha, x, o, mxs[xi], wy, mzs[zi], vars[vi]);
                if (xi == 0)
                    centre = want;
                double e = fabs(hv - want) / centre;
                if (getenv("VSGL_TEST_VERBOSE"))
                    printf("    var %.3f, %.2f m up, %+.2f m aside: quadrature %.4g, half-vector %.4g (weight %.2f): "
                           "off by %.3f of the cluster ahead\n", vars[vi], mzs[zi], mxs[xi], want, hv, w, e);
                if (w > 0.0f)
                    worst = e > worst ? e : worst;
                sum_hv += hv;
                sum_q += want;
            }
            double es = fabs(sum_hv / sum_q - 1.0);
            worst_sum = es > worst_sum ? es : worst_sum;
        }
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    worst: one cluster %.3f of the one ahead; a row of five %.3f\n", worst, worst_sum);
    VT_CHECK(worst < 0.15, "a wide cluster at a grazing view off quadrature by %.3f of the cluster ahead", worst);
    VT_CHECK(worst_sum < 0.2, "a row of wide clusters at a grazing view off quadrature by %.3f", worst_sum);
}
