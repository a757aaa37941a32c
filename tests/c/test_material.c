/* The exact BRDF (material.c): parameters, an independent double-precision
 * reference, reciprocity, white-furnace energy and GlossCol. */
#include "harness.h"
#include "scene/material.h"
#include "vsgl/lobes.h"

#include <stdlib.h>
#include <string.h>

static const double PI = 3.14159265358979323846;

static v3 rand_dir_hemi(vt_rng *r)
{
    double u = vt_uniform(r), v = vt_uniform(r);
    double z = u, s = sqrt(fmax(0.0, 1.0 - z * z)), ph = 2.0 * PI * v;
    return v3_make((float)(s * cos(ph)), (float)(s * sin(ph)), (float)z);
}

/* Independent reference: Cycles 3.x Principled specular closure written
 * from the formulas (Walter et al. 2007 GGX, separable Smith, exact
 * dielectric Fresnel normalised between F0 and 1), frame n = +Z, t = +X. */
static double ref_fresnel(double c, double eta)
{
    double g2 = eta * eta - 1.0 + c * c;
    if (g2 <= 0)
        return 1.0;
    double g = sqrt(g2);
    double A = (g - c) / (g + c), B = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    return 0.5 * A * A * (1.0 + B * B);
}
static double ref_lambda(double ax, double ay, const double w[3])
{
    double a2 = (ax * ax * w[0] * w[0] + ay * ay * w[1] * w[1]) / (w[2] * w[2]);
    return 0.5 * (-1.0 + sqrt(1.0 + a2));
}
/* f(i,o) cos(i) of the glossy lobe for colour channel with F0 = f0c */
static double ref_glossy_hc(double ax, double ay, double f0c, double f0_dielectric,
                            const double i[3], const double o[3], int height_correlated)
{
    if (i[2] <= 0 || o[2] <= 0)
        return 0;
    double h[3] = {i[0] + o[0], i[1] + o[1], i[2] + o[2]};
    double l = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    for (int k = 0; k < 3; ++k)
        h[k] /= l;
    double e = (h[0] / ax) * (h[0] / ax) + (h[1] / ay) * (h[1] / ay) + h[2] * h[2];
    double D = 1.0 / (PI * ax * ay * e * e);
    double li = ref_lambda(ax, ay, i), lo = ref_lambda(ax, ay, o);
    double G = height_correlated ? 1.0 / (1.0 + li + lo) : 1.0 / (1.0 + li) / (1.0 + lo);
    double F = f0c;
    if (f0_dielectric > 0) {
        double s = sqrt(f0_dielectric), eta = (1 + s) / (1 - s);
        double F0 = ((eta - 1) / (eta + 1)) * ((eta - 1) / (eta + 1));
        double FH = (ref_fresnel(i[0] * h[0] + i[1] * h[1] + i[2] * h[2], eta) - F0) / (1 - F0);
        F = f0c * (1 - FH) + FH;
    }
    return F * D * G / (4.0 * i[2] * o[2]) * i[2];
}

/* Blender 3.x's separable shadowing */
static double ref_glossy(double ax, double ay, double f0c, double f0_dielectric, const double i[3], const double o[3])
{
    return ref_glossy_hc(ax, ay, f0c, f0_dielectric, i, o, 0);
}

VT_TEST(material_params_follow_cycles_principled)
{
    vsgl_material m;
    memset(&m, 0, sizeof m);
    m.base_color[0] = 0.8f; m.base_color[1] = 0.4f; m.base_color[2] = 0.2f;
    m.metallic = 0.25f; m.roughness = 0.5f; m.specular_f0 = 0.04f; m.anisotropy = 0.5f;
    vsgl_brdf_params p;
    vsgl__material_params(&m, &p);
    double aspect = sqrt(1.0 - 0.9 * 0.5);
    VT_CHECK_REL(p.alpha_x, 0.25 / aspect, 1e-6, "aniso 0.5 rough 0.5");
    VT_CHECK_REL(p.alpha_y, 0.25 * aspect, 1e-6, "aniso 0.5 rough 0.5");
    VT_CHECK_REL(p.diffuse[0], 0.8 * 0.75, 1e-6, "metallic 0.25");
    VT_CHECK_REL(p.f0[1], 0.04 * 0.75 + 0.4 * 0.25, 1e-6, "metallic 0.25");
    VT_CHECK_REL(p.eta, 1.5, 1e-5, "F0 0.04 -> IOR 1.5");
    VT_CHECK(p.glossy == 1, "glossy flag");
    m.metallic = 0; m.specular_f0 = 0; m.roughness = 0;
    vsgl__material_params(&m, &p);
    VT_CHECK(p.glossy == 0, "no specular, no metal");
    VT_CHECK(p.alpha_x >= VSGL_ALPHA_MIN && p.alpha_y >= VSGL_ALPHA_MIN, "alpha floor %g %g", p.alpha_x, p.alpha_y);
    float gc[3];
    vsgl__glossy_color(&p, v3_make(0, 0, 1), v3_make(0, 0, 1), gc);
    VT_CHECK(gc[0] == 0 && gc[1] == 0 && gc[2] == 0, "GlossCol of a pure diffuse is 0");
    m.metallic = 1;
    vsgl__material_params(&m, &p);
    vsgl__glossy_color(&p, v3_make(0, 0, 1), v3_make(0, 0, 1), gc);
    VT_CHECK(gc[0] == 1 && gc[1] == 1 && gc[2] == 1, "GlossCol of Principled in Blender 3.4 is white (measured)");
}

VT_TEST(material_brdf_matches_double_reference)
{
    vt_rng r = {7};
    const float roughs[] = {0.05f, 0.2f, 0.5f, 1.0f};
    const float anisos[] = {0.0f, 0.7f};
    const float metals[] = {0.0f, 0.6f, 1.0f};
    double worst = 0;
    for (int hc = 0; hc < 2; ++hc) /* Blender 3.x, then 4.x+ (VSGL_MATERIAL_FLAG_BLENDER_4) */
    for (unsigned a = 0; a < 4; ++a)
        for (unsigned b = 0; b < 2; ++b)
            for (unsigned c = 0; c < 3; ++c) {
                vsgl_material m;
                memset(&m, 0, sizeof m);
                m.flags = hc ? VSGL_MATERIAL_FLAG_BLENDER_4 : 0;
                m.base_color[0] = 0.9f; m.base_color[1] = 0.5f; m.base_color[2] = 0.1f;
                m.roughness = roughs[a]; m.anisotropy = anisos[b]; m.metallic = metals[c];
                m.specular_f0 = 0.05f;
                vsgl_brdf_params p;
                vsgl__material_params(&m, &p);
                double ar = (double)roughs[a] * roughs[a], asp = sqrt(1.0 - 0.9 * anisos[b]);
                double ax = fmin(ar / asp, 1.0), ay = ar * asp; /* Cycles saturates alphas */
                for (int k = 0; k < 400; ++k) {
                    v3 wi = rand_dir_hemi(&r), wo = rand_dir_hemi(&r);
                    if (wi.z < 0.02f || wo.z < 0.02f)
                        continue;
                    float d[3], g[3];
                    vsgl__brdf_eval(&p, v3_make(0, 0, 1), v3_make(1, 0, 0), wi, wo, d, g);
                    double i[3] = {wi.x, wi.y, wi.z}, o[3] = {wo.x, wo.y, wo.z};
                    for (int ch = 0; ch < 3; ++ch) {
                        double f0c = 0.05 * (1 - metals[c]) + m.base_color[ch] * metals[c];
                        double want = ref_glossy_hc(ax, ay, f0c, 0.05, i, o, hc);
                        double wd = m.base_color[ch] * (1 - metals[c]) / PI * i[2];
                        double e = fabs(g[ch] - want) / fmax(want, 1e-6);
                        if (e > worst)
                            worst = e;
                        VT_CHECK_REL(g[ch], want, 2e-4, "hc %d rough %g aniso %g metal %g ch %d wi (%g %g %g) wo (%g %g %g)",
                                     hc, roughs[a], anisos[b], metals[c], ch, wi.x, wi.y, wi.z, wo.x, wo.y, wo.z);
                        VT_CHECK_REL(d[ch], wd, 1e-6, "diffuse ch %d", ch);
                    }
                }
            }
    printf("    worst relative difference to the double reference: %.3g\n", worst);
}

VT_TEST(material_brdf_is_reciprocal)
{
    vt_rng r = {11};
    vsgl_material m;
    memset(&m, 0, sizeof m);
    m.base_color[0] = m.base_color[1] = m.base_color[2] = 0.7f;
    m.roughness = 0.35f; m.anisotropy = 0.8f; m.metallic = 0.3f; m.specular_f0 = 0.04f;
    vsgl_brdf_params p;
    vsgl__material_params(&m, &p);
    v3 n = v3_normalize(v3_make(0.2f, -0.3f, 0.9f)), t, b;
    v3_basis(n, &t, &b);
    for (int k = 0; k < 2000; ++k) {
        v3 l1 = rand_dir_hemi(&r), l2 = rand_dir_hemi(&r);
        v3 wi = v3_add(v3_add(v3_scale(t, l1.x), v3_scale(b, l1.y)), v3_scale(n, l1.z));
        v3 wo = v3_add(v3_add(v3_scale(t, l2.x), v3_scale(b, l2.y)), v3_scale(n, l2.z));
        if (l1.z < 0.01f || l2.z < 0.01f)
            continue;
        float d1[3], g1[3], d2[3], g2[3];
        vsgl__brdf_eval(&p, n, t, wi, wo, d1, g1);
        vsgl__brdf_eval(&p, n, t, wo, wi, d2, g2);
        /* f(i,o) = f(o,i): divide out the cosine */
        VT_CHECK_REL(g1[0] / l1.z, g2[0] / l2.z, 1e-4, "wi.n %g wo.n %g", l1.z, l2.z);
        VT_CHECK_REL(d1[1] / l1.z, d2[1] / l2.z, 1e-5, "diffuse");
    }
    float d[3], g[3];
    vsgl__brdf_eval(&p, n, t, v3_neg(n), n, d, g);
    VT_CHECK(d[0] == 0 && g[0] == 0, "light below the surface gives 0");
}

/* White furnace: directional albedo of each lobe by quadrature over wi
 * (stratified uniform hemisphere, independent of the BRDF's sampling). */
static void albedo(const vsgl_brdf_params *p, v3 wo, int n, double out_d[3], double out_g[3])
{
    for (int c = 0; c < 3; ++c)
        out_d[c] = out_g[c] = 0;
    for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
            /* midpoint rule in (cos theta, phi): d omega = dz dphi */
            double z = (a + 0.5) / n, ph = 2 * PI * (b + 0.5) / n, s = sqrt(1 - z * z);
            v3 wi = v3_make((float)(s * cos(ph)), (float)(s * sin(ph)), (float)z);
            float d[3], g[3];
            vsgl__brdf_eval(p, v3_make(0, 0, 1), v3_make(1, 0, 0), wi, wo, d, g);
            for (int c = 0; c < 3; ++c) {
                out_d[c] += d[c];
                out_g[c] += g[c];
            }
        }
    for (int c = 0; c < 3; ++c) {
        out_d[c] *= 2 * PI / ((double)n * n);
        out_g[c] *= 2 * PI / ((double)n * n);
    }
}

VT_TEST(material_white_furnace_energy_at_most_one)
{
    const float roughs[] = {0.3f, 0.5f, 0.8f, 1.0f};
    const float views[] = {1.0f, 0.7f, 0.3f, 0.1f};
    int n = getenv("VSGL_TEST_QUICK") ? 300 : 600;
    for (unsigned a = 0; a < 4; ++a)
        for (unsigned v = 0; v < 4; ++v) {
            vsgl_material m;
            memset(&m, 0, sizeof m);
            m.base_color[0] = m.base_color[1] = m.base_color[2] = 1.0f;
            m.roughness = roughs[a];
            m.metallic = 1.0f; /* F = 1 everywhere: the lobe's own energy */
            vsgl_brdf_params p;
            vsgl__material_params(&m, &p);
            v3 wo = v3_make(sqrtf(1 - views[v] * views[v]), 0, views[v]);
            double ad[3], ag[3];
            albedo(&p, wo, n, ad, ag);
            /* same quadrature on the double reference */
            double want = 0, ar = (double)roughs[a] * roughs[a];
            double o[3] = {wo.x, wo.y, wo.z};
            for (int ia = 0; ia < n; ++ia)
                for (int ib = 0; ib < n; ++ib) {
                    double z = (ia + 0.5) / n, ph = 2 * PI * (ib + 0.5) / n, s = sqrt(1 - z * z);
                    double i[3] = {s * cos(ph), s * sin(ph), z};
                    want += ref_glossy(ar, ar, 1.0, 0.0, i, o);
                }
            want *= 2 * PI / ((double)n * n);
            VT_CHECK(ag[0] <= 1.0 + 1e-3, "GGX albedo %.5f > 1: rough %g cos_o %g", ag[0], roughs[a], views[v]);
            VT_CHECK_REL(ag[0], want, 1e-3, "GGX albedo vs double reference: rough %g cos_o %g", roughs[a], views[v]);
            m.metallic = 0.0f;
            m.specular_f0 = 0.0f;
            m.base_color[0] = 0.6f;
            vsgl__material_params(&m, &p);
            albedo(&p, wo, n, ad, ag);
            VT_CHECK_REL(ad[0], 0.6, 2e-3, "Lambert albedo rough %g cos_o %g", roughs[a], views[v]);
            VT_CHECK(ag[0] == 0.0, "no glossy without specular: %g", ag[0]);
        }
}

/* The glossy directional-albedo table (stratified importance sampling)
 * against the midpoint quadrature above, rough enough for the quadrature
 * to converge; anisotropic lobes averaged over the azimuth. */
VT_TEST(material_glossy_albedo_table_matches_quadrature)
{
    const float roughs[] = {0.4f, 0.6f, 0.8f};
    int n = getenv("VSGL_TEST_QUICK") ? 200 : 400;
    double worst = 0.0;
    for (unsigned a = 0; a < 3; ++a)
        for (int kind = 0; kind < 3; ++kind) { /* dielectric, metal, anisotropic metal */
            vsgl_material m;
            memset(&m, 0, sizeof m);
            m.base_color[0] = 0.9f; m.base_color[1] = 0.6f; m.base_color[2] = 0.3f;
            m.roughness = roughs[a];
            m.specular_f0 = 0.04f;
            m.metallic = kind > 0 ? 1.0f : 0.0f;
            m.anisotropy = kind == 2 ? 0.6f : 0.0f;
            vsgl_brdf_params p;
            vsgl__material_params(&m, &p);
            vsgl_albedo_table t;
            vsgl__glossy_albedo_table(&p, &t);
            const int ks[] = {1, 4, 8, 12, 16};
            for (int q = 0; q < 5; ++q) {
                float c = (float)ks[q] / (VSGL__ALBEDO_N - 1), s = sqrtf(1 - c * c);
                double want[3] = {0, 0, 0};
                int az = kind == 2 ? 8 : 1;
                for (int k = 0; k < az; ++k) {
                    double ph = 2 * PI * (k + 0.5) / az, ad[3], ag[3];
                    albedo(&p, v3_make((float)(s * cos(ph)), (float)(s * sin(ph)), c), n, ad, ag);
                    for (int ch = 0; ch < 3; ++ch)
                        want[ch] += ag[ch] / az;
                }
                for (int ch = 0; ch < 3; ++ch) {
                    double got = vsgl__glossy_albedo(&t, ch, c), e = fabs(got - want[ch]);
                    worst = fmax(worst, e / fmax(want[ch], 0.02));
                    /* 32 x 32 importance samples: ~1 % error, ~3 % at grazing incidence
                     * (where the quick 200^2 quadrature is itself ~1 % off) */
                    VT_CHECK(e <= (c < 0.1f ? 0.05 : 0.015) * want[ch] + 1e-3,
                             "rough %g kind %d cos %g ch %d: table %.4f quadrature %.4f",
                             roughs[a], kind, c, ch, got, want[ch]);
                }
            }
        }
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    worst relative difference %.4f\n", worst);
    /* not the Fresnel term alone: a rough metal reflects well below F at normal incidence */
    vsgl_material m;
    memset(&m, 0, sizeof m);
    m.base_color[0] = m.base_color[1] = m.base_color[2] = 0.8f;
    m.metallic = 1.0f;
    m.roughness = 0.8f;
    vsgl_brdf_params p;
    vsgl__material_params(&m, &p);
    vsgl_albedo_table t;
    vsgl__glossy_albedo_table(&p, &t);
    VT_CHECK(vsgl__glossy_albedo(&t, 0, 1.0f) < 0.5f, "rough metal albedo %g (F = 0.8)", vsgl__glossy_albedo(&t, 0, 1.0f));
}

/* Blender 4.x+ diffuse base weight: 1 - the albedo of the dielectric
 * specular layer alone (F0 = specular_f0, white) divided by the same lobe's
 * albedo with F = 1 (single scattering's shadowing loss compensated, as
 * Cycles' albedo scaling; matched against Cycles 5.0.1's DiffCol in
 * tests/blender/cycles_ref.py), against the quadrature of the exact BRDF;
 * 3.x materials and metals keep weight 1. */
VT_TEST(material_blender4_diffuse_weight_is_one_minus_dielectric_albedo)
{
    int n = getenv("VSGL_TEST_QUICK") ? 200 : 400;
    const float roughs[] = {0.3f, 0.6f};
    for (unsigned a = 0; a < 2; ++a) {
        vsgl_material m;
        memset(&m, 0, sizeof m);
        m.base_color[0] = 0.8f; m.base_color[1] = 0.4f; m.base_color[2] = 0.2f;
        m.roughness = roughs[a];
        m.specular_f0 = 0.04f;
        m.metallic = 0.25f;
        m.flags = VSGL_MATERIAL_FLAG_BLENDER_4;
        vsgl_albedo_table t;
        vsgl_brdf_params p;
        vsgl__material_params(&m, &p);
        vsgl__glossy_albedo_table(&p, &t);
        vsgl__dielectric_albedo_table(&m, &t);
        /* the layer alone, by quadrature */
        vsgl_material d = m;
        d.metallic = 0.0f;
        d.base_color[0] = d.base_color[1] = d.base_color[2] = 0.0f;
        vsgl_brdf_params pd, pw;
        vsgl__material_params(&d, &pd);
        vsgl_material wm = d;
        wm.metallic = 1.0f;
        wm.base_color[0] = wm.base_color[1] = wm.base_color[2] = 1.0f;
        vsgl__material_params(&wm, &pw);
        const float cs[] = {1.0f, 0.75f, 0.5f, 0.25f};
        for (int q = 0; q < 4; ++q) {
            double ad[3], ag[3], aw[3];
            v3 wo = v3_make(sqrtf(1 - cs[q] * cs[q]), 0, cs[q]);
            albedo(&pd, wo, n, ad, ag);
            albedo(&pw, wo, n, ad, aw);
            double want = 1.0 - ag[0] / aw[0], got = vsgl__diffuse_view_weight(&t, cs[q]);
            VT_CHECK(fabs(got - want) < 3e-3, "rough %g cos %g: weight %.4f, 1 - quadrature %.4f", roughs[a], cs[q], got, want);
        }
        /* the diffuse base's emitted power: 2 int (1 - E/E1) mu dmu, trapezoid over 33 quadrature points */
        double pw_sum = 0.0;
        for (int q = 0; q <= 32; ++q) {
            float mu = q == 0 ? 1e-3f : q / 32.0f;
            double ad[3], ag[3], aw[3];
            v3 wo = v3_make(sqrtf(1 - mu * mu), 0, mu);
            albedo(&pd, wo, n / 2, ad, ag);
            albedo(&pw, wo, n / 2, ad, aw);
            pw_sum += (q == 0 || q == 32 ? 0.5 : 1.0) * (1.0 - ag[0] / aw[0]) * mu;
        }
        VT_CHECK(fabs(t.diffuse_power - 2.0 * pw_sum / 32.0) < 3e-3, "rough %g: diffuse power %.4f, quadrature %.4f",
                 roughs[a], t.diffuse_power, 2.0 * pw_sum / 32.0);
        VT_CHECK(t.diffuse_power < 0.97f && t.diffuse_power > 0.85f, "rough %g: diffuse power %g", roughs[a], t.diffuse_power);
        /* without the flag (Blender 3.x), and for a metal: nothing taken off */
        m.flags = 0;
        vsgl__dielectric_albedo_table(&m, &t);
        VT_CHECK(vsgl__diffuse_view_weight(&t, 0.5f) == 1.0f && t.diffuse_power == 1.0f, "3.x material: weight %g",
                 vsgl__diffuse_view_weight(&t, 0.5f));
        m.flags = VSGL_MATERIAL_FLAG_BLENDER_4;
        m.metallic = 1.0f;
        vsgl__dielectric_albedo_table(&m, &t);
        VT_CHECK(vsgl__diffuse_view_weight(&t, 0.5f) == 1.0f, "metal: weight %g", vsgl__diffuse_view_weight(&t, 0.5f));
    }
}

/* "Multiscatter GGX" (VSGL_MATERIAL_FLAG_MULTISCATTER): seen from any view,
 * a white conductor reflects all the light it receives (white furnace:
 * the single-scatter albedo over incident directions times the view's
 * compensation is 1), whatever its roughness, where single scattering
 * loses up to ~70 %; a coloured one less than its F_avg (multi-bounce
 * Fresnel). Matched against Cycles 5.0.1 in tests/blender/cycles_ref.py. */
VT_TEST(material_multiscatter_white_furnace)
{
    const float roughs[] = {0.3f, 0.6f, 0.8f, 1.0f};
    int n = getenv("VSGL_TEST_QUICK") ? 200 : 300;
    for (unsigned a = 0; a < 4; ++a) {
        vsgl_material m;
        memset(&m, 0, sizeof m);
        m.base_color[0] = 1.0f; m.base_color[1] = 0.5f; m.base_color[2] = 1.0f;
        m.metallic = 1.0f;
        m.roughness = roughs[a];
        m.flags = VSGL_MATERIAL_FLAG_BLENDER_4 | VSGL_MATERIAL_FLAG_MULTISCATTER;
        vsgl_brdf_params p;
        vsgl__material_params(&m, &p);
        const float cs[] = {1.0f, 0.5f, 0.25f};
        for (int k = 0; k < 3; ++k) {
            double ad[3], ag[3];
            albedo(&p, v3_make(sqrtf(1 - cs[k] * cs[k]), 0, cs[k]), n, ad, ag);
            double e = ag[0] * vsgl__ms_scale(&p, 0, cs[k]), g = ag[1] * vsgl__ms_scale(&p, 1, cs[k]);
            VT_CHECK(fabs(e - 1.0) < 0.01, "rough %g view cos %g: white albedo %.4f (single scattering %.4f)",
                     roughs[a], cs[k], e, ag[0]);
            VT_CHECK(g < p.favg[1] && g > ag[1], "rough %g view cos %g: F 0.5 albedo %.4f (F_avg %.3f, single %.4f)",
                     roughs[a], cs[k], g, p.favg[1], ag[1]);
        }
    }
}

/* The tabulated row means of the white GGX albedo (ggx_albedo.c) are the
 * trapezoid rule over the albedo table itself. */
VT_TEST(material_ggx_white_albedo_mean_matches_its_table)
{
    for (int j = 0; j < 32; ++j) {
        float r = (float)j / 31.0f;
        double acc = 0.0;
        for (int k = 0; k < 32; ++k) {
            float mu = (float)k / 31.0f;
            float e = vsgl__ggx_white_albedo(r, k == 0 ? 0.0f : mu); /* node k (its first cosine is 0.02) */
            acc += (k == 0 || k == 31 ? 0.5 : 1.0) * e * mu;
        }
        double want = 2.0 * acc / 31.0, got = vsgl__ggx_white_albedo_avg(r);
        VT_CHECK(fabs(got - want) < 2e-5, "roughness %g: mean %.7f, trapezoid %.7f", r, got, want);
        VT_CHECK(j == 0 || got < vsgl__ggx_white_albedo_avg((float)(j - 1) / 31.0f) + 1e-6, "roughness %g: not decreasing", r);
    }
}

/* vsgl__ms_scale3 is vsgl__ms_scale of each channel, bit for bit (the
 * receiver's setup takes the three at once), with and without the flag. */
VT_TEST(material_ms_scale3_equals_ms_scale_per_channel)
{
    vt_rng rng = {4242};
    size_t bad = 0;
    for (int i = 0; i < 3000; ++i) {
        vsgl_material m;
        memset(&m, 0, sizeof m);
        for (int c = 0; c < 3; ++c)
            m.base_color[c] = (float)vt_uniform(&rng);
        m.metallic = (float)vt_uniform(&rng);
        m.roughness = (float)vt_uniform(&rng);
        m.specular_f0 = 0.08f * (float)vt_uniform(&rng);
        m.anisotropy = i % 3 ? 0.0f : (float)vt_uniform(&rng);
        m.flags = i % 2 ? VSGL_MATERIAL_FLAG_BLENDER_4 | VSGL_MATERIAL_FLAG_MULTISCATTER : VSGL_MATERIAL_FLAG_BLENDER_4;
        vsgl_brdf_params p;
        vsgl__material_params(&m, &p);
        float cv = (float)(vt_uniform(&rng) * 1.2 - 0.1), got[3];
        vsgl__ms_scale3(&p, cv, got);
        for (int c = 0; c < 3; ++c) {
            float want = vsgl__ms_scale(&p, c, cv);
            if (memcmp(&want, &got[c], sizeof want) && bad++ < 4)
                vt_note("    ", "material %d channel %d cos %.9g: %.9g vs %.9g", i, c, cv, want, got[c]);
        }
    }
    VT_CHECK(bad == 0, "%zu channels differ", bad);
}

/* Blender 3.x's Principled diffuse (VSGL_MATERIAL_FLAG_BURLEY), written from
 * Cycles' split form (bsdf_principled_diffuse: the Lambert part darkened by
 * (1 - FL/2)(1 - FV/2) plus the retro-reflection RR (FL + FV + FL FV (RR -
 * 1)), RR = 2 r (l.h)^2), which the library computes as Burley's 2012
 * product; over Lambert's 1/pi. */
static double ref_burley(double r, const double l[3], const double v[3])
{
    double h[3] = {l[0] + v[0], l[1] + v[1], l[2] + v[2]};
    double hn = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    double lh = (l[0] * h[0] + l[1] * h[1] + l[2] * h[2]) / hn;
    double fl = pow(1.0 - l[2], 5.0), fv = pow(1.0 - v[2], 5.0), rr = 2.0 * r * lh * lh;
    return (1.0 - 0.5 * fl) * (1.0 - 0.5 * fv) + rr * (fl + fv + fl * fv * (rr - 1.0));
}

/* vsgl__brdf_eval's diffuse part with the flag is base (1 - metallic) / pi
 * cos_i times that reference, and reciprocal; without the flag, Lambert. */
VT_TEST(material_burley_diffuse_matches_cycles_split_form)
{
    vt_rng rng = {777};
    double worst = 0.0;
    for (int k = 0; k < 4000; ++k) {
        vsgl_material m;
        memset(&m, 0, sizeof m);
        m.base_color[0] = 0.8f, m.base_color[1] = 0.5f, m.base_color[2] = 0.2f;
        m.metallic = (float)(0.5 * vt_uniform(&rng));
        m.roughness = (float)vt_uniform(&rng);
        m.specular_f0 = 0.04f;
        m.flags = VSGL_MATERIAL_FLAG_BURLEY;
        vsgl_brdf_params p;
        vsgl__material_params(&m, &p);
        v3 wi = rand_dir_hemi(&rng), wo = rand_dir_hemi(&rng), n = v3_make(0, 0, 1), t = v3_make(1, 0, 0);
        double l[3] = {wi.x, wi.y, wi.z}, v[3] = {wo.x, wo.y, wo.z};
        float d[3], g[3], d2[3], g2[3];
        vsgl__brdf_eval(&p, n, t, wi, wo, d, g);
        vsgl__brdf_eval(&p, n, t, wo, wi, d2, g2);
        for (int c = 0; c < 3; ++c) {
            double want = m.base_color[c] * (1.0 - m.metallic) / PI * wi.z * ref_burley(m.roughness, l, v);
            worst = fmax(worst, fabs(d[c] - want) / fmax(want, 1e-6));
            /* reciprocal: f(i, o) = f(o, i), so d / cos_i = d2 / cos_o */
            VT_CHECK_REL(d[c] / wi.z, d2[c] / wo.z, 1e-4, "reciprocity, sample %d", k);
        }
    }
    VT_CHECK(worst < 2e-4, "worst relative error %.3g against the split form", worst);
    vsgl_material m;
    memset(&m, 0, sizeof m);
    m.base_color[0] = m.base_color[1] = m.base_color[2] = 0.5f;
    m.roughness = 0.9f;
    vsgl_brdf_params p;
    vsgl__material_params(&m, &p);
    float d[3], g[3];
    v3 wi = v3_normalize(v3_make(0.9f, 0.0f, 0.2f)), wo = v3_normalize(v3_make(-0.9f, 0.1f, 0.25f));
    vsgl__brdf_eval(&p, v3_make(0, 0, 1), v3_make(1, 0, 0), wi, wo, d, g);
    VT_CHECK_REL(d[0], 0.5 / PI * wi.z, 1e-6, "without the flag the diffuse base is Lambert's");
}

/* vsgl__burley_albedo(r, mu), the cosine-weighted mean of the reference over
 * the hemisphere seen from mu, against 2-D quadrature (midpoint in cos_l
 * and azimuth), over roughness and view; and its range (Burley darkens
 * smooth surfaces at grazing views and brightens rough ones). */
VT_TEST(material_burley_albedo_matches_quadrature)
{
    const int NC = 200, NP = 128;
    double worst = 0.0;
    for (int ir = 0; ir <= 10; ++ir) {
        double r = ir / 10.0;
        for (int im = 0; im <= 20; ++im) {
            double mu = im == 0 ? 0.02 : im / 20.0, sv = sqrt(1.0 - mu * mu);
            double v[3] = {sv, 0.0, mu}, acc = 0.0;
            for (int i = 0; i < NC; ++i) {
                /* cos_l = sqrt(u): cosine-weighted strata */
                double u = (i + 0.5) / NC, c = sqrt(u), s = sqrt(1.0 - u);
                for (int k = 0; k < NP; ++k) {
                    double ph = 2.0 * PI * (k + 0.5) / NP;
                    double l[3] = {s * cos(ph), s * sin(ph), c};
                    acc += ref_burley(r, l, v);
                }
            }
            double want = acc / ((double)NC * NP), got = vsgl__burley_albedo((float)r, (float)mu);
            worst = fmax(worst, fabs(got - want) / want);
        }
    }
    VT_CHECK(worst < 5e-4, "worst relative error %.3g against quadrature", worst);
    VT_CHECK(vsgl__burley_albedo(0.9f, 0.2f) > 1.15f && vsgl__burley_albedo(0.9f, 0.2f) < 1.25f,
             "a rough surface seen at grazing reflects more than Lambert's: %.4f", vsgl__burley_albedo(0.9f, 0.2f));
    VT_CHECK(vsgl__burley_albedo(0.0f, 0.2f) < 0.9f, "a smooth one less: %.4f", vsgl__burley_albedo(0.0f, 0.2f));
}
