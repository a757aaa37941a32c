/* Internal: Principled subset -> BRDF parameters, and the exact BRDF used by
 * the brute-force gather and as the reference for the SG/ASG lobes.
 * Owner: csrc/src/scene (material.c). */
#ifndef VSGL_SCENE_MATERIAL_H
#define VSGL_SCENE_MATERIAL_H

#include "vsgl/scene.h"
#include "math/vec.h"

typedef struct vsgl_brdf_params {
    float diffuse[3];   /* Lambert albedo (DiffCol): base_color * (1 - metallic) */
    float f0[3];        /* specular reflectance at normal incidence (mix of specular_f0 and base_color by metallic) */
    float alpha_x, alpha_y; /* GGX alphas (Cycles' anisotropy mapping), >= VSGL_ALPHA_MIN */
    int glossy;         /* 0 if the specular lobe contributes nothing */
    float eta;          /* IOR shaping the Fresnel curve between f0 and 1 (Cycles 3.x: from the
                         * dielectric F0, also for metals); 1 = constant f0 */
    int height_correlated; /* Smith shadowing 1/(1 + L(i) + L(o)) (Blender 4.x+), else G1(i) G1(o) */
    int multiscatter;   /* VSGL_MATERIAL_FLAG_MULTISCATTER: see vsgl__ms_scale */
    float favg[3];      /* cosine-weighted mean Fresnel per channel (Schlick: f0 + (1 - f0) / 21) */
    float metallic, base[3], f0_dielectric; /* the Principled inputs (GlossCol of Blender 4.x+) */
    float fms[3];       /* the compensation's Fresnel: F_avg E_avg / (1 - F_avg (1 - E_avg)) (Kulla & Conty) */
    float burley;       /* VSGL_MATERIAL_FLAG_BURLEY: the roughness of Blender 3.x's Burley diffuse; < 0: Lambert */
} vsgl_brdf_params;

void vsgl__material_params(const vsgl_material *m, vsgl_brdf_params *out);

/* Exact reflectance times cosine, split into diffuse and glossy RGB parts:
 * f(wi, wo) * max(wi.n, 0), with tangent t for anisotropy. wi, wo unit,
 * pointing away from the surface; both parts are 0 unless wi.n > 0 and
 * wo.n > 0. Glossy is GGX with separable Smith G1(i) G1(o) (height-correlated
 * with VSGL_MATERIAL_FLAG_BLENDER_4) and Blender 3.x's
 * Principled Fresnel (cspec0 blended to white by the normalised dielectric
 * Fresnel); choices and differences to Cycles in docs/units.md. */
void vsgl__brdf_eval(const vsgl_brdf_params *p, v3 n, v3 t, v3 wi, v3 wo,
                     float diffuse_out[3], float glossy_out[3]);

/* Burley's diffuse over Lambert's (VSGL_MATERIAL_FLAG_BURLEY): (1 + k FL)
 * (1 + k FV), k = r (1 + cos_io) - 1/2 (= 2 r (i.h)^2 - 1/2), F = (1 - cos)^5,
 * for cosines ci, co of the two directions with the normal and cos_io
 * between them; vsgl__brdf_eval's diffuse part takes it, and per pair the
 * shading kernel (shade/kernel_impl.h, k_burley: inline, vectorised). */
static inline float vsgl__burley_factor(float r, float ci, float co, float cio)
{
    float fl = 1.0f - clampf(ci, 0.0f, 1.0f), fv = 1.0f - clampf(co, 0.0f, 1.0f);
    const float fl2 = fl * fl, fv2 = fv * fv;
    fl = fl2 * fl2 * fl;
    fv = fv2 * fv2 * fv;
    const float k = r * (1.0f + clampf(cio, -1.0f, 1.0f)) - 0.5f;
    return (1.0f + k * fl) * (1.0f + k * fv);
}
/* vsgl__burley_factor for a receiver of normal n seen from o, lit from the
 * unit direction l (the shading path's SG axis, or towards a cluster). */
static inline float vsgl__burley_towards(float r, v3 n, v3 o, v3 l)
{
    return vsgl__burley_factor(r, v3_dot(n, l), v3_dot(n, o), v3_dot(l, o));
}
/* Its cosine-weighted mean over the other direction's hemisphere, seen from
 * a direction of cosine mu: the diffuse base's directional albedo over
 * Lambert's, in closed form (docs/units.md; e.g. 1.20 at mu = 0.2 and 1.03
 * at mu = 1 for roughness 0.9, 0.78 and 0.98 for roughness 0). The VSGL
 * fit takes it for a VPL's diffuse power at its light's incidence (the
 * lobe keeps Lambert's shape); receivers take the factor itself per pair
 * (the kernel's k_burley). */
float vsgl__burley_albedo(float r, float mu);

/* Directional albedo of the glossy lobe, int f(wi, wo) cos(wo) dwo: the
 * fraction of the power arriving from wi that the lobe reflects (Fresnel,
 * shadowing and the GGX lobe's spread together), per RGB channel, averaged
 * over wi's azimuth about the normal. Tabulated at VSGL__ALBEDO_N cosines
 * cos_k = k / (N - 1) (the first at 0.01) by stratified importance sampling
 * of the GGX normals (32 x 32 samples per cosine, ~2 ms per glossy
 * material). */
#define VSGL__ALBEDO_N 17
typedef struct vsgl_albedo_table {
    float a[VSGL__ALBEDO_N][3];
    /* Blender 4.x+ (VSGL_MATERIAL_FLAG_BLENDER_4): the albedo of the
     * dielectric specular layer alone (white, F0 = specular_f0) over the same
     * lobe's albedo with F = 1 (shadowing loss compensated, as Cycles' albedo
     * scaling), which Cycles takes off the diffuse base seen from a
     * direction; 0 otherwise */
    float diel[VSGL__ALBEDO_N];
    /* the diffuse base's emitted power with that weight, relative to
     * Lambert's: 2 int_0^1 (1 - diel(mu)) mu dmu (1 without the flag) */
    float diffuse_power;
} vsgl_albedo_table;
void vsgl__glossy_albedo_table(const vsgl_brdf_params *p, vsgl_albedo_table *out);
/* Linear interpolation of the table at cos_i in [0, 1]. */
float vsgl__glossy_albedo(const vsgl_albedo_table *t, int channel, float cos_i);
/* The table's dielectric-layer albedo for material m (zero unless m has
 * VSGL_MATERIAL_FLAG_BLENDER_4, a dielectric part and a specular layer);
 * t's glossy part must already be m's (vsgl__glossy_albedo_table). */
void vsgl__dielectric_albedo_table(const vsgl_material *m, vsgl_albedo_table *t);
/* Weight of the diffuse base seen from a direction of cosine cos_o (DiffCol
 * factor): 1 - the dielectric layer's compensated albedo there (Cycles 4.x+
 * Principled: within 0.5 % of 5.0.1's DiffCol at 90, 45 and 20 degree
 * views); 1 for Blender 3.x materials. */
float vsgl__diffuse_view_weight(const vsgl_albedo_table *t, float cos_o);

/* The white single-scatter GGX albedo E1(mu, roughness) (ggx_albedo.c). */
float vsgl__ggx_white_albedo(float roughness, float mu);
/* Its cosine-weighted mean 2 int E1(mu) mu dmu. */
float vsgl__ggx_white_albedo_avg(float roughness);
/* Multiple-scattering energy compensation of the glossy lobe seen from a
 * view direction of cosine cos_view (the direction towards the camera or
 * the previous bounce): 1 + F_avg (1 - E1) / E1 for
 * VSGL_MATERIAL_FLAG_MULTISCATTER materials, else 1. vsgl__brdf_eval does
 * not apply it (its two directions are symmetric); callers that know the
 * view direction do. */
float vsgl__ms_scale(const vsgl_brdf_params *p, int channel, float cos_view);
/* The three channels' vsgl__ms_scale at once (the albedo looked up once). */
void vsgl__ms_scale3(const vsgl_brdf_params *p, float cos_view, float out[3]);

/* GlossCol of Cycles for this material seen from wo: what the GlossInd pass
 * is divided by. Blender 3.x writes the specular closure's weight, i.e.
 * white (1,1,1) whenever the Principled BSDF has a specular lobe (measured:
 * metallic 0.3 or 1, any base colour -> GlossCol = 1) and 0 otherwise; the
 * Fresnel colour stays inside GlossInd. Blender 4.x+ (VSGL_MATERIAL_FLAG_
 * BLENDER_4) writes the Fresnel reflectance towards the viewer (measured in
 * 5.0.1: 0.0899 for a dielectric of IOR 1.5 at 60 degrees, F = 0.0892; a
 * metal within ~1 % of Schlick's F of its base colour): that is written. */
void vsgl__glossy_color(const vsgl_brdf_params *p, v3 n, v3 wo, float out[3]);

/* The smooth factor of the glossy lobe, F G / (4 cos_o), at light direction
 * i (the receiver lobe's axis) seen from o, per channel: the exact BRDF's
 * own Fresnel (Cycles 3.x's dielectric-shaped curve between f0 and 1, not
 * Schlick's: at 55 degrees from a dielectric of F0 0.04 the two are 0.070
 * and 0.054) and shadowing (separable or height-correlated, as the
 * material's flags say). 0 when either direction is below the surface. */
void vsgl__specular_factor(const vsgl_brdf_params *p, v3 n, v3 o, v3 i, float alpha, float out[3]);

/* The dielectric Fresnel term of vsgl__specular_factor towards light
 * direction l over its value towards the lobe's axis i (the grey f0, the
 * mean of p->f0), as A + B F(l.h, eta) with F the exact dielectric
 * Fresnel: out = {eta, A, B}; {0, 1, 0} (the ratio 1) where the
 * material's Fresnel is constant (eta <= 1: f0 alone, as for a metal of
 * specular 0). The half-vector model (shade/halfvec.h) takes it per
 * direction: a grazing view's Fresnel at the axis is several times that of
 * the directions far out in GGX's tail. */
void vsgl__fresnel_ratio(const vsgl_brdf_params *p, v3 n, v3 o, v3 i, float out[3]);

/* The Fresnel shape both take at i seen from o (0 for eta <= 1), so that a
 * receiver that needs both computes it once (shade.c: two dielectric
 * Fresnels, a square root and a normalisation less per glossy receiver);
 * the _fh forms take it and give the same values bit for bit. */
float vsgl__fresnel_shape_at(const vsgl_brdf_params *p, v3 o, v3 i);
void vsgl__specular_factor_fh(const vsgl_brdf_params *p, v3 n, v3 o, v3 i, float alpha, float fh, float out[3]);
void vsgl__fresnel_ratio_fh(const vsgl_brdf_params *p, v3 n, v3 o, v3 i, float fh, float out[3]);

#endif
