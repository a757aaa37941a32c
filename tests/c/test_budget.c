/* The per-light budget (render/budget.h): the rule on its own, against
 * shares worked out by hand; a render's lights against single-light fits
 * with those shares; one light untouched; the cache keyed by the camera. */
#include "harness.h"
#include "log_capture.h"
#include "scene_fixture.h"
#include "render/budget.h"
#include "render/render_internal.h"
#include "vsgl/debug.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

VT_TEST(budget_rule_matches_shares_worked_by_hand)
{
    /* weights 9 : 1, the square root: shares 3/4 and 1/4 of the 0.75 x 2 x 64
     * left above the floors of 16: 16 + 72 = 88 and 16 + 24 = 40; texels
     * 2 x 64^2 in proportion to VSGLs: sides 64 sqrt(88/64) = 75.05, 64
     * sqrt(40/64) = 50.6 */
    vsgl_light_share l[2] = {{.weight = 9.0, .faces = 1}, {.weight = 1.0, .faces = 1}};
    vsgl__light_budget(l, 2, 64, 64);
    VT_CHECK(fabs(l[0].vsgls - 88.0) < 1e-9 && fabs(l[1].vsgls - 40.0) < 1e-9, "vsgls %g %g", l[0].vsgls, l[1].vsgls);
    VT_CHECK(l[0].vsgl_count == 88 && l[1].vsgl_count == 40, "counts %u %u", l[0].vsgl_count, l[1].vsgl_count);
    VT_CHECK(l[0].rsm_resolution == 75 && l[1].rsm_resolution == 51, "rsm %u %u", l[0].rsm_resolution,
             l[1].rsm_resolution);
    VT_CHECK(fabs(l[0].fraction - 0.75) < 1e-12, "fraction %g", l[0].fraction);

    /* one light that counts: exactly the settings; the dark one the floor */
    vsgl_light_share one[3] = {{.weight = 0.0, .faces = 6}, {.weight = 5.0, .faces = 6}, {.weight = NAN, .faces = 1}};
    vsgl__light_budget(one, 3, 192, 256);
    VT_CHECK(one[1].vsgl_count == 192 && one[1].vsgls == 192.0 && one[1].rsm_resolution == 256, "one: %u %g %u",
             one[1].vsgl_count, one[1].vsgls, one[1].rsm_resolution);
    VT_CHECK(one[0].vsgl_count == 48 && one[2].vsgl_count == 48 && one[0].rsm_resolution == 128 &&
             one[2].fraction == 0.0, "dark: %u %u %u %g", one[0].vsgl_count, one[2].vsgl_count,
             one[0].rsm_resolution, one[2].fraction);

    /* equal lights: the settings each (cube maps and single faces alike) */
    vsgl_light_share eq[2] = {{.weight = 2.0, .faces = 6}, {.weight = 2.0, .faces = 6}};
    vsgl__light_budget(eq, 2, 100, 128);
    VT_CHECK(eq[0].vsgl_count == 100 && eq[1].vsgl_count == 100 && eq[0].rsm_resolution == 128 &&
             eq[1].rsm_resolution == 128, "equal: %u %u %u %u", eq[0].vsgl_count, eq[1].vsgl_count,
             eq[0].rsm_resolution, eq[1].rsm_resolution);

    /* many lights, one far brighter: the cap (4 x 32), the rest to the
     * others, the integers summing to 10 x 32, every light >= the floor of 8,
     * every output finite */
    vsgl_light_share many[10];
    for (int i = 0; i < 10; ++i)
        many[i] = (vsgl_light_share){.weight = i == 3 ? 1e12 : 1.0 + i, .faces = i % 2 ? 6u : 1u};
    vsgl__light_budget(many, 10, 32, 100);
    uint32_t sum = 0;
    double rsum = 0.0;
    int ok = 1;
    for (int i = 0; i < 10; ++i) {
        sum += many[i].vsgl_count;
        rsum += many[i].vsgls;
        ok &= many[i].vsgl_count >= 8 && isfinite(many[i].vsgls) && many[i].rsm_resolution >= 25 &&
              many[i].rsm_resolution <= 150;
    }
    VT_CHECK(many[3].vsgl_count == 128 && sum == 320 && fabs(rsum - 320.0) < 1e-6 && ok, "cap %u sum %u %g ok %d",
             many[3].vsgl_count, sum, rsum, ok);
    VT_CHECK(vsgl__budget_rsm_max(256) == 384 && vsgl__budget_vsgl_max(192) == 768, "caps %u %u",
             vsgl__budget_rsm_max(256), vsgl__budget_vsgl_max(192));
}

enum { BW = 40, BH = 30 };

/* The fixture room with a second spot: a copy of the first at 1/9 of its
 * power (the same geometry, so the probe weighs them exactly 9 : 1 up to
 * float rounding of the flux). */
static void two_spots(fx_scene *fx)
{
    fx_room(fx, BW, BH, 0.3f, 180.0f);
    fx->lights[1] = fx->lights[0];
    fx->lights[1].power = 20.0f;
    fx->light_count = 2;
}

static size_t fit(vsgl_context *ctx, fx_scene *fx, const vsgl_render_settings *s, vsgl_debug_vsgl *out, size_t cap)
{
    vsgl_scene *scene = NULL;
    size_t n = cap;
    if (vsgl_scene_create(ctx, fx_desc(fx), &scene) != VSGL_OK || vsgl_debug_vsgls(ctx, scene, s, &n, out) != VSGL_OK)
        n = 0;
    vsgl_scene_destroy(scene);
    return n;
}

/* The VSGLs of light `light` among a[0..na) equal b[0..nb) to within tol. */
static int same_vsgls(const vsgl_debug_vsgl *a, size_t na, uint32_t light, const vsgl_debug_vsgl *b, size_t nb,
                      double tol, char *why, size_t whylen)
{
    size_t k = 0;
    for (size_t i = 0; i < na; ++i) {
        if (a[i].light != light)
            continue;
        if (k >= nb) {
            snprintf(why, whylen, "more VSGLs than %zu", nb);
            return 0;
        }
        for (int c = 0; c < 3; ++c)
            if (fabs(a[i].mean[c] - b[k].mean[c]) > tol || fabs(a[i].power[c] - b[k].power[c]) >
                tol * (fabs(b[k].power[c]) + 1e-6)) {
                snprintf(why, whylen, "VSGL %zu: mean %g vs %g, power %g vs %g", k, a[i].mean[c], b[k].mean[c],
                         a[i].power[c], b[k].power[c]);
                return 0;
            }
        ++k;
    }
    snprintf(why, whylen, "%zu of %zu", k, nb);
    return k == nb;
}

VT_TEST(budget_render_fits_each_light_with_its_share)
{
    enum { CAP = 4096 };
    vsgl_debug_vsgl *both = calloc(CAP, sizeof *both), *solo = calloc(CAP, sizeof *solo);
    vsgl_context *ctx = fx_context(2);
    VT_REQUIRE(both && solo && ctx, "alloc");
    fx_scene fx;
    two_spots(&fx);
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    s.vsgl_count = 64;
    s.rsm_resolution = 64;
    size_t nb = fit(ctx, &fx, &s, both, CAP);
    VT_REQUIRE(nb > 0, "two lights: %s", vsgl_context_last_error(ctx));

    /* light 0 alone with 88 VSGLs and RSM 75; light 1 alone with 40 and 51 */
    char why[160];
    fx_scene one;
    two_spots(&one);
    one.light_count = 1;
    vsgl_render_settings s0 = s;
    s0.vsgl_count = 88;
    s0.rsm_resolution = 75;
    size_t n0 = fit(ctx, &one, &s0, solo, CAP);
    VT_CHECK(n0 > 0 && same_vsgls(both, nb, 0, solo, n0, 1e-3, why, sizeof why), "light 0 vs 88/75 alone: %s", why);
    one.lights[0] = fx.lights[1];
    vsgl_render_settings s1 = s;
    s1.vsgl_count = 40;
    s1.rsm_resolution = 51;
    size_t n1 = fit(ctx, &one, &s1, solo, CAP);
    VT_CHECK(n1 > 0 && same_vsgls(both, nb, 1, solo, n1, 1e-3, why, sizeof why), "light 1 vs 40/51 alone: %s", why);

    /* the uniform budget would not pass: light 0 alone at the settings' 64 / 64 */
    one.lights[0] = fx.lights[0];
    size_t nu = fit(ctx, &one, &s, solo, CAP);
    VT_CHECK(nu > 0 && !same_vsgls(both, nb, 0, solo, nu, 1e-3, why, sizeof why), "uniform matched: %s", why);
    vsgl_context_destroy(ctx);
    free(both);
    free(solo);
}

typedef struct bplanes {
    float comb[BW * BH * 3], gl[BW * BH * 3];
} bplanes;

/* One render of scene at w x h into comb (and gl, if not NULL), with settings
 * s (NULL: the preview preset), through cache if not NULL. */
static vsgl_result render_planes(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                                 vsgl_render_cache *cache, uint32_t w, uint32_t h, float *comb, float *gl,
                                 vsgl_render_stats *st)
{
    vsgl_render_settings preview;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &preview);
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = w;
    o.height = h;
    o.combined = comb;
    o.glossy_light = gl;
    return vsgl_render_cached(ctx, scene, s ? s : &preview, cache, &o, st);
}

/* render_planes of a scene made from fx for this one render, at its camera's size */
static vsgl_result render_fx(vsgl_context *ctx, fx_scene *fx, const vsgl_render_settings *s,
                             vsgl_render_cache *cache, float *comb, float *gl, vsgl_render_stats *st)
{
    vsgl_scene *scene = NULL;
    vsgl_result r = vsgl_scene_create(ctx, fx_desc(fx), &scene);
    if (r == VSGL_OK)
        r = render_planes(ctx, scene, s, cache, fx->camera.width, fx->camera.height, comb, gl, st);
    vsgl_scene_destroy(scene);
    return r;
}

static vsgl_result render_view(vsgl_context *ctx, const vsgl_scene *scene, vsgl_render_cache *cache, bplanes *p,
                               vsgl_render_stats *st)
{
    return render_planes(ctx, scene, NULL, cache, BW, BH, p->comb, p->gl, st);
}

static vsgl_result render(vsgl_context *ctx, fx_scene *fx, vsgl_render_cache *cache, bplanes *p,
                          vsgl_render_stats *st)
{
    return render_fx(ctx, fx, NULL, cache, p->comb, p->gl, st);
}

VT_TEST(budget_leaves_one_light_alone_and_reports_two)
{
    static bplanes a, b;
    vsgl_context *ctx = fx_context(2);
    VT_REQUIRE(ctx, "context");
    fx_scene fx;
    fx_room(&fx, BW, BH, 0.3f, 150.0f);
    vsgl_render_stats st = {.size = sizeof st};
    VT_CHECK(render(ctx, &fx, NULL, &a, &st) == VSGL_OK && st.budget[0] == 0, "one light: budget '%s'", st.budget);
    /* a second light into the void and a third of zero power change nothing */
    fx.lights[1] = fx.lights[0];
    fx_translation(fx.lights[1].world_from_light, 0, 0, 50);
    fx.lights[1].world_from_light[10] = -1.0f;
    fx.lights[1].world_from_light[5] = -1.0f;
    fx.lights[2] = fx.lights[0];
    fx.lights[2].power = 0.0f;
    fx.light_count = 3;
    VT_CHECK(render(ctx, &fx, NULL, &b, &st) == VSGL_OK && st.budget[0] == 0, "dead lights: budget '%s'", st.budget);
    VT_CHECK(memcmp(&a, &b, sizeof a) == 0, "a light that lights nothing changed the render");

    two_spots(&fx);
    VT_CHECK(render(ctx, &fx, NULL, &a, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    unsigned v0 = 0, v1 = 0, r0 = 0, r1 = 0;
    const char *l1 = strstr(st.budget, "light 1:");
    VT_CHECK(sscanf(st.budget, "light 0: 75 %% of the light on what the camera sees: %u VSGLs, RSM %u", &v0, &r0) == 2 &&
             l1 && sscanf(l1, "light 1: 25 %% of the light on what the camera sees: %u VSGLs, RSM %u", &v1, &r1) == 2,
             "budget text: %s", st.budget);
    /* preview: 32 VSGLs, RSM 128: floors 8, then 36 and 12 */
    VT_CHECK(v0 == 44 && v1 == 20 && r0 == 150 && r1 == 101, "%u %u %u %u", v0, v1, r0, r1);
    vsgl_context_destroy(ctx);
}

VT_TEST(budget_cache_follows_the_camera)
{
    static bplanes cached, plain;
    vsgl_context *ctx = fx_context(2);
    vsgl_render_cache *cache = NULL;
    vsgl_scene *scene = NULL;
    VT_REQUIRE(ctx && vsgl_render_cache_create(ctx, &cache) == VSGL_OK, "cache");
    fx_scene fx;
    two_spots(&fx);
    fx.lights[1].power = 60.0f;
    const float at[3] = {0.5f, 0.5f, 0.3f};
    fx_look_at(fx.lights[1].world_from_light, (const float[3]){0.6f, -0.6f, 1.9f}, at);
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    vsgl_render_stats st = {.size = sizeof st};
    VT_CHECK(render_view(ctx, scene, cache, &cached, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    char before[sizeof st.budget];
    memcpy(before, st.budget, sizeof before);
    /* the camera turns to the other light's side: the budget follows it, so
     * the fit is not reused */
    const float eye[3] = {0.9f, -0.9f, 1.0f}, look[3] = {-1.0f, 0.3f, 0.6f};
    fx_look_at(fx.camera.world_from_camera, eye, look);
    VT_CHECK(vsgl_scene_set_view(ctx, scene, &fx.camera, fx.lights, fx.light_count) == VSGL_OK, "set_view");
    VT_CHECK(render_view(ctx, scene, cache, &cached, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(st.reused == 0 && strcmp(before, st.budget) != 0, "camera moved: reused %u, budget %s -> %s", st.reused,
             before, st.budget);
    VT_CHECK(render_view(ctx, scene, NULL, &plain, NULL) == VSGL_OK, "uncached");
    VT_CHECK(memcmp(&cached, &plain, sizeof cached) == 0, "camera moved: the cached render differs");
    /* nothing moved: both reused, bit-identical, the budget reported again */
    VT_CHECK(render_view(ctx, scene, cache, &cached, &st) == VSGL_OK, "again");
    VT_CHECK(st.reused == (VSGL_REUSED_GBUFFER | VSGL_REUSED_FIT) && st.budget[0], "unchanged: reused %u '%s'",
             st.reused, st.budget);
    VT_CHECK(memcmp(&cached, &plain, sizeof cached) == 0, "unchanged: the cached render differs");
    vsgl_scene_destroy(scene);
    vsgl_render_cache_destroy(cache);
    vsgl_context_destroy(ctx);
}

/* Negligible specular VSGLs (render.c, VSGL__SPECULAR_NEGLIGIBLE): every
 * specular VSGL kept has at least 1 % of its light's mean VSGL peak
 * intensity (power x max(1, sharpness / 2); the mean over what the fit
 * made, dropped ones included), the count dropped and the power they
 * carried are said, and that power is tiny. */
VT_TEST(budget_negligible_specular_vsgls_are_dropped_and_said)
{
    enum { CAP = 8192 };
    vsgl_debug_vsgl *v = calloc(CAP, sizeof *v);
    vsgl_context *ctx = fx_context(2);
    VT_REQUIRE(v && ctx, "alloc");
    fx_scene fx;
    fx_room(&fx, BW, BH, 0.3f, 150.0f);
    fx.materials[3].specular_f0 = 0.04f; /* the white walls and the ceiling glossy too: many specular VSGLs */
    fx.materials[3].roughness = 0.4f;
    vsgl_render_settings s; /* render_view's */
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
    vsgl_scene *scene = NULL;
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    size_t n = CAP;
    VT_REQUIRE(vsgl_debug_vsgls(ctx, scene, &s, &n, v) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    static bplanes p;
    vsgl_render_stats st = {.size = sizeof st};
    VT_REQUIRE(render_view(ctx, scene, NULL, &p, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    unsigned dropped = 0, spec_all = 0;
    double pct = -1.0, saved = -1.0;
    const char *line = strstr(st.skipped, "light 0: ");
    while (line && sscanf(line, "light 0: %u of its %u specular VSGLs under 1 %% of its mean VSGL peak intensity "
                          "(%lf %% of its light, with the fade of those under twice that): %lf %%", &dropped, &spec_all, &pct, &saved) != 4)
        line = strstr(line + 1, "light 0: ");
    VT_CHECK(line && dropped > 0 && pct >= 0.0 && pct < 0.1, "skipped: %s", st.skipped);
    /* peak intensity relative to a diffuse lobe's: power x max(1, sharpness / 2) */
    double peaks = 0.0, min_spec = 1e30;
    size_t spec = 0;
    for (size_t i = 0; i < n; ++i) {
        double k = 0.5 * v[i].sharpness;
        double w = ((double)v[i].power[0] + v[i].power[1] + v[i].power[2]) * (k > 1.0 ? k : 1.0);
        peaks += w;
        if (v[i].lobe == 1) {
            ++spec;
            min_spec = w < min_spec ? w : min_spec;
        }
    }
    VT_CHECK(spec + dropped == spec_all, "kept %zu + dropped %u != %u", spec, dropped, spec_all);
    /* the light's mean before the drop is at least (kept peaks) / (kept + dropped count) */
    double mean_all = peaks / (double)(n + dropped);
    /* kept: peak p >= 1 % of the mean; those under 2 % are faded to w p with w = smoothstep(p / limit
     * - 1), anywhere in (0, 2 %): only that none is kept at zero power can be checked here
     * (tests/python/test_fit_stability.py sees a pop if the fade is missing) */
    VT_CHECK(min_spec > 0.0, "a kept specular VSGL of peak %g (mean %g)", min_spec, mean_all);
    VT_CHECK(fabs(saved - 100.0 * dropped / (double)(n + dropped)) < 0.06, "saved %g %% of %zu", saved, n + dropped);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
    free(v);
}

/* Visibility rays in a convex shell (scene/convex.c): the open box of the
 * fixture has every surface on its convex hull, so rays are skipped (said,
 * and the render equals one without rays bit for bit); a wall standing in
 * the room makes rays count again (the render differs from one without). */
VT_TEST(budget_visibility_rays_skipped_only_in_a_convex_shell)
{
    static bplanes ray, none;
    vsgl_context *ctx = fx_context(2);
    VT_REQUIRE(ctx, "context");
    for (int occluder = 0; occluder < 2; ++occluder) {
        fx_scene fx;
        fx_room(&fx, BW, BH, 0.3f, 150.0f);
        if (occluder) {
            const float wall[4][3] = {{0.2f, -1.0f, 0.0f}, {0.2f, 1.0f, 0.0f}, {0.2f, 1.0f, 1.6f}, {0.2f, -1.0f, 1.6f}};
            fx_quad(&fx, wall, 3);
        }
        vsgl_scene *scene = NULL;
        VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        vsgl_render_stats st = {.size = sizeof st};
        for (int k = 0; k < 2; ++k) {
            vsgl_render_settings s;
            vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
            s.visibility = k ? VSGL_VISIBILITY_NONE : VSGL_VISIBILITY_RAY;
            vsgl_render_output o;
            memset(&o, 0, sizeof o);
            o.width = BW;
            o.height = BH;
            o.combined = k ? none.comb : ray.comb;
            o.glossy_light = k ? none.gl : ray.gl;
            VT_CHECK(vsgl_render(ctx, scene, &s, &o, k ? NULL : &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        }
        int said = strstr(st.skipped, "visibility rays: every surface lies on the scene's convex hull") != NULL;
        int same = memcmp(&ray, &none, sizeof ray) == 0;
        if (occluder)
            VT_CHECK(!said && !same, "with a wall: said %d, same as without rays %d", said, same);
        else
            VT_CHECK(said && same, "open box: said %d, same as without rays %d (%s)", said, same, st.skipped);
        vsgl_scene_destroy(scene);
    }
    vsgl_context_destroy(ctx);
}

/* The footprint rules (budget.h) against sides worked by hand. */
VT_TEST(budget_rsm_side_follows_the_footprint)
{
    /* the split of the settings' texels: equal weights and faces, footprints
     * 1 and 1/4: texels 2 x 128^2 in proportion to 64 / 1 : 64 / 0.25, so
     * the sides are 128 sqrt(2/5) = 80.95 and 128 sqrt(8/5) = 161.9 */
    vsgl_light_share l[2] = {{.weight = 1.0, .footprint = 1.0, .faces = 1},
                             {.weight = 1.0, .footprint = 0.25, .faces = 1}};
    vsgl__light_budget(l, 2, 64, 128);
    VT_CHECK(l[0].vsgl_count == 64 && l[1].vsgl_count == 64 && l[0].rsm_resolution == 81 &&
             l[1].rsm_resolution == 162, "split: %u %u, RSM %u %u", l[0].vsgl_count, l[1].vsgl_count,
             l[0].rsm_resolution, l[1].rsm_resolution);
    /* the auto budget's absolute density: 85.33 texels per VSGL, 192 VSGLs:
     * footprint 1 -> 128; 1/4 -> 256, capped at 200; 0.5 -> 181.02; 0 (or a
     * light of weight 0) keeps its side; the floor rsm / 4 */
    vsgl_light_share a[5] = {{.weight = 1, .footprint = 1.0, .vsgls = 192, .rsm_resolution = 7},
                             {.weight = 1, .footprint = 0.25, .vsgls = 192, .rsm_resolution = 7},
                             {.weight = 1, .footprint = 0.5, .vsgls = 192, .rsm_resolution = 7},
                             {.weight = 1, .footprint = 0.0, .vsgls = 192, .rsm_resolution = 7},
                             {.weight = 1, .footprint = 1.0, .vsgls = 1, .rsm_resolution = 7}};
    vsgl__footprint_rsm(a, 5, VSGL__AUTO_TEXELS_PER_VSGL, 256, 200);
    VT_CHECK(a[0].rsm_resolution == 128 && a[1].rsm_resolution == 200 && a[2].rsm_resolution == 181 &&
             a[3].rsm_resolution == 7 && a[4].rsm_resolution == 64, "auto sides %u %u %u %u %u", a[0].rsm_resolution,
             a[1].rsm_resolution, a[2].rsm_resolution, a[3].rsm_resolution, a[4].rsm_resolution);
}

typedef struct aplanes {
    float comb[BW * 4 * BH * 4 * 3];
} aplanes;

static vsgl_result render_with(vsgl_context *ctx, fx_scene *fx, const vsgl_render_settings *s, float *comb,
                               vsgl_render_stats *st)
{
    return render_fx(ctx, fx, s, NULL, comb, NULL, st);
}

/* The auto preset: what it says it chose is what it rendered (the same
 * pixels as balanced with those knobs set by hand), it chooses by the
 * image size and the sharpest glossy surface seen, and a bad auto_target
 * is refused by name. */
VT_TEST(budget_auto_renders_what_it_says)
{
    static aplanes a, b;
    vsgl_context *ctx = fx_context(2);
    VT_REQUIRE(ctx, "context");
    const struct {
        uint32_t w, h;
        float floor_roughness;
        unsigned aa; /* below the preset's aa_pixel_limit: balanced's 2 */
        const char *glossy;
    } cases[3] = {{BW, BH, 0.3f, 2, "glossy asg2: roughness 0.30 seen"},
                  {BW * 4, BH * 4, 0.3f, 2, "glossy asg2"},
                  {BW, BH, 0.8f, 2, "glossy asg (not asg2): nothing seen sharper than roughness 0.50"}};
    for (int c = 0; c < 3; ++c) {
        fx_scene fx;
        fx_room(&fx, cases[c].w, cases[c].h, cases[c].floor_roughness, 150.0f);
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_AUTO, &s);
        VT_CHECK(s.auto_target == VSGL_AUTO_BALANCED && s.aa_samples == 2 && s.rsm_resolution == 256,
                 "the auto preset is balanced's knobs with auto_target set");
        vsgl_render_stats st = {.size = sizeof st};
        VT_REQUIRE(render_with(ctx, &fx, &s, a.comb, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        unsigned aa = 0, v = 0, rsm = 0, fp = 0;
        const char *l0 = strstr(st.budget, "light 0: ");
        VT_CHECK(sscanf(st.budget, "auto: aa %u", &aa) == 1 && strstr(st.budget, cases[c].glossy) && l0 &&
                 sscanf(l0, "light 0: 100 %% of the light on what the camera sees: %u VSGLs, RSM %u (uniform 192, "
                        "256; footprint %u %%)", &v, &rsm, &fp) == 3, "case %d: budget text: %s", c, st.budget);
        VT_CHECK(aa == cases[c].aa && v == 192 && rsm >= 64 && rsm < 256 && fp > 50,
                 "case %d: aa %u, %u VSGLs, RSM %u, footprint %u", c, aa, v, rsm, fp);
        /* the same knobs by hand: the same pixels */
        vsgl_render_settings h;
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &h);
        h.aa_samples = aa;
        h.rsm_resolution = rsm;
        h.glossy_mode = strstr(st.budget, "glossy asg (not") ? VSGL_GLOSSY_ASG : VSGL_GLOSSY_ASG2;
        VT_REQUIRE(render_with(ctx, &fx, &h, b.comb, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        size_t n = (size_t)cases[c].w * cases[c].h * 3;
        VT_CHECK(memcmp(a.comb, b.comb, n * sizeof(float)) == 0, "case %d: auto differs from its knobs by hand", c);
        /* and not the same as balanced itself (the RSM side changed) */
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &h);
        VT_REQUIRE(render_with(ctx, &fx, &h, b.comb, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        VT_CHECK(memcmp(a.comb, b.comb, n * sizeof(float)) != 0, "case %d: auto equals balanced", c);
    }
    /* aa from the image size: 320 x 240 takes 1 sample */
    fx_scene big;
    fx_room(&big, 320, 240, 0.3f, 150.0f);
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_AUTO, &s);
    static float comb[320 * 240 * 3];
    vsgl_render_stats st = {.size = sizeof st};
    VT_CHECK(render_with(ctx, &big, &s, comb, &st) == VSGL_OK &&
             strncmp(st.budget, "auto: aa 1 (not 2): 320x240, >= 76800 pixels", 44) == 0, "320x240: %s", st.budget);
    /* a bad auto_target */
    s.auto_target = 7;
    VT_CHECK(render_with(ctx, &big, &s, comb, NULL) == VSGL_ERROR_INVALID_ARGUMENT &&
             strstr(vsgl_context_last_error(ctx), "auto_target is 7"), "bad auto_target: %s",
             vsgl_context_last_error(ctx));
    vsgl_context_destroy(ctx);
}

/* An image-size rule's three renders of fx: `s` with the rule (its stats
 * into *st), `h` its result set by hand and `f` without the rule, into
 * out[0..2]; whether s's first n bytes equal h's (*as_hand) and f's
 * (*as_off). */
static void rule_renders(vsgl_context *ctx, fx_scene *fx, const vsgl_render_settings *s,
                         const vsgl_render_settings *h, const vsgl_render_settings *f, float *const out[3], size_t n,
                         vsgl_render_stats *st, int *as_hand, int *as_off)
{
    VT_REQUIRE(render_with(ctx, fx, s, out[0], st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_REQUIRE(render_with(ctx, fx, h, out[1], NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_REQUIRE(render_with(ctx, fx, f, out[2], NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    *as_hand = memcmp(out[0], out[1], n) == 0;
    *as_off = memcmp(out[0], out[2], n) == 0;
}

/* aa_pixel_limit (every preset's 320 x 240): from that many pixels a render
 * takes one sample per pixel, says so in `skipped`, and gives the pixels
 * of aa_samples 1 set by hand; one pixel fewer keeps 2 x 2; the memory
 * estimate follows. */
VT_TEST(budget_aa_pixel_limit_takes_one_sample_and_says_so)
{
    static float lim[320 * 240 * 3], hand[320 * 240 * 3], full[320 * 240 * 3];
    vsgl_context *ctx = fx_context(2);
    VT_REQUIRE(ctx, "context");
    const uint32_t widths[2] = {320, 319};
    for (int c = 0; c < 2; ++c) {
        fx_scene fx;
        fx_room(&fx, widths[c], 240, 0.3f, 150.0f);
        vsgl_render_settings s, h, f;
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
        VT_CHECK(s.aa_samples == 2 && s.aa_pixel_limit == VSGL_AA_PIXEL_LIMIT_PRESETS && s.aa_pixel_limit == 76800u,
                 "balanced: aa %u, limit %u", s.aa_samples, s.aa_pixel_limit);
        h = s;
        h.aa_samples = 1;
        h.aa_pixel_limit = 0;
        f = s;
        f.aa_pixel_limit = 0;
        vsgl_render_stats st = {.size = sizeof st};
        float *const out[3] = {lim, hand, full};
        int as_hand, as_full;
        rule_renders(ctx, &fx, &s, &h, &f, out, (size_t)widths[c] * 240 * 3 * sizeof(float), &st, &as_hand, &as_full);
        int said = strstr(st.skipped, "anti-aliasing: 1 sample per pixel, not 2 x 2: 320 x 240 is at least "
                                      "aa_pixel_limit (76800 pixels); edge pixels keep their edge rays") != NULL;
        vsgl_scene *scene = NULL;
        VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        vsgl_memory_estimate es, eh, ef;
        VT_CHECK(vsgl_render_estimate(ctx, scene, &s, 22, &es) == VSGL_OK &&
                 vsgl_render_estimate(ctx, scene, &h, 22, &eh) == VSGL_OK &&
                 vsgl_render_estimate(ctx, scene, &f, 22, &ef) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        vsgl_scene_destroy(scene);
        if (c == 0)
            VT_CHECK(said && as_hand && !as_full && es.gbuffer == eh.gbuffer && es.gbuffer < ef.gbuffer,
                     "320 x 240: said %d, as aa 1 by hand %d, as 2 x 2 %d, G-buffer estimate %llu (aa 1: %llu, "
                     "2 x 2: %llu); skipped: %s", said, as_hand, as_full, (unsigned long long)es.gbuffer,
                     (unsigned long long)eh.gbuffer, (unsigned long long)ef.gbuffer, st.skipped);
        else
            VT_CHECK(!strstr(st.skipped, "anti-aliasing") && !as_hand && as_full && es.gbuffer == ef.gbuffer,
                     "319 x 240: said %d, as aa 1 %d, as 2 x 2 %d", said, as_hand, as_full);
    }
    vsgl_context_destroy(ctx);
}

/* stride_pixels (every preset's 320 x 240): above that many pixels the
 * stride grows with the image's side, S sqrt(P / P0) rounded down, at
 * most VSGL_SHADE_STRIDE_MAX; a render says so in `skipped` and gives the
 * pixels of that stride set by hand; stride 1 is never scaled. 480 x 360
 * is 2.25 x 76800 (2 -> exactly 3), 479 x 360 just under (2). */
VT_TEST(budget_stride_pixels_scales_the_stride_and_says_so)
{
    vsgl_render_settings p;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &p);
    VT_CHECK(p.shade_stride == 2 && p.stride_pixels == VSGL_STRIDE_PIXELS_PRESETS && p.stride_pixels == 76800u,
             "balanced: stride %u, stride_pixels %u", p.shade_stride, p.stride_pixels);
    const struct {
        uint32_t w, h, stride, want;
    } rule[] = {{320, 240, 2, 2}, {479, 360, 2, 2}, {480, 360, 2, 3}, {960, 540, 2, 5}, {1280, 720, 2, 6},
                {1920, 1080, 2, 8}, {7680, 4320, 2, 8}, {1920, 1080, 1, 1}, {80, 60, 2, 2}, {960, 540, 3, 7}};
    for (size_t i = 0; i < sizeof rule / sizeof rule[0]; ++i) {
        vsgl_render_settings q = p;
        q.shade_stride = rule[i].stride;
        uint32_t got = vsgl__stride_for_image(&q, rule[i].w, rule[i].h);
        VT_CHECK(got == rule[i].want, "%u x %u, stride %u: %u, want %u", rule[i].w, rule[i].h, rule[i].stride, got,
                 rule[i].want);
        q.stride_pixels = 0;
        VT_CHECK(vsgl__stride_for_image(&q, rule[i].w, rule[i].h) == rule[i].stride, "stride_pixels 0 scales");
    }

    static float lim[480 * 360 * 3], hand[480 * 360 * 3], two[480 * 360 * 3];
    vsgl_context *ctx = fx_context(2);
    VT_REQUIRE(ctx, "context");
    const uint32_t widths[2] = {480, 479};
    for (int c = 0; c < 2; ++c) {
        fx_scene fx;
        fx_room(&fx, widths[c], 360, 0.3f, 150.0f);
        vsgl_render_settings s = p, h = p, f = p;
        h.shade_stride = 3;
        h.stride_pixels = 0;
        f.stride_pixels = 0;
        vsgl_render_stats st = {.size = sizeof st};
        float *const out[3] = {lim, hand, two};
        int as_hand, as_two;
        rule_renders(ctx, &fx, &s, &h, &f, out, (size_t)widths[c] * 360 * 3 * sizeof(float), &st, &as_hand, &as_two);
        int said = strstr(st.skipped, "shading: one pixel in 3 x 3 shaded, not 2 x 2: 480 x 360 is 2.2x "
                                      "stride_pixels (76800 pixels)") != NULL;
        if (c == 0)
            VT_CHECK(said && as_hand && !as_two, "480 x 360: said %d, as stride 3 by hand %d, as stride 2 %d; "
                     "skipped: %s", said, as_hand, as_two, st.skipped);
        else
            VT_CHECK(!strstr(st.skipped, "shading: one pixel in") && !as_hand && as_two,
                     "479 x 360: said %d, as stride 3 %d, as stride 2 %d", said, as_hand, as_two);
    }
    /* stride 1: every pixel, whatever the size */
    fx_scene fx;
    fx_room(&fx, 480, 360, 0.3f, 150.0f);
    vsgl_render_settings s = p, f = p;
    s.shade_stride = f.shade_stride = 1;
    f.stride_pixels = 0;
    vsgl_render_stats st = {.size = sizeof st};
    VT_REQUIRE(render_with(ctx, &fx, &s, lim, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_REQUIRE(render_with(ctx, &fx, &f, two, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(memcmp(lim, two, sizeof lim) == 0 && !strstr(st.skipped, "shading: one pixel in"),
             "stride 1 was scaled: %s", st.skipped);
    vsgl_context_destroy(ctx);
}

/* glossy sg shades through the scalar reference path, which has no
 * sparse shading: a stride asked for is not taken (the same pixels and
 * pairs as stride 1) and the render does not claim it; it warns before
 * the wait, naming the path. The kernel path at the same stride shades
 * fewer pairs (what the check would miss if the stride never applied):
 * 0.73x here, a small room seen whole, most of its cells beside a junction
 * (0.44x before the cells beside one were tested, sparse.c). */
/* The glossy sg warnings among those captured. */
static int sg_warnings(const vt_warnings *w)
{
    int n = 0;
    for (const char *p = w->text; (p = strstr(p, "glossy sg")) != NULL; ++p)
        ++n;
    return n;
}

VT_TEST(budget_glossy_sg_shades_every_pixel_and_says_so)
{
    static float a[120 * 90 * 3], b[120 * 90 * 3];
    vt_warnings cap, first;
    memset(&cap, 0, sizeof cap);
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.size = sizeof cd;
    cd.thread_count = 2;
    cd.log = vt_capture_warnings;
    cd.log_user = &cap;
    vsgl_context *ctx = NULL;
    VT_REQUIRE(vsgl_context_create(&cd, &ctx) == VSGL_OK, "context");
    fx_scene fx;
    fx_room(&fx, 120, 90, 0.3f, 150.0f);
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    s.vsgl_count = 16;
    s.rsm_resolution = 64;
    s.visibility = VSGL_VISIBILITY_NONE;
    s.stride_pixels = 0;
    vsgl_render_stats st[4];
    for (int i = 0; i < 4; ++i) {
        memset(&st[i], 0, sizeof st[i]);
        st[i].size = sizeof st[i];
    }
    s.glossy_mode = VSGL_GLOSSY_SG;
    s.shade_stride = 3;
    VT_REQUIRE(render_with(ctx, &fx, &s, a, &st[0]) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    first = cap; /* the stride-3 render's warnings; then the stride-1 render's */
    memset(&cap, 0, sizeof cap);
    s.shade_stride = 1;
    VT_REQUIRE(render_with(ctx, &fx, &s, b, &st[1]) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(memcmp(a, b, sizeof a) == 0 && st[0].shading_pairs == st[1].shading_pairs,
             "glossy sg at stride 3 is not its render at stride 1: pairs %llu vs %llu",
             (unsigned long long)st[0].shading_pairs, (unsigned long long)st[1].shading_pairs);
    VT_CHECK(!strstr(st[0].skipped, "shading: one pixel in"), "claims a stride it did not take: %s", st[0].skipped);
    VT_CHECK(sg_warnings(&first) == 1 && sg_warnings(&cap) == 1 && strstr(first.text, "reference path") &&
                 strstr(first.text, "shade_stride ignored") && !strstr(cap.text, "shade_stride ignored"),
             "warnings: '%s' / '%s'", first.text, cap.text);
    s.glossy_mode = VSGL_GLOSSY_ASG2;
    s.shade_stride = 3;
    VT_REQUIRE(render_with(ctx, &fx, &s, a, &st[2]) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    s.shade_stride = 1;
    VT_REQUIRE(render_with(ctx, &fx, &s, b, &st[3]) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(st[2].shading_pairs * 5 < st[3].shading_pairs * 4 && sg_warnings(&cap) == 1,
             "asg2: stride 3 %llu pairs, stride 1 %llu; sg warnings %d",
             (unsigned long long)st[2].shading_pairs, (unsigned long long)st[3].shading_pairs, sg_warnings(&cap));
    vsgl_context_destroy(ctx);
}
