/* Textures: lookups against direct pixel arithmetic, the camera's DiffCol of
 * a textured plane against the texels each pixel covers, and the light a
 * textured floor reflects against its analytic value. */
#include "harness.h"
#include "scene_fixture.h"

#include "fit/vsgl_set.h"
#include "gbuffer/gbuffer.h"
#include "rsm/rsm.h"
#include "scene/texture.h"

#include <stdlib.h>

static uint32_t rng_state = 12345u;
static float frand(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (float)(rng_state >> 8) * (1.0f / 16777216.0f);
}

static float *random_pixels(uint32_t w, uint32_t h)
{
    float *p = malloc((size_t)w * h * 4 * sizeof(float));
    for (size_t i = 0; i < (size_t)w * h * 4; ++i)
        p[i] = frand();
    return p;
}

/* Direct: the texel (i, j) of level 0 with Blender's extension rules. */
static float texel(const float *p, long w, long h, long i, long j, int wrap, int c)
{
    if (wrap == VSGL_WRAP_REPEAT) {
        i = ((i % w) + w) % w;
        j = ((j % h) + h) % h;
    } else if (wrap == VSGL_WRAP_EXTEND) {
        i = i < 0 ? 0 : (i >= w ? w - 1 : i);
        j = j < 0 ? 0 : (j >= h ? h - 1 : j);
    } else if (i < 0 || j < 0 || i >= w || j >= h) {
        return 0.0f;
    }
    return p[((size_t)j * (size_t)w + (size_t)i) * 4 + (size_t)c];
}

VT_TEST(texture_lookup_matches_direct_pixel_arithmetic)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    const uint32_t w = 37, h = 21; /* odd sizes on purpose */
    float *px = random_pixels(w, h);
    vsgl_texture in = {w, h, px, 0, 0};
    vsgl_tex t;
    VT_CHECK(vsgl__texture_build(ctx, 0, &in, &t) == VSGL_OK, "build");
    VT_CHECK(t.levels == 7 && t.lv[6].w == 1 && t.lv[6].h == 1, "levels %u", t.levels);
    double worst = 0.0;
    for (int wrap = 0; wrap < 3; ++wrap)
        for (int k = 0; k < 500; ++k) {
            float u = frand() * 3.0f - 1.0f, v = frand() * 3.0f - 1.0f;
            if (wrap == VSGL_WRAP_CLIP) { u = frand() * 1.2f - 0.1f; v = frand() * 1.2f - 0.1f; }
            float got[4];
            vsgl__texture_lookup(&t, u, v, 0.0f, VSGL_FILTER_LINEAR, wrap, got);
            float uu = u, vv = v;
            int outside = wrap == VSGL_WRAP_CLIP && (u < 0 || u > 1 || v < 0 || v > 1);
            if (wrap == VSGL_WRAP_EXTEND) { uu = fminf(fmaxf(u, 0), 1); vv = fminf(fmaxf(v, 0), 1); }
            double x = (double)uu * w - 0.5, y = (double)vv * h - 0.5;
            long i0 = (long)floor(x), j0 = (long)floor(y);
            double fx = x - i0, fy = y - j0;
            for (int c = 0; c < 4; ++c) {
                double want = outside ? 0.0 :
                    (1 - fx) * (1 - fy) * texel(px, w, h, i0, j0, wrap, c) + fx * (1 - fy) * texel(px, w, h, i0 + 1, j0, wrap, c) +
                    (1 - fx) * fy * texel(px, w, h, i0, j0 + 1, wrap, c) + fx * fy * texel(px, w, h, i0 + 1, j0 + 1, wrap, c);
                double e = fabs(got[c] - want);
                worst = e > worst ? e : worst;
                VT_CHECK(e < 2e-4, "wrap %d uv (%g, %g) ch %d got %g want %g", wrap, u, v, c, got[c], want);
            }
            /* Closest: the texel the point lies in */
            vsgl__texture_lookup(&t, u, v, 0.0f, VSGL_FILTER_CLOSEST, wrap, got);
            long ci = (long)floor((double)uu * w), cj = (long)floor((double)vv * h);
            if (wrap == VSGL_WRAP_EXTEND) { ci = ci >= (long)w ? (long)w - 1 : ci; cj = cj >= (long)h ? (long)h - 1 : cj; }
            VT_CHECK(fabsf(got[0] - (outside ? 0.0f : texel(px, w, h, ci, cj, wrap, 0))) < 1e-6f,
                     "closest wrap %d uv (%g, %g)", wrap, u, v);
        }
    fprintf(stderr, "    bilinear vs direct: worst abs error %.3g\n", worst);
    vsgl__texture_free(&t);
    free(px);

    /* Power-of-two: level k's texels are the averages of 2^k x 2^k blocks, and
     * the top level is the mean of the image */
    const uint32_t W = 64, H = 32;
    px = random_pixels(W, H);
    vsgl_texture in2 = {W, H, px, 0, 0};
    VT_CHECK(vsgl__texture_build(ctx, 0, &in2, &t) == VSGL_OK, "build");
    for (int k = 1; k <= 4; ++k) {
        uint32_t b = 1u << k;
        for (int trial = 0; trial < 20; ++trial) {
            uint32_t bi = (uint32_t)(frand() * (float)(W / b)), bj = (uint32_t)(frand() * (float)(H / b));
            double want[4] = {0, 0, 0, 0};
            for (uint32_t j = bj * b; j < (bj + 1) * b; ++j)
                for (uint32_t i = bi * b; i < (bi + 1) * b; ++i)
                    for (int c = 0; c < 4; ++c)
                        want[c] += px[((size_t)j * W + i) * 4 + c] / (double)(b * b);
            float got[4];
            vsgl__texture_lookup(&t, ((float)bi + 0.5f) * (float)b / (float)W, ((float)bj + 0.5f) * (float)b / (float)H,
                                 (float)k, VSGL_FILTER_LINEAR, VSGL_WRAP_REPEAT, got);
            for (int c = 0; c < 4; ++c)
                VT_CHECK(fabs(got[c] - want[c]) < 1e-5, "level %d block (%u, %u) ch %d got %g want %g", k, bi, bj, c,
                         got[c], want[c]);
        }
    }
    double mean = 0;
    for (size_t i = 0; i < (size_t)W * H; ++i)
        mean += px[i * 4 + 1] / (double)(W * H);
    float got[4];
    vsgl__texture_lookup(&t, 0.3f, 0.7f, 40.0f, VSGL_FILTER_LINEAR, VSGL_WRAP_REPEAT, got);
    VT_CHECK_REL(got[1], mean, 1e-5, "top level is the mean");
    vsgl__texture_free(&t);
    free(px);

    /* sRGB: the finest level is decoded after the bilinear lookup (as Cycles'
     * 8-bit images), coarser levels average decoded values */
    float s2[8] = {0.2f, 0.2f, 0.2f, 1.0f, 0.9f, 0.9f, 0.9f, 1.0f};
    vsgl_texture in4 = {2, 1, s2, VSGL_TEXTURE_FLAG_SRGB, 0};
    VT_CHECK(vsgl__texture_build(ctx, 0, &in4, &t) == VSGL_OK, "build");
    vsgl__texture_lookup(&t, 0.5f, 0.5f, 0.0f, VSGL_FILTER_LINEAR, VSGL_WRAP_EXTEND, got);
    VT_CHECK_REL(got[0], vsgl__srgb_to_linear(0.55f), 1e-5, "decode after interpolation");
    vsgl__texture_lookup(&t, 0.5f, 0.5f, 1.0f, VSGL_FILTER_LINEAR, VSGL_WRAP_EXTEND, got);
    VT_CHECK_REL(got[0], 0.5 * (vsgl__srgb_to_linear(0.2f) + vsgl__srgb_to_linear(0.9f)), 1e-5, "mip of decoded values");
    vsgl__texture_free(&t);
    /* and a single texel (alpha untouched) */
    float s4[4] = {0.5f, 0.04f, 1.0f, 0.5f};
    vsgl_texture in3 = {1, 1, s4, VSGL_TEXTURE_FLAG_SRGB, 0};
    VT_CHECK(vsgl__texture_build(ctx, 0, &in3, &t) == VSGL_OK, "build");
    vsgl__texture_lookup(&t, 0.5f, 0.5f, 0.0f, VSGL_FILTER_LINEAR, VSGL_WRAP_REPEAT, got);
    VT_CHECK_REL(got[0], pow((0.5 + 0.055) / 1.055, 2.4), 1e-5, "sRGB 0.5");
    VT_CHECK_REL(got[1], 0.04 / 12.92, 1e-5, "sRGB 0.04 (linear segment)");
    VT_CHECK_REL(got[2], 1.0, 1e-6, "sRGB 1");
    VT_CHECK_REL(got[3], 0.5, 1e-6, "alpha stays linear");
    vsgl__texture_free(&t);
    vsgl_context_destroy(ctx);
}

/* A W x H orthographic view of a floor quad [-1, 1]^2 with UVs [0, 1]^2
 * textured on material 0 (other materials unused). */
typedef struct tex_plane {
    fx_scene fx;
    float uvs[2 * 12]; /* the floor's two triangles, and an occluder's two (untextured) */
    vsgl_texture tex;
    vsgl_material_textures mt[4];
} tex_plane;

static void make_plane(tex_plane *s, uint32_t w, uint32_t h, const float *pixels, uint32_t tw, uint32_t th)
{
    memset(s, 0, sizeof *s);
    fx_room(&s->fx, w, h, 1.0f, 10.0f);
    s->fx.triangle_count = 2; /* the floor only */
    s->fx.vertex_count = 4;
    const float uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const uint32_t tri[6] = {0, 1, 2, 0, 2, 3};
    for (int k = 0; k < 6; ++k) {
        s->uvs[k * 2] = uv[tri[k]][0];
        s->uvs[k * 2 + 1] = uv[tri[k]][1];
    }
    vsgl_material *m = &s->fx.materials[0];
    m->base_color[0] = m->base_color[1] = m->base_color[2] = 1.0f;
    m->specular_f0 = 0.0f;
    m->roughness = 1.0f;
    vsgl_camera *c = &s->fx.camera;
    c->type = VSGL_CAMERA_ORTHOGRAPHIC;
    c->ortho_scale = 2.0f;
    const float eye[3] = {0, 0, 3}, at[3] = {0, 0, 0};
    fx_look_at(c->world_from_camera, eye, at);
    s->tex = (vsgl_texture){tw, th, pixels, 0, 0};
    s->mt[0].base_color.texture = 1;
}

static const vsgl_scene_desc *plane_desc(tex_plane *s)
{
    vsgl_scene_desc *d = (vsgl_scene_desc *)fx_desc(&s->fx);
    d->corner_uvs = s->uvs;
    d->texture_count = 1;
    d->textures = &s->tex;
    d->material_textures = s->mt;
    return d;
}

VT_TEST(texture_gbuffer_colour_is_the_texels_each_pixel_covers)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    const uint32_t W = 16, H = 16;
    for (uint32_t scale = 1; scale <= 8; scale *= 2) {
        uint32_t tw = W * scale, th = H * scale;
        float *px = random_pixels(tw, th);
        tex_plane s;
        make_plane(&s, W, H, px, tw, th);
        vsgl_scene *sc = NULL;
        VT_CHECK(vsgl_scene_create(ctx, plane_desc(&s), &sc) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        vsgl_gbuffer g;
        VT_CHECK(vsgl__gbuffer_build(ctx, sc, 1, 0, &g) == VSGL_OK, "gbuffer");
        VT_CHECK(g.surf[0] != NULL, "textured scene keeps per-sample inputs");
        double worst = 0;
        for (uint32_t row = 0; row < H; ++row)
            for (uint32_t col = 0; col < W; ++col) {
                /* image row 0 is the top: v = 1 there (the camera's up is +y) */
                uint32_t j0 = (H - 1 - row) * scale, i0 = col * scale;
                for (int c = 0; c < 3; ++c) {
                    double want = 0;
                    for (uint32_t j = j0; j < j0 + scale; ++j)
                        for (uint32_t i = i0; i < i0 + scale; ++i)
                            want += px[((size_t)j * tw + i) * 4 + c] / (double)(scale * scale);
                    double got = g.surf[VSGL__SURF_BASE + c][row * W + col];
                    worst = fmax(worst, fabs(got - want));
                }
            }
        VT_CHECK(worst < 2e-3, "texture %ux scale %u: worst |DiffCol - mean of the pixel's texels| = %g", tw, scale, worst);
        vsgl__gbuffer_free(&g);
        vsgl_scene_destroy(sc);
        free(px);
    }
    vsgl_context_destroy(ctx);
}

/* The share of pixel (col, row) of a W x W view of make_plane's floor that
 * lies left of the line x = e0 + (e1 - e0) (y + 1) / 2 (world units), and
 * the mean of texel channel c over it: texels (scale^2 per pixel) by
 * their centres. */
static double left_share_mean(const float *px, uint32_t W, uint32_t scale, uint32_t col, uint32_t row, double e0,
                              double e1, int c, double *share)
{
    const uint32_t tw = W * scale;
    double sum = 0.0, n = 0.0;
    for (uint32_t jj = 0; jj < scale; ++jj)
        for (uint32_t ii = 0; ii < scale; ++ii) {
            uint32_t i = col * scale + ii, j = (W - 1 - row) * scale + jj;
            double x = -1.0 + 2.0 * (i + 0.5) / tw, y = -1.0 + 2.0 * (j + 0.5) / tw;
            if (x < e0 + (e1 - e0) * (y + 1.0) / 2.0) {
                sum += px[((size_t)j * tw + i) * 4 + c];
                n += 1.0;
            }
        }
    *share = n / (double)(scale * scale);
    return n > 0.0 ? sum / n : 0.0;
}

VT_TEST(texture_edge_slot_filters_its_share_of_the_pixel)
{
    /* A slanted occluder (untextured, 0.5 above the floor) covers the
     * textured floor right of a line across a 16 x 16 top view, 8 x 8
     * random texels per pixel (deviation 0.29), 3 x 3 samples per pixel
     * (the quality preset) and 12 x 12 edge rays: each edge pixel keeps
     * one slot for the floor, weighted by its share of the pixel. Its
     * colour is one texture lookup at its ray nearest the share's centre,
     * filtered over a first-pass sample's footprint (2/3 of a pixel at
     * 3 x 3), and should be the mean of the texels in its share: RMS
     * error 0.045 over the edge slots. Filtered over k sqrt(weight) of a
     * pixel instead (the share's side, as a first-pass sample's is 1/3,
     * times k): k = 1 0.046, 1.5 0.051, 2 0.055. The wider filter steadies
     * the textured room's quality camera animation (Diff flicker 0.0174 ->
     * 0.0161) by blurring the edge slots, so it is not taken
     * (docs/accuracy.md, "A textured edge slot's filter"). Asks < 0.05. */
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    const uint32_t W = 16, scale = 8, tw = W * scale;
    float *px = random_pixels(tw, tw);
    tex_plane s;
    make_plane(&s, W, W, px, tw, tw);
    const double e0 = 0.03, e1 = 0.61; /* the line's x at y = -1 and y = 1 */
    const float occ[4][3] = {{(float)e0, -1.0f, 0.5f}, {1.5f, -1.0f, 0.5f}, {1.5f, 1.0f, 0.5f}, {(float)e1, 1.0f, 0.5f}};
    fx_quad(&s.fx, occ, 1);
    vsgl_scene *sc = NULL;
    VT_CHECK(vsgl_scene_create(ctx, plane_desc(&s), &sc) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    vsgl_gbuffer g;
    VT_CHECK(vsgl__gbuffer_build(ctx, sc, 3, 12, &g) == VSGL_OK, "gbuffer");
    double se = 0.0;
    size_t n = 0;
    for (uint32_t row = 0; row < W && g.weight; ++row)
        for (uint32_t col = 0; col < W; ++col)
            for (uint32_t q = 0; q < g.spp; ++q) {
                const size_t i = ((size_t)row * W + col) * g.spp + q;
                if (!g.refined || g.refined[(size_t)row * W + col] != VSGL__GBUFFER_REFINED || g.material[i] != 0 ||
                    g.weight[i] > 0.9f || g.weight[i] < 0.1f)
                    continue; /* the floor's slot of an edge pixel */
                for (int c = 0; c < 3; ++c) {
                    double share, want = left_share_mean(px, W, scale, col, row, e0, e1, c, &share);
                    VT_CHECK(fabs(share - g.weight[i]) < 0.1, "pixel (%u, %u): slot weight %g, share %g", col, row,
                             (double)g.weight[i], share);
                    double d = g.surf[VSGL__SURF_BASE + c][i] - want;
                    se += d * d;
                    ++n;
                }
            }
    VT_CHECK(n >= 3 * 12, "%zu edge slots' channels (a line across 16 rows)", n);
    double rms = sqrt(se / (double)(n ? n : 1));
    VT_CHECK(rms < 0.05, "RMS |edge slot colour - mean of its share's texels| = %.4f over %zu channels", rms, n);
    vsgl__gbuffer_free(&g);
    vsgl_scene_destroy(sc);
    free(px);
    vsgl_context_destroy(ctx);
}

VT_TEST(texture_rsm_reflected_power_matches_analytic)
{
    /* A sun of irradiance E straight down on the textured floor (4 m^2):
     * the diffuse power its VPLs reflect is E x integral of the albedo =
     * E x 4 x mean(texture), at every RSM size (the footprint picks the mip). */
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    const uint32_t tw = 256, th = 128;
    float *px = random_pixels(tw, th);
    for (size_t i = 0; i < (size_t)tw * th; ++i) { /* a ramp so that the mean is not 0.5 by chance */
        px[i * 4 + 0] *= (float)(i % tw) / (float)tw;
        px[i * 4 + 2] *= 0.2f;
    }
    double mean[3] = {0, 0, 0};
    for (size_t i = 0; i < (size_t)tw * th; ++i)
        for (int c = 0; c < 3; ++c)
            mean[c] += px[i * 4 + c] / (double)(tw * th);
    tex_plane s;
    make_plane(&s, 8, 8, px, tw, th);
    vsgl_light *L = &s.fx.lights[0];
    memset(L, 0, sizeof *L);
    L->type = VSGL_LIGHT_SUN;
    L->color[0] = L->color[1] = L->color[2] = 1.0f;
    L->power = 3.0f;
    fx_translation(L->world_from_light, 0, 0, 5);
    vsgl_scene *sc = NULL;
    VT_CHECK(vsgl_scene_create(ctx, plane_desc(&s), &sc) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    for (uint32_t res = 32; res <= 256; res *= 2) {
        vsgl_rsm r;
        VT_CHECK(vsgl__rsm_build(ctx, sc, 0, res, &r) == VSGL_OK, "rsm");
        double pd[3] = {0, 0, 0};
        for (size_t t = 0; t < r.count; ++t) {
            vsgl_moments mo[2];
            if (vsgl__vpl_moments(sc, &r, t, v3_make(0, 0, 0), VSGL_SHARPNESS_TOKSVIG, mo))
                for (int c = 0; c < 3; ++c)
                    pd[c] += mo[VSGL__LOBE_DIFFUSE].power[c];
        }
        for (int c = 0; c < 3; ++c)
            VT_CHECK_REL(pd[c], 3.0 * 4.0 * mean[c], 0.01, "res %u channel %d (mean albedo %g)", res, c, mean[c]);
        vsgl__rsm_free(&r);
    }
    vsgl_scene_destroy(sc);
    free(px);
    vsgl_context_destroy(ctx);
}

VT_TEST(texture_validation_and_old_desc_size)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    float px[4] = {1, 0, 0, 1};
    tex_plane s;
    make_plane(&s, 8, 8, px, 1, 1);
    vsgl_scene *sc = NULL;
    s.mt[0].base_color.texture = 2;
    VT_CHECK(vsgl_scene_create(ctx, plane_desc(&s), &sc) == VSGL_ERROR_INVALID_ARGUMENT, "texture index");
    VT_CHECK(strstr(vsgl_context_last_error(ctx), "material 0: base_color texture is 2") != NULL, "%s",
             vsgl_context_last_error(ctx));
    s.mt[0].base_color.texture = 1;
    s.mt[0].base_color.wrap = 7;
    VT_CHECK(vsgl_scene_create(ctx, plane_desc(&s), &sc) == VSGL_ERROR_INVALID_ARGUMENT, "wrap");
    s.mt[0].base_color.wrap = 0;
    px[1] = NAN;
    VT_CHECK(vsgl_scene_create(ctx, plane_desc(&s), &sc) == VSGL_ERROR_INVALID_ARGUMENT, "NaN texel");
    VT_CHECK(strstr(vsgl_context_last_error(ctx), "texture 0: texel (0, 0) channel 1 is nan") != NULL, "%s",
             vsgl_context_last_error(ctx));
    px[1] = 0;
    /* a 0.1 caller: the smaller size, whatever follows is not read */
    vsgl_scene_desc *d = (vsgl_scene_desc *)plane_desc(&s);
    d->size = VSGL_SCENE_DESC_SIZE_0_1;
    d->texture_count = 99; /* garbage past the old struct */
    VT_CHECK(vsgl_scene_create(ctx, d, &sc) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(sc && !vsgl__scene_textured(sc), "0.1 desc has no textures");
    vsgl_scene_destroy(sc);
    vsgl_context_destroy(ctx);
}

VT_TEST(texture_bundle_roundtrip_keeps_textures)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    float *px = random_pixels(5, 3);
    tex_plane s;
    make_plane(&s, 8, 8, px, 5, 3);
    s.tex.flags = VSGL_TEXTURE_FLAG_SRGB;
    s.mt[0].base_color.wrap = VSGL_WRAP_CLIP;
    s.mt[0].base_color.uv_transform[0] = 2.0f;
    s.mt[0].base_color.uv_transform[4] = 3.0f;
    s.mt[0].roughness = s.mt[0].base_color;
    s.mt[0].roughness.channel = 2;
    s.mt[0].flags = VSGL_MATERIAL_TEXTURES_VERTEX_COLOR;
    float cc[2 * 9];
    for (int k = 0; k < 18; ++k)
        cc[k] = frand();
    vsgl_scene_desc *d = (vsgl_scene_desc *)plane_desc(&s);
    d->corner_colors = cc;
    size_t n = 0;
    VT_CHECK(vsgl_bundle_write_memory(ctx, d, NULL, NULL, NULL, 0, &n) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    unsigned char *b = malloc(n);
    VT_CHECK(vsgl_bundle_write_memory(ctx, d, NULL, NULL, b, n, &n) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    vsgl_bundle *bd = NULL;
    VT_CHECK(vsgl_bundle_read_memory(ctx, b, n, &bd) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    if (bd) {
        const vsgl_scene_desc *r = vsgl_bundle_scene(bd);
        VT_CHECK(r->texture_count == 1 && r->textures[0].width == 5 && r->textures[0].height == 3 &&
                     r->textures[0].flags == VSGL_TEXTURE_FLAG_SRGB,
                 "texture header");
        VT_CHECK(r->textures && memcmp(r->textures[0].pixels, px, 5 * 3 * 4 * sizeof(float)) == 0, "pixels");
        VT_CHECK(r->material_textures && memcmp(r->material_textures, s.mt, 4 * sizeof s.mt[0]) == 0, "material textures");
        VT_CHECK(r->corner_colors && memcmp(r->corner_colors, cc, sizeof cc) == 0, "corner colours");
        vsgl_scene *sc = NULL;
        VT_CHECK(vsgl_scene_create(ctx, r, &sc) == VSGL_OK && vsgl__scene_textured(sc), "%s", vsgl_context_last_error(ctx));
        vsgl_scene_destroy(sc);
        /* and it rewrites to the same bytes */
        size_t n2 = 0;
        unsigned char *b2 = malloc(n);
        VT_CHECK(vsgl_bundle_write_memory(ctx, r, NULL, NULL, b2, n, &n2) == VSGL_OK && n2 == n && memcmp(b, b2, n) == 0,
                 "rewrite differs");
        free(b2);
    }
    vsgl_bundle_destroy(bd);
    /* a truncated pixel section is refused */
    free(b);
    free(px);
    vsgl_context_destroy(ctx);
}
