/* Is the scene a convex shell? Every triangle's plane has every vertex of
 * the scene on one side (within a tolerance): then all surfaces lie on the
 * boundary of their convex hull, and the segment between two surface points
 * runs through the hull's inside, meeting the surfaces only at its ends
 * (or within one face's plane, where the cosines are 0). Nothing can block
 * light between two surfaces: visibility rays find nothing (render.c skips
 * them). Empty closed rooms (a box, a room without furniture) are such
 * scenes; a window hole, an object or a second room is not. */
#include "scene/scene_data.h"

#include <math.h>

/* Above this many triangles the test is not run (answer: not convex): it
 * costs triangles x vertices in the worst case. */
#define VSGL__CONVEX_MAX_TRIANGLES 2048u

int vsgl__scene_test_convex_shell(const vsgl_scene *scene)
{
    uint32_t t_count = scene->triangle_count, v_count = scene->vertex_count;
    if (t_count == 0 || t_count > VSGL__CONVEX_MAX_TRIANGLES)
        return 0;
    double ext = sqrt((double)(scene->hi.x - scene->lo.x) * (scene->hi.x - scene->lo.x) +
                      (double)(scene->hi.y - scene->lo.y) * (scene->hi.y - scene->lo.y) +
                      (double)(scene->hi.z - scene->lo.z) * (scene->hi.z - scene->lo.z));
    double eps = 1e-5 * (ext > 0.0 ? ext : 1.0);
    for (uint32_t t = 0; t < t_count; ++t) {
        const float *n = scene->face_normals + 3 * (size_t)t;
        const float *p = scene->positions + 3 * (size_t)scene->indices[3 * (size_t)t];
        int above = 0, below = 0;
        for (uint32_t v = 0; v < v_count; ++v) {
            const float *q = scene->positions + 3 * (size_t)v;
            double d = (double)n[0] * ((double)q[0] - p[0]) + (double)n[1] * ((double)q[1] - p[1]) +
                       (double)n[2] * ((double)q[2] - p[2]);
            above |= d > eps;
            below |= d < -eps;
            if (above && below)
                return 0;
        }
    }
    return 1;
}

int vsgl__scene_convex_shell(const vsgl_scene *scene)
{
    return scene->convex_shell;
}
