/**
 * @file vsgl/debug.h
 * @brief Test and debugging helpers: expose internal stages of the
 * pipeline so that they can be checked against an external reference
 * (Cycles' Position/Normal passes). Not needed for rendering; the
 * signatures may change between minor versions.
 */
#ifndef VSGL_DEBUG_H
#define VSGL_DEBUG_H

#include "scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief Build the camera G-buffer of @p scene and copy it out.
 *
 * Samples: @p aa x @p aa per pixel on a stratified grid, sample s = j*aa + i
 * of pixel (col, row) at raster position (col + (i+0.5)/aa, row + (j+0.5)/aa),
 * row 0 = top of the image (aa = 1: pixel centres). Element index
 * e = (row * width + col) * aa*aa + s, with width/height the camera's.
 *
 * @param[in]  aa         samples per pixel per axis, 1..16 (0 means 1).
 * @param[out] positions  NULL or count*3 floats: world position (m), 0 where missed.
 * @param[out] normals    NULL or count*3 floats: unit shading normal facing the
 *                        camera side of the surface (Cycles' Normal pass), 0 where missed.
 * @param[out] materials  NULL or count uint32: material index, 0xFFFFFFFF where missed.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT (NULL scene, aa > 16),
 *         ::VSGL_ERROR_OUT_OF_MEMORY, ::VSGL_ERROR_CANCELLED.
 *         Outputs are untouched on failure.
 */
VSGL_API vsgl_result vsgl_debug_gbuffer(vsgl_context *ctx, const vsgl_scene *scene, uint32_t aa,
                                        float *positions, float *normals, uint32_t *materials);

/**
 * @brief Like ::vsgl_debug_gbuffer, for the shading frame: same samples,
 * same element order.
 *
 * @param[out] tangents  NULL or count*3 floats: unit tangent orthogonal to the
 *                       shading normal (corner tangents, else UV dP/du, else
 *                       an edge; material's anisotropic rotation applied), 0 where missed.
 * @param[out] views     NULL or count*3 floats: unit direction from the point
 *                       towards the camera (set for misses too: minus the ray direction).
 * @return as ::vsgl_debug_gbuffer.
 */
VSGL_API vsgl_result vsgl_debug_gbuffer_frames(vsgl_context *ctx, const vsgl_scene *scene, uint32_t aa,
                                               float *tangents, float *views);

#ifdef __cplusplus
}
#endif
#endif /* VSGL_DEBUG_H */
