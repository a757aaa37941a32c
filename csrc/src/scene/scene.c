/* vsgl_scene: validate, copy, drop degenerate triangles, build the Embree
 * BVH (one RTCDevice per scene, no global state). */
#include "scene/scene_data.h"
#include "core/parallel.h"
#include "core/versioned.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* At most this many "dropped" warnings are logged individually. */
#define VSGL__MAX_DROP_WARNINGS 10
/* Embree worker threads are capped: BVH builds gain little past this here. */
#define VSGL__EMBREE_MAX_THREADS 64

static void embree_error(void *user, enum RTCError code, const char *str)
{
    vsgl_scene *s = user;
    if (s->embree_message[0] == '\0')
        snprintf(s->embree_message, sizeof s->embree_message, "Embree error %d: %s", (int)code,
                 str ? str : "(no message)");
}

static vsgl_result embree_check(vsgl_context *ctx, vsgl_scene *s, const char *what)
{
    enum RTCError e = rtcGetDeviceError(s->device);
    if (e == RTC_ERROR_NONE && s->embree_message[0] == '\0')
        return VSGL_OK;
    if (e == RTC_ERROR_OUT_OF_MEMORY)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: %s: Embree ran out of memory", what);
    return vsgl__fail(ctx, VSGL_ERROR_INTERNAL, "scene: %s failed: %s (code %d)", what,
                      s->embree_message[0] ? s->embree_message : "no message", (int)e);
}

void vsgl_scene_destroy(vsgl_scene *s)
{
    if (!s)
        return;
    if (s->rtc)
        rtcReleaseScene(s->rtc);
    if (s->device)
        rtcReleaseDevice(s->device);
    free(s->corner_normals);
    free(s->corner_uvs);
    free(s->corner_tangents);
    free(s->face_normals);
    free(s->tri_material);
    free(s->source_triangle);
    free(s->materials);
    free(s->glossy_albedo);
    free(s->lights);
    for (uint32_t i = 0; i < s->texture_count; ++i)
        vsgl__texture_free(&s->textures[i]);
    free(s->textures);
    free(s->material_textures);
    free(s->corner_colors);
    free(s->uv_density);
    free(s->occ_boxes);
    free(s->occ_few);
    free(s->tri_part);
    free(s->tri_side);
    free(s->part_curved);
    free(s);
}

/* Unit face normal in double; returns 0 for a zero-area triangle. */
static int face_normal(const float *p0, const float *p1, const float *p2, float n[3])
{
    double e1[3], e2[3], c[3];
    for (int k = 0; k < 3; ++k) {
        e1[k] = (double)p1[k] - p0[k];
        e2[k] = (double)p2[k] - p0[k];
    }
    c[0] = e1[1] * e2[2] - e1[2] * e2[1];
    c[1] = e1[2] * e2[0] - e1[0] * e2[2];
    c[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double l = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    if (!(l > 0.0) || !isfinite(l))
        return 0;
    for (int k = 0; k < 3; ++k)
        n[k] = (float)(c[k] / l);
    /* a normal that underflowed in float is as good as degenerate */
    return (n[0] != 0.0f || n[1] != 0.0f || n[2] != 0.0f);
}

/* First corner (0-2) of a triangle whose normal has (near) zero length, or -1. */
static int zero_normal_corner(const float *n9)
{
    for (int c = 0; c < 3; ++c) {
        const float *n = n9 + c * 3;
        double l2 = (double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2];
        if (!(l2 > 1e-20))
            return c;
    }
    return -1;
}

/* Pass 1: which triangles survive (non-zero area, no zero-length corner
 * normal); the first few dropped ones are named in warnings. NULL with the
 * error set when out of memory (and for no triangles: *kept = 0). */
static unsigned char *select_triangles(vsgl_context *ctx, const vsgl_scene_desc *d, uint32_t *kept_out,
                                       uint32_t *dropped_out, vsgl_result *r)
{
    uint32_t tc = d->triangle_count, kept = 0, dropped = 0;
    *r = VSGL_OK;
    unsigned char *keep = tc ? malloc(tc) : NULL;
    if (tc && !keep) {
        *r = vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: out of memory for %u triangles", (unsigned)tc);
        return NULL;
    }
    for (uint32_t t = 0; t < tc; ++t) {
        const uint32_t *ix = d->indices + (size_t)t * 3;
        float n[3];
        keep[t] = (unsigned char)face_normal(d->positions + (size_t)ix[0] * 3, d->positions + (size_t)ix[1] * 3,
                                             d->positions + (size_t)ix[2] * 3, n);
        int zero_corner = -1;
        if (keep[t] && d->corner_normals)
            zero_corner = zero_normal_corner(d->corner_normals + (size_t)t * 9);
        if (zero_corner >= 0)
            keep[t] = 0;
        if (keep[t]) {
            ++kept;
            continue;
        }
        if (dropped < VSGL__MAX_DROP_WARNINGS) {
            if (zero_corner >= 0) {
                const float *cn = d->corner_normals + (size_t)t * 9 + zero_corner * 3;
                vsgl__log(ctx, VSGL_LOG_WARNING, "triangle %u: corner %d normal (%g, %g, %g) has zero length, dropped",
                          (unsigned)t, zero_corner, (double)cn[0], (double)cn[1], (double)cn[2]);
            } else {
                vsgl__log(ctx, VSGL_LOG_WARNING, "triangle %u: zero area (vertices %u, %u, %u), dropped",
                          (unsigned)t, (unsigned)ix[0], (unsigned)ix[1], (unsigned)ix[2]);
            }
        }
        ++dropped;
    }
    if (dropped > VSGL__MAX_DROP_WARNINGS)
        vsgl__log(ctx, VSGL_LOG_WARNING, "scene: %u degenerate triangles (zero area or zero-length normal) dropped in all",
                  (unsigned)dropped);
    *kept_out = kept;
    *dropped_out = dropped;
    return keep;
}

/* The per-triangle arrays of the kept triangles. */
static vsgl_result alloc_triangle_arrays(vsgl_context *ctx, const vsgl_scene_desc *d, vsgl_scene *s, uint32_t kept)
{
    size_t k = kept ? kept : 1;
    s->corner_normals = malloc(k * 9 * sizeof(float));
    s->face_normals = malloc(k * 3 * sizeof(float));
    s->tri_material = malloc(k * sizeof(uint32_t));
    s->source_triangle = malloc(k * sizeof(uint32_t));
    if (d->corner_uvs)
        s->corner_uvs = malloc(k * 6 * sizeof(float));
    if (d->corner_tangents)
        s->corner_tangents = malloc(k * 12 * sizeof(float));
    if (s->textured && d->corner_colors)
        s->corner_colors = malloc(k * 9 * sizeof(float));
    if (s->textured)
        s->uv_density = calloc(k, sizeof(float));
    if (!s->corner_normals || !s->face_normals || !s->tri_material || !s->source_triangle ||
        (d->corner_uvs && !s->corner_uvs) || (d->corner_tangents && !s->corner_tangents) ||
        (s->textured && d->corner_colors && !s->corner_colors) || (s->textured && !s->uv_density))
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: out of memory for %u triangles", (unsigned)kept);
    return VSGL_OK;
}

/* The scene's Embree device (its own: no global state) and empty scene. */
static vsgl_result new_embree_scene(vsgl_context *ctx, vsgl_scene *s)
{
    char config[96];
    uint32_t threads = vsgl_context_thread_count(ctx);
    if (threads > VSGL__EMBREE_MAX_THREADS)
        threads = VSGL__EMBREE_MAX_THREADS;
    snprintf(config, sizeof config, "threads=%u,set_affinity=0,verbose=0", (unsigned)threads);
    s->device = rtcNewDevice(config);
    if (!s->device)
        return vsgl__fail(ctx, VSGL_ERROR_INTERNAL, "scene: rtcNewDevice(\"%s\") failed (Embree error %d)", config,
                          (int)rtcGetDeviceError(NULL));
    rtcSetDeviceErrorFunction(s->device, embree_error, s);
    s->rtc = rtcNewScene(s->device);
    vsgl_result r = embree_check(ctx, s, "rtcNewScene");
    if (r != VSGL_OK)
        return r;
    rtcSetSceneFlags(s->rtc, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(s->rtc, RTC_BUILD_QUALITY_MEDIUM);
    return VSGL_OK;
}

/* Texture-space area per world area of triangle t, for the lookups' footprints. */
static float uv_density(const vsgl_scene_desc *d, uint32_t t)
{
    const uint32_t *ix = d->indices + (size_t)t * 3;
    const float *uv = d->corner_uvs + (size_t)t * 6;
    double a_uv = 0.5 * fabs(((double)uv[2] - uv[0]) * ((double)uv[5] - uv[1]) -
                             ((double)uv[4] - uv[0]) * ((double)uv[3] - uv[1]));
    const float *p0 = d->positions + (size_t)ix[0] * 3, *p1 = d->positions + (size_t)ix[1] * 3,
                *p2 = d->positions + (size_t)ix[2] * 3;
    double e1[3], e2[3];
    for (int q = 0; q < 3; ++q) {
        e1[q] = (double)p1[q] - p0[q];
        e2[q] = (double)p2[q] - p0[q];
    }
    double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2], cz = e1[0] * e2[1] - e1[1] * e2[0];
    double a_w = 0.5 * sqrt(cx * cx + cy * cy + cz * cz);
    double dens = a_w > 0.0 ? a_uv / a_w : 0.0;
    return dens < 3e38 ? (float)dens : 3e38f;
}

/* Caller's triangle t becomes the scene's triangle o: indices into the
 * Embree buffer `ib`, normals (unit, in double), per-corner data, bounds. */
static void copy_triangle(const vsgl_scene_desc *d, vsgl_scene *s, uint32_t *ib, uint32_t t, uint32_t o, v3 *lo,
                          v3 *hi)
{
    const uint32_t *ix = d->indices + (size_t)t * 3;
    memcpy(ib + (size_t)o * 3, ix, 3 * sizeof(uint32_t));
    for (int c = 0; c < 3; ++c) {
        const float *p = d->positions + (size_t)ix[c] * 3;
        *lo = v3_make(fminf(lo->x, p[0]), fminf(lo->y, p[1]), fminf(lo->z, p[2]));
        *hi = v3_make(fmaxf(hi->x, p[0]), fmaxf(hi->y, p[1]), fmaxf(hi->z, p[2]));
    }
    float *fn = s->face_normals + (size_t)o * 3;
    face_normal(d->positions + (size_t)ix[0] * 3, d->positions + (size_t)ix[1] * 3, d->positions + (size_t)ix[2] * 3, fn);
    float *cn = s->corner_normals + (size_t)o * 9;
    for (int c = 0; c < 3; ++c) {
        v3 n = d->corner_normals
                   ? v3_make(d->corner_normals[(size_t)t * 9 + c * 3], d->corner_normals[(size_t)t * 9 + c * 3 + 1],
                             d->corner_normals[(size_t)t * 9 + c * 3 + 2])
                   : v3_make(fn[0], fn[1], fn[2]);
        /* normalise in double: validated lengths may be tiny or large */
        double l = sqrt((double)n.x * n.x + (double)n.y * n.y + (double)n.z * n.z);
        cn[c * 3 + 0] = (float)(n.x / l);
        cn[c * 3 + 1] = (float)(n.y / l);
        cn[c * 3 + 2] = (float)(n.z / l);
        s->smooth |= cn[c * 3] * fn[0] + cn[c * 3 + 1] * fn[1] + cn[c * 3 + 2] * fn[2] < 1.0f - 1e-6f;
    }
    if (s->corner_uvs)
        memcpy(s->corner_uvs + (size_t)o * 6, d->corner_uvs + (size_t)t * 6, 6 * sizeof(float));
    if (s->corner_tangents)
        memcpy(s->corner_tangents + (size_t)o * 12, d->corner_tangents + (size_t)t * 12, 12 * sizeof(float));
    if (s->corner_colors)
        memcpy(s->corner_colors + (size_t)o * 9, d->corner_colors + (size_t)t * 9, 9 * sizeof(float));
    if (s->uv_density && d->corner_uvs)
        s->uv_density[o] = uv_density(d, t);
    s->tri_material[o] = d->material_indices ? d->material_indices[t] : 0u;
    s->source_triangle[o] = t;
}

/* The kept triangles into the Embree geometry and the scene's arrays. */
static vsgl_result add_geometry(vsgl_context *ctx, const vsgl_scene_desc *d, vsgl_scene *s, const unsigned char *keep,
                                uint32_t kept)
{
    RTCGeometry g = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *vb = g ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                            d->vertex_count) : NULL;
    uint32_t *ib = g ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t),
                                               kept) : NULL;
    if (!g || !vb || !ib) {
        if (g)
            rtcReleaseGeometry(g);
        vsgl_result r = embree_check(ctx, s, "creating the triangle geometry");
        return r != VSGL_OK ? r : vsgl__fail(ctx, VSGL_ERROR_INTERNAL, "scene: Embree returned no buffer");
    }
    memcpy(vb, d->positions, (size_t)d->vertex_count * 3 * sizeof(float));
    s->positions = vb;
    s->indices = ib;
    v3 lo = v3_make(INFINITY, INFINITY, INFINITY), hi = v3_make(-INFINITY, -INFINITY, -INFINITY);
    uint32_t o = 0;
    for (uint32_t t = 0; t < d->triangle_count; ++t)
        if (keep[t])
            copy_triangle(d, s, ib, t, o++, &lo, &hi);
    s->lo = lo;
    s->hi = hi;
    rtcCommitGeometry(g);
    rtcAttachGeometry(s->rtc, g);
    rtcReleaseGeometry(g);
    return VSGL_OK;
}

static vsgl_result build(vsgl_context *ctx, const vsgl_scene_desc *d, vsgl_scene *s)
{
    uint32_t kept = 0, dropped = 0;
    vsgl_result r;
    unsigned char *keep = select_triangles(ctx, d, &kept, &dropped, &r);
    if (r != VSGL_OK)
        return r;
    s->triangle_count = kept;
    s->dropped_triangles = dropped;
    r = alloc_triangle_arrays(ctx, d, s, kept);
    if (r == VSGL_OK)
        r = new_embree_scene(ctx, s);
    if (r == VSGL_OK && kept > 0)
        r = add_geometry(ctx, d, s, keep, kept);
    free(keep);
    if (r != VSGL_OK)
        return r;
    s->vertex_count = d->vertex_count;
    s->convex_shell = vsgl__scene_test_convex_shell(s); /* geometry never changes after this */
    r = vsgl__scene_build_parts(ctx, s);
    if (r == VSGL_OK)
        r = vsgl__scene_build_occluders(ctx, s);
    if (r != VSGL_OK)
        return r;
    rtcCommitScene(s->rtc);
    return embree_check(ctx, s, "building the BVH");
}

/* The glossy directional-albedo table of materials [begin, end) (~2 ms each
 * for glossy ones, nothing for the rest). */
static int32_t albedo_range(void *user, size_t chunk, size_t begin, size_t end)
{
    (void)chunk;
    vsgl_scene *s = user;
    for (size_t k = begin; k < end; ++k) {
        vsgl_brdf_params bp;
        vsgl__material_params(&s->materials[k], &bp);
        vsgl__glossy_albedo_table(&bp, &s->glossy_albedo[k]);
        vsgl__dielectric_albedo_table(&s->materials[k], &s->glossy_albedo[k]);
    }
    return 0;
}

/* Copy the texture tables and build the mip pyramids. */
static vsgl_result copy_textures(vsgl_context *ctx, const vsgl_scene_desc *d, vsgl_scene *s)
{
    if (d->material_textures && d->material_count) {
        for (uint32_t m = 0; m < d->material_count; ++m) {
            const vsgl_material_textures *mt = &d->material_textures[m];
            if (mt->base_color.texture || mt->roughness.texture || mt->metallic.texture ||
                ((mt->flags & VSGL_MATERIAL_TEXTURES_VERTEX_COLOR) && d->corner_colors))
                s->textured = 1;
        }
        if (s->textured) {
            s->material_textures = malloc((size_t)d->material_count * sizeof *s->material_textures);
            if (!s->material_textures)
                return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: out of memory for material textures");
            memcpy(s->material_textures, d->material_textures, (size_t)d->material_count * sizeof *s->material_textures);
        }
    }
    if (!s->textured || !d->texture_count)
        return VSGL_OK;
    s->textures = calloc(d->texture_count, sizeof *s->textures);
    if (!s->textures)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: out of memory for %u textures", (unsigned)d->texture_count);
    for (uint32_t i = 0; i < d->texture_count; ++i) {
        vsgl_result r = vsgl__texture_build(ctx, i, &d->textures[i], &s->textures[i]);
        if (r != VSGL_OK)
            return r;
        s->texture_count = i + 1;
    }
    return VSGL_OK;
}

vsgl_result vsgl_scene_create(vsgl_context *ctx, const vsgl_scene_desc *caller_desc, vsgl_scene **out)
{
    vsgl__clear_error(ctx);
    if (!out)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "scene: out is NULL");
    *out = NULL;
    if (!caller_desc)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "scene: desc is NULL");
    if (caller_desc->size > sizeof(vsgl_scene_desc) ||
        (caller_desc->size && (caller_desc->size < sizeof caller_desc->size || caller_desc->size % 4 != 0)))
        return vsgl__validate_scene_desc(ctx, caller_desc); /* names the size */
    vsgl_scene_desc full;
    vsgl__scene_desc_normalise(caller_desc, &full);
    const vsgl_scene_desc *desc = &full;
    vsgl_result r = vsgl__validate_scene_desc(ctx, desc);
    if (r != VSGL_OK)
        return r;
    vsgl_scene *s = calloc(1, sizeof *s);
    if (!s)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: out of memory");
    r = copy_textures(ctx, desc, s);
    if (r != VSGL_OK) {
        vsgl_scene_destroy(s);
        return r;
    }
    s->camera = *desc->camera;
    s->material_count = desc->material_count;
    s->light_count = desc->light_count;
    if (desc->material_count) {
        s->materials = malloc((size_t)desc->material_count * sizeof *s->materials);
        if (!s->materials) {
            vsgl_scene_destroy(s);
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: out of memory for %u materials", (unsigned)desc->material_count);
        }
        memcpy(s->materials, desc->materials, (size_t)desc->material_count * sizeof *s->materials);
        s->glossy_albedo = calloc(desc->material_count, sizeof *s->glossy_albedo);
        if (!s->glossy_albedo) {
            vsgl_scene_destroy(s);
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: out of memory for %u materials", (unsigned)desc->material_count);
        }
        vsgl__parallel_for(vsgl_context_thread_count(ctx), desc->material_count, 1, albedo_range, s);
    }
    if (desc->light_count) {
        s->lights = malloc((size_t)desc->light_count * sizeof *s->lights);
        if (!s->lights) {
            vsgl_scene_destroy(s);
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: out of memory for %u lights", (unsigned)desc->light_count);
        }
        memcpy(s->lights, desc->lights, (size_t)desc->light_count * sizeof *s->lights);
    }
    r = build(ctx, desc, s);
    if (r != VSGL_OK) {
        vsgl_scene_destroy(s);
        return r;
    }
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    s->identity = (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
    *out = s;
    return VSGL_OK;
}

vsgl_result vsgl_scene_get_info(const vsgl_scene *scene, vsgl_scene_info *info)
{
    if (!scene || !info)
        return VSGL_ERROR_INVALID_ARGUMENT;
    const vsgl_scene_info i = {
        .size = sizeof i,
        .triangle_count = scene->triangle_count,
        .dropped_triangles = scene->dropped_triangles,
        .light_count = scene->light_count,
        .material_count = scene->material_count,
        .bounds_min = {scene->lo.x, scene->lo.y, scene->lo.z},
        .bounds_max = {scene->hi.x, scene->hi.y, scene->hi.z},
    };
    return vsgl__return_versioned(NULL, info, &i, sizeof i, "vsgl_scene_info");
}

const vsgl_material *vsgl__scene_materials(const vsgl_scene *scene, uint32_t *count)
{
    if (count)
        *count = scene->material_count;
    return scene->materials;
}

const vsgl_albedo_table *vsgl__scene_glossy_albedo(const vsgl_scene *scene, uint32_t material)
{
    return material < scene->material_count ? &scene->glossy_albedo[material] : NULL;
}

float vsgl__scene_diffuse_weight(const vsgl_scene *scene, uint32_t material, float cos_view)
{
    return vsgl__diffuse_view_weight(vsgl__scene_glossy_albedo(scene, material), cos_view);
}

float vsgl__scene_diffuse_power(const vsgl_scene *scene, uint32_t material, const vsgl_brdf_params *bp,
                                float cos_i)
{
    const vsgl_albedo_table *t = vsgl__scene_glossy_albedo(scene, material);
    return (t ? t->diffuse_power : 1.0f) * (bp->burley >= 0.0f ? vsgl__burley_albedo(bp->burley, cos_i) : 1.0f);
}

const vsgl_light *vsgl__scene_lights(const vsgl_scene *scene, uint32_t *count)
{
    if (count)
        *count = scene->light_count;
    return scene->lights;
}

uint64_t vsgl__scene_identity(const vsgl_scene *scene)
{
    return scene->identity;
}

const vsgl_camera *vsgl__scene_camera(const vsgl_scene *scene)
{
    return &scene->camera;
}

void vsgl__scene_bounds(const vsgl_scene *scene, v3 *lo, v3 *hi)
{
    *lo = scene->lo;
    *hi = scene->hi;
}
