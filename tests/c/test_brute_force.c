/* Brute-force VPL gather against an independent one-bounce quadrature: a
 * spot lights a Lambert floor; a ceiling patch above receives the floor's
 * reflected light. Reference: E(x) = int_floor (rho/pi) E_spot(y) cos_y
 * cos_x / d^2 dA with E_spot analytic (Blender 3.4 spot, docs/units.md).
 * Also: visibility, determinism across thread counts, GlossCol/colour
 * planes, resolve. */
#include "harness.h"
#include "scene_fixture.h"
#include "core/context.h"
#include "gbuffer/gbuffer.h"
#include "rsm/rsm.h"
#include "shade/brute_force.h"
#include "scene/material.h"

#include <stdlib.h>
#include <string.h>

static const double PI = 3.14159265358979323846;

/* floor z=0 [-2,2]^2 (material 0: Lambert 0.5), ceiling patch z=1
 * [-0.5,0.5]^2 (material 1: Lambert 0.8 or metal), optional occluder
 * z=0.8 (material 0); spot at (0,0,0.6) pointing down; camera at
 * (0,0,0.3) looking up. */
static void setup(fx_scene *s, int occluder, int metal_ceiling)
{
    fx_room(s, 16, 12, 0.5f, 100.0f);
    s->vertex_count = s->triangle_count = 0;
    const float fl[4][3] = {{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}};
    const float ce[4][3] = {{-0.5f, -0.5f, 1}, {-0.5f, 0.5f, 1}, {0.5f, 0.5f, 1}, {0.5f, -0.5f, 1}};
    fx_quad(s, fl, 0);
    fx_quad(s, ce, 1);
    if (occluder) {
        const float oc[4][3] = {{0.0f, -0.6f, 0.8f}, {0.0f, 0.6f, 0.8f}, {0.6f, 0.6f, 0.8f}, {0.6f, -0.6f, 0.8f}};
        fx_quad(s, oc, 2);
    }
    memset(s->materials, 0, sizeof s->materials);
    for (int c = 0; c < 3; ++c) {
        s->materials[0].base_color[c] = 0.5f;
        s->materials[1].base_color[c] = 0.8f;
        s->materials[2].base_color[c] = 0.3f;
    }
    s->materials[1].roughness = 1.0f;
    if (metal_ceiling) {
        s->materials[1].metallic = 1.0f;
        s->materials[1].roughness = 0.5f;
    }
    vsgl_light *L = &s->lights[0];
    memset(L, 0, sizeof *L);
    L->type = VSGL_LIGHT_SPOT;
    L->color[0] = L->color[1] = L->color[2] = 1.0f;
    L->power = 100.0f;
    fx_translation(L->world_from_light, 0, 0, 0.6f);
    L->spot_size = 1.2f;
    L->spot_blend = 0.3f;
    s->light_count = 1;
    const float eye[3] = {0, 0, 0.3f}, at[3] = {0, 0, 1};
    fx_look_at(s->camera.world_from_camera, eye, at);
    s->camera.lens_mm = 18.0f;
}

static double smooth01(double f) { f = f < 0 ? 0 : (f > 1 ? 1 : f); return f * f * (3 - 2 * f); }

/* floor irradiance from the spot (intensity P/(4pi) cos(t) smoothstep) */
static double spot_E(double x, double y)
{
    double h = 0.6, d2 = x * x + y * y + h * h, c = h / sqrt(d2);
    double ch = cos(0.6), sm = (1 - ch) * 0.3;
    if (c <= ch)
        return 0;
    return 100.0 / (4 * PI) * c * smooth01((c - ch) / sm) * c / d2;
}

/* irradiance at ceiling point (x, y, 1), normal -z, from the Lambert floor */
static double ceiling_E(double x, double y)
{
    int n = 300;
    double a = 0.45, s = 0, dA = (2 * a / n) * (2 * a / n); /* spot disk radius 0.6 tan 0.6 = 0.41 */
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            double px = -a + (i + 0.5) * 2 * a / n, py = -a + (j + 0.5) * 2 * a / n;
            double E = spot_E(px, py);
            if (E <= 0)
                continue;
            double dx = x - px, dy = y - py, d2 = dx * dx + dy * dy + 1.0;
            s += 0.5 / PI * E * (1.0 / d2) * (1.0 / d2) * dA; /* cos_y cos_x / d^2 = 1/d^4 at height 1 */
        }
    return s;
}

typedef struct run {
    vsgl_gbuffer g;
    float *dl, *gl, *dc, *gc;
} run;

/* cn: corner normals (triangle_count x 9), or NULL for flat faces */
static int do_run_normals(fx_scene *s, const float *cn, uint32_t threads, uint32_t res, int vis, run *out)
{
    vsgl_context *ctx = fx_context(threads);
    vsgl_scene *sc = NULL;
    vsgl_scene_desc *d = (vsgl_scene_desc *)fx_desc(s);
    d->corner_normals = cn;
    int ok = ctx && vsgl_scene_create(ctx, d, &sc) == VSGL_OK;
    VT_CHECK(ok, "scene: %s", ctx ? vsgl_context_last_error(ctx) : "no context");
    vsgl_rsm r;
    memset(out, 0, sizeof *out);
    if (ok)
        ok = vsgl__gbuffer_build(ctx, sc, 1, 0, &out->g) == VSGL_OK;
    if (ok)
        ok = vsgl__rsm_build(ctx, sc, 0, res, &r) == VSGL_OK;
    if (ok) {
        size_t n = out->g.count * 3;
        out->dl = malloc(n * sizeof(float));
        out->gl = malloc(n * sizeof(float));
        out->dc = malloc(n * sizeof(float));
        out->gc = malloc(n * sizeof(float));
        ok = vsgl__brute_force_shade(ctx, sc, &out->g, &r, 1, vis, out->dl, out->gl, out->dc, out->gc) == VSGL_OK;
        vsgl__rsm_free(&r);
    }
    VT_CHECK(ok, "pipeline: %s", vsgl_context_last_error(ctx));
    vsgl_scene_destroy(sc);
    vsgl_context_destroy(ctx);
    return ok;
}

static int do_run(fx_scene *s, uint32_t threads, uint32_t res, int vis, run *out)
{
    return do_run_normals(s, NULL, threads, res, vis, out);
}

static void free_run(run *r)
{
    vsgl__gbuffer_free(&r->g);
    free(r->dl); free(r->gl); free(r->dc); free(r->gc);
}

VT_TEST(brute_force_matches_one_bounce_quadrature)
{
    fx_scene s;
    setup(&s, 0, 0);
    run r;
    if (!do_run(&s, 0, 128, 1, &r))
        return;
    int checked = 0;
    double worst = 0;
    for (size_t i = 0; i < r.g.count; i += 5) {
        if (r.g.material[i] != 1)
            continue;
        double x = r.g.pos[0][i], y = r.g.pos[1][i];
        double want = ceiling_E(x, y) / PI; /* DiffInd = E / pi */
        double e = fabs(r.dl[3 * i] - want) / want;
        worst = e > worst ? e : worst;
        VT_CHECK_REL(r.dl[3 * i], want, 0.01, "sample %zu at (%.3f, %.3f, %.3f), RSM 128", i, x, y, (double)r.g.pos[2][i]);
        VT_CHECK_REL(r.dc[3 * i], 0.8, 1e-6, "DiffCol");
        VT_CHECK(r.gc[3 * i] == 0.0f && r.gl[3 * i] == 0.0f, "no glossy lobe: GlossCol %g GlossInd %g", r.gc[3 * i], r.gl[3 * i]);
        ++checked;
    }
    VT_CHECK(checked > 10, "only %d ceiling samples", checked);
    printf("    %d samples, worst relative error %.3g %%\n", checked, 100 * worst);
    free_run(&r);
}

VT_TEST(brute_force_visibility_and_determinism)
{
    fx_scene s;
    setup(&s, 1, 1);
    run a, b, nv;
    if (!do_run(&s, 1, 64, 1, &a) || !do_run(&s, 3, 64, 1, &b) || !do_run(&s, 2, 64, 0, &nv))
        return;
    size_t n = a.g.count * 3;
    VT_CHECK(memcmp(a.dl, b.dl, n * sizeof(float)) == 0 && memcmp(a.gl, b.gl, n * sizeof(float)) == 0,
             "bit-identical for 1 and 3 threads");
    /* the occluder (x in [0, 0.6]) shadows ceiling points above it from the lit floor */
    double occluded = 0, open = 0;
    int metal = 0;
    for (size_t i = 0; i < a.g.count; ++i) {
        if (a.g.material[i] != 1)
            continue;
        ++metal;
        VT_CHECK(a.gc[3 * i] == 1.0f && a.dc[3 * i] == 0.0f, "metal: GlossCol 1, DiffCol 0 (Blender 3.4)");
        VT_CHECK(a.gl[3 * i] <= nv.gl[3 * i] * (1 + 1e-6) + 1e-9, "visibility can only remove light");
        occluded += nv.gl[3 * i] - a.gl[3 * i];
        open += nv.gl[3 * i];
    }
    VT_CHECK(metal > 0 && occluded > 0.01 * open, "occluder removes %.3g of %.3g", occluded, open);
    /* resolve: pixel light x colour = mean of sample light x colour */
    float *pl = malloc(a.g.width * a.g.height * 3 * sizeof(float)), *pc = malloc(a.g.width * a.g.height * 3 * sizeof(float));
    vsgl__brute_force_resolve(&a.g, a.gl, a.gc, pl, pc);
    for (size_t p = 0; p < (size_t)a.g.width * a.g.height; ++p)
        VT_CHECK_REL(pl[3 * p] * pc[3 * p] + 1e-12, a.gl[3 * p] * a.gc[3 * p] + 1e-12, 1e-6, "pixel %zu (spp 1)", p);
    free(pl);
    free(pc);
    free_run(&a);
    free_run(&b);
    free_run(&nv);
}

/* A smooth-shaded receiver's visibility rays start on its smooth surface
 * (gbuffer.h lift) and end short of the VPL measured from there: measured
 * from the receiver's flat point instead, a ray lifted towards the VPL
 * ran past it into the VPL's own surface (the sphere room's brute force
 * lost 28 % of its glossy light). The ceiling patch shaded as the bottom
 * of a dome (corner normals tilted outwards by ~17-23 degrees), nothing
 * between it and the lit floor: visibility may take nothing. */
VT_TEST(brute_force_visibility_from_a_smooth_receiver)
{
    fx_scene s;
    setup(&s, 0, 0);
    float cn[4 * 9];
    for (uint32_t t = 0; t < 4; ++t)
        for (int k = 0; k < 3; ++k) {
            const float *p = s.positions + 3 * s.indices[3 * t + (uint32_t)k];
            float *n = cn + 9 * t + 3 * k;
            if (t < 2) { /* the floor: flat */
                n[0] = n[1] = 0.0f;
                n[2] = 1.0f;
            } else {
                n[0] = 0.6f * p[0];
                n[1] = 0.6f * p[1];
                n[2] = -1.0f;
            }
        }
    run a, nv;
    if (!do_run_normals(&s, cn, 2, 64, 1, &a) || !do_run_normals(&s, cn, 2, 64, 0, &nv))
        return;
    VT_REQUIRE(a.g.lift[0] != NULL, "no lift on a smooth-shaded receiver");
    double with = 0, without = 0, lift = 0;
    for (size_t i = 0; i < a.g.count; ++i) {
        if (a.g.material[i] != 1)
            continue;
        with += a.dl[3 * i];
        without += nv.dl[3 * i];
        lift = fmax(lift, fabs((double)a.g.lift[2][i]));
    }
    printf("    ceiling: diffuse light with visibility %.4g of without; lifted up to %.3g m\n", with / without, lift);
    VT_CHECK(lift > 1e-3, "the ceiling's points are lifted by %.3g m at most: the test cannot tell", lift);
    VT_CHECK(without > 0 && with > 0.99 * without, "visibility took %.3g of the ceiling's light with nothing in the way",
             1.0 - with / without);
    free_run(&a);
    free_run(&nv);
}

/* Glossy VPLs: a metal floor (GGX) reflects the spot onto the Lambert
 * ceiling. Reference: E(x) = int_floor E_spot(y) [f(wi_y, w) cos_w] cos_x /
 * d^2 dA with the library's BRDF evaluated in double-checked form (the
 * BRDF itself is tested against Cycles and a double reference elsewhere);
 * this isolates the gather's handling of sharp VPL lobes. */
static double ceiling_E_metal(const vsgl_brdf_params *P, double x, double y, int n)
{
    double a = 0.45, s = 0, dA = (2 * a / n) * (2 * a / n);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            double px = -a + (i + 0.5) * 2 * a / n, py = -a + (j + 0.5) * 2 * a / n;
            double E = spot_E(px, py);
            if (E <= 0)
                continue;
            double dx = x - px, dy = y - py, d2 = dx * dx + dy * dy + 1.0, d = sqrt(d2);
            double l2 = px * px + py * py + 0.36;
            v3 wi = v3_make((float)(-px / sqrt(l2)), (float)(-py / sqrt(l2)), (float)(0.6 / sqrt(l2)));
            v3 wo = v3_make((float)(dx / d), (float)(dy / d), (float)(1.0 / d));
            float fd[3], fg[3];
            vsgl__brdf_eval(P, v3_make(0, 0, 1), v3_make(1, 0, 0), wo, wi, fd, fg); /* f cos at the floor, out to x */
            s += E * (double)(fd[0] + fg[0]) * (1.0 / d) / d2 * dA;  /* cos_x = 1/d */
        }
    return s;
}

VT_TEST(brute_force_glossy_vpls_match_quadrature)
{
    const float roughs[] = {0.5f, 0.3f, 0.15f};
    int quick = getenv("VSGL_TEST_QUICK") != NULL;
    uint32_t res = quick ? 128 : 256;
    int nq = quick ? 250 : 400;
    for (int k = 0; k < 3; ++k) {
        fx_scene s;
        setup(&s, 0, 0);
        s.materials[0].metallic = 1.0f;
        s.materials[0].roughness = roughs[k];
        s.materials[0].specular_f0 = 0.04f;
        for (int c = 0; c < 3; ++c)
            s.materials[0].base_color[c] = 0.9f;
        vsgl_brdf_params P;
        vsgl__material_params(&s.materials[0], &P);
        run r;
        if (!do_run(&s, 0, res, 1, &r))
            return;
        double sum_got = 0, sum_want = 0, worst = 0;
        int m = 0;
        for (size_t i = 0; i < r.g.count; i += 3) {
            if (r.g.material[i] != 1)
                continue;
            double want = ceiling_E_metal(&P, r.g.pos[0][i], r.g.pos[1][i], nq) / PI;
            double e = fabs(r.dl[3 * i] - want) / want;
            worst = e > worst ? e : worst;
            sum_got += r.dl[3 * i];
            sum_want += want;
            ++m;
        }
        printf("    roughness %.2f: %d samples, mean ratio %.4f, worst %.2f %%\n", roughs[k], m, sum_got / sum_want, 100 * worst);
        VT_CHECK_REL(sum_got / sum_want, 1.0, 0.02, "mean over the ceiling, metal floor roughness %g, RSM %u", roughs[k], res);
        free_run(&r);
    }
}
