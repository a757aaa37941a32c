/* The MRP glossy pass of vsgl_render (proxies.h, docs/mrp.md §4). */
#include "mrp/proxies.h"
#include "core/context.h"

vsgl_result vsgl__mrp_glossy_pass(vsgl_context *ctx, const vsgl_scene *scene, uint32_t rsm_resolution,
                                  double min_area, uint32_t cells, const vsgl_gbuffer *g,
                                  const vsgl_pixel_planes *planes, size_t *proxies)
{
    vsgl__mrp_proxy_set set;
    vsgl_result r = vsgl__mrp_proxies_build(ctx, scene, min_area, cells, &set);
    if (r != VSGL_OK)
        return r;
    if (proxies)
        *proxies = set.count;
    uint32_t light_count = 0;
    (void)vsgl__scene_lights(scene, &light_count);
    for (uint32_t l = 0; l < light_count && r == VSGL_OK && set.count; ++l) {
        const vsgl_light *L = &vsgl__scene_lights(scene, &light_count)[l];
        if (!(L->power * (L->color[0] + L->color[1] + L->color[2]) > 0.0f))
            continue;
        vsgl_rsm rsm;
        r = vsgl__rsm_build(ctx, scene, l, rsm_resolution, &rsm);
        if (r != VSGL_OK)
            break;
        vsgl__mrp_proxies_add_rsm(&set, scene, &rsm);
        vsgl__rsm_free(&rsm);
        if (vsgl__progress(ctx, "mrp", 0.5f * (float)(l + 1) / (float)light_count))
            r = vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "mrp: cancelled");
    }
    if (r == VSGL_OK) {
        vsgl__mrp_proxies_finish(&set);
        r = vsgl__mrp_shade_glossy(ctx, scene, g, &set, planes);
        if (r == VSGL_OK && vsgl__progress(ctx, "mrp", 1.0f))
            r = vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "mrp: cancelled");
    }
    vsgl__mrp_proxies_free(&set);
    return r;
}
