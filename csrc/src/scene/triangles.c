/* Read access to a scene's valid triangles (triangles.h). */
#include "scene/triangles.h"
#include "scene/scene_data.h"

uint32_t vsgl__scene_triangles(const vsgl_scene *scene, const float **positions, const uint32_t **indices,
                               const float **face_normals, const uint32_t **materials)
{
    *positions = scene->positions;
    *indices = scene->indices;
    *face_normals = scene->face_normals;
    *materials = scene->tri_material;
    return scene->triangle_count;
}
