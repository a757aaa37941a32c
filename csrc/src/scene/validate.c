/* Validation of everything a caller passes in a vsgl_scene_desc. The first
 * problem found is reported with a message naming the element, e.g.
 * "light 3: spot size is 0" or "triangle 17: vertex index 99 out of range
 * (vertex_count 40)". Checks run in a fixed order: header, camera,
 * materials, lights, vertices, triangles. */
#include "scene/scene_data.h"
#include "core/versioned.h"
#include "math/constants.h"

#include <math.h>
#include <string.h>
#include <stdio.h>

/* Largest accepted coordinate magnitude: keeps products of coordinates
 * (cross products, squared distances) finite in float. */
#define VSGL__MAX_COORD 1e18f

static int finite_f(float x) { return isfinite(x) != 0; }

const char *vsgl__matrix_problem(const float m[12])
{
    for (int i = 0; i < 12; ++i) {
        if (!finite_f(m[i]))
            return "is not finite";
        if (fabsf(m[i]) > VSGL__MAX_COORD)
            return "has an element above 1e18";
    }
    /* determinant of the 3x3 part, relative to the product of column lengths */
    double a[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            a[r][c] = m[r * 4 + c];
    double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
               - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
               + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    double scale = 1.0;
    for (int c = 0; c < 3; ++c)
        scale *= sqrt(a[0][c] * a[0][c] + a[1][c] * a[1][c] + a[2][c] * a[2][c]);
    if (!(scale > 0.0) || !(fabs(det) > 1e-12 * scale))
        return "is singular";
    return NULL;
}

/* "who: field is value" if value is outside [lo, hi] or not finite. */
#define CHECK_RANGE(ctx, who, field, value, lo, hi)                                       \
    do {                                                                                  \
        float v_ = (value);                                                               \
        if (!finite_f(v_) || v_ < (lo) || v_ > (hi))                                      \
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT,                           \
                              "%s: %s is %g (must be in [%g, %g])", who, field, (double)v_, \
                              (double)(lo), (double)(hi));                                \
    } while (0)

#define CHECK_POSITIVE(ctx, who, field, value)                                            \
    do {                                                                                  \
        float v_ = (value);                                                               \
        if (!finite_f(v_) || !(v_ > 0.0f))                                                \
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT,                           \
                              "%s: %s is %g (must be > 0)", who, field, (double)v_);      \
    } while (0)

#define CHECK_FINITE(ctx, who, field, value)                                              \
    do {                                                                                  \
        float v_ = (value);                                                               \
        if (!finite_f(v_) || fabsf(v_) > VSGL__MAX_COORD)                                  \
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT,                           \
                              "%s: %s is %g (must be finite, |x| <= 1e18)", who, field,   \
                              (double)v_);                                                \
    } while (0)

vsgl_result vsgl__validate_camera(vsgl_context *ctx, const vsgl_camera *c)
{
    const char *who = "camera";
    if (c->type != VSGL_CAMERA_PERSPECTIVE && c->type != VSGL_CAMERA_ORTHOGRAPHIC)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "camera: type is %d (must be 0 perspective or 1 orthographic)", (int)c->type);
    if (c->sensor_fit < VSGL_SENSOR_FIT_AUTO || c->sensor_fit > VSGL_SENSOR_FIT_VERTICAL)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "camera: sensor_fit is %d (must be 0 auto, 1 horizontal or 2 vertical)", (int)c->sensor_fit);
    const char *mp = vsgl__matrix_problem(c->world_from_camera);
    if (mp)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "camera: world_from_camera %s", mp);
    if (c->type == VSGL_CAMERA_PERSPECTIVE) {
        if (!finite_f(c->lens_mm) || !(c->lens_mm > 0.0f))
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "camera: lens_mm is %g", (double)c->lens_mm);
    } else {
        CHECK_FINITE(ctx, who, "lens_mm", c->lens_mm);
        CHECK_POSITIVE(ctx, who, "ortho_scale", c->ortho_scale);
    }
    CHECK_POSITIVE(ctx, who, "sensor_width_mm", c->sensor_width_mm);
    CHECK_POSITIVE(ctx, who, "sensor_height_mm", c->sensor_height_mm);
    CHECK_FINITE(ctx, who, "ortho_scale", c->ortho_scale);
    CHECK_FINITE(ctx, who, "shift_x", c->shift_x);
    CHECK_FINITE(ctx, who, "shift_y", c->shift_y);
    if (!finite_f(c->clip_start) || c->clip_start < 0.0f)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "camera: clip_start is %g (must be >= 0)", (double)c->clip_start);
    if (!finite_f(c->clip_end) || !(c->clip_start < c->clip_end))
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "camera: clip_end is %g (must be finite and > clip_start %g)",
                          (double)c->clip_end, (double)c->clip_start);
    if (c->width < 1 || c->width > 65535)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "camera: width is %u (must be in [1, 65535])", (unsigned)c->width);
    if (c->height < 1 || c->height > 65535)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "camera: height is %u (must be in [1, 65535])", (unsigned)c->height);
    CHECK_POSITIVE(ctx, who, "pixel_aspect_x", c->pixel_aspect_x);
    CHECK_POSITIVE(ctx, who, "pixel_aspect_y", c->pixel_aspect_y);
    if (c->pixel_aspect_x > 1e6f || c->pixel_aspect_y > 1e6f)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "camera: pixel aspect %g:%g is above 1e6",
                          (double)c->pixel_aspect_x, (double)c->pixel_aspect_y);
    return VSGL_OK;
}

vsgl_result vsgl__validate_material(vsgl_context *ctx, uint32_t index, const vsgl_material *m)
{
    char who[32];
    snprintf(who, sizeof who, "material %u", (unsigned)index);
    static const char *const rgb[3] = {"base_color[0]", "base_color[1]", "base_color[2]"};
    for (int k = 0; k < 3; ++k)
        CHECK_RANGE(ctx, who, rgb[k], m->base_color[k], 0.0f, 1.0f);
    CHECK_RANGE(ctx, who, "metallic", m->metallic, 0.0f, 1.0f);
    CHECK_RANGE(ctx, who, "roughness", m->roughness, 0.0f, 1.0f);
    CHECK_RANGE(ctx, who, "specular_f0", m->specular_f0, 0.0f, 1.0f);
    CHECK_RANGE(ctx, who, "anisotropy", m->anisotropy, 0.0f, 1.0f);
    CHECK_RANGE(ctx, who, "anisotropic_rotation", m->anisotropic_rotation, 0.0f, 1.0f);
    if (m->flags & ~(uint32_t)VSGL_MATERIAL_FLAGS_KNOWN)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "%s: flags 0x%x has unknown bits", who, (unsigned)m->flags);
    if (m->reserved != 0)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "%s: reserved is %u (must be 0)", who, (unsigned)m->reserved);
    return VSGL_OK;
}

vsgl_result vsgl__validate_light(vsgl_context *ctx, uint32_t index, const vsgl_light *l)
{
    char who[32];
    snprintf(who, sizeof who, "light %u", (unsigned)index);
    if (l->type < VSGL_LIGHT_POINT || l->type > VSGL_LIGHT_AREA)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "%s: type is %d (must be 0 point, 1 spot, 2 sun or 3 area)", who, (int)l->type);
    if (l->area_shape < VSGL_AREA_SQUARE || l->area_shape > VSGL_AREA_ELLIPSE)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "%s: area_shape is %d (must be 0 square, 1 rectangle, 2 disk or 3 ellipse)", who, (int)l->area_shape);
    static const char *const rgb[3] = {"color[0]", "color[1]", "color[2]"};
    for (int k = 0; k < 3; ++k)
        CHECK_RANGE(ctx, who, rgb[k], l->color[k], 0.0f, 3.0e38f);
    CHECK_RANGE(ctx, who, "power", l->power, 0.0f, 1e18f);
    const char *mp = vsgl__matrix_problem(l->world_from_light);
    if (mp)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "%s: world_from_light %s", who, mp);
    CHECK_RANGE(ctx, who, "radius", l->radius, 0.0f, 1e18f);
    /* fields of other light types must still be finite */
    CHECK_FINITE(ctx, who, "spot_size", l->spot_size);
    CHECK_FINITE(ctx, who, "spot_blend", l->spot_blend);
    CHECK_FINITE(ctx, who, "sun_angle", l->sun_angle);
    CHECK_FINITE(ctx, who, "size_x", l->size_x);
    CHECK_FINITE(ctx, who, "size_y", l->size_y);
    CHECK_FINITE(ctx, who, "spread", l->spread);
    if (l->type == VSGL_LIGHT_SPOT) {
        if (!(l->spot_size > 0.0f) || l->spot_size > VSGL__PI)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "%s: spot size is %g", who, (double)l->spot_size);
        CHECK_RANGE(ctx, who, "spot_blend", l->spot_blend, 0.0f, 1.0f);
    } else if (l->type == VSGL_LIGHT_SUN) {
        CHECK_RANGE(ctx, who, "sun_angle", l->sun_angle, 0.0f, VSGL__PI);
    } else if (l->type == VSGL_LIGHT_AREA) {
        CHECK_POSITIVE(ctx, who, "size_x", l->size_x);
        if (l->area_shape == VSGL_AREA_RECTANGLE || l->area_shape == VSGL_AREA_ELLIPSE)
            CHECK_POSITIVE(ctx, who, "size_y", l->size_y);
        if (!(l->spread > 0.0f) || l->spread > VSGL__PI)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "%s: spread is %g (must be in (0, pi])", who, (double)l->spread);
    }
    if (l->flags & ~VSGL_LIGHT_FLAGS_KNOWN)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "%s: flags 0x%x has unknown bits (known: 0x%x)", who,
                          (unsigned)l->flags, (unsigned)VSGL_LIGHT_FLAGS_KNOWN);
    return VSGL_OK;
}

static vsgl_result need_array(vsgl_context *ctx, const void *p, uint32_t count, const char *name, const char *count_name)
{
    if (count > 0 && !p)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "scene: %s is NULL but %s is %u", name, count_name, (unsigned)count);
    return VSGL_OK;
}

void vsgl__scene_desc_normalise(const vsgl_scene_desc *in, vsgl_scene_desc *out)
{
    /* an older, shorter desc (e.g. VSGL_SCENE_DESC_SIZE_0_1) gets zero
     * (absent) new fields; a size the library cannot read gives an empty
     * desc, which validation refuses */
    if (vsgl__copy_versioned(NULL, out, sizeof *out, in, "vsgl_scene_desc") != VSGL_OK)
        memset(out, 0, sizeof *out);
}

static vsgl_result validate_slot(vsgl_context *ctx, uint32_t m, const char *name, const vsgl_texture_slot *s,
                                 uint32_t texture_count)
{
    if (s->texture == 0)
        return VSGL_OK;
    if (s->texture > texture_count)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "material %u: %s texture is %u (1-based; texture_count %u)",
                          (unsigned)m, name, (unsigned)s->texture, (unsigned)texture_count);
    if (s->filter != VSGL_FILTER_LINEAR && s->filter != VSGL_FILTER_CLOSEST)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "material %u: %s filter is %d (unknown)", (unsigned)m, name,
                          (int)s->filter);
    if (s->wrap < VSGL_WRAP_REPEAT || s->wrap > VSGL_WRAP_CLIP)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "material %u: %s wrap is %d (unknown)", (unsigned)m, name,
                          (int)s->wrap);
    if (s->channel < 0 || s->channel > 3)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "material %u: %s channel is %d (must be 0..3)", (unsigned)m,
                          name, (int)s->channel);
    for (int k = 0; k < 6; ++k)
        if (!finite_f(s->uv_transform[k]) || fabsf(s->uv_transform[k]) > VSGL__MAX_COORD)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "material %u: %s uv_transform[%d] is %g (must be finite)",
                              (unsigned)m, name, k, (double)s->uv_transform[k]);
    return VSGL_OK;
}

static vsgl_result validate_textures(vsgl_context *ctx, const vsgl_scene_desc *d)
{
    vsgl_result r;
    if ((r = need_array(ctx, d->textures, d->texture_count, "textures", "texture_count")) != VSGL_OK)
        return r;
    for (uint32_t i = 0; i < d->texture_count; ++i) {
        const vsgl_texture *t = &d->textures[i];
        if (t->width < 1 || t->width > 65536 || t->height < 1 || t->height > 65536)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "texture %u: size %ux%u (each side must be in [1, 65536])",
                              (unsigned)i, (unsigned)t->width, (unsigned)t->height);
        if (!t->pixels)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "texture %u: pixels is NULL", (unsigned)i);
        if (t->flags & ~(uint32_t)VSGL_TEXTURE_FLAGS_KNOWN)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "texture %u: flags 0x%x has unknown bits", (unsigned)i,
                              (unsigned)t->flags);
        if (t->reserved != 0)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "texture %u: reserved is %u (must be 0)", (unsigned)i,
                              (unsigned)t->reserved);
        size_t n = (size_t)t->width * t->height * 4;
        for (size_t k = 0; k < n; ++k)
            if (!finite_f(t->pixels[k]) || fabsf(t->pixels[k]) > VSGL__MAX_COORD)
                return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "texture %u: texel (%zu, %zu) channel %zu is %g (must be finite)",
                                  (unsigned)i, (k / 4) % t->width, (k / 4) / t->width, k % 4, (double)t->pixels[k]);
    }
    if (d->material_textures)
        for (uint32_t m = 0; m < d->material_count; ++m) {
            const vsgl_material_textures *mt = &d->material_textures[m];
            if ((r = validate_slot(ctx, m, "base_color", &mt->base_color, d->texture_count)) != VSGL_OK ||
                (r = validate_slot(ctx, m, "roughness", &mt->roughness, d->texture_count)) != VSGL_OK ||
                (r = validate_slot(ctx, m, "metallic", &mt->metallic, d->texture_count)) != VSGL_OK)
                return r;
            if (mt->flags & ~(uint32_t)VSGL_MATERIAL_TEXTURES_FLAGS_KNOWN)
                return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "material %u: textures flags 0x%x has unknown bits",
                                  (unsigned)m, (unsigned)mt->flags);
            if (mt->reserved != 0)
                return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "material %u: textures reserved is %u (must be 0)",
                                  (unsigned)m, (unsigned)mt->reserved);
        }
    if (d->corner_colors)
        for (size_t k = 0; k < (size_t)d->triangle_count * 9; ++k)
            if (!finite_f(d->corner_colors[k]) || fabsf(d->corner_colors[k]) > VSGL__MAX_COORD)
                return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "triangle %zu: corner %zu colour channel %zu is %g (must be finite)",
                                  k / 9, (k % 9) / 3, k % 3, (double)d->corner_colors[k]);
    return VSGL_OK;
}

vsgl_result vsgl__validate_scene_desc(vsgl_context *ctx, const vsgl_scene_desc *d)
{
    vsgl_result r;
    if (d->size > sizeof(vsgl_scene_desc) || (d->size != 0 && (d->size < sizeof d->size || d->size % 4 != 0)))
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT,
                          "vsgl_scene_desc.size is %u: this library knows multiples of 4 from %zu to %zu (0 = %zu; %u is 0.1's)",
                          (unsigned)d->size, sizeof d->size, sizeof(vsgl_scene_desc), sizeof(vsgl_scene_desc),
                          (unsigned)VSGL_SCENE_DESC_SIZE_0_1);
    if ((r = need_array(ctx, d->positions, d->vertex_count, "positions", "vertex_count")) != VSGL_OK ||
        (r = need_array(ctx, d->indices, d->triangle_count, "indices", "triangle_count")) != VSGL_OK ||
        (r = need_array(ctx, d->materials, d->material_count, "materials", "material_count")) != VSGL_OK ||
        (r = need_array(ctx, d->lights, d->light_count, "lights", "light_count")) != VSGL_OK)
        return r;
    if (!d->camera)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "scene: camera is NULL (a camera is required)");
    if (d->triangle_count > 0 && d->material_count == 0)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "scene: material_count is 0 but triangle_count is %u (need >= 1 material)",
                          (unsigned)d->triangle_count);
    if (d->triangle_count > 0 && d->vertex_count == 0)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "scene: vertex_count is 0 but triangle_count is %u",
                          (unsigned)d->triangle_count);
    if ((r = vsgl__validate_camera(ctx, d->camera)) != VSGL_OK)
        return r;
    for (uint32_t i = 0; i < d->material_count; ++i)
        if ((r = vsgl__validate_material(ctx, i, &d->materials[i])) != VSGL_OK)
            return r;
    for (uint32_t i = 0; i < d->light_count; ++i)
        if ((r = vsgl__validate_light(ctx, i, &d->lights[i])) != VSGL_OK)
            return r;
    if ((r = validate_textures(ctx, d)) != VSGL_OK)
        return r;
    static const char axis[3] = {'x', 'y', 'z'};
    for (uint32_t i = 0; i < d->vertex_count; ++i)
        for (int k = 0; k < 3; ++k) {
            float v = d->positions[(size_t)i * 3 + k];
            if (!finite_f(v) || fabsf(v) > VSGL__MAX_COORD)
                return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "vertex %u: %c is %g (must be finite, |x| <= 1e18)",
                                  (unsigned)i, axis[k], (double)v);
        }
    for (uint32_t t = 0; t < d->triangle_count; ++t) {
        for (int c = 0; c < 3; ++c) {
            uint32_t vi = d->indices[(size_t)t * 3 + c];
            if (vi >= d->vertex_count)
                return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "triangle %u: vertex index %u out of range (vertex_count %u)",
                                  (unsigned)t, (unsigned)vi, (unsigned)d->vertex_count);
        }
        if (d->material_indices && d->material_indices[t] >= d->material_count)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "triangle %u: material index %u out of range (material_count %u)",
                              (unsigned)t, (unsigned)d->material_indices[t], (unsigned)d->material_count);
        if (d->corner_normals)
            for (int c = 0; c < 3; ++c) {
                const float *n = d->corner_normals + (size_t)t * 9 + c * 3;
                if (!finite_f(n[0]) || !finite_f(n[1]) || !finite_f(n[2]))
                    return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "triangle %u: corner %d normal (%g, %g, %g) is not finite",
                                      (unsigned)t, c, (double)n[0], (double)n[1], (double)n[2]);
                /* a zero-length normal (an object scaled to zero along an axis)
                 * makes the triangle degenerate: scene.c drops it with a warning */
            }
        if (d->corner_uvs)
            for (int k = 0; k < 6; ++k) {
                float u = d->corner_uvs[(size_t)t * 6 + k];
                if (!finite_f(u) || fabsf(u) > VSGL__MAX_COORD)
                    return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "triangle %u: corner %d uv %c is %g (must be finite)",
                                      (unsigned)t, k / 2, k % 2 ? 'v' : 'u', (double)u);
            }
        if (d->corner_tangents)
            for (int k = 0; k < 12; ++k) {
                float u = d->corner_tangents[(size_t)t * 12 + k];
                if (!finite_f(u) || fabsf(u) > VSGL__MAX_COORD)
                    return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "triangle %u: corner %d tangent component %d is %g (must be finite)",
                                      (unsigned)t, k / 4, k % 4, (double)u);
            }
    }
    return VSGL_OK;
}
