/* Reflective shadow maps: power conservation in a closed box per light
 * type (against the emitted power derived from Cycles' radiance
 * conventions, computed here independently), irradiance implied on a lit
 * plane against analytic values, determinism and cancel. */
#include "harness.h"
#include "scene_fixture.h"
#include "core/context.h"
#include "rsm/rsm.h"
#include "rsm/rsm_light.h"

#include <stdlib.h>
#include <string.h>

static const double PI = 3.14159265358979323846;

/* Closed box: the fixture room plus its front wall y = -1. */
static void closed_box(fx_scene *s)
{
    fx_room(s, 8, 6, 0.5f, 100.0f);
    const float front[4][3] = {{-1, -1, 0}, {-1, -1, 2}, {1, -1, 2}, {1, -1, 0}};
    fx_quad(s, front, 3);
}

/* A large floor quad (z = 0, +-half) only. */
static void floor_only(fx_scene *s, float half)
{
    fx_room(s, 8, 6, 0.5f, 100.0f);
    s->vertex_count = s->triangle_count = 0;
    const float fl[4][3] = {{-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0}};
    fx_quad(s, fl, 3);
}

static vsgl_scene *make(vsgl_context *ctx, fx_scene *s)
{
    vsgl_scene *sc = NULL;
    vsgl_result r = vsgl_scene_create(ctx, fx_desc(s), &sc);
    VT_CHECK(r == VSGL_OK, "scene_create: %s", vsgl_context_last_error(ctx));
    return sc;
}

/* The scene and the RSM of its light 0 at `res`; NULL (after a failed
 * check, nothing left allocated) if either fails. */
static vsgl_scene *make_rsm(vsgl_context *ctx, fx_scene *s, uint32_t res, vsgl_rsm *r)
{
    vsgl_scene *sc = make(ctx, s);
    if (sc && vsgl__rsm_build(ctx, sc, 0, res, r) == VSGL_OK)
        return sc;
    VT_CHECK(0, "build: %s", vsgl_context_last_error(ctx));
    vsgl_scene_destroy(sc);
    return NULL;
}

static void set_light(vsgl_light *L, int type, float x, float y, float z)
{
    float keep_c[3] = {1.0f, 0.5f, 0.25f};
    memset(L, 0, sizeof *L);
    L->type = type;
    L->power = 100.0f;
    memcpy(L->color, keep_c, sizeof keep_c);
    fx_translation(L->world_from_light, x, y, z); /* emits along -Z */
    L->spot_size = 1.2f;
    L->spot_blend = 0.3f;
    L->size_x = L->size_y = 0.05f;
    L->spread = (float)PI;
}

static double smooth01(double f) { f = f < 0 ? 0 : (f > 1 ? 1 : f); return f * f * (3 - 2 * f); }

/* Blender 3.4 spot: relative intensity (measured: cos(theta) times the blend smoothstep) */
static double spot_rel(double c, double size, double blend)
{
    double ch = cos(size / 2), sm = (1 - ch) * blend;
    if (c <= ch)
        return 0;
    return c * (sm > 0 ? smooth01((c - ch) / sm) : 1.0);
}

/* Emitted power / (colour x power) for each type, derived independently. */
static double emitted_fraction(const vsgl_light *L)
{
    if (L->type == VSGL_LIGHT_POINT)
        return 1.0; /* I = P/(4 pi) over 4 pi sr */
    if (L->type == VSGL_LIGHT_SPOT) {
        /* (1/4pi) int mask dw, Simpson in cos(theta) */
        int n = 20000;
        double a = cos(L->spot_size / 2), h = (1 - a) / n, s = 0;
        for (int i = 0; i <= n; ++i)
            s += (i == 0 || i == n ? 1 : (i & 1 ? 4 : 2)) * spot_rel(a + i * h, L->spot_size, L->spot_blend);
        return 2 * PI * s * h / 3 / (4 * PI);
    }
    if (L->type == VSGL_LIGHT_AREA)
        return PI / 4; /* L = P/(4A), Lambertian: pi L A (spread keeps the total) */
    return 0;
}

VT_TEST(rsm_closed_box_total_flux_equals_emitted_power)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    const int types[] = {VSGL_LIGHT_POINT, VSGL_LIGHT_SPOT, VSGL_LIGHT_SPOT, VSGL_LIGHT_AREA, VSGL_LIGHT_AREA, VSGL_LIGHT_AREA, VSGL_LIGHT_SPOT};
    for (unsigned k = 0; k < sizeof types / sizeof types[0]; ++k) {
        fx_scene s;
        closed_box(&s);
        vsgl_light *L = &s.lights[0];
        set_light(L, types[k], 0.1f, 0.2f, 1.5f);
        if (k == 2) { L->spot_size = 2.6f; L->spot_blend = 0.0f; } /* wide: cube map, hard edge */
        if (k == 4) { L->spread = 1.0f; L->area_shape = VSGL_AREA_DISK; L->size_x = 0.4f; }
        if (k == 5) { L->area_shape = VSGL_AREA_RECTANGLE; L->size_x = 0.6f; L->size_y = 0.3f; L->spread = 2.0f; }
        if (k == 6) { L->spot_size = 0.5f; L->spot_blend = 1.0f; fx_look_at(L->world_from_light, (float[3]){0.3f, 0.1f, 1.0f}, (float[3]){-1, 0.5f, 0.2f}); }
        vsgl_scene *sc = make(ctx, &s);
        if (!sc)
            continue;
        vsgl_rsm r;
        uint32_t res = 128;
        VT_CHECK(vsgl__rsm_build(ctx, sc, 0, res, &r) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        double want = emitted_fraction(L) * L->power;
        for (int c = 0; c < 3; ++c) {
            double sum = 0;
            for (size_t i = 0; i < r.count; ++i)
                sum += r.flux[c][i];
            VT_CHECK_REL(r.total_flux[c], sum, 1e-9, "total_flux is the sum");
            VT_CHECK_REL(r.total_flux[c], want * L->color[c], 2e-4,
                         "case %u type %d size %g blend %g spread %g shape %d res %u ch %d", k, L->type,
                         L->spot_size, L->spot_blend, L->spread, L->area_shape, res, c);
        }
        if (k == 0) { /* footprints of a point light's texels tile the box: 6 faces of 4 m^2 */
            double area = 0;
            for (size_t i = 0; i < r.count; ++i)
                area += r.area[i];
            VT_CHECK_REL(area, 24.0, 5e-3, "sum of texel footprints, point light in a 2 m box, res %u", res);
        }
        size_t empty = 0;
        for (size_t i = 0; i < r.count; ++i)
            empty += r.material[i] == VSGL__RSM_EMPTY && r.flux[0][i] > 0;
        VT_CHECK(empty == 0, "%zu texels with flux but no surface", empty);
        vsgl__rsm_free(&r);
        vsgl_scene_destroy(sc);
    }
    vsgl_context_destroy(ctx);
}

VT_TEST(rsm_sun_flux_is_irradiance_times_projected_area)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    fx_scene s;
    closed_box(&s); /* box 2 x 2 x 2 */
    vsgl_light *L = &s.lights[0];
    set_light(L, VSGL_LIGHT_SUN, 0, 0, 5);
    L->power = 3.0f;
    const float eye[3] = {3, 1, 4}, at[3] = {0, 0, 0};
    fx_look_at(L->world_from_light, eye, at);
    double d[3] = {-3, -1, -4}, l = sqrt(26.0);
    double want = 3.0 * (fabs(d[0]) / l * 4 + fabs(d[1]) / l * 4 + fabs(d[2]) / l * 4);
    vsgl_scene *sc = make(ctx, &s);
    vsgl_rsm r;
    if (sc && vsgl__rsm_build(ctx, sc, 0, 256, &r) == VSGL_OK) {
        /* texel footprints straddle the silhouette: error ~ perimeter / res */
        VT_CHECK_REL(r.total_flux[0], want, 5e-3, "sun 3 W/m^2 along (-3,-1,-4), box 2^3");
        vsgl__rsm_free(&r);
    } else {
        VT_CHECK(0, "build: %s", vsgl_context_last_error(ctx));
    }
    vsgl_scene_destroy(sc);
    vsgl_context_destroy(ctx);
}

/* Smooth separable kernel of half-width w with unit integral over the
 * plane: k(t) = cos^2(pi t / 2) on [-1, 1]. A texel grid aligned with a box
 * patch aliases (a 0.3 m patch over 7.8 mm texels loses 2 %); this kernel's
 * spectrum decays as 1/f^3, so the grid sum converges fast. */
static double kern(double dx, double dy, double w)
{
    double u = dx / w, v = dy / w;
    if (fabs(u) >= 1 || fabs(v) >= 1)
        return 0;
    double a = cos(0.5 * PI * u), b = cos(0.5 * PI * v);
    return a * a * b * b / (w * w);
}

/* Irradiance implied at floor point (x, y) by the RSM, kernel-filtered. */
static double rsm_irradiance(const vsgl_rsm *r, int c, double x, double y, double w)
{
    double s = 0;
    for (size_t i = 0; i < r->count; ++i)
        if (r->material[i] != VSGL__RSM_EMPTY)
            s += r->flux[c][i] * kern(r->pos[0][i] - x, r->pos[1][i] - y, w);
    return s;
}

VT_TEST(rsm_irradiance_on_plane_matches_analytic)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    const int types[] = {VSGL_LIGHT_POINT, VSGL_LIGHT_SPOT, VSGL_LIGHT_SUN, VSGL_LIGHT_AREA};
    const double h = 2.0;
    for (unsigned k = 0; k < 4; ++k) {
        fx_scene s;
        floor_only(&s, 6.0f);
        vsgl_light *L = &s.lights[0];
        set_light(L, types[k], 0, 0, (float)h);
        if (types[k] == VSGL_LIGHT_SUN) {
            L->power = 3.0f;
            const float eye[3] = {1, 0, 3}, at[3] = {0, 0, 0};
            fx_look_at(L->world_from_light, eye, at);
        }
        vsgl_rsm r;
        vsgl_scene *sc = make_rsm(ctx, &s, 512, &r);
        if (!sc)
            continue;
        const double xs[] = {0.0, 0.5, 1.0};
        for (int q = 0; q < 3; ++q) {
            const double w = 0.2;
            /* analytic irradiance filtered by the same kernel (midpoint rule, 64^2) */
            double want = 0;
            int n = 64;
            for (int a = 0; a < n; ++a)
                for (int b = 0; b < n; ++b) {
                    double x = xs[q] + w * (2.0 * (a + 0.5) / n - 1), y = w * (2.0 * (b + 0.5) / n - 1);
                    double d2 = x * x + y * y + h * h, c = h / sqrt(d2), E;
                    switch (types[k]) {
                    case VSGL_LIGHT_POINT: E = L->power / (4 * PI) * c / d2; break;
                    case VSGL_LIGHT_SPOT: E = L->power / (4 * PI) * spot_rel(c, L->spot_size, L->spot_blend) * c / d2; break;
                    case VSGL_LIGHT_SUN: E = 3.0 * 3.0 / sqrt(10.0); break;
                    default: E = L->power / 4.0 * c * c / d2; break; /* L A cos cos / d^2, L = P/(4A) */
                    }
                    want += E * kern(x - xs[q], y, w);
                }
            want *= 4 * w * w / ((double)n * n);
            if (want <= 0)
                continue;
            for (int ch = 0; ch < 3; ++ch)
                VT_CHECK_REL(rsm_irradiance(&r, ch, xs[q], 0.0, w), want * L->color[ch], 2e-3,
                             "type %d patch at x=%g (h=%g, res 512) ch %d", types[k], xs[q], h, ch);
        }
        vsgl__rsm_free(&r);
        vsgl_scene_destroy(sc);
    }
    vsgl_context_destroy(ctx);
}

/* Blender 4.0+ spot (VSGL_LIGHT_FLAG_BLENDER_4, measured in Blender 5.0):
 * intensity P/(4 pi) times the blend alone, the cone in the light frame
 * divided by the object's scale. Relative intensity towards local
 * direction (x, y, z) (the spot points along -z) for scales (sx, sy, sz). */
static double spot_v4_rel(double x, double y, double z, const double sc[3], double size, double blend)
{
    x /= sc[0];
    y /= sc[1];
    z /= sc[2];
    return spot_rel(-z / sqrt(x * x + y * y + z * z), size, blend) / (-z / sqrt(x * x + y * y + z * z));
}

VT_TEST(rsm_spot_v4_irradiance_and_power)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    const double h = 2.0;
    const double scales[2][3] = {{1.0, 1.0, 1.0}, {1.0, 0.5, 1.0}};
    for (int k = 0; k < 2; ++k) {
        const double *sc3 = scales[k];
        /* irradiance on a floor 2 m below */
        fx_scene s;
        floor_only(&s, 6.0f);
        vsgl_light *L = &s.lights[0];
        set_light(L, VSGL_LIGHT_SPOT, 0, 0, (float)h);
        L->flags = VSGL_LIGHT_FLAG_BLENDER_4;
        for (int c = 0; c < 3; ++c)
            L->world_from_light[4 * c + 1] *= (float)sc3[1];
        vsgl_rsm r;
        vsgl_scene *sc = make_rsm(ctx, &s, 512, &r);
        if (!sc)
            continue;
        const double pts[5][2] = {{0, 0}, {0.5, 0}, {1.0, 0}, {0, 0.3}, {0, 0.55}};
        for (int q = 0; q < 5; ++q) {
            const double w = 0.1;
            double want = 0, want34 = 0;
            int n = 64;
            for (int a = 0; a < n; ++a)
                for (int b = 0; b < n; ++b) {
                    double x = pts[q][0] + w * (2.0 * (a + 0.5) / n - 1), y = pts[q][1] + w * (2.0 * (b + 0.5) / n - 1);
                    double d2 = x * x + y * y + h * h, c = h / sqrt(d2);
                    double kk = kern(x - pts[q][0], y - pts[q][1], w);
                    want += L->power / (4 * PI) * spot_v4_rel(x, y, -h, sc3, L->spot_size, L->spot_blend) * c / d2 * kk;
                    want34 += L->power / (4 * PI) * spot_rel(c, L->spot_size, L->spot_blend) * c / d2 * kk;
                }
            want *= 4 * w * w / ((double)n * n);
            want34 *= 4 * w * w / ((double)n * n);
            double got = rsm_irradiance(&r, 0, pts[q][0], pts[q][1], w);
            VT_CHECK(fabs(got - want * L->color[0]) <= 3e-3 * fmax(want * L->color[0], 0.01),
                     "scale (%g %g %g) at (%g, %g): RSM %g, 4.0+ model %g (3.4 model %g)", sc3[0], sc3[1], sc3[2],
                     pts[q][0], pts[q][1], got, want * L->color[0], want34 * L->color[0]);
        }
        vsgl__rsm_free(&r);
        vsgl_scene_destroy(sc);

        /* total flux in a closed box = (P / 4 pi) int mask dw, integrated
         * here over the plane z = -1 (dw = dx dy / (1 + x^2 + y^2)^1.5) */
        closed_box(&s);
        L = &s.lights[0];
        set_light(L, VSGL_LIGHT_SPOT, 0.1f, 0.2f, 1.5f);
        L->flags = VSGL_LIGHT_FLAG_BLENDER_4;
        for (int c = 0; c < 3; ++c)
            L->world_from_light[4 * c + 1] *= (float)sc3[1];
        sc = make_rsm(ctx, &s, 256, &r);
        if (!sc)
            continue;
        double e = 0, lim = 1.0; /* the cone (half 0.6 rad, tan 0.68) fits in [-1, 1]^2 */
        int n = 1000;
        for (int a = 0; a < n; ++a)
            for (int b = 0; b < n; ++b) {
                double x = lim * (2.0 * (a + 0.5) / n - 1), y = lim * (2.0 * (b + 0.5) / n - 1);
                double m = spot_v4_rel(x, y, -1.0, sc3, L->spot_size, L->spot_blend);
                e += m / pow(1 + x * x + y * y, 1.5);
            }
        e *= 4 * lim * lim / ((double)n * n) / (4 * PI);
        VT_CHECK_REL(r.total_flux[0], e * L->power * L->color[0], 1e-3, "scale (%g %g %g): total flux", sc3[0], sc3[1], sc3[2]);
        vsgl__rsm_free(&r);
        vsgl_scene_destroy(sc);
    }
    vsgl_context_destroy(ctx);
}

VT_TEST(rsm_is_deterministic_across_thread_counts)
{
    fx_scene s;
    closed_box(&s);
    set_light(&s.lights[0], VSGL_LIGHT_AREA, 0.1f, 0.2f, 1.5f);
    s.lights[0].size_x = 0.5f;
    vsgl_rsm r[2];
    for (int t = 0; t < 2; ++t) {
        const uint32_t threads = t ? 3 : 1;
        vsgl_context *ctx = fx_context(threads);
        vsgl_scene *sc = ctx ? make(ctx, &s) : NULL;
        VT_CHECK(sc && vsgl__rsm_build(ctx, sc, 0, 64, &r[t]) == VSGL_OK, "threads %u", threads);
        vsgl_scene_destroy(sc);
        vsgl_context_destroy(ctx);
    }
    VT_CHECK(memcmp(r[0].total_flux, r[1].total_flux, sizeof r[0].total_flux) == 0, "total flux differs");
    for (int k = 0; k < 3; ++k) {
        VT_CHECK(memcmp(r[0].flux[k], r[1].flux[k], r[0].count * sizeof(float)) == 0, "flux %d", k);
        VT_CHECK(memcmp(r[0].pos[k], r[1].pos[k], r[0].count * sizeof(float)) == 0, "pos %d", k);
    }
    vsgl__rsm_free(&r[0]);
    vsgl__rsm_free(&r[1]);
}

static int32_t cancel_at_half(void *user, const char *stage, float f)
{
    (void)user;
    return strcmp(stage, "rsm") == 0 && f >= 0.5f;
}

VT_TEST(rsm_cancel_and_bad_arguments)
{
    fx_scene s;
    closed_box(&s);
    set_light(&s.lights[0], VSGL_LIGHT_POINT, 0, 0, 1);
    vsgl_context_desc d;
    memset(&d, 0, sizeof d);
    d.progress = cancel_at_half;
    vsgl_context *ctx = NULL;
    vsgl_context_create(&d, &ctx);
    vsgl_scene *sc = make(ctx, &s);
    vsgl_rsm r;
    VT_CHECK(vsgl__rsm_build(ctx, sc, 0, 32, &r) == VSGL_ERROR_CANCELLED, "cancel");
    VT_CHECK(r.pos[0] == NULL && r.count == 0, "nothing left allocated after cancel");
    VT_CHECK(vsgl__rsm_build(ctx, sc, 1, 32, &r) == VSGL_ERROR_INVALID_ARGUMENT, "light index");
    VT_CHECK(strstr(vsgl_context_last_error(ctx), "light 1") != NULL, "message: %s", vsgl_context_last_error(ctx));
    vsgl_scene_destroy(sc);
    vsgl_context_destroy(ctx);
}

VT_TEST(rsm_rect_solid_angle_sums_to_sphere)
{
    /* six cube faces [-1,1]^2 at distance 1 cover 4 pi exactly */
    VT_CHECK_REL(6 * vsgl__rsm_rect_solid_angle(-1, 1, -1, 1), 4 * PI, 1e-12, "cube");
    /* small rectangle: ~ area cos^3 */
    double x = 0.7, y = -0.4, e = 1e-3;
    double want = 4 * e * e / pow(1 + x * x + y * y, 1.5);
    VT_CHECK_REL(vsgl__rsm_rect_solid_angle(x - e, x + e, y - e, y + e), want, 1e-5, "at (%g, %g)", x, y);
}

VT_TEST(rsm_degenerate_lights_and_scenes)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    for (int k = 0; k < 4; ++k) {
        fx_scene s;
        floor_only(&s, 1.0f);
        vsgl_light *L = &s.lights[0];
        set_light(L, k == 3 ? VSGL_LIGHT_SUN : VSGL_LIGHT_SPOT, 0, 0, 1);
        if (k == 0)
            L->power = 0.0f;                          /* zero power */
        if (k == 1) {                                 /* a spot looking up sees nothing */
            const float eye[3] = {0, 0, 1}, at[3] = {0, 0, 2};
            fx_look_at(L->world_from_light, eye, at);
        }
        if (k >= 2)
            s.triangle_count = s.vertex_count = 0;    /* empty scene (k = 3: sun over empty bounds) */
        vsgl_scene *sc = make(ctx, &s);
        if (!sc)
            continue;
        vsgl_rsm r;
        VT_CHECK(vsgl__rsm_build(ctx, sc, 0, 16, &r) == VSGL_OK, "case %d: %s", k, vsgl_context_last_error(ctx));
        int finite = 1;
        for (size_t i = 0; i < r.count; ++i)
            finite &= isfinite(r.flux[0][i]) && isfinite(r.pos[0][i]) && isfinite(r.area[i]);
        VT_CHECK(finite, "case %d: non-finite texel", k);
        VT_CHECK(r.total_flux[0] == 0.0 && r.total_flux[1] == 0.0, "case %d: total flux %g", k, r.total_flux[0]);
        vsgl__rsm_free(&r);
        vsgl_scene_destroy(sc);
    }
    vsgl_context_destroy(ctx);
}

/* vsgl__rsm_light_row (rsm.c's rows: the corner terms shared between
 * neighbouring texels) against vsgl__rsm_light_texel per texel, bit for
 * bit: point (cube faces), spots (3.x, a wide hard-edged cube-map spot, a
 * 4.0+ spot in a scaled, rotated frame), sun, area; odd and even sizes. */
VT_TEST(rsm_light_row_equals_texel_by_texel)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    const int types[] = {VSGL_LIGHT_POINT, VSGL_LIGHT_SPOT, VSGL_LIGHT_SPOT, VSGL_LIGHT_SPOT, VSGL_LIGHT_SUN, VSGL_LIGHT_AREA};
    for (unsigned k = 0; k < sizeof types / sizeof types[0]; ++k) {
        fx_scene s;
        closed_box(&s);
        vsgl_light *L = &s.lights[0];
        set_light(L, types[k], 0.1f, 0.2f, 1.5f);
        if (k == 2) { L->spot_size = 2.6f; L->spot_blend = 0.0f; }
        if (k == 3) {
            L->spot_size = 0.9f; L->spot_blend = 0.4f; L->flags = VSGL_LIGHT_FLAG_BLENDER_4;
            fx_look_at(L->world_from_light, (float[3]){0.3f, 0.1f, 1.0f}, (float[3]){-1, 0.5f, 0.2f});
            for (int c = 0; c < 3; ++c) { L->world_from_light[c] *= 1.5f; L->world_from_light[4 + c] *= 0.7f; }
        }
        vsgl_scene *sc = make(ctx, &s);
        if (!sc)
            continue;
        for (uint32_t res = 31; res <= 64; res += 33) {
            vsgl_rsm_light l;
            vsgl__rsm_light_setup(sc, 0, res, &l);
            v3 org[64], dir[64], o1, d1;
            double fl[4 * 64], scratch[VSGL__RSM_ROW_SCRATCH(64)], f1[3], b1;
            int lit[64];
            size_t bad = 0, lit_texels = 0;
            for (uint32_t face = 0; face < l.faces; ++face)
                for (uint32_t row = 0; row < res; ++row) {
                    vsgl__rsm_light_row(&l, face, row, org, dir, fl, lit, scratch);
                    for (uint32_t c = 0; c < res; ++c) {
                        int want = vsgl__rsm_light_texel(&l, face, row, c, &o1, &d1, f1, &b1);
                        lit_texels += want != 0;
                        bad += lit[c] != want || memcmp(&org[c], &o1, sizeof o1) != 0 ||
                               memcmp(&dir[c], &d1, sizeof d1) != 0 || memcmp(&fl[4 * c], f1, sizeof f1) != 0 ||
                               memcmp(&fl[4 * c + 3], &b1, sizeof b1) != 0;
                    }
                }
            VT_CHECK(bad == 0 && lit_texels > 0, "case %u type %d res %u: %zu texels differ (%zu lit)", k, L->type, res,
                     bad, lit_texels);
        }
        vsgl_scene_destroy(sc);
    }
    vsgl_context_destroy(ctx);
}

/* A large area light's RSM lights a wall near the light's horizon evenly.
 * A panel like the demo room's lamp (1.4 x 0.8 m, 2.67 m up, facing down)
 * and a wall 2.8-4.2 m off: an origin's offset on the panel moves its
 * texel's hit on the wall by up to ~0.8 m, several texel spacings, so the
 * origins' pattern decides the density of hits there. Separable 8 x 8
 * strata (8 coordinates per axis) piled the hits into bands 0.1 m apart
 * (here 0.82-1.35 of the exact flux in 0.4 m bands); the (0,2)-sequence's
 * 64 coordinates per axis keep every band within 20 % (0.86-1.07; what is
 * left is the noise of ~45 texels a band, whose origins scatter their hits
 * over ~9 texel spacings). The exact flux: the light's radiance through the
 * rectangle, quadrature over the light and the band. */
VT_TEST(rsm_area_light_lights_a_far_wall_evenly)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    fx_scene s;
    floor_only(&s, 1.0f);
    s.vertex_count = s.triangle_count = 0; /* the fixture's materials and light; the wall alone */
    const float wall[4][3] = {{3, -2.5f, 0}, {3, -2.5f, 2.8f}, {3, 2.5f, 2.8f}, {3, 2.5f, 0}};
    fx_quad(&s, wall, 3);
    vsgl_light *L = &s.lights[0];
    const double lx = -0.5, ly = -0.1, lz = 2.67, sx = 1.4, sy = 0.8;
    set_light(L, VSGL_LIGHT_AREA, (float)lx, (float)ly, (float)lz);
    L->area_shape = VSGL_AREA_RECTANGLE;
    L->size_x = (float)sx;
    L->size_y = (float)sy;
    vsgl_rsm r;
    vsgl_scene *sc = make_rsm(ctx, &s, 128, &r);
    if (sc) {
        const double y0 = -2.3, y1 = -0.9, band = 0.4, rad = L->power / (4.0 * sx * sy); /* L = P/(4A) */
        double worst = 1.0;
        for (int k = 0; k < 4; ++k) { /* z in [0.1, 1.7]: well inside the wall, above the panel's horizon */
            double z0 = 0.1 + band * k, got = 0.0, want = 0.0;
            for (size_t i = 0; i < r.count; ++i)
                if (r.material[i] != VSGL__RSM_EMPTY && r.pos[0][i] > 2.99f && r.pos[1][i] >= y0 &&
                    r.pos[1][i] < y1 && r.pos[2][i] >= z0 && r.pos[2][i] < z0 + band)
                    got += r.flux[0][i] / L->color[0];
            const int nl = 16, ny = 28, nz = 4;
            for (int a = 0; a < nl; ++a)
                for (int b = 0; b < nl; ++b)
                    for (int c = 0; c < ny; ++c)
                        for (int e = 0; e < nz; ++e) {
                            double px = lx + sx * ((a + 0.5) / nl - 0.5), py = ly + sy * ((b + 0.5) / nl - 0.5);
                            double wy = y0 + (y1 - y0) * (c + 0.5) / ny, wz = z0 + band * (e + 0.5) / nz;
                            double dx = 3.0 - px, dy = wy - py, dz = lz - wz, d2 = dx * dx + dy * dy + dz * dz;
                            want += (dz / sqrt(d2)) * (dx / sqrt(d2)) / d2; /* cos at the light x cos at the wall */
                        }
            want *= rad * (sx * sy / (nl * nl)) * ((y1 - y0) * band / (ny * nz));
            double q = got / want;
            worst = fabs(q - 1.0) > fabs(worst - 1.0) ? q : worst;
            VT_CHECK(fabs(q - 1.0) < 0.2, "band z %.1f-%.1f: RSM flux %.4g W, exact %.4g W (%.2fx)", z0, z0 + band,
                     got, want, q);
        }
        printf("    worst 0.4 m band: %.3f of the exact flux\n", worst);
        vsgl__rsm_free(&r);
        vsgl_scene_destroy(sc);
    }
    vsgl_context_destroy(ctx);
}
