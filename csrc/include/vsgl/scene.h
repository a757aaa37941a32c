/**
 * @file vsgl/scene.h
 * @brief Scene input: triangles, materials, lights and camera as flat,
 * caller-owned arrays, validated and copied into an opaque ::vsgl_scene
 * (with its ray-tracing acceleration structure).
 *
 * Frames and units: world space is Blender's (+Z up, metres). Matrices are
 * 3x4 row-major affine transforms "world_from_local", i.e. Blender's
 * `matrix_world` without its last row: world = M[:, :3] * local + M[:, 3].
 * A camera looks down its local -Z with +Y up; a spot, area or sun light
 * emits along its local -Z. Light power follows Cycles (docs/units.md).
 */
#ifndef VSGL_SCENE_H
#define VSGL_SCENE_H

#include "base.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------ */
/* Materials                                                                  */
/* ------------------------------------------------------------------------ */

/** Material flags. */
#define VSGL_MATERIAL_UNSUPPORTED 1u /**< the caller's mark that it could not map the material: kept (bundles
                                          carry it) but not read by the library, which shades it as given */
/** GGX shadowing as Cycles in Blender 4.x and later: height-correlated Smith
 *  1 / (1 + L(i) + L(o)); without it Blender 3.x's separable G1(i) G1(o). */
#define VSGL_MATERIAL_FLAG_BLENDER_4 2u
/** GGX with the multiple-scattering energy compensation of Cycles 4.x+
 *  ("Multiscatter GGX", the Principled BSDF's default there): the glossy
 *  lobe seen from a view of cosine mu is scaled by 1 + F_ms (1 - E1(mu)) /
 *  E1(mu), E1 the lobe's single-scatter albedo with F = 1, F_ms =
 *  F_avg E_avg / (1 - F_avg (1 - E_avg)) (E_avg the mean of E1, F_avg of F). */
#define VSGL_MATERIAL_FLAG_MULTISCATTER 4u
/** The diffuse base as Blender 3.x's Principled BSDF reflects it (Burley's
 *  2012 "Disney" diffuse: retro-reflection on rough surfaces, darkening on
 *  smooth ones at grazing angles): base (1 - metallic) / pi times
 *  (1 + k (1 - cos_i)^5)(1 + k (1 - cos_o)^5), k = 2 roughness (i.h)^2 - 1/2.
 *  Without it the diffuse base is Lambert's (Blender 4.x+, and the Diffuse
 *  BSDF). DiffCol stays the base colour either way, as Cycles 3.x writes it. */
#define VSGL_MATERIAL_FLAG_BURLEY 8u
/** Every material flag this version knows; other bits are rejected. */
#define VSGL_MATERIAL_FLAGS_KNOWN                                                                 \
    (VSGL_MATERIAL_UNSUPPORTED | VSGL_MATERIAL_FLAG_BLENDER_4 | VSGL_MATERIAL_FLAG_MULTISCATTER | \
     VSGL_MATERIAL_FLAG_BURLEY)

/**
 * The Principled BSDF subset the method models. Zero-initialised is black.
 * Specular reflectance at normal incidence of the dielectric layer is
 * @p specular_f0 (Blender 3.x: 0.08 * Specular; 4.x: from IOR and
 * "Specular IOR Level"; the add-on converts). Metallic blends towards a
 * conductor with F0 = base_color.
 */
typedef struct vsgl_material {
    float base_color[3];     /**< linear RGB albedo in [0, 1] */
    float metallic;          /**< [0, 1] */
    float roughness;         /**< Blender roughness in [0, 1]; alpha = roughness^2 */
    float specular_f0;       /**< dielectric F0 in [0, 1], typically 0.04 */
    float anisotropy;        /**< [0, 1]; Cycles' mapping to alpha_x, alpha_y */
    float anisotropic_rotation; /**< [0, 1] turns of the tangent about the normal */
    uint32_t flags;          /**< VSGL_MATERIAL_* */
    uint32_t reserved;       /**< must be 0 (room for texture slots) */
} vsgl_material;

/* ------------------------------------------------------------------------ */
/* Textures                                                                   */
/* ------------------------------------------------------------------------ */

/** Texture flags. */
/** The RGB channels hold sRGB-encoded values (an 8-bit image whose colour
 *  space is sRGB, as Blender's Image.pixels hands it over). As Cycles does
 *  for such images, lookups in the full-resolution level interpolate the
 *  encoded values and decode the result; the coarser mip levels average
 *  decoded (linear) values. Alpha is always linear. */
#define VSGL_TEXTURE_FLAG_SRGB 1u
#define VSGL_TEXTURE_FLAGS_KNOWN VSGL_TEXTURE_FLAG_SRGB

/**
 * An image, as caller-owned float RGBA pixels; copied (and mip-mapped: 2 x 2
 * box-filtered levels down to 1 x 1) by ::vsgl_scene_create.
 * Rows run bottom to top: texel (i, j) covers u in [i/w, (i+1)/w],
 * v in [j/h, (j+1)/h], i.e. Blender's Image.pixels order, with UV (0, 0) at
 * the image's bottom-left corner. Pixels are linear RGB unless
 * ::VSGL_TEXTURE_FLAG_SRGB; they must be finite (values outside [0, 1] are
 * allowed: colour slots clamp the product to [0, 1]).
 */
typedef struct vsgl_texture {
    uint32_t width, height;  /**< texels, 1..65536 each */
    const float *pixels;     /**< width * height * 4 floats (RGBA) */
    uint32_t flags;          /**< VSGL_TEXTURE_FLAG_* */
    uint32_t reserved;       /**< must be 0 */
} vsgl_texture;

#define VSGL_FILTER_LINEAR  0 /**< bilinear (Blender "Linear"; "Cubic"/"Smart" are taken as this) */
#define VSGL_FILTER_CLOSEST 1 /**< nearest texel (Blender "Closest") */

#define VSGL_WRAP_REPEAT 0    /**< Blender "Repeat" */
#define VSGL_WRAP_EXTEND 1    /**< Blender "Extend": edge texels continue */
#define VSGL_WRAP_CLIP   2    /**< Blender "Clip": transparent black outside [0, 1] */

/**
 * Where a material input reads a texture. Zero-initialised = unused.
 * The lookup point is the surface's UV (vsgl_scene_desc.corner_uvs,
 * interpolated; (0, 0) without UVs) mapped by @p uv_transform. Lookups are
 * filtered over the footprint of what asks (a camera sample's share of its
 * pixel, an RSM texel's patch): trilinear between mip levels chosen from the
 * footprint's area in texels (isotropic), so a distant wall averages its
 * texture instead of aliasing. ::VSGL_FILTER_CLOSEST takes the nearest
 * texel of level 0 while the footprint is under one texel.
 */
typedef struct vsgl_texture_slot {
    uint32_t texture;        /**< 1 + index into vsgl_scene_desc.textures; 0 = unused */
    int32_t filter;          /**< VSGL_FILTER_* */
    int32_t wrap;            /**< VSGL_WRAP_* */
    int32_t channel;         /**< scalar inputs: 0..3 = R, G, B, A; colour inputs ignore it */
    /** (u', v') = (m[0] u + m[1] v + m[2], m[3] u + m[4] v + m[5]); all zero = identity
     *  (Blender's Mapping node of type Point/Texture, folded in by the caller) */
    float uv_transform[6];
} vsgl_texture_slot;

/** Base colour is also multiplied by the interpolated corner colour
 *  (vsgl_scene_desc.corner_colors; white where the scene has none). */
#define VSGL_MATERIAL_TEXTURES_VERTEX_COLOR 1u
#define VSGL_MATERIAL_TEXTURES_FLAGS_KNOWN VSGL_MATERIAL_TEXTURES_VERTEX_COLOR

/**
 * Textured inputs of one material (vsgl_scene_desc.material_textures,
 * parallel to materials). Each used slot multiplies the material's constant:
 * base colour = clamp01(base_color x texture RGB [x corner colour]),
 * roughness = clamp01(roughness x texture channel), metallic likewise. A
 * caller mapping a texture linked straight into an input sets the constant
 * to 1; node chains in front of the input (mix, multiply, invert, hue /
 * saturation, colour ramps) are baked into the texture's pixels by the
 * caller. The material's constants are its untextured values for
 * everything the library precomputes per material (the glossy albedo
 * tables: a textured roughness or metallic uses the constants' tables).
 */
typedef struct vsgl_material_textures {
    vsgl_texture_slot base_color;
    vsgl_texture_slot roughness;
    vsgl_texture_slot metallic;
    uint32_t flags;          /**< VSGL_MATERIAL_TEXTURES_* */
    uint32_t reserved;       /**< must be 0 */
} vsgl_material_textures;

/* ------------------------------------------------------------------------ */
/* Lights                                                                     */
/* ------------------------------------------------------------------------ */

#define VSGL_LIGHT_POINT 0
#define VSGL_LIGHT_SPOT  1
#define VSGL_LIGHT_SUN   2
#define VSGL_LIGHT_AREA  3

#define VSGL_AREA_SQUARE    0
#define VSGL_AREA_RECTANGLE 1
#define VSGL_AREA_DISK      2
#define VSGL_AREA_ELLIPSE   3

/**
 * A light with Blender semantics and Cycles units.
 * - @p power: watts for point, spot and area; irradiance in W/m^2 for sun.
 *   The caller folds in Blender 4's exposure (2^exposure) and blackbody.
 * - @p color: linear RGB multiplier of @p power.
 * - @p world_from_light: the object's matrix; scale is allowed (an area's
 *   size is scaled by it).
 * - Lights follow Cycles as measured (docs/units.md). By default
 *   (@p flags 0) Blender 3.x: a spot's intensity inside the cone carries an
 *   extra cos(theta) and its cone ignores the object's scale; an area light
 *   of P watts emits pi P / 4 W (radiance P / (4 A)). With
 *   ::VSGL_LIGHT_FLAG_BLENDER_4, Blender 4.x and later (measured in 4.2 and
 *   5.0): a spot has no cos(theta) and its cone follows the object's scaled
 *   axes (a spot scaled (1, 0.5, 1) has an elliptical cone, half as wide in
 *   tangent along its local Y); an area light of P watts emits P W
 *   (radiance P / (pi A)). Point and sun lights are the same in both.
 */
typedef struct vsgl_light {
    int32_t type;            /**< VSGL_LIGHT_* */
    int32_t area_shape;      /**< VSGL_AREA_* (area lights only) */
    float color[3];
    float power;
    float world_from_light[12];
    float radius;            /**< point/spot soft radius in metres (>= 0) */
    float spot_size;         /**< full cone angle in radians, (0, pi] */
    float spot_blend;        /**< [0, 1] */
    float sun_angle;         /**< angular diameter in radians, [0, pi] */
    float size_x, size_y;    /**< area size in metres (size_y ignored for square/disk) */
    float spread;            /**< area spread in radians, (0, pi] */
    uint32_t flags;          /**< VSGL_LIGHT_FLAG_* bits; 0 = Blender 3.x semantics */
} vsgl_light;

/** Spot and area lights as Cycles in Blender 4.x and later (see ::vsgl_light). */
#define VSGL_LIGHT_FLAG_BLENDER_4 1u
/** Every flag this version knows; other bits are rejected. */
#define VSGL_LIGHT_FLAGS_KNOWN VSGL_LIGHT_FLAG_BLENDER_4

/* ------------------------------------------------------------------------ */
/* Camera                                                                     */
/* ------------------------------------------------------------------------ */

#define VSGL_CAMERA_PERSPECTIVE  0
#define VSGL_CAMERA_ORTHOGRAPHIC 1

#define VSGL_SENSOR_FIT_AUTO       0
#define VSGL_SENSOR_FIT_HORIZONTAL 1
#define VSGL_SENSOR_FIT_VERTICAL   2

/**
 * Blender camera. @p width/@p height are the final pixel counts (after
 * resolution percentage). Shift is in units of the larger image side, as
 * in Blender. Pixel aspect is Blender's (x, y).
 */
typedef struct vsgl_camera {
    int32_t type;            /**< VSGL_CAMERA_* */
    int32_t sensor_fit;      /**< VSGL_SENSOR_FIT_* */
    float world_from_camera[12];
    float lens_mm;           /**< focal length (perspective) */
    float sensor_width_mm;
    float sensor_height_mm;
    float ortho_scale;       /**< orthographic view size in metres */
    float shift_x, shift_y;
    float clip_start, clip_end;
    uint32_t width, height;  /**< pixels */
    float pixel_aspect_x, pixel_aspect_y;
} vsgl_camera;

/* ------------------------------------------------------------------------ */
/* Scene description and handle                                               */
/* ------------------------------------------------------------------------ */

/**
 * Everything the library reads, as caller-owned arrays; only read during
 * ::vsgl_scene_create (copied). Instances arrive flattened by the caller.
 */
typedef struct vsgl_scene_desc {
    uint32_t size;                 /**< sizeof(vsgl_scene_desc) or 0 */
    uint32_t vertex_count;
    const float *positions;        /**< vertex_count * 3, world space, metres */
    uint32_t triangle_count;
    const uint32_t *indices;       /**< triangle_count * 3 vertex indices */
    const float *corner_normals;   /**< triangle_count * 9 (split normals); NULL = face normals */
    const float *corner_uvs;       /**< triangle_count * 6; NULL = none */
    const float *corner_tangents;  /**< triangle_count * 12 (xyz + bitangent sign); NULL = derived */
    const uint32_t *material_indices; /**< triangle_count; NULL = all 0 */
    uint32_t material_count;       /**< >= 1 if triangle_count > 0 */
    const vsgl_material *materials;
    uint32_t light_count;
    const vsgl_light *lights;
    const vsgl_camera *camera;     /**< required */
    /* Since 0.2: textures. A caller built against 0.1 passes the smaller
     * size (or 0 with these fields zeroed): no textures. */
    uint32_t texture_count;
    const vsgl_texture *textures;  /**< texture_count; NULL if 0 */
    const vsgl_material_textures *material_textures; /**< material_count entries; NULL = none textured */
    const float *corner_colors;    /**< triangle_count * 9 linear RGB (colour attribute); NULL = white */
} vsgl_scene_desc;

/** Size of a vsgl_scene_desc of library 0.1 (before textures): accepted as @c size. */
#define VSGL_SCENE_DESC_SIZE_0_1 ((uint32_t)offsetof(vsgl_scene_desc, texture_count))

/** Opaque validated scene with its acceleration structure. Immutable but for
 *  ::vsgl_scene_set_view; may be shared by threads while nobody changes it. */
typedef struct vsgl_scene vsgl_scene;

/**
 * @brief Validate @p desc and build a scene.
 *
 * Every array, count and index is checked: NaN/Inf, out-of-range indices,
 * degenerate triangles (zero area or a zero-length corner normal:
 * reported as warnings, counted in vsgl_scene_info.dropped_triangles and
 * dropped), non-finite or singular matrices, non-positive sizes, unknown
 * enums. The first error is returned with a message naming the element,
 * e.g. "light 3: spot size is 0" (see ::vsgl_context_last_error).
 *
 * @param[out] out receives the scene, NULL on failure.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT, ::VSGL_ERROR_OUT_OF_MEMORY,
 *         ::VSGL_ERROR_INTERNAL (the ray-tracing kernel failed).
 */
VSGL_API vsgl_result vsgl_scene_create(vsgl_context *ctx, const vsgl_scene_desc *desc,
                                       vsgl_scene **out);

/** @brief Release a scene. NULL is allowed. */
VSGL_API void vsgl_scene_destroy(vsgl_scene *scene);

/**
 * @brief Replace the camera and the lights of @p scene, keeping its
 * geometry, materials and acceleration structure (what an interactive
 * view changes between frames; a new scene costs a BVH build).
 *
 * Both are validated as ::vsgl_scene_create validates them; on any error
 * the scene is left unchanged. Not to be called while another call (e.g.
 * ::vsgl_render) uses @p scene. A render after it equals a render of a
 * scene created with the same camera and lights, bit for bit.
 *
 * @param[in] camera      required; copied.
 * @param[in] lights      @p light_count lights (world space, as in
 *                        vsgl_scene_desc); copied. 0 lights is allowed.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT (message names the light
 *         or camera field), ::VSGL_ERROR_OUT_OF_MEMORY.
 */
VSGL_API vsgl_result vsgl_scene_set_view(vsgl_context *ctx, vsgl_scene *scene, const vsgl_camera *camera,
                                         const vsgl_light *lights, uint32_t light_count);

/** Counts after validation (degenerate triangles dropped). */
typedef struct vsgl_scene_info {
    uint32_t size;               /**< sizeof(vsgl_scene_info) or 0, set by the caller; read, not written */
    uint32_t triangle_count;
    uint32_t dropped_triangles;
    uint32_t light_count;
    uint32_t material_count;
    float bounds_min[3], bounds_max[3];
} vsgl_scene_info;

/**
 * @brief Fill @p info. Both pointers must be non-NULL; set @p info->size to
 * sizeof(vsgl_scene_info) or 0 first.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT (also for a size this
 *         library does not know).
 */
VSGL_API vsgl_result vsgl_scene_get_info(const vsgl_scene *scene, vsgl_scene_info *info);

#ifdef __cplusplus
}
#endif
#endif /* VSGL_SCENE_H */
