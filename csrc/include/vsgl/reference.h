/**
 * @file vsgl/reference.h
 * @brief Test-only entry points: the reflective shadow maps of a scene and
 * the brute-force one-bounce reference (every RSM texel a VPL, exact BRDF),
 * for checks against Cycles and analytic values. Not needed for rendering;
 * signatures may change between minor versions.
 */
#ifndef VSGL_REFERENCE_H
#define VSGL_REFERENCE_H

#include "scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @brief Build the RSM of light @p light at @p res texels per side and copy
 * it out. Texel count = faces * res * res (6 faces for point lights and
 * spots wider than 120 degrees, else 1): pass NULL arrays to learn it.
 *
 * @param[out] count      texel count (required).
 * @param[out] positions  NULL or count*3 floats: VPL position (m), 0 if empty.
 * @param[out] normals    NULL or count*3 floats: shading normal facing the light.
 * @param[out] flux       NULL or count*3 floats: RGB power (W) the texel
 *                        receives (Cycles light units, docs/units.md).
 * @param[out] areas      NULL or count floats: footprint of the texel (m^2).
 * @param[out] materials  NULL or count uint32: material index, 0xFFFFFFFF if empty.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT (NULL scene/count, light
 *         index, res outside 1..16384), ::VSGL_ERROR_OUT_OF_MEMORY,
 *         ::VSGL_ERROR_CANCELLED. Arrays untouched on failure.
 */
VSGL_API vsgl_result vsgl_reference_rsm(vsgl_context *ctx, const vsgl_scene *scene, uint32_t light,
                                        uint32_t res, size_t *count, float *positions, float *normals,
                                        float *flux, float *areas, uint32_t *materials);

/**
 * @brief The exact BRDF of the brute-force reference (docs/units.md,
 * "Materials"): for @p count direction pairs, f(wi, wo) * max(wi.n, 0) of
 * material @p m, split into the diffuse and the glossy lobe.
 *
 * @param[in]  normals, tangents, wi, wo  count*3 floats each: unit shading
 *             normal, tangent (anisotropy frame), direction towards the
 *             light, direction towards the viewer (both away from the surface);
 *             the glossy lobe's multiple-scattering compensation
 *             (VSGL_MATERIAL_FLAG_MULTISCATTER) is taken for this viewer.
 * @param[out] diffuse, glossy  NULL or count*3 floats (RGB, 1/sr).
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT (NULL material or input array).
 */
VSGL_API vsgl_result vsgl_reference_brdf(const vsgl_material *m, uint32_t count, const float *normals,
                                         const float *tangents, const float *wi, const float *wo,
                                         float *diffuse, float *glossy);

/** Timings and sizes of ::vsgl_reference_render (seconds, bytes). */
typedef struct vsgl_reference_stats {
    double seconds_gbuffer;
    double seconds_rsm;
    double seconds_gather;
    uint64_t rsm_bytes;      /**< memory of all RSMs held during the gather */
    uint64_t vpl_count;      /**< lit texels, all lights */
    double total_flux[3];    /**< sum of RSM flux, all lights (W) */
} vsgl_reference_stats;

/**
 * @brief Brute-force one-bounce indirect light: camera G-buffer (@p aa x
 * @p aa samples per pixel), one RSM per light at @p rsm_res, then every
 * sample shaded by every lit texel with the exact BRDF on both ends
 * (distance clamped at the texel footprint; @p visibility 1 = one shadow
 * ray per pair). Planes are width*height*3 floats, rows from the top,
 * NULL if not wanted; names follow Cycles' passes (DiffInd, GlossInd =
 * light only; DiffCol, GlossCol = colours; per pixel light =
 * mean(light*colour)/mean(colour)).
 * @param[out] stats may be NULL.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT, ::VSGL_ERROR_OUT_OF_MEMORY,
 *         ::VSGL_ERROR_CANCELLED.
 */
VSGL_API vsgl_result vsgl_reference_render(vsgl_context *ctx, const vsgl_scene *scene, uint32_t rsm_res,
                                           uint32_t aa, int32_t visibility, float *diffuse_light,
                                           float *glossy_light, float *diffuse_color, float *glossy_color,
                                           vsgl_reference_stats *stats);

#ifdef __cplusplus
}
#endif
#endif /* VSGL_REFERENCE_H */
