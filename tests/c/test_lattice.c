/* The lattice fit (fit/lattice.c) and the emitter-hemisphere clip
 * (shade.h): power conservation, orientations kept apart, continuity in
 * the light's motion, and the clipped lighting of a uniformly lit plane
 * against its exact (polygon) irradiance. */
#include "harness.h"
#include "scene_fixture.h"
#include "fit/grid.h"
#include "shade/shade.h"
#include "shade/near_field.h"
#include "vsgl/debug.h"

#include <stdlib.h>

#define PI_D 3.14159265358979323846

/* A single-face RSM of res^2 texels: VPLs on the floor z = 0 (normal +z)
 * of [-1, 1]^2 and, where `wall`, on the wall x = 1 (normal -x), all of
 * material `mat`, flux `flux` W per texel, footprint `area` m^2. */
typedef struct plane_rsm {
    vsgl_rsm r;
    float *mem;
} plane_rsm;

static void make_plane_rsm(plane_rsm *h, uint32_t res, int wall, float shift, uint32_t mat)
{
    memset(h, 0, sizeof *h);
    vsgl_rsm *r = &h->r;
    r->faces = 1;
    r->res = res;
    r->count = (size_t)res * res;
    h->mem = calloc(r->count * 19, sizeof(float));
    r->area = h->mem + r->count * 18;
    for (int c = 0; c < 3; ++c) {
        r->pos[c] = h->mem + r->count * (size_t)c;
        r->nrm[c] = h->mem + r->count * (size_t)(3 + c);
        r->wi[c] = h->mem + r->count * (size_t)(6 + c);
        r->flux[c] = h->mem + r->count * (size_t)(9 + c);
        r->tan[c] = h->mem + r->count * (size_t)(12 + c);
    }
    r->material = calloc(r->count, sizeof(uint32_t));
    for (uint32_t row = 0; row < res; ++row)
        for (uint32_t col = 0; col < res; ++col) {
            size_t t = (size_t)row * res + col;
            float u = -1.0f + 2.0f * ((float)col + 0.5f) / (float)res + shift;
            float v = -1.0f + 2.0f * ((float)row + 0.5f) / (float)res;
            int on_wall = wall && col >= res / 2;
            float p[3] = {u, v, 0.0f}, n[3] = {0.0f, 0.0f, 1.0f};
            if (on_wall) { /* fold the right half of the map up onto the wall x = 0.5 */
                p[0] = 0.5f; p[2] = u - 0.5f;
                n[0] = -1.0f; n[2] = 0.0f;
            }
            r->material[t] = mat;
            for (int c = 0; c < 3; ++c) {
                r->pos[c][t] = p[c];
                r->nrm[c][t] = n[c];
                r->wi[c][t] = n[c];
                r->flux[c][t] = 4.0f / (float)r->count; /* 1 W/m^2 over the 2 x 2 map */
                r->total_flux[c] += r->flux[c][t];
            }
            r->tan[0][t] = on_wall ? 0.0f : 1.0f;
            r->tan[1][t] = on_wall ? 1.0f : 0.0f;
            r->area[t] = 4.0f / (float)r->count;
        }
}

static void free_plane_rsm(plane_rsm *h)
{
    free(h->mem);
    free(h->r.material);
}

typedef struct lroom { fx_scene fx; vsgl_context *ctx; vsgl_scene *scene; } lroom;

static int lroom_open(lroom *r)
{
    fx_room(&r->fx, 32, 24, 0.3f, 100.0f);
    r->ctx = NULL;
    r->scene = NULL;
    if (vsgl_context_create(NULL, &r->ctx) == VSGL_OK)
        vsgl_scene_create(r->ctx, fx_desc(&r->fx), &r->scene);
    VT_CHECK(r->scene != NULL, "scene: %s", r->ctx ? vsgl_context_last_error(r->ctx) : "no context");
    if (!r->scene)
        vsgl_context_destroy(r->ctx);
    return r->scene != NULL;
}

static void lroom_close(lroom *r)
{
    vsgl_scene_destroy(r->scene);
    vsgl_context_destroy(r->ctx);
}

/* The balanced preset's lattice of `count` clusters over RSM r in the room;
 * 0 (the context says why) if the fit failed. */
static int fit_balanced(lroom *rm, const vsgl_rsm *r, uint32_t count, vsgl_vsgl_set *lat)
{
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    s.vsgl_count = count;
    memset(lat, 0, sizeof *lat);
    return vsgl__fit_lattice(rm->ctx, rm->scene, r, &s, lat) == VSGL_OK;
}

static double set_power(const vsgl_vsgl_set *s)
{
    double w = 0;
    for (size_t k = 0; k < s->count; ++k)
        w += (double)s->items[k].power[0] + s->items[k].power[1] + s->items[k].power[2];
    return w;
}

VT_TEST(fit_lattice_conserves_power_and_keeps_orientations_apart)
{
    static lroom rm;
    if (!lroom_open(&rm))
        return;
    plane_rsm h;
    make_plane_rsm(&h, 64, 1, 0.0f, 3); /* white diffuse: material 3 of the fixture */
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    vsgl_vsgl_set two = {0};
    vsgl__fit_two(rm.ctx, rm.scene, &h.r, &s, &two);
    double want = set_power(&two);
    VT_CHECK(two.count == 1 && two.items[0].coherence < 0.8f, "the two-VSGL fit mixes floor and wall (coherence %g)",
             two.count ? (double)two.items[0].coherence : -1.0);
    const uint32_t counts[4] = {4, 16, 64, 256};
    for (int i = 0; i < 4; ++i) {
        s.vsgl_count = counts[i];
        vsgl_vsgl_set lat = {0};
        VT_CHECK(vsgl__fit_lattice(rm.ctx, rm.scene, &h.r, &s, &lat) == VSGL_OK, "lattice N=%u", counts[i]);
        VT_CHECK_REL(set_power(&lat), want, 1e-5, "lattice N=%u (%zu VSGLs)", counts[i], lat.count);
        VT_CHECK(lat.count >= counts[i] / 4 && lat.count <= 8 * (size_t)counts[i], "N=%u: %zu VSGLs", counts[i], lat.count);
        size_t floor_n = 0, wall_n = 0;
        for (size_t k = 0; k < lat.count; ++k) {
            const vsgl_vsgl *v = &lat.items[k];
            VT_CHECK(v->coherence > 0.9999f, "N=%u VSGL %zu mixes orientations: coherence %g", counts[i], k, (double)v->coherence);
            floor_n += v->normal.z > 0.99f;
            wall_n += v->normal.x < -0.99f;
            VT_CHECK(isfinite(v->variance) && v->variance > 0.0f, "N=%u VSGL %zu variance %g", counts[i], k, (double)v->variance);
        }
        VT_CHECK(floor_n + wall_n == lat.count && floor_n > 0 && wall_n > 0, "N=%u: %zu floor + %zu wall of %zu",
                 counts[i], floor_n, wall_n, lat.count);
        vsgl__vsgl_set_free(&lat);
    }
    vsgl__vsgl_set_free(&two);
    free_plane_rsm(&h);
    lroom_close(&rm);
}

/* A room's floor and ceiling lie on the faces of the scene's bounds, and
 * their VPLs' positions on either side of them by rounding. Every texel
 * of such a face must fall into one cluster per lattice cell: slabs
 * starting at a face put the texels a hair below the floor into another
 * slab than those a hair above, two clusters for one cell whose powers
 * swung from frame to frame with the rounding (a wall's foot in the sphere
 * room, docs/accuracy.md). */
VT_TEST(fit_lattice_keeps_a_face_of_the_bounds_in_one_slab)
{
    static lroom rm;
    if (!lroom_open(&rm))
        return;
    for (int ceiling = 0; ceiling < 2; ++ceiling) {
        plane_rsm h;
        make_plane_rsm(&h, 64, 0, 0.0f, 3);
        const float face = ceiling ? 2.0f : 0.0f, ulp = ceiling ? 2.4e-7f : 1e-7f;
        for (size_t t = 0; t < h.r.count; ++t) { /* the face, each texel a rounding off it */
            h.r.pos[2][t] = face + ((t * 7u + t / 64u) % 3u == 0 ? -ulp : (t % 3u == 1 ? ulp : 0.0f));
            h.r.nrm[2][t] = h.r.wi[2][t] = ceiling ? -1.0f : 1.0f;
        }
        vsgl_vsgl_set lat;
        VT_REQUIRE(fit_balanced(&rm, &h.r, 64, &lat), "%s", vsgl_context_last_error(rm.ctx));
        int twins = 0;
        for (size_t a = 0; a < lat.count; ++a)
            for (size_t b = a + 1; b < lat.count; ++b) {
                const vsgl_vsgl *x = &lat.items[a], *y = &lat.items[b];
                if (x->lobe == y->lobe && x->cell_axis == y->cell_axis && x->cell_side == y->cell_side &&
                    x->cell_centre[0] == y->cell_centre[0] && x->cell_centre[1] == y->cell_centre[1] &&
                    twins++ < 3)
                    VT_REPORT("%s: VSGLs %zu and %zu share the cell at (%g, %g), powers %g and %g W",
                              ceiling ? "ceiling" : "floor", a, b, (double)x->cell_centre[0],
                              (double)x->cell_centre[1], (double)x->power[0], (double)y->power[0]);
            }
        VT_CHECK(twins == 0, "%s: %d pairs of clusters share a lattice cell", ceiling ? "ceiling" : "floor", twins);
        VT_CHECK(lat.count >= 16, "%s: %zu VSGLs", ceiling ? "ceiling" : "floor", lat.count);
        vsgl__vsgl_set_free(&lat);
        free_plane_rsm(&h);
    }
    lroom_close(&rm);
}

/* A cluster's cut (cell_lo, cell_hi: where its VPLs end) lies within the
 * scene's bounds, whatever the texels' footprints: a floor's VPLs shifted
 * by a fraction of a texel towards the wall x = 1 reach past it by that
 * fraction, and the cut there wandered with them (the sphere room's
 * preview: the back wall's corner cell cut at x = -2.504, -2.499, -2.519
 * around the wall at -2.5 in three frames, its reflection in the floor
 * 27 % darker in one of them). */
VT_TEST(fit_lattice_keeps_its_cuts_within_the_scene)
{
    static lroom rm;
    if (!lroom_open(&rm))
        return;
    v3 blo, bhi;
    vsgl__scene_bounds(rm.scene, &blo, &bhi);
    const float lo[3] = {blo.x, blo.y, blo.z}, hi[3] = {bhi.x, bhi.y, bhi.z};
    const uint32_t res = 64;
    size_t outside = 0;
    float reach[3];
    for (int i = 0; i < 3; ++i) {
        const float shift = (0.25f + 0.25f * (float)i) / (float)res; /* the last texels' centres stay inside */
        plane_rsm h;
        make_plane_rsm(&h, res, 0, shift, 3);
        vsgl_vsgl_set lat;
        VT_REQUIRE(fit_balanced(&rm, &h.r, 64, &lat), "%s", vsgl_context_last_error(rm.ctx));
        reach[i] = -INFINITY;
        for (size_t k = 0; k < lat.count; ++k) {
            const vsgl_vsgl *v = &lat.items[k];
            for (int c = 0; c < 2; ++c) {
                const int a = ((int)v->cell_axis + 1 + c) % 3;
                if (v->cell_lo[c] < lo[a] - 1e-6f || v->cell_hi[c] > hi[a] + 1e-6f) {
                    if (outside++ < 3)
                        VT_REPORT("shift %g: VSGL %zu cut at [%g, %g] on axis %d, bounds [%g, %g]", (double)shift, k,
                                  (double)v->cell_lo[c], (double)v->cell_hi[c], a, (double)lo[a], (double)hi[a]);
                }
                if (v->cell_axis == 2 && a == 0)
                    reach[i] = fmaxf(reach[i], v->cell_hi[c]);
            }
        }
        vsgl__vsgl_set_free(&lat);
        free_plane_rsm(&h);
    }
    printf("    the floor's cut at the wall x = %g: %.5f %.5f %.5f for shifts of 1/4, 1/2, 3/4 texel\n", (double)hi[0],
           (double)reach[0], (double)reach[1], (double)reach[2]);
    VT_CHECK(outside == 0, "%zu cuts outside the scene's bounds", outside);
    VT_CHECK(reach[0] == hi[0] && reach[1] == hi[0] && reach[2] == hi[0], "the cut at the wall moved: %g %g %g",
             (double)reach[0], (double)reach[1], (double)reach[2]);
    lroom_close(&rm);
}

/* Light at receiver x (normal n) from a set, through the reference path's
 * formulas (the kernel is checked against them in test_kernel.c). */
/* clip: 0 no clip (the papers' model but for the plane spread, shade.h), 1 the emitter clip, 2 the clip and the near
 * field (shade/near_field.h), blended in as the shading does */
static double diffuse_at(const vsgl_vsgl_set *set, v3 x, v3 n, int clip)
{
    double e = 0.0;
    for (size_t k = 0; k < set->count; ++k) {
        const vsgl_vsgl *v = &set->items[k];
        vsgl_sg in;
        double far = 0.0;
        if (vsgl__vsgl_incident_sg(v, x, &in)) {
            float f = vsgl__emitter_clip(v, x, n, clip != 0);
            far = f * vsgl_sg_cosine_integral(&in, &n, VSGL_COSINE_ACCURATE) / PI_D;
        }
        vsgl_near_cell c;
        if (clip == 2 && vsgl__near_cell(v, (uint32_t)k, &c)) {
            float w, q = vsgl__near_diffuse(&c, x, n, &w);
            far += w * (q - far);
        }
        e += (double)v->power[0] * far;
    }
    return e;
}

/* VSGLs that move a little when the VPLs move a little: the light they
 * give a row of receivers changes in proportion, never in jumps. */
VT_TEST(fit_lattice_is_continuous_in_the_vpls_motion)
{
    static lroom rm;
    if (!lroom_open(&rm))
        return;
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    s.vsgl_count = 64;
    enum { STEPS = 24, PROBES = 40 };
    double light[STEPS][PROBES], near[STEPS][PROBES];
    int fits[2] = {VSGL_FIT_LATTICE, VSGL_FIT_KMEANS};
    double worst_jerk[2] = {0, 0}, near_jerk = 0.0;
    for (int f = 0; f < 2; ++f) {
        for (int st = 0; st < STEPS; ++st) {
            plane_rsm h;
            make_plane_rsm(&h, 64, 1, 0.0005f * (float)st, 3); /* the VPLs slide by 0.5 mm a step */
            vsgl_vsgl_set set = {0};
            s.fit_mode = fits[f];
            if (f == 0)
                vsgl__fit_lattice(rm.ctx, rm.scene, &h.r, &s, &set);
            else
                vsgl__fit_kmeans(rm.ctx, rm.scene, &h.r, &s, &set);
            for (int p = 0; p < PROBES; ++p) { /* a ceiling row 0.4 m above the floor, facing down */
                light[st][p] = diffuse_at(&set, v3_make(-0.95f + 0.05f * (float)p, 0.1f, 0.4f), v3_make(0, 0, -1), 1);
                /* and, in the near field, a row 3 cm above it, facing across it, over its moving edge */
                near[st][p] = diffuse_at(&set, v3_make(-0.95f + 0.05f * (float)p, 0.1f, 0.03f),
                                         v3_normalize(v3_make(-1, 0, -1)), 2);
            }
            vsgl__vsgl_set_free(&set);
            free_plane_rsm(&h);
        }
        /* relative second difference per probe: smooth motion has it ~0 */
        for (int st = 1; st + 1 < STEPS; ++st)
            for (int p = 0; p < PROBES; ++p) {
                double d2 = fabs(light[st + 1][p] - 2.0 * light[st][p] + light[st - 1][p]) / (light[st][p] + 1e-12);
                worst_jerk[f] = d2 > worst_jerk[f] ? d2 : worst_jerk[f];
                double n2 = fabs(near[st + 1][p] - 2.0 * near[st][p] + near[st - 1][p]) / (near[st][p] + 1e-12);
                if (f == 0)
                    near_jerk = n2 > near_jerk ? n2 : near_jerk;
            }
    }
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    worst relative second difference: lattice %.3g (its near field %.3g), k-means %.3g\n", worst_jerk[0],
               near_jerk, worst_jerk[1]);
    VT_CHECK(worst_jerk[0] < 2e-3, "lattice: the light jumps by %.3g between 0.5 mm steps", worst_jerk[0]);
    VT_CHECK(near_jerk < 2e-3, "lattice near field: the light jumps by %.3g between 0.5 mm steps", near_jerk);
    /* the test can fail: importance-drawn k-means centres jump */
    VT_CHECK(worst_jerk[1] > 10.0 * worst_jerk[0], "k-means jerk %.3g not above the lattice's %.3g", worst_jerk[1], worst_jerk[0]);
    lroom_close(&rm);
}

/* Irradiance at x (normal n) from the uniformly emitting square [-1, 1]^2
 * on z = 0 (exitance M W/m^2, Lambertian): the exact polygon formula
 * (Lambert), the square first clipped to the receiver's hemisphere. */
static double polygon_irradiance(v3 x, v3 n, double M)
{
    if (x.z <= 0.0f)
        return 0.0;
    double P[8][3], Q[8][3];
    int np = 4;
    const double sq[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int i = 0; i < 4; ++i) {
        P[i][0] = sq[i][0] - x.x; P[i][1] = sq[i][1] - x.y; P[i][2] = -x.z;
    }
    /* clip against n.p >= 0 (Sutherland-Hodgman) */
    int nq = 0;
    for (int i = 0; i < np; ++i) {
        const double *a = P[i], *b = P[(i + 1) % np];
        double da = a[0] * n.x + a[1] * n.y + a[2] * n.z, db = b[0] * n.x + b[1] * n.y + b[2] * n.z;
        if (da >= 0) { memcpy(Q[nq++], a, sizeof Q[0]); }
        if ((da >= 0) != (db >= 0)) {
            double t = da / (da - db);
            for (int c = 0; c < 3; ++c)
                Q[nq][c] = a[c] + t * (b[c] - a[c]);
            ++nq;
        }
    }
    double sum = 0.0;
    for (int i = 0; i < nq; ++i) {
        const double *a = Q[i], *b = Q[(i + 1) % nq];
        double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        if (la < 1e-12 || lb < 1e-12)
            continue;
        double cr[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
        double cl = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
        if (cl < 1e-15)
            continue;
        double c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
        c = c > 1 ? 1 : (c < -1 ? -1 : c);
        sum += acos(c) * (cr[0] * n.x + cr[1] * n.y + cr[2] * n.z) / cl;
    }
    return fabs(sum) * 0.5 * M / PI_D; /* E = L/2 sum, L = M / pi */
}

/* A uniformly lit floor square, fitted on the lattice and shaded with the
 * clip, against its exact irradiance: nothing behind or beside it in its
 * plane, the far field within a few per cent (the papers' SG emission
 * lobe is 15-25 % off there), the near field (below ~h/2) darker (the
 * limit docs/accuracy.md measures). */
VT_TEST(shade_clipped_lattice_lights_like_the_exact_plane)
{
    static lroom rm;
    if (!lroom_open(&rm))
        return;
    plane_rsm h;
    make_plane_rsm(&h, 128, 0, 0.0f, 3);
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    s.vsgl_count = 64;
    vsgl_vsgl_set set = {0};
    VT_CHECK(vsgl__fit_lattice(rm.ctx, rm.scene, &h.r, &s, &set) == VSGL_OK, "fit");
    double M = 0.8 * 1.0; /* the white material's albedo x 1 W/m^2, per channel */
    struct { float x, y, z, nx, ny, nz; double tol; const char *what; } cases[] = {
        {0.0f, 0.0f, 1.5f, 0, 0, -1, 0.06, "facing, 1.5 m"},
        {0.3f, -0.2f, 0.8f, 0, 0, -1, 0.06, "facing, 0.8 m"},
        {0.0f, 0.0f, 3.0f, 0.6f, 0, -0.8f, 0.06, "tilted, 3 m"},
        {1.0f, 0.0f, 1.0f, -1, 0, 0, 0.08, "wall at the edge, 1 m up"},
        {1.8f, 0.3f, 0.5f, -1, 0, 0, 0.08, "wall beyond the edge, 0.5 m up"},
        {-2.5f, 0.0f, 2.0f, 0.7071f, 0, -0.7071f, 0.08, "oblique, far"},
        /* the near field: a wall standing on the square's edge, at its foot */
        {1.0f, 0.2f, 0.02f, -1, 0, 0, 0.05, "wall at the edge, 2 cm up"},
        {1.0f, -0.5f, 0.1f, -1, 0, 0, 0.05, "wall at the edge, 10 cm up"},
        {1.0f, 0.0f, 0.3f, -1, 0, 0, 0.05, "wall at the edge, 30 cm up"},
        {0.3f, 0.2f, 0.05f, 0, 0, -1, 0.05, "facing, 5 cm"},
        {0.9f, 0.9f, 0.1f, -0.7071f, -0.7071f, 0, 0.05, "a corner's diagonal, 10 cm up"},
        /* a slope beside the square, facing it (a bump beside a lit
         * floor), where the round spread's product put the light below
         * the square's plane: -9.8 % and -9.4 % with it, -4.9 % and
         * -0.2 % with the foreshortened spread (shade.h) */
        {1.3f, 0.0f, 0.05f, -0.5f, 0, 0.866f, 0.06, "slope 30 deg, 30 cm off, 5 cm up"},
        {1.6f, 0.3f, 0.1f, -0.2588f, 0, 0.9659f, 0.06, "slope 15 deg, 60 cm off, 10 cm up"},
        {2.0f, 0.0f, 0.05f, -0.7071f, 0, 0.7071f, 0.05, "slope 45 deg, 1 m off, 5 cm up"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        v3 x = v3_make(cases[i].x, cases[i].y, cases[i].z), n = v3_normalize(v3_make(cases[i].nx, cases[i].ny, cases[i].nz));
        double want = polygon_irradiance(x, n, M) / PI_D, got = diffuse_at(&set, x, n, 2),
               clipped = diffuse_at(&set, x, n, 1), paper = diffuse_at(&set, x, n, 0);
        if (getenv("VSGL_TEST_VERBOSE"))
            printf("    %-32s exact %.5f near field %.5f (%+.1f %%) clip only %.5f (%+.1f %%) no clip %.5f (%+.1f %%)\n",
                   cases[i].what, want, got, 100 * (got / want - 1), clipped, 100 * (clipped / want - 1), paper,
                   100 * (paper / want - 1));
        VT_CHECK_REL(got, want, cases[i].tol, "%s", cases[i].what);
    }
    /* nothing where the plane cannot be seen: behind it, in it, facing its way */
    const float zero[4][6] = {{0.2f, 0.1f, -0.3f, 0, 0, -1}, {0.2f, 0.1f, -0.05f, 0, 0, 1},
                              {1.5f, 0.0f, 0.0f, 0, 0, 1}, {0.2f, -0.3f, 0.5f, 0, 0, 1}};
    for (int i = 0; i < 4; ++i) {
        v3 x = v3_make(zero[i][0], zero[i][1], zero[i][2]), n = v3_make(zero[i][3], zero[i][4], zero[i][5]);
        double got = diffuse_at(&set, x, n, 2), paper = diffuse_at(&set, x, n, 0);
        VT_CHECK(got <= 1e-6 * M, "case %d: %g where the plane is not seen (the papers' model: %g)", i, got, paper);
        if (i < 3) /* behind and in the plane the papers' SG lobe leaks: the check can fail */
            VT_CHECK(paper > 1e-6 * M, "case %d: the papers' model leaks here (%g)", i, paper);
    }
    vsgl__vsgl_set_free(&set);
    free_plane_rsm(&h);
    lroom_close(&rm);
}

/* An area light 5 mm under the ceiling, facing it: its power lands on a
 * few RSM texels, and the spacing from the participation area alone made
 * 500 x the requested clusters, some of one texel (variance 0), whose
 * d^2 / variance overflowed to inf and gave NaN pixels. Now: at most 16
 * cells per requested VSGL (two lobes each) and finite, non-negative light. */
VT_TEST(render_light_millimetres_from_a_wall_stays_finite_and_bounded)
{
    enum { W = 32, H = 24 };
    static float comb[W * H * 3];
    fx_scene fx;
    fx_room(&fx, W, H, 0.35f, 100.0f);
    fx.materials[3].roughness = 0.35f;   /* a glossy-ish ceiling */
    vsgl_light *L = &fx.lights[0];
    memset(L, 0, sizeof *L);
    L->type = VSGL_LIGHT_AREA;
    L->color[0] = L->color[1] = L->color[2] = 1.0f;
    L->power = 100.0f;
    L->size_x = L->size_y = 0.6f;
    L->spread = 3.14159f;
    fx_translation(L->world_from_light, 0.0f, 0.0f, 1.995f);
    L->world_from_light[5] = -1.0f;      /* flip: the light's -Z (its emission) points up at the ceiling */
    L->world_from_light[10] = -1.0f;
    vsgl_context *ctx = NULL;
    vsgl_scene *scene = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    const int presets[3] = {VSGL_PRESET_PREVIEW, VSGL_PRESET_BALANCED, VSGL_PRESET_QUALITY};
    for (int p = 0; p < 3; ++p) {
        vsgl_render_settings s;
        vsgl_render_settings_preset(presets[p], &s);
        size_t count = 0;
        VT_CHECK(vsgl_debug_vsgls(ctx, scene, &s, &count, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        VT_CHECK(count <= (size_t)(2 * 16 * s.vsgl_count), "preset %d: %zu VSGLs for %u requested", presets[p], count,
                 s.vsgl_count);
        vsgl_render_output o;
        memset(&o, 0, sizeof o);
        o.width = W;
        o.height = H;
        o.combined = comb;
        VT_CHECK(vsgl_render(ctx, scene, &s, &o, NULL) == VSGL_OK, "preset %d: %s", presets[p], vsgl_context_last_error(ctx));
        double sum = 0;
        for (size_t i = 0; i < sizeof comb / sizeof comb[0]; ++i) {
            VT_CHECK(isfinite(comb[i]) && comb[i] >= 0.0f, "pixel value %g", (double)comb[i]);
            sum += comb[i];
        }
        VT_CHECK(sum > 0.0, "preset %d: no indirect light at all", presets[p]);
    }
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* The cuts where the planar glossy model folds (vsgl_vsgl.cell_ends): a
 * floor lit only for x < 0.13 (a spot's rim, say) in the fixture room,
 * whose walls rise at x = -1, x = 1 and y = 1 and whose floor stops at
 * y = -1. With a one-lobe receiver mode only the surface's ends fold (the
 * walls, the open end), never the rim; with two lobes the rim too. */
VT_TEST(fit_lattice_marks_where_the_surface_ends)
{
    static lroom rm;
    if (!lroom_open(&rm))
        return;
    plane_rsm h;
    make_plane_rsm(&h, 128, 0, 0.0f, 3);
    for (size_t t = 0; t < h.r.count; ++t)
        if (h.r.pos[0][t] > 0.13f) {
            h.r.material[t] = VSGL__RSM_EMPTY;
            for (int c = 0; c < 3; ++c) {
                h.r.total_flux[c] -= h.r.flux[c][t];
                h.r.flux[c][t] = 0.0f;
            }
        }
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    s.vsgl_count = 64;
    for (int two = 0; two < 2; ++two) {
        s.glossy_mode = two ? VSGL_GLOSSY_ASG2 : VSGL_GLOSSY_ASG;
        vsgl_vsgl_set lat = {0};
        VT_REQUIRE(vsgl__fit_lattice(rm.ctx, rm.scene, &h.r, &s, &lat) == VSGL_OK, "lattice");
        int rim = 0, rim_marked = 0, wall = 0, wall_marked = 0, open = 0, open_marked = 0;
        for (size_t k = 0; k < lat.count; ++k) {
            const vsgl_vsgl *v = &lat.items[k];
            if (v->lobe != VSGL__LOBE_DIFFUSE || v->cell_axis != 2)
                continue;
            const float hh = v->cell_h;
            /* x: in-plane axis 0; y: axis 1 */
            if (v->cell_hi[0] < v->cell_centre[0] + 0.9f * hh) { /* cut at the rim, x = 0.13 */
                ++rim;
                rim_marked += (v->cell_ends >> 1) & 1u;
            }
            if (v->cell_lo[0] > v->cell_centre[0] - 0.9f * hh) { /* the wall x = -1 */
                ++wall;
                wall_marked += v->cell_ends & 1u;
            }
            if (v->cell_lo[1] > v->cell_centre[1] - 0.9f * hh) { /* the open end y = -1 */
                ++open;
                open_marked += (v->cell_ends >> 2) & 1u;
            }
            if (v->cell_hi[1] < v->cell_centre[1] + 0.9f * hh) { /* the wall y = 1 */
                ++wall;
                wall_marked += (v->cell_ends >> 3) & 1u;
            }
        }
        VT_CHECK(rim > 0 && wall > 0 && open > 0, "cells cut: %d at the rim, %d at walls, %d at the open end", rim,
                 wall, open);
        VT_CHECK(wall_marked == wall && open_marked == open, "%s: %d of %d wall cuts and %d of %d open-end cuts marked",
                 two ? "two lobes" : "one lobe", wall_marked, wall, open_marked, open);
        VT_CHECK(rim_marked == (two ? rim : 0), "%s: %d of %d rim cuts marked", two ? "two lobes" : "one lobe",
                 rim_marked, rim);
        vsgl__vsgl_set_free(&lat);
    }
    free_plane_rsm(&h);
    lroom_close(&rm);
}

/* A specular cell's cut where a wall rises moves to the wall's face (its
 * near field then reaches the junction, the wall's foot beside a metal
 * floor): the glossy floor of the fixture room lit up to one texel (7.8
 * mm) short of the wall x = -1 (the VPLs' extent stops there, as an RSM's
 * does up to half a texel short). Its specular cells at that wall end at x = -1 with
 * every preset's receivers; the rim cuts elsewhere stay where the VPLs
 * stop. */
VT_TEST(fit_lattice_specular_cut_moves_to_the_wall)
{
    static lroom rm;
    if (!lroom_open(&rm))
        return;
    plane_rsm h;
    make_plane_rsm(&h, 256, 0, 0.0f, 0); /* material 0: the glossy floor (GGX, roughness 0.3) */
    for (size_t t = 0; t < h.r.count; ++t)
        if (h.r.pos[0][t] < -0.99f || h.r.pos[0][t] > 0.13f) {
            h.r.material[t] = VSGL__RSM_EMPTY;
            for (int c = 0; c < 3; ++c) {
                h.r.total_flux[c] -= h.r.flux[c][t];
                h.r.flux[c][t] = 0.0f;
            }
        }
    const int presets[3] = {VSGL_PRESET_PREVIEW, VSGL_PRESET_BALANCED, VSGL_PRESET_QUALITY};
    for (int p = 0; p < 3; ++p) {
        vsgl_render_settings s;
        vsgl_render_settings_preset(presets[p], &s);
        vsgl_vsgl_set lat = {0};
        VT_REQUIRE(vsgl__fit_lattice(rm.ctx, rm.scene, &h.r, &s, &lat) == VSGL_OK, "lattice");
        int wall = 0, at_wall = 0, rim = 0, at_rim = 0;
        float worst = 0.0f;
        for (size_t k = 0; k < lat.count; ++k) {
            const vsgl_vsgl *v = &lat.items[k];
            if (v->lobe != VSGL__LOBE_SPECULAR || v->cell_axis != 2)
                continue;
            const float hh = v->cell_h;
            if (v->cell_centre[0] - hh < -0.99f) { /* the tent crosses the lit floor's end by the wall */
                ++wall;
                at_wall += fabsf(v->cell_lo[0] + 1.0f) < 1e-4f;
                worst = fmaxf(worst, fabsf(v->cell_lo[0] + 1.0f));
            }
            if (v->cell_centre[0] + hh > 0.14f) { /* ... and its end at the rim, x = 0.13 */
                ++rim;
                at_rim += fabsf(v->cell_hi[0] - 0.13f) < 0.01f;
            }
        }
        VT_CHECK(wall > 0 && at_wall == wall, "preset %d: %d of %d specular cells by the wall end at it (worst %.4f m off)",
                 presets[p], at_wall, wall, (double)worst);
        VT_CHECK(rim > 0 && at_rim == rim, "preset %d: %d of %d specular cells at the rim end there", presets[p], at_rim,
                 rim);
        vsgl__vsgl_set_free(&lat);
    }
    free_plane_rsm(&h);
    lroom_close(&rm);
}
