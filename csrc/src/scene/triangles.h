/* Internal: read access to a scene's valid triangles (for stages that
 * need the geometry itself, e.g. the MRP rectangle proxies). */
#ifndef VSGL_SCENE_TRIANGLES_H
#define VSGL_SCENE_TRIANGLES_H

#include "scene/scene_internal.h"

/* The valid (compacted) triangles: positions (3 floats per vertex), indices
 * (3 per triangle), unit face normals (3 floats per triangle) and material
 * indices; owned by the scene, valid while it lives. Returns the count. */
uint32_t vsgl__scene_triangles(const vsgl_scene *scene, const float **positions, const uint32_t **indices,
                               const float **face_normals, const uint32_t **materials);

#endif
