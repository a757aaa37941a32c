/* The per-light budget's measurement (budget.h): how much light each light
 * sends, after one bounce, onto what the camera sees. A sparse grid of
 * camera rays finds receivers; each light's small probe RSM gives VPLs; the
 * unshadowed one-bounce gather between them (clamped cosines at both ends,
 * 1/d^2 clamped by the VPL's footprint) is the light's weight. Cheap: a
 * 32-ray-wide camera grid and 16^2 texels per RSM face, ~1 ms per light. */
#include "render/budget.h"
#include "render/render_internal.h"
#include "fit/vsgl_set.h"
#include "rsm/rsm.h"
#include "scene/camera.h"
#include "scene/material.h"
#include "core/context.h"
#include "math/constants.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define VSGL__BUDGET_CAMERA 32u /* camera probe rays across the image */

typedef struct probe_receivers {
    uint32_t count;
    float *px, *py, *pz, *nx, *ny, *nz;
} probe_receivers;

static void receivers_free(probe_receivers *r)
{
    free(r->px);
    memset(r, 0, sizeof *r);
}

/* The glossy lobe a receiver's material has there (textures read at the hit): 1 and its roughness
 * (sqrt of the smaller GGX alpha) if it contributes. */
static int receiver_glossy(const vsgl_scene *scene, const vsgl_hit *hit, uint32_t material, float *roughness)
{
    uint32_t n = 0;
    const vsgl_material *mats = vsgl__scene_materials(scene, &n);
    if (material >= n)
        return 0;
    vsgl_material m = mats[material];
    if (vsgl__scene_textured(scene)) {
        float in[VSGL__SURF_N];
        vsgl__scene_inputs(scene, hit, 0.0f, in);
        vsgl__material_with_inputs(&mats[material], in, &m);
    }
    vsgl_brdf_params bp;
    vsgl__material_params(&m, &bp);
    if (!bp.glossy)
        return 0;
    float a = bp.alpha_x < bp.alpha_y ? bp.alpha_x : bp.alpha_y;
    *roughness = sqrtf(a > 0.0f ? a : 0.0f);
    return 1;
}

/* Receivers: what a sparse grid of camera rays hits (normals facing the camera); *view (may be NULL)
 * what they see. */
static vsgl_result camera_receivers(vsgl_context *ctx, const vsgl_scene *scene, probe_receivers *out,
                                    vsgl_budget_view *view)
{
    memset(out, 0, sizeof *out);
    if (view) {
        memset(view, 0, sizeof *view);
        view->sharpest_roughness = 1.0f;
    }
    const vsgl_camera *cam = vsgl__scene_camera(scene);
    vsgl_camera_model m;
    vsgl__camera_model(cam, &m);
    uint32_t nx = cam->width < VSGL__BUDGET_CAMERA ? cam->width : VSGL__BUDGET_CAMERA;
    uint32_t ny = (uint32_t)lround((double)nx * cam->height / (cam->width ? cam->width : 1));
    if (ny < 1)
        ny = 1;
    if (ny > cam->height)
        ny = cam->height;
    uint32_t n = nx * ny;
    v3 *org = malloc(n * sizeof *org), *dir = malloc(n * sizeof *dir);
    float *tmin = malloc(n * sizeof *tmin), *tmax = malloc(n * sizeof *tmax);
    vsgl_hit *hits = malloc(n * sizeof *hits);
    out->px = malloc(6 * (size_t)n * sizeof(float));
    vsgl_result r = VSGL_OK;
    if (!org || !dir || !tmin || !tmax || !hits || !out->px) {
        r = vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "render: out of memory for the light budget's probe");
        receivers_free(out);
        goto done;
    }
    out->py = out->px + n;
    out->pz = out->py + n;
    out->nx = out->pz + n;
    out->ny = out->nx + n;
    out->nz = out->ny + n;
    for (uint32_t j = 0; j < ny; ++j)
        for (uint32_t i = 0; i < nx; ++i) {
            uint32_t k = j * nx + i;
            vsgl__camera_ray(&m, ((float)i + 0.5f) * (float)cam->width / (float)nx,
                             ((float)j + 0.5f) * (float)cam->height / (float)ny, &org[k], &dir[k], &tmin[k],
                             &tmax[k]);
        }
    vsgl__scene_intersect_many(scene, n, org, dir, tmin, tmax, 1, hits);
    for (uint32_t k = 0; k < n; ++k) {
        if (hits[k].triangle == VSGL__HIT_NONE)
            continue;
        vsgl_surface sf;
        vsgl__scene_surface(scene, &hits[k], dir[k], &sf);
        float rough = 1.0f;
        if (view && receiver_glossy(scene, &hits[k], sf.material, &rough)) {
            ++view->glossy;
            if (rough < view->sharpest_roughness)
                view->sharpest_roughness = rough;
        }
        uint32_t c = out->count++;
        out->px[c] = sf.position.x; out->py[c] = sf.position.y; out->pz[c] = sf.position.z;
        out->nx[c] = sf.normal.x; out->ny[c] = sf.normal.y; out->nz[c] = sf.normal.z;
    }
    if (view)
        view->receivers = out->count;
done:
    free(org); free(dir); free(tmin); free(tmax); free(hits);
    return r;
}

vsgl_result vsgl__budget_view(vsgl_context *ctx, const vsgl_scene *scene, vsgl_budget_view *view)
{
    probe_receivers rc;
    vsgl_result r = camera_receivers(ctx, scene, &rc, view);
    receivers_free(&rc);
    return r;
}

/* One light's weight: the probe RSM's VPLs gathered at the receivers
 * (their reflected power if the camera sees nothing), and in *footprint
 * the fraction of its lit texels that send at least VSGL__FOOTPRINT_TEXEL
 * of the mean lit texel's light onto the receivers (1 without receivers;
 * `sent`: scratch of rsm->count doubles, NULL: footprint 1). */
static double light_weight(const vsgl_scene *scene, const vsgl_rsm *rsm, int32_t estimator,
                           const probe_receivers *rc, double *sent, double *footprint)
{
    v3 origin = vsgl__rsm_origin(rsm);
    double total = 0.0, reflected = 0.0;
    size_t lit = 0;
    *footprint = 1.0;
    for (size_t t = 0; t < rsm->count; ++t) {
        vsgl_moments mo[2];
        if (sent)
            sent[t] = -1.0; /* not lit */
        if (!vsgl__vpl_moments(scene, rsm, t, origin, estimator, mo))
            continue;
        double p = mo[0].weight + mo[1].weight; /* reflected power, W (RGB sum) */
        if (!(p > 0.0 && p < INFINITY))
            continue;
        reflected += p;
        ++lit;
        /* clamped-cosine emission P/pi cos, 1/d^2 clamped by the footprint */
        float vx = rsm->pos[0][t], vy = rsm->pos[1][t], vz = rsm->pos[2][t];
        float mx = rsm->nrm[0][t], my = rsm->nrm[1][t], mz = rsm->nrm[2][t];
        float a = rsm->area[t] > 1e-12f && rsm->area[t] < INFINITY ? rsm->area[t] : 1e-12f;
        float e = 0.0f;
        for (uint32_t i = 0; i < rc->count; ++i) {
            float dx = rc->px[i] - vx, dy = rc->py[i] - vy, dz = rc->pz[i] - vz;
            float d2 = dx * dx + dy * dy + dz * dz;
            float ce = mx * dx + my * dy + mz * dz;          /* |d| cos at the VPL */
            float cr = -(rc->nx[i] * dx + rc->ny[i] * dy + rc->nz[i] * dz); /* |d| cos at the receiver */
            ce = ce > 0.0f ? ce : 0.0f;
            cr = cr > 0.0f ? cr : 0.0f;
            /* cos_e cos_r / max(d^2, a) = ce cr / (d^2 max(d^2, a)) */
            e += ce * cr / ((d2 > 1e-30f ? d2 : 1e-30f) * (d2 > a ? d2 : a));
        }
        total += p * (double)e;
        if (sent)
            sent[t] = p * (double)e;
    }
    if (rc->count == 0)
        return reflected;
    if (sent && lit && total > 0.0 && total < INFINITY) {
        double limit = VSGL__FOOTPRINT_TEXEL * total / (double)lit;
        size_t in = 0;
        for (size_t t = 0; t < rsm->count; ++t)
            in += sent[t] >= limit;
        *footprint = (double)in / (double)lit;
    }
    return total / (VSGL__PI_D * (double)rc->count);
}

vsgl_result vsgl__budget_weights(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                                 vsgl_light_share *sh, uint32_t *receivers)
{
    uint32_t light_count = 0;
    const vsgl_light *lights = vsgl__scene_lights(scene, &light_count);
    uint32_t probe = s->rsm_resolution < VSGL__BUDGET_PROBE ? s->rsm_resolution : VSGL__BUDGET_PROBE;
    probe_receivers rc;
    vsgl_result r = camera_receivers(ctx, scene, &rc, NULL);
    if (r != VSGL_OK)
        return r;
    *receivers = rc.count;
    double *sent = malloc(6 * (size_t)probe * probe * sizeof *sent);
    if (!sent) {
        receivers_free(&rc);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "render: out of memory for the light budget's probe");
    }
    for (uint32_t l = 0; l < light_count && r == VSGL_OK; ++l) {
        const vsgl_light *L = &lights[l];
        sh[l].weight = 0.0;
        sh[l].footprint = 1.0;
        sh[l].faces = 1;
        if (!(L->power * (L->color[0] + L->color[1] + L->color[2]) > 0.0f))
            continue;
        vsgl_rsm rsm;
        r = vsgl__rsm_build(ctx, scene, l, probe, &rsm);
        if (r != VSGL_OK)
            break;
        sh[l].faces = rsm.faces ? rsm.faces : 1;
        if (rsm.total_flux[0] + rsm.total_flux[1] + rsm.total_flux[2] > 0.0)
            sh[l].weight = light_weight(scene, &rsm, s->sharpness_estimator, &rc,
                                        rsm.count <= 6 * (size_t)probe * probe ? sent : NULL, &sh[l].footprint);
        vsgl__rsm_free(&rsm);
    }
    free(sent);
    receivers_free(&rc);
    return r;
}
