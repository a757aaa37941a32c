/* Test fixture: small analytic scenes built as vsgl_scene_desc arrays
 * (a box room with a glossy floor and coloured walls, lit by one light). */
#ifndef VSGL_TEST_SCENE_FIXTURE_H
#define VSGL_TEST_SCENE_FIXTURE_H

#include "vsgl.h"

#include <math.h>
#include <string.h>

#define FX_MAX_TRIS 64
#define FX_MAX_VERTS (FX_MAX_TRIS * 3)

typedef struct fx_scene {
    float positions[FX_MAX_VERTS * 3];
    uint32_t indices[FX_MAX_TRIS * 3];
    uint32_t material_indices[FX_MAX_TRIS];
    uint32_t vertex_count, triangle_count;
    vsgl_material materials[4];
    vsgl_light lights[4];
    uint32_t light_count;
    vsgl_camera camera;
    vsgl_scene_desc desc;
} fx_scene;

/* Quad p0,p1,p2,p3 (counter-clockwise seen from the side its normal faces). */
static inline void fx_quad(fx_scene *s, const float p[4][3], uint32_t material)
{
    uint32_t base = s->vertex_count;
    for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 3; ++c)
            s->positions[(base + (uint32_t)i) * 3 + (uint32_t)c] = p[i][c];
    s->vertex_count += 4;
    const uint32_t tri[6] = {0, 1, 2, 0, 2, 3};
    for (int t = 0; t < 2; ++t) {
        for (int k = 0; k < 3; ++k)
            s->indices[s->triangle_count * 3 + (uint32_t)k] = base + tri[t * 3 + k];
        s->material_indices[s->triangle_count] = material;
        ++s->triangle_count;
    }
}

/* Identity rotation, translation t: a 3x4 row-major matrix. */
static inline void fx_translation(float m[12], float x, float y, float z)
{
    memset(m, 0, 12 * sizeof(float));
    m[0] = m[5] = m[10] = 1.0f;
    m[3] = x; m[7] = y; m[11] = z;
}

/* Camera/light at `eye` looking at `at` (local -Z forward, +Y up, world +Z up). */
static inline void fx_look_at(float m[12], const float eye[3], const float at[3])
{
    float f[3] = {at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]};
    float fl = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int i = 0; i < 3; ++i) f[i] /= fl;
    float up[3] = {0, 0, 1};
    if (fabsf(f[2]) > 0.999f) { up[1] = 1; up[2] = 0; }
    float r[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0]};
    float rl = sqrtf(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int i = 0; i < 3; ++i) r[i] /= rl;
    float u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    for (int i = 0; i < 3; ++i) {
        m[i * 4 + 0] = r[i];
        m[i * 4 + 1] = u[i];
        m[i * 4 + 2] = -f[i];
        m[i * 4 + 3] = eye[i];
    }
}

/* A perspective camera (36 x 24 mm sensor, auto fit) at `eye` looking at
 * `at`, `lens_mm`, width x height pixels. */
static inline void fx_camera(fx_scene *s, const float eye[3], const float at[3], float lens_mm, uint32_t width,
                             uint32_t height)
{
    vsgl_camera *c = &s->camera;
    c->type = VSGL_CAMERA_PERSPECTIVE;
    c->sensor_fit = VSGL_SENSOR_FIT_AUTO;
    fx_look_at(c->world_from_camera, eye, at);
    c->lens_mm = lens_mm;
    c->sensor_width_mm = 36.0f;
    c->sensor_height_mm = 24.0f;
    c->ortho_scale = 1.0f;
    c->clip_start = 0.01f;
    c->clip_end = 100.0f;
    c->width = width;
    c->height = height;
    c->pixel_aspect_x = c->pixel_aspect_y = 1.0f;
}

/* The scene's only light: a white spot (radius 0) at eye aimed at `at`,
 * power W, cone `size` rad, blend. */
static inline void fx_spot(fx_scene *s, const float eye[3], const float at[3], float power, float size, float blend)
{
    vsgl_light *L = &s->lights[0];
    memset(L, 0, sizeof *L);
    L->type = VSGL_LIGHT_SPOT;
    L->color[0] = L->color[1] = L->color[2] = 1.0f;
    L->power = power;
    fx_look_at(L->world_from_light, eye, at);
    L->spot_size = size;
    L->spot_blend = blend;
    s->light_count = 1;
}

/* Room [-1,1] x [-1,1] x [0,2]: glossy grey floor (material 0), red left
 * wall x=-1 (1), green right wall x=+1 (2), white back wall y=+1 and
 * ceiling (3). A spot light at the ceiling aimed at the floor, power P. */
static inline void fx_room(fx_scene *s, uint32_t width, uint32_t height, float floor_roughness, float power)
{
    memset(s, 0, sizeof *s);
    const float floor_[4][3] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    const float left[4][3] = {{-1, -1, 0}, {-1, 1, 0}, {-1, 1, 2}, {-1, -1, 2}};
    const float right[4][3] = {{1, -1, 0}, {1, -1, 2}, {1, 1, 2}, {1, 1, 0}};
    const float back[4][3] = {{-1, 1, 0}, {1, 1, 0}, {1, 1, 2}, {-1, 1, 2}};
    const float ceil_[4][3] = {{-1, -1, 2}, {-1, 1, 2}, {1, 1, 2}, {1, -1, 2}};
    fx_quad(s, floor_, 0);
    fx_quad(s, left, 1);
    fx_quad(s, right, 2);
    fx_quad(s, back, 3);
    fx_quad(s, ceil_, 3);
    vsgl_material *m = s->materials;
    m[0].base_color[0] = m[0].base_color[1] = m[0].base_color[2] = 0.5f;
    m[0].roughness = floor_roughness;
    m[0].specular_f0 = 0.04f;
    m[1].base_color[0] = 0.8f; m[1].base_color[1] = 0.1f; m[1].base_color[2] = 0.1f;
    m[1].roughness = 1.0f;
    m[2].base_color[0] = 0.1f; m[2].base_color[1] = 0.8f; m[2].base_color[2] = 0.1f;
    m[2].roughness = 1.0f;
    m[3].base_color[0] = m[3].base_color[1] = m[3].base_color[2] = 0.8f;
    m[3].roughness = 1.0f;
    const float eye[3] = {-0.5f, -0.3f, 1.9f}, at[3] = {-0.9f, -0.2f, 0.0f};
    fx_spot(s, eye, at, power, 1.2f, 0.2f);
    const float ceye[3] = {0.0f, -3.5f, 1.0f}, cat[3] = {0.0f, 0.0f, 0.8f};
    fx_camera(s, ceye, cat, 35.0f, width, height);
}

/* A context with `threads` threads (0: all cores) and nothing else set;
 * NULL if it cannot be created. */
static inline vsgl_context *fx_context(uint32_t threads)
{
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.size = sizeof cd;
    cd.thread_count = threads;
    vsgl_context *ctx = NULL;
    return vsgl_context_create(&cd, &ctx) == VSGL_OK ? ctx : NULL;
}

/* Point the descriptor at the arrays (call after edits, before create). */
static inline const vsgl_scene_desc *fx_desc(fx_scene *s)
{
    vsgl_scene_desc *d = &s->desc;
    memset(d, 0, sizeof *d);
    d->size = sizeof *d;
    d->vertex_count = s->vertex_count;
    d->positions = s->positions;
    d->triangle_count = s->triangle_count;
    d->indices = s->indices;
    d->material_indices = s->material_indices;
    d->material_count = 4;
    d->materials = s->materials;
    d->light_count = s->light_count;
    d->lights = s->lights;
    d->camera = &s->camera;
    return d;
}

#endif
