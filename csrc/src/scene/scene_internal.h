/* Internal: the validated scene and the ray queries every stage uses.
 * Owner: the scene stage (csrc/src/scene). Other stages use only what is
 * declared here. */
#ifndef VSGL_SCENE_INTERNAL_H
#define VSGL_SCENE_INTERNAL_H

#include "vsgl/scene.h"
#include "math/vec.h"

/* A ray hit: distance along the (unit) ray direction and the triangle. */
typedef struct vsgl_hit {
    float t;
    uint32_t triangle;   /* index into the validated (compacted) triangle list */
    float u, v;          /* barycentrics of corners 1 and 2 */
} vsgl_hit;

/* Everything shading needs about a surface point. */
typedef struct vsgl_surface {
    v3 position;         /* world, metres */
    v3 normal;           /* interpolated shading normal, flipped to face the ray origin side */
    v3 geometric_normal; /* unit face normal, same side as `normal` */
    v3 tangent;          /* unit, orthogonal to normal, anisotropic rotation applied */
    uint32_t material;   /* index into the scene's materials */
    uint32_t part;       /* convex part key (vsgl__scene_part_key below), VSGL__PART_NONE if none */
} vsgl_surface;

/* Closest hit along org + t*dir for t in (tmin, tmax); dir unit. Returns 1 on hit. Thread-safe. */
int vsgl__scene_intersect(const vsgl_scene *scene, v3 org, v3 dir, float tmin, float tmax, vsgl_hit *hit);

/* 1 if anything blocks the open segment (tmin, tmax) along dir. Thread-safe. */
int vsgl__scene_occluded(const vsgl_scene *scene, v3 org, v3 dir, float tmin, float tmax);

/* Batch of n closest-hit queries (Embree ray streams; faster for many rays).
 * Rays with tmin > tmax, or misses, give hits[i].triangle = VSGL__HIT_NONE
 * and t = +inf. coherent = 1 for camera-like bundles. Thread-safe. */
#define VSGL__HIT_NONE 0xFFFFFFFFu
void vsgl__scene_intersect_many(const vsgl_scene *scene, uint32_t n, const v3 *org, const v3 *dir,
                                const float *tmin, const float *tmax, int coherent, vsgl_hit *hits);

/* Batch of n occlusion queries: blocked[i] = 1 if anything lies on the segment
 * (tmin[i], tmax[i]) along unit dir[i]; 0 for an empty interval. Thread-safe. */
void vsgl__scene_occluded_many(const vsgl_scene *scene, uint32_t n, const v3 *org, const v3 *dir,
                               const float *tmin, const float *tmax, int coherent, unsigned char *blocked);

/* vsgl__scene_occluded_many for the segments from origin lane[i] (ox, oy,
 * oz: coordinates indexed by lane) to target lane[i] (tgt[0..2], the same
 * indexing), short of it by eps (a segment of eps or less: unblocked, no
 * ray); blocked[i], i < n. Thread-safe. */
void vsgl__scene_occluded_towards_each(const vsgl_scene *scene, uint32_t n, const uint32_t *lane, const float *ox,
                                       const float *oy, const float *oz, const float *const tgt[3], float eps,
                                       unsigned char *blocked);

/* Index in the caller's triangle array of validated triangle `triangle`. */
uint32_t vsgl__scene_source_triangle(const vsgl_scene *scene, uint32_t triangle);

/* Surface attributes at a hit seen along ray direction dir. */
void vsgl__scene_surface(const vsgl_scene *scene, const vsgl_hit *hit, v3 dir, vsgl_surface *out);
/* The shading normal a camera sample is shaded with, as Cycles' BSDF nodes
 * take it (ensure_valid_reflection): n itself, unless the mirror
 * reflection of the view i about n dips below the face (ng) by more than
 * allowed; then the normal nearest n, in the plane of n and ng, whose
 * reflection of i leaves the face at height min(0.9 ng.i, 0.01). On
 * smooth-shaded silhouettes, where the interpolated normal faces away from
 * the camera, it keeps the rim's glossy reflection that Cycles renders.
 * ng: unit face normal on the camera's side; i: unit direction towards the
 * camera; n: unit shading normal (scene/shading_normal.c). */
v3 vsgl__valid_reflection_normal(v3 ng, v3 i, v3 n);
/* sf seen from direction i (unit, towards the viewer) shaded as Cycles'
 * BSDF nodes shade it: its normal vsgl__valid_reflection_normal, its
 * tangent made orthogonal to that normal again where it turned. */
void vsgl__surface_valid_reflection(vsgl_surface *sf, v3 i);
#if defined(__SSE2__)
/* The same for four hits (every one a hit), bit for bit (scene/surface4.c). */
void vsgl__scene_surface4(const vsgl_scene *scene, const vsgl_hit hit[4], const v3 dir[4], vsgl_surface out[4]);
#endif

/* Hit point sf->position of `hit` lifted from its flat triangle onto the
 * smooth surface its corner normals describe, on the side the ray came
 * from (sf->geometric_normal's): p - sum_i b_i min(0, (p - v_i).n_i) n_i,
 * the shadow-terminator offset of Hanika, Droske and Fascione (2021), as
 * Cycles starts its shadow rays. On a flat face (corner normals = the face
 * normal) it is p. */
v3 vsgl__scene_smooth_point(const vsgl_scene *scene, const vsgl_hit *hit, const vsgl_surface *sf);
/* 1 if some triangle's corner normals are not its face normal (a smooth-
 * shaded mesh), where vsgl__scene_smooth_point moves points. */
int vsgl__scene_smooth(const vsgl_scene *scene);

/* Textures (scene/texture.h). A scene whose materials read textures or
 * corner colours is "textured": the stages then evaluate the material
 * inputs per point (G-buffer sample, RSM texel) instead of per material. */
#define VSGL__SURF_BASE 0       /* base colour RGB */
#define VSGL__SURF_ROUGHNESS 3
#define VSGL__SURF_METALLIC 4
#define VSGL__SURF_N 5
int vsgl__scene_textured(const vsgl_scene *scene);
/* The material inputs (VSGL_SURF_*) at a hit, textures filtered over a
 * footprint of `area` m^2 on the surface (a camera sample's share of its
 * pixel, an RSM texel's patch). Thread-safe. */
void vsgl__scene_inputs(const vsgl_scene *scene, const vsgl_hit *hit, float area, float out[VSGL__SURF_N]);
/* *m with base colour, roughness and metallic replaced by in (VSGL_SURF_*). */
void vsgl__material_with_inputs(const vsgl_material *m, const float in[VSGL__SURF_N], vsgl_material *out);

/* Validated copies (never NULL when the count is > 0). */
const vsgl_material *vsgl__scene_materials(const vsgl_scene *scene, uint32_t *count);
/* The glossy lobe's directional albedo table of a material (scene/material.h),
 * computed when the scene is created; NULL for an index out of range. */
struct vsgl_albedo_table;
const struct vsgl_albedo_table *vsgl__scene_glossy_albedo(const vsgl_scene *scene, uint32_t material);
/* The DiffCol weight of a material seen from a direction of cosine cos_view
 * (vsgl__diffuse_view_weight: 1 unless it is a Blender 4.x+ material). */
float vsgl__scene_diffuse_weight(const vsgl_scene *scene, uint32_t material, float cos_view);
/* The diffuse power a VPL of that material (parameters bp, its textures
 * applied) reflects from light arriving at cosine cos_i, over Lambert's
 * base (1 - metallic): Blender 4.x+'s cosine-weighted mean dimming by the
 * specular layer, times Blender 3.x's Burley albedo at cos_i
 * (vsgl__burley_albedo); 1 for a Lambert material. The VSGL fit
 * (fit/moments.c) and the MRP proxies (mrp/proxies.c) take it alike. */
struct vsgl_brdf_params;
float vsgl__scene_diffuse_power(const vsgl_scene *scene, uint32_t material, const struct vsgl_brdf_params *bp,
                                float cos_i);
const vsgl_light *vsgl__scene_lights(const vsgl_scene *scene, uint32_t *count);
const vsgl_camera *vsgl__scene_camera(const vsgl_scene *scene);
/* With the scene's address, distinguishes scenes whose geometry or
 * materials may differ, also a new scene at a destroyed one's address. */
uint64_t vsgl__scene_identity(const vsgl_scene *scene);
/* Bounding box of the valid triangles; lo = hi = (0,0,0) when there are none. */
void vsgl__scene_bounds(const vsgl_scene *scene, v3 *lo, v3 *hi);
/* 1 if no triangle can block the segment from a to b, proven from bounds
 * (scene/occluders.c): both ends inside the scene's box, clear of the
 * triangles on its faces, and the segment misses the boxes of all others.
 * 0 means "trace it": it may or may not be blocked. */
int vsgl__scene_segment_clear(const vsgl_scene *scene, v3 a, v3 b);
/* 1 if every triangle's plane has all of the scene's vertices on one side
 * (scene/convex.c): no surface can block light between two others, so
 * visibility rays find nothing. 0 otherwise, and above 2048 triangles. */
int vsgl__scene_convex_shell(const vsgl_scene *scene);
/* The test itself (up to triangles x vertices): run once by the scene's build. */
int vsgl__scene_test_convex_shell(const vsgl_scene *scene);

/* Convex parts (scene/convex.c). A part is a connected set of triangles
 * (sharing vertices or vertex positions) every one of whose planes has all
 * of the part's vertices on one side: a sphere, a box, a plane, a room's
 * closed shell. Two points on the outside of a convex surface each lie
 * behind the other's tangent plane, so they exchange no light; a point on
 * the inside and one on the outside neither; two points on the inside
 * (a closed room seen from within) do. A flat part has no inside: its
 * points never light each other. A surface point's key is 2 part + inner
 * (inner: 1 on the part's inside); the shading drops the light a cluster
 * sends from a part to the same part's receivers except inside to inside
 * (fit/vsgl_set.h, vsgl_vsgl.part). */
#define VSGL__PART_NONE 0xFFFFFFFFu
/* The number of convex parts found when the scene was built. */
uint32_t vsgl__scene_part_count(const vsgl_scene *scene);
/* 1 if convex part `part` is smooth-shaded (a curved surface: a sphere, a
 * cylinder), 0 if flat-shaded or out of range. */
int vsgl__scene_part_curved(const vsgl_scene *scene, uint32_t part);

#endif
