/* Internal: the camera G-buffer, what each pixel sample sees.
 * Owner: csrc/src/gbuffer. Consumed by fit/shade and the brute-force gather. */
#ifndef VSGL_GBUFFER_H
#define VSGL_GBUFFER_H

#include "scene/scene_internal.h"

#define VSGL__GBUFFER_MISS 0xFFFFFFFFu
#define VSGL__GBUFFER_MAX_SPP 256 /* 16 x 16 samples per pixel */
#define VSGL__GBUFFER_REFINED 1u   /* vsgl_gbuffer.refined */
#define VSGL__GBUFFER_TRACED 2u

/* Structure of arrays; sample index = (row * width + col) * spp + s,
 * row 0 = top of the image, samples on a stratified aa x aa pattern
 * (vsgl__gbuffer_pattern). */
typedef struct vsgl_gbuffer {
    uint32_t width, height, spp;   /* slots per pixel: vsgl__gbuffer_slots (aa * aa, or 3 at aa = 1
                                      with edge refinement: slots 1 and 2 empty misses of weight 0
                                      unless an edge fills them) */
    uint32_t aa;                   /* the stratified pattern's side: slot s < aa * aa of pixel (col, row)
                                      was traced at (col, row) + vsgl__gbuffer_pattern(s, aa) */
    size_t count;                  /* width * height * spp */
    float *pos[3];                 /* world position */
    float *nrm[3];                 /* unit shading normal on the camera's side of the surface: flipped
                                      with the geometric normal on back faces, as Cycles' Normal pass;
                                      n.view may be slightly negative at smooth-shaded silhouettes */
    float *view[3];                /* unit direction from the point towards the camera */
    float *tan[3];                 /* unit tangent (anisotropy frame), orthogonal to nrm */
    uint32_t *material;            /* material index, VSGL__GBUFFER_MISS where nothing was hit
                                      (then pos, nrm, tan are 0; view is still set) */
    uint32_t *part;                /* the convex part key of its surface (vsgl_surface.part); NULL: none */
    float *surf[VSGL__SURF_N];      /* textured scenes only (else NULL): the material inputs at the
                                      sample (scene_internal.h VSGL_SURF_*), textures filtered over the
                                      sample's 1/spp share of its pixel; 0 for misses */
    float *weight;                 /* NULL: every sample weighs 1/spp. Else (edge refinement) each
                                      sample's share of its pixel, summing to 1 per pixel: an edge
                                      pixel's slots hold one sample per surface it sees, weighted by
                                      the fraction of edge_aa x edge_aa rays that saw it (0 for unused
                                      slots, which are misses) */
    float *spread;                 /* with weight: the length of the mean of the unit shading normals a
                                      sample stands for, in (0, 1]: 1 for one ray; an edge slot's
                                      group of rays on a curved surface, less (edges.c). The shade
                                      stage widens its glossy lobe by the spread (shade.c) */
    float *lift[3];                /* NULL unless the scene has smooth-shaded triangles; else per sample
                                      the step from its point (on its flat triangle, where Cycles
                                      shades it too) up to the smooth surface its normals describe
                                      (vsgl__scene_smooth_point), where its visibility rays start:
                                      from the triangle they would hit the sample's own mesh */
    unsigned char *refined;        /* with weight: per pixel, VSGL__GBUFFER_REFINED where edge
                                      refinement rewrote its slots (edges.c), VSGL__GBUFFER_TRACED
                                      where it traced the pixel again but its slots came out as the
                                      grid's (weights 1 / (aa * aa), no surface split), else 0; NULL
                                      without edge refinement */
    size_t edge_pixels;            /* pixels refined */
} vsgl_gbuffer;

/* Position of sample s of an n x n pattern within its pixel, in [0, 1)^2
 * (x right, y down): the first pass's aa x aa samples (n = aa) and an edge
 * pixel's edge_aa x edge_aa rays (n = edge_aa). Not the square grid
 * ((i + 0.5) / n, (j + 0.5) / n) but that grid sheared by 1 / n of a cell
 * both ways, ((i + (j + 0.5) / n) / n, (j + (i + 0.5) / n) / n): still a
 * lattice (the rays s + 1 and s + n are s's neighbours) and still one
 * sample per 1 / n stratum, but all n^2 samples have distinct x and
 * distinct y, so the coverage of a horizontal or vertical edge takes n^2
 * values instead of n. On the square grid a room's vertical edges crept
 * across a pixel in steps of 1 / n: the corridor's end wall (an edge
 * moving 0.09 px a frame, 8 x 8 edge rays) jumped in some frames and
 * stood still in others (docs/accuracy.md, "Edges that move in steps").
 * For n = 2 this is the rotated-grid pattern of 4x supersampling. */
static inline void vsgl__gbuffer_pattern(uint32_t s, uint32_t n, float inv_n, float *ox, float *oy)
{
    const float i = (float)(s % n), j = (float)(s / n);
    *ox = (i + (j + 0.5f) * inv_n) * inv_n;
    *oy = (j + (i + 0.5f) * inv_n) * inv_n;
}

/* Slots per pixel for aa x aa samples, with or without edge refinement. At
 * aa = 1 an edge pixel has three slots, one per surface it sees, so that a
 * corner, where two faces of a cabinet meet the floor, keeps all three:
 * with two, the third joined the slot of another material, whose shading
 * it took, and a pixel's glossy light jumped from 1.6 to 0.004 in one
 * frame of a camera animation where Cycles' falls smoothly (the preview's
 * sun rooms at 80 x 60: camera-motion Gloss above Cycles' own 0.019 ->
 * 0.008, docs/quality.md). */
static inline uint32_t vsgl__gbuffer_slots(uint32_t aa, int refine)
{
    return refine && aa == 1 ? 3u : aa * aa;
}

/* Slot k's share of its pixel as the aa x aa grid leaves it (before any
 * edge refinement): 1 / (aa * aa) for the grid's samples, 0 beyond. */
static inline float vsgl__gbuffer_grid_weight(uint32_t aa, size_t k)
{
    return k < (size_t)aa * aa ? 1.0f / (float)(aa * aa) : 0.0f;
}

/* Sample i's share of its pixel. */
static inline float vsgl__gbuffer_weight(const vsgl_gbuffer *g, size_t i)
{
    return g->weight ? g->weight[i] : 1.0f / (float)g->spp;
}

/* Did edge refinement rewrite pixel px's slots (edges.c)? Then each slot
 * stands for a group of rays anywhere in the pixel, not for its sample of
 * the aa x aa grid, even where the groups' shares happen to be the grid's
 * 1 / (aa * aa) each (a rim cut into as many runs as the pixel has slots,
 * edges.c split_curved). A pixel traced again whose slots came out as the
 * grid's, unsplit, is not (its slots are read as grid samples, as before
 * rims were cut). */
static inline int vsgl__gbuffer_refined(const vsgl_gbuffer *g, size_t px)
{
    return g->refined && g->refined[px] == VSGL__GBUFFER_REFINED;
}

/* Material of sample i with its own inputs (textured scenes), else its
 * material's constants. The sample must be a hit. */
void vsgl__gbuffer_material(const vsgl_gbuffer *g, const vsgl_material *materials, size_t i, vsgl_material *out);

/* Trace the camera's primary rays (aa x aa per pixel, aa in 1..16, 0 means 1;
 * sample s at raster (col, row) + vsgl__gbuffer_pattern(s, aa)) in
 * parallel. With edge_aa > aa, pixels whose samples (or whose
 * neighbours' nearest samples) lie on different surfaces are traced again
 * with edge_aa x edge_aa rays, and their aa x aa slots hold one sample per
 * surface seen, weighted by coverage (edges.c): edges move smoothly as the
 * camera moves instead of in steps of 1/spp. Reports progress as stage "gbuffer"; on cancellation returns
 * VSGL_ERROR_CANCELLED with *out zeroed. Bit-identical for any thread count.
 * Free with vsgl__gbuffer_free (also safe on a zeroed struct). */
vsgl_result vsgl__gbuffer_build(vsgl_context *ctx, const vsgl_scene *scene, uint32_t aa, uint32_t edge_aa,
                                vsgl_gbuffer *out);
void vsgl__gbuffer_free(vsgl_gbuffer *g);

#endif
