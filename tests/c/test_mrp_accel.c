/* The MRP glossy mode's speed-ups and its size knob (docs/mrp.md §4): the
 * cell pyramid of a proxy (proxies.c: each block the mean of the cells it
 * covers, and their contrast), and vsgl_render_settings.mrp_min_area
 * (validated; a threshold above every face leaves no proxy, so the MRP
 * glossy pass is black; the default reflects the lit wall). The pyramid's
 * and the 2 x 2 interpolation's effect on the image is measured against
 * Cycles and the brute force by tools/mrp_quality.sh and
 * test_mrp_render.c. */
#include "harness.h"
#include "scene_fixture.h"
#include "mrp/proxies.h"

#include <stdlib.h>

/* A 6 x 6 x 3 m room: a metal floor (0), a grey back wall (1) lit by a spot. */
static void room(fx_scene *s, uint32_t w, uint32_t h)
{
    memset(s, 0, sizeof *s);
    const float floor_[4][3] = {{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}};
    const float back[4][3] = {{-3, 3, 0}, {3, 3, 0}, {3, 3, 3}, {-3, 3, 3}};
    fx_quad(s, floor_, 0);
    fx_quad(s, back, 1);
    vsgl_material *m = s->materials;
    m[0].base_color[0] = m[0].base_color[1] = m[0].base_color[2] = 0.9f;
    m[0].metallic = 1.0f;
    m[0].roughness = 0.2f;
    m[0].specular_f0 = 0.04f;
    m[1].base_color[0] = m[1].base_color[1] = m[1].base_color[2] = 0.8f;
    m[1].roughness = 1.0f;
    const float eye[3] = {0.0f, -1.0f, 2.6f}, at[3] = {0.5f, 3.0f, 1.2f};
    fx_spot(s, eye, at, 2500.0f, 40.0f * 3.14159265f / 180.0f, 0.3f);
    const float ceye[3] = {0.0f, -2.8f, 1.2f}, cat[3] = {0.0f, 3.0f, 0.6f};
    fx_camera(s, ceye, cat, 28.0f, w, h);
}

VT_TEST(mrp_pyramid_blocks_are_the_mean_of_their_cells)
{
    fx_scene fx;
    room(&fx, 16, 12);
    vsgl_context *ctx = NULL;
    vsgl_scene *scene = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
    const uint32_t cells[3] = {32, 7, 1};
    for (int c = 0; c < 3; ++c) {
        vsgl__mrp_proxy_set set;
        VT_REQUIRE(vsgl__mrp_proxies_build(ctx, scene, 0.25, cells[c], &set) == VSGL_OK, "build");
        VT_REQUIRE(set.count == 2, "two faces: %zu", set.count);
        vt_rng r = {1400u + (uint32_t)c};
        for (size_t k = 0; k < set.count; ++k) { /* random power, a third of the cells unlit */
            vsgl__mrp_proxy *p = &set.items[k];
            for (size_t i = 0; i < 2 * (size_t)p->nu * p->nv; ++i) {
                float v = vt_uniform(&r) < 0.33 ? 0.0f : (float)vt_uniform(&r);
                for (int ch = 0; ch < 3; ++ch)
                    p->power[i * 3 + ch] = v * (1.0f + 0.5f * (float)ch);
            }
        }
        vsgl__mrp_proxies_finish(&set);
        for (size_t k = 0; k < set.count; ++k) {
            const vsgl__mrp_proxy *p = &set.items[k];
            uint32_t nu, nv, st;
            const float *top = vsgl__mrp_level(p, 0, p->levels - 1, &nu, &nv, &st);
            VT_CHECK(nu == 1 && nv == 1, "cells %u: the top level is one block (%u x %u)", cells[c], nu, nv);
            (void)top;
            for (int side = 0; side < 2; ++side) {
                const float *l0 = vsgl__mrp_level(p, side, 0, &nu, &nv, &st);
                VT_CHECK(nu == p->nu && nv == p->nv && st == 3, "level 0 is the cells");
                for (uint32_t l = 1; l < p->levels; ++l) {
                    uint32_t bu, bv;
                    const float *b = vsgl__mrp_level(p, side, l, &bu, &bv, &st);
                    VT_CHECK(st == 4 && bu == (p->nu + (1u << l) - 1) >> l && bv == (p->nv + (1u << l) - 1) >> l,
                             "level %u: %u x %u, stride %u", l, bu, bv, st);
                    for (uint32_t jv = 0; jv < bv; ++jv)
                        for (uint32_t ju = 0; ju < bu; ++ju) {
                            double sum[3] = {0, 0, 0}, lo = 1e30, hi = 0.0;
                            int n = 0;
                            for (uint32_t iv = jv << l; iv < ((jv + 1) << l) && iv < p->nv; ++iv)
                                for (uint32_t iu = ju << l; iu < ((ju + 1) << l) && iu < p->nu; ++iu, ++n) {
                                    const float *q = l0 + ((size_t)iv * p->nu + iu) * 3;
                                    double t = (double)q[0] + q[1] + q[2];
                                    lo = t < lo ? t : lo;
                                    hi = t > hi ? t : hi;
                                    for (int ch = 0; ch < 3; ++ch)
                                        sum[ch] += q[ch];
                                }
                            const float *o = b + ((size_t)jv * bu + ju) * 4;
                            for (int ch = 0; ch < 3; ++ch)
                                VT_CHECK_ABS(o[ch], sum[ch] / n, 1e-6 * (1.0 + sum[ch] / n),
                                             "cells %u side %d level %u block %u,%u channel %d", cells[c], side, l, ju,
                                             jv, ch);
                            double want = hi > 0.0 ? (hi - lo) / (hi + lo) : 0.0;
                            VT_CHECK_ABS(o[3], want, 1e-6, "contrast of block %u,%u level %u", ju, jv, l);
                        }
                }
            }
        }
        vsgl__mrp_proxies_free(&set);
    }
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

static vsgl_result render_mrp(vsgl_context *ctx, vsgl_scene *scene, float min_area, uint32_t w, uint32_t h,
                              float *glossy)
{
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
    s.glossy_mode = VSGL_GLOSSY_MRP;
    s.rsm_resolution = 64;
    s.mrp_min_area = min_area;
    vsgl_render_output out;
    memset(&out, 0, sizeof out);
    out.width = w;
    out.height = h;
    out.glossy = glossy;
    return vsgl_render(ctx, scene, &s, &out, NULL);
}

VT_TEST(mrp_min_area_setting)
{
    const uint32_t w = 32, h = 24;
    const size_t n = (size_t)w * h * 3;
    fx_scene fx;
    room(&fx, w, h);
    vsgl_context *ctx = NULL;
    vsgl_scene *scene = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
    float *g = calloc(2 * n, sizeof(float));
    VT_REQUIRE(g, "memory");
    /* refused by name: negative, NaN, infinite */
    const float bad[3] = {-1.0f, NAN, INFINITY};
    for (int k = 0; k < 3; ++k) {
        vsgl_result r = render_mrp(ctx, scene, bad[k], w, h, g);
        VT_CHECK(r == VSGL_ERROR_INVALID_ARGUMENT && strstr(vsgl_context_last_error(ctx), "mrp_min_area"),
                 "mrp_min_area %g: %d %s", (double)bad[k], r, vsgl_context_last_error(ctx));
    }
    /* 0 is the default (0.25 m^2): the same image */
    VT_REQUIRE(render_mrp(ctx, scene, 0.0f, w, h, g) == VSGL_OK, "render: %s", vsgl_context_last_error(ctx));
    VT_REQUIRE(render_mrp(ctx, scene, VSGL_MRP_MIN_AREA_DEFAULT, w, h, g + n) == VSGL_OK, "render");
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        VT_CHECK(g[i] == g[n + i], "0 and the default differ at %zu: %g %g", i, g[i], g[n + i]);
        sum += g[i];
    }
    VT_CHECK(sum > 0.0, "the lit wall reflected: %g", sum);
    /* 18 m^2 keeps the back wall (18 m^2) and the floor; 19 m^2 only the floor (36), which
     * is not lit: no glossy light at all */
    VT_REQUIRE(render_mrp(ctx, scene, 18.0f, w, h, g + n) == VSGL_OK, "render");
    double s18 = 0.0;
    for (size_t i = 0; i < n; ++i)
        s18 += g[n + i];
    VT_CHECK(fabs(s18 - sum) <= 1e-6 * sum, "18 m^2: %g vs %g", s18, sum);
    VT_REQUIRE(render_mrp(ctx, scene, 19.0f, w, h, g + n) == VSGL_OK, "render");
    double s19 = 0.0;
    for (size_t i = 0; i < n; ++i)
        s19 += g[n + i];
    VT_CHECK(s19 == 0.0, "19 m^2: no proxy is lit, glossy sum %g", s19);
    free(g);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}
