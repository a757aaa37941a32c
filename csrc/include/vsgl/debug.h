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
#include "render.h"

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

/** One fitted VSGL (vsgl_render's VSGL method), world frame, metres. */
typedef struct vsgl_debug_vsgl {
    float mean[3];      /**< mean VPL position */
    float variance;     /**< positional variance per axis (m^2), widening included */
    float axis[3];      /**< unit axis of the radiant intensity */
    float sharpness;    /**< its SG sharpness */
    float power[3];     /**< RGB power (W) */
    float normal[3];    /**< unit mean surface normal of the cluster */
    float coherence;    /**< length of the mean normal, 0..1 (1: every VPL faces the same way) */
    uint32_t light;     /**< scene light index */
    uint32_t lobe;      /**< 0 diffuse, 1 specular */
} vsgl_debug_vsgl;

/**
 * @brief Fit the VSGLs that ::vsgl_render would shade with @p settings
 * (RSM resolution, fit mode, count, estimator) and copy them out.
 * @param[in,out] count in: capacity of @p out (0 with @p out NULL asks for
 *        the count); out: the number of VSGLs.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT (bad settings; a
 *         capacity below the count: *count then holds the count),
 *         ::VSGL_ERROR_OUT_OF_MEMORY.
 */
VSGL_API vsgl_result vsgl_debug_vsgls(vsgl_context *ctx, const vsgl_scene *scene,
                                      const vsgl_render_settings *settings, size_t *count,
                                      vsgl_debug_vsgl *out);

#ifdef __cplusplus
}
#endif
#endif /* VSGL_DEBUG_H */
