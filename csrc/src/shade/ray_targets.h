/* Internal: where a VSGL's visibility rays aim.
 *
 * A VSGL stands for a cluster of lit surface, not a point. Aiming every
 * receiver's ray at the cluster's centre gives each cluster a point
 * light's hard shadow edge, and a few dozen clusters behind one occluder
 * give a few dozen parallel edges: the sun room's cabinet cast a fan of
 * vertical stripes on the wall where Cycles has one soft penumbra
 * (docs/quality.md). Instead each cluster gets VSGL__RAY_TARGETS points
 * spread over a disk with its in-plane variance, and each receiver aims at
 * one of them, picked by its pixel (its G-buffer sample) from a blue-noise
 * mask: neighbouring receivers see different parts of the cluster, so a shadow
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

/* The blue-noise mask the picks come from (blue_noise_table.c,
 * tools/gen_blue_noise.py): 64 x 64 ranks, each of 0 .. 4095 once. */
#define VSGL__BLUE_NOISE_SIDE 64u
extern const uint16_t vsgl__blue_noise[VSGL__BLUE_NOISE_SIDE * VSGL__BLUE_NOISE_SIDE];

/* A receiver's key: G-buffer sample i's place on the image's grid of
 * camera samples (pixel (col, row), slot s < aa x aa at (col aa + s % aa,
 * row aa + s / aa)) modulo the mask's side, in bits 0-5 (x) and 6-11 (y);
 * an edge pixel's slots beyond that grid count from 1 in bits 12 up. i:
 * (row width + col) spp + s (gbuffer.h). */
static inline uint32_t vsgl__ray_key(size_t i, uint32_t width, uint32_t spp, uint32_t aa)
{
    const size_t p = i / spp;
    const uint32_t s = (uint32_t)(i % spp), grid = aa * aa;
    const uint32_t x = (uint32_t)(p % width) * aa + (s < grid ? s % aa : 0u);
    const uint32_t y = (uint32_t)(p / width) * aa + (s < grid ? s / aa : 0u);
    return (x & (VSGL__BLUE_NOISE_SIDE - 1u)) | (y & (VSGL__BLUE_NOISE_SIDE - 1u)) << 6 |
           (s < grid ? 0u : s - grid + 1u) << 12;
}

/* The point of VSGL `item` that the receiver with key `key`
 * (vsgl__ray_key) aims its ray `ray` at (0, or 0 .. n - 1 for a pair with
 * n rays, vsgl_render_settings.dominant_rays): a function of the three
 * alone, so the same receiver and cluster always trace the same rays
 * (bit-identical renders and replays, and a cluster's glossy core and
 * tail, which share their centre, share their rays). Each cluster reads
 * the blue-noise mask shifted by its seed (so that one receiver's picks of
 * different clusters are independent), at 16 levels turned by the seed:
 * any 4 x 4 camera samples pick 12.5 of a cluster's 16 points on average
 * (10 at least), where a white-noise hash of the pixel picked 10.3 (6 at
 * least). A pair's n rays take levels 16 / n apart (n = 4, the presets':
 * every fourth point). An
 * edge pixel's extra slots turn the levels further. */
static inline const float *vsgl__ray_target_for(const vsgl_ray_targets *t, size_t item, uint32_t key, uint32_t ray,
                                                uint32_t n)
{
    const uint32_t seed = t->seed[item], side = VSGL__BLUE_NOISE_SIDE - 1u;
    const uint32_t x = (key + seed) & side, y = ((key >> 6) + (seed >> 6)) & side;
    const uint32_t level = (uint32_t)vsgl__blue_noise[y * VSGL__BLUE_NOISE_SIDE + x] >> 8;
    _Static_assert(VSGL__RAY_TARGETS == 16u && VSGL__BLUE_NOISE_SIDE == 64u, "16 levels of 4096 ranks");
    const uint32_t h = (level + (seed >> 12) + (key >> 12) * 5u + ray * VSGL__RAY_TARGETS / n) & (VSGL__RAY_TARGETS - 1u);
    return t->xyz + (item * VSGL__RAY_TARGETS + h) * 3;
}

#endif
