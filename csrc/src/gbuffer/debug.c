/* vsgl_debug_gbuffer: the G-buffer copied into caller buffers (tests). */
#include "vsgl/debug.h"
#include "gbuffer/gbuffer.h"
#include "core/context.h"

vsgl_result vsgl_debug_gbuffer(vsgl_context *ctx, const vsgl_scene *scene, uint32_t aa,
                               float *positions, float *normals, uint32_t *materials)
{
    vsgl__clear_error(ctx);
    if (!scene)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "debug_gbuffer: scene is NULL");
    vsgl_gbuffer g;
    vsgl_result r = vsgl__gbuffer_build(ctx, scene, aa, 0, &g);
    if (r != VSGL_OK)
        return r;
    for (size_t i = 0; i < g.count; ++i) {
        for (int k = 0; k < 3; ++k) {
            if (positions)
                positions[i * 3 + k] = g.pos[k][i];
            if (normals)
                normals[i * 3 + k] = g.nrm[k][i];
        }
        if (materials)
            materials[i] = g.material[i];
    }
    vsgl__gbuffer_free(&g);
    return VSGL_OK;
}

vsgl_result vsgl_debug_gbuffer_frames(vsgl_context *ctx, const vsgl_scene *scene, uint32_t aa,
                                      float *tangents, float *views)
{
    vsgl__clear_error(ctx);
    if (!scene)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "debug_gbuffer_frames: scene is NULL");
    vsgl_gbuffer g;
    vsgl_result r = vsgl__gbuffer_build(ctx, scene, aa, 0, &g);
    if (r != VSGL_OK)
        return r;
    for (size_t i = 0; i < g.count; ++i)
        for (int k = 0; k < 3; ++k) {
            if (tangents)
                tangents[i * 3 + k] = g.tan[k][i];
            if (views)
                views[i * 3 + k] = g.view[k][i];
        }
    vsgl__gbuffer_free(&g);
    return VSGL_OK;
}
