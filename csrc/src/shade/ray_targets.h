/* Internal: where a VSGL's visibility rays aim.
 *
 * A VSGL stands for a cluster of lit surface, not a point. Aiming every
 * receiver's ray at the cluster's centre gives each cluster a point
 * light's hard shadow edge, and a few dozen clusters behind one occluder
 * give a few dozen parallel edges: the sun room's cabinet cast a fan of
 * vertical stripes on the wall where Cycles has one soft penumbra
 * (docs/quality.md). Instead each cluster gets VSGL__RAY_TARGETS points
 * spread over a disk with its in-plane variance, and each receiver aims at
 * one of them, picked by a hash of its pixel (its G-buffer sample):
 * neighbouring receivers see different parts of the cluster, so a shadow
 * edge becomes a dithered ramp as wide as the cluster's penumbra, at one
 * ray per pair as before. The pick stays with the pixel, not the surface
 * point: as the camera moves a pixel keeps its point and its light changes
 * smoothly (a hash of the surface point drew a new pattern every frame:
 * the sun room's camera flicker 0.0145 -> 0.0156, Diff, 320 x 240).
 * The points are pulled in where the disk would reach into a surface (a
 * wall's cluster at the floor, a corner), so that a ray is never blocked
 * by the surface its own cluster lies against. */
#ifndef VSGL_SHADE_RAY_TARGETS_H
#define VSGL_SHADE_RAY_TARGETS_H

#include "fit/vsgl_set.h"
#include "math/vec.h"
#include "scene/scene_internal.h"

#include <stdint.h>

/* Points per cluster (a power of two: a receiver's pick is a mask). */
#define VSGL__RAY_TARGETS 16u

typedef struct vsgl_ray_targets {
    float *xyz;     /* per VSGL (set order), VSGL__RAY_TARGETS x 3 floats */
    uint32_t *seed; /* per VSGL: the hash its receivers' picks start from */
} vsgl_ray_targets;

/* The targets of every VSGL of set: a disk of radius spread x its in-plane
 * sigma (spread 2: the disk's variance is the cluster's) around its centre
 * target (pushed off its surface, vsgl__ray_centre), clamped halfway to
 * any surface in between. spread 0: every point is the centre (a point
 * light's hard shadows). The seeds come from the cell of side `cell`
 * (metres) that holds the centre. VSGL_ERROR_OUT_OF_MEMORY leaves *out
 * empty. */
vsgl_result vsgl__ray_targets_build(const vsgl_scene *scene, const vsgl_vsgl_set *set, float spread, float cell,
                                    vsgl_ray_targets *out);
void vsgl__ray_targets_free(vsgl_ray_targets *t);

/* A cluster's centre target: its mean, pushed off its surface along its
 * mean normal by one sigma. A curved surface's cluster has its mean inside
 * the object (a sphere's cap: the mean of points on it lies below them),
 * and rays from the surface around it would be blocked by that very
 * surface. */
static inline v3 vsgl__ray_centre(const vsgl_vsgl *v)
{
    return v3_add(v->mean, v3_scale(v->normal, v->coherence * sqrtf(v->variance)));
}

static inline uint32_t vsgl__hash32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

/* The point of VSGL `item` that the receiver with key `key` (a hash of its
 * G-buffer sample: its pixel and slot) aims at: a function of the two
 * alone, so the same receiver and cluster always trace the same ray
 * (bit-identical renders and replays, and a cluster's glossy core and
 * tail, which share their centre, share their rays). The top bits of one
 * multiply: the seed decorrelates the clusters' picks at one receiver. */
static inline const float *vsgl__ray_target_for(const vsgl_ray_targets *t, size_t item, uint32_t key)
{
    uint32_t h = ((key ^ t->seed[item]) * 0x9e3779b1u) >> 28;
    _Static_assert(VSGL__RAY_TARGETS == 16u, "the pick keeps 4 bits");
    return t->xyz + (item * VSGL__RAY_TARGETS + h) * 3;
}

#endif
