/* VPL lobes -> moment sums -> VSGL parameters (poster Sec. 2, FIS Sec. 3,
 * with the errata of docs/references.md §3: the mean direction averages the
 * *filtered* directions). */
#include "fit/vsgl_set.h"
#include "scene/material.h"
#include "math/sg_internal.h"
#include "vsgl/lobes.h"

#include <stdlib.h>
#include <string.h>

vsgl_result vsgl__vsgl_set_push(vsgl_vsgl_set *set, const vsgl_vsgl *v)
{
    if (set->count == set->capacity) {
        size_t cap = set->capacity ? set->capacity * 2 : 64;
        vsgl_vsgl *p = realloc(set->items, cap * sizeof *p);
        if (!p)
            return VSGL_ERROR_OUT_OF_MEMORY;
        set->items = p;
        set->capacity = cap;
    }
    set->items[set->count++] = *v;
    return VSGL_OK;
}

void vsgl__vsgl_set_free(vsgl_vsgl_set *set)
{
    free(set->items);
    memset(set, 0, sizeof *set);
}

v3 vsgl__rsm_origin(const vsgl_rsm *rsm)
{
    for (size_t t = 0; t < rsm->count; ++t)
        if (rsm->material[t] != VSGL__RSM_EMPTY)
            return v3_make(rsm->pos[0][t], rsm->pos[1][t], rsm->pos[2][t]);
    return v3_make(0.0f, 0.0f, 0.0f);
}

void vsgl__moments_add(vsgl_moments *acc, const vsgl_moments *m, double scale)
{
    acc->weight += scale * m->weight;
    for (int c = 0; c < 3; ++c) {
        acc->power[c] += scale * m->power[c];
        acc->dir[c] += scale * m->dir[c];
        acc->pos[c] += scale * m->pos[c];
        acc->nrm[c] += scale * m->nrm[c];
    }
    acc->pos2 += scale * m->pos2;
}

/* `footprint`: the texel's area on the surface (m^2). A VPL stands for a
 * patch, not a point: its own second moment about its centre, a/(2 pi) for
 * a disk of area a, is added so that small clusters (down to one texel)
 * keep the spread of the surface they represent instead of becoming
 * singular point lights (the brute force clamps the same singularity by
 * the footprint). */
static void fill(vsgl_moments *m, const double power[3], v3 axis, float mean_length, v3 rel, v3 n,
                 float footprint)
{
    double w = power[0] + power[1] + power[2];
    m->weight = w;
    for (int c = 0; c < 3; ++c)
        m->power[c] = power[c];
    m->dir[0] = w * mean_length * axis.x;
    m->dir[1] = w * mean_length * axis.y;
    m->dir[2] = w * mean_length * axis.z;
    m->pos[0] = w * rel.x;
    m->pos[1] = w * rel.y;
    m->pos[2] = w * rel.z;
    m->pos2 = w * ((double)rel.x * rel.x + (double)rel.y * rel.y + (double)rel.z * rel.z +
                   (footprint > 0.0f && footprint < INFINITY ? footprint * 0.15915494309189535 : 0.0));
    m->nrm[0] = w * n.x;
    m->nrm[1] = w * n.y;
    m->nrm[2] = w * n.z;
}

int vsgl__vpl_moments(const vsgl_scene *scene, const vsgl_rsm *rsm, size_t t, v3 origin,
                      int32_t estimator, vsgl_moments out[2])
{
    memset(out, 0, 2 * sizeof *out);
    uint32_t mat = rsm->material[t];
    if (mat == VSGL__RSM_EMPTY)
        return 0;
    double flux[3] = {rsm->flux[0][t], rsm->flux[1][t], rsm->flux[2][t]};
    if (!(flux[0] + flux[1] + flux[2] > 0.0))
        return 0;
    uint32_t material_count = 0;
    const vsgl_material *materials = vsgl__scene_materials(scene, &material_count);
    if (mat >= material_count)
        return 0;
    vsgl_material tm;
    vsgl__rsm_material(rsm, materials, t, &tm);
    vsgl_brdf_params bp;
    vsgl__material_params(&tm, &bp);

    v3 p = v3_make(rsm->pos[0][t], rsm->pos[1][t], rsm->pos[2][t]);
    v3 n = v3_make(rsm->nrm[0][t], rsm->nrm[1][t], rsm->nrm[2][t]);
    v3 wi = v3_make(rsm->wi[0][t], rsm->wi[1][t], rsm->wi[2][t]);
    v3 rel = v3_sub(p, origin);
    float foot = rsm->area ? rsm->area[t] : 0.0f;
    int any = 0;

    /* Diffuse lobe: Phi R_d G(w; n, l_d) / A(l_d). */
    /* (Blender 4.x+ materials: the dielectric layer dims the diffuse
     * reflection in each direction; the lobe keeps its shape, its power
     * takes the cosine-weighted mean of the dimming) */
    /* (Blender 3.x's Burley diffuse, VSGL_MATERIAL_FLAG_BURLEY: the power
     * it reflects from light arriving at cos_i, vsgl__burley_albedo; the
     * lobe keeps Lambert's shape) */
    const vsgl_albedo_table *alb = vsgl__scene_glossy_albedo(scene, mat);
    const double kd = vsgl__scene_diffuse_power(scene, mat, &bp, v3_dot(wi, n));
    double pd[3];
    for (int c = 0; c < 3; ++c)
        pd[c] = flux[c] * bp.diffuse[c] * kd;
    if (pd[0] + pd[1] + pd[2] > 0.0) {
        float ld = vsgl_sg_cosine_sharpness();
        fill(&out[VSGL__LOBE_DIFFUSE], pd, n, vsgl_mean_length_from_sharpness(ld, estimator), rel, n, foot);
        any = 1;
    }
    /* Specular lobe: Phi R_s G(w; axis, l) / A(.), with axis and l the
     * in-plane mean and spread of the warped NDF cut at the horizon
     * (vsgl__warp_ndf_sg_emitted; the poster's reflect(wi, n) and
     * l_h / (4 |wi.n|) are several times too sharp at grazing incidence), and
     * R_s the lobe's directional albedo at the incident angle (Fresnel,
     * shadowing and the lobe's spread; the poster's R_s is the Fresnel term
     * alone, which overstates rough lobes: 0.8 against 0.44 for a metal of
     * roughness 0.8 at normal incidence, 0.61 against 0.07 for a rough
     * dielectric at grazing incidence). */
    if (bp.glossy) {
        float cos_i = v3_dot(wi, n);
        double ps[3];
        for (int c = 0; c < 3; ++c)
            ps[c] = flux[c] * vsgl__glossy_albedo(alb, c, cos_i);
        if (cos_i > 0.0f && ps[0] + ps[1] + ps[2] > 0.0) {
            float alpha = sqrtf(bp.alpha_x * bp.alpha_y);
            vsgl_sg ndf, warped;
            vsgl_ndf_to_sg(&n, alpha, VSGL_NDF_GGX, &ndf);
            float f0 = (bp.f0[0] + bp.f0[1] + bp.f0[2]) * (1.0f / 3.0f);
            vsgl__warp_ndf_sg_emitted_fresnel(&ndf, &wi, bp.eta, f0, &warped);
            fill(&out[VSGL__LOBE_SPECULAR], ps, warped.axis,
                 vsgl_mean_length_from_sharpness(warped.sharpness, estimator), rel, n, foot);
            any = 1;
        }
    }
    return any;
}

int vsgl__moments_to_vsgl(const vsgl_moments *m, v3 origin, int32_t estimator,
                          uint32_t light, uint32_t lobe, vsgl_vsgl *out)
{
    memset(out, 0, sizeof *out);
    if (!(m->weight > 0.0) || !(m->power[0] + m->power[1] + m->power[2] > 0.0))
        return 0;
    double inv = 1.0 / m->weight;
    double dx = m->dir[0] * inv, dy = m->dir[1] * inv, dz = m->dir[2] * inv;
    double r = sqrt(dx * dx + dy * dy + dz * dz);
    if (r > 1.0)
        r = 1.0;
    if (r > 0.0) {
        out->axis = v3_make((float)(dx / r), (float)(dy / r), (float)(dz / r));
    } else {
        out->axis = v3_make(0.0f, 0.0f, 1.0f); /* isotropic: any axis */
    }
    out->sharpness = r > 0.0 ? vsgl_sharpness_from_mean_length((float)r, estimator) : 0.0f;
    double mx = m->pos[0] * inv, my = m->pos[1] * inv, mz = m->pos[2] * inv;
    out->mean = v3_make((float)(origin.x + mx), (float)(origin.y + my), (float)(origin.z + mz));
    /* Positions of VPLs lie on surfaces: the spread is 2-D, so the variance
     * per axis is half the total (docs/references.md §4). Cancellation can make it
     * slightly negative: clamp. */
    double var = (m->pos2 * inv - (mx * mx + my * my + mz * mz)) * 0.5;
    out->variance = var > 0.0 ? (float)var : 0.0f;
    for (int c = 0; c < 3; ++c)
        out->power[c] = (float)m->power[c];
    double nx = m->nrm[0] * inv, ny = m->nrm[1] * inv, nz = m->nrm[2] * inv;
    double nl = sqrt(nx * nx + ny * ny + nz * nz);
    out->coherence = (float)(nl < 1.0 ? nl : 1.0);
    out->normal = nl > 0.0 ? v3_make((float)(nx / nl), (float)(ny / nl), (float)(nz / nl)) : out->axis;
    out->light = light;
    out->part = VSGL__PART_NONE;
    out->lobe = lobe;
    return 1;
}

float vsgl__vsgl_lobe_integral(const vsgl_vsgl *v)
{
    float a = vsgl_sg_integral(v->sharpness);
    if (v->lobe != VSGL__LOBE_SPECULAR)
        return a;
    /* a glossy emitter sends all its power above its surface: the SG's
     * part that dips below the mean normal's plane (a rough or grazing
     * lobe's, 10-40 %) is light no receiver gets, so the lobe is scaled to
     * carry the power above it. A cluster's normals spread as its coherence
     * falls: the plane holds that much. */
    float f = vsgl__sg_fraction_above(v->sharpness, v3_dot(v->axis, v->normal));
    return a * (1.0f - v->coherence * (1.0f - fmaxf(f, 0.25f)));
}
