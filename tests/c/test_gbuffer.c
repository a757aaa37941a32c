/* Camera G-buffer against analytic planes: sample positions, normals,
 * view vectors, misses, clipping, determinism, progress and cancellation. */
#include "harness.h"
#include "vsgl.h"
#include "vsgl/debug.h"
#include "core/context.h"
#include "gbuffer/gbuffer.h"
#include "math/constants.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct plane_scene {
    float pos[12];
    uint32_t ix[6];
    vsgl_material mat;
    vsgl_camera cam;
    vsgl_scene_desc desc;
} plane_scene;

/* Quad z = z0 spanning [-half, half]^2, winding facing +z (or -z if flip). */
static void plane_init(plane_scene *p, float z0, float half, int flip)
{
    memset(p, 0, sizeof *p);
    float v[12] = {-half, -half, z0, half, -half, z0, half, half, z0, -half, half, z0};
    memcpy(p->pos, v, sizeof v);
    uint32_t a[6] = {0, 1, 2, 0, 2, 3}, b[6] = {0, 2, 1, 0, 3, 2};
    memcpy(p->ix, flip ? b : a, sizeof a);
    p->mat.base_color[0] = 0.5f;
    vsgl_camera *c = &p->cam;
    c->type = VSGL_CAMERA_PERSPECTIVE;
    c->world_from_camera[0] = c->world_from_camera[5] = c->world_from_camera[10] = 1.0f;
    c->lens_mm = 50.0f;
    c->sensor_width_mm = 36.0f;
    c->sensor_height_mm = 24.0f;
    c->ortho_scale = 4.0f;
    c->clip_start = 0.1f;
    c->clip_end = 100.0f;
    c->width = 64;
    c->height = 48;
    c->pixel_aspect_x = c->pixel_aspect_y = 1.0f;
    p->desc.vertex_count = 4;
    p->desc.positions = p->pos;
    p->desc.triangle_count = 2;
    p->desc.indices = p->ix;
    p->desc.material_count = 1;
    p->desc.materials = &p->mat;
    p->desc.camera = &p->cam;
}

static vsgl_context *make_ctx(uint32_t threads)
{
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.thread_count = threads;
    vsgl_context *ctx = NULL;
    vsgl_context_create(&cd, &ctx);
    return ctx;
}

/* Analytic hit of sample (col, row, i, j) of the default camera on z = z0:
 * a horizontal-fit 36 mm sensor at 50 mm, 64 x 48 pixels. */
static void analytic_point(double z0, uint32_t col, uint32_t row, uint32_t i, uint32_t j, uint32_t aa, double out[3])
{
    /* the sheared aa x aa grid of gbuffer.h (vsgl__gbuffer_pattern) */
    double px = col + (i + (j + 0.5) / aa) / aa, py = row + (j + (i + 0.5) / aa) / aa;
    double hx = 18.0 / 50.0, hy = hx * 48.0 / 64.0;
    double x = (2.0 * px / 64.0 - 1.0) * hx, y = (1.0 - 2.0 * py / 48.0) * hy;
    out[0] = x * -z0;
    out[1] = y * -z0;
    out[2] = z0;
}

VT_TEST(gbuffer_perspective_plane_matches_analytic_points)
{
    vsgl_context *ctx = make_ctx(2);
    plane_scene p;
    plane_init(&p, -5.0f, 100.0f, 0);
    vsgl_scene *s = NULL;
    VT_CHECK(vsgl_scene_create(ctx, &p.desc, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    for (uint32_t aa = 1; s && aa <= 3; ++aa) {
        vsgl_gbuffer g;
        vsgl_result r = vsgl__gbuffer_build(ctx, s, aa, 0, &g);
        VT_CHECK(r == VSGL_OK && g.count == 64u * 48u * aa * aa && g.spp == aa * aa && g.width == 64 && g.height == 48,
                 "aa %u: r %d count %zu", aa, r, g.count);
        if (r != VSGL_OK)
            continue;
        double maxerr = 0, maxn = 0, maxv = 0;
        for (uint32_t row = 0; row < 48; ++row)
            for (uint32_t col = 0; col < 64; ++col)
                for (uint32_t sidx = 0; sidx < aa * aa; ++sidx) {
                    size_t e = ((size_t)row * 64 + col) * aa * aa + sidx;
                    double want[3];
                    analytic_point(-5.0, col, row, sidx % aa, sidx / aa, aa, want);
                    double err = fabs(g.pos[0][e] - want[0]) + fabs(g.pos[1][e] - want[1]) + fabs(g.pos[2][e] - want[2]);
                    if (err > maxerr) maxerr = err;
                    double nerr = fabs(g.nrm[0][e]) + fabs(g.nrm[1][e]) + fabs(g.nrm[2][e] - 1.0);
                    if (nerr > maxn) maxn = nerr;
                    double l = sqrt(want[0] * want[0] + want[1] * want[1] + 25.0);
                    double verr = fabs(g.view[0][e] + want[0] / l) + fabs(g.view[1][e] + want[1] / l) + fabs(g.view[2][e] - 5.0 / l);
                    if (verr > maxv) maxv = verr;
                    VT_CHECK(g.material[e] == 0, "aa %u pixel (%u %u) s %u: material %u", aa, col, row, sidx, g.material[e]);
                    if (err > 1e-4)
                        VT_CHECK(0, "aa %u pixel (%u %u) s %u: (%g %g %g) want (%g %g %g)", aa, col, row, sidx,
                                 g.pos[0][e], g.pos[1][e], g.pos[2][e], want[0], want[1], want[2]);
                    float td = g.tan[0][e] * g.nrm[0][e] + g.tan[1][e] * g.nrm[1][e] + g.tan[2][e] * g.nrm[2][e];
                    float tl = g.tan[0][e] * g.tan[0][e] + g.tan[1][e] * g.tan[1][e] + g.tan[2][e] * g.tan[2][e];
                    if (fabsf(td) > 1e-6f || fabsf(tl - 1) > 1e-5f)
                        VT_CHECK(0, "pixel (%u %u): tangent.n %g |t|^2 %g", col, row, td, tl);
                }
        VT_CHECK(maxerr < 1e-4 && maxn < 1e-6 && maxv < 1e-5, "aa %u: max position error %g m, normal %g, view %g", aa,
                 maxerr, maxn, maxv);
        vsgl__gbuffer_free(&g);
        VT_CHECK(g.pos[0] == NULL && g.count == 0, "free clears");
    }
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

VT_TEST(gbuffer_misses_backfaces_and_clipping)
{
    vsgl_context *ctx = make_ctx(2);
    plane_scene p;
    /* back-facing quad of half-size 1 at z = -5: covers |x| <= 1 of the +-1.8 view */
    plane_init(&p, -5.0f, 1.0f, 1);
    vsgl_scene *s = NULL;
    VT_CHECK(vsgl_scene_create(ctx, &p.desc, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    vsgl_gbuffer g;
    if (s && vsgl__gbuffer_build(ctx, s, 1, 0, &g) == VSGL_OK) {
        size_t hits = 0, want_hits = 0;
        for (uint32_t row = 0; row < 48; ++row)
            for (uint32_t col = 0; col < 64; ++col) {
                size_t e = (size_t)row * 64 + col;
                double w[3];
                analytic_point(-5.0, col, row, 0, 0, 1, w);
                int inside = fabs(w[0]) < 1.0 && fabs(w[1]) < 1.0;
                int edge = fabs(fabs(w[0]) - 1.0) < 1e-3 || fabs(fabs(w[1]) - 1.0) < 1e-3;
                int hit = g.material[e] != VSGL__GBUFFER_MISS;
                want_hits += (size_t)inside;
                hits += (size_t)hit;
                if (!edge)
                    VT_CHECK(hit == inside, "pixel (%u %u) at (%g %g): hit %d", col, row, w[0], w[1], hit);
                if (hit)
                    VT_CHECK(g.nrm[2][e] == 1.0f, "pixel (%u %u): back face normal z %g (want +1, facing the camera)",
                             col, row, g.nrm[2][e]);
                else
                    VT_CHECK(g.pos[0][e] == 0 && g.nrm[2][e] == 0 && g.view[2][e] > 0, "pixel (%u %u): miss not cleared", col, row);
            }
        VT_CHECK(hits == want_hits && hits > 0, "hits %zu want %zu", hits, want_hits);
        vsgl__gbuffer_free(&g);
    }
    vsgl_scene_destroy(s);
    /* clip range: depth 5 outside [6, 100] and [0.1, 4.9] -> nothing; [4.9, 5.1] -> everything */
    float ranges[3][2] = {{6.0f, 100.0f}, {0.1f, 4.9f}, {4.9f, 5.1f}};
    plane_init(&p, -5.0f, 100.0f, 0);
    for (int k = 0; k < 3; ++k)
        for (int type = 0; type < 2; ++type) {
            p.cam.type = type;
            p.cam.clip_start = ranges[k][0];
            p.cam.clip_end = ranges[k][1];
            s = NULL;
            VT_CHECK(vsgl_scene_create(ctx, &p.desc, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
            if (s && vsgl__gbuffer_build(ctx, s, 1, 0, &g) == VSGL_OK) {
                size_t hits = 0;
                for (size_t e = 0; e < g.count; ++e)
                    hits += g.material[e] != VSGL__GBUFFER_MISS;
                VT_CHECK(hits == (k == 2 ? g.count : 0), "type %d clip [%g, %g]: %zu hits of %zu", type, ranges[k][0],
                         ranges[k][1], hits, g.count);
                vsgl__gbuffer_free(&g);
            }
            vsgl_scene_destroy(s);
        }
    vsgl_context_destroy(ctx);
}

VT_TEST(gbuffer_orthographic_positions)
{
    vsgl_context *ctx = make_ctx(2);
    plane_scene p;
    plane_init(&p, -3.0f, 10.0f, 0);
    p.cam.type = VSGL_CAMERA_ORTHOGRAPHIC;
    p.cam.ortho_scale = 4.0f;
    p.cam.shift_y = 0.25f;
    /* camera at (1, 2, 0), axis-aligned */
    p.cam.world_from_camera[3] = 1.0f;
    p.cam.world_from_camera[7] = 2.0f;
    vsgl_scene *s = NULL;
    VT_CHECK(vsgl_scene_create(ctx, &p.desc, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    vsgl_gbuffer g;
    if (s && vsgl__gbuffer_build(ctx, s, 2, 0, &g) == VSGL_OK) {
        double maxerr = 0;
        for (uint32_t row = 0; row < 48; ++row)
            for (uint32_t col = 0; col < 64; ++col)
                for (uint32_t k = 0; k < 4; ++k) {
                    size_t e = ((size_t)row * 64 + col) * 4 + k;
                    double px = col + (k % 2 + (k / 2 + 0.5) / 2) / 2, py = row + (k / 2 + (k % 2 + 0.5) / 2) / 2;
                    /* 4 m across 64 px; 3 m across 48 px; shift 0.25 * 4 m up */
                    double x = 1.0 + (px / 64.0 - 0.5) * 4.0, y = 2.0 + (0.5 - py / 48.0) * 3.0 + 1.0;
                    double err = fabs(g.pos[0][e] - x) + fabs(g.pos[1][e] - y) + fabs(g.pos[2][e] + 3.0);
                    if (err > maxerr) maxerr = err;
                    if (err > 1e-5)
                        VT_CHECK(0, "pixel (%u %u) s %u: (%g %g %g) want (%g %g -3)", col, row, k, g.pos[0][e], g.pos[1][e],
                                 g.pos[2][e], x, y);
                    if (g.view[2][e] != 1.0f)
                        VT_CHECK(0, "ortho view (%g %g %g)", g.view[0][e], g.view[1][e], g.view[2][e]);
                }
        VT_CHECK(maxerr < 1e-5, "max error %g", maxerr);
        vsgl__gbuffer_free(&g);
    }
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* A random triangle soup: the buffer is bit-identical for 1, 2 and 5 threads. */
VT_TEST(gbuffer_is_deterministic_across_thread_counts)
{
    enum { T = 300 };
    static float pos[T * 9];
    static uint32_t ix[T * 3];
    vt_rng rng = {5};
    for (int i = 0; i < T * 9; ++i)
        pos[i] = (float)(vt_uniform(&rng) * 4 - 2) + ((i % 3 == 2) ? -6.0f : 0.0f);
    for (int i = 0; i < T * 3; ++i)
        ix[i] = (uint32_t)i;
    plane_scene p;
    plane_init(&p, -5.0f, 1.0f, 0);
    p.desc.vertex_count = T * 3;
    p.desc.positions = pos;
    p.desc.triangle_count = T;
    p.desc.indices = ix;
    vsgl_gbuffer ref;
    memset(&ref, 0, sizeof ref);
    uint32_t threads[3] = {1, 2, 5};
    for (int k = 0; k < 3; ++k) {
        vsgl_context *ctx = make_ctx(threads[k]);
        vsgl_scene *s = NULL;
        VT_CHECK(vsgl_scene_create(ctx, &p.desc, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
        vsgl_gbuffer g;
        if (s && vsgl__gbuffer_build(ctx, s, 2, 0, &g) == VSGL_OK) {
            if (k == 0) {
                ref = g;
            } else {
                int same = memcmp(g.material, ref.material, g.count * 4) == 0;
                for (int c = 0; c < 3; ++c)
                    same &= memcmp(g.pos[c], ref.pos[c], g.count * 4) == 0 && memcmp(g.nrm[c], ref.nrm[c], g.count * 4) == 0 &&
                            memcmp(g.tan[c], ref.tan[c], g.count * 4) == 0 && memcmp(g.view[c], ref.view[c], g.count * 4) == 0;
                VT_CHECK(same, "threads %u differ from 1 thread", threads[k]);
                vsgl__gbuffer_free(&g);
            }
        }
        vsgl_scene_destroy(s);
        vsgl_context_destroy(ctx);
    }
    size_t hits = 0;
    for (size_t e = 0; e < ref.count; ++e)
        hits += ref.material[e] != VSGL__GBUFFER_MISS;
    VT_CHECK(hits > ref.count / 10 && hits < ref.count, "soup covers %zu of %zu samples", hits, ref.count);
    vsgl__gbuffer_free(&ref);
}

/* Edge refinement (gbuffer/edges.c): a plane whose slanted edge crosses the
 * image. The coverage of every pixel (the weights of its hit samples) is
 * compared with the exact fraction of the pixel inside the edge, from 200 x
 * 200 points mapped through the camera analytically (no ray tracing): 2 x 2
 * samples quantise it to quarters (error up to 0.5), 16 x 16 edge rays to
 * 1/256 of the pixel. Weights sum to 1, pixels away from the edge are the
 * unrefined buffer's, and the result does not depend on the thread count. */
static double exact_coverage(uint32_t col, uint32_t row, double x0, double k, double z0)
{
    const int n = 200;
    double hx = 18.0 / 50.0, hy = hx * 48.0 / 64.0;
    int in = 0;
    for (int b = 0; b < n; ++b)
        for (int a = 0; a < n; ++a) {
            double px = col + (a + 0.5) / n, py = row + (b + 0.5) / n;
            double x = (2.0 * px / 64.0 - 1.0) * hx * -z0, y = (1.0 - 2.0 * py / 48.0) * hy * -z0;
            in += x < x0 + k * y;
        }
    return (double)in / (n * n);
}

/* The plane z = z0, half-width h, cut by the slanted edge x = x0 + k y. */
static void slanted_plane(plane_scene *p, float z0, float x0, float k, float h)
{
    plane_init(p, z0, h, 0);
    float v[12] = {-h, -h, z0, x0 - k * h, -h, z0, x0 + k * h, h, z0, -h, h, z0};
    memcpy(p->pos, v, sizeof v);
}

VT_TEST(gbuffer_edge_refinement_resolves_coverage)
{
    const float z0 = -5.0f, x0 = 0.3f, k = 0.37f;
    plane_scene p;
    slanted_plane(&p, z0, x0, k, 100.0f);
    vsgl_gbuffer ref[2];
    memset(ref, 0, sizeof ref);
    uint32_t threads[2] = {1, 2};
    double worst[2] = {0, 0}, mean_err[2] = {0, 0};
    size_t edge_px = 0, changed_non_edge = 0, bad_weights = 0;
    for (int t = 0; t < 2; ++t) {
        vsgl_context *ctx = make_ctx(threads[t]);
        vsgl_scene *s = NULL;
        VT_REQUIRE(vsgl_scene_create(ctx, &p.desc, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
        vsgl_gbuffer plain, fine;
        VT_REQUIRE(vsgl__gbuffer_build(ctx, s, 2, 0, &plain) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
        VT_REQUIRE(vsgl__gbuffer_build(ctx, s, 2, 16, &fine) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
        VT_CHECK(plain.weight == NULL && fine.weight != NULL, "weights only when refining");
        if (t == 0) {
            edge_px = fine.edge_pixels;
            for (uint32_t row = 0; row < 48; ++row)
                for (uint32_t col = 0; col < 64; ++col) {
                    size_t base = ((size_t)row * 64 + col) * 4;
                    double want = exact_coverage(col, row, x0, k, z0), cov[2] = {0, 0}, wsum = 0;
                    for (int q = 0; q < 4; ++q) {
                        cov[0] += plain.material[base + q] != VSGL__GBUFFER_MISS ? 0.25 : 0.0;
                        cov[1] += fine.material[base + q] != VSGL__GBUFFER_MISS ? fine.weight[base + q] : 0.0;
                        wsum += fine.weight[base + q];
                    }
                    bad_weights += fabs(wsum - 1.0) > 1e-5;
                    for (int m = 0; m < 2; ++m) {
                        double e = fabs(cov[m] - want);
                        worst[m] = e > worst[m] ? e : worst[m];
                        mean_err[m] += e / (64.0 * 48.0);
                    }
                    if (want == 0.0 || want == 1.0) {
                        /* far from the edge: the unrefined samples, unweighted */
                        int near = exact_coverage(col > 0 ? col - 1 : col, row, x0, k, z0) != want ||
                                   exact_coverage(col < 63 ? col + 1 : col, row, x0, k, z0) != want;
                        if (!near)
                            for (int q = 0; q < 4; ++q)
                                changed_non_edge += fine.material[base + q] != plain.material[base + q] ||
                                                    fine.pos[0][base + q] != plain.pos[0][base + q] ||
                                                    fine.weight[base + q] != 0.25f;
                    }
                }
        }
        ref[t] = fine;
        vsgl__gbuffer_free(&plain);
        vsgl_scene_destroy(s);
        vsgl_context_destroy(ctx);
    }
    printf("    edge pixels %zu; coverage error worst/mean: 2x2 %.3f / %.4f, 16x16 edge rays %.3f / %.4f\n", edge_px,
           worst[0], mean_err[0], worst[1], mean_err[1]);
    VT_CHECK(edge_px >= 48 && edge_px <= 4 * 48, "%zu edge pixels for one edge across 48 rows", edge_px);
    VT_CHECK(worst[0] > 0.1, "the unrefined buffer's coverage error %.3f: the test scene has no edge", worst[0]);
    VT_CHECK(worst[1] < 0.035, "refined coverage off by %.3f (16 x 16 rays: < 1/32)", worst[1]);
    VT_CHECK(bad_weights == 0, "%zu pixels whose weights do not sum to 1", bad_weights);
    VT_CHECK(changed_non_edge == 0, "%zu samples away from the edge changed", changed_non_edge);
    int same = memcmp(ref[0].material, ref[1].material, ref[0].count * 4) == 0 &&
               memcmp(ref[0].weight, ref[1].weight, ref[0].count * 4) == 0;
    for (int c = 0; c < 3; ++c)
        same &= memcmp(ref[0].pos[c], ref[1].pos[c], ref[0].count * 4) == 0;
    VT_CHECK(same, "1 and 2 threads refine differently");
    vsgl__gbuffer_free(&ref[0]);
    vsgl__gbuffer_free(&ref[1]);

    /* one sample per pixel: three slots per pixel, slots 1 and 2 empty (misses
     * of weight 0) except where an edge puts a second surface in them */
    vsgl_context *ctx = make_ctx(2);
    vsgl_scene *s = NULL;
    VT_REQUIRE(vsgl_scene_create(ctx, &p.desc, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    vsgl_gbuffer one;
    VT_REQUIRE(vsgl__gbuffer_build(ctx, s, 1, 16, &one) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    VT_CHECK(one.spp == 3 && one.weight != NULL, "spp %u", one.spp);
    double worst1 = 0.0;
    size_t filled = 0, bad_empty = 0;
    for (uint32_t row = 0; one.spp == 3 && row < 48; ++row)
        for (uint32_t col = 0; col < 64; ++col) {
            size_t base = ((size_t)row * 64 + col) * 3;
            double cov = 0.0;
            for (int q = 0; q < 3; ++q)
                cov += one.material[base + q] != VSGL__GBUFFER_MISS ? one.weight[base + q] : 0.0;
            double e = fabs(cov - exact_coverage(col, row, x0, k, z0));
            worst1 = e > worst1 ? e : worst1;
            if (one.weight[base + 1] > 0.0f)
                ++filled;
            else
                bad_empty += one.material[base + 1] != VSGL__GBUFFER_MISS || one.weight[base] != 1.0f;
            /* one edge in the scene: two surfaces, the third slot stays empty */
            bad_empty += one.material[base + 2] != VSGL__GBUFFER_MISS || one.weight[base + 2] != 0.0f;
        }
    printf("    one sample per pixel: %zu second slots filled, coverage error worst %.3f\n", filled, worst1);
    VT_CHECK(worst1 < 0.035, "coverage off by %.3f at one sample per pixel", worst1);
    VT_CHECK(filled >= 40 && bad_empty == 0, "%zu filled, %zu bad empty slots", filled, bad_empty);
    vsgl__gbuffer_free(&one);
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* A vertical edge sliding across a pixel in 1/32 steps, one sample per
 * pixel and 8 x 8 edge rays: the refined coverage follows it within half
 * of 1/64 (the sheared pattern, gbuffer.h vsgl__gbuffer_pattern: 64
 * distinct columns of rays) and never steps backwards. On the square 8 x 8
 * grid it moved in steps of 1/8, off by up to 1/16 (the corridor's end
 * wall crept in steps as the camera moved, docs/accuracy.md). */
VT_TEST(gbuffer_edge_rays_follow_an_axis_aligned_edge)
{
    const float z0 = -5.0f;
    const double hx = 18.0 / 50.0, width = 2.0 * hx * -z0 / 64.0; /* a pixel's width on the plane, m */
    const uint32_t col = 40, row = 24;
    vsgl_context *ctx = make_ctx(2);
    double worst = 0.0, prev = -1.0;
    size_t backwards = 0, steps = 0;
    for (int t = 0; t < 32; ++t) {
        const double f = (t + 0.25) / 32.0; /* the edge's position within the pixel */
        const float x0 = (float)((2.0 * col / 64.0 - 1.0) * hx * -z0 + f * width);
        plane_scene p;
        slanted_plane(&p, z0, x0, 0.0f, 100.0f);
        vsgl_scene *s = NULL;
        VT_REQUIRE(vsgl_scene_create(ctx, &p.desc, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
        vsgl_gbuffer g;
        VT_REQUIRE(vsgl__gbuffer_build(ctx, s, 1, 8, &g) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
        const size_t base = ((size_t)row * 64 + col) * g.spp;
        double cov = 0.0;
        for (uint32_t q = 0; q < g.spp; ++q)
            cov += g.material[base + q] != VSGL__GBUFFER_MISS ? g.weight[base + q] : 0.0;
        const double want = exact_coverage(col, row, x0, 0.0, z0);
        worst = fmax(worst, fabs(cov - want));
        backwards += prev >= 0.0 && cov < prev - 1e-6; /* the plane covers x < x0: more as the edge moves right */
        steps += prev >= 0.0 && cov > prev + 1e-6;
        prev = cov;
        vsgl__gbuffer_free(&g);
        vsgl_scene_destroy(s);
    }
    printf("    32 positions: coverage off by %.4f at worst, %zu steps up, %zu back\n", worst, steps, backwards);
    VT_CHECK(worst < 0.6 / 64.0 + 1e-4, "coverage off by %.4f (1/64 steps: within %.4f)", worst, 0.6 / 64.0);
    VT_CHECK(backwards == 0 && steps == 31, "%zu steps up and %zu back over 31 moves", steps, backwards);
    vsgl_context_destroy(ctx);
}

/* The edge slot tests' G-buffers of plane p: 2 x 2 samples with 16 x 16
 * edge rays (fine), and 16 x 16 samples in every pixel (dense, the edge
 * rays' own grid); 0 on failure (the context says why). */
static int fine_and_dense(vsgl_context *ctx, const plane_scene *p, vsgl_scene **s, vsgl_gbuffer *fine,
                          vsgl_gbuffer *dense)
{
    return vsgl_scene_create(ctx, &p->desc, s) == VSGL_OK && vsgl__gbuffer_build(ctx, *s, 2, 16, fine) == VSGL_OK &&
           vsgl__gbuffer_build(ctx, *s, 16, 0, dense) == VSGL_OK;
}

/* The one slot of pixel px (4 slots) that holds a surface, where px is an
 * edge pixel with one surface covering more than min_weight of it; else SIZE_MAX. */
static size_t one_surface_slot(const vsgl_gbuffer *g, size_t px, float min_weight)
{
    size_t base = px * 4, hit_slot = SIZE_MAX;
    int hits = 0;
    for (int q = 0; q < 4; ++q)
        if (g->material[base + q] != VSGL__GBUFFER_MISS && g->weight[base + q] > 0.0f) {
            ++hits;
            hit_slot = base + (size_t)q;
        }
    if (hits != 1 || g->weight[hit_slot] > 0.99f || g->weight[hit_slot] < min_weight)
        return SIZE_MAX;
    return hit_slot;
}

/* An edge pixel's slot stands for its surface's share of the pixel with
 * the mean of that share's shading normals (edges.c mean_normal), not the
 * one ray that represents it: on a smooth-shaded surface whose normal turns
 * across the pixel (a rim), the representative ray jumps as the edge moves
 * and the mean does not. The plane of the coverage test, its normal tilted
 * along x (corner normals (-2x, 0, 1)), against the same pixels traced with
 * 16 x 16 samples each (the edge rays' own grid). The representative ray is the
 * one nearest the share's centre, so on this linear field it is off the mean
 * by only ~1e-3 rad (the mean: ~3e-4, rounding). */
VT_TEST(gbuffer_edge_slot_takes_its_surfaces_mean_normal)
{
    plane_scene p;
    slanted_plane(&p, -5.0f, 0.3f, 0.37f, 2.0f);
    float cn[18];
    for (int t = 0; t < 6; ++t) { /* corners of triangles {0,1,2}, {0,2,3} */
        const float *q = p.pos + 3 * p.ix[t];
        cn[3 * t] = -2.0f * q[0];
        cn[3 * t + 1] = 0.0f;
        cn[3 * t + 2] = 1.0f;
    }
    p.desc.corner_normals = cn;
    vsgl_context *ctx = make_ctx(2);
    vsgl_scene *s = NULL;
    vsgl_gbuffer fine, dense;
    VT_REQUIRE(fine_and_dense(ctx, &p, &s, &fine, &dense), "'%s'", vsgl_context_last_error(ctx));
    size_t checked = 0;
    double worst = 0.0, spread = 0.0, worst_spread = 0.0, max_spread = 0.0;
    size_t spread_px = 0;
    for (size_t px = 0; px < (size_t)64 * 48; ++px) {
        const size_t hit_slot = one_surface_slot(&fine, px, 0.0f);
        if (hit_slot == SIZE_MAX)
            continue; /* not an edge pixel with one surface */
        double m[3] = {0, 0, 0};
        for (size_t j = px * 256; j < px * 256 + 256; ++j)
            if (dense.material[j] != VSGL__GBUFFER_MISS)
                for (int c = 0; c < 3; ++c)
                    m[c] += dense.nrm[c][j];
        double len = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
        if (!(len > 0.0))
            continue;
        double dot = 0.0;
        for (int c = 0; c < 3; ++c)
            dot += m[c] / len * fine.nrm[c][hit_slot];
        worst = fmax(worst, acos(fmin(1.0, dot)));
        size_t nh = 0; /* the spread: 1 - the mean resultant length of the rays' normals */
        for (size_t j = px * 256; j < px * 256 + 256; ++j)
            nh += dense.material[j] != VSGL__GBUFFER_MISS;
        double want = 1.0 - len / (double)nh, got = 1.0 - (double)fine.spread[hit_slot];
        if (want > 1e-5) { /* (below, float rounding of the sum) */
            worst_spread = fmax(worst_spread, fabs(got - want) / want);
            ++spread_px;
        }
        max_spread = fmax(max_spread, want);
        for (size_t j = px * 256; j < px * 256 + 256; ++j) /* how far one ray's normal is from the mean */
            if (dense.material[j] != VSGL__GBUFFER_MISS) {
                double d = 0.0;
                for (int c = 0; c < 3; ++c)
                    d += m[c] / len * dense.nrm[c][j];
                spread = fmax(spread, acos(fmin(1.0, d)));
            }
        ++checked;
    }
    printf("    %zu edge pixels: slot normal off the mean by %.2g rad at worst; a single ray up to %.2g rad off\n",
           checked, worst, spread);
    VT_CHECK(checked >= 16, "%zu edge pixels with one surface", checked);
    VT_CHECK(spread > 0.02, "the normal turns by %.3g rad within a pixel: the test cannot tell a ray from the mean",
             spread);
    VT_CHECK(worst < 5e-4, "an edge slot's normal is %.3g rad off its surface's mean normal", worst);
    /* ... and the normals' spread (gbuffer.h spread), which widens its glossy lobe */
    printf("    %zu of them with 1 - R > 1e-5 (at most %.2g): 1 - spread off the rays' own by %.2g (relative) at worst\n",
           spread_px, max_spread, worst_spread);
    VT_CHECK(spread_px >= 4, "%zu edge pixels whose normals spread measurably", spread_px);
    VT_CHECK(worst_spread < 0.05, "an edge slot's spread is %.3g (relative) off its rays' own", worst_spread);
    vsgl__gbuffer_free(&fine);
    vsgl__gbuffer_free(&dense);
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* A curved surface's rim is split where, and only where, its normal turns
 * (edges.c split_curved), and the split follows the camera. The edge rays
 * on one surface chain into one piece first (group_rays): compared with
 * each group's first ray instead, a glossy sphere's rim split at whichever
 * ray came first, and the split moved from frame to frame as the camera
 * moved (the sphere room's camera jitter). A piece that turns is then
 * halved at the median along its turn while the pixel has free slots. A
 * smooth-shaded cylinder (radius 0.25 m, 5 m away: ~4.5 pixels) upright
 * before the empty background, its silhouettes the edges; its normal turns
 * by ~20 degrees across a pixel next to them. The camera slides by 1/16 of
 * a pixel 16 times. In every rim pixel whose number of cylinder slots stays
 * the same, the slots' extreme normals (their azimuths around the axis)
 * move every step, fastest near the silhouette, where the normal turns
 * fastest; a jump shows in their second difference over the steps: 0.06
 * of the pixel's turn at most, where halving the larger half again for a
 * third slot (the choice flipping with the count's parity) gave 0.27. */
/* A smooth-shaded upright cylinder of radius r and `segments` facets
 * around the axis x = 0, z = -5 (the default camera's view), 4 m tall, in
 * p's arrays (segments <= CYL_MAX): radial corner normals. */
#define CYL_MAX 96
typedef struct cylinder_scene {
    plane_scene p;
    float pos[CYL_MAX * 2 * 3], cn[CYL_MAX * 2 * 9];
    uint32_t ix[CYL_MAX * 6];
} cylinder_scene;

static void cylinder_init(cylinder_scene *c, float r, int segments)
{
    plane_init(&c->p, -5.0f, 1.0f, 0);
    for (int k = 0; k < segments; ++k) {
        float a = 6.2831853f * (float)k / (float)segments;
        for (int e = 0; e < 2; ++e) {
            float *v = c->pos + 3 * (2 * k + e);
            v[0] = r * sinf(a);
            v[1] = e ? 2.0f : -2.0f;
            v[2] = -5.0f + r * cosf(a);
        }
        uint32_t a0 = 2u * (uint32_t)k, a1 = a0 + 1, b0 = 2u * (uint32_t)((k + 1) % segments), b1 = b0 + 1;
        uint32_t t[6] = {a0, b0, b1, a0, b1, a1};
        memcpy(c->ix + 6 * k, t, sizeof t);
    }
    for (int q = 0; q < segments * 6; ++q) {
        const float *v = c->pos + 3 * c->ix[q];
        c->cn[3 * q] = v[0] / r;
        c->cn[3 * q + 1] = 0.0f;
        c->cn[3 * q + 2] = (v[2] + 5.0f) / r;
    }
    c->p.desc.vertex_count = (uint32_t)segments * 2;
    c->p.desc.positions = c->pos;
    c->p.desc.triangle_count = (uint32_t)segments * 2;
    c->p.desc.indices = c->ix;
    c->p.desc.corner_normals = c->cn;
}

VT_TEST(gbuffer_edge_slots_of_a_curved_rim_follow_the_camera)
{
    enum { STEPS = 17, PX = 64 * 48 };
    static cylinder_scene cyl;
    static float lo[STEPS][PX], hi[STEPS][PX], turn[PX];
    static int slots[STEPS][PX];
    cylinder_init(&cyl, 0.25f, CYL_MAX);
    vsgl_context *ctx = make_ctx(2);
    const float px_m = 5.0f * 36.0f / 50.0f / 64.0f; /* a pixel's width at the cylinder's distance */
    for (int k = 0; k < STEPS; ++k) {
        plane_scene p = cyl.p;
        p.cam.world_from_camera[3] = (float)k * px_m / 16.0f;
        p.desc.camera = &p.cam;
        vsgl_scene *s = NULL;
        vsgl_gbuffer fine, dense;
        VT_REQUIRE(fine_and_dense(ctx, &p, &s, &fine, &dense), "'%s'", vsgl_context_last_error(ctx));
        for (size_t px = 0; px < PX; ++px) {
            slots[k][px] = 0;
            lo[k][px] = 10.0f;
            hi[k][px] = -10.0f;
            for (size_t q = px * 4; q < px * 4 + 4; ++q)
                if (fine.weight[q] > 0.0f && fine.material[q] != VSGL__GBUFFER_MISS) {
                    const float az = atan2f(fine.nrm[0][q], fine.nrm[2][q]);
                    ++slots[k][px];
                    lo[k][px] = fminf(lo[k][px], az);
                    hi[k][px] = fmaxf(hi[k][px], az);
                }
            if (k == 0) { /* how far the normal turns within the pixel (its 16 x 16 rays) */
                float a0 = 10.0f, a1 = -10.0f;
                for (size_t j = px * 256; j < px * 256 + 256; ++j)
                    if (dense.material[j] != VSGL__GBUFFER_MISS) {
                        const float az = atan2f(dense.nrm[0][j], dense.nrm[2][j]);
                        a0 = fminf(a0, az);
                        a1 = fmaxf(a1, az);
                    }
                turn[px] = a1 > a0 ? a1 - a0 : 0.0f;
            }
        }
        vsgl__gbuffer_free(&fine);
        vsgl__gbuffer_free(&dense);
        vsgl_scene_destroy(s);
    }
    size_t turning = 0, split = 0, compared = 0;
    double worst = 0.0, worst2 = 0.0;
    for (size_t px = 0; px < PX; ++px) {
        if (!(turn[px] > 0.25f) || slots[0][px] == 0)
            continue; /* not a rim pixel whose normal turns by more than 14 degrees */
        ++turning;
        split += slots[0][px] > 1;
        for (int k = 1; k < STEPS; ++k)
            if (slots[k][px] == slots[k - 1][px] && slots[k][px] > 1) {
                ++compared;
                worst = fmax(worst, fabs(lo[k][px] - lo[k - 1][px]) / turn[px]);
                worst = fmax(worst, fabs(hi[k][px] - hi[k - 1][px]) / turn[px]);
                if (k >= 2 && slots[k - 2][px] == slots[k][px]) {
                    worst2 = fmax(worst2, fabs(lo[k][px] - 2.0f * lo[k - 1][px] + lo[k - 2][px]) / turn[px]);
                    worst2 = fmax(worst2, fabs(hi[k][px] - 2.0f * hi[k - 1][px] + hi[k - 2][px]) / turn[px]);
                }
            }
    }

    printf("    %zu rim pixels whose normal turns by more than 14 degrees, %zu of them split; over %zu steps of 1/16 px "
           "the slots' extreme normals moved by %.3f of the pixel's turn at most, second difference %.3f\n", turning,
           split, compared, worst, worst2);
    VT_CHECK(turning >= 24, "%zu turning rim pixels: the test cannot tell", turning);
    VT_CHECK(split * 10 >= turning * 9, "only %zu of %zu turning rim pixels split", split, turning);
    VT_CHECK(compared >= 100, "%zu steps compared", compared);
    VT_CHECK(worst2 < 0.12, "a slot's normal jumped: second difference %.3f of its pixel's turn over 1/16-pixel "
             "steps", worst2);
    vsgl_context_destroy(ctx);
}

/* At one sample per pixel an edge pixel has three slots: where a box's
 * front and side faces meet the floor, each of the three keeps its own
 * share of the pixel. With two slots the third surface's rays joined
 * another surface's slot and took its shading, and the pixel's light
 * jumped as the surfaces' order in the pixel changed (the sun room's
 * cabinet foot, docs/quality.md). The corner (-1.209, -1.153, -5) projects
 * onto the centre of pixel (10, 44); the truth is the same 16 x 16 rays
 * traced as a plain 16 x 16 grid, classified by normal. */
VT_TEST(gbuffer_one_sample_edge_pixel_keeps_three_surfaces)
{
    const float h = -1.153125f, xc = -1.209375f;
    const float v[36] = {-10, h, -1, 10, h, -1, 10, h, -30, -10, h, -30,        /* floor, +y */
                         -4, h, -5, xc, h, -5, xc, 0.5f, -5, -4, 0.5f, -5,      /* front, +z */
                         xc, h, -5, xc, h, -8, xc, 0.5f, -8, xc, 0.5f, -5};     /* side, +x */
    uint32_t ix[18], mi[6] = {0, 0, 1, 1, 1, 1};
    for (uint32_t q = 0; q < 3; ++q) {
        const uint32_t t[6] = {0, 1, 2, 0, 2, 3};
        for (int k = 0; k < 6; ++k)
            ix[q * 6 + k] = q * 4 + t[k];
    }
    plane_scene p;
    plane_init(&p, -5.0f, 1.0f, 0);
    vsgl_material mats[2] = {p.mat, p.mat};
    mats[1].base_color[1] = 0.5f;
    p.desc.vertex_count = 12;
    p.desc.positions = v;
    p.desc.triangle_count = 6;
    p.desc.indices = ix;
    p.desc.material_indices = mi;
    p.desc.material_count = 2;
    p.desc.materials = mats;
    vsgl_context *ctx = make_ctx(2);
    vsgl_scene *s = NULL;
    VT_REQUIRE(vsgl_scene_create(ctx, &p.desc, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    vsgl_gbuffer one, dense;
    VT_REQUIRE(vsgl__gbuffer_build(ctx, s, 1, 16, &one) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    VT_REQUIRE(vsgl__gbuffer_build(ctx, s, 16, 0, &dense) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    VT_REQUIRE(one.spp == 3, "spp %u", one.spp);
    /* class of a sample by its normal: 0 floor, 1 front, 2 side, 3 miss */
#define CLASS(g, i) ((g).material[i] == VSGL__GBUFFER_MISS ? 3 : (g).nrm[1][i] > 0.9f ? 0 : (g).nrm[2][i] > 0.9f ? 1 : 2)
    double worst = 0.0, corner_worst = 0.0;
    size_t three = 0;
    for (size_t px = 0; px < (size_t)64 * 48; ++px) {
        double want[4] = {0, 0, 0, 0}, got[4] = {0, 0, 0, 0};
        for (size_t j = px * 256; j < px * 256 + 256; ++j)
            want[CLASS(dense, j)] += 1.0 / 256.0;
        for (size_t q = px * one.spp; q < px * one.spp + one.spp; ++q)
            if (one.weight[q] > 0.0f)
                got[CLASS(one, q)] += one.weight[q];
        int present = (want[0] > 0.0) + (want[1] > 0.0) + (want[2] > 0.0) + (want[3] > 0.0);
        double e = 0.0;
        for (int c = 0; c < 4; ++c)
            e = fmax(e, fabs(got[c] - want[c]));
        worst = present <= 3 ? fmax(worst, e) : worst;
        if (present == 3 && want[3] == 0.0 && want[0] > 0.1 && want[1] > 0.1 && want[2] > 0.1) {
            ++three;
            corner_worst = fmax(corner_worst, e);
        }
    }
#undef CLASS
    printf("    %zu pixels share the three faces (>= 10 %% each), worst share error %.4f there, %.4f in any pixel "
           "of at most three surfaces\n", three, corner_worst, worst);
    VT_CHECK(three >= 1, "no pixel holds the three faces: the test cannot tell");
    VT_CHECK(worst < 1e-5, "a surface's share off by %.4f", worst);
    vsgl__gbuffer_free(&one);
    vsgl__gbuffer_free(&dense);
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* Visibility rays start on the smooth surface a mesh's normals describe
 * (gbuffer.h lift, scene/raytrace.c vsgl__scene_smooth_point), the
 * samples stay on their flat triangles (where Cycles shades them): from
 * the facets, rays that leave above the shading normal's horizon but
 * below the facet's plane hit the mesh itself (the shadow terminator),
 * and in the sphere room a visibility ray from the sphere's rim toggled as
 * the light moved (a pixel's Gloss 0.437 -> 0.341 in one frame). A
 * 12-facet cylinder (radius 1 m), rays from each sample 10 degrees above
 * its shading horizon, both ways around the axis: on a convex mesh alone,
 * every blocked ray is a self-hit. */
static size_t self_shadowed(const vsgl_scene *s, const vsgl_gbuffer *g, int lifted, size_t *rays)
{
    const float up = sinf(10.0f * 3.14159265f / 180.0f), along = cosf(10.0f * 3.14159265f / 180.0f);
    size_t blocked = 0;
    *rays = 0;
    for (size_t i = 0; i < g->count; ++i) {
        if (g->material[i] == VSGL__GBUFFER_MISS)
            continue;
        v3 x = v3_make(g->pos[0][i], g->pos[1][i], g->pos[2][i]), n = v3_make(g->nrm[0][i], g->nrm[1][i], g->nrm[2][i]);
        v3 around = v3_make(-n.z, 0.0f, n.x); /* horizontal, tangent to the cylinder */
        for (int sign = -1; sign <= 1; sign += 2) {
            v3 d = v3_add(v3_scale(n, up), v3_scale(around, along * (float)sign));
            v3 o = v3_add(x, v3_scale(n, 1e-4f));
            if (lifted)
                o = v3_add(o, v3_make(g->lift[0][i], g->lift[1][i], g->lift[2][i]));
            const uint32_t lane = 0;
            unsigned char b = 0;
            v3 t = v3_add(o, v3_scale(d, 10.0f));
            const float *const tgt[3] = {&t.x, &t.y, &t.z};
            vsgl__scene_occluded_towards_each(s, 1, &lane, &o.x, &o.y, &o.z, tgt, 1e-4f, &b);
            blocked += b != 0;
            ++*rays;
        }
    }
    return blocked;
}

VT_TEST(gbuffer_smooth_mesh_does_not_shadow_itself)
{
    static cylinder_scene cyl;
    cylinder_init(&cyl, 1.0f, 12);
    vsgl_context *ctx = make_ctx(2);
    vsgl_scene *s = NULL;
    vsgl_gbuffer g;
    VT_REQUIRE(vsgl_scene_create(ctx, &cyl.p.desc, &s) == VSGL_OK && vsgl__gbuffer_build(ctx, s, 2, 0, &g) == VSGL_OK,
               "'%s'", vsgl_context_last_error(ctx));
    VT_REQUIRE(g.lift[0] != NULL, "no lift on a smooth-shaded scene");
    double r_lo = 2.0, r_hi = 0.0, lift = 0.0;
    for (size_t i = 0; i < g.count; ++i)
        if (g.material[i] != VSGL__GBUFFER_MISS) {
            double r = sqrt((double)g.pos[0][i] * g.pos[0][i] + ((double)g.pos[2][i] + 5.0) * ((double)g.pos[2][i] + 5.0));
            r_lo = fmin(r_lo, r);
            r_hi = fmax(r_hi, r);
            lift = fmax(lift, sqrt((double)g.lift[0][i] * g.lift[0][i] + (double)g.lift[1][i] * g.lift[1][i] +
                                   (double)g.lift[2][i] * g.lift[2][i]));
        }
    size_t rays, rays2;
    size_t from_facet = self_shadowed(s, &g, 0, &rays), from_smooth = self_shadowed(s, &g, 1, &rays2);
    printf("    samples %.4f-%.4f m from the axis (the facets span %.4f-1), lifted up to %.4f m; of %zu rays 10 "
           "degrees above the shading horizon, %zu hit the cylinder from the facets, %zu from the lifted points\n",
           r_lo, r_hi, cos(3.14159265 / 12.0), lift, rays, from_facet, from_smooth);
    VT_CHECK(r_lo > cos(3.14159265 / 12.0) - 1e-4 && r_hi < 1.0 + 1e-4, "samples left their facets");
    VT_CHECK(from_facet * 10 > rays, "only %zu of %zu rays from the facets self-hit: the test cannot tell", from_facet,
             rays);
    VT_CHECK(from_smooth * 100 <= rays2, "%zu of %zu lifted rays shadowed by their own surface", from_smooth, rays2);
    vsgl__gbuffer_free(&g);
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* An edge slot's lift is its ray's: the edge rays keep only their hits,
 * and the lift (and textured inputs) of the ray a slot keeps are computed
 * from its hit afterwards (vsgl__gbuffer_store_deferred). On a smooth
 * 12-facet cylinder, a rim slot at one sample per pixel (8 x 8 edge rays)
 * sits at one of its rays' points (the one whose normal is nearest the
 * group's mean): the ray of the 8 x 8 grid traced plainly at that point
 * must have the slot's lift, to the bit. A slot of a flat group takes the
 * mean point and no lift. */
VT_TEST(gbuffer_edge_slot_lift_is_its_rays)
{
    static cylinder_scene cyl;
    cylinder_init(&cyl, 1.0f, 12);
    vsgl_context *ctx = make_ctx(2);
    vsgl_scene *s = NULL;
    vsgl_gbuffer one, dense;
    VT_REQUIRE(vsgl_scene_create(ctx, &cyl.p.desc, &s) == VSGL_OK && vsgl__gbuffer_build(ctx, s, 1, 8, &one) == VSGL_OK &&
                   vsgl__gbuffer_build(ctx, s, 8, 0, &dense) == VSGL_OK,
               "'%s'", vsgl_context_last_error(ctx));
    VT_REQUIRE(one.lift[0] != NULL && dense.lift[0] != NULL, "no lift on a smooth-shaded scene");
    size_t lifted = 0, matched = 0, flat = 0;
    for (size_t px = 0; px < (size_t)64 * 48; ++px)
        for (size_t q = px * one.spp; q < px * one.spp + one.spp; ++q) {
            if (one.material[q] == VSGL__GBUFFER_MISS || one.weight[q] == 1.0f || !(one.weight[q] > 0.0f))
                continue; /* a miss, an empty slot, or not an edge pixel */
            if (one.lift[0][q] == 0.0f && one.lift[1][q] == 0.0f && one.lift[2][q] == 0.0f) {
                ++flat;
                continue;
            }
            ++lifted;
            for (size_t j = px * 64; j < px * 64 + 64; ++j)
                if (dense.pos[0][j] == one.pos[0][q] && dense.pos[1][j] == one.pos[1][q] &&
                    dense.pos[2][j] == one.pos[2][q]) {
                    matched += dense.lift[0][j] == one.lift[0][q] && dense.lift[1][j] == one.lift[1][q] &&
                               dense.lift[2][j] == one.lift[2][q];
                    break;
                }
        }
    printf("    %zu lifted edge slots, %zu with their ray's lift to the bit; %zu without a lift\n", lifted, matched, flat);
    VT_CHECK(lifted >= 48, "%zu lifted edge slots: the test cannot tell", lifted);
    VT_CHECK(matched == lifted, "%zu of %zu edge slots lack their ray's lift", lifted - matched, lifted);
    vsgl__gbuffer_free(&one);
    vsgl__gbuffer_free(&dense);
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* A flat scene has no lift (gbuffer.h: nothing to model). */
VT_TEST(gbuffer_flat_scene_has_no_lift)
{
    plane_scene p;
    plane_init(&p, -5.0f, 2.0f, 0);
    vsgl_context *ctx = make_ctx(1);
    vsgl_scene *s = NULL;
    vsgl_gbuffer g;
    VT_REQUIRE(vsgl_scene_create(ctx, &p.desc, &s) == VSGL_OK && vsgl__gbuffer_build(ctx, s, 1, 0, &g) == VSGL_OK,
               "'%s'", vsgl_context_last_error(ctx));
    VT_CHECK(g.lift[0] == NULL, "a flat plane's G-buffer allocated a lift");
    vsgl__gbuffer_free(&g);
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* On a flat surface (one normal) an edge slot stands at the mean point of
 * its share's rays (edges.c mean_surface), not at its representative ray:
 * the coverage test's slanted plane, against the same pixels traced with 16
 * x 16 samples (the edge rays' own grid). */
VT_TEST(gbuffer_edge_slot_on_a_flat_surface_takes_its_mean_point)
{
    plane_scene p;
    slanted_plane(&p, -5.0f, 0.3f, 0.37f, 2.0f);
    vsgl_context *ctx = make_ctx(2);
    vsgl_scene *s = NULL;
    vsgl_gbuffer fine, dense;
    VT_REQUIRE(fine_and_dense(ctx, &p, &s, &fine, &dense), "'%s'", vsgl_context_last_error(ctx));
    size_t checked = 0;
    double worst = 0.0, ray = 0.0;
    for (size_t px = 0; px < (size_t)64 * 48; ++px) {
        const size_t hit_slot = one_surface_slot(&fine, px, 0.1f);
        if (hit_slot == SIZE_MAX)
            continue; /* not an edge pixel with one surface (of at least a tenth of it) */
        double m[3] = {0, 0, 0};
        size_t nh = 0;
        for (size_t j = px * 256; j < px * 256 + 256; ++j)
            if (dense.material[j] != VSGL__GBUFFER_MISS) {
                for (int c = 0; c < 3; ++c)
                    m[c] += dense.pos[c][j];
                ++nh;
            }
        double d2 = 0.0, far2 = 0.0;
        for (int c = 0; c < 3; ++c)
            d2 += pow(m[c] / (double)nh - fine.pos[c][hit_slot], 2.0);
        for (size_t j = px * 256; j < px * 256 + 256; ++j) /* how far one ray's hit is from the mean */
            if (dense.material[j] != VSGL__GBUFFER_MISS) {
                double r2 = 0.0;
                for (int c = 0; c < 3; ++c)
                    r2 += pow(m[c] / (double)nh - dense.pos[c][j], 2.0);
                far2 = fmax(far2, r2);
            }
        worst = fmax(worst, sqrt(d2 / far2));
        ray = fmax(ray, far2);
        ++checked;
    }
    printf("    %zu edge pixels: slot point off its rays' mean by %.2g of their spread at worst\n", checked, worst);
    VT_CHECK(checked >= 16, "%zu edge pixels with one surface", checked);
    VT_CHECK(ray > 0.0, "the rays of a pixel hit one point: the test cannot tell a ray from the mean");
    VT_CHECK(worst < 1e-3, "an edge slot's point is %.3g of its rays' spread off their mean", worst);
    vsgl__gbuffer_free(&fine);
    vsgl__gbuffer_free(&dense);
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

typedef struct progress_log { int calls, cancel_at; float last; int decreasing; } progress_log;
static int32_t on_progress(void *user, const char *stage, float f)
{
    progress_log *l = user;
    if (strcmp(stage, "gbuffer") != 0 || f < l->last)
        l->decreasing = 1;
    l->last = f;
    return ++l->calls == l->cancel_at;
}

VT_TEST(gbuffer_progress_cancel_and_debug_copy)
{
    progress_log log;
    memset(&log, 0, sizeof log);
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.thread_count = 2;
    cd.progress = on_progress;
    cd.progress_user = &log;
    vsgl_context *ctx = NULL;
    vsgl_context_create(&cd, &ctx);
    plane_scene p;
    plane_init(&p, -5.0f, 1.0f, 0);
    vsgl_scene *s = NULL;
    VT_CHECK(vsgl_scene_create(ctx, &p.desc, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    if (!s) { vsgl_context_destroy(ctx); return; }
    vsgl_gbuffer g;
    VT_CHECK(vsgl__gbuffer_build(ctx, s, 1, 0, &g) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    VT_CHECK(log.calls >= 2 && log.last == 1.0f && !log.decreasing, "calls %d last %g decreasing %d", log.calls, log.last,
             log.decreasing);
    /* debug copy equals the internal buffer */
    size_t n = g.count;
    float *pos = malloc(n * 12), *nrm = malloc(n * 12);
    uint32_t *mat = malloc(n * 4);
    VT_CHECK(vsgl_debug_gbuffer(ctx, s, 1, pos, nrm, mat) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    int same = 1;
    for (size_t e = 0; e < n; ++e)
        for (int c = 0; c < 3; ++c)
            same &= pos[e * 3 + c] == g.pos[c][e] && nrm[e * 3 + c] == g.nrm[c][e] && mat[e] == g.material[e];
    VT_CHECK(same, "debug copy differs");
    float *tg = malloc(n * 12), *vw = malloc(n * 12);
    VT_CHECK(vsgl_debug_gbuffer_frames(ctx, s, 1, tg, vw) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    same = 1;
    for (size_t e = 0; e < n; ++e)
        for (int c = 0; c < 3; ++c)
            same &= tg[e * 3 + c] == g.tan[c][e] && vw[e * 3 + c] == g.view[c][e];
    VT_CHECK(same, "debug frames copy differs");
    VT_CHECK(vsgl_debug_gbuffer_frames(ctx, NULL, 1, tg, vw) == VSGL_ERROR_INVALID_ARGUMENT, "NULL scene");
    free(tg); free(vw);
    VT_CHECK(vsgl_debug_gbuffer(ctx, s, 1, NULL, NULL, NULL) == VSGL_OK, "all outputs NULL");
    VT_CHECK(vsgl_debug_gbuffer(ctx, NULL, 1, pos, NULL, NULL) == VSGL_ERROR_INVALID_ARGUMENT, "NULL scene");
    vsgl__gbuffer_free(&g);
    /* cancel on the first report (this image is one step of rows: steps of at least 2^17 samples) */
    memset(&log, 0, sizeof log);
    log.cancel_at = 1;
    memset(&g, 0xAB, sizeof g);
    vsgl_result r = vsgl__gbuffer_build(ctx, s, 1, 0, &g);
    VT_CHECK(r == VSGL_ERROR_CANCELLED && g.pos[0] == NULL && g.material == NULL && g.count == 0, "r %d", r);
    VT_CHECK(strncmp(vsgl_context_last_error(ctx), "gbuffer: cancelled at row ", 26) == 0, "'%s'", vsgl_context_last_error(ctx));
    memset(&log, 0, sizeof log);
    log.cancel_at = 1;
    pos[0] = 42.0f;
    r = vsgl_debug_gbuffer(ctx, s, 1, pos, NULL, NULL);
    VT_CHECK(r == VSGL_ERROR_CANCELLED && pos[0] == 42.0f, "debug cancel r %d, output touched %g", r, pos[0]);
    /* aa out of range */
    r = vsgl__gbuffer_build(ctx, s, 17, 0, &g);
    VT_CHECK(r == VSGL_ERROR_INVALID_ARGUMENT && strcmp(vsgl_context_last_error(ctx), "gbuffer: aa_samples is 17 (must be in [1, 16])") == 0,
             "r %d '%s'", r, vsgl_context_last_error(ctx));
    free(pos); free(nrm); free(mat);
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}

/* Height above the face (z = ng) of the mirror reflection of i about m. */
static double reflection_height(const double ng[3], const double i[3], const double m[3])
{
    double mi = m[0] * i[0] + m[1] * i[1] + m[2] * i[2];
    return (2.0 * mi * m[0] - i[0]) * ng[0] + (2.0 * mi * m[1] - i[1]) * ng[1] + (2.0 * mi * m[2] - i[2]) * ng[2];
}

/* vsgl__valid_reflection_normal against a search along the arc from n to
 * ng: where n's reflection is high enough it is returned unchanged (to the
 * bit); else the result is a unit normal in the plane of n and ng, between
 * them, whose reflection of i leaves the face at the threshold
 * min(0.9 ng.i, 0.01), the first point of the arc from n that does (found
 * by bisection in double); in a few configurations Cycles' root choice,
 * which this follows, takes the root of the squared equation whose
 * reflection is lower but still rises, counted and bounded here. */
VT_TEST(valid_reflection_normal_matches_a_search_along_the_arc)
{
    uint64_t st = 0x9E3779B97F4A7C15ull;
    size_t kept = 0, turned = 0, searched = 0, lower = 0;
    double worst = 0.0;
    for (int trial = 0; trial < 20000; ++trial) {
        double u[6];
        for (int k = 0; k < 6; ++k) {
            st = st * 6364136223846793005ull + 1442695040888963407ull;
            u[k] = (double)(st >> 11) * (1.0 / 9007199254740992.0);
        }
        /* ng = +z; i above the face (elevation 0.2 .. 90 degrees); n within 85 degrees of ng */
        double ie = (0.2 + 89.8 * u[0]) * VSGL__PI_D / 180.0, ia = 2.0 * VSGL__PI_D * u[1];
        double ne = (5.0 + 85.0 * u[2]) * VSGL__PI_D / 180.0, na = 2.0 * VSGL__PI_D * u[3];
        double ng[3] = {0, 0, 1}, i[3] = {cos(ie) * cos(ia), cos(ie) * sin(ia), sin(ie)};
        double n[3] = {cos(ne) * cos(na), cos(ne) * sin(na), sin(ne)};
        v3 r = vsgl__valid_reflection_normal(v3_make(0, 0, 1), v3_make((float)i[0], (float)i[1], (float)i[2]),
                                             v3_make((float)n[0], (float)n[1], (float)n[2]));
        double t = fmin(0.9 * i[2], 0.01);
        if (reflection_height(ng, i, n) >= t + 1e-5) {
            VT_CHECK(r.x == (float)n[0] && r.y == (float)n[1] && r.z == (float)n[2], "trial %d: n changed", trial);
            ++kept;
            continue;
        }
        if (reflection_height(ng, i, n) < t - 1e-5)
            ++turned;
        else
            continue; /* at the threshold within float rounding: either answer */
        double m[3] = {r.x, r.y, r.z};
        double len = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
        /* in the plane of n and ng, on n's side of ng */
        double plane = m[0] * n[1] - m[1] * n[0]; /* (n x ng) . m */
        double side = m[0] * n[0] + m[1] * n[1];
        VT_CHECK(fabs(len - 1.0) < 1e-5 && fabs(plane) < 1e-5 && side >= -1e-6, "trial %d: |m| %g, out of plane %g, side %g",
                 trial, len, plane, side);
        /* the arc from n (angle 0) to ng: the first angle whose reflection reaches t */
        double c = cos(ne), x[3] = {n[0] / c, n[1] / c, 0.0};
        double lo = 0.0, hi = VSGL__PI_D / 2 - ne;
        for (int it = 0; it < 80; ++it) {
            double a = 0.5 * (lo + hi), e = ne + a, q[3] = {cos(e) * x[0], cos(e) * x[1], sin(e)};
            if (reflection_height(ng, i, q) >= t)
                hi = a;
            else
                lo = a;
        }
        /* the first crossing from n; a steeper normal further along the arc first */
        double e = ne + hi, want[3] = {cos(e) * x[0], cos(e) * x[1], sin(e)};
        double d = sqrt((m[0] - want[0]) * (m[0] - want[0]) + (m[1] - want[1]) * (m[1] - want[1]) +
                        (m[2] - want[2]) * (m[2] - want[2]));
        double h = reflection_height(ng, i, m);
        ++searched;
        if (d < 1e-3) { /* float against double at grazing views */
            if (d > worst)
                worst = d;
            continue;
        }
        ++lower; /* Cycles' other root: its reflection rises, below the threshold */
        VT_CHECK(h >= 1e-5 - 1e-6 && h < t, "trial %d: neither the arc's normal (%g away) nor a lower rising one (height %g, t %g)",
                 trial, d, h, t);
    }
    VT_CHECK(kept > 2000 && turned > 2000, "both cases exercised: %zu kept, %zu turned", kept, turned);
    VT_CHECK(lower * 50 < searched, "the arc's normal in all but %zu of %zu", lower, searched);
    VT_CHECK(worst < 1e-3, "worst distance to the arc's normal %g", worst);
}

/* The G-buffer shades with the normal Cycles' BSDF takes: a plane facing
 * the camera with corner normals bent 45 degrees towards +x, which
 * reflect the view of the right half of the image below the plane. Every
 * sample's stored normal reflects its view direction at least
 * min(0.9 ng.v, 0.01) above the plane, the stored tangent stays
 * orthonormal to it, and samples whose bent normal already did keep it. */
VT_TEST(gbuffer_normals_reflect_above_the_face)
{
    plane_scene p;
    plane_init(&p, -5.0f, 100.0f, 0);
    float cn[18];
    const float bend = 45.0f * (float)VSGL__PI_D / 180.0f; /* reflection height = the view's x */
    for (int k = 0; k < 6; ++k) {
        cn[3 * k] = sinf(bend);
        cn[3 * k + 1] = 0.0f;
        cn[3 * k + 2] = cosf(bend);
    }
    p.desc.corner_normals = cn;
    vsgl_context *ctx = make_ctx(2);
    vsgl_scene *s = NULL;
    VT_CHECK(vsgl_scene_create(ctx, &p.desc, &s) == VSGL_OK, "'%s'", vsgl_context_last_error(ctx));
    vsgl_gbuffer g;
    memset(&g, 0, sizeof g);
    if (s && vsgl__gbuffer_build(ctx, s, 2, 0, &g) == VSGL_OK) {
        size_t kept = 0, turned = 0;
        for (size_t e = 0; e < g.count; ++e) {
            double ng[3] = {0, 0, 1}, v[3] = {g.view[0][e], g.view[1][e], g.view[2][e]};
            double m[3] = {g.nrm[0][e], g.nrm[1][e], g.nrm[2][e]}, bent[3] = {sinf(bend), 0.0, cosf(bend)};
            double t = fmin(0.9 * v[2], 0.01), h = reflection_height(ng, v, m);
            double td = g.tan[0][e] * m[0] + g.tan[1][e] * m[1] + g.tan[2][e] * m[2];
            double tl = g.tan[0][e] * g.tan[0][e] + g.tan[1][e] * g.tan[1][e] + g.tan[2][e] * g.tan[2][e];
            if (h < fmin(t, 1e-5) - 1e-5 || fabs(td) > 1e-5 || fabs(tl - 1.0) > 1e-5 || m[0] * v[0] + m[1] * v[1] + m[2] * v[2] <= 0.0) {
                VT_CHECK(0, "sample %zu: reflection height %g (t %g), tangent.n %g, |t|^2 %g", e, h, t, td, tl);
                break;
            }
            if (reflection_height(ng, v, bent) >= t + 1e-4) {
                VT_CHECK(fabs(m[0] - bent[0]) + fabs(m[1]) + fabs(m[2] - bent[2]) < 1e-6, "sample %zu: a valid normal changed", e);
                ++kept;
            } else if (reflection_height(ng, v, bent) < t - 1e-4) {
                ++turned;
            }
        }
        VT_CHECK(kept > g.count / 10 && turned > g.count / 10, "both halves: %zu kept, %zu turned of %zu", kept, turned,
                 g.count);
    }
    vsgl__gbuffer_free(&g);
    vsgl_scene_destroy(s);
    vsgl_context_destroy(ctx);
}
