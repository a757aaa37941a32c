/* vsgl_scene_set_view: replace a scene's camera and lights, keeping its
 * geometry, materials and BVH (the live viewport's light and camera edits). */
#include "scene/scene_data.h"

#include <stdlib.h>
#include <string.h>

vsgl_result vsgl_scene_set_view(vsgl_context *ctx, vsgl_scene *scene, const vsgl_camera *camera,
                                const vsgl_light *lights, uint32_t light_count)
{
    vsgl__clear_error(ctx);
    if (!scene)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "scene_set_view: scene is NULL");
    if (!camera)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "scene_set_view: camera is NULL (a camera is required)");
    if (light_count > 0 && !lights)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "scene_set_view: lights is NULL but light_count is %u",
                          (unsigned)light_count);
    vsgl_result r = vsgl__validate_camera(ctx, camera);
    if (r != VSGL_OK)
        return r;
    for (uint32_t i = 0; i < light_count; ++i)
        if ((r = vsgl__validate_light(ctx, i, &lights[i])) != VSGL_OK)
            return r;
    /* Everything is checked before anything changes: a refused view leaves
     * the scene as it was. */
    vsgl_light *copy = NULL;
    if (light_count) {
        copy = malloc((size_t)light_count * sizeof *copy);
        if (!copy)
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene_set_view: out of memory for %u lights",
                              (unsigned)light_count);
        memcpy(copy, lights, (size_t)light_count * sizeof *copy);
    }
    free(scene->lights);
    scene->lights = copy;
    scene->light_count = light_count;
    scene->camera = *camera;
    return VSGL_OK;
}
