/* Internal: brute-force VPL gathering, the internal ground truth of the VSGL
 * approximation (same RSMs, exact BRDF on both ends, no lobe fitting).
 * Owner: csrc/src/shade/brute_force.c. */
#ifndef VSGL_SHADE_BRUTE_FORCE_H
#define VSGL_SHADE_BRUTE_FORCE_H

#include "gbuffer/gbuffer.h"
#include "rsm/rsm.h"

/* Shade every G-buffer sample with every lit texel of every RSM as a
 * differential area emitter:
 *
 *   L(x -> v) += Phi_j * f_j(wi_j, -w) cos_j * f_x(w, v) cos_x / (d^2 + A_j/pi)
 *
 * w = unit direction from the sample x to VPL j at distance d, Phi_j the
 * texel flux (W), f_j the VPL material's exact BRDF lit from wi_j, cos_j =
 * n_j.(-w), f_x the receiver's BRDF, cos_x = n_x.w, A_j the texel's
 * footprint (rsm->area). The regularised distance d^2 + A_j/pi is exact
 * on the axis of a Lambertian disk of area A_j (irradiance pi L R^2 /
 * (d^2 + R^2)); it tends to d^2 beyond the texel's size and bounds the
 * 1/d^2 singularity at contact. Measured against Cycles (room, RSM 128):
 * no regularisation keeps the mean within 0.2 % but hot pixels raise
 * relMSE to 0.05; max(d^2, A_j) and d^2 + A_j/pi both lose ~1.7 % of the
 * diffuse mean in corners at relMSE 0.014 (docs/validation.md).
 * visibility != 0: one shadow ray per pair (vsgl__scene_occluded), else
 * none.
 *
 * Outputs, each g->count * 3 floats in G-buffer sample order, NULL if not
 * wanted (misses give 0 everywhere):
 *   diffuse_light  DiffInd: diffuse radiance / DiffCol (0 where DiffCol is 0)
 *   glossy_light   GlossInd: glossy radiance / GlossCol (0 where GlossCol is 0)
 *   diffuse_color  DiffCol: Lambert albedo base * (1 - metallic)
 *   glossy_color   GlossCol: vsgl__glossy_color (Blender 3.x: 1 or 0)
 * Per pixel, as Cycles does: average DiffCol and DiffInd*DiffCol over the
 * pixel's samples, then divide (see vsgl__brute_force_resolve).
 *
 * Parallel over samples (chunks of 64), deterministic for any thread count
 * (each sample sums its VPLs in order, in double). Progress "gather".
 * Returns VSGL_OK, VSGL_ERROR_OUT_OF_MEMORY, VSGL_ERROR_CANCELLED (outputs
 * then partially written). */
vsgl_result vsgl__brute_force_shade(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_gbuffer *g,
                                    const vsgl_rsm *rsms, uint32_t rsm_count, int visibility,
                                    float *diffuse_light, float *glossy_light,
                                    float *diffuse_color, float *glossy_color);

/* Per-sample planes (as written above) -> per-pixel planes (width*height*3,
 * rows from the top): colours averaged, light = mean(light * colour) /
 * mean(colour), 0 where the mean colour is 0. Any pointer pair may be NULL.
 * In/out may not alias. */
void vsgl__brute_force_resolve(const vsgl_gbuffer *g, const float *sample_light, const float *sample_color,
                               float *pixel_light, float *pixel_color);

#endif
