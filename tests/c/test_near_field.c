/* The lattice's near field (shade/near_field.c): the cell's form factor
 * against numerical quadrature of the same emitter, the index against a
 * scan of every cell, and a room's junctions against the brute force. */
#include "harness.h"
#include "scene_fixture.h"
#include "accuracy.h"
#include "shade/near_field.h"

#include <stdlib.h>

/* A cell on the plane z = 0 facing +z, spacing 1, around (0, 0), its VPLs
 * in [-1, 1] x [v0, 1] (v0 > -1: a junction cuts it at v = v0), the
 * cluster's mean where the steps' centroid is (radiosity uniform). */
static vsgl_vsgl cell_cluster(float v0)
{
    vsgl_vsgl v;
    memset(&v, 0, sizeof v);
    v.cell_h = 1.0f;
    v.cell_axis = 2;
    v.cell_side = 0;
    v.cell_lo[0] = -1.0f;
    v.cell_hi[0] = 1.0f;
    v.cell_lo[1] = v0;
    v.cell_hi[1] = 1.0f;
    v.normal = v3_make(0.0f, 0.0f, 1.0f);
    v.coherence = 1.0f;
    v.power[0] = v.power[1] = v.power[2] = 1.0f;
    v.lobe = VSGL__LOBE_DIFFUSE;
    /* centroid of the steps in v (u is symmetric) */
    static const float half[2] = {0.75f, 0.25f};
    double sa = 0.0, sv = 0.0;
    for (int iu = 0; iu < 2; ++iu)
        for (int iv = 0; iv < 2; ++iv) {
            double a0 = fmax(-half[iv], v0), a1 = half[iv];
            if (a1 <= a0)
                continue;
            double ar = 2.0 * half[iu] * (a1 - a0);
            sa += ar;
            sv += ar * 0.5 * (a0 + a1);
        }
    v.mean = v3_make(0.0f, (float)(sv / sa), 0.0f);
    return v;
}

/* The same light by midpoint quadrature: the steps' density (a quarter
 * each) over their area, Lambertian, seen from x with normal n: E / (pi P). */
static double quadrature(float v0, v3 x, v3 n, int grid)
{
    static const double half[2] = {0.75, 0.25};
    double e = 0.0, area = 0.0;
    for (int iu = 0; iu < 2; ++iu)
        for (int iv = 0; iv < 2; ++iv) {
            double u0 = -half[iu], u1 = half[iu], a0 = fmax(-half[iv], v0), a1 = half[iv];
            if (a1 <= a0)
                continue;
            area += (u1 - u0) * (a1 - a0);
            double du = (u1 - u0) / grid, dv = (a1 - a0) / grid;
            for (int i = 0; i < grid; ++i)
                for (int k = 0; k < grid; ++k) {
                    double py = a0 + (k + 0.5) * dv, px = u0 + (i + 0.5) * du;
                    double d[3] = {px - x.x, py - x.y, -x.z};
                    double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    double cr = (d[0] * n.x + d[1] * n.y + d[2] * n.z) / sqrt(r2);
                    double ce = x.z / sqrt(r2);
                    if (cr > 0.0)
                        e += cr * ce / (3.14159265358979323846 * r2) * du * dv;
                }
        }
    /* exitance P / area: E / P = e / area; diffuse light per watt = E / (pi P) */
    return e / area / 3.14159265358979323846;
}

VT_TEST(near_field_form_factor_matches_quadrature)
{
    srand(7);
    const float cuts[3] = {-1.0f, -0.3f, 0.4f};
    int tested = 0, clipped = 0;
    double worst = 0.0;
    for (int ci = 0; ci < 3; ++ci) {
        vsgl_vsgl v = cell_cluster(cuts[ci]);
        vsgl_near_cell c;
        VT_REQUIRE(vsgl__near_cell(&v, 0, &c), "cut %g: no cell", cuts[ci]);
        VT_CHECK_REL(c.fit, 1.0f, 1e-5, "cut %g: uniform radiosity, a plane: fit %g", cuts[ci], c.fit);
        for (int t = 0; t < 40; ++t) {
            float h = 0.1f + 0.8f * (float)rand() / (float)RAND_MAX;
            v3 x = v3_make(-1.5f + 3.0f * (float)rand() / (float)RAND_MAX, -1.5f + 3.0f * (float)rand() / (float)RAND_MAX, h);
            /* normals all round, including ones whose tangent plane cuts the cell */
            v3 n = v3_normalize(v3_make((float)rand() / (float)RAND_MAX - 0.5f, (float)rand() / (float)RAND_MAX - 0.5f,
                                        (float)rand() / (float)RAND_MAX - 0.7f));
            float w;
            double got = vsgl__near_diffuse(&c, x, n, &w), want = quadrature(cuts[ci], x, n, 240);
            /* beyond the near field (weight 0) the value is never used and
             * the function returns 0 early; a receiver on that boundary
             * falls either side of it with the compiler's rounding */
            if (want < 1e-4 || w == 0.0f)
                continue;
            ++tested;
            int cut = 0;
            for (int k = 0; k < 4; ++k) {
                float px = k & 1 ? 0.75f : -0.75f, py = k & 2 ? 0.75f : fmaxf(-0.75f, cuts[ci]);
                cut |= (px - x.x) * n.x + (py - x.y) * n.y - x.z * n.z > 0.0f ? 1 : 2;
            }
            clipped += cut == 3;
            double rel = fabs(got - want) / want;
            worst = rel > worst ? rel : worst;
            VT_CHECK(rel < 0.01, "cut %g at (%g %g %g) n (%g %g %g): %g, quadrature %g", cuts[ci], x.x, x.y, x.z, n.x, n.y,
                     n.z, got, want);
        }
    }
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    %d receivers (%d whose tangent plane cuts the cell): worst relative error %.2g\n", tested, clipped,
               worst);
    VT_CHECK(tested > 60 && clipped > 10, "%d receivers tested, %d clipped", tested, clipped);
}

VT_TEST(near_field_degenerate_receivers_and_cells)
{
    vsgl_vsgl v = cell_cluster(-1.0f);
    vsgl_near_cell c;
    VT_REQUIRE(vsgl__near_cell(&v, 0, &c), "no cell");
    float w;
    /* behind, in the plane (a thin wall's back face), on the cell's outline */
    const v3 xs[4] = {v3_make(0.1f, 0.2f, -0.3f), v3_make(0.1f, 0.2f, 0.0f), v3_make(0.75f, 0.75f, 0.0f),
                      v3_make(0.2f, 0.1f, 1e-7f)};
    for (int k = 0; k < 4; ++k) {
        float q = vsgl__near_diffuse(&c, xs[k], v3_make(0.0f, 0.0f, -1.0f), &w);
        VT_CHECK(isfinite(q) && q >= 0.0f && q < 1e-3f, "receiver %d: %g", k, q);
    }
    /* beyond the near field: weight 0 */
    vsgl__near_diffuse(&c, v3_make(5.0f, 0.0f, 0.2f), v3_make(-1.0f, 0.0f, 0.0f), &w);
    VT_CHECK(w == 0.0f, "far receiver weight %g", w);
    vsgl__near_diffuse(&c, v3_make(0.0f, 0.0f, 3.0f), v3_make(0.0f, 0.0f, -1.0f), &w);
    VT_CHECK(w == 0.0f, "receiver 3 spacings above the plane: weight %g", w);
    /* a curved surface's cluster (its normal off the axis), a radiosity off
     * the steps' centroid (a shadow in the cell), a specular lobe, no
     * power, another fit: no near field */
    vsgl_vsgl bad[5];
    for (int k = 0; k < 5; ++k)
        bad[k] = v;
    bad[0].normal = v3_normalize(v3_make(0.6f, 0.0f, 1.0f)); /* facing 0.86 (VSGL__NEAR_FACING_LO 0.90) */
    bad[1].mean = v3_make(0.4f, 0.0f, 0.0f);
    bad[2].lobe = VSGL__LOBE_SPECULAR;
    bad[3].power[0] = bad[3].power[1] = bad[3].power[2] = 0.0f;
    bad[4].cell_h = 0.0f;
    for (int k = 0; k < 5; ++k)
        VT_CHECK(!vsgl__near_cell(&bad[k], 0, &c), "cluster %d has a near field (fit %g)", k, c.fit);
    /* a cell that bends a little (facing 0.958: a bumpy floor's) reaches a
     * receiver across its plane (a wall's foot) but not one that faces its
     * way (a point of the same floor: near_field.c VSGL__NEAR_ACROSS_*);
     * a plane's cell reaches both */
    vsgl_vsgl bent = v;
    bent.normal = v3_normalize(v3_make(0.3f, 0.0f, 1.0f));
    vsgl_near_cell cb;
    VT_REQUIRE(vsgl__near_cell(&bent, 0, &cb) && cb.flat == 0.0f, "bent cell: fit %g flat %g", cb.fit, cb.flat);
    VT_REQUIRE(vsgl__near_cell(&v, 0, &c) && c.flat == 1.0f, "plane cell: flat %g", c.flat);
    const v3 foot = v3_make(0.9f, 0.1f, 0.05f), floor_pt = v3_make(0.3f, 0.2f, 0.05f);
    float wa, wb, pa, pb;
    vsgl__near_diffuse(&cb, foot, v3_make(-1.0f, 0.0f, 0.0f), &wa);
    vsgl__near_diffuse(&cb, floor_pt, v3_make(0.0f, 0.0f, 1.0f), &wb);
    vsgl__near_diffuse(&c, foot, v3_make(-1.0f, 0.0f, 0.0f), &pa);
    vsgl__near_diffuse(&c, floor_pt, v3_make(0.0f, 0.0f, 1.0f), &pb);
    VT_CHECK(wa > 0.5f && wb == 0.0f && pa > 0.5f && pb > 0.5f,
             "weights: bent cell, wall %g floor %g; plane, wall %g floor %g", wa, wb, pa, pb);
}

VT_TEST(near_field_index_lists_every_cell_that_reaches_a_point)
{
    /* a few hundred cells of two spacings on the six axis planes of a box */
    vsgl_vsgl_set set;
    memset(&set, 0, sizeof set);
    srand(11);
    for (int k = 0; k < 400; ++k) {
        vsgl_vsgl v = cell_cluster(-1.0f);
        uint32_t bin = (uint32_t)(rand() % 6);
        float h = k % 2 ? 0.3f : 0.7f;
        v.cell_h = h;
        v.cell_axis = bin >> 1;
        v.cell_side = bin & 1;
        float cu = -2.0f + 4.0f * (float)rand() / (float)RAND_MAX, cv = -2.0f + 4.0f * (float)rand() / (float)RAND_MAX;
        float za = (v.cell_side ? 2.0f : -2.0f);
        v.cell_centre[0] = cu;
        v.cell_centre[1] = cv;
        v.cell_lo[0] = cu - h;
        v.cell_hi[0] = cu + h;
        v.cell_lo[1] = cv - h;
        v.cell_hi[1] = cv + h;
        float p[3], nn[3] = {0, 0, 0};
        p[v.cell_axis] = za;
        p[(v.cell_axis + 1) % 3] = cu;
        p[(v.cell_axis + 2) % 3] = cv;
        nn[v.cell_axis] = v.cell_side ? -1.0f : 1.0f;
        v.mean = v3_make(p[0], p[1], p[2]);
        v.normal = v3_make(nn[0], nn[1], nn[2]);
        VT_REQUIRE(vsgl__vsgl_set_push(&set, &v) == VSGL_OK, "push");
    }
    vsgl_near_index ix;
    VT_REQUIRE(vsgl__near_index_build(&set, &ix), "index");
    int missing = 0, reached = 0;
    for (int t = 0; t < 3000; ++t) {
        v3 x = v3_make(-2.0f + 4.0f * (float)rand() / (float)RAND_MAX, -2.0f + 4.0f * (float)rand() / (float)RAND_MAX,
                       -2.0f + 4.0f * (float)rand() / (float)RAND_MAX);
        v3 n = v3_normalize(v3_make((float)rand() / (float)RAND_MAX - 0.5f, (float)rand() / (float)RAND_MAX - 0.5f,
                                    (float)rand() / (float)RAND_MAX - 0.5f));
        size_t nc;
        const uint32_t *cand = vsgl__near_candidates(&ix, x, &nc);
        for (size_t k = 0; k < set.count; ++k) {
            if (ix.cell_of[k] < 0)
                continue;
            float w;
            vsgl__near_diffuse(&ix.cells[ix.cell_of[k]], x, n, &w);
            if (!(w > 0.0f))
                continue;
            ++reached;
            int found = 0;
            for (size_t i = 0; i < nc; ++i)
                found |= cand[i] == (uint32_t)ix.cell_of[k];
            missing += !found;
        }
        for (size_t i = 1; i < nc; ++i)
            VT_CHECK(cand[i] > cand[i - 1], "candidates out of order");
    }
    VT_CHECK(missing == 0 && reached > 1000, "%d of %d reaching cells not listed", missing, reached);
    vsgl__near_index_free(&ix);
    vsgl__vsgl_set_free(&set);
}

/* The diffuse plane of the fixture room's scene, shaded every pixel without
 * visibility rays (a convex room), by `method` with leak correction `leak`
 * on RSMs of `rsm` texels a side;
 * NULL if the render failed. *count: the VSGLs shaded. */
/* The coloured diffuse (glossy = 0) or glossy pass of a balanced render
 * at one sample per pixel, every pixel shaded, no visibility rays. */
static float *render_pass(vsgl_context *ctx, vsgl_scene *scene, uint32_t W, uint32_t H, int32_t method,
                          int32_t leak, uint32_t rsm, uint32_t *count, int glossy)
{
    float *img = calloc((size_t)W * H * 3, sizeof(float));
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    s.shade_stride = 1;
    s.aa_samples = 1;
    s.rsm_resolution = rsm;
    s.visibility = VSGL_VISIBILITY_NONE;
    s.method = method;
    s.leak_correction = leak;
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = W;
    o.height = H;
    if (glossy)
        o.glossy = img;
    else
        o.diffuse = img;
    vsgl_render_stats st;
    memset(&st, 0, sizeof st);
    st.size = sizeof st;
    if (!img || vsgl_render(ctx, scene, &s, &o, &st) != VSGL_OK) {
        free(img);
        return NULL;
    }
    if (count)
        *count = st.vsgl_count;
    return img;
}

static float *render_diffuse(vsgl_context *ctx, vsgl_scene *scene, uint32_t W, uint32_t H, int32_t method,
                             int32_t leak, uint32_t rsm, uint32_t *count)
{
    return render_pass(ctx, scene, W, H, method, leak, rsm, count, 0);
}

/* A room lit by a spot (the fixture): with the near field the lattice's
 * diffuse light beside the junctions moves to the brute force's, where the
 * far-field model alone is dark. The reference is the brute force at RSM
 * 256 (the RSM's limit: 128 is within 1.3e-5 of it), not on the lattice's
 * own RSM 64: there the brute force's point VPLs are themselves off at the
 * junctions (relMSE 8.3e-5 against RSM 256), and the near field matched
 * that error while its cells reached past the walls by the texels'
 * footprints (8.3e-5); with its cuts within the scene's bounds
 * (fit_lattice_keeps_its_cuts_within_the_scene) it is 2.4e-5, without the
 * near field 1.7e-4. */
VT_TEST(near_field_junctions_against_brute_force)
{
    const uint32_t W = 64, H = 48;
    fx_scene fx;
    fx_room(&fx, W, H, 1.0f, 150.0f);
    vsgl_context *ctx = fx_context(0);
    VT_REQUIRE(ctx, "context");
    vsgl_scene *scene;
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    size_t n = (size_t)W * H * 3;
    /* the reference, the lattice with and without the near field, the brute force on the lattice's RSM */
    const int32_t method[4] = {VSGL_METHOD_BRUTE_FORCE, VSGL_METHOD_VSGL, VSGL_METHOD_VSGL, VSGL_METHOD_BRUTE_FORCE};
    const int32_t leak[4] = {VSGL_LEAK_AUTO, VSGL_LEAK_AUTO, VSGL_LEAK_CLIP, VSGL_LEAK_AUTO};
    const uint32_t rsm[4] = {256, 64, 64, 64};
    float *img[4];
    for (int k = 0; k < 4; ++k) {
        img[k] = render_diffuse(ctx, scene, W, H, method[k], leak[k], rsm[k], NULL);
        VT_REQUIRE(img[k], "render %d: %s", k, vsgl_context_last_error(ctx));
    }
    double e_near = acc_relmse(img[1], img[0], n), e_far = acc_relmse(img[2], img[0], n);
    double e_brute = acc_relmse(img[3], img[0], n);
    double s0 = 0, s1 = 0, s2 = 0;
    for (size_t i = 0; i < n; ++i) {
        s0 += img[0][i];
        s1 += img[1][i];
        s2 += img[2][i];
    }
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    diffuse relMSE against the brute force at RSM 256: %.4g with the near field, %.4g without, %.4g "
               "the brute force at RSM 64; sums %.4f / %.4f\n",
               e_near, e_far, e_brute, s1 / s0, s2 / s0);
    VT_CHECK(e_near < 0.8 * e_far, "relMSE %.4g with the near field, %.4g without", e_near, e_far);
    VT_CHECK(e_near < 0.5 * e_brute, "relMSE %.4g with the near field, %.4g the brute force on the same RSM", e_near,
             e_brute);
    VT_CHECK(fabs(s1 / s0 - 1.0) < fabs(s2 / s0 - 1.0), "sum ratio %.4f with, %.4f without", s1 / s0, s2 / s0);
    for (int k = 0; k < 4; ++k)
        free(img[k]);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* A metal floor (roughness 0.3) under a spot reflects onto the walls: the
 * lattice splits each planar cluster's specular lobe into GGX's core and
 * tail (fit/lattice.c), and the walls' diffuse light moves towards the
 * brute force's over the same RSMs (one SG per cluster: the reflection too
 * bright in its middle, missing around it). In the far field alone (leak
 * clip): the near field of specular cells, which takes the walls' feet,
 * is checked against quadrature (test_near_specular.c), and there the
 * brute force's point VPLs a few cm away are no reference (with it
 * relMSE 0.00152). */
VT_TEST(lattice_specular_tail_against_brute_force)
{
    const uint32_t W = 64, H = 48;
    fx_scene fx;
    fx_room(&fx, W, H, 0.3f, 150.0f);
    fx.materials[0].metallic = 1.0f;
    fx.materials[0].base_color[0] = fx.materials[0].base_color[1] = fx.materials[0].base_color[2] = 0.9f;
    vsgl_context *ctx = fx_context(0);
    VT_REQUIRE(ctx, "context");
    vsgl_scene *scene;
    VT_REQUIRE(vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    size_t n = (size_t)W * H * 3;
    float *img[2];
    uint32_t count = 0;
    for (int k = 0; k < 2; ++k) {
        img[k] = render_diffuse(ctx, scene, W, H, k ? VSGL_METHOD_VSGL : VSGL_METHOD_BRUTE_FORCE, VSGL_LEAK_CLIP, 64,
                                &count);
        VT_REQUIRE(img[k], "render %d: %s", k, vsgl_context_last_error(ctx));
    }
    double e = acc_relmse(img[1], img[0], n);
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    walls' diffuse light against the brute force: relMSE %.4g (%u VSGLs)\n", e, count);
    /* measured 0.00121 (555 VSGLs); one SG per cluster 0.00188 (387 VSGLs) */
    VT_CHECK(e < 0.0015, "relMSE %.4g against the brute force", e);
    for (int k = 0; k < 2; ++k)
        free(img[k]);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* The fixture room with its floor a gentle heightfield: z = A sin(2 pi x /
 * L) sin(2 pi y / L), A = 2 cm, L = 0.5 m (slopes up to 14 degrees), a
 * grid of 2 x 32 x 32 triangles, its material the fixture floor's of the
 * given roughness. fx keeps the walls; desc is the whole scene. */
#define BUMPY_N 32
typedef struct bumpy_scene {
    fx_scene fx;
    float pos[3 * (16 + (BUMPY_N + 1) * (BUMPY_N + 1))];
    uint32_t idx[3 * (8 + 2 * BUMPY_N * BUMPY_N)], mat[8 + 2 * BUMPY_N * BUMPY_N];
    vsgl_scene_desc desc;
} bumpy_scene;

static void bumpy_room(bumpy_scene *s, uint32_t W, uint32_t H, float floor_roughness)
{
    fx_scene *fx = &s->fx;
    float *pos = s->pos;
    uint32_t *idx = s->idx, *mat = s->mat;
    fx_room(fx, W, H, floor_roughness, 150.0f);
    /* the walls and ceiling: vertices 4.., triangles 2.. of the fixture */
    uint32_t nv = 0, nt = 0;
    for (uint32_t v = 4; v < fx->vertex_count; ++v, ++nv)
        for (int c = 0; c < 3; ++c)
            pos[nv * 3 + (uint32_t)c] = fx->positions[v * 3 + (uint32_t)c];
    for (uint32_t t = 2; t < fx->triangle_count; ++t, ++nt) {
        for (int k = 0; k < 3; ++k)
            idx[nt * 3 + (uint32_t)k] = fx->indices[t * 3 + (uint32_t)k] - 4;
        mat[nt] = fx->material_indices[t];
    }
    const uint32_t base = nv, n = BUMPY_N;
    for (uint32_t j = 0; j <= n; ++j)
        for (uint32_t i = 0; i <= n; ++i, ++nv) {
            float x = -1.0f + 2.0f * (float)i / (float)n, y = -1.0f + 2.0f * (float)j / (float)n;
            pos[nv * 3 + 0] = x;
            pos[nv * 3 + 1] = y;
            pos[nv * 3 + 2] = 0.02f * sinf(12.566371f * x) * sinf(12.566371f * y);
        }
    for (uint32_t j = 0; j < n; ++j)
        for (uint32_t i = 0; i < n; ++i) {
            uint32_t a = base + j * (n + 1) + i, b = a + 1, c = a + n + 1, e = c + 1;
            const uint32_t q[6] = {a, b, e, a, e, c};
            for (int t = 0; t < 2; ++t, ++nt) {
                for (int k = 0; k < 3; ++k)
                    idx[nt * 3 + (uint32_t)k] = q[t * 3 + k];
                mat[nt] = 0;
            }
        }
    fx_desc(fx);
    vsgl_scene_desc *d = &s->desc;
    *d = fx->desc;
    d->vertex_count = nv;
    d->positions = pos;
    d->triangle_count = nt;
    d->indices = idx;
    d->material_indices = mat;
}

/* bumpy_room's scene, in a context of all cores (*ctx); NULL if either
 * cannot be made (*ctx then says why, or is NULL). */
static vsgl_scene *bumpy_create(bumpy_scene *room, uint32_t W, uint32_t H, float floor_roughness, vsgl_context **ctx)
{
    bumpy_room(room, W, H, floor_roughness);
    vsgl_scene *scene = NULL;
    *ctx = fx_context(0);
    if (!*ctx || vsgl_scene_create(*ctx, &room->desc, &scene) != VSGL_OK)
        return NULL;
    return scene;
}

/* A gently bumped floor (bumpy_room, matte) lit by the spot beside a wall: its
 * clusters are nearly planar, and the near field takes them for the
 * receivers across their plane (VSGL__NEAR_FACING_*, _ACROSS_*: the
 * wall's foot): the lattice's diffuse relMSE against the brute force at
 * RSM 128 is under 0.4 of the far field's alone (0.29). With the near
 * field faded in over 0.98-0.995 for every receiver (before 2026-12-07)
 * most of these cells had none: 0.56 of it. */
VT_TEST(near_field_takes_a_gently_bumped_floor)
{
    const uint32_t W = 64, H = 48;
    static bumpy_scene room;
    vsgl_context *ctx;
    vsgl_scene *scene = bumpy_create(&room, W, H, 1.0f, &ctx);
    VT_REQUIRE(scene, "scene: %s", ctx ? vsgl_context_last_error(ctx) : "no context");
    size_t n = (size_t)W * H * 3;
    const int32_t method[3] = {VSGL_METHOD_BRUTE_FORCE, VSGL_METHOD_VSGL, VSGL_METHOD_VSGL};
    const int32_t leak[3] = {VSGL_LEAK_AUTO, VSGL_LEAK_AUTO, VSGL_LEAK_CLIP};
    const uint32_t rsm[3] = {128, 64, 64};
    float *img[3];
    for (int k = 0; k < 3; ++k) {
        img[k] = render_diffuse(ctx, scene, W, H, method[k], leak[k], rsm[k], NULL);
        VT_REQUIRE(img[k], "render %d: %s", k, vsgl_context_last_error(ctx));
    }
    double e_near = acc_relmse(img[1], img[0], n), e_far = acc_relmse(img[2], img[0], n);
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    bumpy floor: diffuse relMSE against the brute force at RSM 128: %.4g with the near field, %.4g "
               "without (ratio %.3f)\n", e_near, e_far, e_near / e_far);
    VT_CHECK(e_near < 0.4 * e_far, "relMSE %.4g with the near field, %.4g without", e_near, e_far);
    for (int k = 0; k < 3; ++k)
        free(img[k]);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

/* A glossy bumpy floor reflects its own bumps (kernel.h,
 * vsgl__planar_weight): the lattice's clusters on it are nearly planar
 * (coherence ~0.99), and the planar glossy model, weighted by coherence^2,
 * gave a receiver on the same floor almost none of their light: its lobe
 * meets their plane at a grazing angle, where the bumps stand up into it.
 * The bumpy fixture room with its floor glossy (roughness 0.3): the floor's
 * glossy light in the image's lower half (mostly floor), balanced's
 * against the brute force at RSM 128 (every texel a VPL, the exact BRDF):
 * 0.57 of it with the planar model at full weight, 0.74 with its weight
 * faded for receivers facing the cluster's way on a bumpy surface (the
 * rest not traced). */
VT_TEST(planar_glossy_lets_a_bumpy_floor_reflect_itself)
{
    const uint32_t W = 64, H = 48;
    static bumpy_scene room;
    vsgl_context *ctx;
    vsgl_scene *scene = bumpy_create(&room, W, H, 0.3f, &ctx);
    VT_REQUIRE(scene, "scene: %s", ctx ? vsgl_context_last_error(ctx) : "no context");
    float *brute = render_pass(ctx, scene, W, H, VSGL_METHOD_BRUTE_FORCE, VSGL_LEAK_AUTO, 128, NULL, 1);
    float *vsgl = render_pass(ctx, scene, W, H, VSGL_METHOD_VSGL, VSGL_LEAK_AUTO, 256, NULL, 1);
    VT_REQUIRE(brute && vsgl, "render: %s", vsgl_context_last_error(ctx));
    double a = 0.0, b = 0.0;
    for (size_t i = (size_t)W * (H / 2) * 3; i < (size_t)W * H * 3; ++i) {
        a += vsgl[i];
        b += brute[i];
    }
    printf("    bumpy glossy floor, lower half: the lattice's glossy light %.3f of the brute force's\n", a / b);
    VT_CHECK(b > 0.0, "the brute force's floor has no glossy light: the test cannot tell");
    VT_CHECK(a > 0.65 * b && a < 1.15 * b, "the floor's glossy light is %.3f of the brute force's (0.57 with the "
             "planar model at full weight)", a / b);
    free(brute);
    free(vsgl);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}
