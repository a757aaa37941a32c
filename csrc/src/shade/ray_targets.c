/* Where visibility rays aim: points over each VSGL's cluster (ray_targets.h). */
#include "shade/ray_targets.h"
#include "scene/scene_data.h"

#include <math.h>
#include <stdlib.h>

/* The golden angle: successive points of a Vogel spiral. */
#define VSGL__GOLDEN_ANGLE 2.39996323f

/* The integer cell of a coordinate in cells (clamped: a cast out of
 * int32_t's range is undefined). */
static uint32_t cell_of(float x)
{
    return (uint32_t)(int32_t)floorf(fminf(fmaxf(x, -2.0e9f), 2.0e9f));
}

vsgl_result vsgl__ray_targets_build(const vsgl_scene *scene, const vsgl_vsgl_set *set, float spread, float cell,
                                    vsgl_ray_targets *out)
{
    const float inv_cell = 1.0f / cell;
    const size_t count = set->count, K = VSGL__RAY_TARGETS;
    out->xyz = malloc((count * K + 1) * 3 * sizeof *out->xyz);
    out->seed = malloc((count + 1) * sizeof *out->seed);
    if (!out->xyz || !out->seed) {
        vsgl__ray_targets_free(out);
        return VSGL_ERROR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < count; ++i) {
        const vsgl_vsgl *v = &set->items[i];
        const v3 c = vsgl__ray_centre(v);
        /* from the cell of the centre and the facing of the cluster: a
         * glossy core and tail get the same points, a cluster that moves a
         * little with its light keeps them (a new pattern every frame
         * flickers), and a wall's clusters pick apart from the floor's in
         * the same cell */
        const uint32_t facing = cell_of(4.0f * v->normal.x + 4.5f) | cell_of(4.0f * v->normal.y + 4.5f) << 4 |
                                cell_of(4.0f * v->normal.z + 4.5f) << 8;
        const uint32_t seed = vsgl__hash32(cell_of(c.x * inv_cell) ^
                                           vsgl__hash32(cell_of(c.y * inv_cell) ^
                                                        vsgl__hash32(cell_of(c.z * inv_cell) ^ vsgl__hash32(facing))));
        out->seed[i] = seed;
        /* variance is per axis; a flat cluster's 3 sigma^2 lie in its plane */
        const float radius = spread * sqrtf(1.5f * fmaxf(v->variance, 0.0f));
        v3 tx, ty;
        v3_basis(v->normal, &tx, &ty);
        const float turn = (float)(seed >> 8) * (6.28318531f / 16777216.0f);
        for (size_t k = 0; k < K; ++k) {
            float *p = out->xyz + (i * K + k) * 3;
            float r = radius * sqrtf(((float)k + 0.5f) / (float)K), phi = turn + VSGL__GOLDEN_ANGLE * (float)k;
            v3 d = v3_add(v3_scale(tx, cosf(phi)), v3_scale(ty, sinf(phi)));
            vsgl_hit hit;
            if (r > 0.0f && scene->triangle_count && vsgl__scene_intersect(scene, c, d, 0.0f, r, &hit))
                r = 0.5f * hit.t; /* halfway to the surface in the way */
            v3 q = v3_add(c, v3_scale(d, r));
            p[0] = q.x;
            p[1] = q.y;
            p[2] = q.z;
        }
    }
    return VSGL_OK;
}

void vsgl__ray_targets_free(vsgl_ray_targets *t)
{
    free(t->xyz);
    free(t->seed);
    t->xyz = NULL;
    t->seed = NULL;
}
