/* VSGL accuracy against brute-force VPL gathering on the same RSMs (which
 * isolates the VSGL approximation from the RSM discretisation): on three
 * scenes (spot, point, area light), the error of FIS falls as the number
 * of VSGLs grows, and every mode stays within a bound of the reference. */
#include "harness.h"
#include "accuracy.h"

VT_TEST(accuracy_fis_error_falls_with_vsgl_count_on_three_scenes)
{
    const uint32_t W = 40, H = 30;
    const uint32_t counts[4] = {1, 8, 64, 512};
    for (int k = 0; k < ACC_SCENES; ++k) {
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
        s.shade_stride = 1; /* every pixel shaded, no visibility rays: the model alone */
        s.visibility = VSGL_VISIBILITY_NONE;
        s.aa_samples = 1;
        s.rsm_resolution = 32;
        s.method = VSGL_METHOD_BRUTE_FORCE;
        acc_planes ref, got;
        if (!acc_render(k, W, H, &s, &ref, NULL)) {
            VT_CHECK(0, "scene %d reference failed", k);
            continue;
        }
        s.method = VSGL_METHOD_VSGL;
        s.fit_mode = VSGL_FIT_FIS;
        double err[4][2];
        for (int i = 0; i < 4; ++i) {
            s.vsgl_count = counts[i];
            VT_CHECK(acc_render(k, W, H, &s, &got, NULL), "scene %d N=%u", k, counts[i]);
            err[i][0] = acc_relmse(got.diffuse, ref.diffuse, (size_t)W * H * 3);
            err[i][1] = acc_relmse(got.glossy, ref.glossy, (size_t)W * H * 3);
            acc_free(&got);
        }
        for (int lobe = 0; lobe < 2; ++lobe) {
            VT_CHECK(err[3][lobe] < err[0][lobe],
                     "scene %d %s: relMSE N=512 %.4g not below N=1 %.4g (N=8 %.4g, N=64 %.4g)", k,
                     lobe ? "glossy" : "diffuse", err[3][lobe], err[0][lobe], err[1][lobe], err[2][lobe]);
            VT_CHECK(err[2][lobe] < err[0][lobe], "scene %d %s: relMSE N=64 %.4g not below N=1 %.4g", k,
                     lobe ? "glossy" : "diffuse", err[2][lobe], err[0][lobe]);
        }
        /* with many VSGLs the diffuse AOV is close to the reference */
        VT_CHECK(err[3][0] < 0.05, "scene %d: diffuse relMSE %.4g at N=512", k, err[3][0]);
        acc_free(&ref);
    }
}

/* Render scene's diffuse plane (W x H x 3 floats) with settings s. */
static int render_diffuse(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s, uint32_t W,
                          uint32_t H, float *diffuse)
{
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = W;
    o.height = H;
    o.diffuse = diffuse;
    return vsgl_render(ctx, scene, s, &o, NULL) == VSGL_OK;
}

/* A partition between the lit red wall and the green wall: with visibility
 * rays the VSGL render moves towards the brute-force reference with
 * visibility (indirect shadows), and the green wall loses red light. The
 * budget (visibility_budget 0.02: no ray for the weakest 2 % of each
 * receiver's light) keeps that: it differs from a ray for every pair by a
 * small part of what visibility changes, and the more it skips (0.5: half
 * of every receiver's light without its own ray) the more it differs. */
VT_TEST(accuracy_visibility_casts_indirect_shadows)
{
    const uint32_t W = 40, H = 30;
    fx_scene fx;
    fx_room(&fx, W, H, 0.3f, 150.0f);
    const float wall[4][3] = {{0.2f, -1.0f, 0.0f}, {0.2f, 1.0f, 0.0f}, {0.2f, 1.0f, 1.6f}, {0.2f, -1.0f, 1.6f}};
    fx_quad(&fx, wall, 3);
    vsgl_context *ctx;
    vsgl_scene *scene;
    vsgl_context_create(NULL, &ctx);
    VT_CHECK(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    float *bf = calloc(W * H * 3, sizeof(float)), *on = calloc(W * H * 3, sizeof(float)),
          *off = calloc(W * H * 3, sizeof(float)), *all = calloc(W * H * 3, sizeof(float)),
          *half = calloc(W * H * 3, sizeof(float));
    float *planes[5] = {bf, on, off, all, half};
    for (int k = 0; k < 5; ++k) {
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
        s.shade_stride = 1; /* every pixel shaded, no visibility rays: the model alone */
        s.aa_samples = 1;
        s.rsm_resolution = 32;
        s.vsgl_count = 128;
        s.method = k == 0 ? VSGL_METHOD_BRUTE_FORCE : VSGL_METHOD_VSGL;
        s.visibility = k == 2 ? VSGL_VISIBILITY_NONE : VSGL_VISIBILITY_RAY;
        s.visibility_budget = k == 3 ? -1.0f : (k == 4 ? 0.5f : 0.0f); /* every pair; half; the default */
        VT_CHECK(render_diffuse(ctx, scene, &s, W, H, planes[k]), "render %d: %s", k, vsgl_context_last_error(ctx));
    }
    double e_on = acc_relmse(on, bf, W * H * 3), e_off = acc_relmse(off, bf, W * H * 3);
    VT_CHECK(e_on < 0.5 * e_off, "relMSE with visibility %.4g, without %.4g (reference with visibility)", e_on, e_off);
    double d_budget = acc_relmse(on, all, W * H * 3), d_off = acc_relmse(off, all, W * H * 3),
           d_half = acc_relmse(half, all, W * H * 3);
    printf("    relMSE against a ray for every pair: budget 0.02 %.3g, 0.5 %.3g, no visibility %.3g\n", d_budget, d_half,
           d_off);
    VT_CHECK(d_budget < 0.05 * d_off && d_budget < d_half, "the budget's difference to every ray %.4g (0.5: %.4g; no "
             "visibility: %.4g)", d_budget, d_half, d_off);
    /* red light on the green wall (right edge columns, middle rows) */
    double red_on = 0, red_off = 0;
    for (uint32_t y = H / 3; y < 2 * H / 3; ++y)
        for (uint32_t x = W - 6; x < W - 2; ++x) {
            red_on += on[(y * W + x) * 3];
            red_off += off[(y * W + x) * 3];
        }
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    relMSE vs brute force with visibility: %.4g (VSGL with rays), %.4g (without); red on green wall %.4g vs %.4g\n",
               e_on, e_off, red_on, red_off);
    VT_CHECK(red_on < 0.7 * red_off, "red on the green wall: %.4g with visibility, %.4g without", red_on, red_off);
    free(bf);
    free(on);
    free(off);
    free(all);
    free(half);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* The same partition lit through a coarse lattice (the preview's few large
 * clusters): a receiver half hidden from a cluster took all or none of its
 * light from one ray, and the soft shadow behind the partition was grain.
 * With 8 rays for the pairs that carry 2 % or more of a receiver's light
 * (vsgl_render_settings.dominant_rays) the pixel-scale noise of the light
 * the rays take away (the image without visibility minus the image; each
 * pixel of it against the mean of its 8 neighbours, RMS over the mean)
 * falls by over 1.5x, the image stays within 2 % of one ray's in sum (the
 * same expectation), and it moves no further from the brute force with
 * visibility. */
VT_TEST(accuracy_dominant_rays_smooth_a_soft_shadow)
{
    const uint32_t W = 64, H = 48;
    fx_scene fx;
    fx_room(&fx, W, H, 0.3f, 150.0f);
    /* a 0.5 m white cube on the floor, right of the lit corner: its soft indirect shadow on the floor */
    const float x0 = -0.1f, x1 = 0.4f, y0 = -0.2f, y1 = 0.3f, z1 = 0.5f;
    const float cube[5][4][3] = {
        {{x0, y0, 0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, 0}}, {{x1, y0, 0}, {x1, y1, 0}, {x1, y1, z1}, {x1, y0, z1}},
        {{x0, y0, 0}, {x1, y0, 0}, {x1, y0, z1}, {x0, y0, z1}}, {{x0, y1, 0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, 0}},
        {{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}}};
    for (int f = 0; f < 5; ++f)
        fx_quad(&fx, cube[f], 3);
    vsgl_context *ctx;
    vsgl_scene *scene;
    vsgl_context_create(NULL, &ctx);
    VT_CHECK(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    float *img[4]; /* brute force, no visibility, one ray, 8 dominant rays */
    double noise[4] = {0, 0, 0, 0}, sum[4] = {0, 0, 0, 0};
    for (int k = 0; k < 4; ++k) {
        img[k] = calloc(W * H * 3, sizeof(float));
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
        s.shade_stride = 1;
        s.rsm_resolution = 64;
        s.method = k == 0 ? VSGL_METHOD_BRUTE_FORCE : VSGL_METHOD_VSGL;
        s.visibility = k == 1 ? VSGL_VISIBILITY_NONE : VSGL_VISIBILITY_RAY;
        s.dominant_rays = k == 3 ? 8u : 1u;
        VT_CHECK(render_diffuse(ctx, scene, &s, W, H, img[k]), "render %d: %s", k, vsgl_context_last_error(ctx));
        for (size_t i = 0; i < (size_t)W * H * 3; ++i)
            sum[k] += img[k][i];
    }
    for (int k = 2; k < 4; ++k) {
        double e = 0.0, m = 0.0;
        for (uint32_t y = 1; y + 1 < H; ++y)
            for (uint32_t x = 1; x + 1 < W; ++x)
                for (int c = 0; c < 3; ++c) {
#define TAKEN(yy, xx) ((double)img[1][((yy) * W + (xx)) * 3 + c] - img[k][((yy) * W + (xx)) * 3 + c])
                    double nb = 0.0;
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx)
                            if (dx || dy)
                                nb += TAKEN(y + dy, x + dx);
                    double d = TAKEN(y, x) - nb / 8.0;
#undef TAKEN
                    e += d * d;
                    m += fabs((double)img[1][(y * W + x) * 3 + c] - img[k][(y * W + x) * 3 + c]);
                }
        noise[k] = sqrt(e / ((W - 2) * (H - 2) * 3)) / (m / ((W - 2) * (H - 2) * 3));
    }
    double e1 = acc_relmse(img[2], img[0], W * H * 3), e8 = acc_relmse(img[3], img[0], W * H * 3);
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    pixel-scale noise of the light the rays take: one ray %.4f, 8 dominant rays %.4f; sums %.5g / "
               "%.5g (no visibility %.5g); relMSE vs brute force %.4g / %.4g\n", noise[2], noise[3], sum[2], sum[3],
               sum[1], e1, e8);
    VT_CHECK(noise[3] < noise[2] / 1.5, "pixel-scale noise %.4f with 8 dominant rays, %.4f with one", noise[3],
             noise[2]);
    VT_CHECK(fabs(sum[3] / sum[2] - 1.0) < 0.02 && sum[2] < 0.98 * sum[1], "sum with 8 dominant rays %.5g, with one "
             "%.5g, without visibility %.5g", sum[3], sum[2], sum[1]);
    VT_CHECK(e8 <= e1, "relMSE against the brute force %.4g with 8 dominant rays, %.4g with one", e8, e1);
    for (int k = 0; k < 4; ++k)
        free(img[k]);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}
