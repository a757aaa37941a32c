/* The MRP glossy pass of vsgl_render (proxies.h, docs/mrp.md §4), and the
 * hybrid glossy mode built on it. */
#include "mrp/proxies.h"
#include "mrp/geom.h"
#include "core/context.h"

#include <stdlib.h>
#include <string.h>

/* Proxies, their radiance from this frame's RSMs, and the glossy shading
 * (hybrid: glossy_q the VSGL glossy of the clusters off the proxies). */
static vsgl_result run_pass(vsgl_context *ctx, const vsgl_scene *scene, uint32_t rsm_resolution,
                            vsgl__mrp_proxy_set *set, const vsgl_gbuffer *g, const vsgl_pixel_planes *planes,
                            const float *glossy_q, int lit)
{
    vsgl_result r = VSGL_OK;
    uint32_t light_count = 0;
    (void)vsgl__scene_lights(scene, &light_count);
    for (uint32_t l = 0; l < light_count && r == VSGL_OK && set->count && !lit; ++l) {
        const vsgl_light *L = &vsgl__scene_lights(scene, &light_count)[l];
        if (!(L->power * (L->color[0] + L->color[1] + L->color[2]) > 0.0f))
            continue;
        vsgl_rsm rsm;
        double outward[3]; /* texels facing out of the scene: nothing in front of them to light */
        r = vsgl__rsm_build_inward(ctx, scene, l, rsm_resolution, &rsm, outward);
        if (r != VSGL_OK)
            break;
        vsgl__mrp_proxies_add_rsm(set, scene, &rsm);
        vsgl__rsm_free(&rsm);
        if (vsgl__progress(ctx, "mrp", 0.5f * (float)(l + 1) / (float)light_count))
            r = vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "mrp: cancelled");
    }
    if (r == VSGL_OK) {
        vsgl__mrp_proxies_finish(set);
        r = vsgl__mrp_shade_glossy(ctx, scene, g, set, planes, glossy_q, VSGL__MRP_HYBRID_MAX_ALPHA);
        if (r == VSGL_OK && vsgl__progress(ctx, "mrp", 1.0f))
            r = vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "mrp: cancelled");
    }
    return r;
}

vsgl_result vsgl__mrp_glossy_pass(vsgl_context *ctx, const vsgl_scene *scene, uint32_t rsm_resolution,
                                  double min_area, uint32_t cells, const vsgl_gbuffer *g,
                                  const vsgl_pixel_planes *planes, size_t *proxies, vsgl__mrp_proxy_set *lit)
{
    vsgl__mrp_proxy_set own = {0}, *set = lit ? lit : &own;
    vsgl_result r = lit ? VSGL_OK : vsgl__mrp_proxies_build(ctx, scene, min_area, cells, &own);
    if (r != VSGL_OK)
        return r;
    if (proxies)
        *proxies = set->count;
    r = run_pass(ctx, scene, rsm_resolution, set, g, planes, NULL, lit != NULL);
    if (!lit)
        vsgl__mrp_proxies_free(&own);
    return r;
}

int vsgl__mrp_on_proxy(const vsgl__mrp_proxy_set *set, const vsgl_vsgl *v)
{
    if (v->lobe != VSGL__LOBE_DIFFUSE) /* the cells carry diffuse radiance only */
        return 0;
    d3 m = d3_of_v3(v->mean), nv = d3_of_v3(v->normal);
    for (size_t k = 0; k < set->count; ++k) {
        const vsgl__mrp_rect *rc = &set->items[k].rect;
        d3 d = d3_sub(m, rc->center);
        if (fabs(d3_dot(d, rc->normal)) <= VSGL__MRP_ON_PROXY_TOL * set->plane_tol &&
            fabs(d3_dot(nv, rc->normal)) >= 0.95 && fabs(d3_dot(d, rc->u)) <= rc->half_u &&
            fabs(d3_dot(d, rc->v)) <= rc->half_v)
            return 1;
    }
    return 0;
}

vsgl_result vsgl__mrp_hybrid_pass(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                                  const vsgl_gbuffer *g, const vsgl_vsgl_set *vsgls, const vsgl_pixel_planes *planes,
                                  size_t *excluded, vsgl__mrp_proxy_set *lit)
{
    vsgl__mrp_proxy_set own = {0}, *sp = lit ? lit : &own;
    vsgl_result r = lit ? VSGL_OK
                        : vsgl__mrp_proxies_build(ctx, scene,
                                                  s->mrp_min_area > 0.0f ? (double)s->mrp_min_area : VSGL__MRP_MIN_AREA,
                                                  VSGL__MRP_CELLS, &own);
    if (r != VSGL_OK)
        return r;
    size_t pixels = (size_t)g->width * g->height;
    float *buf = calloc(pixels * 13, sizeof(float));
    vsgl_vsgl_set q;
    memset(&q, 0, sizeof q);
    size_t off = 0;
    if (!buf)
        r = vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "mrp: out of memory for %zu pixels", pixels);
    /* the VSGLs off every proxy: their glossy light goes with MRP's in the pixels MRP takes */
    for (size_t k = 0; k < vsgls->count && r == VSGL_OK; ++k) {
        if (vsgl__mrp_on_proxy(sp, &vsgls->items[k]))
            ++off;
        else
            r = vsgl__vsgl_set_push(&q, &vsgls->items[k]);
    }
    if (excluded)
        *excluded = off;
    vsgl_pixel_planes pq = {buf, buf + 3 * pixels, buf + 6 * pixels, buf + 9 * pixels, buf + 12 * pixels};
    if (r == VSGL_OK && q.count) {
        uint64_t pairs = 0;
        r = vsgl__shade_planned(ctx, scene, g, &q, s, &pq, VSGL__SHADE_KERNEL, &pairs, NULL, NULL);
    }
    if (r == VSGL_OK)
        r = run_pass(ctx, scene, s->rsm_resolution, sp, g, planes, pq.glossy, lit != NULL);
    vsgl__vsgl_set_free(&q);
    free(buf);
    if (!lit)
        vsgl__mrp_proxies_free(&own);
    return r;
}
