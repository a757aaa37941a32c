/* vsgl_render end to end on the room fixture: every mode gives finite,
 * non-negative planes with colour bleeding where physics puts it; output
 * sizes, settings validation and determinism across thread counts. */
#include "harness.h"
#include "scene_fixture.h"
#include "gbuffer/gbuffer.h"

#include <stdlib.h>

enum { W = 48, H = 36 };

typedef struct planes {
    float dl[W * H * 3], gl[W * H * 3], dc[W * H * 3], gc[W * H * 3], comb[W * H * 3], alpha[W * H];
} planes;

static vsgl_render_output bind(planes *p)
{
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = W;
    o.height = H;
    o.diffuse_light = p->dl;
    o.glossy_light = p->gl;
    o.diffuse_color = p->dc;
    o.glossy_color = p->gc;
    o.combined = p->comb;
    o.alpha = p->alpha;
    return o;
}

/* Render w x h of scene with settings s into the diffuse and glossy light
 * planes dl, gl (either NULL: not asked for). */
static vsgl_result render_light(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s, uint32_t w,
                                uint32_t h, float *dl, float *gl)
{
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = w;
    o.height = h;
    o.diffuse_light = dl;
    o.glossy_light = gl;
    return vsgl_render(ctx, scene, s, &o, NULL);
}

static vsgl_result render_room_flags(uint32_t threads, const vsgl_render_settings *s, planes *p,
                                     vsgl_render_stats *st, char *err, size_t errlen, uint32_t material_flags)
{
    fx_scene fx;
    fx_room(&fx, W, H, 0.25f, 200.0f);
    for (uint32_t k = 0; k < 4; ++k)
        fx.materials[k].flags |= material_flags;
    vsgl_context *ctx = fx_context(threads);
    vsgl_scene *scene = NULL;
    vsgl_result r = ctx ? VSGL_OK : VSGL_ERROR_OUT_OF_MEMORY;
    if (r == VSGL_OK)
        r = vsgl_scene_create(ctx, fx_desc(&fx), &scene);
    vsgl_render_output o = bind(p);
    if (r == VSGL_OK)
        r = vsgl_render(ctx, scene, s, &o, st);
    if (r != VSGL_OK && err)
        snprintf(err, errlen, "%s", ctx ? vsgl_context_last_error(ctx) : "no context");
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
    return r;
}

static vsgl_result render_room(uint32_t threads, const vsgl_render_settings *s, planes *p, vsgl_render_stats *st,
                               char *err, size_t errlen)
{
    return render_room_flags(threads, s, p, st, err, errlen, 0);
}

/* Relative RMS difference of a from ref over n floats: sqrt(sum (a - ref)^2
 * / sum ref^2). */
static double rel_rms(const float *a, const float *ref, size_t n)
{
    double e = 0.0, r = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double d = (double)a[i] - ref[i];
        e += d * d;
        r += (double)ref[i] * ref[i];
    }
    return sqrt(e / (r > 0.0 ? r : 1.0));
}

/* Mean of channel c of plane v over pixel rectangle [x0,x1) x [y0,y1). */
static double region_mean(const float *v, int c, int x0, int x1, int y0, int y1)
{
    double s = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
            s += v[(y * W + x) * 3 + c];
    return s / ((x1 - x0) * (y1 - y0));
}

VT_TEST(render_every_mode_is_finite_and_bleeds_colour)
{
    static planes p;
    const int fits[3] = {VSGL_FIT_TWO, VSGL_FIT_FIS, VSGL_FIT_KMEANS};
    const int diffuse[3] = {VSGL_COSINE_SG, VSGL_COSINE_PULLED_OUT, VSGL_COSINE_ACCURATE};
    for (int f = 0; f < 3; ++f)
        for (int d = 0; d < 3; ++d)
            for (int gm = 0; gm < 2; ++gm) {
                vsgl_render_settings s;
                vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
                s.aa_samples = 1;
                s.rsm_resolution = 64;
                s.vsgl_count = 16;
                s.fit_mode = fits[f];
                s.diffuse_mode = diffuse[d];
                s.glossy_mode = gm;
                vsgl_render_stats st = {.size = sizeof st};
                char err[256] = "";
                memset(&p, 0xff, sizeof p); /* NaN pattern: every pixel must be written */
                vsgl_result r = render_room(0, &s, &p, &st, err, sizeof err);
                VT_CHECK(r == VSGL_OK, "fit %d diffuse %d glossy %d: %s", fits[f], diffuse[d], gm, err);
                if (r != VSGL_OK)
                    continue;
                int bad = 0;
                for (int i = 0; i < W * H * 3; ++i)
                    bad += !(isfinite(p.dl[i]) && p.dl[i] >= 0 && isfinite(p.gl[i]) && p.gl[i] >= 0 &&
                             isfinite(p.comb[i]) && p.comb[i] >= 0);
                VT_CHECK(bad == 0, "fit %d diffuse %d glossy %d: %d bad values", fits[f], diffuse[d], gm, bad);
                VT_CHECK(st.vsgl_count > 0 && st.lights_used == 1, "fit %d: %u VSGLs", fits[f], st.vsgl_count);
                /* The spot lights the red wall (left): the right (green) wall receives red
                 * light, i.e. its DiffInd has more red than green. Right wall: columns near
                 * the right edge, middle rows. */
                double red = region_mean(p.dl, 0, W - 8, W - 3, H / 3, 2 * H / 3);
                double green = region_mean(p.dl, 1, W - 8, W - 3, H / 3, 2 * H / 3);
                VT_CHECK(red > 1.5 * green && red > 0, "fit %d diffuse %d: right wall DiffInd red %g green %g",
                         fits[f], diffuse[d], red, green);
            }
}

VT_TEST(render_is_bit_identical_for_any_thread_count)
{
    static planes a, b;
    const int fits[3] = {VSGL_FIT_TWO, VSGL_FIT_FIS, VSGL_FIT_KMEANS};
    for (int f = 0; f < 3; ++f) {
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
        s.aa_samples = 2;
        s.rsm_resolution = 64;
        s.vsgl_count = 32;
        s.fit_mode = fits[f];
        s.visibility = VSGL_VISIBILITY_RAY;
        VT_CHECK(render_room(1, &s, &a, NULL, NULL, 0) == VSGL_OK, "1 thread");
        VT_CHECK(render_room(3, &s, &b, NULL, NULL, 0) == VSGL_OK, "3 threads");
        VT_CHECK(memcmp(&a, &b, sizeof a) == 0, "fit %d: planes differ between 1 and 3 threads", fits[f]);
    }
}

VT_TEST(render_rejects_bad_settings_and_sizes_without_touching_output)
{
    static planes p;
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
    char err[256];
    struct { const char *field; int value; const char *want; } cases[] = {
        {"fit_mode", 7, "settings: fit_mode is 7"},
        {"diffuse_mode", 3, "settings: diffuse_mode is 3"},
        {"rsm_resolution", 100000, "settings: rsm_resolution is 100000"},
        {"aa_samples", 99, "settings: aa_samples is 99"},
        {"glossy_lobes", 3, "settings: glossy_lobes is 3 (valid 4 or 5; 0 = 4)"},
        {"visibility_budget", 1, "settings: visibility_budget is 0.6 (valid: at most 0.5"},
        {"visibility_budget", 2, "settings: visibility_budget is nan (valid: at most 0.5"},
        {"visibility_spread", 1, "settings: visibility_spread is 4.5 (valid: at most 4; 0 = 2, negative = rays"},
        {"visibility_spread", 2, "settings: visibility_spread is inf (valid: at most 4"},
        {"visibility_spread", 3, "settings: visibility_spread is nan (valid: at most 4"},
        {"dominant_rays", 17, "settings: dominant_rays is 17 (valid: 1..16; 0 = 1)"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        vsgl_render_settings bad = s;
        if (i == 0) bad.fit_mode = cases[i].value;
        if (i == 1) bad.diffuse_mode = cases[i].value;
        if (i == 2) bad.rsm_resolution = (uint32_t)cases[i].value;
        if (i == 3) bad.aa_samples = (uint32_t)cases[i].value;
        if (i == 4) bad.glossy_lobes = (uint32_t)cases[i].value;
        if (i == 5) bad.visibility_budget = 0.6f;
        if (i == 6) bad.visibility_budget = NAN;
        if (i == 7) bad.visibility_spread = 4.5f;
        if (i == 8) bad.visibility_spread = INFINITY;
        if (i == 9) bad.visibility_spread = NAN;
        if (i == 10) bad.dominant_rays = (uint32_t)cases[i].value;
        memset(&p, 0x7f, sizeof p);
        err[0] = 0;
        VT_CHECK(render_room(0, &bad, &p, NULL, err, sizeof err) == VSGL_ERROR_INVALID_ARGUMENT, "%s", cases[i].field);
        VT_CHECK(strncmp(err, cases[i].want, strlen(cases[i].want)) == 0, "got '%s' want '%s'", err, cases[i].want);
        VT_CHECK(p.dl[0] == p.dl[W * H * 3 - 1] && p.alpha[0] == p.alpha[W * H - 1], "output touched");
    }
    /* wrong plane size */
    fx_scene fx;
    fx_room(&fx, W, H, 0.3f, 10.0f);
    vsgl_context *ctx;
    vsgl_scene *scene;
    vsgl_context_create(NULL, &ctx);
    VT_CHECK(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
    vsgl_render_output o = bind(&p);
    o.width = W + 1;
    VT_CHECK(vsgl_render(ctx, scene, &s, &o, NULL) == VSGL_ERROR_INVALID_ARGUMENT, "size mismatch");
    VT_CHECK(strstr(vsgl_context_last_error(ctx), "camera renders 48x36") != NULL, "%s", vsgl_context_last_error(ctx));
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

VT_TEST(render_skips_dark_lights_and_says_why)
{
    static planes p;
    fx_scene fx;
    fx_room(&fx, W, H, 0.3f, 100.0f);
    fx.lights[1] = fx.lights[0];
    fx.lights[1].power = 0.0f;                  /* zero power */
    fx.lights[2] = fx.lights[0];
    fx_translation(fx.lights[2].world_from_light, 0, 0, 50); /* far above, aimed away? spot points down -Z: at the roof's back */
    fx.lights[2].world_from_light[10] = -1.0f;  /* flip Z: emits up, into the void */
    fx.lights[2].world_from_light[5] = -1.0f;
    fx.light_count = 3;
    vsgl_context *ctx;
    vsgl_scene *scene;
    vsgl_context_create(NULL, &ctx);
    VT_CHECK(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene: %s", vsgl_context_last_error(ctx));
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
    vsgl_render_output o = bind(&p);
    vsgl_render_stats st = {.size = sizeof st};
    VT_CHECK(vsgl_render(ctx, scene, &s, &o, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(st.lights_used == 1 && st.lights_skipped == 2, "used %u skipped %u", st.lights_used, st.lights_skipped);
    VT_CHECK(strstr(st.skipped, "light 1: zero power") != NULL, "skipped: %s", st.skipped);
    VT_CHECK(strstr(st.skipped, "light 2: lights no geometry") != NULL, "skipped: %s", st.skipped);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* The output structs are size-prefixed too (core/versioned.c): an older,
 * shorter stats or output struct gets only its fields, the size is kept,
 * and a size this library does not know is refused before anything runs. */
VT_TEST(render_output_structs_follow_the_versioned_rule)
{
    static planes p;
    fx_scene fx;
    fx_room(&fx, W, H, 0.3f, 100.0f);
    vsgl_context *ctx = NULL;
    vsgl_scene *scene = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene: %s", vsgl_context_last_error(ctx));
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
    /* an older stats struct ending before `skipped`: the tail is not written */
    vsgl_render_stats st;
    memset(&st, 0x5a, sizeof st);
    st.size = (uint32_t)offsetof(vsgl_render_stats, skipped);
    vsgl_render_output o = bind(&p);
    VT_CHECK(vsgl_render(ctx, scene, &s, &o, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(st.size == offsetof(vsgl_render_stats, skipped), "size changed to %u", st.size);
    VT_CHECK(st.lights_used == 1 && st.seconds_total > 0.0, "known fields not written");
    VT_CHECK((unsigned char)st.skipped[0] == 0x5a && (st.reused & 0xff) == 0x5a, "wrote past the caller's size");
    /* an older output struct ending before `alpha`: alpha is not requested */
    memset(p.alpha, 0x7f, sizeof p.alpha);
    o = bind(&p);
    o.size = (uint32_t)offsetof(vsgl_render_output, alpha);
    VT_CHECK(vsgl_render(ctx, scene, &s, &o, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(p.alpha[0] == p.alpha[W * H - 1] && p.alpha[0] != 1.0f, "alpha written beyond the caller's size");
    /* unknown sizes: refused, named, the planes untouched */
    memset(p.dl, 0x7f, sizeof p.dl);
    o = bind(&p);
    vsgl_render_stats newer = {.size = sizeof newer + 8};
    VT_CHECK(vsgl_render(ctx, scene, &s, &o, &newer) == VSGL_ERROR_INVALID_ARGUMENT, "newer stats accepted");
    VT_CHECK(strstr(vsgl_context_last_error(ctx), "vsgl_render_stats.size") != NULL, "%s",
             vsgl_context_last_error(ctx));
    o.size = 6;
    VT_CHECK(vsgl_render(ctx, scene, &s, &o, NULL) == VSGL_ERROR_INVALID_ARGUMENT, "output size 6 accepted");
    VT_CHECK(strstr(vsgl_context_last_error(ctx), "vsgl_render_output.size") != NULL, "%s",
             vsgl_context_last_error(ctx));
    VT_CHECK(p.dl[0] == p.dl[W * H * 3 - 1], "output touched");
    /* the infos */
    vsgl_scene_info info;
    memset(&info, 0x5a, sizeof info);
    info.size = (uint32_t)offsetof(vsgl_scene_info, bounds_min);
    VT_CHECK(vsgl_scene_get_info(scene, &info) == VSGL_OK && info.light_count == 1, "older scene info");
    VT_CHECK(((unsigned char *)info.bounds_min)[0] == 0x5a, "scene info written past its size");
    info.size = sizeof info + 4;
    VT_CHECK(vsgl_scene_get_info(scene, &info) == VSGL_ERROR_INVALID_ARGUMENT, "newer scene info accepted");
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* Many skipped lights: stats.skipped keeps whole lines and ends by saying
 * that the rest is in the log, never a cut line. */
VT_TEST(render_skipped_list_says_when_it_is_full)
{
    enum { N = 64 };
    static planes p;
    static vsgl_light lights[N];
    fx_scene fx;
    fx_room(&fx, W, H, 0.3f, 100.0f);
    lights[0] = fx.lights[0];
    for (int i = 1; i < N; ++i) {
        lights[i] = fx.lights[0];
        lights[i].power = 0.0f;
    }
    vsgl_scene_desc d = *fx_desc(&fx);
    d.lights = lights;
    d.light_count = N;
    vsgl_context *ctx = NULL;
    vsgl_scene *scene = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    VT_REQUIRE(vsgl_scene_create(ctx, &d, &scene) == VSGL_OK, "scene: %s", vsgl_context_last_error(ctx));
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
    vsgl_render_output o = bind(&p);
    vsgl_render_stats st = {.size = sizeof st};
    VT_CHECK(vsgl_render(ctx, scene, &s, &o, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(st.lights_skipped == N - 1, "skipped %u", st.lights_skipped);
    size_t len = strlen(st.skipped);
    VT_CHECK(len > 0 && len < sizeof st.skipped && st.skipped[len - 1] == '\n', "ends with a whole line");
    VT_CHECK(strstr(st.skipped, "(more: every skipped item is logged") != NULL, "no 'more' line: %s", st.skipped);
    VT_CHECK(strstr(st.skipped, "light 1: zero power") != NULL, "first item missing");
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* Issue 10: a render that cannot fit is refused before anything is
 * allocated, with a message naming the size, the estimate and the limit;
 * the estimate validates settings exactly as the render does. */
typedef struct warn_log { int warnings; char first[512]; } warn_log;
static void log_warnings(void *user, int32_t level, const char *message)
{
    warn_log *w = user;
    if (level == VSGL_LOG_WARNING && w->warnings++ == 0)
        snprintf(w->first, sizeof w->first, "%s", message);
}

VT_TEST(render_refuses_what_exceeds_the_memory_limit_up_front)
{
    static planes p;
    fx_scene fx;
    fx_room(&fx, W, H, 0.3f, 100.0f);
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.size = sizeof cd;
    cd.max_memory = 1u << 20; /* 1 MiB: the 48x36 room at aa 2 needs more */
    vsgl_context *ctx = NULL;
    vsgl_scene *scene = NULL;
    VT_CHECK(vsgl_context_create(&cd, &ctx) == VSGL_OK, "context");
    VT_CHECK(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene: %s", vsgl_context_last_error(ctx));
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    vsgl_memory_estimate e;
    vsgl_result r = vsgl_render_estimate(ctx, scene, &s, 22, &e);
    const char *msg = vsgl_context_last_error(ctx);
    VT_CHECK(r == VSGL_ERROR_OUT_OF_MEMORY, "estimate result %d '%s'", r, msg);
    VT_CHECK(strstr(msg, "render: 48x36 with aa 2 and RSM 256 needs about ") == msg, "'%s'", msg);
    VT_CHECK(strstr(msg, "more than the memory limit of 1.0 MiB (max_memory)") != NULL, "'%s'", msg);
    /* the parts: 48x36 pixels x 22 output floats; 4 samples x 56 bytes (pos, nrm, view, tan;
     * material, convex part), + 8 for the edge refinement's weight and normal spread, + a
     * byte of edge mask per pixel; 52 bytes of planes */
    VT_CHECK(e.output == (uint64_t)W * H * 22 * 4 && e.gbuffer == (uint64_t)W * H * (4 * (56 + 8) + 1) &&
                 e.planes == (uint64_t)W * H * 52 && e.limit == (1u << 20),
             "output %llu gbuffer %llu planes %llu limit %llu", (unsigned long long)e.output,
             (unsigned long long)e.gbuffer, (unsigned long long)e.planes, (unsigned long long)e.limit);
    VT_CHECK(e.rsm >= 256u * 256u * 68u && e.fit > 0 && e.shade > 0, "rsm %llu fit %llu shade %llu",
             (unsigned long long)e.rsm, (unsigned long long)e.fit, (unsigned long long)e.shade);
    VT_CHECK(e.total == e.output + e.gbuffer + e.planes + e.rsm + e.fit + e.shade && e.total > e.limit, "total %llu",
             (unsigned long long)e.total);
    /* the render refuses at once and leaves the planes alone */
    memset(&p, 0x7f, sizeof p);
    vsgl_render_output o = bind(&p);
    r = vsgl_render(ctx, scene, &s, &o, NULL);
    msg = vsgl_context_last_error(ctx);
    VT_CHECK(r == VSGL_ERROR_OUT_OF_MEMORY && strstr(msg, "more than the memory limit of 1.0 MiB") != NULL,
             "render result %d '%s'", r, msg);
    VT_CHECK(p.dl[0] == p.dl[W * H * 3 - 1] && p.alpha[0] == p.alpha[W * H - 1], "output touched");
    /* the same settings errors as vsgl_render, before any estimate */
    struct { uint32_t aa, rsm, vsgls; const char *want; } bad[] = {
        {17, 256, 64, "settings: aa_samples is 17 (valid 1..16)"},
        {1, 1, 64, "settings: rsm_resolution is 1 (valid 2..8192)"},
        {1, 16384, 64, "settings: rsm_resolution is 16384 (valid 2..8192)"},
        {1, 256, 65537, "settings: vsgl_count is 65537 (valid 1..65536)"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        vsgl_render_settings b = s;
        b.aa_samples = bad[i].aa;
        b.rsm_resolution = bad[i].rsm;
        b.vsgl_count = bad[i].vsgls;
        r = vsgl_render_estimate(ctx, scene, &b, 22, &e);
        VT_CHECK(r == VSGL_ERROR_INVALID_ARGUMENT && strcmp(vsgl_context_last_error(ctx), bad[i].want) == 0,
                 "case %zu: %d '%s'", i, r, vsgl_context_last_error(ctx));
    }
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
    /* a generous limit: the same render runs, and its estimate says OK */
    cd.max_memory = 0;
    VT_CHECK(vsgl_context_create(&cd, &ctx) == VSGL_OK, "context");
    VT_CHECK(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
    VT_CHECK(vsgl_render_estimate(ctx, scene, &s, 22, &e) == VSGL_OK && e.limit > e.total, "limit %llu '%s'",
             (unsigned long long)e.limit, vsgl_context_last_error(ctx));
    VT_CHECK(vsgl_render(ctx, scene, &s, &o, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* Issue 10: a scene without lights renders black and says why. */
VT_TEST(render_without_lights_warns_that_it_is_black)
{
    static planes p;
    fx_scene fx;
    fx_room(&fx, W, H, 0.3f, 100.0f);
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 0)
            fx.light_count = 0;
        else {
            fx.light_count = 1;
            fx.lights[0].power = 0.0f;
        }
        warn_log w;
        memset(&w, 0, sizeof w);
        vsgl_context_desc cd;
        memset(&cd, 0, sizeof cd);
        cd.log = log_warnings;
        cd.log_user = &w;
        vsgl_context *ctx = NULL;
        vsgl_scene *scene = NULL;
        vsgl_context_create(&cd, &ctx);
        VT_CHECK(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene: %s", vsgl_context_last_error(ctx));
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
        vsgl_render_output o = bind(&p);
        VT_CHECK(vsgl_render(ctx, scene, &s, &o, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        const char *want = pass == 0 ? "render: the scene has no lights: the indirect light is black"
                                     : "render: none of the 1 lights lights anything (all skipped): the indirect light is black";
        VT_CHECK(w.warnings == 1 && strcmp(w.first, want) == 0, "pass %d: %d warnings, first '%s'", pass, w.warnings,
                 w.first);
        vsgl_scene_destroy(scene);
        vsgl_context_destroy(ctx);
    }
}

typedef struct progress_log { float last; int backwards, calls; } progress_log;
static int32_t log_progress(void *user, const char *stage, float f)
{
    progress_log *p = user;
    (void)stage;
    p->backwards += f < p->last;
    p->last = f;
    p->calls++;
    return 0;
}

VT_TEST(render_progress_is_overall_and_monotone)
{
    static planes p;
    fx_scene fx;
    fx_room(&fx, W, H, 0.3f, 100.0f);
    fx.lights[1] = fx.lights[0];
    fx.light_count = 2;
    for (int method = 0; method < 2; ++method) {
        progress_log log = {-1.0f, 0, 0};
        vsgl_context_desc d;
        memset(&d, 0, sizeof d);
        d.size = sizeof d;
        d.progress = log_progress;
        d.progress_user = &log;
        vsgl_context *ctx;
        vsgl_scene *scene;
        vsgl_context_create(&d, &ctx);
        VT_CHECK(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
        s.method = method;
        s.rsm_resolution = 32;
        vsgl_render_output o = bind(&p);
        VT_CHECK(vsgl_render(ctx, scene, &s, &o, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        VT_CHECK(log.calls >= 10 && log.backwards == 0 && log.last == 1.0f,
                 "method %d: %d reports, %d went backwards, last %g", method, log.calls, log.backwards, log.last);
        vsgl_scene_destroy(scene);
        vsgl_context_destroy(ctx);
    }
}

/* Sample merging shades about one sample per pixel away from edges and
 * changes the image by little (compared with shading every sample). */
VT_TEST(render_sample_merging_cuts_pairs_at_small_error)
{
    static planes on, off;
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    s.shade_stride = 1; /* every pixel shaded, no visibility rays: the model alone */
    s.visibility = VSGL_VISIBILITY_NONE;
    s.aa_samples = 3;
    s.rsm_resolution = 32;
    s.vsgl_count = 32;
    vsgl_render_stats st_on = {.size = sizeof st_on}, st_off = {.size = sizeof st_off};
    char err[256] = "";
    VT_CHECK(render_room(0, &s, &on, &st_on, err, sizeof err) == VSGL_OK, "%s", err);
    s.sample_merging = VSGL_MERGE_OFF;
    VT_CHECK(render_room(0, &s, &off, &st_off, err, sizeof err) == VSGL_OK, "%s", err);
    double rel_rmse = rel_rms(on.comb, off.comb, (size_t)W * H * 3);
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    merging: %llu pairs vs %llu, relative RMSE %.3g\n", (unsigned long long)st_on.shading_pairs,
               (unsigned long long)st_off.shading_pairs, rel_rmse);
    VT_CHECK(st_on.shading_pairs * 3 < st_off.shading_pairs, "pairs %llu merged vs %llu",
             (unsigned long long)st_on.shading_pairs, (unsigned long long)st_off.shading_pairs);
    VT_CHECK(rel_rmse < 0.025, "relative RMSE of the combined plane %.3g", rel_rmse);
    int same_colour = 1;
    for (int i = 0; i < W * H * 3; ++i)
        same_colour &= fabsf(on.dc[i] - off.dc[i]) <= 1e-6f * (1.0f + off.dc[i]);
    VT_CHECK(same_colour, "DiffCol must not change (every sample weights with its own colour)");
}

/* The combined plane of the room at w x h with settings s and `threads`. */
static float *render_room_rough(uint32_t w, uint32_t h, uint32_t threads, const vsgl_render_settings *s,
                                vsgl_render_stats *st, float **dc, float floor_roughness)
{
    fx_scene fx;
    fx_room(&fx, w, h, floor_roughness, 200.0f);
    vsgl_context *ctx = fx_context(threads);
    vsgl_scene *scene = NULL;
    float *comb = calloc((size_t)w * h * 3, sizeof *comb), *col = calloc((size_t)w * h * 3, sizeof *col);
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = w;
    o.height = h;
    o.combined = comb;
    o.diffuse_color = col;
    int ok = ctx && vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK &&
             vsgl_render(ctx, scene, s, &o, st) == VSGL_OK;
    VT_CHECK(ok, "render %ux%u: %s", w, h, ctx ? vsgl_context_last_error(ctx) : "no context");
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
    *dc = col;
    return comb;
}

static float *render_room_size(uint32_t w, uint32_t h, uint32_t threads, const vsgl_render_settings *s,
                               vsgl_render_stats *st, float **dc)
{
    return render_room_rough(w, h, threads, s, st, dc, 0.25f);
}

/* Shading one pixel in S x S (shade_stride): the shading pairs fall by
 * several times (not S^2: where the anchors' light disagrees by more than
 * sparse.c's contrast bound, samples are shaded themselves), the light stays
 * close to every pixel shaded (at 240 x 180, a room of coloured walls and a
 * glossy floor under a spot), the colours are the same, and the result does
 * not depend on the thread count. tests/quality/check.py measures the
 * contrast bound's gain on a glossy floor's reflection. */
VT_TEST(render_shade_stride_cuts_pairs_at_small_error)
{
    enum { SW = 240, SH = 180 };
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    s.shade_stride = 1; /* every pixel shaded, no visibility rays: the model alone */
    s.visibility = VSGL_VISIBILITY_NONE;
    s.rsm_resolution = 64;
    s.aa_samples = 1;
    vsgl_render_stats st_full = {.size = sizeof st_full}, st_sparse = {.size = sizeof st_sparse};
    float *dc_full, *dc_sparse, *dc1;
    float *full = render_room_size(SW, SH, 0, &s, &st_full, &dc_full);
    const uint32_t strides[2] = {2, 4};
    const double tol[2] = {0.035, 0.07}, cut[2] = {2.5, 4.0};
    for (int k = 0; k < 2; ++k) {
        s.shade_stride = strides[k];
        float *sparse = render_room_size(SW, SH, 0, &s, &st_sparse, &dc_sparse);
        double rel = rel_rms(sparse, full, (size_t)SW * SH * 3);
        if (getenv("VSGL_TEST_VERBOSE"))
            printf("    stride %u: %llu pairs vs %llu, relative RMSE %.3g\n", strides[k],
                   (unsigned long long)st_sparse.shading_pairs, (unsigned long long)st_full.shading_pairs, rel);
        VT_CHECK(rel < tol[k], "stride %u: relative RMSE of the combined plane %.3g", strides[k], rel);
        VT_CHECK((double)st_sparse.shading_pairs * cut[k] < (double)st_full.shading_pairs,
                 "stride %u: pairs %llu vs %llu", strides[k], (unsigned long long)st_sparse.shading_pairs,
                 (unsigned long long)st_full.shading_pairs);
        VT_CHECK(memcmp(dc_sparse, dc_full, sizeof(float) * SW * SH * 3) == 0, "stride %u: DiffCol changed",
                 strides[k]);
        float *one = render_room_size(SW, SH, 1, &s, NULL, &dc1);
        VT_CHECK(memcmp(sparse, one, sizeof(float) * SW * SH * 3) == 0, "stride %u: 1 thread differs", strides[k]);
        free(sparse);
        free(dc_sparse);
        free(one);
        free(dc1);
    }
    free(full);
    free(dc_full);
}

/* The balanced preset without visibility rays, on RSM 64: the stride tests' model. */
static void balanced_without_rays(vsgl_render_settings *s)
{
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, s);
    s->visibility = VSGL_VISIBILITY_NONE;
    s->rsm_resolution = 64;
}

/* The diffuse light of the fixture room seen from eye towards at (lens in
 * mm) at w x h with settings s: dl[0] every pixel shaded, dl[1] one in 4 x
 * 4 (the caller frees both). */
static void room_at_strides_1_and_4(uint32_t w, uint32_t h, const vsgl_render_settings *s, const float eye[3],
                                    const float at[3], float lens, float *dl[2])
{
    static fx_scene fx;
    fx_room(&fx, w, h, 0.25f, 200.0f);
    fx_camera(&fx, eye, at, lens, w, h);
    vsgl_context *ctx = fx_context(0);
    vsgl_scene *scene = NULL;
    VT_REQUIRE(ctx && vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene: %s",
               ctx ? vsgl_context_last_error(ctx) : "no context");
    for (int k = 0; k < 2; ++k) {
        vsgl_render_settings t = *s;
        t.shade_stride = k ? 4 : 1;
        dl[k] = calloc((size_t)w * h * 3, sizeof(float));
        VT_REQUIRE(dl[k] && render_light(ctx, scene, &t, w, h, dl[k], NULL) == VSGL_OK, "render: %s",
                   vsgl_context_last_error(ctx));
    }
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* The anchors sit at S c and on the last pixel (sparse.c): where the
 * image's side minus one is not a multiple of S, the last cell is narrower
 * than S, and its samples must be weighted across its own width (weighted
 * as if it were S wide, the last column's samples took half their light
 * from the anchor a pixel before it); and with more than one sample per
 * pixel, the last pixel's later samples lie past the last anchor (shaded
 * at the pixel's first), where interpolation would extrapolate: they are
 * shaded themselves. The fixture room seen from inside (every pixel on a
 * wall) at stride 4 without visibility rays: 242 x 182 and 244 x 184 at
 * 1 x 1 samples (the last cells 1 and 3 pixels wide), 243 x 183 at 3 x 3
 * (2 pixels). The relative RMS difference of the diffuse light from every
 * pixel shaded, in the last cells against the two rings of full cells
 * before them (0.0023-0.0024): weighted as if S wide 0.0054 / 0.0047 /
 * 0.0076, by their width 0.0009 / 0.0024 / 0.0035, with the samples past
 * the anchor shaded 0.0012 at 3 x 3 (since the cells beside a junction are
 * tested, sparse.h: 0.0009 / 0.0014 / 0.0011 against 0.0019-0.0021). Asks
 * < 1.5x the cells before. */
VT_TEST(render_shade_stride_weights_the_last_cell_by_its_width)
{
    vsgl_render_settings s;
    balanced_without_rays(&s);
    const uint32_t sizes[3][3] = {{242, 182, 1}, {244, 184, 1}, {243, 183, 3}}; /* width, height, aa */
    for (int z = 0; z < 3; ++z) {
        const uint32_t SW = sizes[z][0], SH = sizes[z][1];
        s.aa_samples = sizes[z][2];
        const float eye[3] = {0.0f, -0.95f, 1.0f}, at[3] = {0.0f, 1.0f, 0.7f};
        float *dl[2];
        room_at_strides_1_and_4(SW, SH, &s, eye, at, 20.0f, dl);
        /* the columns and rows past the last anchor at a multiple of 4, in
         * the narrow last cells, against those of the full cells before */
        const uint32_t lx = (SW - 1) / 4 * 4, ly = (SH - 1) / 4 * 4;
        double e[2] = {0, 0}, r[2] = {0, 0};
        for (uint32_t y = 0; y < SH; ++y)
            for (uint32_t x = 0; x < SW; ++x) {
                const int q = x > lx || y > ly ? 0 : (x + 8 > lx || y + 8 > ly ? 1 : -1);
                for (int c = 0; c < 3 && q >= 0; ++c) {
                    const size_t i = ((size_t)y * SW + x) * 3 + (size_t)c;
                    const double d = (double)dl[1][i] - dl[0][i];
                    e[q] += d * d;
                    r[q] += (double)dl[0][i] * dl[0][i];
                }
            }
        const double eb = r[0] > 0.0 ? sqrt(e[0] / r[0]) : 1.0, ec = r[1] > 0.0 ? sqrt(e[1] / r[1]) : 1.0;
        printf("    %u x %u, aa %u, stride 4: relative RMS difference from every pixel shaded %.4f in the last cells, "
               "%.4f in the two rings of cells before\n", SW, SH, s.aa_samples, eb, ec);
        VT_CHECK(r[0] > 0.0 && r[1] > 0.0, "%u x %u: no light on the border", SW, SH);
        VT_CHECK(eb < 1.5 * ec, "%u x %u: the last cells' %.4f against the cells before %.4f", SW, SH, eb, ec);
        free(dl[0]);
        free(dl[1]);
    }
}

/* The longest run of pixels along a row or column of a w x h plane pair
 * (a: sparse, b: every pixel shaded) whose summed light differs by more
 * than rel of b's, among pixels brighter than 5 % of b's mean: a seam. */
static int longest_seam(const float *a, const float *b, uint32_t w, uint32_t h, double rel)
{
    double mean = 0.0;
    for (size_t i = 0; i < (size_t)w * h * 3; ++i)
        mean += b[i];
    mean /= (double)w * h;
    int best = 0;
    for (int axis = 0; axis < 2; ++axis) {
        const uint32_t n0 = axis ? w : h, n1 = axis ? h : w;
        for (uint32_t u = 0; u < n0; ++u) {
            int run = 0;
            for (uint32_t v = 0; v < n1; ++v) {
                const size_t i = axis ? (size_t)v * w + u : (size_t)u * w + v;
                const double sa = (double)a[3 * i] + a[3 * i + 1] + a[3 * i + 2],
                             sb = (double)b[3 * i] + b[3 * i + 1] + b[3 * i + 2];
                run = sb > 0.05 * mean && fabs(sa - sb) > rel * sb ? run + 1 : 0;
                best = run > best ? run : best;
            }
        }
    }
    return best;
}

/* Beside a junction (a wall's foot, a room's corner) the light bends
 * within one anchor cell, and no second difference through the anchors on
 * the surface sees it: where an anchor's neighbour along an axis lies on
 * another surface that touches its own, the anchor's second difference
 * there is taken as SPARSE_JUNCTION_SLOPE x the step of its light from its
 * neighbour on its own surface (sparse.c). Interpolated as before, the row
 * of a ceiling next to the red-wall room's back wall was 3-12 % darker than
 * every pixel shaded (80 x 60, stride 2: a dark seam along the junction).
 * The fixture room from inside at 160 x 120 (its spot-lit corner and the
 * floor's and ceiling's junctions in view), stride 4, no visibility rays,
 * against every pixel shaded: relative RMS difference of the diffuse light
 * 0.0102 before, 0.0053 now; the longest run of pixels along a row or
 * column off by more than 2 % (a seam) 14 before, 5 now. Asks < 0.0075 and
 * < 8. */
VT_TEST(render_shade_stride_leaves_no_seam_beside_a_junction)
{
    enum { SW = 160, SH = 120 };
    vsgl_render_settings s;
    balanced_without_rays(&s);
    s.aa_samples = 1;
    const float eye[3] = {0.5f, -0.8f, 1.5f}, at[3] = {-1.0f, 0.3f, 0.3f};
    float *dl[2];
    room_at_strides_1_and_4(SW, SH, &s, eye, at, 14.0f, dl);
    const int seam = longest_seam(dl[1], dl[0], SW, SH, 0.02);
    const double rms = rel_rms(dl[1], dl[0], (size_t)SW * SH * 3);
    printf("    stride 4 against every pixel shaded: relative RMS difference %.4f, the longest run of pixels off by "
           "more than 2 %%: %d\n", rms, seam);
    VT_CHECK(rms < 0.0075, "relative RMS difference %.4f", rms);
    VT_CHECK(seam < 8, "a seam of %d pixels", seam);
    free(dl[0]);
    free(dl[1]);
}

/* At shade_stride 2 every pixel that edge refinement rewrote is shaded
 * itself, as at stride 1: its slots stand for groups of rays anywhere in
 * the pixel, which no anchor cell describes. Interpolated at its slots'
 * grid positions, an edge pixel took its light from the anchors in some
 * frames and its own in others, and the corridor's end-wall edges jumped
 * as the camera moved (docs/accuracy.md, "Edges that move in steps"). */
VT_TEST(render_shade_stride_shades_edge_pixels_themselves)
{
    enum { SW = 160, SH = 120 };
    vsgl_render_settings s;
    balanced_without_rays(&s);
    float *dc[2], *img[2];
    for (int k = 0; k < 2; ++k) {
        s.shade_stride = k ? 2 : 1;
        img[k] = render_room_rough(SW, SH, 0, &s, NULL, &dc[k], 0.25f);
    }
    fx_scene fx;
    fx_room(&fx, SW, SH, 0.25f, 200.0f);
    vsgl_context *ctx = fx_context(0);
    vsgl_scene *scene = NULL;
    vsgl_gbuffer g;
    memset(&g, 0, sizeof g);
    VT_REQUIRE(ctx && vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK &&
                   vsgl__gbuffer_build(ctx, scene, s.aa_samples, s.edge_samples, &g) == VSGL_OK,
               "G-buffer: %s", ctx ? vsgl_context_last_error(ctx) : "no context");
    size_t refined = 0, differ = 0;
    double worst = 0.0;
    for (size_t px = 0; px < (size_t)SW * SH; ++px) {
        if (!vsgl__gbuffer_refined(&g, px))
            continue;
        ++refined;
        for (int c = 0; c < 3; ++c) {
            const double a = img[1][px * 3 + c], b = img[0][px * 3 + c], e = fabs(a - b) / (1e-3 + fabs(b));
            worst = e > worst ? e : worst;
            differ += e > 1e-4; /* (float rounding: the blocks differ) */
        }
    }
    printf("    %zu refined pixels: %zu channels differ from every pixel shaded, by %.2g (relative) at worst\n",
           refined, differ, worst);
    VT_CHECK(refined >= 100, "%zu refined pixels: the room has no edges", refined);
    VT_CHECK(differ == 0, "%zu channels of refined pixels interpolated (worst %.3g)", differ, worst);
    vsgl__gbuffer_free(&g);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
    for (int k = 0; k < 2; ++k) {
        free(img[k]);
        free(dc[k]);
    }
}

/* A mirror floor (roughness 0, GGX alpha 5e-10) still shares its light
 * between pixels at shade_stride 2: sparse.c takes two normals of a sharp
 * glossy material for one surface only within half its alpha, but never
 * within less than SPARSE_GLOSSY_MIN_TURN; at the alpha itself not even
 * the floor's own normals were one surface, and every pixel was shaded. */
VT_TEST(render_shade_stride_interpolates_a_mirror_floor)
{
    enum { SW = 120, SH = 90 };
    vsgl_render_settings s;
    balanced_without_rays(&s);
    s.aa_samples = 1;
    s.edge_samples = 0;
    vsgl_render_stats st[2] = {{.size = sizeof st[0]}, {.size = sizeof st[1]}};
    float *dc[2], *img[2];
    for (int k = 0; k < 2; ++k) {
        s.shade_stride = k ? 2 : 1;
        img[k] = render_room_rough(SW, SH, 0, &s, &st[k], &dc[k], 0.0f);
    }
    VT_CHECK((double)st[1].shading_pairs * 2.0 < (double)st[0].shading_pairs, "stride 2: pairs %llu vs %llu",
             (unsigned long long)st[1].shading_pairs, (unsigned long long)st[0].shading_pairs);
    for (int k = 0; k < 2; ++k) {
        free(img[k]);
        free(dc[k]);
    }
}

/* The same room at very different scales and far from the origin: every
 * plane finite and non-negative, and the light (a scale-free quantity once
 * the power is scaled with the area) about the same. */
VT_TEST(render_survives_extreme_scales_and_offsets)
{
    static planes ref, p;
    const float scales[4] = {1.0f, 1e-3f, 1e3f, 1.0f};
    const float offsets[4] = {0.0f, 0.0f, 0.0f, 1e5f};
    double ref_mean = 0;
    for (int k = 0; k < 4; ++k) {
        fx_scene fx;
        fx_room(&fx, W, H, 0.3f, 150.0f * scales[k] * scales[k]); /* same irradiance */
        for (uint32_t v = 0; v < fx.vertex_count * 3; ++v)
            fx.positions[v] = fx.positions[v] * scales[k] + offsets[k];
        for (int r = 0; r < 3; ++r) {
            fx.lights[0].world_from_light[r * 4 + 3] = fx.lights[0].world_from_light[r * 4 + 3] * scales[k] + offsets[k];
            fx.camera.world_from_camera[r * 4 + 3] = fx.camera.world_from_camera[r * 4 + 3] * scales[k] + offsets[k];
        }
        fx.camera.clip_start *= scales[k];
        fx.camera.clip_end *= scales[k];
        vsgl_context *ctx;
        vsgl_scene *scene;
        vsgl_context_create(NULL, &ctx);
        VT_CHECK(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scale %g: %s", scales[k], vsgl_context_last_error(ctx));
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_QUALITY, &s);
        s.rsm_resolution = 32;
        s.vsgl_count = 32;
        planes *out = k == 0 ? &ref : &p;
        vsgl_render_output o = bind(out);
        VT_CHECK(vsgl_render(ctx, scene, &s, &o, NULL) == VSGL_OK, "scale %g offset %g: %s", scales[k], offsets[k],
                 vsgl_context_last_error(ctx));
        int bad = 0;
        double mean = 0;
        for (int i = 0; i < W * H * 3; ++i) {
            bad += !(isfinite(out->comb[i]) && out->comb[i] >= 0.0f);
            mean += out->comb[i];
        }
        mean /= W * H * 3;
        VT_CHECK(bad == 0, "scale %g offset %g: %d bad values", scales[k], offsets[k], bad);
        if (k == 0)
            ref_mean = mean;
        else
            VT_CHECK(fabs(mean - ref_mean) <= (offsets[k] > 0 ? 0.05 : 0.02) * ref_mean,
                     "scale %g offset %g: mean %.5g vs %.5g at scale 1", scales[k], offsets[k], mean, ref_mean);
        vsgl_scene_destroy(scene);
        vsgl_context_destroy(ctx);
    }
}

/* Blender 4.x+ materials (VSGL_MATERIAL_FLAG_BLENDER_4): DiffCol is the
 * base colour times 1 - the dielectric layer's albedo seen from the
 * camera (Cycles 5.0.1 measured 0.7578 for base 0.8 at a 45 degree view,
 * roughness 0.5; the weight itself is tested in test_material.c). The
 * glossy floor, seen at 60-80 degrees from its normal here, is dimmed by
 * 15-25 %, identically for the VSGL kernel, the reference shading path and
 * the brute force; the walls (no specular layer) keep their colour. */
VT_TEST(render_blender4_diffuse_colour_dimmed_by_specular_layer)
{
    static planes p3, p4;
    static double first[W * H];
    double light_ratio[3] = {0, 0, 0};
    char err[256] = "";
    const int methods[3] = {0, 1, 2}; /* kernel, reference shading path, brute force */
    for (int mi = 0; mi < 3; ++mi) {
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
        s.rsm_resolution = 32;
        s.aa_samples = 1; /* one surface per pixel: a floor pixel is one whose DiffCol is the floor's */
        s.edge_samples = 0;
        if (methods[mi] == 1)
            s.glossy_mode = VSGL_GLOSSY_SG; /* shades through the reference path */
        if (methods[mi] == 2)
            s.method = VSGL_METHOD_BRUTE_FORCE;
        VT_CHECK(render_room_flags(1, &s, &p3, NULL, err, sizeof err, 0) == VSGL_OK, "%s", err);
        VT_CHECK(render_room_flags(1, &s, &p4, NULL, err, sizeof err, VSGL_MATERIAL_FLAG_BLENDER_4) == VSGL_OK, "%s", err);
        int floor_px = 0, wall_px = 0;
        double lo = 1.0, hi = 0.0, l3 = 0.0, l4 = 0.0;
        for (int i = 0; i < W * H; ++i) {
            double a = p3.dc[3 * i], b = p4.dc[3 * i];
            if (!(a > 0.0) || p3.alpha[i] < 1.0f)
                continue;
            double ratio = b / a;
            if (p3.dc[3 * i] == 0.5f) { /* the floor: grey 0.5 with a specular layer */
                ++floor_px;
                if (mi == 0)
                    first[i] = ratio;
                VT_CHECK(fabs(ratio - first[i]) < 1e-6, "method %d pixel %d: ratio %g, kernel path %g", mi, i, ratio, first[i]);
                lo = fmin(lo, ratio);
                hi = fmax(hi, ratio);
            } else {
                ++wall_px;
                VT_CHECK(ratio == 1.0, "method %d pixel %d: a wall's colour changed (%g)", mi, i, ratio);
                l3 += p3.dl[3 * i];
                l4 += p4.dl[3 * i];
            }
        }
        VT_CHECK(floor_px > 50 && wall_px > 50, "method %d: %d floor and %d wall pixels", mi, floor_px, wall_px);
        VT_CHECK(lo > 0.70 && hi < 0.95 && hi - lo > 0.03, "method %d: floor DiffCol ratio in [%g, %g]", mi, lo, hi);
        light_ratio[mi] = l4 / l3;
    }
    /* the floor's VPLs reflect less diffuse light onto the walls: the VSGL
     * fit (power times the dimming's mean) and the brute force (dimmed per
     * direction) agree on how much */
    VT_CHECK(light_ratio[2] < 0.99 && light_ratio[2] > 0.8, "brute force: wall light ratio %g", light_ratio[2]);
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    wall light ratio (4.x / 3.x materials): VSGL %.4f, SG-glossy path %.4f, brute force %.4f\n", light_ratio[0],
               light_ratio[1], light_ratio[2]);
    VT_CHECK(fabs(light_ratio[0] - light_ratio[2]) < 0.01, "wall light ratio: VSGL %g, brute force %g",
             light_ratio[0], light_ratio[2]);
}

/* The room of fx_room with an upright smooth-shaded cylinder (radius r,
 * 1.2 m tall, `segments` facets, centre (cx, cy)) of the floor's glossy
 * material standing on the floor; corner normals in cn (triangle_count x
 * 9 floats, the room's quads their face normals). */
#define RIM_SEGMENTS 24
static void fx_room_cylinder(fx_scene *fx, float *cn, uint32_t w, uint32_t h, float cx, float cy, float r)
{
    fx_room(fx, w, h, 0.25f, 200.0f);
    const uint32_t room_tris = fx->triangle_count;
    for (int k = 0; k < RIM_SEGMENTS; ++k) {
        const float a0 = 6.2831853f * (float)k / RIM_SEGMENTS, a1 = 6.2831853f * (float)(k + 1) / RIM_SEGMENTS;
        const float q[4][3] = {{cx + r * cosf(a0), cy + r * sinf(a0), 0.0f},
                               {cx + r * cosf(a1), cy + r * sinf(a1), 0.0f},
                               {cx + r * cosf(a1), cy + r * sinf(a1), 1.2f},
                               {cx + r * cosf(a0), cy + r * sinf(a0), 1.2f}};
        fx_quad(fx, q, 0);
    }
    for (uint32_t t = 0; t < fx->triangle_count; ++t)
        for (int c = 0; c < 3; ++c) {
            const float *p = fx->positions + 3 * fx->indices[3 * t + (uint32_t)c];
            float *n = cn + 9 * t + 3 * c;
            if (t >= room_tris) { /* radial: the smooth cylinder */
                const float dx = p[0] - cx, dy = p[1] - cy, l = sqrtf(dx * dx + dy * dy);
                n[0] = dx / l;
                n[1] = dy / l;
                n[2] = 0.0f;
            } else { /* the quad's face normal */
                const uint32_t *ix = fx->indices + 3 * t;
                const float *a = fx->positions + 3 * ix[0], *b = fx->positions + 3 * ix[1], *d = fx->positions + 3 * ix[2];
                const float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
                const float v[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
                float f[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
                const float l = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
                for (int i = 0; i < 3; ++i)
                    n[i] = f[i] / l;
            }
        }
}

/* Scene of fx (its corner normals cn) in ctx; NULL (and a failed check) if
 * it cannot be made. */
static vsgl_scene *scene_with_normals(vsgl_context *ctx, fx_scene *fx, const float *cn)
{
    vsgl_scene *scene = NULL;
    fx_desc(fx);
    fx->desc.corner_normals = cn;
    VT_CHECK(ctx && vsgl_scene_create(ctx, &fx->desc, &scene) == VSGL_OK, "scene: %s",
             ctx ? vsgl_context_last_error(ctx) : "no context");
    return scene;
}


/* An edge pixel on a curved surface's silhouette is shaded at more than
 * one point when it has slots to spare (edges.c split_curved): across a
 * glossy cylinder's rim the normal turns by tens of degrees within a
 * pixel, and one point with the mean normal (its lobe widened by the
 * spread) is not the mean of the light across the pixel. Against the
 * same room shaded with 16 x 16 samples in every pixel (no edge rays), the
 * rim pixels' glossy light at 2 x 2 samples with 16 x 16 edge rays (no
 * visibility rays, RSM 64): one point per surface was off by 13.8 % of the
 * rim's light (summed |error| / summed light), the split 5.9 %; the rim's
 * inside (pixels not refined, 2 x 2 samples) 1.1 %. */
VT_TEST(render_edge_pixels_shade_a_curved_rim_at_several_points)
{
    enum { SW = 80, SH = 60 };
    static fx_scene fx;
    static float cn[FX_MAX_TRIS * 9];
    fx_room_cylinder(&fx, cn, SW, SH, 0.15f, 0.1f, 0.22f);
    vsgl_render_settings s;
    balanced_without_rays(&s);
    s.shade_stride = 1;
    vsgl_context *ctx = fx_context(0);
    vsgl_scene *scene = scene_with_normals(ctx, &fx, cn);
    VT_REQUIRE(scene != NULL, "no scene");
    float *gl[2];
    for (int k = 0; k < 2; ++k) {
        vsgl_render_settings t = s;
        if (k) { /* the truth: 16 x 16 samples shaded in every pixel */
            t.aa_samples = 16;
            t.edge_samples = 0;
            t.aa_pixel_limit = 0;
        }
        gl[k] = calloc((size_t)SW * SH * 3, sizeof(float));
        VT_REQUIRE(render_light(ctx, scene, &t, SW, SH, NULL, gl[k]) == VSGL_OK, "render %d: %s", k,
                   vsgl_context_last_error(ctx));
    }
    /* the rim: refined pixels with a slot on the cylinder (horizontal normal, material 0) */
    vsgl_gbuffer g;
    memset(&g, 0, sizeof g);
    VT_REQUIRE(vsgl__gbuffer_build(ctx, scene, s.aa_samples, s.edge_samples, &g) == VSGL_OK, "G-buffer: %s",
               vsgl_context_last_error(ctx));
    size_t rim = 0, split = 0;
    double err = 0.0, sum = 0.0;
    for (size_t px = 0; px < (size_t)SW * SH; ++px) {
        if (!vsgl__gbuffer_refined(&g, px))
            continue;
        int on = 0;
        for (size_t q = px * g.spp; q < (px + 1) * g.spp; ++q)
            on += g.weight[q] > 0.0f && g.material[q] == 0 && fabsf(g.nrm[2][q]) < 0.1f;
        if (!on)
            continue;
        ++rim;
        split += on > 1;
        for (int c = 0; c < 3; ++c) {
            err += fabs((double)gl[0][px * 3 + c] - gl[1][px * 3 + c]);
            sum += gl[1][px * 3 + c];
        }
    }
    printf("    %zu rim pixels (%zu shaded at more than one point on the cylinder): glossy light off the 16 x 16 "
           "samples' by %.2f %% of it\n", rim, split, 100.0 * err / sum);
    VT_CHECK(rim >= 40, "%zu rim pixels: the test cannot tell", rim);
    VT_CHECK(split * 2 >= rim, "only %zu of %zu rim pixels shade the cylinder at more than one point", split, rim);
    VT_CHECK(err <= 0.09 * sum, "the rim's glossy light is off by %.2f %% (one point per surface: 13.8 %%)",
             100.0 * err / sum);
    vsgl__gbuffer_free(&g);
    free(gl[0]);
    free(gl[1]);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* Sample merging shades a pixel's samples on one surface at their
 * centroid. On a smooth-shaded convex mesh the centroid of points on two
 * facets lies inside the mesh, below both; visibility rays from there hit
 * the mesh itself. The bundled rough_room's metal sphere (roughness 0.7,
 * which merges) had 0.64 of its glossy light at shade_stride 1 (80 x 60,
 * balanced, against merging off; the sparse path of stride 2 and more does
 * not merge). Here a smooth white cylinder of 24 facets (diffuse: it
 * merges) in the fixture room, 2 x 2 samples, every pixel shaded: its
 * diffuse light merged over every sample shaded, with visibility rays and
 * without. With rays from the centroid it was 0.9430 (1.0126 without
 * rays: the group took its first sample's normal, off to one side); from
 * the group's first sample 1.0139; with the group's mean normal too,
 * 1.0003 with and without. */
VT_TEST(render_merged_samples_see_past_their_own_mesh)
{
    enum { SW = 80, SH = 60 };
    static fx_scene fx;
    static float cn[FX_MAX_TRIS * 9];
    fx_room_cylinder(&fx, cn, SW, SH, 0.1f, 0.2f, 0.4f);
    for (uint32_t t = 10; t < fx.triangle_count; ++t) /* the cylinder (after the room's 5 quads) */
        fx.material_indices[t] = 3;
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    s.rsm_resolution = 64;
    s.shade_stride = 1;
    vsgl_context *ctx = fx_context(0);
    vsgl_scene *scene = scene_with_normals(ctx, &fx, cn);
    VT_REQUIRE(scene != NULL, "no scene");
    vsgl_gbuffer g;
    memset(&g, 0, sizeof g);
    VT_REQUIRE(vsgl__gbuffer_build(ctx, scene, s.aa_samples, 0, &g) == VSGL_OK, "G-buffer: %s",
               vsgl_context_last_error(ctx));
    float *dl = calloc((size_t)SW * SH * 3, sizeof(float));
    double ratio[2] = {0.0, 0.0}; /* merged / every sample, with rays and without */
    size_t on = 0;
    for (int r = 0; r < 2; ++r) {
        double sum[2] = {0.0, 0.0};
        for (int k = 0; k < 2; ++k) {
            vsgl_render_settings t = s;
            t.visibility = r ? VSGL_VISIBILITY_NONE : VSGL_VISIBILITY_RAY;
            t.sample_merging = k ? VSGL_MERGE_OFF : VSGL_MERGE_AUTO;
            VT_REQUIRE(render_light(ctx, scene, &t, SW, SH, dl, NULL) == VSGL_OK, "render: %s",
                       vsgl_context_last_error(ctx));
            on = 0;
            for (size_t px = 0; px < (size_t)SW * SH; ++px) { /* pixels whose samples all lie on the cylinder */
                int all = 1;
                for (size_t q = px * g.spp; q < (px + 1) * g.spp; ++q)
                    all &= g.material[q] == 3 && fabsf(g.nrm[2][q]) < 0.1f;
                on += all;
                for (int c = 0; c < 3 && all; ++c)
                    sum[k] += dl[px * 3 + c];
            }
        }
        ratio[r] = sum[1] > 0.0 ? sum[0] / sum[1] : 0.0;
    }
    printf("    %zu pixels on the cylinder: diffuse light merged / every sample shaded %.4f with visibility rays, "
           "%.4f without\n", on, ratio[0], ratio[1]);
    VT_CHECK(on >= 200, "%zu pixels on the cylinder: the test cannot tell", on);
    VT_CHECK(fabs(ratio[1] - 1.0) < 0.005, "merging alone changes the light by %.4f", ratio[1]);
    VT_CHECK(fabs(ratio[0] - ratio[1]) < 0.005, "merged samples' rays change their light by %.4f (%.4f / %.4f)",
             ratio[0] / ratio[1], ratio[0], ratio[1]);
    vsgl__gbuffer_free(&g);
    free(dl);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}
