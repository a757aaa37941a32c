/* Principled subset -> BRDF parameters and the exact BRDF (Lambert + GGX).
 *
 * What Cycles does and what we chose (docs/units.md, "Materials"):
 * - Alphas: alpha = roughness^2; anisotropy a gives aspect = sqrt(1 - 0.9 a),
 *   alpha_x = alpha / aspect, alpha_y = alpha * aspect (Blender 3.x and 4.x
 *   use the same mapping; both clamp alpha to <= 1).
 * - Fresnel: Blender 3.x's Principled specular closure
 *   (MICROFACET_GGX_FRESNEL): F = cspec0 (1 - FH) + FH with
 *   FH = (F_dielectric(h.i, eta) - F0) / (1 - F0), eta = (1 + sqrt(F0)) /
 *   (1 - sqrt(F0)) from the dielectric F0, cspec0 = lerp(F0, base_color,
 *   metallic). Specular tint is not modelled (taken as 0).
 * - Shadowing: separable Smith G1(i) G1(o) for GGX (Cycles 3.x), or with
 *   VSGL_MATERIAL_FLAG_BLENDER_4 the height-correlated form 1/(1 + L(i) +
 *   L(o)) of Cycles 4.x; the two agree at normal view and differ in
 *   directional albedo by < 0.1 % at alpha 0.09, 1 % at alpha 0.25, 16 % at
 *   alpha 1 (view cosine 0.3).
 * - Diffuse: base_color (1 - metallic), not attenuated by the specular
 *   layer (3.x); Lambert, or with VSGL_MATERIAL_FLAG_BURLEY Burley's
 *   (Blender 3.x's Principled: retro-reflection, grazing darkening; Cycles'
 *   bsdf_principled_diffuse). 4.x's is Lambert attenuated by the specular
 *   albedo; a Diffuse BSDF with roughness 0 is Lambert.
 * - Single-scatter GGX only ("GGX" distribution). Multiscatter GGX adds the
 *   energy single scattering loses (up to ~25 % at roughness 1).
 */
#include "material.h"
#include "math/constants.h"
#include "math/fresnel.h"

#include "vsgl/lobes.h"

#include <math.h>
#include <string.h>


static float saturate(float x) { return x != x ? 0.0f : clampf(x, 0.0f, 1.0f); }

void vsgl__material_params(const vsgl_material *m, vsgl_brdf_params *out)
{
    float metallic = saturate(m->metallic);
    float rough = saturate(m->roughness);
    float aniso = saturate(m->anisotropy);
    float f0 = saturate(m->specular_f0);
    float a = rough * rough;
    float aspect = sqrtf(1.0f - 0.9f * aniso);
    out->alpha_x = clampf(a / aspect, VSGL_ALPHA_MIN, 1.0f);
    out->alpha_y = clampf(a * aspect, VSGL_ALPHA_MIN, 1.0f);
    for (int c = 0; c < 3; ++c) {
        float base = saturate(m->base_color[c]);
        out->diffuse[c] = base * (1.0f - metallic);
        out->f0[c] = f0 * (1.0f - metallic) + base * metallic;
    }
    /* Cycles 3.x allocates the specular closure when Specular or Metallic
     * is above its cutoff (1e-5). */
    out->glossy = (f0 > 0.08f * 1e-5f || metallic > 1e-5f) ? 1 : 0;
    out->height_correlated = (m->flags & VSGL_MATERIAL_FLAG_BLENDER_4) ? 1 : 0;
    out->multiscatter = (m->flags & VSGL_MATERIAL_FLAG_MULTISCATTER) && out->glossy ? 1 : 0;
    out->metallic = metallic;
    out->f0_dielectric = f0;
    for (int c = 0; c < 3; ++c)
        out->base[c] = saturate(m->base_color[c]);
    float eavg = out->multiscatter ? vsgl__ggx_white_albedo_avg(sqrtf(sqrtf(out->alpha_x * out->alpha_y))) : 1.0f;
    for (int c = 0; c < 3; ++c) {
        out->favg[c] = out->f0[c] + (1.0f - out->f0[c]) * (1.0f / 21.0f);
        /* multi-bounce Fresnel: light leaving after k bounces carries F^k */
        out->fms[c] = out->favg[c] * eavg / (1.0f - out->favg[c] * (1.0f - eavg));
    }
    float s0 = sqrtf(fminf(f0, 0.99f));
    out->eta = (1.0f + s0) / (1.0f - s0);
    out->burley = (m->flags & VSGL_MATERIAL_FLAG_BURLEY) ? rough : -1.0f;
}

/* E[.] over the other direction l, cosine-weighted (pdf cos_l / pi), with
 * s = l.v: E[FL] = 1/21, E[s] = 2 mu / 3, E[s FL] = mu / 84, E[s^2 FL] =
 * mu^2 / 252 + (1 - mu^2) 11 / 504 (Beta integrals of c^j (1 - c)^5 and
 * the azimuthal mean of s^2, c^2 mu^2 + (1 - c^2)(1 - mu^2) / 2). With
 * k = a + r s, a = r - 1/2: E[Fd] = 1 + FV E[k] + E[k FL] + FV E[k^2 FL]. */
float vsgl__burley_albedo(float r, float mu)
{
    mu = clampf(mu, 0.0f, 1.0f);
    const float a = r - 0.5f, m2 = mu * mu;
    float fv = 1.0f - mu;
    fv *= fv * fv * fv * fv;
    const float ek = a + r * (2.0f / 3.0f) * mu;
    const float ekl = a * (1.0f / 21.0f) + r * mu * (1.0f / 84.0f);
    const float ek2l = a * a * (1.0f / 21.0f) + a * r * mu * (1.0f / 42.0f) +
                       r * r * (m2 * (1.0f / 252.0f) + (1.0f - m2) * (11.0f / 504.0f));
    return 1.0f + fv * ek + ekl + fv * ek2l;
}

/* Unpolarised Fresnel reflectance of a dielectric interface (Cycles'
 * fresnel_dielectric_cos) at cosine |cosi|; 1 under total internal reflection. */
static float fresnel_dielectric(float cosi, float eta)
{
    return vsgl__fresnel_dielectric(fabsf(cosi), eta);
}

/* Cycles 3.x's Fresnel shape between f0 and 1 at i.h = cos_ih: the
 * dielectric Fresnel normalised, (F(i.h) - F0) / (1 - F0) in [0, 1]; 0 for
 * eta <= 1 (the constant f0). The glossy factors below blend f0 to 1 by it. */
static float fresnel_shape(const vsgl_brdf_params *p, float cos_ih)
{
    if (!(p->eta > 1.0f))
        return 0.0f;
    float F0 = fresnel_dielectric(1.0f, p->eta);
    return clampf((fresnel_dielectric(cos_ih, p->eta) - F0) / (1.0f - F0), 0.0f, 1.0f);
}

/* GGX Smith Lambda for direction (x, y, z) in the tangent frame, z > 0;
 * G1 = 1 / (1 + Lambda). */
static float ggx_lambda(float ax, float ay, float x, float y, float z)
{
    float a2t2 = (ax * ax * x * x + ay * ay * y * y) / (z * z);
    return 0.5f * (sqrtf(1.0f + a2t2) - 1.0f);
}

void vsgl__brdf_eval(const vsgl_brdf_params *p, v3 n, v3 t, v3 wi, v3 wo,
                     float diffuse_out[3], float glossy_out[3])
{
    float ci = v3_dot(wi, n), co = v3_dot(wo, n);
    for (int c = 0; c < 3; ++c)
        diffuse_out[c] = glossy_out[c] = 0.0f;
    if (!(ci > 0.0f && co > 0.0f))
        return;
    float kd = ci * (1.0f / VSGL__PI);
    if (p->burley >= 0.0f) /* Blender 3.x's Principled diffuse */
        kd *= vsgl__burley_factor(p->burley, ci, co, v3_dot(wi, wo));
    for (int c = 0; c < 3; ++c)
        diffuse_out[c] = p->diffuse[c] * kd;
    if (!p->glossy)
        return;
    /* tangent frame; an unusable tangent falls back to an arbitrary one
     * (only matters for anisotropic materials) */
    v3 tx = v3_normalize(v3_sub(t, v3_scale(n, v3_dot(t, n))));
    v3 ty;
    if (tx.x == 0.0f && tx.y == 0.0f && tx.z == 0.0f)
        v3_basis(n, &tx, &ty);
    else
        ty = v3_cross(n, tx);
    v3 h = v3_normalize(v3_add(wi, wo));
    float hx = v3_dot(h, tx), hy = v3_dot(h, ty), hz = v3_dot(h, n);
    if (!(hz > 0.0f))
        return;
    float ax = p->alpha_x, ay = p->alpha_y;
    float sx = hx / ax, sy = hy / ay;
    float q = sx * sx + sy * sy + hz * hz;
    float D = 1.0f / (VSGL__PI * ax * ay * q * q);
    float li = ggx_lambda(ax, ay, v3_dot(wi, tx), v3_dot(wi, ty), ci);
    float lo = ggx_lambda(ax, ay, v3_dot(wo, tx), v3_dot(wo, ty), co);
    float G = p->height_correlated ? 1.0f / (1.0f + li + lo) : 1.0f / ((1.0f + li) * (1.0f + lo));
    /* f cos(i) = F D G / (4 cos(o)) */
    float common = D * G / (4.0f * co);
    if (!(common < INFINITY))
        common = 3.0e38f;
    float FH = fresnel_shape(p, v3_dot(wi, h));
    for (int c = 0; c < 3; ++c)
        glossy_out[c] = (p->f0[c] * (1.0f - FH) + FH) * common;
}

float vsgl__fresnel_shape_at(const vsgl_brdf_params *p, v3 o, v3 i)
{
    return fresnel_shape(p, v3_dot(i, v3_normalize(v3_add(i, o))));
}

void vsgl__specular_factor(const vsgl_brdf_params *p, v3 n, v3 o, v3 i, float alpha, float out[3])
{
    if (!(v3_dot(n, o) > 0.0f) || !(v3_dot(n, i) > 0.0f) || !p->glossy) {
        out[0] = out[1] = out[2] = 0.0f;
        return;
    }
    vsgl__specular_factor_fh(p, n, o, i, alpha, vsgl__fresnel_shape_at(p, o, i), out);
}

void vsgl__specular_factor_fh(const vsgl_brdf_params *p, v3 n, v3 o, v3 i, float alpha, float fh, float out[3])
{
    out[0] = out[1] = out[2] = 0.0f;
    float co = v3_dot(n, o), ci = v3_dot(n, i);
    if (!(co > 0.0f) || !(ci > 0.0f) || !p->glossy)
        return;
    co = co < 1.0f ? co : 1.0f;
    ci = ci < 1.0f ? ci : 1.0f;
    float a = alpha > 1e-4f ? (alpha < 1.0f ? alpha : 1.0f) : 1e-4f, a2 = a * a;
    float so = sqrtf(a2 + (1.0f - a2) * co * co), si = sqrtf(a2 + (1.0f - a2) * ci * ci);
    /* G / (4 co): height-correlated 2 ci co / (ci so + co si), separable G1(i) G1(o), G1(c) = 2c / (c + s) */
    float g4 = p->height_correlated ? ci / (2.0f * (ci * so + co * si)) : ci / ((ci + si) * (co + so));
    for (int c = 0; c < 3; ++c)
        out[c] = (p->f0[c] * (1.0f - fh) + fh) * g4;
}

void vsgl__fresnel_ratio(const vsgl_brdf_params *p, v3 n, v3 o, v3 i, float out[3])
{
    if (!p->glossy || !(p->eta > 1.0f) || !(v3_dot(n, o) > 0.0f) || !(v3_dot(n, i) > 0.0f)) {
        out[0] = 0.0f;
        out[1] = 1.0f;
        out[2] = 0.0f;
        return;
    }
    vsgl__fresnel_ratio_fh(p, n, o, i, vsgl__fresnel_shape_at(p, o, i), out);
}

void vsgl__fresnel_ratio_fh(const vsgl_brdf_params *p, v3 n, v3 o, v3 i, float fh, float out[3])
{
    out[0] = 0.0f;
    out[1] = 1.0f;
    out[2] = 0.0f;
    if (!p->glossy || !(p->eta > 1.0f) || !(v3_dot(n, o) > 0.0f) || !(v3_dot(n, i) > 0.0f))
        return;
    float f0 = (p->f0[0] + p->f0[1] + p->f0[2]) * (1.0f / 3.0f);
    float F0 = fresnel_dielectric(1.0f, p->eta);
    if (!(F0 < 1.0f))
        return;
    float fa = f0 * (1.0f - fh) + fh; /* the factor at the axis */
    if (!(fa > 1e-6f))
        return;
    /* f0 (1 - FH(l)) + FH(l) with FH(l) = (F(l.h) - F0) / (1 - F0), over fa */
    out[0] = p->eta;
    out[1] = (f0 - (1.0f - f0) * F0 / (1.0f - F0)) / fa;
    out[2] = (1.0f - f0) / ((1.0f - F0) * fa);
}

void vsgl__glossy_color(const vsgl_brdf_params *p, v3 n, v3 wo, float out[3])
{
    float g = p->glossy ? 1.0f : 0.0f;
    out[0] = out[1] = out[2] = g;
    if (!p->glossy || !p->height_correlated)
        return;
    /* Blender 4.x+: the Fresnel reflectance towards the viewer, the
     * dielectric's exact one and the metal's Schlick one, mixed by metallic */
    float c = clampf(v3_dot(n, wo), 0.0f, 1.0f);
    float fd = p->f0_dielectric > 0.0f && p->eta > 1.0f ? fresnel_dielectric(c, p->eta) : p->f0_dielectric;
    float m = 1.0f - c, m5 = m * m * m * m * m;
    for (int k = 0; k < 3; ++k)
        out[k] = (1.0f - p->metallic) * fd + p->metallic * (p->base[k] + (1.0f - p->base[k]) * m5);
}

void vsgl__glossy_albedo_table(const vsgl_brdf_params *p, vsgl_albedo_table *out)
{
    enum { S = 32 };
    memset(out, 0, sizeof *out);
    if (!p->glossy)
        return;
    const v3 n = v3_make(0.0f, 0.0f, 1.0f), t = v3_make(1.0f, 0.0f, 0.0f);
    const float ax = p->alpha_x, ay = p->alpha_y;
    for (int k = 0; k < VSGL__ALBEDO_N; ++k) {
        double ci = k == 0 ? 0.01 : (double)k / (VSGL__ALBEDO_N - 1);
        double si = sqrt(fmax(0.0, 1.0 - ci * ci));
        double acc[3] = {0.0, 0.0, 0.0};
        for (int a = 0; a < S; ++a)
            for (int b = 0; b < S; ++b) {
                /* wi's azimuth (anisotropic lobes only): a golden-ratio sequence
                 * over the samples, independent of the normal's strata */
                double gi = (a * S + b) * 0.6180339887498949;
                double phi_i = p->alpha_x == p->alpha_y ? 0.0 : 2.0 * VSGL__PI_D * (gi - floor(gi));
                v3 wi = v3_make((float)(si * cos(phi_i)), (float)(si * sin(phi_i)), (float)ci);
                /* GGX normal with pdf D(h) (h.n): a stretched slope */
                double u = (a + 0.5) / S, v = (b + 0.5) / S;
                double r = sqrt(u / (1.0 - u)), ph = 2.0 * VSGL__PI_D * v;
                double mx = -r * cos(ph) * ax, my = -r * sin(ph) * ay;
                double len = sqrt(mx * mx + my * my + 1.0);
                v3 h = v3_make((float)(mx / len), (float)(my / len), (float)(1.0 / len));
                double ih = v3_dot(wi, h);
                if (!(ih > 0.0))
                    continue;
                v3 wo = v3_sub(v3_scale(h, (float)(2.0 * ih)), wi);
                if (!(wo.z > 0.0f))
                    continue;
                float dif[3], gl[3];
                vsgl__brdf_eval(p, n, t, wo, wi, dif, gl); /* f cos(wo) (reciprocal) */
                double hx = h.x / ax, hy = h.y / ay, q = hx * hx + hy * hy + (double)h.z * h.z;
                double D = 1.0 / (VSGL__PI_D * ax * ay * q * q);
                double pdf = D * h.z / (4.0 * ih); /* of wo */
                for (int c = 0; c < 3; ++c) /* seen from wo (multiple scattering, 4.x+) */
                    acc[c] += gl[c] * vsgl__ms_scale(p, c, wo.z) / pdf;
            }
        for (int c = 0; c < 3; ++c)
            out->a[k][c] = (float)(acc[c] / (S * S));
    }
}

void vsgl__dielectric_albedo_table(const vsgl_material *m, vsgl_albedo_table *t)
{
    memset(t->diel, 0, sizeof t->diel);
    t->diffuse_power = 1.0f;
    if (!(m->flags & VSGL_MATERIAL_FLAG_BLENDER_4) || !(saturate(m->metallic) < 1.0f))
        return;
    vsgl_material d = *m;
    d.metallic = 0.0f;
    d.base_color[0] = d.base_color[1] = d.base_color[2] = 0.0f;
    vsgl_brdf_params bp;
    vsgl__material_params(&d, &bp);
    if (!bp.glossy)
        return;
    vsgl_albedo_table tmp, white;
    if (saturate(m->metallic) > 0.0f)
        vsgl__glossy_albedo_table(&bp, &tmp);
    else
        tmp = *t; /* a dielectric's own glossy lobe is that layer: already in t */
    /* the same lobe with F = 1: what single scattering loses to shadowing */
    vsgl_material w = d;
    w.metallic = 1.0f;
    w.base_color[0] = w.base_color[1] = w.base_color[2] = 1.0f;
    vsgl_brdf_params bw;
    vsgl__material_params(&w, &bw);
    vsgl__glossy_albedo_table(&bw, &white);
    for (int k = 0; k < VSGL__ALBEDO_N; ++k)
        t->diel[k] = clampf(tmp.a[k][0] / fmaxf(white.a[k][0], 1e-6f), 0.0f, 1.0f);
    /* 2 int (1 - diel) mu dmu over the piecewise-linear table, 64 midpoints */
    double acc = 0.0;
    for (int i = 0; i < 64; ++i) {
        float mu = (i + 0.5f) / 64.0f;
        acc += vsgl__diffuse_view_weight(t, mu) * mu;
    }
    t->diffuse_power = (float)(2.0 * acc / 64.0);
}

void vsgl__ms_scale3(const vsgl_brdf_params *p, float cos_view, float out[3])
{
    if (!p->multiscatter) {
        out[0] = out[1] = out[2] = 1.0f;
        return;
    }
    float e1 = vsgl__ggx_white_albedo(sqrtf(sqrtf(p->alpha_x * p->alpha_y)), cos_view);
    e1 = e1 > 0.05f ? e1 : 0.05f;
    for (int c = 0; c < 3; ++c)
        out[c] = 1.0f + p->fms[c] * (1.0f - e1) / e1;
}

float vsgl__ms_scale(const vsgl_brdf_params *p, int channel, float cos_view)
{
    if (!p->multiscatter)
        return 1.0f;
    float e1 = vsgl__ggx_white_albedo(sqrtf(sqrtf(p->alpha_x * p->alpha_y)), cos_view);
    e1 = e1 > 0.05f ? e1 : 0.05f;
    return 1.0f + p->fms[channel] * (1.0f - e1) / e1;
}

float vsgl__diffuse_view_weight(const vsgl_albedo_table *t, float cos_o)
{
    if (!t)
        return 1.0f;
    float x = clampf(cos_o, 0.0f, 1.0f) * (VSGL__ALBEDO_N - 1);
    int k = (int)x;
    if (k >= VSGL__ALBEDO_N - 1)
        return 1.0f - t->diel[VSGL__ALBEDO_N - 1];
    float f = x - (float)k;
    return 1.0f - (t->diel[k] * (1.0f - f) + t->diel[k + 1] * f);
}

float vsgl__glossy_albedo(const vsgl_albedo_table *t, int channel, float cos_i)
{
    float x = clampf(cos_i, 0.0f, 1.0f) * (VSGL__ALBEDO_N - 1);
    int k = (int)x;
    if (k >= VSGL__ALBEDO_N - 1)
        return t->a[VSGL__ALBEDO_N - 1][channel];
    float f = x - (float)k;
    return t->a[k][channel] * (1.0f - f) + t->a[k + 1][channel] * f;
}
