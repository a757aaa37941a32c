/**
 * @file vsgl/lobes.h
 * @brief Reflection lobes as SGs/ASGs: Lambert, GGX/Beckmann NDFs,
 * spherical warping from half-vector to light-direction space, the smooth
 * Fresnel/shadowing factor, Ward and Ashikhmin-Shirley.
 *
 * Directions: @p n surface normal, @p view the unit direction from the
 * surface towards the viewer (o), @p light towards the light (i).
 * Roughness @p alpha is the microfacet alpha (Blender roughness squared),
 * clamped to [2^-31, 1]. Pure, thread-safe, never fails.
 */
#ifndef VSGL_LOBES_H
#define VSGL_LOBES_H

#include "asg.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Smallest microfacet alpha used (2^-31); smaller values are clamped. */
#define VSGL_ALPHA_MIN 4.656612873077393e-10f

/**
 * @brief Lambert lobe as a normalised SG: max(w.n,0)/pi ~ G(w; n, l_d)/A(l_d)
 * with l_d = vsgl_sg_cosine_sharpness() (poster Eq. 1).
 */
VSGL_API void vsgl_lambert_to_sg(const vsgl_vec3 *n, vsgl_sg *out);

/** NDF families for ::vsgl_ndf_to_sg. */
#define VSGL_NDF_GGX      0
#define VSGL_NDF_BECKMANN 1

/** @brief NDF sharpness lambda_h = 2 / alpha^2 (capped at VSGL_SHARPNESS_MAX). */
VSGL_API float vsgl_ndf_sharpness(float alpha);

/**
 * @brief Isotropic NDF D(h) ~ (1/(pi alpha^2)) exp(lambda_h (h.n - 1)):
 * axis n, sharpness 2/alpha^2, amplitude the NDF's peak 1/(pi alpha^2).
 */
VSGL_API void vsgl_ndf_to_sg(const vsgl_vec3 *n, float alpha, int32_t ndf, vsgl_sg *out);

/**
 * @brief Anisotropic NDF as an ASG in half-vector space: z = n, x = the
 * tangent (made orthogonal to n), bandwidths 1/alpha_x^2 and 1/alpha_y^2,
 * amplitude the peak 1/(pi alpha_x alpha_y).
 */
VSGL_API void vsgl_ndf_aniso_to_asg(const vsgl_vec3 *n, const vsgl_vec3 *tangent,
                                    float alpha_x, float alpha_y, vsgl_asg *out);

/**
 * @brief Spherical warping of an NDF SG to light-direction space as an SG
 * (Wang et al. 2009): axis reflect(view, n) = 2 (o.n) n - o, sharpness
 * lambda_h / (4 |o.n|) (|o.n| floored at 1e-6), amplitude kept.
 */
VSGL_API void vsgl_warp_ndf_sg(const vsgl_sg *ndf, const vsgl_vec3 *view, vsgl_sg *out);

/**
 * @brief Spherical warping of an NDF ASG (half-vector space) to an ASG in
 * light-direction space (Xu et al. 2013 Sec. 5.2): lobe axis the reflection
 * of @p view about the NDF axis, bandwidths and frame from the 2x2 Hessian
 * of the warped exponent at that axis (derived in docs/math.md).
 * An isotropic NDF of SG sharpness s gives bandwidths s/(8 (o.n)^2)
 * across the plane of incidence and s/8 within it.
 */
VSGL_API void vsgl_warp_ndf_asg(const vsgl_asg *ndf, const vsgl_vec3 *view, vsgl_asg *out);

/**
 * @brief The smooth factor M of a microfacet lobe, rho_s(i,o) cos(i) =
 * M(i) D(h): F_schlick(i.h; f0) G2(i, o; alpha) / (4 |o.n|), G2 the
 * height-correlated Smith GGX masking-shadowing.
 * Evaluate it at the lobe axis. Returns 0 if i or o is below the surface.
 * (vsgl_render's shading uses the material's own Fresnel and shadowing
 * instead, those of its exact BRDF: Schlick's F is 23 % below a dielectric's
 * at 55 degrees.)
 */
VSGL_API float vsgl_specular_factor(const vsgl_vec3 *n, const vsgl_vec3 *view,
                                    const vsgl_vec3 *light, float alpha, float f0);

/**
 * @brief Ward NDF as an ASG (Xu et al. Sec. 5.2): frame [x, y, n],
 * bandwidths 1/alpha_x^2, 1/alpha_y^2, amplitude 1.
 */
VSGL_API void vsgl_ward_to_asg(const vsgl_vec3 *n, const vsgl_vec3 *x,
                               float alpha_x, float alpha_y, vsgl_asg *out);

/**
 * @brief Ashikhmin-Shirley NDF as an ASG (Xu et al. Sec. 5.2): frame
 * [u, v, n], bandwidths n_u/2, n_v/2, amplitude 1.
 */
VSGL_API void vsgl_ashikhmin_shirley_to_asg(const vsgl_vec3 *n, const vsgl_vec3 *u,
                                            float n_u, float n_v, vsgl_asg *out);

#ifdef __cplusplus
}
#endif
#endif /* VSGL_LOBES_H */
