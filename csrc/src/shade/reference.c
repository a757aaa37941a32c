/* Test-only public entries (vsgl/reference.h): RSM copy-out and the
 * brute-force reference pipeline scene -> G-buffer -> RSMs -> gather. */
#include "vsgl/reference.h"

#include "core/context.h"
#include "gbuffer/gbuffer.h"
#include "rsm/rsm.h"
#include "scene/material.h"
#include "shade/brute_force.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

vsgl_result vsgl_reference_rsm(vsgl_context *ctx, const vsgl_scene *scene, uint32_t light,
                               uint32_t res, size_t *count, float *positions, float *normals,
                               float *flux, float *areas, uint32_t *materials)
{
    vsgl__clear_error(ctx);
    if (!scene || !count)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "reference_rsm: %s is NULL", scene ? "count" : "scene");
    vsgl_rsm r;
    vsgl_result rc = vsgl__rsm_build(ctx, scene, light, res, &r);
    if (rc != VSGL_OK)
        return rc;
    *count = r.count;
    for (size_t i = 0; i < r.count; ++i) {
        for (int k = 0; k < 3; ++k) {
            if (positions)
                positions[3 * i + k] = r.pos[k][i];
            if (normals)
                normals[3 * i + k] = r.nrm[k][i];
            if (flux)
                flux[3 * i + k] = r.flux[k][i];
        }
        if (areas)
            areas[i] = r.area[i];
        if (materials)
            materials[i] = r.material[i];
    }
    vsgl__rsm_free(&r);
    return VSGL_OK;
}

vsgl_result vsgl_reference_brdf(const vsgl_material *m, uint32_t count, const float *normals,
                                const float *tangents, const float *wi, const float *wo,
                                float *diffuse, float *glossy)
{
    if (!m || (count && (!normals || !tangents || !wi || !wo)))
        return VSGL_ERROR_INVALID_ARGUMENT;
    vsgl_brdf_params p;
    vsgl__material_params(m, &p);
    for (uint32_t i = 0; i < count; ++i) {
        const float *n = normals + 3 * (size_t)i, *t = tangents + 3 * (size_t)i;
        const float *a = wi + 3 * (size_t)i, *b = wo + 3 * (size_t)i;
        float d[3], g[3];
        vsgl__brdf_eval(&p, v3_make(n[0], n[1], n[2]), v3_make(t[0], t[1], t[2]), v3_make(a[0], a[1], a[2]),
                        v3_make(b[0], b[1], b[2]), d, g);
        for (int c = 0; c < 3; ++c) {
            if (diffuse)
                diffuse[3 * (size_t)i + c] = d[c];
            if (glossy) /* with multiple scattering (4.x+) seen from wo */
                glossy[3 * (size_t)i + c] = g[c] * vsgl__ms_scale(&p, c, n[0] * b[0] + n[1] * b[1] + n[2] * b[2]);
        }
    }
    return VSGL_OK;
}

vsgl_result vsgl_reference_render(vsgl_context *ctx, const vsgl_scene *scene, uint32_t rsm_res,
                                  uint32_t aa, int32_t visibility, float *diffuse_light,
                                  float *glossy_light, float *diffuse_color, float *glossy_color,
                                  vsgl_reference_stats *stats)
{
    vsgl__clear_error(ctx);
    if (!scene)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "reference_render: scene is NULL");
    if (aa == 0)
        aa = 1;
    if (aa > 16 || rsm_res < 1 || rsm_res > 16384)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "reference_render: aa %u (1..16) or rsm_res %u (1..16384)",
                          aa, rsm_res);
    vsgl_reference_stats st;
    memset(&st, 0, sizeof st);
    double t0 = now_s();
    vsgl_gbuffer g;
    vsgl_result rc = vsgl__gbuffer_build(ctx, scene, aa, 0, &g);
    if (rc != VSGL_OK)
        return rc;
    st.seconds_gbuffer = now_s() - t0;
    uint32_t nl = 0;
    vsgl__scene_lights(scene, &nl);
    vsgl_rsm *rsms = calloc(nl ? nl : 1, sizeof *rsms);
    size_t n3 = g.count * 3;
    float *planes = malloc(4 * (n3 ? n3 : 1) * sizeof *planes);
    if (!rsms || !planes) {
        free(rsms);
        free(planes);
        vsgl__gbuffer_free(&g);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "reference_render: out of memory");
    }
    t0 = now_s();
    uint32_t built = 0;
    for (; built < nl && rc == VSGL_OK; ++built) {
        double outward[3]; /* texels facing out of the scene light no receiver: not gathered (a sun's map
                              then covers what is left, as vsgl_render's) */
        rc = vsgl__rsm_build_inward(ctx, scene, built, rsm_res, &rsms[built], outward);
        if (rc != VSGL_OK)
            break;
        const vsgl_rsm *R = &rsms[built];
        st.rsm_bytes += (uint64_t)R->count * (16 * sizeof(float) + sizeof(uint32_t));
        for (int c = 0; c < 3; ++c)
            st.total_flux[c] += R->total_flux[c];
        for (size_t i = 0; i < R->count; ++i)
            st.vpl_count += R->material[i] != VSGL__RSM_EMPTY;
    }
    st.seconds_rsm = now_s() - t0;
    if (rc == VSGL_OK) {
        t0 = now_s();
        rc = vsgl__brute_force_shade(ctx, scene, &g, rsms, nl, visibility, planes, planes + n3,
                                     planes + 2 * n3, planes + 3 * n3);
        st.seconds_gather = now_s() - t0;
    }
    if (rc == VSGL_OK) {
        vsgl__brute_force_resolve(&g, planes, planes + 2 * n3, diffuse_light, diffuse_color);
        vsgl__brute_force_resolve(&g, planes + n3, planes + 3 * n3, glossy_light, glossy_color);
        if (stats)
            *stats = st;
    }
    for (uint32_t i = 0; i < nl; ++i)
        vsgl__rsm_free(&rsms[i]);
    free(rsms);
    free(planes);
    vsgl__gbuffer_free(&g);
    return rc;
}
