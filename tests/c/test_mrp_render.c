/* glossy_mode = VSGL_GLOSSY_MRP in vsgl_render (csrc/src/mrp/proxies.c,
 * shade_mrp.c, pass.c; docs/mrp.md §4): proxies from a room's walls, and
 * the glossy pass of a spot-lit metal floor (the quality suite's
 * spot_metal_floor: a spot lights the back wall, the GGX floor of
 * roughness 0.2 reflects it) against the brute force over the same RSMs,
 * next to the VSGL glossy term (k-means 256 and the balanced preset's
 * lattice). VSGL_TEST_TABLES=1 prints the figures of docs/mrp.md. */
#include "harness.h"
#include "scene_fixture.h"
#include "mrp/proxies.h"
#include "vsgl/reference.h"

#include <stdlib.h>
#include <time.h>

static int tables(void) { return getenv("VSGL_TEST_TABLES") != NULL; }

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* 6 x 6 x 3 m room, metal floor (0), white walls and ceiling (3), light
 * grey back wall (1), a spot under the ceiling aimed at the back wall. */
static void metal_floor_room_aimed(fx_scene *s, uint32_t w, uint32_t h, float roughness, const float at[3]);

static void metal_floor_room(fx_scene *s, uint32_t w, uint32_t h, float roughness)
{
    const float at[3] = {0.0f, 3.0f, 1.5f};
    metal_floor_room_aimed(s, w, h, roughness, at);
}

/* The same room with the spot aimed at `at` on the back wall. */
static void metal_floor_room_aimed(fx_scene *s, uint32_t w, uint32_t h, float roughness, const float at[3])
{
    memset(s, 0, sizeof *s);
    const float floor_[4][3] = {{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}};
    const float left[4][3] = {{-3, -3, 0}, {-3, 3, 0}, {-3, 3, 3}, {-3, -3, 3}};
    const float right[4][3] = {{3, -3, 0}, {3, -3, 3}, {3, 3, 3}, {3, 3, 0}};
    const float back[4][3] = {{-3, 3, 0}, {3, 3, 0}, {3, 3, 3}, {-3, 3, 3}};
    const float front[4][3] = {{-3, -3, 0}, {-3, -3, 3}, {3, -3, 3}, {3, -3, 0}};
    const float ceil_[4][3] = {{-3, -3, 3}, {-3, 3, 3}, {3, 3, 3}, {3, -3, 3}};
    fx_quad(s, floor_, 0);
    fx_quad(s, left, 3);
    fx_quad(s, right, 3);
    fx_quad(s, back, 1);
    fx_quad(s, front, 3);
    fx_quad(s, ceil_, 3);
    vsgl_material *m = s->materials;
    m[0].base_color[0] = m[0].base_color[1] = m[0].base_color[2] = 0.9f;
    m[0].metallic = 1.0f;
    m[0].roughness = roughness;
    m[0].specular_f0 = 0.04f;
    m[1].base_color[0] = m[1].base_color[1] = m[1].base_color[2] = 0.8f;
    m[1].roughness = 1.0f;
    m[2] = m[1];
    m[3].base_color[0] = m[3].base_color[1] = m[3].base_color[2] = 0.7f;
    m[3].roughness = 1.0f;
    const float eye[3] = {0.0f, -1.0f, 2.6f};
    fx_spot(s, eye, at, 2500.0f, 40.0f * 3.14159265f / 180.0f, 0.3f);
    const float ceye[3] = {0.0f, -2.8f, 1.2f}, cat[3] = {0.0f, 3.0f, 0.6f};
    fx_camera(s, ceye, cat, 28.0f, w, h);
}

VT_TEST(mrp_proxies_from_a_room)
{
    fx_scene fx;
    metal_floor_room(&fx, 32, 24, 0.2f);
    vsgl_context *ctx = NULL;
    vsgl_scene *scene = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
    vsgl__mrp_proxy_set set;
    VT_REQUIRE(vsgl__mrp_proxies_build(ctx, scene, 0.25, 8, &set) == VSGL_OK, "build");
    VT_CHECK(set.count == 6, "six faces: %zu", set.count);
    for (size_t k = 0; k < set.count; ++k) {
        const vsgl__mrp_proxy *p = &set.items[k];
        double area = 4.0 * p->rect.half_u * p->rect.half_v;
        VT_CHECK(fabs(area - (k < 2 ? 36.0 : 18.0)) < 1e-4, "proxy %zu area %g", k, area);
        VT_CHECK(fabs(p->coverage - 1.0) < 1e-6, "coverage %g", p->coverage);
        VT_CHECK(p->nu == 8 || p->nv == 8, "cells %u x %u", p->nu, p->nv);
    }
    /* the radiance: the lit back wall carries the RSM's flux x albedo */
    size_t count = 0;
    VT_REQUIRE(vsgl_reference_rsm(ctx, scene, 0, 64, &count, NULL, NULL, NULL, NULL, NULL) == VSGL_OK, "rsm");
    vsgl__mrp_proxies_free(&set);
    /* a size threshold above every face: none */
    VT_REQUIRE(vsgl__mrp_proxies_build(ctx, scene, 40.0, 8, &set) == VSGL_OK, "build");
    VT_CHECK(set.count == 0, "%zu", set.count);
    vsgl__mrp_proxies_free(&set);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

static double render_glossy(vsgl_context *ctx, vsgl_scene *scene, const vsgl_render_settings *s, uint32_t w,
                            uint32_t h, float *glossy, float *diffuse)
{
    vsgl_render_output out;
    memset(&out, 0, sizeof out);
    out.width = w;
    out.height = h;
    out.glossy = glossy;
    out.diffuse = diffuse;
    double t0 = now();
    vsgl_result r = vsgl_render(ctx, scene, s, &out, NULL);
    double t = now() - t0;
    VT_CHECK(r == VSGL_OK, "render %d: %s", r, vsgl_context_last_error(ctx));
    return t;
}

static double relmse(const float *a, const float *b, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; ++i)
        s += (a[i] - b[i]) * (a[i] - b[i]) / (b[i] * b[i] + 0.01);
    return s / n;
}

static double ratio(const float *a, const float *b, size_t n)
{
    double sa = 0.0, sb = 0.0;
    for (size_t i = 0; i < n; ++i)
        sa += a[i], sb += b[i];
    return sb > 0.0 ? sa / sb : 0.0;
}

VT_TEST(mrp_render_spot_metal_floor_against_brute_force)
{
    /* VSGL_MRP_FULL=1: 120 x 90, RSM 128 (the balanced preset's), roughness
     * 0.1 and 0.2 (~2.5 min: the brute force); else 64 x 48, RSM 64, 0.2 */
    const int full = getenv("VSGL_MRP_FULL") != NULL;
    const uint32_t w = full ? 120 : 64, h = full ? 90 : 48;
    const size_t n = (size_t)w * h * 3;
    vsgl_context *ctx = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    float *buf = calloc(10 * n, sizeof(float));
    VT_REQUIRE(buf, "memory");
    const float rough[2] = {0.1f, 0.2f};
    double worst_gain = 1e9;
    for (int ri = full ? 0 : 1; ri < 2; ++ri) {
        fx_scene fx;
        metal_floor_room(&fx, w, h, rough[ri]);
        vsgl_scene *scene = NULL;
        VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
        s.aa_samples = 1;
        if (!full)
            s.rsm_resolution = 64;
        float *ref = buf, *vk = buf + n, *vl = buf + 2 * n, *mr = buf + 3 * n, *dif = buf + 4 * n;
        float *dif_ref = buf + 5 * n, *dif_mrp = buf + 6 * n;
        vsgl_render_settings b = s;
        b.method = VSGL_METHOD_BRUTE_FORCE;
        double t_ref = render_glossy(ctx, scene, &b, w, h, ref, dif_ref);
        vsgl_render_settings k = s;
        k.fit_mode = VSGL_FIT_KMEANS;
        k.vsgl_count = 256;
        double t_k = render_glossy(ctx, scene, &k, w, h, vk, dif);
        double t_l = render_glossy(ctx, scene, &s, w, h, vl, dif);
        vsgl_render_settings m = s;
        m.glossy_mode = VSGL_GLOSSY_MRP;
        double t_m = render_glossy(ctx, scene, &m, w, h, mr, dif_mrp);
        int finite = 1;
        for (size_t i = 0; i < n; ++i)
            finite &= isfinite(mr[i]) && mr[i] >= 0.0f;
        VT_CHECK(finite, "MRP glossy plane finite, non-negative");
        /* the diffuse pass is untouched by the glossy mode */
        VT_CHECK(relmse(dif_mrp, dif, n) < 1e-12, "diffuse changed: %g", relmse(dif_mrp, dif, n));
        double e_k = relmse(vk, ref, n), e_l = relmse(vl, ref, n), e_m = relmse(mr, ref, n);
        if (tables()) {
            printf("    roughness %.1f, %u x %u, RSM %u, glossy pass against the brute force (same RSMs):\n", rough[ri], w, h, s.rsm_resolution);
            printf("      brute force          %.3f s\n", t_ref);
            printf("      VSGL k-means 256     relMSE %.4f  sum ratio %.3f  %.3f s\n", e_k, ratio(vk, ref, n), t_k);
            printf("      VSGL lattice (bal.)  relMSE %.4f  sum ratio %.3f  %.3f s\n", e_l, ratio(vl, ref, n), t_l);
            printf("      MRP                  relMSE %.4f  sum ratio %.3f  %.3f s\n", e_m, ratio(mr, ref, n), t_m);
        }
        const char *dump = getenv("VSGL_MRP_DUMP"); /* raw float planes for tools/mrp_images.py */
        if (dump) {
            const float *pl_[4] = {ref, vk, vl, mr};
            const char *nm[4] = {"ref", "kmeans", "lattice", "mrp"};
            for (int q = 0; q < 4; ++q) {
                char path[512];
                snprintf(path, sizeof path, "%s/r%02d_%s_%ux%u.f32", dump, (int)lroundf(rough[ri] * 100), nm[q], w, h);
                FILE *f = fopen(path, "wb");
                if (f) {
                    fwrite(pl_[q], sizeof(float), n, f);
                    fclose(f);
                }
            }
        }
        if (tables()) { /* the radiance grid: cells along a proxy's longer side */
            vsgl_gbuffer g;
            VT_REQUIRE(vsgl__gbuffer_build(ctx, scene, 1, 1, &g) == VSGL_OK, "gbuffer");
            float *pl = buf + 7 * n;
            vsgl_pixel_planes planes = {NULL, pl, NULL, NULL, NULL};
            const uint32_t cells[4] = {8, 16, 32, 64};
            for (int c = 0; c < 4; ++c) {
                size_t np = 0;
                double t0 = now();
                VT_CHECK(vsgl__mrp_glossy_pass(ctx, scene, s.rsm_resolution, VSGL__MRP_MIN_AREA, cells[c], &g, &planes,
                                               &np, NULL) == VSGL_OK, "pass");
                printf("      MRP pass, %2u cells: relMSE %.4f  sum ratio %.3f  %.3f s (%zu proxies)\n", cells[c],
                       relmse(pl, ref, n), ratio(pl, ref, n), now() - t0, np);
            }
            vsgl__gbuffer_free(&g);
        }
        worst_gain = fmin(worst_gain, e_k / (e_m > 0 ? e_m : 1e-30));
        /* the acceptance against the internal ground truth: lower
         * glossy relMSE than VSGL k-means 256 (the time is measured, not
         * asserted: the MRP render includes the whole VSGL pass, for its
         * diffuse light, and a second RSM per light) */
        /* measured at 64 x 48, RSM 64: 0.059 against 0.228. At 120 x 90, RSM 256 (VSGL_MRP_FULL)
         * k-means 256 with two GGX lobes wins: 0.0105 against 0.022 at roughness 0.2, 0.094 against
         * 0.092 at 0.1 (docs/mrp.md §4); the full size only prints */
        if (!full)
            VT_CHECK(e_m < e_k, "MRP %g (%g s) vs k-means 256 %g (%g s)", e_m, t_m, e_k, t_k);
        VT_CHECK(ratio(mr, ref, n) > 0.5 && ratio(mr, ref, n) < 1.5, "MRP glossy sum %g of the brute force's",
                 ratio(mr, ref, n));
        vsgl_scene_destroy(scene);
    }
    if (tables())
        printf("    k-means 256 relMSE / MRP relMSE, worst of the two roughnesses: %.2f\n", worst_gain);
    free(buf);
    vsgl_context_destroy(ctx);
}

/* The lit patch off the wall's centre (low, to the right): its reflection is
 * not symmetric, so radiance put in the wrong cells shows. The back wall's
 * lit face is the back side of its proxy (proxies.c orients a plane by its
 * largest normal component, +y; the wall faces -y): shade_mrp.c once placed
 * the back side's cells mirrored along the proxy's v axis. */
VT_TEST(mrp_render_off_centre_patch_against_brute_force)
{
    const uint32_t w = 64, h = 48;
    const size_t n = (size_t)w * h * 3;
    vsgl_context *ctx = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    float *buf = calloc(3 * n, sizeof(float));
    VT_REQUIRE(buf, "memory");
    fx_scene fx;
    const float at[3] = {1.2f, 3.0f, 0.8f};
    metal_floor_room_aimed(&fx, w, h, 0.2f, at);
    vsgl_scene *scene = NULL;
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    s.aa_samples = 1;
    s.rsm_resolution = 64;
    float *ref = buf, *mr = buf + n, *dif = buf + 2 * n;
    vsgl_render_settings b = s;
    b.method = VSGL_METHOD_BRUTE_FORCE;
    render_glossy(ctx, scene, &b, w, h, ref, dif);
    vsgl_render_settings m = s;
    m.glossy_mode = VSGL_GLOSSY_MRP;
    render_glossy(ctx, scene, &m, w, h, mr, dif);
    double e = relmse(mr, ref, n), q = ratio(mr, ref, n);
    if (tables())
        printf("    off-centre patch: MRP glossy relMSE %.4f against the brute force, sum ratio %.3f\n", e, q);
    /* measured 0.098, sum 0.927 (RSM 64: the brute force's own VPLs are coarse; the lobes' reach
     * e^{-6}: e^{-9} gave 0.929, e^{-1.5} 0.864); the mirrored cells gave 0.60, sum 0.69 */
    VT_CHECK(e < 0.2 && q > 0.91 && q < 1.15, "MRP relMSE %g, sum ratio %g against the brute force", e, q);
    vsgl_scene_destroy(scene);
    free(buf);
    vsgl_context_destroy(ctx);
}

/* vsgl__mrp_on_proxy: which clusters the hybrid leaves to MRP. */
VT_TEST(mrp_hybrid_on_proxy_classification)
{
    vsgl_context *ctx = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    fx_scene fx;
    metal_floor_room(&fx, 32, 24, 0.2f);
    vsgl_scene *scene = NULL;
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
    vsgl__mrp_proxy_set set;
    VT_REQUIRE(vsgl__mrp_proxies_build(ctx, scene, VSGL__MRP_MIN_AREA, 8, &set) == VSGL_OK, "proxies");
    vsgl_vsgl v;
    memset(&v, 0, sizeof v);
    v.lobe = VSGL__LOBE_DIFFUSE;
    v.mean = v3_make(0.5f, 3.0f, 1.2f); /* on the back wall, facing into the room */
    v.normal = v3_make(0.0f, -1.0f, 0.0f);
    VT_CHECK(vsgl__mrp_on_proxy(&set, &v) == 1, "a cluster on the back wall");
    v.normal = v3_make(0.0f, -0.99f, 0.14f);
    VT_CHECK(vsgl__mrp_on_proxy(&set, &v) == 1, "normal 8 degrees off");
    v.normal = v3_make(0.0f, -0.7f, 0.714f);
    VT_CHECK(vsgl__mrp_on_proxy(&set, &v) == 0, "normal 45 degrees off (mixed surfaces)");
    v.normal = v3_make(0.0f, -1.0f, 0.0f);
    v.mean = v3_make(0.5f, 2.8f, 1.2f);
    VT_CHECK(vsgl__mrp_on_proxy(&set, &v) == 0, "20 cm in front of the wall (a corner cluster's mean)");
    v.mean = v3_make(3.5f, 3.0f, 1.2f);
    VT_CHECK(vsgl__mrp_on_proxy(&set, &v) == 0, "in the wall's plane, outside its rectangle");
    v.mean = v3_make(0.5f, 3.0f, 1.2f);
    v.lobe = VSGL__LOBE_SPECULAR;
    VT_CHECK(vsgl__mrp_on_proxy(&set, &v) == 0, "a specular cluster (the cells carry diffuse light only)");
    vsgl__mrp_proxies_free(&set);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* MRP's light as the hybrid computes it (its reach
 * e^{-VSGL__MRP_REACH_HYBRID}, its roughness limit), with no VSGL estimate
 * beside it (both VSGL planes zero, so the ratio rule takes MRP's light
 * wherever it has any): the proxies and cells of the render, this frame's
 * RSM of the one light, one sample per pixel. */
static void hybrid_mrp_light(vsgl_context *ctx, vsgl_scene *scene, uint32_t rsm_resolution, float *out, size_t n)
{
    vsgl_gbuffer g;
    VT_REQUIRE(vsgl__gbuffer_build(ctx, scene, 1, 1, &g) == VSGL_OK, "gbuffer");
    VT_REQUIRE(g.width * g.height * 3 == n, "G-buffer %ux%u", g.width, g.height);
    vsgl__mrp_proxy_set set;
    VT_REQUIRE(vsgl__mrp_proxies_build(ctx, scene, VSGL__MRP_MIN_AREA, VSGL__MRP_CELLS, &set) == VSGL_OK, "proxies");
    vsgl_rsm rsm;
    VT_REQUIRE(vsgl__rsm_build(ctx, scene, 0, rsm_resolution, &rsm) == VSGL_OK, "rsm");
    vsgl__mrp_proxies_add_rsm(&set, scene, &rsm);
    vsgl__rsm_free(&rsm);
    vsgl__mrp_proxies_finish(&set);
    float *zero = calloc(n, sizeof(float));
    VT_REQUIRE(zero, "memory");
    memset(out, 0, n * sizeof(float));
    vsgl_pixel_planes planes = {NULL, out, NULL, NULL, NULL};
    VT_CHECK(vsgl__mrp_shade_glossy(ctx, scene, &g, &set, &planes, zero, VSGL__MRP_HYBRID_MAX_ALPHA) == VSGL_OK,
             "the hybrid's MRP pass: %s", vsgl_context_last_error(ctx));
    free(zero);
    vsgl__mrp_proxies_free(&set);
    vsgl__gbuffer_free(&g);
}

/* VSGL_GLOSSY_HYBRID: a rough floor (roughness 0.8 > 0.5) keeps the two-lobe
 * VSGL glossy light bit for bit; a sharp one (0.2) takes the proxies' light
 * from MRP where MRP's is above VSGL__MRP_HYBRID_RATIO times the on-proxy
 * VSGLs', else from the VSGLs, never both (its sum against the brute force
 * within 10 %, its relMSE at most ASG2's x 1.2). The rule hides a reach cut
 * short (the VSGLs' light takes over where MRP's ends), so MRP's light at
 * the hybrid's reach is checked on its own: against MRP alone (reach
 * e^{-VSGL__MRP_REACH}) and the brute force. */
VT_TEST(mrp_hybrid_rule_against_asg2_and_mrp)
{
    const uint32_t w = 48, h = 36;
    const size_t n = (size_t)w * h * 3;
    vsgl_context *ctx = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    float *buf = calloc(7 * n, sizeof(float));
    VT_REQUIRE(buf, "memory");
    float *a2 = buf, *hy = buf + n, *mr = buf + 2 * n, *ref = buf + 3 * n, *dif = buf + 4 * n, *dif_h = buf + 5 * n;
    float *hm = buf + 6 * n;
    const float rough[2] = {0.8f, 0.2f};
    for (int ri = 0; ri < 2; ++ri) {
        fx_scene fx;
        metal_floor_room(&fx, w, h, rough[ri]);
        vsgl_scene *scene = NULL;
        VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
        s.aa_samples = 1;
        s.rsm_resolution = 64;
        s.glossy_mode = VSGL_GLOSSY_ASG2;
        render_glossy(ctx, scene, &s, w, h, a2, dif);
        vsgl_render_settings hs = s;
        hs.glossy_mode = VSGL_GLOSSY_HYBRID;
        render_glossy(ctx, scene, &hs, w, h, hy, dif_h);
        int finite = 1;
        for (size_t i = 0; i < n; ++i)
            finite &= isfinite(hy[i]) && hy[i] >= 0.0f;
        VT_CHECK(finite, "hybrid glossy plane finite, non-negative");
        VT_CHECK(relmse(dif_h, dif, n) < 1e-12, "diffuse changed: %g", relmse(dif_h, dif, n));
        if (ri == 0) {
            VT_CHECK(relmse(hy, a2, n) == 0.0, "rough floor: hybrid differs from ASG2 (%g)", relmse(hy, a2, n));
        } else {
            vsgl_render_settings m = s, b = s;
            m.glossy_mode = VSGL_GLOSSY_MRP;
            b.method = VSGL_METHOD_BRUTE_FORCE;
            render_glossy(ctx, scene, &m, w, h, mr, dif);
            render_glossy(ctx, scene, &b, w, h, ref, dif);
            hybrid_mrp_light(ctx, scene, s.rsm_resolution, hm, n);
            double e_h = relmse(hy, ref, n), e_m = relmse(mr, ref, n), e_a = relmse(a2, ref, n);
            double q_h = ratio(hy, ref, n), q_m = ratio(mr, ref, n), q_r = ratio(hm, ref, n), q_rm = ratio(hm, mr, n);
            if (tables())
                printf("    hybrid, roughness 0.2: glossy relMSE against the brute force %.4f (sum %.3f), "
                       "MRP %.4f (sum %.3f), ASG2 lattice %.4f; MRP's light at the hybrid's reach: sum %.3f of "
                       "the brute force's, %.3f of MRP alone's\n", e_h, q_h, e_m, q_m, e_a, q_r, q_rm);
            /* every cluster of this room's lattice lies on a wall or is a specular floor cluster: in
             * the floor's pixels the hybrid takes MRP's light or the on-proxy VSGLs'. Measured with
             * the ratio 2: 0.0444 (sum 1.008), the same as ASG2 (MRP's light is nowhere 2x the
             * lattice's); MRP alone 0.0388 (0.939). The larger of the two (ratio 1): 0.0504 (1.015) */
            VT_CHECK(e_h < 1.2 * e_a && q_h > 0.9 && q_h < 1.1, "hybrid %g (sum %g) vs MRP %g (sum %g), ASG2 %g",
                     e_h, q_h, e_m, q_m, e_a);
            /* MRP's light at the hybrid's reach. Measured (sum of the brute force's, of MRP alone's):
             * e^{-3} (the default) 0.917, 0.976; e^{-6} 0.935, 0.996; cut short, e^{-2} 0.891, 0.949
             * and e^{-1.5} 0.867, 0.923 fail (the hybrid's own plane was 0.0444, 1.008 in all four) */
            VT_CHECK(q_rm > 0.96 && q_rm < 1.01 && q_r > 0.90, "MRP's light at the hybrid's reach: sum %g "
                     "of MRP alone's (reach e^-6), %g of the brute force's: the reach cut short?", q_rm, q_r);
        }
        vsgl_scene_destroy(scene);
    }
    free(buf);
    vsgl_context_destroy(ctx);
}

/* vsgl__mrp_proxies_add_rsm reuses a texel's material parameters while its
 * neighbours share its material: the same cells, bit for bit, as adding the
 * texels one at a time (each then computing its own), with a spot on a
 * room's corner (the metal floor, the back and the side wall: three
 * materials interleaved along the RSM's rows). */
VT_TEST(mrp_proxies_add_rsm_material_reuse_is_exact)
{
    fx_scene fx;
    const float at[3] = {2.9f, 2.9f, 0.1f};
    metal_floor_room_aimed(&fx, 32, 24, 0.2f, at);
    vsgl_context *ctx = NULL;
    vsgl_scene *scene = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
    vsgl__mrp_proxy_set a, b;
    VT_REQUIRE(vsgl__mrp_proxies_build(ctx, scene, 0.25, 16, &a) == VSGL_OK, "build");
    VT_REQUIRE(vsgl__mrp_proxies_build(ctx, scene, 0.25, 16, &b) == VSGL_OK, "build");
    vsgl_rsm rsm;
    VT_REQUIRE(vsgl__rsm_build(ctx, scene, 0, 64, &rsm) == VSGL_OK, "rsm");
    vsgl__mrp_proxies_add_rsm(&a, scene, &rsm);
    int changes = 0;
    uint32_t prev = VSGL__RSM_EMPTY;
    for (size_t i = 0; i < rsm.count; ++i) { /* one texel at a time */
        if (rsm.material[i] == VSGL__RSM_EMPTY)
            continue;
        changes += prev != VSGL__RSM_EMPTY && rsm.material[i] != prev;
        prev = rsm.material[i];
        vsgl_rsm one = rsm;
        one.count = 1;
        for (int c = 0; c < 3; ++c) {
            one.pos[c] = rsm.pos[c] + i, one.nrm[c] = rsm.nrm[c] + i, one.flux[c] = rsm.flux[c] + i;
            one.tan[c] = rsm.tan[c] ? rsm.tan[c] + i : NULL, one.wi[c] = rsm.wi[c] ? rsm.wi[c] + i : NULL;
        }
        one.area = rsm.area ? rsm.area + i : NULL;
        one.material = rsm.material + i;
        for (int q = 0; q < VSGL__SURF_N; ++q)
            one.surf[q] = rsm.surf[q] ? rsm.surf[q] + i : NULL;
        vsgl__mrp_proxies_add_rsm(&b, scene, &one);
    }
    VT_CHECK(changes > 20, "the lit texels' material changes %d times along the rows", changes);
    size_t diff = 0, lit = 0;
    for (size_t k = 0; k < a.count; ++k) {
        const vsgl__mrp_proxy *p = &a.items[k], *q = &b.items[k];
        for (size_t i = 0; i < 2 * (size_t)p->nu * p->nv * 3; ++i) {
            diff += p->power[i] != q->power[i];
            lit += p->power[i] > 0.0f;
        }
    }
    VT_CHECK(diff == 0 && lit > 100, "%zu of the cells' values differ (%zu lit)", diff, lit);
    vsgl__rsm_free(&rsm);
    vsgl__mrp_proxies_free(&a);
    vsgl__mrp_proxies_free(&b);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* MRP and the hybrid take each light's RSM as the fit builds it (render.c,
 * vsgl__fit_lights_mrp); when the fit comes from a render cache the pass
 * builds its own RSMs, as before. Both glossy planes bit-identical, and
 * not black (a lost RSM would leave the proxies dark). */
VT_TEST(mrp_pass_takes_the_fits_rsms_bit_identically)
{
    const uint32_t w = 40, h = 30;
    const size_t n = (size_t)w * h * 3;
    fx_scene fx;
    metal_floor_room(&fx, w, h, 0.2f);
    vsgl_context *ctx = NULL;
    vsgl_scene *scene = NULL;
    vsgl_render_cache *cache = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
    float *a = calloc(2 * n, sizeof(float)), *b = a ? a + n : NULL;
    VT_REQUIRE(a, "memory");
    const int modes[2] = {VSGL_GLOSSY_MRP, VSGL_GLOSSY_HYBRID};
    for (int m = 0; m < 2; ++m) {
        VT_REQUIRE(vsgl_render_cache_create(ctx, &cache) == VSGL_OK, "cache");
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
        s.aa_samples = 1;
        s.rsm_resolution = 64;
        s.glossy_mode = modes[m];
        vsgl_render_output out;
        memset(&out, 0, sizeof out);
        out.width = w;
        out.height = h;
        vsgl_render_stats st;
        memset(&st, 0, sizeof st);
        st.size = sizeof st;
        out.glossy = a; /* the fit's RSMs */
        VT_CHECK(vsgl_render_cached(ctx, scene, &s, cache, &out, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        VT_CHECK(st.reused == 0, "first render: reused %u", st.reused);
        out.glossy = b; /* the fit from the cache: the pass's own RSMs */
        VT_CHECK(vsgl_render_cached(ctx, scene, &s, cache, &out, &st) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        VT_CHECK(st.reused & VSGL_REUSED_FIT, "second render: reused %u", st.reused);
        double sum = 0.0;
        size_t diff = 0;
        for (size_t i = 0; i < n; ++i) {
            sum += a[i];
            diff += a[i] != b[i];
        }
        VT_CHECK(diff == 0 && sum > 0.0, "mode %d: %zu values differ (glossy sum %g)", (int)modes[m], diff, sum);
        vsgl_render_cache_destroy(cache);
    }
    free(a);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

static int32_t cancel_in_mrp(void *user, const char *stage, float fraction)
{
    (void)fraction;
    int *seen = user;
    if (strcmp(stage, "mrp") == 0) {
        ++*seen;
        return 1;
    }
    return 0;
}

VT_TEST(mrp_render_cancels_in_the_mrp_pass)
{
    fx_scene fx;
    metal_floor_room(&fx, 32, 24, 0.2f);
    int seen = 0;
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.size = sizeof cd;
    cd.progress = cancel_in_mrp;
    cd.progress_user = &seen;
    vsgl_context *ctx = NULL;
    vsgl_scene *scene = NULL;
    VT_REQUIRE(vsgl_context_create(&cd, &ctx) == VSGL_OK, "context");
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
    s.glossy_mode = VSGL_GLOSSY_MRP;
    float *glossy = calloc(32 * 24 * 3, sizeof(float));
    vsgl_render_output out;
    memset(&out, 0, sizeof out);
    out.width = 32;
    out.height = 24;
    out.glossy = glossy;
    VT_CHECK(vsgl_render(ctx, scene, &s, &out, NULL) == VSGL_ERROR_CANCELLED, "cancelled");
    VT_CHECK(seen == 1, "the mrp stage reported %d times before stopping", seen);
    free(glossy);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}
