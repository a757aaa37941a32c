/* Where visibility rays aim (shade/ray_targets.c): points over a disk with
 * the cluster's own spread, pulled in before a wall, and a receiver's pick
 * among them; through an occluder's straight edge the share of receivers
 * that see the cluster must follow a uniform disk's penumbra (the area of
 * the disk beyond the edge's shadow line), not one hard step. */
#include "harness.h"
#include "scene_fixture.h"
#include "shade/ray_targets.h"
#include "shade/shade.h"

#include <math.h>
#include <string.h>

/* The fixture room with a horizontal plate at height z_plate over
 * x in [-0.9, 0], y in [-0.9, 0.9]: its edge is the line x = 0. */
static vsgl_scene *room_with_plate(vsgl_context *ctx, fx_scene *fx, float z_plate)
{
    fx_room(fx, 8, 6, 0.5f, 100.0f);
    const float plate[4][3] = {{-0.9f, -0.9f, z_plate}, {0.0f, -0.9f, z_plate}, {0.0f, 0.9f, z_plate},
                               {-0.9f, 0.9f, z_plate}};
    fx_quad(fx, plate, 3);
    vsgl_scene *sc = NULL;
    return vsgl_scene_create(ctx, fx_desc(fx), &sc) == VSGL_OK ? sc : NULL;
}

static vsgl_vsgl floor_cluster(float x, float y, float sigma)
{
    vsgl_vsgl v;
    memset(&v, 0, sizeof v);
    v.mean = v3_make(x, y, 0.0f);
    v.normal = v3_make(0.0f, 0.0f, 1.0f);
    v.coherence = 1.0f;
    v.variance = sigma * sigma;
    return v;
}

/* The share of a uniform disk of radius 1 on the side x >= -u of a line. */
static double disk_share_beyond(double u)
{
    if (u <= -1.0)
        return 0.0;
    if (u >= 1.0)
        return 1.0;
    return 1.0 - (acos(u) - u * sqrt(1.0 - u * u)) / 3.14159265358979;
}

VT_TEST(ray_targets_spread_over_the_cluster_and_stop_before_a_wall)
{
    vsgl_context *ctx = fx_context(1);
    VT_REQUIRE(ctx, "context");
    fx_scene fx;
    vsgl_scene *sc = room_with_plate(ctx, &fx, 0.525f);
    VT_REQUIRE(sc, "%s", vsgl_context_last_error(ctx));
    const float sigma = 0.05f;
    vsgl_vsgl items[2] = {floor_cluster(0.0f, 0.0f, sigma), floor_cluster(0.95f, 0.0f, sigma)};
    vsgl_vsgl_set set = {items, 2, 2};
    vsgl_ray_targets t;
    VT_REQUIRE(vsgl__ray_targets_build(sc, &set, 2.0f, 0.25f, &t) == VSGL_OK, "build");
    const float R = 2.0f * sqrtf(1.5f) * sigma; /* a uniform disk with the cluster's in-plane variance */
    for (int i = 0; i < 2; ++i) {
        v3 c = vsgl__ray_centre(&items[i]);
        VT_CHECK(fabsf(c.z - sigma) < 1e-6f, "cluster %d: centre pushed off the floor to %g, want sigma %g", i,
                 (double)c.z, (double)sigma);
        double m2 = 0.0, mx = 0.0, my = 0.0;
        int pulled = 0;
        for (unsigned k = 0; k < VSGL__RAY_TARGETS; ++k) {
            const float *p = t.xyz + (i * VSGL__RAY_TARGETS + k) * 3;
            v3 d = v3_sub(v3_make(p[0], p[1], p[2]), c);
            const float rk = R * sqrtf(((float)k + 0.5f) / VSGL__RAY_TARGETS), len = v3_length(d);
            VT_CHECK(fabsf(d.z) < 1e-6f, "cluster %d point %u off the cluster's plane by %g", i, k, (double)d.z);
            VT_CHECK(len <= rk * 1.0001f, "cluster %d point %u at %g, past its radius %g", i, k, (double)len,
                     (double)rk);
            if (len < rk * 0.999f) { /* pulled in: halfway to the wall x = 1 */
                ++pulled;
                VT_CHECK(fabsf(c.x + 2.0f * d.x - 1.0f) < 1e-4f, "cluster %d point %u pulled in to %g, but the "
                         "wall is not at twice that (%g)", i, k, (double)len, (double)(c.x + 2.0f * d.x));
            } else {
                VT_CHECK(p[0] < 1.0f, "cluster %d point %u at x = %g, behind the wall", i, k, (double)p[0]);
            }
            m2 += (double)v3_dot(d, d) / VSGL__RAY_TARGETS;
            mx += (double)d.x / VSGL__RAY_TARGETS;
            my += (double)d.y / VSGL__RAY_TARGETS;
        }
        if (i == 0) { /* nothing in the way: the disk's second moment, R^2 / 2 = 3 sigma^2 */
            VT_CHECK(pulled == 0, "%d points pulled in with nothing in the way", pulled);
            VT_CHECK(fabs(m2 / (3.0 * sigma * sigma) - 1.0) < 1e-3, "second moment %g sigma^2, want 3",
                     m2 / (sigma * sigma));
            VT_CHECK(fabs(mx) < 0.25 * sigma && fabs(my) < 0.25 * sigma, "points centred off by (%g, %g) sigma",
                     mx / sigma, my / sigma);
        } else { /* 5 cm from the wall, the disk 12 cm wide: some points reach it */
            VT_CHECK(pulled >= 2, "%d points pulled in before the wall 5 cm away", pulled);
        }
    }
    vsgl__ray_targets_free(&t);
    /* spread 0: every point is the centre */
    VT_REQUIRE(vsgl__ray_targets_build(sc, &set, 0.0f, 0.25f, &t) == VSGL_OK, "build");
    v3 c = vsgl__ray_centre(&items[1]);
    for (unsigned k = 0; k < VSGL__RAY_TARGETS; ++k) {
        const float *p = t.xyz + (VSGL__RAY_TARGETS + k) * 3;
        VT_CHECK(p[0] == c.x && p[1] == c.y && p[2] == c.z, "spread 0: point %u is not the centre", k);
    }
    vsgl__ray_targets_free(&t);
    vsgl_scene_destroy(sc);
    vsgl_context_destroy(ctx);
}

/* A cluster on the floor under the plate's edge, receivers in lines above
 * the plate at x = u R (R: the disk's radius), each receiver with the key
 * of one pixel of a 32 x 32 image, the plate halfway up: a
 * receiver's ray to point p of the disk passes the plate's plane at
 * x = (u R + p.x) / 2, so the share that gets through is the disk's share
 * beyond x = -u R. Measured over 1024 receivers a line: within binomial
 * noise of the 16 points' share, which is within 0.1 of the disk's. With
 * every ray at the centre, the share is 0 or 1: the hard step. */
VT_TEST(ray_targets_give_an_edge_the_cluster_penumbra)
{
    vsgl_context *ctx = fx_context(1);
    VT_REQUIRE(ctx, "context");
    fx_scene fx;
    const float sigma = 0.05f, zr = 1.0f;
    vsgl_vsgl items[1] = {floor_cluster(0.0f, 0.0f, sigma)};
    const v3 c = vsgl__ray_centre(&items[0]);
    vsgl_scene *sc = room_with_plate(ctx, &fx, 0.5f * (c.z + zr));
    VT_REQUIRE(sc, "%s", vsgl_context_last_error(ctx));
    vsgl_vsgl_set set = {items, 1, 1};
    const float R = 2.0f * sqrtf(1.5f) * sigma;
    enum { N = 1024 };
    static float ox[N], oy[N], oz[N], tx[N], ty[N], tz[N];
    static uint32_t lane[N];
    static unsigned char blocked[N];
    const float *const tgt[3] = {tx, ty, tz};
    for (int spread = 0; spread < 2; ++spread) {
        vsgl_ray_targets t;
        VT_REQUIRE(vsgl__ray_targets_build(sc, &set, spread ? 2.0f : 0.0f, 0.25f, &t) == VSGL_OK, "build");
        const double us[] = {-0.8, -0.5, -0.2, 0.2, 0.5, 0.8};
        double prev = -1.0;
        for (size_t q = 0; q < sizeof us / sizeof us[0]; ++q) {
            double points = 0.0; /* the share of the 16 points beyond the line */
            for (unsigned k = 0; k < VSGL__RAY_TARGETS; ++k)
                points += t.xyz[3 * k] >= c.x - (float)us[q] * R ? 1.0 / VSGL__RAY_TARGETS : 0.0;
            for (int i = 0; i < N; ++i) {
                v3 x = v3_make((float)us[q] * R, -0.5f + (float)i / N, zr);
                /* the receivers of a 32 x 32-pixel image, one line of it per pixel's key */
                const float *p = vsgl__ray_target_for(&t, 0, vsgl__ray_key((size_t)i, 32u, 1u, 1u), 0, 1);
                ox[i] = x.x, oy[i] = x.y, oz[i] = x.z;
                tx[i] = p[0], ty[i] = p[1], tz[i] = p[2];
                lane[i] = (uint32_t)i;
            }
            vsgl__scene_occluded_towards_each(sc, N, lane, ox, oy, oz, tgt, 1e-4f, blocked);
            double seen = 0.0;
            for (int i = 0; i < N; ++i)
                seen += blocked[i] ? 0.0 : 1.0 / N;
            if (spread) {
                double disk = disk_share_beyond(us[q]);
                VT_CHECK(fabs(seen - points) < 0.05, "u %.1f: %.3f of the receivers see the cluster, its points "
                         "give %.3f (the picks are not uniform)", us[q], seen, points);
                VT_CHECK(fabs(points - disk) < 0.1, "u %.1f: the points give %.3f, a uniform disk %.3f", us[q],
                         points, disk);
                VT_CHECK(seen > prev, "u %.1f: %.3f, not more than the line before (%.3f)", us[q], seen, prev);
                prev = seen;
            } else {
                VT_CHECK(seen == (us[q] > 0.0 ? 1.0 : 0.0), "spread 0, u %.1f: %.3f see the centre, want a hard "
                         "step", us[q], seen);
            }
        }
        vsgl__ray_targets_free(&t);
    }
    vsgl_scene_destroy(sc);
    vsgl_context_destroy(ctx);
}

/* Which of a cluster's 16 points the receivers pick (vsgl__ray_key,
 * vsgl__ray_target_for), from the targets' own table:
 *  - the picks come from a blue-noise mask: any 4 x 4 pixels of an image
 *    take at least 10 of a cluster's points and 12.5 on average (a
 *    white-noise hash of the pixel: 6 and 10.3), so a dithered shadow edge
 *    has little grain left at the scale of a few pixels;
 *  - a pair's n dominant rays (vsgl_render_settings.dominant_rays) take n
 *    different points, every one of the 16 at n = 16;
 *  - a pixel's slots on the aa x aa grid read the mask at their own place
 *    on the image's sample grid (2 x 2 slots of one pixel: 4 points). */
VT_TEST(ray_targets_picks_are_blue_noise_and_rays_distinct)
{
    vsgl_context *ctx = fx_context(1);
    VT_REQUIRE(ctx, "context");
    fx_scene fx;
    vsgl_vsgl items[2] = {floor_cluster(0.0f, 0.0f, 0.05f), floor_cluster(0.3f, 0.2f, 0.05f)};
    vsgl_scene *sc = room_with_plate(ctx, &fx, 0.5f);
    VT_REQUIRE(sc, "%s", vsgl_context_last_error(ctx));
    vsgl_vsgl_set set = {items, 2, 2};
    vsgl_ray_targets t;
    VT_REQUIRE(vsgl__ray_targets_build(sc, &set, 2.0f, 0.25f, &t) == VSGL_OK, "build");
    enum { W = 96, H = 80 };
    for (size_t item = 0; item < 2; ++item) {
        int least = 16;
        double mean = 0.0;
        size_t windows = 0;
        for (uint32_t y0 = 0; y0 + 4 <= H; ++y0)
            for (uint32_t x0 = 0; x0 + 4 <= W; ++x0) {
                unsigned seen = 0;
                for (uint32_t y = y0; y < y0 + 4; ++y)
                    for (uint32_t x = x0; x < x0 + 4; ++x) {
                        const float *p = vsgl__ray_target_for(&t, item, vsgl__ray_key((size_t)y * W + x, W, 1u, 1u),
                                                              0, 1);
                        seen |= 1u << ((size_t)(p - t.xyz) / 3 - item * VSGL__RAY_TARGETS);
                    }
                const int c = __builtin_popcount(seen);
                least = c < least ? c : least;
                mean += c;
                ++windows;
            }
        mean /= (double)windows;
        VT_CHECK(least >= 10 && mean >= 12.5, "cluster %zu: 4 x 4 pixels pick at least %d of 16 points, %.2f on "
                 "average (want >= 10, >= 12.5: blue noise)", item, least, mean);
        for (uint32_t n = 2; n <= VSGL__RAY_TARGETS; n *= 2)
            for (size_t i = 0; i < 200; ++i) {
                const uint32_t key = vsgl__ray_key(i * 37u, W, 1u, 1u);
                unsigned seen = 0;
                for (uint32_t r = 0; r < n; ++r)
                    seen |= 1u << ((size_t)(vsgl__ray_target_for(&t, item, key, r, n) - t.xyz) / 3 -
                                   item * VSGL__RAY_TARGETS);
                VT_CHECK((unsigned)__builtin_popcount(seen) == n, "cluster %zu, key %u: %u rays take %d points",
                         item, key, n, __builtin_popcount(seen));
            }
    }
    /* aa 2: pixel (5, 7)'s four slots sit at (10..11, 14..15) of the sample grid */
    for (uint32_t s = 0; s < 4; ++s) {
        const uint32_t key = vsgl__ray_key((size_t)(7 * W + 5) * 4 + s, W, 4u, 2u);
        VT_CHECK((key & 63u) == 10u + s % 2u && ((key >> 6) & 63u) == 14u + s / 2u && key >> 12 == 0,
                 "slot %u: key %u", s, key);
    }
    /* an edge pixel's third slot (aa 1, 3 slots): the pixel's place, turned */
    VT_CHECK(vsgl__ray_key((size_t)(7 * W + 5) * 3 + 2, W, 3u, 1u) == (5u | 7u << 6 | 2u << 12), "edge slot key");
    vsgl__ray_targets_free(&t);
    vsgl_scene_destroy(sc);
    vsgl_context_destroy(ctx);
}

/* A receiver never aims below its own horizon (vsgl__ray_aim): above it a
 * point is kept as it is; below it, its mirror image through the cluster's
 * centre, raised to 5 % of its distance above the horizon where it is
 * lower, so the ray cannot start into the receiver's own surface. The
 * height above the horizon goes on continuously as the mirror image sinks
 * (a ray that jumped to the centre below the horizon, blocked by the
 * receiver itself, took a cluster's whole light for a frame). Random
 * receivers, normals, clusters and points. */
VT_TEST(ray_aim_stays_above_the_receivers_horizon)
{
    uint64_t st = 0x243F6A8885A308D3ull;
    size_t kept = 0, mirrored = 0, raised = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        float u[12];
        for (int k = 0; k < 12; ++k) {
            st = st * 6364136223846793005ull + 1442695040888963407ull;
            u[k] = (float)((double)(st >> 11) * (1.0 / 9007199254740992.0)) * 2.0f - 1.0f;
        }
        v3 x = v3_make(u[0], u[1], u[2]);
        v3 n = v3_normalize(v3_make(u[3], u[4], u[5] + 0.01f));
        v3 c = v3_add(x, v3_scale(v3_make(u[6], u[7], u[8]), 2.0f));
        v3 t = v3_add(c, v3_scale(v3_make(u[9], u[10], u[11]), 0.5f));
        v3 a = vsgl__ray_aim(x, n, c, t);
        float ht = v3_dot(n, v3_sub(t, x));
        if (ht > 0.0f) {
            VT_CHECK(a.x == t.x && a.y == t.y && a.z == t.z, "trial %d: a point above the horizon moved", trial);
            ++kept;
            continue;
        }
        v3 m = v3_sub(v3_scale(c, 2.0f), t), dm = v3_sub(m, x);
        float hm = v3_dot(n, dm), lm = v3_length(dm);
        v3 da = v3_sub(a, x);
        float ha = v3_dot(n, da), la = v3_length(da);
        if (hm >= 0.05f * lm) {
            VT_CHECK(a.x == m.x && a.y == m.y && a.z == m.z, "trial %d: not the mirror image", trial);
            ++mirrored;
            continue;
        }
        /* raised along n to 5 % of the mirror image's distance, nothing else moved */
        v3 off = v3_sub(a, m);
        float along = v3_dot(off, n), across = v3_length(v3_sub(off, v3_scale(n, along)));
        VT_CHECK(fabsf(ha - 0.05f * lm) <= 1e-4f * (1.0f + lm) && across <= 1e-5f * (1.0f + lm) && ha > 0.0f && la > 0.0f,
                 "trial %d: height %g, want %g; moved across n by %g", trial, ha, 0.05f * lm, across);
        ++raised;
    }
    VT_CHECK(kept > 1000 && mirrored > 1000 && raised > 1000, "cases: %zu kept, %zu mirrored, %zu raised", kept, mirrored,
             raised);
}
