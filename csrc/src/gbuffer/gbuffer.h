/* Internal: the camera G-buffer, what each pixel sample sees.
 * Owner: csrc/src/gbuffer. Consumed by fit/shade and the brute-force gather. */
#ifndef VSGL_GBUFFER_H
#define VSGL_GBUFFER_H

#include "scene/scene_internal.h"

#define VSGL_GBUFFER_MISS 0xFFFFFFFFu

/* Structure of arrays; sample index = (row * width + col) * spp + s,
 * row 0 = top of the image, samples on a stratified aa x aa grid. */
typedef struct vsgl_gbuffer {
    uint32_t width, height, spp;   /* spp = aa * aa */
    size_t count;                  /* width * height * spp */
    float *pos[3];                 /* world position */
    float *nrm[3];                 /* shading normal, facing the camera */
    float *view[3];                /* unit direction from the point towards the camera */
    float *tan[3];                 /* unit tangent (anisotropy frame), orthogonal to nrm */
    uint32_t *material;            /* material index, VSGL_GBUFFER_MISS where nothing was hit */
} vsgl_gbuffer;

/* Trace the camera's primary rays (aa x aa per pixel) in parallel. */
vsgl_result vsgl__gbuffer_build(vsgl_context *ctx, const vsgl_scene *scene, uint32_t aa, vsgl_gbuffer *out);
void vsgl__gbuffer_free(vsgl_gbuffer *g);

#endif
