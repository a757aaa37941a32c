/* vsgl_scene_set_view: a scene whose camera and lights are replaced renders
 * exactly as a scene built with them; a refused view changes nothing. */
#include "harness.h"
#include "scene_fixture.h"
#include "render/render_internal.h"

#include <stdlib.h>

enum { W = 40, H = 30 };

typedef struct img {
    float comb[W * H * 3];
} img;

static vsgl_result render(vsgl_context *ctx, const vsgl_scene *scene, img *out)
{
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = W;
    o.height = H;
    o.combined = out->comb;
    return vsgl_render(ctx, scene, &s, &o, NULL);
}

/* The fixture room seen from another place, lit by a moved spot plus a point light. */
static void other_view(fx_scene *fx)
{
    const float eye[3] = {0.6f, -2.5f, 1.4f}, at[3] = {-0.2f, 0.5f, 0.6f};
    fx_look_at(fx->camera.world_from_camera, eye, at);
    fx->lights[0].world_from_light[3] += 0.3f;
    fx->lights[1] = fx->lights[0];
    fx->lights[1].type = VSGL_LIGHT_POINT;
    fx->lights[1].power = 50.0f;
    fx_translation(fx->lights[1].world_from_light, 0.5f, 0.2f, 1.5f);
    fx->light_count = 2;
}

VT_TEST(scene_set_view_renders_as_a_new_scene)
{
    static img a, b, before, after;
    fx_scene fx;
    fx_room(&fx, W, H, 0.25f, 200.0f);
    vsgl_context *ctx = NULL;
    vsgl_scene *reused = NULL, *fresh = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &reused) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(render(ctx, reused, &before) == VSGL_OK, "%s", vsgl_context_last_error(ctx));

    other_view(&fx);
    VT_CHECK(vsgl_scene_set_view(ctx, reused, &fx.camera, fx.lights, fx.light_count) == VSGL_OK, "%s",
             vsgl_context_last_error(ctx));
    VT_CHECK(vsgl_scene_create(ctx, fx_desc(&fx), &fresh) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(render(ctx, reused, &a) == VSGL_OK && render(ctx, fresh, &b) == VSGL_OK, "render");
    VT_CHECK(memcmp(&a, &b, sizeof a) == 0, "set_view differs from a scene built with the same view");
    VT_CHECK(memcmp(&a, &before, sizeof a) != 0, "the new view changed nothing (test cannot fail)");
    vsgl_scene_info info = {.size = sizeof info};
    VT_CHECK(vsgl_scene_get_info(reused, &info) == VSGL_OK && info.light_count == 2, "light count %u",
             info.light_count);

    /* a bad light: refused with its index named, the scene keeps its view */
    vsgl_light bad[2] = {fx.lights[0], fx.lights[1]};
    bad[1].power = NAN;
    VT_CHECK(vsgl_scene_set_view(ctx, reused, &fx.camera, bad, 2) == VSGL_ERROR_INVALID_ARGUMENT, "NaN power");
    VT_CHECK(strstr(vsgl_context_last_error(ctx), "light 1") != NULL, "message: %s", vsgl_context_last_error(ctx));
    VT_CHECK(vsgl_scene_set_view(ctx, reused, NULL, fx.lights, 1) == VSGL_ERROR_INVALID_ARGUMENT, "NULL camera");
    VT_CHECK(vsgl_scene_set_view(ctx, reused, &fx.camera, NULL, 1) == VSGL_ERROR_INVALID_ARGUMENT, "NULL lights");
    VT_CHECK(render(ctx, reused, &after) == VSGL_OK, "render after refusals");
    VT_CHECK(memcmp(&a, &after, sizeof a) == 0, "a refused view changed the scene");

    /* no lights: allowed, renders black */
    VT_CHECK(vsgl_scene_set_view(ctx, reused, &fx.camera, NULL, 0) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(render(ctx, reused, &after) == VSGL_OK, "render without lights");
    double sum = 0;
    for (size_t i = 0; i < sizeof after.comb / sizeof after.comb[0]; ++i)
        sum += after.comb[i];
    VT_CHECK(sum == 0.0, "no lights but light %g", sum);
    vsgl_scene_destroy(fresh);
    vsgl_scene_destroy(reused);
    vsgl_context_destroy(ctx);
}

static vsgl_result render_with(vsgl_context *ctx, const vsgl_scene *scene, vsgl_render_cache *cache, img *out,
                               vsgl_render_stats *st)
{
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = W;
    o.height = H;
    o.combined = out->comb;
    return vsgl_render_cached(ctx, scene, &s, cache, &o, st);
}

VT_TEST(render_cache_reuses_what_stood_still_bit_identically)
{
    static img cached, plain;
    fx_scene fx;
    fx_room(&fx, W, H, 0.25f, 200.0f);
    vsgl_context *ctx = NULL;
    vsgl_scene *scene = NULL;
    vsgl_render_cache *cache = NULL;
    vsgl_render_stats st = {.size = sizeof st};
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    VT_REQUIRE(vsgl_render_cache_create(ctx, &cache) == VSGL_OK, "cache");
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(render_with(ctx, scene, cache, &cached, &st) == VSGL_OK && st.reused == 0, "first: reused %u", st.reused);

    /* the light moves: the G-buffer is reused */
    fx.lights[0].world_from_light[3] += 0.2f;
    VT_CHECK(vsgl_scene_set_view(ctx, scene, &fx.camera, fx.lights, fx.light_count) == VSGL_OK, "set_view");
    VT_CHECK(render_with(ctx, scene, cache, &cached, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(st.reused == VSGL_REUSED_GBUFFER, "light moved: reused %u", st.reused);
    VT_CHECK(st.lights_used == 1 && st.vsgl_count > 0, "stats %u %u", st.lights_used, st.vsgl_count);
    VT_CHECK(render_with(ctx, scene, NULL, &plain, NULL) == VSGL_OK, "uncached");
    VT_CHECK(memcmp(&cached, &plain, sizeof cached) == 0, "light moved: cached render differs");

    /* the camera moves: the VSGLs are reused, with the fit's stats */
    uint32_t vsgls = st.vsgl_count;
    const float eye[3] = {0.4f, -3.0f, 1.2f}, at[3] = {0.0f, 0.0f, 0.7f};
    fx_look_at(fx.camera.world_from_camera, eye, at);
    VT_CHECK(vsgl_scene_set_view(ctx, scene, &fx.camera, fx.lights, fx.light_count) == VSGL_OK, "set_view");
    VT_CHECK(render_with(ctx, scene, cache, &cached, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(st.reused == VSGL_REUSED_FIT && st.vsgl_count == vsgls && st.lights_used == 1,
             "camera moved: reused %u, %u VSGLs", st.reused, st.vsgl_count);
    VT_CHECK(render_with(ctx, scene, NULL, &plain, NULL) == VSGL_OK, "uncached");
    VT_CHECK(memcmp(&cached, &plain, sizeof cached) == 0, "camera moved: cached render differs");

    /* nothing moved: both reused */
    VT_CHECK(render_with(ctx, scene, cache, &cached, &st) == VSGL_OK, "again");
    VT_CHECK(st.reused == (VSGL_REUSED_GBUFFER | VSGL_REUSED_FIT), "unchanged: reused %u", st.reused);
    VT_CHECK(memcmp(&cached, &plain, sizeof cached) == 0, "unchanged: cached render differs");

    /* a new scene with other geometry, most likely at the old one's address,
     * with the same camera and lights: nothing may be reused */
    vsgl_scene_destroy(scene);
    scene = NULL;
    for (uint32_t v = 0; v < fx.vertex_count; ++v)
        fx.positions[v * 3 + 2] *= 0.9f;
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(render_with(ctx, scene, cache, &cached, &st) == VSGL_OK && st.reused == 0, "new scene: reused %u",
             st.reused);
    VT_CHECK(render_with(ctx, scene, NULL, &plain, NULL) == VSGL_OK, "uncached");
    VT_CHECK(memcmp(&cached, &plain, sizeof cached) == 0, "new scene: cached render differs");

    /* a failed render empties the cache */
    vsgl_render_settings bad;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &bad);
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = W + 1; /* wrong size */
    o.height = H;
    o.combined = cached.comb;
    VT_CHECK(vsgl_render_cached(ctx, scene, &bad, cache, &o, &st) == VSGL_ERROR_INVALID_ARGUMENT, "bad size");
    VT_CHECK(render_with(ctx, scene, cache, &cached, &st) == VSGL_OK, "after failure");
    VT_CHECK(memcmp(&cached, &plain, sizeof cached) == 0, "after failure: cached render differs");
    vsgl_render_cache_destroy(cache);
    vsgl_render_cache_destroy(NULL);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* Every output plane of a render, for whole-output comparisons. */
typedef struct planes8 {
    float p[7][W * H * 3];
    float alpha[W * H];
} planes8;

static vsgl_result render_planes(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                                 vsgl_render_cache *cache, planes8 *out, vsgl_render_stats *st)
{
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = W;
    o.height = H;
    o.diffuse_light = out->p[0];
    o.glossy_light = out->p[1];
    o.diffuse_color = out->p[2];
    o.glossy_color = out->p[3];
    o.diffuse = out->p[4];
    o.glossy = out->p[5];
    o.combined = out->p[6];
    o.alpha = out->alpha;
    return vsgl_render_cached(ctx, scene, s, cache, &o, st);
}

/* A light edit through a cache replays the shading plan recorded with the
 * G-buffer (shade/shade_job.h): every plane equals an uncached render, bit
 * for bit, for sparse shading with edge slots, AA, visibility rays, GGX's
 * two lobes, and any thread count; a new stride records a new plan. */
VT_TEST(render_cache_shading_plan_replays_bit_identically)
{
    static planes8 cached, plain;
    vsgl_render_settings cases[4];
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &cases[0]);          /* stride 2, edge slots */
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &cases[1]);         /* aa 2, visibility rays */
    cases[1].vsgl_count = 32;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &cases[2]);
    cases[2].shade_stride = 3;
    cases[2].edge_samples = 0;
    cases[2].glossy_mode = VSGL_GLOSSY_ASG2;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &cases[3]);
    cases[3].shade_stride = 4;
    for (uint32_t threads = 1; threads <= 3; threads += 2) {
        fx_scene fx;
        fx_room(&fx, W, H, 0.25f, 200.0f);
        vsgl_context *ctx = fx_context(threads);
        vsgl_scene *scene = NULL;
        vsgl_render_cache *cache = NULL;
        VT_REQUIRE(ctx != NULL, "context");
        VT_REQUIRE(vsgl_render_cache_create(ctx, &cache) == VSGL_OK, "cache");
        VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        for (int c = 0; c < 4; ++c) {
            vsgl_render_stats st = {.size = sizeof st};
            /* the first render of a case records (a new G-buffer, stride or glossy mode), the next ones replay */
            for (int edit = 0; edit < 3; ++edit) {
                fx.lights[0].world_from_light[3] += 0.05f;
                fx.lights[0].world_from_light[7] -= 0.03f;
                VT_CHECK(vsgl_scene_set_view(ctx, scene, &fx.camera, fx.lights, fx.light_count) == VSGL_OK,
                         "set_view");
                VT_CHECK(render_planes(ctx, scene, &cases[c], cache, &cached, &st) == VSGL_OK, "%s",
                         vsgl_context_last_error(ctx));
                VT_CHECK(edit == 0 || st.reused == VSGL_REUSED_GBUFFER, "case %d edit %d: reused %u", c, edit,
                         st.reused);
                VT_CHECK(render_planes(ctx, scene, &cases[c], NULL, &plain, NULL) == VSGL_OK, "uncached");
                for (int p = 0; p < 7; ++p)
                    VT_CHECK(memcmp(cached.p[p], plain.p[p], sizeof plain.p[p]) == 0,
                             "threads %u case %d edit %d: plane %d differs from an uncached render", threads, c,
                             edit, p);
                VT_CHECK(memcmp(cached.alpha, plain.alpha, sizeof plain.alpha) == 0, "case %d: alpha differs", c);
            }
        }
        /* the camera moves: a new G-buffer, a new plan */
        const float eye[3] = {0.4f, -3.0f, 1.2f}, at[3] = {0.0f, 0.0f, 0.7f};
        fx_look_at(fx.camera.world_from_camera, eye, at);
        for (int edit = 0; edit < 2; ++edit) {
            fx.lights[0].world_from_light[3] += 0.05f;
            VT_CHECK(vsgl_scene_set_view(ctx, scene, &fx.camera, fx.lights, fx.light_count) == VSGL_OK, "set_view");
            VT_CHECK(render_planes(ctx, scene, &cases[0], cache, &cached, NULL) == VSGL_OK, "camera moved");
            VT_CHECK(render_planes(ctx, scene, &cases[0], NULL, &plain, NULL) == VSGL_OK, "uncached");
            VT_CHECK(memcmp(&cached, &plain, sizeof plain) == 0, "camera moved, edit %d: cached render differs", edit);
        }
        vsgl_render_cache_destroy(cache);
        vsgl_scene_destroy(scene);
        vsgl_context_destroy(ctx);
    }
}

/* The same in a smooth-shaded scene, where visibility rays start from the
 * smooth surface the corner normals describe (the G-buffer's lift): the
 * floor's corner normals lean outwards, so its samples lie under their
 * smooth surface. The replay rebuilt its receivers from the plan's lanes
 * without the lift and traced from uninitialised origins (Embree's
 * assertion aborted the process); the lanes now carry it. */
VT_TEST(render_cache_replay_keeps_the_smooth_surface_lift)
{
    static planes8 cached, plain;
    static float corner_normals[FX_MAX_TRIS * 9];
    fx_scene fx;
    fx_room(&fx, W, H, 0.25f, 200.0f);
    /* a low block on the floor: something for the rays to meet (an empty
     * box room is a convex shell and traces none) */
    const float lo[3] = {-0.5f, -0.3f, 0.0f}, hi[3] = {0.3f, 0.3f, 0.25f};
    const float top[4][3] = {{lo[0], lo[1], hi[2]}, {hi[0], lo[1], hi[2]}, {hi[0], hi[1], hi[2]}, {lo[0], hi[1], hi[2]}};
    const float front[4][3] = {{lo[0], lo[1], lo[2]}, {hi[0], lo[1], lo[2]}, {hi[0], lo[1], hi[2]}, {lo[0], lo[1], hi[2]}};
    const float back[4][3] = {{hi[0], hi[1], lo[2]}, {lo[0], hi[1], lo[2]}, {lo[0], hi[1], hi[2]}, {hi[0], hi[1], hi[2]}};
    const float left[4][3] = {{lo[0], hi[1], lo[2]}, {lo[0], lo[1], lo[2]}, {lo[0], lo[1], hi[2]}, {lo[0], hi[1], hi[2]}};
    const float right[4][3] = {{hi[0], lo[1], lo[2]}, {hi[0], hi[1], lo[2]}, {hi[0], hi[1], hi[2]}, {hi[0], lo[1], hi[2]}};
    fx_quad(&fx, top, 3);
    fx_quad(&fx, front, 3);
    fx_quad(&fx, back, 3);
    fx_quad(&fx, left, 3);
    fx_quad(&fx, right, 3);
    for (uint32_t t = 0; t < fx.triangle_count; ++t) {
        const float *p[3];
        for (int k = 0; k < 3; ++k)
            p[k] = fx.positions + 3 * fx.indices[3 * t + (uint32_t)k];
        v3 e1 = v3_make(p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]);
        v3 e2 = v3_make(p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]);
        v3 n = v3_normalize(v3_cross(e1, e2));
        for (int k = 0; k < 3; ++k) {
            v3 c = n;
            if (t < 2) /* the floor (fx_room's first quad): lean out from its middle */
                c = v3_normalize(v3_add(n, v3_make(0.4f * p[k][0], 0.4f * p[k][1], 0.0f)));
            corner_normals[9 * t + 3 * (uint32_t)k] = c.x;
            corner_normals[9 * t + 3 * (uint32_t)k + 1] = c.y;
            corner_normals[9 * t + 3 * (uint32_t)k + 2] = c.z;
        }
    }
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s); /* stride 2, visibility rays */
    s.vsgl_count = 32;
    vsgl_context *ctx = fx_context(2);
    VT_REQUIRE(ctx != NULL, "context");
    vsgl_scene_desc d = *fx_desc(&fx);
    d.corner_normals = corner_normals;
    vsgl_scene *scene = NULL;
    vsgl_render_cache *cache = NULL;
    VT_REQUIRE(vsgl_render_cache_create(ctx, &cache) == VSGL_OK, "cache");
    VT_REQUIRE(vsgl_scene_create(ctx, &d, &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    for (int edit = 0; edit < 3; ++edit) {
        vsgl_render_stats st = {.size = sizeof st};
        fx.lights[0].world_from_light[3] += 0.05f;
        VT_CHECK(vsgl_scene_set_view(ctx, scene, &fx.camera, fx.lights, fx.light_count) == VSGL_OK, "set_view");
        VT_CHECK(render_planes(ctx, scene, &s, cache, &cached, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        VT_CHECK(edit == 0 || st.reused == VSGL_REUSED_GBUFFER, "edit %d: reused %u", edit, st.reused);
        VT_CHECK(render_planes(ctx, scene, &s, NULL, &plain, NULL) == VSGL_OK, "uncached");
        VT_CHECK(memcmp(&cached, &plain, sizeof plain) == 0, "edit %d: the replay differs from an uncached render",
                 edit);
    }
    vsgl_render_cache_destroy(cache);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* A replay leaves DiffCol, GlossCol and coverage in the cache's planes as
 * its record or last replay wrote them (sparse_replay.c); a render between
 * them that wrote the planes otherwise (here every pixel shaded, then the
 * colours overwritten as a render with other colours would) makes the next
 * replay write them again: still equal to an uncached render. Stride 4 with
 * one sample per pixel also puts the record's four-pixel lanes
 * (record_cell4, sparse.c) against the uncached render's per-sample
 * classification (a 0.2 % change of its plane tolerance fails here). */
VT_TEST(render_cache_replay_rewrites_colours_after_another_render)
{
    static planes8 cached, plain;
    vsgl_render_settings sparse, full;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &sparse);
    sparse.shade_stride = 4;
    sparse.edge_samples = 0;
    full = sparse;
    full.shade_stride = 1;
    fx_scene fx;
    fx_room(&fx, W, H, 0.25f, 200.0f);
    vsgl_context *ctx = fx_context(2);
    vsgl_scene *scene = NULL;
    vsgl_render_cache *cache = NULL;
    VT_REQUIRE(ctx != NULL, "context");
    VT_REQUIRE(vsgl_render_cache_create(ctx, &cache) == VSGL_OK, "cache");
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    const vsgl_render_settings *order[4] = {&sparse, &sparse, &full, &sparse}; /* record, replay, other, replay */
    for (int k = 0; k < 4; ++k) {
        fx.lights[0].world_from_light[3] += 0.05f;
        VT_CHECK(vsgl_scene_set_view(ctx, scene, &fx.camera, fx.lights, fx.light_count) == VSGL_OK, "set_view");
        VT_CHECK(render_planes(ctx, scene, order[k], cache, &cached, NULL) == VSGL_OK, "%s",
                 vsgl_context_last_error(ctx));
        VT_CHECK(render_planes(ctx, scene, order[k], NULL, &plain, NULL) == VSGL_OK, "uncached");
        VT_CHECK(memcmp(&cached, &plain, sizeof plain) == 0, "render %d: cached render differs", k);
        if (k == 2) { /* colours as another render could leave them */
            VT_REQUIRE(cache->planes && cache->planes_floats >= (size_t)W * H * 13, "the cache keeps planes");
            for (size_t i = (size_t)W * H * 6; i < (size_t)W * H * 13; ++i)
                cache->planes[i] = 0.5f;
        }
    }
    vsgl_render_cache_destroy(cache);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* The live preview while the view moves (addon live.NavigationSchedule):
 * each view rendered through the cache at a coarser size (1/2, 1/3 in each
 * direction) or a coarser shade stride, a coarse render cancelled half-way,
 * then the full render of the view at rest through the same cache (the
 * refine): every plane equal to a plain render of that view bit for bit,
 * and a light edit after it (the replay of the refine's plan) as well. */
enum { CW = (W + 1) / 2, CH = (H + 1) / 2 };

static int32_t cancel_at_shade(void *user, const char *stage, float fraction)
{
    (void)stage;
    return *(const int *)user && fraction > 0.5f;
}

VT_TEST(render_cache_refine_after_coarse_views_equals_a_plain_render)
{
    static planes8 cached, plain;
    static float small[W * H * 3];
    vsgl_render_settings live;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &live); /* the add-on's Live quality */
    live.shade_stride = 4;
    live.edge_samples = 0;
    live.glossy_mode = VSGL_GLOSSY_ASG;
    vsgl_render_settings coarse_stride = live;
    coarse_stride.shade_stride = 8;
    for (uint32_t threads = 1; threads <= 2; ++threads) {
        fx_scene fx;
        fx_room(&fx, W, H, 0.25f, 200.0f);
        int cancel = 0;
        vsgl_context_desc cd;
        memset(&cd, 0, sizeof cd);
        cd.size = sizeof cd;
        cd.thread_count = threads;
        cd.progress = cancel_at_shade;
        cd.progress_user = &cancel;
        vsgl_context *ctx = NULL;
        vsgl_scene *scene = NULL;
        vsgl_render_cache *cache = NULL;
        VT_REQUIRE(vsgl_context_create(&cd, &ctx) == VSGL_OK, "context");
        VT_REQUIRE(vsgl_render_cache_create(ctx, &cache) == VSGL_OK, "cache");
        VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        VT_CHECK(render_planes(ctx, scene, &live, cache, &cached, NULL) == VSGL_OK, "first full render");
        const vsgl_camera full_camera = fx.camera;
        for (int round = 0; round < 3; ++round) {
            /* the view moves: three coarse views, the last one cancelled half-way in round 1 */
            for (int k = 0; k < 3; ++k) {
                const float eye[3] = {0.3f - 0.1f * (float)(round * 3 + k), -3.0f, 1.2f}, at[3] = {0.0f, 0.0f, 0.7f};
                fx_look_at(fx.camera.world_from_camera, eye, at);
                vsgl_camera c = fx.camera;
                const vsgl_render_settings *s = &live;
                if (round == 2) {
                    s = &coarse_stride; /* full size, a coarser stride */
                } else {
                    c.width = round == 0 ? CW : (W + 2) / 3;
                    c.height = round == 0 ? CH : (H + 2) / 3;
                }
                VT_CHECK(vsgl_scene_set_view(ctx, scene, &c, fx.lights, fx.light_count) == VSGL_OK, "set_view");
                vsgl_render_output o;
                memset(&o, 0, sizeof o);
                o.width = c.width;
                o.height = c.height;
                o.combined = small;
                cancel = round == 1 && k == 2;
                vsgl_result r = vsgl_render_cached(ctx, scene, s, cache, &o, NULL);
                VT_CHECK(r == (cancel ? VSGL_ERROR_CANCELLED : VSGL_OK), "round %d coarse view %d: %s", round, k,
                         vsgl_context_last_error(ctx));
                cancel = 0;
            }
            /* the view rests: the refine at the full size */
            fx.camera.width = full_camera.width;
            fx.camera.height = full_camera.height;
            VT_CHECK(vsgl_scene_set_view(ctx, scene, &fx.camera, fx.lights, fx.light_count) == VSGL_OK, "set_view");
            vsgl_render_stats st = {.size = sizeof st};
            VT_CHECK(render_planes(ctx, scene, &live, cache, &cached, &st) == VSGL_OK, "%s",
                     vsgl_context_last_error(ctx));
            VT_CHECK(round == 2 || !(st.reused & VSGL_REUSED_GBUFFER), "round %d: the refine took a coarse G-buffer",
                     round); /* round 2's coarse views were at the full size: its G-buffer is the view's */
            VT_CHECK(render_planes(ctx, scene, &live, NULL, &plain, NULL) == VSGL_OK, "uncached");
            for (int p = 0; p < 7; ++p)
                VT_CHECK(memcmp(cached.p[p], plain.p[p], sizeof plain.p[p]) == 0,
                         "threads %u round %d: the refine's plane %d differs from a plain render", threads, round, p);
            VT_CHECK(memcmp(cached.alpha, plain.alpha, sizeof plain.alpha) == 0, "round %d: alpha differs", round);
            /* a light edit after the rest replays the refine's plan */
            fx.lights[0].world_from_light[3] += 0.05f;
            VT_CHECK(vsgl_scene_set_view(ctx, scene, &fx.camera, fx.lights, fx.light_count) == VSGL_OK, "set_view");
            VT_CHECK(render_planes(ctx, scene, &live, cache, &cached, &st) == VSGL_OK, "light edit");
            VT_CHECK(st.reused & VSGL_REUSED_GBUFFER, "round %d: the light edit did not reuse the refine", round);
            VT_CHECK(render_planes(ctx, scene, &live, NULL, &plain, NULL) == VSGL_OK, "uncached");
            VT_CHECK(memcmp(&cached, &plain, sizeof plain) == 0, "threads %u round %d: light edit after the refine "
                     "differs from a plain render", threads, round);
        }
        vsgl_render_cache_destroy(cache);
        vsgl_scene_destroy(scene);
        vsgl_context_destroy(ctx);
    }
}
