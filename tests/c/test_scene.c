/* Scene input validation (every bad-input case checks code AND message),
 * copy semantics, degenerate triangles, ray queries against analytic
 * geometry, surface attributes and the camera model. */
#include "harness.h"
#include "vsgl.h"
#include "core/context.h"
#include "scene/scene_internal.h"
#include "scene/camera.h"

#include <stdlib.h>
#include <string.h>

/* ---- a small valid scene that each case mutates ------------------------ */

typedef struct fixture {
    float positions[8 * 3];
    uint32_t indices[4 * 3];
    float normals[4 * 9];
    float uvs[4 * 6];
    float tangents[4 * 12];
    uint32_t mat_idx[4];
    vsgl_material materials[2];
    vsgl_light lights[2];
    vsgl_camera camera;
    vsgl_scene_desc desc;
} fixture;

static void identity12(float m[12])
{
    memset(m, 0, 12 * sizeof(float));
    m[0] = m[5] = m[10] = 1.0f;
}

static void default_camera(vsgl_camera *c)
{
    memset(c, 0, sizeof *c);
    c->type = VSGL_CAMERA_PERSPECTIVE;
    c->sensor_fit = VSGL_SENSOR_FIT_AUTO;
    identity12(c->world_from_camera);
    c->lens_mm = 50.0f;
    c->sensor_width_mm = 36.0f;
    c->sensor_height_mm = 24.0f;
    c->ortho_scale = 6.0f;
    c->clip_start = 0.1f;
    c->clip_end = 100.0f;
    c->width = 64;
    c->height = 48;
    c->pixel_aspect_x = c->pixel_aspect_y = 1.0f;
}

/* Two quads (4 triangles) at z = -5 and z = -6; point + spot light. */
static void fixture_init(fixture *f)
{
    memset(f, 0, sizeof *f);
    static const float p[8 * 3] = {-1, -1, -5, 1, -1, -5, 1, 1, -5, -1, 1, -5,
                                   -2, -2, -6, 2, -2, -6, 2, 2, -6, -2, 2, -6};
    static const uint32_t ix[4 * 3] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
    memcpy(f->positions, p, sizeof p);
    memcpy(f->indices, ix, sizeof ix);
    for (int i = 0; i < 12; ++i) {
        f->normals[i * 3 + 2] = 1.0f;
        f->tangents[i * 4 + 0] = 1.0f;
        f->tangents[i * 4 + 3] = 1.0f;
    }
    for (int t = 0; t < 4; ++t)
        f->mat_idx[t] = (uint32_t)(t / 2);
    for (int m = 0; m < 2; ++m) {
        f->materials[m].base_color[0] = f->materials[m].base_color[1] = f->materials[m].base_color[2] = 0.8f;
        f->materials[m].roughness = 0.5f;
        f->materials[m].specular_f0 = 0.04f;
    }
    f->lights[0].type = VSGL_LIGHT_POINT;
    f->lights[0].color[0] = f->lights[0].color[1] = f->lights[0].color[2] = 1.0f;
    f->lights[0].power = 100.0f;
    identity12(f->lights[0].world_from_light);
    f->lights[0].world_from_light[11] = 2.0f;
    f->lights[1] = f->lights[0];
    f->lights[1].type = VSGL_LIGHT_SPOT;
    f->lights[1].spot_size = 1.0f;
    f->lights[1].spot_blend = 0.15f;
    default_camera(&f->camera);
    vsgl_scene_desc *d = &f->desc;
    d->size = sizeof *d;
    d->vertex_count = 8;
    d->positions = f->positions;
    d->triangle_count = 4;
    d->indices = f->indices;
    d->corner_normals = f->normals;
    d->corner_uvs = f->uvs;
    d->corner_tangents = f->tangents;
    d->material_indices = f->mat_idx;
    d->material_count = 2;
    d->materials = f->materials;
    d->light_count = 2;
    d->lights = f->lights;
    d->camera = &f->camera;
}

static vsgl_context *quiet_context(void)
{
    vsgl_context *ctx = NULL;
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.size = sizeof cd;
    cd.thread_count = 2;
    vsgl_context_create(&cd, &ctx);
    return ctx;
}

VT_TEST(scene_valid_fixture_builds)
{
    vsgl_context *ctx = quiet_context();
    fixture f;
    fixture_init(&f);
    vsgl_scene *s = NULL;
    vsgl_result r = vsgl_scene_create(ctx, &f.desc, &s);
    VT_CHECK(r == VSGL_OK && s, "result %d '%s'", r, vsgl_context_last_error(ctx));
    if (s) {
        vsgl_scene_info info = {.size = sizeof info};
        VT_CHECK(vsgl_scene_get_info(s, &info) == VSGL_OK, "info");
        VT_CHECK(info.triangle_count == 4 && info.dropped_triangles == 0 && info.light_count == 2 && info.material_count == 2,
                 "tris %u dropped %u lights %u mats %u", info.triangle_count, info.dropped_triangles, info.light_count,
                 info.material_count);
        VT_CHECK(info.bounds_min[0] == -2 && info.bounds_min[1] == -2 && info.bounds_min[2] == -6 &&
                     info.bounds_max[0] == 2 && info.bounds_max[1] == 2 && info.bounds_max[2] == -5,
                 "bounds (%g %g %g)-(%g %g %g)", info.bounds_min[0], info.bounds_min[1], info.bounds_min[2],
                 info.bounds_max[0], info.bounds_max[1], info.bounds_max[2]);
        VT_CHECK(vsgl_scene_get_info(s, NULL) == VSGL_ERROR_INVALID_ARGUMENT, "NULL info");
        VT_CHECK(vsgl_scene_get_info(NULL, &info) == VSGL_ERROR_INVALID_ARGUMENT, "NULL scene");
        uint32_t n = 0;
        VT_CHECK(vsgl__scene_lights(s, &n) && n == 2 && vsgl__scene_lights(s, NULL)[1].type == VSGL_LIGHT_SPOT, "lights %u", n);
        VT_CHECK(vsgl__scene_materials(s, &n) && n == 2, "materials %u", n);
        VT_CHECK(vsgl__scene_camera(s)->width == 64, "camera copy");
    }
    vsgl_scene_destroy(s);
    vsgl_scene_destroy(NULL);
    /* an empty scene (camera only) is valid and hits nothing */
    vsgl_scene_desc e;
    memset(&e, 0, sizeof e);
    e.camera = &f.camera;
    r = vsgl_scene_create(ctx, &e, &s);
    VT_CHECK(r == VSGL_OK, "empty scene: %d '%s'", r, vsgl_context_last_error(ctx));
    if (s) {
        vsgl_hit h;
        VT_CHECK(!vsgl__scene_intersect(s, v3_make(0, 0, 0), v3_make(0, 0, -1), 0, 1e30f, &h), "empty scene hit");
        VT_CHECK(!vsgl__scene_occluded(s, v3_make(0, 0, 0), v3_make(0, 0, -1), 0, 1e30f), "empty scene occluded");
    }
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* ---- bad inputs: one mutation per case, exact code and message ---------- */

typedef void (*mutate_fn)(fixture *f);
typedef struct bad_case {
    const char *name;
    mutate_fn mutate;
    const char *message; /* exact expected message */
} bad_case;

#define MUT(name, body) static void name(fixture *f) { body; }
MUT(m_positions_null, f->desc.positions = NULL)
MUT(m_indices_null, f->desc.indices = NULL)
MUT(m_materials_null, f->desc.materials = NULL)
MUT(m_lights_null, f->desc.lights = NULL)
MUT(m_camera_null, f->desc.camera = NULL)
MUT(m_size, f->desc.size = 7)
MUT(m_no_material, f->desc.material_count = 0; f->desc.materials = NULL)
MUT(m_no_vertices, f->desc.vertex_count = 0; f->desc.positions = NULL)
MUT(m_vertex_nan, f->positions[3 * 3 + 1] = NAN)
MUT(m_vertex_inf, f->positions[5 * 3 + 2] = -INFINITY)
MUT(m_vertex_huge, f->positions[0] = 2e18f)
MUT(m_index_range, f->indices[1 * 3 + 2] = 99)
MUT(m_material_index, f->mat_idx[3] = 2)
MUT(m_normal_nan, f->normals[0] = NAN)
MUT(m_uv_nan, f->uvs[1 * 6 + 3] = NAN)
MUT(m_tangent_inf, f->tangents[3 * 12 + 7] = INFINITY)
MUT(m_cam_type, f->camera.type = 2)
MUT(m_cam_fit, f->camera.sensor_fit = -1)
MUT(m_cam_lens, f->camera.lens_mm = -1.0f)
MUT(m_cam_lens_zero, f->camera.lens_mm = 0.0f)
MUT(m_cam_sensor, f->camera.sensor_width_mm = 0.0f)
MUT(m_cam_sensor_h, f->camera.sensor_height_mm = NAN)
MUT(m_cam_clip, f->camera.clip_start = 5.0f; f->camera.clip_end = 5.0f)
MUT(m_cam_clip_neg, f->camera.clip_start = -0.5f)
MUT(m_cam_clip_inf, f->camera.clip_end = INFINITY)
MUT(m_cam_width0, f->camera.width = 0)
MUT(m_cam_height_big, f->camera.height = 65536)
MUT(m_cam_aspect, f->camera.pixel_aspect_y = 0.0f)
MUT(m_cam_ortho, f->camera.type = VSGL_CAMERA_ORTHOGRAPHIC; f->camera.ortho_scale = -2.0f)
MUT(m_cam_singular, f->camera.world_from_camera[10] = 0.0f)
MUT(m_cam_matrix_nan, f->camera.world_from_camera[3] = NAN)
MUT(m_cam_shift, f->camera.shift_x = INFINITY)
MUT(m_light_type, f->lights[1].type = 9)
MUT(m_light_shape, f->lights[0].area_shape = 4)
MUT(m_spot_zero, f->lights[1].spot_size = 0.0f)
MUT(m_spot_big, f->lights[1].spot_size = 3.5f)
MUT(m_spot_blend, f->lights[1].spot_blend = 1.5f)
MUT(m_power_neg, f->lights[0].power = -1.0f)
MUT(m_color_nan, f->lights[1].color[2] = NAN)
MUT(m_light_singular, f->lights[0].world_from_light[0] = 0.0f; f->lights[0].world_from_light[5] = 0.0f)
MUT(m_light_radius, f->lights[0].radius = -0.1f)
MUT(m_area_size, f->lights[0].type = VSGL_LIGHT_AREA; f->lights[0].area_shape = VSGL_AREA_RECTANGLE;
    f->lights[0].size_x = 1.0f; f->lights[0].size_y = 0.0f; f->lights[0].spread = 3.14159f)
MUT(m_area_spread, f->lights[0].type = VSGL_LIGHT_AREA; f->lights[0].size_x = 1.0f; f->lights[0].spread = 0.0f)
MUT(m_sun_angle, f->lights[0].type = VSGL_LIGHT_SUN; f->lights[0].sun_angle = 4.0f)
MUT(m_light_flags, f->lights[1].flags = 6)
MUT(m_light_unused_nan, f->lights[0].size_x = NAN)
MUT(m_light_matrix_inf, f->lights[1].world_from_light[7] = INFINITY)
MUT(m_cam_matrix_huge, f->camera.world_from_camera[11] = 1e19f)
MUT(m_light_color_neg, f->lights[0].color[0] = -0.5f)
MUT(m_mat_rough, f->materials[1].roughness = 2.0f)
MUT(m_mat_color, f->materials[0].base_color[1] = -0.1f)
MUT(m_mat_metal_nan, f->materials[0].metallic = NAN)
MUT(m_mat_flags, f->materials[1].flags = 0x10)
MUT(m_mat_reserved, f->materials[0].reserved = 1)
MUT(m_mat_aniso, f->materials[0].anisotropy = 1.5f)

static const bad_case bad_cases[] = {
    {"positions NULL", m_positions_null, "scene: positions is NULL but vertex_count is 8"},
    {"indices NULL", m_indices_null, "scene: indices is NULL but triangle_count is 4"},
    {"materials NULL", m_materials_null, "scene: materials is NULL but material_count is 2"},
    {"lights NULL", m_lights_null, "scene: lights is NULL but light_count is 2"},
    {"camera NULL", m_camera_null, "scene: camera is NULL (a camera is required)"},
    {"desc size", m_size, "vsgl_scene_desc.size is 7: this library knows multiples of 4" /* prefix */},
    {"no material", m_no_material, "scene: material_count is 0 but triangle_count is 4 (need >= 1 material)"},
    {"no vertices", m_no_vertices, "scene: vertex_count is 0 but triangle_count is 4"},
    {"vertex NaN", m_vertex_nan, "vertex 3: y is nan (must be finite, |x| <= 1e18)"},
    {"vertex Inf", m_vertex_inf, "vertex 5: z is -inf (must be finite, |x| <= 1e18)"},
    {"vertex huge", m_vertex_huge, "vertex 0: x is 2e+18 (must be finite, |x| <= 1e18)"},
    {"index range", m_index_range, "triangle 1: vertex index 99 out of range (vertex_count 8)"},
    {"material index", m_material_index, "triangle 3: material index 2 out of range (material_count 2)"},
    {"normal NaN", m_normal_nan, "triangle 0: corner 0 normal (nan, 0, 1) is not finite"},
    {"uv NaN", m_uv_nan, "triangle 1: corner 1 uv v is nan (must be finite)"},
    {"tangent Inf", m_tangent_inf, "triangle 3: corner 1 tangent component 3 is inf (must be finite)"},
    {"camera type", m_cam_type, "camera: type is 2 (must be 0 perspective or 1 orthographic)"},
    {"camera fit", m_cam_fit, "camera: sensor_fit is -1 (must be 0 auto, 1 horizontal or 2 vertical)"},
    {"camera lens", m_cam_lens, "camera: lens_mm is -1"},
    {"camera lens 0", m_cam_lens_zero, "camera: lens_mm is 0"},
    {"camera sensor", m_cam_sensor, "camera: sensor_width_mm is 0 (must be > 0)"},
    {"camera sensor h", m_cam_sensor_h, "camera: sensor_height_mm is nan (must be > 0)"},
    {"camera clip", m_cam_clip, "camera: clip_end is 5 (must be finite and > clip_start 5)"},
    {"camera clip neg", m_cam_clip_neg, "camera: clip_start is -0.5 (must be >= 0)"},
    {"camera clip inf", m_cam_clip_inf, "camera: clip_end is inf (must be finite and > clip_start 0.1)"},
    {"camera width", m_cam_width0, "camera: width is 0 (must be in [1, 65535])"},
    {"camera height", m_cam_height_big, "camera: height is 65536 (must be in [1, 65535])"},
    {"camera aspect", m_cam_aspect, "camera: pixel_aspect_y is 0 (must be > 0)"},
    {"camera ortho", m_cam_ortho, "camera: ortho_scale is -2 (must be > 0)"},
    {"camera singular", m_cam_singular, "camera: world_from_camera is singular"},
    {"camera matrix NaN", m_cam_matrix_nan, "camera: world_from_camera is not finite"},
    {"camera shift", m_cam_shift, "camera: shift_x is inf (must be finite, |x| <= 1e18)"},
    {"light type", m_light_type, "light 1: type is 9 (must be 0 point, 1 spot, 2 sun or 3 area)"},
    {"light shape", m_light_shape, "light 0: area_shape is 4 (must be 0 square, 1 rectangle, 2 disk or 3 ellipse)"},
    {"spot size 0", m_spot_zero, "light 1: spot size is 0"},
    {"spot size big", m_spot_big, "light 1: spot size is 3.5"},
    {"spot blend", m_spot_blend, "light 1: spot_blend is 1.5 (must be in [0, 1])"},
    {"power", m_power_neg, "light 0: power is -1 (must be in [0, 1e+18])"},
    {"color NaN", m_color_nan, "light 1: color[2] is nan (must be in [0, 3e+38])"},
    {"light singular", m_light_singular, "light 0: world_from_light is singular"},
    {"light radius", m_light_radius, "light 0: radius is -0.1 (must be in [0, 1e+18])"},
    {"area size", m_area_size, "light 0: size_y is 0 (must be > 0)"},
    {"area spread", m_area_spread, "light 0: spread is 0 (must be in (0, pi])"},
    {"sun angle", m_sun_angle, "light 0: sun_angle is 4 (must be in [0, 3.14159])"},
    {"light unknown flags", m_light_flags, "light 1: flags 0x6 has unknown bits (known: 0x1)"},
    {"light unused NaN", m_light_unused_nan, "light 0: size_x is nan (must be finite, |x| <= 1e18)"},
    {"light matrix Inf", m_light_matrix_inf, "light 1: world_from_light is not finite"},
    {"camera matrix huge", m_cam_matrix_huge, "camera: world_from_camera has an element above 1e18"},
    {"light colour negative", m_light_color_neg, "light 0: color[0] is -0.5 (must be in [0, 3e+38])"},
    {"material roughness", m_mat_rough, "material 1: roughness is 2 (must be in [0, 1])"},
    {"material colour", m_mat_color, "material 0: base_color[1] is -0.1 (must be in [0, 1])"},
    {"material metallic", m_mat_metal_nan, "material 0: metallic is nan (must be in [0, 1])"},
    {"material flags", m_mat_flags, "material 1: flags 0x10 has unknown bits"},
    {"material reserved", m_mat_reserved, "material 0: reserved is 1 (must be 0)"},
    {"material anisotropy", m_mat_aniso, "material 0: anisotropy is 1.5 (must be in [0, 1])"},
};

VT_TEST(scene_rejects_every_bad_input_with_a_named_message)
{
    vsgl_context *ctx = quiet_context();
    for (size_t i = 0; i < sizeof bad_cases / sizeof bad_cases[0]; ++i) {
        fixture f;
        fixture_init(&f);
        bad_cases[i].mutate(&f);
        vsgl_scene *s = (vsgl_scene *)&f; /* must be overwritten with NULL */
        vsgl_result r = vsgl_scene_create(ctx, &f.desc, &s);
        const char *msg = vsgl_context_last_error(ctx);
        VT_CHECK(r == VSGL_ERROR_INVALID_ARGUMENT, "case '%s': result %d ('%s')", bad_cases[i].name, r, msg);
        VT_CHECK(s == NULL, "case '%s': out not cleared", bad_cases[i].name);
        VT_CHECK(strncmp(msg, bad_cases[i].message, strlen(bad_cases[i].message)) == 0,
                 "case '%s': message '%s', want '%s'", bad_cases[i].name, msg, bad_cases[i].message);
        if (r == VSGL_OK)
            vsgl_scene_destroy(s);
    }
    /* NULL desc / out */
    vsgl_scene *s = NULL;
    VT_CHECK(vsgl_scene_create(ctx, NULL, &s) == VSGL_ERROR_INVALID_ARGUMENT &&
                 strcmp(vsgl_context_last_error(ctx), "scene: desc is NULL") == 0, "'%s'", vsgl_context_last_error(ctx));
    fixture f;
    fixture_init(&f);
    VT_CHECK(vsgl_scene_create(ctx, &f.desc, NULL) == VSGL_ERROR_INVALID_ARGUMENT &&
                 strcmp(vsgl_context_last_error(ctx), "scene: out is NULL") == 0, "'%s'", vsgl_context_last_error(ctx));
    /* a NULL context still gets the code */
    VT_CHECK(vsgl_scene_create(NULL, NULL, &s) == VSGL_ERROR_INVALID_ARGUMENT, "NULL ctx");
    /* a success clears the previous error */
    VT_CHECK(vsgl_scene_create(ctx, &f.desc, &s) == VSGL_OK && strcmp(vsgl_context_last_error(ctx), "") == 0,
             "'%s'", vsgl_context_last_error(ctx));
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* Values of unused fields of other light types do not matter if finite,
 * and every valid enum/edge value is accepted. */
VT_TEST(scene_accepts_edge_values)
{
    vsgl_context *ctx = quiet_context();
    fixture f;
    fixture_init(&f);
    f.lights[1].spot_size = 3.14159265f; /* pi (rounded down in float) */
    f.lights[1].spot_blend = 1.0f;
    f.lights[0].type = VSGL_LIGHT_AREA;
    f.lights[0].area_shape = VSGL_AREA_DISK;
    f.lights[0].size_x = 0.5f;
    f.lights[0].size_y = 0.0f; /* ignored for disks */
    f.lights[0].spread = 3.14159265f;
    f.lights[0].power = 0.0f;
    f.materials[0].roughness = 0.0f;
    f.materials[1].roughness = 1.0f;
    f.materials[1].flags = VSGL_MATERIAL_UNSUPPORTED;
    f.camera.sensor_fit = VSGL_SENSOR_FIT_VERTICAL;
    f.camera.width = 65535;
    f.camera.height = 1;
    f.camera.clip_start = 0.0f;
    f.desc.corner_normals = NULL;
    f.desc.corner_uvs = NULL;
    f.desc.corner_tangents = NULL;
    f.desc.material_indices = NULL;
    vsgl_scene *s = NULL;
    vsgl_result r = vsgl_scene_create(ctx, &f.desc, &s);
    VT_CHECK(r == VSGL_OK, "result %d '%s'", r, vsgl_context_last_error(ctx));
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* ---- degenerate triangles ------------------------------------------------ */

typedef struct log_capture { int warnings; char first[256]; } log_capture;
static void capture_log(void *user, int32_t level, const char *message)
{
    log_capture *c = user;
    if (level == VSGL_LOG_WARNING) {
        if (c->warnings++ == 0)
            snprintf(c->first, sizeof c->first, "%s", message);
    }
}

VT_TEST(scene_drops_degenerate_triangles_with_a_warning)
{
    log_capture cap;
    memset(&cap, 0, sizeof cap);
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.thread_count = 1;
    cd.log = capture_log;
    cd.log_user = &cap;
    vsgl_context *ctx = NULL;
    vsgl_context_create(&cd, &ctx);
    fixture f;
    fixture_init(&f);
    f.indices[1 * 3 + 2] = 0;              /* triangle 1: (0, 2, 0) repeated vertex */
    f.positions[6 * 3 + 0] = 0.0f;         /* triangle 2: (4, 5, 6) with 6 on the line 4-5 */
    f.positions[6 * 3 + 1] = -2.0f;
    vsgl_scene *s = NULL;
    vsgl_result r = vsgl_scene_create(ctx, &f.desc, &s);
    VT_CHECK(r == VSGL_OK, "result %d '%s'", r, vsgl_context_last_error(ctx));
    if (s) {
        vsgl_scene_info info = {.size = sizeof info};
        vsgl_scene_get_info(s, &info);
        VT_CHECK(info.triangle_count == 2 && info.dropped_triangles == 2, "kept %u dropped %u", info.triangle_count,
                 info.dropped_triangles);
        VT_CHECK(cap.warnings == 2, "warnings %d", cap.warnings);
        VT_CHECK(strcmp(cap.first, "triangle 1: zero area (vertices 0, 2, 0), dropped") == 0, "first warning '%s'", cap.first);
        /* compacted triangle 1 is the caller's triangle 3, material 1 */
        VT_CHECK(vsgl__scene_source_triangle(s, 0) == 0 && vsgl__scene_source_triangle(s, 1) == 3, "source %u %u",
                 vsgl__scene_source_triangle(s, 0), vsgl__scene_source_triangle(s, 1));
        vsgl_hit h;
        /* inside what is left of the far quad: triangle 3 (4, 6, 7) = (-2,-2), (0,-2), (-2,2) */
        int hit = vsgl__scene_intersect(s, v3_make(-1.8f, 1.0f, 0.0f), v3_make(0, 0, -1), 0.0f, 100.0f, &h);
        VT_CHECK(hit && h.triangle == 1 && fabsf(h.t - 6.0f) < 1e-5f, "hit %d tri %u t %g", hit, h.triangle, h.t);
        if (hit) {
            vsgl_surface sf;
            vsgl__scene_surface(s, &h, v3_make(0, 0, -1), &sf);
            VT_CHECK(sf.material == 1, "material %u", sf.material);
        }
    }
    vsgl_scene_destroy(s);
    /* every triangle degenerate: a valid scene that hits nothing */
    for (int i = 0; i < 8 * 3; ++i)
        f.positions[i] = 1.0f;
    s = NULL;
    r = vsgl_scene_create(ctx, &f.desc, &s);
    VT_CHECK(r == VSGL_OK, "all degenerate: %d '%s'", r, vsgl_context_last_error(ctx));
    if (s) {
        vsgl_scene_info info = {.size = sizeof info};
        vsgl_scene_get_info(s, &info);
        VT_CHECK(info.triangle_count == 0 && info.dropped_triangles == 4 && info.bounds_min[0] == 0 && info.bounds_max[2] == 0,
                 "kept %u dropped %u", info.triangle_count, info.dropped_triangles);
        vsgl_hit h;
        VT_CHECK(!vsgl__scene_intersect(s, v3_make(0, 0, 5), v3_make(0, 0, -1), 0.0f, 100.0f, &h), "hit in an empty scene");
    }
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* Issue 10: an object scaled (1, 1, 0) or (0, 0, 0) gives zero-length
 * corner normals; such a triangle is dropped with a warning like a
 * zero-area one (it used to refuse the whole frame). */
VT_TEST(scene_drops_triangles_with_zero_normals)
{
    log_capture cap;
    memset(&cap, 0, sizeof cap);
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.thread_count = 1;
    cd.log = capture_log;
    cd.log_user = &cap;
    vsgl_context *ctx = NULL;
    vsgl_context_create(&cd, &ctx);
    fixture f;
    fixture_init(&f);
    for (int k = 0; k < 3; ++k)
        f.normals[2 * 9 + 3 + k] = 0.0f;  /* triangle 2, corner 1: (0, 0, 0) */
    vsgl_scene *s = NULL;
    vsgl_result r = vsgl_scene_create(ctx, &f.desc, &s);
    VT_CHECK(r == VSGL_OK, "result %d '%s'", r, vsgl_context_last_error(ctx));
    if (s) {
        vsgl_scene_info info = {.size = sizeof info};
        vsgl_scene_get_info(s, &info);
        VT_CHECK(info.triangle_count == 3 && info.dropped_triangles == 1, "kept %u dropped %u", info.triangle_count,
                 info.dropped_triangles);
        VT_CHECK(cap.warnings == 1, "warnings %d", cap.warnings);
        VT_CHECK(strcmp(cap.first, "triangle 2: corner 1 normal (0, 0, 0) has zero length, dropped") == 0,
                 "first warning '%s'", cap.first);
        VT_CHECK(vsgl__scene_source_triangle(s, 2) == 3, "source %u", vsgl__scene_source_triangle(s, 2));
    }
    vsgl_scene_destroy(s);
    /* every normal zero (scale 0, 0, 0 collapses the normal matrix): valid, empty */
    memset(f.normals, 0, sizeof f.normals);
    s = NULL;
    r = vsgl_scene_create(ctx, &f.desc, &s);
    VT_CHECK(r == VSGL_OK, "all zero: %d '%s'", r, vsgl_context_last_error(ctx));
    if (s) {
        vsgl_scene_info info = {.size = sizeof info};
        vsgl_scene_get_info(s, &info);
        VT_CHECK(info.triangle_count == 0 && info.dropped_triangles == 4, "kept %u dropped %u", info.triangle_count,
                 info.dropped_triangles);
    }
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* The scene keeps no pointer to caller memory (ASan would report a use after free). */
VT_TEST(scene_copies_caller_data)
{
    vsgl_context *ctx = quiet_context();
    fixture *f = malloc(sizeof *f);
    fixture_init(f);
    vsgl_scene *s = NULL;
    VT_CHECK(vsgl_scene_create(ctx, &f->desc, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    memset(f, 0xFF, sizeof *f); /* NaN everywhere */
    free(f);
    if (s) {
        vsgl_hit h;
        VT_CHECK(vsgl__scene_intersect(s, v3_make(0.5f, 0.5f, 0.0f), v3_make(0, 0, -1), 0.0f, 100.0f, &h) &&
                     fabsf(h.t - 5.0f) < 1e-5f, "t %g", h.t);
        vsgl_surface sf;
        vsgl__scene_surface(s, &h, v3_make(0, 0, -1), &sf);
        VT_CHECK(sf.normal.z == 1.0f && sf.material == 0, "n.z %g mat %u", sf.normal.z, sf.material);
        VT_CHECK(vsgl__scene_camera(s)->lens_mm == 50.0f && vsgl__scene_lights(s, NULL)[0].power == 100.0f, "copies");
    }
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* ---- ray queries against an analytic box --------------------------------- */

static void box_mesh(float lo[3], float hi[3], float *pos, uint32_t *ix)
{
    for (int i = 0; i < 8; ++i) {
        pos[i * 3 + 0] = (i & 1) ? hi[0] : lo[0];
        pos[i * 3 + 1] = (i & 2) ? hi[1] : lo[1];
        pos[i * 3 + 2] = (i & 4) ? hi[2] : lo[2];
    }
    /* faces as quads (outward winding) */
    static const uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int fi = 0; fi < 6; ++fi) {
        uint32_t *t = ix + fi * 6;
        t[0] = q[fi][0]; t[1] = q[fi][1]; t[2] = q[fi][2];
        t[3] = q[fi][0]; t[4] = q[fi][2]; t[5] = q[fi][3];
    }
}

/* Slab test in double: entry distance and axis of the entry face, or -1. */
static double slab(const double o[3], const double d[3], const float lo[3], const float hi[3], int *axis, double *tout)
{
    double t0 = -1e300, t1 = 1e300;
    int ax = -1;
    for (int k = 0; k < 3; ++k) {
        double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
        if (a > b) { double tmp = a; a = b; b = tmp; }
        if (a > t0) { t0 = a; ax = k; }
        if (b < t1) t1 = b;
    }
    *axis = ax;
    *tout = t1;
    return (t0 <= t1 && t0 > 0) ? t0 : -1.0;
}

VT_TEST(scene_ray_queries_match_an_analytic_box)
{
    vsgl_context *ctx = quiet_context();
    float lo[3] = {-1.0f, -2.0f, 0.5f}, hi[3] = {1.5f, 0.5f, 2.0f};
    float pos[24];
    uint32_t ix[36];
    box_mesh(lo, hi, pos, ix);
    vsgl_material mat;
    memset(&mat, 0, sizeof mat);
    vsgl_camera cam;
    default_camera(&cam);
    vsgl_scene_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 8; d.positions = pos; d.triangle_count = 12; d.indices = ix;
    d.material_count = 1; d.materials = &mat; d.camera = &cam;
    vsgl_scene *s = NULL;
    VT_CHECK(vsgl_scene_create(ctx, &d, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    if (!s) { vsgl_context_destroy(ctx); return; }
    vt_rng rng = {7};
    int n = getenv("VSGL_TEST_QUICK") ? 2000 : 20000, hits = 0, checked = 0;
    v3 *orgs = malloc((size_t)n * sizeof *orgs), *dirs = malloc((size_t)n * sizeof *dirs);
    float *t0s = malloc((size_t)n * sizeof(float)), *t1s = malloc((size_t)n * sizeof(float));
    vsgl_hit *many = malloc((size_t)n * sizeof *many);
    for (int i = 0; i < n; ++i) {
        /* origin on a sphere of radius 6, direction towards a random point near the box */
        double z = 2 * vt_uniform(&rng) - 1, ph = 6.283185307179586 * vt_uniform(&rng), r = sqrt(1 - z * z);
        double o[3] = {6 * r * cos(ph), 6 * r * sin(ph), 6 * z};
        double tgt[3] = {-1.5 + 3.5 * vt_uniform(&rng), -2.5 + 3.5 * vt_uniform(&rng), 0.0 + 2.5 * vt_uniform(&rng)};
        double dd[3] = {tgt[0] - o[0], tgt[1] - o[1], tgt[2] - o[2]};
        double l = sqrt(dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2]);
        for (int k = 0; k < 3; ++k) dd[k] /= l;
        v3 org = v3_make((float)o[0], (float)o[1], (float)o[2]);
        v3 dir = v3_make((float)dd[0], (float)dd[1], (float)dd[2]);
        /* reference with the float-rounded ray */
        double of[3] = {org.x, org.y, org.z}, df[3] = {dir.x, dir.y, dir.z};
        int axis;
        double texit;
        double tref = slab(of, df, lo, hi, &axis, &texit);
        orgs[i] = org; dirs[i] = dir; t0s[i] = 0.0f; t1s[i] = 100.0f;
        vsgl_hit h;
        int got = vsgl__scene_intersect(s, org, dir, 0.0f, 100.0f, &h);
        int occ = vsgl__scene_occluded(s, org, dir, 0.0f, 100.0f);
        VT_CHECK(got == occ, "ray %d: intersect %d occluded %d", i, got, occ);
        /* skip rays grazing an edge (ambiguous within float precision) */
        if (tref > 0 && texit - tref < 1e-3)
            continue;
        ++checked;
        VT_CHECK(got == (tref > 0), "ray %d org (%g %g %g) dir (%g %g %g): hit %d want %d", i, org.x, org.y, org.z,
                 dir.x, dir.y, dir.z, got, tref > 0);
        if (got && tref > 0) {
            ++hits;
            VT_CHECK_ABS(h.t, tref, 1e-5 * (1 + tref), "ray %d", i);
            vsgl_surface sf;
            vsgl__scene_surface(s, &h, dir, &sf);
            float nn[3] = {sf.geometric_normal.x, sf.geometric_normal.y, sf.geometric_normal.z};
            float sgn = (float)(df[axis] > 0 ? -1 : 1);
            VT_CHECK(fabsf(nn[axis] - sgn) < 1e-6f && v3_dot(sf.normal, dir) < 0, "ray %d: normal (%g %g %g) axis %d",
                     i, nn[0], nn[1], nn[2], axis);
            VT_CHECK_ABS(v3_length(v3_sub(sf.position, v3_add(org, v3_scale(dir, h.t)))), 0, 1e-5, "ray %d position", i);
            /* occlusion respects the segment */
            VT_CHECK(!vsgl__scene_occluded(s, org, dir, 0.0f, (float)tref * 0.999f), "ray %d: blocked before the box", i);
            VT_CHECK(!vsgl__scene_intersect(s, org, dir, (float)texit + 1e-3f, 100.0f, &h), "ray %d: hit past the box", i);
        }
    }
    VT_CHECK(hits > n / 4 && checked > n * 9 / 10, "hits %d checked %d of %d", hits, checked, n);
    /* the stream variant agrees bit for bit with single rays */
    vsgl__scene_intersect_many(s, (uint32_t)n, orgs, dirs, t0s, t1s, 0, many);
    int diff = 0;
    for (int i = 0; i < n; ++i) {
        vsgl_hit h;
        int got = vsgl__scene_intersect(s, orgs[i], dirs[i], 0.0f, 100.0f, &h);
        if (got != (many[i].triangle != VSGL__HIT_NONE) || (got && (h.t != many[i].t || h.triangle != many[i].triangle)))
            ++diff;
    }
    VT_CHECK(diff == 0, "%d of %d stream results differ from rtcIntersect1", diff, n);
    /* the occlusion stream agrees with single occlusion rays, on half-length segments too */
    unsigned char *blk = malloc((size_t)n);
    for (int i = 0; i < n; ++i)
        t1s[i] = (i & 1) ? 100.0f : 5.0f;
    vsgl__scene_occluded_many(s, (uint32_t)n, orgs, dirs, t0s, t1s, 0, blk);
    diff = 0;
    int blocked = 0;
    for (int i = 0; i < n; ++i) {
        int want = vsgl__scene_occluded(s, orgs[i], dirs[i], t0s[i], t1s[i]);
        diff += want != blk[i];
        blocked += blk[i];
    }
    VT_CHECK(diff == 0 && blocked > n / 8, "%d of %d stream occlusion results differ (%d blocked)", diff, n, blocked);
    t0s[0] = 5.0f; t1s[0] = 1.0f;
    vsgl__scene_occluded_many(s, 1, orgs, dirs, t0s, t1s, 0, blk);
    VT_CHECK(blk[0] == 0, "tmin > tmax blocked");
    free(blk);
    for (int i = 0; i < n; ++i)
        t1s[i] = 100.0f;
    /* empty intervals never hit */
    t0s[0] = 5.0f; t1s[0] = 1.0f;
    vsgl__scene_intersect_many(s, 1, orgs, dirs, t0s, t1s, 0, many);
    VT_CHECK(many[0].triangle == VSGL__HIT_NONE, "tmin > tmax hit");
    free(orgs); free(dirs); free(t0s); free(t1s); free(many);
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* ---- surface attributes --------------------------------------------------- */

VT_TEST(scene_surface_interpolates_normals_and_tangents)
{
    vsgl_context *ctx = quiet_context();
    /* one triangle in the z = 0 plane, corner normals tilted differently */
    float pos[9] = {0, 0, 0, 2, 0, 0, 0, 2, 0};
    uint32_t ix[3] = {0, 1, 2};
    float cn[9] = {0, 0, 1, 1, 0, 1, 0, -1, 2};
    float uv[6] = {0, 0, 0, 1, -1, 0}; /* u grows along -y, v along +x */
    vsgl_material mats[2];
    memset(mats, 0, sizeof mats);
    mats[1].anisotropic_rotation = 0.25f;
    uint32_t mi[1] = {0};
    vsgl_camera cam;
    default_camera(&cam);
    vsgl_scene_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = 3; d.positions = pos; d.triangle_count = 1; d.indices = ix; d.corner_normals = cn;
    d.corner_uvs = uv; d.material_indices = mi; d.material_count = 2; d.materials = mats; d.camera = &cam;
    vsgl_scene *s = NULL;
    VT_CHECK(vsgl_scene_create(ctx, &d, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    if (!s) { vsgl_context_destroy(ctx); return; }
    vt_rng rng = {3};
    for (int i = 0; i < 200; ++i) {
        double a = vt_uniform(&rng), b = vt_uniform(&rng);
        if (a + b > 0.98) { a *= 0.49; b *= 0.49; }
        double px = 2 * a + 0.0, py = 2 * b;   /* p = w p0 + a p1 + b p2 */
        int below = i & 1;
        v3 org = v3_make((float)px, (float)py, below ? -3.0f : 3.0f);
        v3 dir = v3_make(0, 0, below ? 1.0f : -1.0f);
        vsgl_hit h;
        if (!vsgl__scene_intersect(s, org, dir, 0.0f, 10.0f, &h)) {
            VT_CHECK(0, "miss at %g %g", px, py);
            continue;
        }
        vsgl_surface sf;
        vsgl__scene_surface(s, &h, dir, &sf);
        /* reference: normalised barycentric blend of the unit corner normals */
        double w = 1 - a - b, n0[3] = {0, 0, 1}, n1[3] = {0.70710678118654752440, 0, 0.70710678118654752440};
        double n2[3] = {0, -1 / sqrt(5.0), 2 / sqrt(5.0)}, n[3], l = 0;
        for (int k = 0; k < 3; ++k) { n[k] = w * n0[k] + a * n1[k] + b * n2[k]; l += n[k] * n[k]; }
        l = sqrt(l) * (below ? -1 : 1);
        VT_CHECK(fabs(sf.normal.x - n[0] / l) < 2e-3 && fabs(sf.normal.y - n[1] / l) < 2e-3 && fabs(sf.normal.z - n[2] / l) < 2e-3,
                 "bary (%g %g) below %d: normal (%g %g %g) want (%g %g %g)", a, b, below, sf.normal.x, sf.normal.y,
                 sf.normal.z, n[0] / l, n[1] / l, n[2] / l);
        VT_CHECK(sf.geometric_normal.z == (below ? -1.0f : 1.0f), "geometric normal z %g", sf.geometric_normal.z);
        /* tangent = dP/du = -y direction, orthogonalised against n */
        v3 want = v3_normalize(v3_sub(v3_make(0, -1, 0), v3_scale(sf.normal, -sf.normal.y)));
        VT_CHECK(v3_dot(sf.tangent, want) > 1 - 1e-5f && fabsf(v3_dot(sf.tangent, sf.normal)) < 1e-5f,
                 "tangent (%g %g %g) want (%g %g %g)", sf.tangent.x, sf.tangent.y, sf.tangent.z, want.x, want.y, want.z);
    }
    vsgl_scene_destroy(s);
    /* anisotropic rotation of a quarter turn: t -> n x t */
    mi[0] = 1;
    d.corner_normals = NULL;
    VT_CHECK(vsgl_scene_create(ctx, &d, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    if (s) {
        vsgl_hit h;
        vsgl_surface sf;
        vsgl__scene_intersect(s, v3_make(0.5f, 0.5f, 1.0f), v3_make(0, 0, -1), 0.0f, 10.0f, &h);
        vsgl__scene_surface(s, &h, v3_make(0, 0, -1), &sf);
        /* unrotated (0,-1,0); n = +z; z x (0,-1,0) = (1, 0, 0) */
        VT_CHECK(fabsf(sf.tangent.x - 1.0f) < 1e-5f && fabsf(sf.tangent.y) < 1e-5f && sf.material == 1,
                 "rotated tangent (%g %g %g)", sf.tangent.x, sf.tangent.y, sf.tangent.z);
        VT_CHECK(sf.normal.z == 1.0f, "face normal used without corner normals: %g", sf.normal.z);
        vsgl_scene_destroy(s);
    }
    /* no UVs: a deterministic unit tangent orthogonal to n */
    d.corner_uvs = NULL;
    VT_CHECK(vsgl_scene_create(ctx, &d, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    if (s) {
        vsgl_hit h;
        vsgl_surface sf;
        vsgl__scene_intersect(s, v3_make(0.5f, 0.5f, 1.0f), v3_make(0, 0, -1), 0.0f, 10.0f, &h);
        vsgl__scene_surface(s, &h, v3_make(0, 0, -1), &sf);
        VT_CHECK(fabsf(v3_length(sf.tangent) - 1) < 1e-6f && fabsf(v3_dot(sf.tangent, sf.normal)) < 1e-6f,
                 "tangent (%g %g %g)", sf.tangent.x, sf.tangent.y, sf.tangent.z);
        vsgl_scene_destroy(s);
    }
    vsgl_context_destroy(ctx);
}

/* ---- camera model -------------------------------------------------------- */

/* Reference: Blender's BKE_camera_params_compute_viewplane formulation
 * (pixsize / viewfac at the clip_start plane), a different derivation from
 * the Cycles-style one in camera.c. Returns the camera-space direction
 * (x, y, -1) (perspective) or the plane offset (x, y) (ortho) of raster (px, py),
 * py measured from the top. */
static void blender_reference(const vsgl_camera *c, double px, double py, double *x, double *y)
{
    double aspx = c->pixel_aspect_x, aspy = c->pixel_aspect_y, winx = c->width, winy = c->height;
    double ycor = aspy / aspx;
    double sensor = c->sensor_fit == VSGL_SENSOR_FIT_VERTICAL ? c->sensor_height_mm : c->sensor_width_mm;
    double pixsize = c->type == VSGL_CAMERA_ORTHOGRAPHIC ? c->ortho_scale : sensor * c->clip_start / c->lens_mm;
    int fit = c->sensor_fit;
    if (fit == VSGL_SENSOR_FIT_AUTO)
        fit = (aspx * winx >= aspy * winy) ? VSGL_SENSOR_FIT_HORIZONTAL : VSGL_SENSOR_FIT_VERTICAL;
    double viewfac = fit == VSGL_SENSOR_FIT_HORIZONTAL ? winx : ycor * winy;
    pixsize /= viewfac;
    double xmin = -0.5 * winx, ymin = -0.5 * ycor * winy, xmax = 0.5 * winx, ymax = 0.5 * ycor * winy;
    double dx = c->shift_x * viewfac, dy = c->shift_y * viewfac;
    xmin = (xmin + dx) * pixsize; xmax = (xmax + dx) * pixsize;
    ymin = (ymin + dy) * pixsize; ymax = (ymax + dy) * pixsize;
    double fx = px / winx, fy = 1.0 - py / winy;
    *x = xmin + fx * (xmax - xmin);
    *y = ymin + fy * (ymax - ymin);
    if (c->type == VSGL_CAMERA_PERSPECTIVE) {
        *x /= c->clip_start;
        *y /= c->clip_start;
    }
}

VT_TEST(camera_matches_blender_viewplane)
{
    vt_rng rng = {11};
    int cases = 0;
    for (int type = 0; type < 2; ++type)
        for (int fit = 0; fit < 3; ++fit)
            for (int variant = 0; variant < 6; ++variant) {
                vsgl_camera c;
                default_camera(&c);
                c.type = type;
                c.sensor_fit = fit;
                c.width = 16 + (uint32_t)(vt_uniform(&rng) * 300);
                c.height = 16 + (uint32_t)(vt_uniform(&rng) * 300);
                c.lens_mm = (float)(10 + 90 * vt_uniform(&rng));
                c.sensor_width_mm = (float)(10 + 40 * vt_uniform(&rng));
                c.sensor_height_mm = (float)(10 + 40 * vt_uniform(&rng));
                c.ortho_scale = (float)(1 + 9 * vt_uniform(&rng));
                c.clip_start = (float)(0.01 + vt_uniform(&rng));
                if (variant >= 2) {
                    c.shift_x = (float)(vt_uniform(&rng) - 0.5);
                    c.shift_y = (float)(vt_uniform(&rng) - 0.5);
                }
                if (variant >= 4) {
                    c.pixel_aspect_x = (float)(0.5 + 2 * vt_uniform(&rng));
                    c.pixel_aspect_y = (float)(0.5 + 2 * vt_uniform(&rng));
                }
                if (variant & 1) { /* rotated, translated and scaled camera object */
                    double a = vt_uniform(&rng) * 6.28, sc = 0.5 + 2 * vt_uniform(&rng);
                    float m[12] = {(float)(cos(a) * sc), 0, (float)(sin(a) * sc), 1.5f,
                                   0, (float)sc, 0, -2.0f,
                                   (float)(-sin(a) * sc), 0, (float)(cos(a) * sc), 0.25f};
                    memcpy(c.world_from_camera, m, sizeof m);
                }
                vsgl_camera_model cm;
                vsgl__camera_model(&c, &cm);
                v3 ex = v3_normalize(v3_make(c.world_from_camera[0], c.world_from_camera[4], c.world_from_camera[8]));
                v3 ey = v3_normalize(v3_make(c.world_from_camera[1], c.world_from_camera[5], c.world_from_camera[9]));
                v3 ez = v3_normalize(v3_make(c.world_from_camera[2], c.world_from_camera[6], c.world_from_camera[10]));
                v3 eo = v3_make(c.world_from_camera[3], c.world_from_camera[7], c.world_from_camera[11]);
                for (int k = 0; k < 20; ++k) {
                    double px = vt_uniform(&rng) * c.width, py = vt_uniform(&rng) * c.height;
                    if (k == 0) { px = 0; py = 0; }
                    if (k == 1) { px = c.width; py = c.height; }
                    double x, y;
                    blender_reference(&c, px, py, &x, &y);
                    v3 org, dir;
                    float t0, t1;
                    vsgl__camera_ray(&cm, (float)px, (float)py, &org, &dir, &t0, &t1);
                    if (type == VSGL_CAMERA_PERSPECTIVE) {
                        v3 want = v3_normalize(v3_add(v3_add(v3_scale(ex, (float)x), v3_scale(ey, (float)y)), v3_neg(ez)));
                        VT_CHECK(v3_length(v3_sub(dir, want)) < 2e-6f && v3_length(v3_sub(org, eo)) == 0,
                                 "persp fit %d %ux%u aspect %g:%g shift %g %g raster (%g %g): dir (%g %g %g) want (%g %g %g)",
                                 fit, c.width, c.height, c.pixel_aspect_x, c.pixel_aspect_y, c.shift_x, c.shift_y, px, py,
                                 dir.x, dir.y, dir.z, want.x, want.y, want.z);
                        /* clip on depth: the depth of the ray's first point is clip_start */
                        VT_CHECK_REL(v3_dot(v3_scale(dir, t0), v3_neg(ez)), c.clip_start, 1e-5, "clip depth");
                    } else {
                        v3 want = v3_add(eo, v3_add(v3_scale(ex, (float)x), v3_scale(ey, (float)y)));
                        VT_CHECK(v3_length(v3_sub(org, want)) < 2e-5f * (1 + c.ortho_scale) &&
                                     v3_length(v3_sub(dir, v3_neg(ez))) < 1e-6f && t0 == c.clip_start,
                                 "ortho fit %d %ux%u aspect %g:%g shift %g %g raster (%g %g): org (%g %g %g) want (%g %g %g)",
                                 fit, c.width, c.height, c.pixel_aspect_x, c.pixel_aspect_y, c.shift_x, c.shift_y, px, py,
                                 org.x, org.y, org.z, want.x, want.y, want.z);
                    }
                    ++cases;
                }
            }
    VT_CHECK(cases == 2 * 3 * 6 * 20, "cases %d", cases);
}

/* Plain numbers: a 36 mm sensor and 50 mm lens, 3:2 image, AUTO fit: the
 * right edge of the middle row is at x/z = 18/50; the top edge at 12/50. */
VT_TEST(camera_field_of_view_hand_values)
{
    vsgl_camera c;
    default_camera(&c);
    c.width = 300; c.height = 200;
    vsgl_camera_model m;
    vsgl__camera_model(&c, &m);
    v3 o, d;
    float t0, t1;
    vsgl__camera_ray(&m, 300.0f, 100.0f, &o, &d, &t0, &t1);
    VT_CHECK_REL(d.x / -d.z, 18.0 / 50.0, 1e-6, "right edge dir (%g %g %g)", d.x, d.y, d.z);
    vsgl__camera_ray(&m, 150.0f, 0.0f, &o, &d, &t0, &t1);
    VT_CHECK_REL(d.y / -d.z, 12.0 / 50.0, 1e-6, "top edge dir (%g %g %g)", d.x, d.y, d.z);
    /* VERTICAL fit with a 24 mm sensor height: the top edge is at 12/50 again */
    c.sensor_fit = VSGL_SENSOR_FIT_VERTICAL;
    c.sensor_height_mm = 24.0f;
    vsgl__camera_model(&c, &m);
    vsgl__camera_ray(&m, 150.0f, 0.0f, &o, &d, &t0, &t1);
    VT_CHECK_REL(d.y / -d.z, 12.0 / 50.0, 1e-6, "vertical fit top edge (%g %g %g)", d.x, d.y, d.z);
    /* shift_x = 0.5 of the larger side moves the centre to the old right edge */
    c.sensor_fit = VSGL_SENSOR_FIT_AUTO;
    c.shift_x = 0.5f;
    vsgl__camera_model(&c, &m);
    vsgl__camera_ray(&m, 150.0f, 100.0f, &o, &d, &t0, &t1);
    VT_CHECK_REL(d.x / -d.z, 18.0 / 50.0, 1e-6, "shifted centre (%g %g %g)", d.x, d.y, d.z);
    /* orthographic: 6 m across the larger side */
    c.type = VSGL_CAMERA_ORTHOGRAPHIC;
    c.shift_x = 0.0f;
    vsgl__camera_model(&c, &m);
    vsgl__camera_ray(&m, 300.0f, 0.0f, &o, &d, &t0, &t1);
    VT_CHECK(fabsf(o.x - 3.0f) < 1e-6f && fabsf(o.y - 2.0f) < 1e-6f && d.z == -1.0f, "ortho corner (%g %g %g)", o.x, o.y, o.z);
}
