/* What is decided from bounds before a ray or a fit: segments proven
 * unblocked (scene/occluders.c), checked against an exact segment-triangle
 * test in double precision; and RSM texels facing out of the scene
 * (vsgl__rsm_drop_outward), against the sun's power on the one outside
 * wall it lights. */
#include "harness.h"
#include "scene_fixture.h"
#include "rsm/rsm.h"
#include "scene/scene_data.h"
#include "scene/scene_internal.h"

#include <string.h>

/* Does segment a-b meet triangle p0 p1 p2 (Moller-Trumbore, double, ends
 * and edges included)? */
static int segment_meets_triangle(const double a[3], const double b[3], const float *p0, const float *p1,
                                  const float *p2)
{
    double d[3], e1[3], e2[3], s[3], h[3], q[3];
    for (int k = 0; k < 3; ++k) {
        d[k] = b[k] - a[k];
        e1[k] = (double)p1[k] - p0[k];
        e2[k] = (double)p2[k] - p0[k];
        s[k] = a[k] - p0[k];
    }
    h[0] = d[1] * e2[2] - d[2] * e2[1];
    h[1] = d[2] * e2[0] - d[0] * e2[2];
    h[2] = d[0] * e2[1] - d[1] * e2[0];
    double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
    if (fabs(det) < 1e-18)
        return 0; /* parallel: a segment in the triangle's plane counts as not blocked */
    double u = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) / det;
    q[0] = s[1] * e1[2] - s[2] * e1[1];
    q[1] = s[2] * e1[0] - s[0] * e1[2];
    q[2] = s[0] * e1[1] - s[1] * e1[0];
    double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
    double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
    const double m = 1e-9;
    return u >= -m && v >= -m && u + v <= 1.0 + m && t >= -m && t <= 1.0 + m;
}

static uint32_t next(uint32_t *x)
{
    *x ^= *x << 13;
    *x ^= *x >> 17;
    *x ^= *x << 5;
    return *x;
}

static double uniform(uint32_t *x) { return (next(x) >> 8) * (1.0 / 16777216.0); }

/* The fixture room (its walls on the bounds' faces) with two blocks in it
 * (12 triangles each: one box around both; 96 each: a box per leaf of the
 * split), or only the walls. Random segments, half of them from a point on a wall
 * (offset off it like a shading ray's origin): a segment called clear must
 * meet no triangle, and in the room with blocks a good share of them is
 * clear (with the walls alone, every segment inside). End points outside
 * the bounds are never called clear. */
/* Scene arrays with room for the blocks' many small triangles. */
#define OCC_TRIS 5120
static float occ_pos[OCC_TRIS * 9];
static uint32_t occ_idx[OCC_TRIS * 3], occ_mat[OCC_TRIS];

/* Blocks [lo, hi] as 6 quads, each face cut into n x n pieces (so that the
 * occluders' split has enough triangles to make leaves), into `fx`'s
 * arrays copied to occ_*: returns the triangle count. */
static uint32_t copy_with_pieces(const fx_scene *fx, const float (*lo)[3], const float (*hi)[3], int blocks, int n)
{
    uint32_t t = 0;
    for (uint32_t i = 0; i < fx->triangle_count; ++i, ++t) {
        for (int k = 0; k < 3; ++k) {
            memcpy(occ_pos + 9 * t + 3 * k, fx->positions + 3 * fx->indices[3 * i + k], 3 * sizeof(float));
            occ_idx[3 * t + k] = 3 * t + (uint32_t)k;
        }
        occ_mat[t] = fx->material_indices[i];
    }
    for (int b = 0; b < blocks; ++b)
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side)
                for (int u = 0; u < n; ++u)
                    for (int v = 0; v < n; ++v)
                        for (int half = 0; half < 2; ++half, ++t) {
                            const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
                            const int cu[3] = {0, 1, half ? 1 : 0}, cv[3] = {0, half ? 1 : 1, half ? 0 : 1};
                            for (int k = 0; k < 3; ++k) {
                                float *p = occ_pos + 9 * t + 3 * k;
                                p[axis] = side ? hi[b][axis] : lo[b][axis];
                                p[a1] = lo[b][a1] + (hi[b][a1] - lo[b][a1]) * (float)(u + cu[k]) / (float)n;
                                p[a2] = lo[b][a2] + (hi[b][a2] - lo[b][a2]) * (float)(v + cv[k]) / (float)n;
                                occ_idx[3 * t + k] = 3 * t + (uint32_t)k;
                            }
                            occ_mat[t] = 3;
                        }
    return t;
}

/* The fixture room with `blocks` of the two blocks [lo, hi] in it, each
 * face cut into pieces x pieces quads (copy_with_pieces); NULL (reported)
 * if the scene is refused. *tris: its triangle count. */
static vsgl_scene *room_with_blocks(vsgl_context *ctx, const float (*lo)[3], const float (*hi)[3], int blocks,
                                    int pieces, uint32_t *tris)
{
    fx_scene fx;
    fx_room(&fx, 8, 6, 0.5f, 100.0f);
    *tris = copy_with_pieces(&fx, lo, hi, blocks, pieces);
    vsgl_scene_desc d = *fx_desc(&fx);
    d.vertex_count = 3 * *tris;
    d.positions = occ_pos;
    d.triangle_count = *tris;
    d.indices = occ_idx;
    d.material_indices = occ_mat;
    vsgl_scene *sc = NULL;
    if (vsgl_scene_create(ctx, &d, &sc) != VSGL_OK)
        VT_REPORT("scene: %s", vsgl_context_last_error(ctx));
    return sc;
}

VT_TEST(occluders_never_call_a_blocked_segment_clear)
{
    vsgl_context *ctx = fx_context(1);
    VT_REQUIRE(ctx, "context");
    /* two blocks: one on the floor, one under the ceiling across the room */
    const float lo[2][3] = {{-0.6f, -0.2f, 0.0f}, {0.4f, 0.5f, 1.2f}}, hi[2][3] = {{-0.2f, 0.3f, 0.7f}, {0.8f, 0.9f, 1.5f}};
    int clear_one_box = 0;
    for (int blocks = 0; blocks < 3; ++blocks) { /* none, two of 12 triangles, two of 96 (leaves) */
        uint32_t tris;
        vsgl_scene *sc = room_with_blocks(ctx, lo, hi, blocks ? 2 : 0, blocks == 2 ? 2 : 1, &tris);
        VT_REQUIRE(sc, "blocks %d: no scene", blocks);
        uint32_t rng = 12345u; /* the same segments in each scene */
        int clear = 0, wrong = 0, inside = 0, outside_clear = 0;
        const int n = 20000;
        for (int i = 0; i < n; ++i) {
            double a[3], b[3];
            for (int k = 0; k < 3; ++k) {
                a[k] = k == 2 ? 2.0 * uniform(&rng) : 2.0 * uniform(&rng) - 1.0;
                b[k] = k == 2 ? 2.0 * uniform(&rng) : 2.0 * uniform(&rng) - 1.0;
            }
            if (i & 1) { /* on the floor, the left wall or the ceiling, 1e-4 off it */
                int w = (int)(next(&rng) % 3);
                if (w == 0) a[2] = 1e-4;
                else if (w == 1) a[0] = -1.0 + 1e-4;
                else a[2] = 2.0 - 1e-4;
            }
            if (i % 7 == 0) /* past the bounds, by 1 um to 1 cm */
                b[1] = -1.0 - 1e-6 * pow(10.0, 4.0 * uniform(&rng));
            int blocked = 0;
            for (uint32_t t = 0; t < tris && !blocked; ++t)
                blocked = segment_meets_triangle(a, b, occ_pos + 9 * t, occ_pos + 9 * t + 3, occ_pos + 9 * t + 6);
            int c = vsgl__scene_segment_clear(sc, v3_make((float)a[0], (float)a[1], (float)a[2]),
                                              v3_make((float)b[0], (float)b[1], (float)b[2]));
            clear += c;
            inside += i % 7 != 0;
            outside_clear += c && i % 7 == 0;
            if (c && blocked && wrong++ < 4)
                VT_REPORT("blocks %d: segment (%g %g %g)-(%g %g %g) called clear, but it meets a triangle", blocks,
                          a[0], a[1], a[2], b[0], b[1], b[2]);
        }
        VT_CHECK(outside_clear == 0, "blocks %d: %d segments leaving the bounds called clear", blocks, outside_clear);
        if (blocks == 2) /* the leaves' boxes leave the space between the blocks free */
            VT_CHECK(clear > clear_one_box * 11 / 10, "leaves: %d clear, one box around both: %d", clear,
                     clear_one_box);
        clear_one_box = clear;
        if (blocks)
            VT_CHECK(clear > inside / 4, "blocks %d: only %d of %d segments inside called clear", blocks, clear,
                     inside);
        else
            VT_CHECK(clear == inside, "walls only: %d of %d segments inside called clear", clear, inside);
        vsgl_scene_destroy(sc);
    }
    vsgl_context_destroy(ctx);
}

/* Shading's visibility rays (vsgl__scene_occluded_towards_each): in a
 * scene whose occluders are few (one block: 12 triangles, at most
 * VSGL__OCC_FEW) or none (walls only), a segment strictly inside the bounds
 * is tested against the occluders alone (scene/occlude_few.c) or is clear;
 * the rest, and every segment of a scene with more occluders (two blocks:
 * 24), are traced by Embree: as a coherent stream, and with the blocks'
 * faces cut into 14 x 14 pieces (4716 triangles, at least
 * VSGL__RAY_INCOHERENT_MIN) as an incoherent one. Each answer against the
 * exact test in double over every triangle, for segments from a point just
 * off a wall (as a shading ray starts) or inside the room to one inside or
 * past the bounds.
 * They may differ only for a segment grazing a triangle's edge or ending
 * on it: none of these 20000 does within 1e-4. */
VT_TEST(visibility_rays_route_inside_segments_to_the_occluders)
{
    vsgl_context *ctx = fx_context(1);
    VT_REQUIRE(ctx, "context");
    const float lo[2][3] = {{-0.6f, -0.2f, 0.0f}, {0.4f, 0.5f, 1.2f}}, hi[2][3] = {{-0.2f, 0.3f, 0.7f}, {0.8f, 0.9f, 1.5f}};
    for (int blocks = 0; blocks < 4; ++blocks) { /* none, one, two, two of many triangles */
        uint32_t tris;
        vsgl_scene *sc = room_with_blocks(ctx, lo, hi, blocks < 3 ? blocks : 2, blocks < 3 ? 1 : 14, &tris);
        VT_REQUIRE(sc, "blocks %d: no scene", blocks);
        if (blocks == 3)
            VT_CHECK(tris >= VSGL__RAY_INCOHERENT_MIN, "%u triangles: the incoherent stream is not tested", tris);
        enum { N = 20000, B = 64 };
        static float ox[N], oy[N], oz[N], tx[N], ty[N], tz[N];
        static int want[N];
        static uint32_t lane[N];
        static unsigned char got[N];
        uint32_t rng = 777u;
        const float eps = 1e-4f;
        int blocked = 0;
        for (int i = 0; i < N; ++i) {
            double a[3], b[3];
            for (int k = 0; k < 3; ++k) {
                a[k] = k == 2 ? 2.0 * uniform(&rng) : 2.0 * uniform(&rng) - 1.0;
                b[k] = k == 2 ? 2.0 * uniform(&rng) : 2.0 * uniform(&rng) - 1.0;
            }
            if (i & 1) { /* off the floor or the left wall, as a shading ray's origin */
                if (next(&rng) & 1) a[2] = 1e-4;
                else a[0] = -1.0 + 1e-4;
            }
            if (i % 5 == 0) /* its target past the bounds */
                b[1] = -1.0 - 0.01 * uniform(&rng);
            ox[i] = (float)a[0], oy[i] = (float)a[1], oz[i] = (float)a[2];
            tx[i] = (float)b[0], ty[i] = (float)b[1], tz[i] = (float)b[2];
            lane[i] = (uint32_t)i;
            /* the traced segment stops eps short of the target */
            double e[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            double len = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]), f = (len - eps) / len, c[3];
            for (int k = 0; k < 3; ++k)
                c[k] = a[k] + e[k] * f;
            want[i] = 0;
            for (uint32_t t = 0; t < tris && !want[i] && len > eps; ++t)
                want[i] = segment_meets_triangle(a, c, occ_pos + 9 * t, occ_pos + 9 * t + 3, occ_pos + 9 * t + 6);
            blocked += want[i];
        }
        const float *const tgt[3] = {tx, ty, tz};
        for (int b = 0; b < N; b += B) /* the shading's batches of a block's lanes */
            vsgl__scene_occluded_towards_each(sc, N - b < B ? (uint32_t)(N - b) : B, lane + b, ox, oy, oz, tgt, eps,
                                              got + b);
        int wrong = 0;
        for (int i = 0; i < N; ++i)
            if (got[i] != want[i] && wrong++ < 4)
                VT_REPORT("blocks %d: segment %d (%g %g %g)-(%g %g %g): blocked %d, exact %d", blocks, i, ox[i], oy[i],
                          oz[i], tx[i], ty[i], tz[i], got[i], want[i]);
        VT_CHECK(wrong == 0, "blocks %d: %d of %d answers differ from the exact test", blocks, wrong, N);
        if (blocks)
            VT_CHECK(blocked > N / 20, "blocks %d: only %d segments blocked: the test sees little", blocks, blocked);
        vsgl_scene_destroy(sc);
    }
    vsgl_context_destroy(ctx);
}

/* The fixture's only light: a white sun of 3 W/m^2 from (x, 0, 4) towards
 * the origin. */
static void sun_only(fx_scene *fx, float x)
{
    vsgl_light *L = &fx->lights[0];
    memset(L, 0, sizeof *L);
    L->type = VSGL_LIGHT_SUN;
    L->color[0] = L->color[1] = L->color[2] = 1.0f;
    L->power = 3.0f; /* W/m^2 */
    const float eye[3] = {x, 0, 4}, at[3] = {0, 0, 0};
    fx_look_at(L->world_from_light, eye, at);
    fx->light_count = 1;
}

/* An open-top box (the fixture room with a front wall, no ceiling) under a
 * sun from (3, 0, 4): it lights the floor and the inside of the left wall
 * through the top, and the outside of the right wall x = +1 (4 m^2 at
 * cos 0.6). Only that outside is dropped: its power is E 0.6 x 4, and
 * every texel left has a corner of the box in front of it. */
VT_TEST(rsm_drop_outward_takes_only_the_outside_of_a_wall)
{
    vsgl_context *ctx = fx_context(1);
    VT_REQUIRE(ctx, "context");
    fx_scene fx;
    fx_room(&fx, 8, 6, 0.5f, 100.0f);
    fx.triangle_count -= 2; /* no ceiling (the room's last quad) */
    fx.vertex_count -= 4;
    const float front[4][3] = {{-1, -1, 0}, {-1, -1, 2}, {1, -1, 2}, {1, -1, 0}};
    fx_quad(&fx, front, 3);
    sun_only(&fx, 3.0f);
    vsgl_scene *sc = NULL;
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &sc) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    vsgl_rsm r;
    VT_REQUIRE(vsgl__rsm_build(ctx, sc, 0, 256, &r) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    double before = r.total_flux[0], dropped[3];
    vsgl__rsm_drop_outward(sc, &r, dropped);
    /* texel footprints straddle the wall's edges: error ~ perimeter / res */
    VT_CHECK_REL(dropped[0], 3.0 * 0.6 * 4.0, 0.01, "the right wall's outside");
    VT_CHECK_REL(r.total_flux[0], before - dropped[0], 1e-9, "what is left");
    int facing_out = 0;
    for (size_t i = 0; i < r.count; ++i) {
        if (r.material[i] == VSGL__RSM_EMPTY)
            continue;
        double best = -1e30;
        for (int c = 0; c < 8; ++c) {
            double q[3] = {c & 1 ? 1.0 : -1.0, c & 2 ? 1.0 : -1.0, c & 4 ? 2.0 : 0.0}, h = 0.0;
            for (int k = 0; k < 3; ++k)
                h += (q[k] - r.pos[k][i]) * r.nrm[k][i];
            best = h > best ? h : best;
        }
        facing_out += best <= 1e-3;
    }
    VT_CHECK(facing_out == 0, "%d texels left with the whole box behind them", facing_out);
    vsgl__rsm_free(&r);
    vsgl_scene_destroy(sc);
    vsgl_context_destroy(ctx);
}

/* A closed room with a 0.4 m square opening in its roof under a sun from
 * (1, 0, 4): the power that enters is E x 0.16 m^2 x cos(14 deg), all of it
 * on the floor. vsgl__rsm_build_inward's map covers only the square around
 * the opening, on the whole map's grid refined `zoom` times: it holds the
 * same texels as the whole map built at res x zoom (after both drop what
 * faces out), and its power is the analytic one within a texel of that
 * finer grid along the opening's edges. */
VT_TEST(rsm_build_inward_zooms_a_sun_onto_an_opening)
{
    vsgl_context *ctx = fx_context(1);
    VT_REQUIRE(ctx, "context");
    fx_scene fx;
    fx_room(&fx, 8, 6, 0.5f, 100.0f);
    fx.triangle_count -= 2; /* the roof, rebuilt around the opening */
    fx.vertex_count -= 4;
    const float o = 0.2f, front[4][3] = {{-1, -1, 0}, {-1, -1, 2}, {1, -1, 2}, {1, -1, 0}};
    const float strips[4][4] = {{-1, -o, -1, 1}, {o, 1, -1, 1}, {-o, o, -1, -o}, {-o, o, o, 1}}; /* x0 x1 y0 y1 */
    for (int k = 0; k < 4; ++k) {
        const float *s = strips[k];
        const float q[4][3] = {{s[0], s[2], 2}, {s[0], s[3], 2}, {s[1], s[3], 2}, {s[1], s[2], 2}};
        fx_quad(&fx, q, 3);
    }
    fx_quad(&fx, front, 3);
    sun_only(&fx, 1.0f);
    vsgl_scene *sc = NULL;
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &sc) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    const double exact = 3.0 * (2 * o) * (2 * o) * 4.0 / sqrt(17.0);
    const uint32_t res = 64;
    vsgl_rsm whole, win, fine;
    double dropped[3];
    VT_REQUIRE(vsgl__rsm_build(ctx, sc, 0, res, &whole) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    vsgl__rsm_drop_outward(sc, &whole, dropped);
    VT_REQUIRE(vsgl__rsm_build_inward(ctx, sc, 0, res, &win, dropped) == VSGL_OK, "%s",
               vsgl_context_last_error(ctx));
    VT_CHECK(whole.zoom == 1 && win.zoom == 4, "zoom %u (whole map %u): the opening and its margin span 1/4 "
             "to 1/8 of the map", win.zoom, whole.zoom);
    VT_REQUIRE(vsgl__rsm_build(ctx, sc, 0, res * win.zoom, &fine) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    vsgl__rsm_drop_outward(sc, &fine, dropped);
    size_t n_win = 0, n_fine = 0, n_whole = 0;
    for (size_t i = 0; i < whole.count; ++i)
        n_whole += whole.material[i] != VSGL__RSM_EMPTY;
    for (size_t i = 0; i < win.count; ++i)
        n_win += win.material[i] != VSGL__RSM_EMPTY;
    for (size_t i = 0; i < fine.count; ++i)
        n_fine += fine.material[i] != VSGL__RSM_EMPTY;
    /* the same grid: the same texels, but for the edges the window traces
     * again (rsm_edges.c: the outer ring of partly lit texels) */
    VT_CHECK(n_win >= n_fine && n_win <= n_fine + n_fine / 10, "%zu texels in the window, %zu in the finer whole map",
             n_win, n_fine);
    double e_whole = fabs(whole.total_flux[0] / exact - 1), e_win = fabs(win.total_flux[0] / exact - 1);
    /* a texel of the finer grid is ~1.1 cm across the beam; the edge texels
     * carry the fraction of their 16 rays that land inside */
    VT_CHECK(e_win < 0.005, "window power %.5f W against %.5f W through the opening (%.2f %%)", win.total_flux[0],
             exact, 100 * e_win);
    printf("    power through the opening %.5f W: whole map at %u %.5f (%.2f %%), window %.5f (%.2f %%); %zu texels in "
           "the room, %zu with the whole map\n", exact, res, whole.total_flux[0], 100 * e_whole, win.total_flux[0],
           100 * e_win, n_win, n_whole);
    vsgl__rsm_free(&whole);
    vsgl__rsm_free(&win);
    vsgl__rsm_free(&fine);
    vsgl_scene_destroy(sc);
    vsgl_context_destroy(ctx);
}

/* The same room, the sun turned in 24 small steps (its patch slides by
 * ~1/5 of a texel of the whole 64^2 map per step): the power through the
 * opening is E A cos at every step. Texels lit whole or not at all by one
 * ray put it off by up to half the edge texels (1.7 % for the finer whole
 * map at x = 1) and move it in steps as the edge crosses texel centres;
 * the edge texels traced with 16 rays each keep it within 0.3 % throughout
 * (0.17 % measured). */
VT_TEST(rsm_edges_keep_a_sliding_opening_power_steady)
{
    vsgl_context *ctx = fx_context(2);
    VT_REQUIRE(ctx, "context");
    fx_scene fx;
    fx_room(&fx, 8, 6, 0.5f, 100.0f);
    fx.triangle_count -= 2;
    fx.vertex_count -= 4;
    const float o = 0.2f, front[4][3] = {{-1, -1, 0}, {-1, -1, 2}, {1, -1, 2}, {1, -1, 0}};
    const float strips[4][4] = {{-1, -o, -1, 1}, {o, 1, -1, 1}, {-o, o, -1, -o}, {-o, o, o, 1}};
    for (int k = 0; k < 4; ++k) {
        const float *s = strips[k];
        const float q[4][3] = {{s[0], s[2], 2}, {s[0], s[3], 2}, {s[1], s[3], 2}, {s[1], s[2], 2}};
        fx_quad(&fx, q, 3);
    }
    fx_quad(&fx, front, 3);
    double worst = 0.0, worst_plain = 0.0, lo = INFINITY, hi = -INFINITY;
    for (int step = 0; step < 24; ++step) {
        float x = 1.0f + 0.004f * (float)step;
        sun_only(&fx, x);
        vsgl_scene *sc = NULL;
        VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &sc) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        const double exact = 3.0 * (2 * o) * (2 * o) * 4.0 / sqrt((double)x * x + 16.0);
        vsgl_rsm win, plain;
        double dropped[3];
        VT_REQUIRE(vsgl__rsm_build_inward(ctx, sc, 0, 64, &win, dropped) == VSGL_OK, "%s",
                   vsgl_context_last_error(ctx));
        VT_REQUIRE(vsgl__rsm_build(ctx, sc, 0, 64 * win.zoom, &plain) == VSGL_OK, "%s",
                   vsgl_context_last_error(ctx));
        vsgl__rsm_drop_outward(sc, &plain, dropped);
        double e = win.total_flux[0] / exact - 1.0, ep = plain.total_flux[0] / exact - 1.0;
        worst = fmax(worst, fabs(e));
        worst_plain = fmax(worst_plain, fabs(ep));
        lo = fmin(lo, e);
        hi = fmax(hi, e);
        vsgl__rsm_free(&win);
        vsgl__rsm_free(&plain);
        vsgl_scene_destroy(sc);
    }
    VT_CHECK(worst < 0.003, "the power through the opening off by up to %.3f %% as the sun turns", 100 * worst);
    printf("    power through the opening over 24 steps: within %.3f %% (range %.3f %%); one ray per texel "
           "at the same grid: within %.3f %%\n", 100 * worst, 100 * (hi - lo), 100 * worst_plain);
    vsgl_context_destroy(ctx);
}
