/* Private to csrc/src/scene: the layout of a validated scene. Other stages
 * use scene_internal.h only. */
#ifndef VSGL_SCENE_DATA_H
#define VSGL_SCENE_DATA_H

#include <embree3/rtcore.h>

#include "scene/scene_internal.h"
#include "scene/material.h"
#include "scene/texture.h"
#include "core/context.h"

#define VSGL__SCENE_EMBREE_MESSAGE 256

struct vsgl_scene {
    RTCDevice device;
    RTCScene rtc;
    uint32_t vertex_count;
    const float *positions;      /* vertex_count * 3, owned by Embree's vertex buffer */
    uint32_t triangle_count;     /* valid (compacted) triangles */
    uint32_t dropped_triangles;
    const uint32_t *indices;     /* triangle_count * 3, owned by Embree's index buffer */
    float *corner_normals;       /* triangle_count * 9, unit; face normal when the caller gave none */
    float *corner_uvs;           /* triangle_count * 6 or NULL */
    float *corner_tangents;      /* triangle_count * 12 or NULL */
    float *face_normals;         /* triangle_count * 3, unit, (p1-p0)x(p2-p0) */
    uint32_t *tri_material;      /* triangle_count */
    uint32_t *source_triangle;   /* triangle_count: index in the caller's array */
    uint32_t material_count;
    vsgl_material *materials;
    vsgl_albedo_table *glossy_albedo; /* material_count: the glossy lobe's directional albedo */
    uint32_t light_count;
    vsgl_light *lights;
    vsgl_camera camera;
    uint32_t texture_count;
    vsgl_tex *textures;          /* texture_count mip pyramids */
    vsgl_material_textures *material_textures; /* material_count or NULL */
    float *corner_colors;        /* triangle_count * 9 or NULL */
    float *uv_density;           /* triangle_count: UV area / world area (0 without UVs); NULL if untextured */
    int textured;                /* some material reads a texture or corner colours */
    int smooth;                  /* some corner normal is not its face's normal (vsgl__scene_smooth) */
    v3 lo, hi;                   /* bounds of the valid triangles (0,0,0 when empty) */
    v3 occ_inner_lo, occ_inner_hi; /* scene/occluders.c: segments strictly inside meet no face triangle */
    uint32_t occ_count;          /* boxes around the triangles off the bounds' faces */
    float *occ_boxes;            /* occ_count * 6 (lo xyz, hi xyz), padded; NULL when occ_count is 0 */
    float occ_union[6];          /* the boxes' union */
    uint32_t occ_triangles;      /* triangles off the bounds' faces (the occluders) */
    float *occ_few;              /* occ_few_count * 12 (v0, e1, e2, e1 x e2) when they are few (occlude_few.c), or NULL */
    uint32_t occ_few_count;
    int convex_shell;            /* vsgl__scene_convex_shell, decided once when the scene is built */
    uint32_t *tri_part;          /* triangle_count: its convex part (scene/convex.c), VSGL__PART_NONE if none */
    signed char *tri_side;       /* triangle_count: +1 / -1: the face normal / its opposite points out of the
                                  * part; 0: the part is flat (no inside) */
    uint32_t part_count;         /* convex parts found */
    unsigned char *part_curved;  /* part_count: 1 if the part is smooth-shaded (some corner normal is not
                                  * its face's): a curved surface, vsgl__scene_part_curved */
    uint64_t identity;           /* creation time (CLOCK_MONOTONIC ns): with the address, tells this scene's
                                    geometry and materials from a destroyed one's at the same address;
                                    kept by vsgl_scene_set_view (render caches key on both) */
    char embree_message[VSGL__SCENE_EMBREE_MESSAGE]; /* first Embree error seen */
};

/* 1 if (x, y, z) lies strictly inside the occluders' inner box (occluders.c):
 * a segment between two such points meets no triangle on the bounds'
 * faces. Branch-free, so that occlude_few.c's loop over segments
 * vectorises. */
static inline int vsgl__scene_strictly_inside(const vsgl_scene *s, float x, float y, float z)
{
    const v3 lo = s->occ_inner_lo, hi = s->occ_inner_hi;
    return (x > lo.x) & (y > lo.y) & (z > lo.z) & (x < hi.x) & (y < hi.y) & (z < hi.z);
}

/* From this many triangles on, visibility rays go to Embree as an
 * incoherent stream (raytrace.c, vsgl__scene_occluded_towards_each): one
 * ray at a time through the BVH rather than packets. A block's rays to one
 * cluster share a target but part ways at the leaves of a fine mesh, where
 * packets trace the union of their paths. Balanced at 960 x 540 (shade
 * stage, coherent -> incoherent, this machine): a bumpy floor of 968
 * triangles 2.08 -> 2.14 s, 9.8k 3.44 -> 3.09 s, 97k 3.11 -> 2.16 s, 500k
 * 3.63 -> 2.15 s; the 2.2k-triangle sphere room 1.85 -> 1.77 s; the 52-
 * triangle thick sun room 8-10 % slower incoherent. The images are the
 * same bit for bit either way. */
#define VSGL__RAY_INCOHERENT_MIN 2048u

/* Segments per visibility batch (raytrace.c, occlude_few.c). */
#define VSGL__OCC_STREAM 64
/* At most this many occluders are tested one by one (occlude_few.c). */
#define VSGL__OCC_FEW 16u
/* The few occluders ids[0, n) as vertex, two edges and their cross product (occlude_few.c). */
vsgl_result vsgl__scene_build_few(vsgl_context *ctx, vsgl_scene *s, const uint32_t *ids, uint32_t n);
void vsgl__scene_occluded_few(const vsgl_scene *s, uint32_t m, const float *ox, const float *oy, const float *oz,
                              const float *ex, const float *ey, const float *ez, const float *reach,
                              unsigned char *hit);
void vsgl__scene_segments_route(const vsgl_scene *s, uint32_t m, const float *ox, const float *oy, const float *oz,
                                const float *ex, const float *ey, const float *ez, float eps, float *inv, float *reach,
                                int *route);

/* The occluders' bounds (occluders.c), once the triangles and bounds are set. */
vsgl_result vsgl__scene_build_occluders(vsgl_context *ctx, vsgl_scene *s);

/* Validation (validate.c): first error -> vsgl__fail with a message naming the element. */
vsgl_result vsgl__validate_scene_desc(vsgl_context *ctx, const vsgl_scene_desc *d);
/* The caller's desc as this version's struct (fields past its size zeroed). */
void vsgl__scene_desc_normalise(const vsgl_scene_desc *in, vsgl_scene_desc *out);
vsgl_result vsgl__validate_camera(vsgl_context *ctx, const vsgl_camera *c);
vsgl_result vsgl__validate_light(vsgl_context *ctx, uint32_t index, const vsgl_light *l);
vsgl_result vsgl__validate_material(vsgl_context *ctx, uint32_t index, const vsgl_material *m);

/* The convex parts (scene/convex.c), once the triangles are set. */
vsgl_result vsgl__scene_build_parts(vsgl_context *ctx, vsgl_scene *s);
/* The part key of a point on triangle tri seen from its back (back = 1:
 * the ray met the face against its normal's side) or front. */
static inline uint32_t vsgl__scene_part_key(const vsgl_scene *s, uint32_t tri, int back)
{
    uint32_t part = s->tri_part ? s->tri_part[tri] : VSGL__PART_NONE;
    if (part == VSGL__PART_NONE)
        return VSGL__PART_NONE;
    int side = s->tri_side[tri];
    /* seen from the side the face normal x side points to: the outside */
    int inner = side != 0 && ((side > 0) == (back != 0));
    return 2u * part + (uint32_t)inner;
}

/* Affine 3x4 row-major matrix checks. Returns NULL if fine, else a static reason. */
const char *vsgl__matrix_problem(const float m[12]);

#endif
