/* Internal to csrc/src/gbuffer: tracing camera samples into a G-buffer,
 * shared by the regular grid (gbuffer.c) and the edge refinement (edges.c). */
#ifndef VSGL_GBUFFER_TRACE_H
#define VSGL_GBUFFER_TRACE_H

#include "gbuffer/gbuffer.h"
#include "scene/camera.h"

/* Rays traced per Embree stream call: the most vsgl__gbuffer_trace takes. */
#define VSGL__GBUFFER_BATCH 64

typedef struct gb_job {
    const vsgl_scene *scene;
    vsgl_camera_model cam;
    uint32_t aa;
    uint32_t edge_aa; /* samples per axis in an edge pixel; <= aa: no refinement */
    float plane_tol;  /* metres off a sample's tangent plane that count as another surface */
    vsgl_gbuffer *g;
    uint32_t row0;    /* first row of the current step */
    unsigned char *edge; /* width x height: 1 where the pixel is refined */
} gb_job;

/* The texture footprint (pixels a side) of a camera sample `spacing`
 * pixels from its neighbours: two spacings, at most the pixel. One spacing
 * (the sample's own share of the pixel) left the stripes of a textured
 * room's wallpaper, about a pixel wide at 80 x 60, sampled 2 x 2 with too
 * little of a prefilter: as the camera moved its DiffCol flickered 0.0205
 * a frame (Diff, balanced) against Cycles' own 0.0157, 0.0157 with two
 * spacings, with structured error 0.00013 -> 0.00011. A whole pixel for
 * every sample blurred 16 x 16 samples' mean 7 % off Cycles' DiffCol
 * (tests/blender/texture_ref.py: 0.71 % with one spacing, 0.72 % with
 * two). One sample per pixel keeps the pixel. */
static inline float vsgl__texture_footprint(float spacing)
{
    return 2.0f * spacing < 1.0f ? 2.0f * spacing : 1.0f;
}

/* Trace m <= VSGL__GBUFFER_BATCH camera rays at raster positions (rx[k],
 * ry[k]) and store what each sees at index dst[k] of g; `foot` is a
 * sample's side in pixels (the texture filter's footprint). With `hits`,
 * also each ray's hit at hits[dst[k]]: a g without surf and lift arrays
 * (the edge refinement's rays) skips those, and vsgl__gbuffer_store_deferred
 * fills them later for the few samples kept. */
void vsgl__gbuffer_trace(const gb_job *j, vsgl_gbuffer *g, uint32_t m, const float *rx, const float *ry,
                         const size_t *dst, float foot, vsgl_hit *hits);

/* Sample i's lift and (with `inputs`) textured inputs, those of g's arrays
 * that exist, from the hit of the camera ray at raster (rx, ry): the same
 * values the trace stores. Nothing for a miss. */
void vsgl__gbuffer_store_deferred(const gb_job *j, vsgl_gbuffer *g, size_t i, const vsgl_hit *hit, float rx,
                                  float ry, float foot, int inputs);

/* Allocate g's per-sample arrays for n samples (surf too when textured,
 * weight and spread when weighted, lift when smooth); 0 when out of memory
 * (then g is freed). */
int vsgl__gbuffer_alloc(vsgl_gbuffer *g, size_t n, int textured, int weighted, int smooth);

/* Empty slot i (a miss that weighs nothing); its view is slot `like`'s. */
static inline void vsgl__gbuffer_clear_slot(vsgl_gbuffer *g, size_t i, size_t like)
{
    g->material[i] = VSGL__GBUFFER_MISS;
    if (g->part)
        g->part[i] = VSGL__PART_NONE;
    for (int k = 0; k < 3; ++k) {
        g->pos[k][i] = g->nrm[k][i] = g->tan[k][i] = 0.0f;
        g->view[k][i] = g->view[k][like];
    }
    if (g->surf[0])
        for (int t = 0; t < VSGL__SURF_N; ++t)
            g->surf[t][i] = 0.0f;
    if (g->weight) {
        g->weight[i] = 0.0f;
        g->spread[i] = 1.0f;
    }
    if (g->lift[0])
        for (int k = 0; k < 3; ++k)
            g->lift[k][i] = 0.0f;
}

/* Edge pixels (edges.c): mark then refine, rows [begin, end) of the job. */
int32_t vsgl__gbuffer_mark_edges(void *job, size_t chunk, size_t begin, size_t end);
int32_t vsgl__gbuffer_refine_edges(void *job, size_t chunk, size_t begin, size_t end);

#endif
