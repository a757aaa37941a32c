/* Convex parts (scene/convex.c, vsgl__scene_build_parts) and the light a
 * cluster on a part sends to the same part (fit/vsgl_set.h vsgl_vsgl.part,
 * kernel.h vsgl__part_keep): which meshes are parts, which side of them a
 * hit is on, and that a convex object alone in the dark receives no
 * indirect light from itself, while a room seen from inside keeps its own. */
#include "harness.h"
#include "scene_fixture.h"
#include "fit/vsgl_set.h"
#include "rsm/rsm.h"
#include "scene/scene_internal.h"
#include "vsgl/reference.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A growable triangle soup with indexed vertices. */
typedef struct mesh {
    float *pos;
    uint32_t *idx, *mat;
    uint32_t nv, nt, cap_v, cap_t;
} mesh;

static uint32_t mesh_vertex(mesh *m, float x, float y, float z)
{
    if (m->nv == m->cap_v) {
        m->cap_v = m->cap_v ? 2 * m->cap_v : 256;
        m->pos = realloc(m->pos, m->cap_v * 3 * sizeof *m->pos);
    }
    m->pos[3 * m->nv] = x, m->pos[3 * m->nv + 1] = y, m->pos[3 * m->nv + 2] = z;
    return m->nv++;
}

static void mesh_tri(mesh *m, uint32_t a, uint32_t b, uint32_t c, uint32_t mat)
{
    if (m->nt == m->cap_t) {
        m->cap_t = m->cap_t ? 2 * m->cap_t : 256;
        m->idx = realloc(m->idx, m->cap_t * 3 * sizeof *m->idx);
        m->mat = realloc(m->mat, m->cap_t * sizeof *m->mat);
    }
    m->idx[3 * m->nt] = a, m->idx[3 * m->nt + 1] = b, m->idx[3 * m->nt + 2] = c;
    m->mat[m->nt++] = mat;
}

/* A quad p0..p3 as two triangles; `soup`: its own vertices (not shared). */
static void mesh_quad(mesh *m, const float p[4][3], uint32_t mat)
{
    uint32_t v[4];
    for (int i = 0; i < 4; ++i)
        v[i] = mesh_vertex(m, p[i][0], p[i][1], p[i][2]);
    mesh_tri(m, v[0], v[1], v[2], mat);
    mesh_tri(m, v[0], v[2], v[3], mat);
}

/* A UV sphere (seg x rings) with one vertex at each pole, as Blender
 * builds it; soup = 1: every triangle with its own three vertices (welded
 * by position only). */
static void mesh_sphere(mesh *m, float cx, float cy, float cz, float r, int seg, int rings, int soup, uint32_t mat)
{
    const float pi = 3.14159265f;
    uint32_t north = mesh_vertex(m, cx, cy, cz + r), base = m->nv;
    for (int i = 1; i < rings; ++i)
        for (int j = 0; j < seg; ++j) {
            float th = pi * (float)i / (float)rings, ph = 2.0f * pi * (float)j / (float)seg;
            mesh_vertex(m, cx + r * sinf(th) * cosf(ph), cy + r * sinf(th) * sinf(ph), cz + r * cosf(th));
        }
    uint32_t south = mesh_vertex(m, cx, cy, cz - r);
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < seg; ++j) {
            /* ring i's vertex j (ring 0 and rings: the poles) */
#define RV(i_, j_) ((i_) == 0 ? north : (i_) == rings ? south : base + (uint32_t)(((i_) - 1) * seg + ((j_) % seg)))
            uint32_t a = RV(i, j), b = RV(i, j + 1), c = RV(i + 1, j), d = RV(i + 1, j + 1);
#undef RV
            uint32_t tri[2][3] = {{a, c, d}, {a, d, b}};
            for (int t = 0; t < 2; ++t) {
                if ((i == 0 && t == 1) || (i == rings - 1 && t == 0))
                    continue; /* the poles' degenerate halves */
                uint32_t v[3];
                for (int k = 0; k < 3; ++k)
                    v[k] = soup ? mesh_vertex(m, m->pos[3 * tri[t][k]], m->pos[3 * tri[t][k] + 1],
                                              m->pos[3 * tri[t][k] + 2])
                                : tri[t][k];
                mesh_tri(m, v[0], v[1], v[2], mat);
            }
        }
}

/* Corner normals for triangles [first, m->nt): radial about (cx, cy, cz)
 * (a smooth-shaded sphere), the face normal elsewhere. malloc'd, nt * 9. */
static float *mesh_normals(const mesh *m, uint32_t first, float cx, float cy, float cz)
{
    float *cn = malloc((size_t)m->nt * 9 * sizeof *cn);
    if (!cn)
        return NULL;
    for (uint32_t t = 0; t < m->nt; ++t) {
        const float *p[3];
        for (int k = 0; k < 3; ++k)
            p[k] = m->pos + 3 * m->idx[3 * t + k];
        float e1[3], e2[3];
        for (int a = 0; a < 3; ++a)
            e1[a] = p[1][a] - p[0][a], e2[a] = p[2][a] - p[0][a];
        float fn[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        for (int k = 0; k < 3; ++k) {
            float n[3] = {p[k][0] - cx, p[k][1] - cy, p[k][2] - cz};
            const float *src = t >= first ? n : fn;
            float l = sqrtf(src[0] * src[0] + src[1] * src[1] + src[2] * src[2]);
            for (int a = 0; a < 3; ++a)
                cn[9 * t + 3 * k + a] = src[a] / l;
        }
    }
    return cn;
}

static void mesh_free(mesh *m)
{
    free(m->pos), free(m->idx), free(m->mat);
    memset(m, 0, sizeof *m);
}

/* The scene of m (corner normals cn, or NULL) with fx's materials, light
 * and camera; NULL on failure (the context says why). */
static vsgl_scene *mesh_scene(vsgl_context *ctx, const mesh *m, const float *cn, fx_scene *fx)
{
    fx_desc(fx);
    fx->desc.vertex_count = m->nv;
    fx->desc.positions = m->pos;
    fx->desc.triangle_count = m->nt;
    fx->desc.indices = m->idx;
    fx->desc.material_indices = m->mat;
    fx->desc.corner_normals = cn;
    vsgl_scene *scene = NULL;
    if (vsgl_scene_create(ctx, &fx->desc, &scene) != VSGL_OK)
        return NULL;
    return scene;
}

/* The part key where the ray from o along d first hits, NONE for a miss. */
static uint32_t key_at(const vsgl_scene *scene, const float o[3], const float d[3])
{
    vsgl_hit hit;
    v3 dir = v3_normalize(v3_make(d[0], d[1], d[2]));
    if (!vsgl__scene_intersect(scene, v3_make(o[0], o[1], o[2]), dir, 0.0f, 100.0f, &hit))
        return 0xFFFFFFFEu;
    vsgl_surface sf;
    vsgl__scene_surface(scene, &hit, dir, &sf);
    return sf.part;
}

/* A sphere (shared vertices, wound outwards), the same sphere as a triangle
 * soup wound inwards, a flat quad, a wedge (two quads meeting at a right
 * angle: convex) and a step (three quads: not convex). Four parts; hits
 * from outside are on the outside, from the sphere's centre on its
 * inside, from either side of the quad on no inside, in the wedge's corner
 * on its inside; the step is in no part. */
VT_TEST(convex_parts_of_spheres_planes_a_wedge_and_a_step)
{
    vsgl_context *ctx = fx_context(1);
    VT_REQUIRE(ctx, "context");
    fx_scene fx;
    fx_room(&fx, 8, 6, 0.3f, 10.0f);
    mesh m = {0};
    mesh_sphere(&m, 0.0f, 0.0f, 0.0f, 1.0f, 24, 12, 0, 0);
    uint32_t first_soup = m.nt;
    mesh_sphere(&m, 5.0f, 0.0f, 0.0f, 1.0f, 24, 12, 1, 0);
    for (uint32_t t = first_soup; t < m.nt; ++t) { /* wound inwards */
        uint32_t s = m.idx[3 * t + 1];
        m.idx[3 * t + 1] = m.idx[3 * t + 2];
        m.idx[3 * t + 2] = s;
    }
    const float flat[4][3] = {{-1, 4, 0}, {1, 4, 0}, {1, 6, 0}, {-1, 6, 0}};
    mesh_quad(&m, flat, 1);
    /* the wedge: floor y in [10, 12] and a wall at y = 12, sharing an edge's positions */
    const float wf[4][3] = {{-1, 10, 0}, {1, 10, 0}, {1, 12, 0}, {-1, 12, 0}};
    const float ww[4][3] = {{-1, 12, 0}, {1, 12, 0}, {1, 12, 2}, {-1, 12, 2}};
    mesh_quad(&m, wf, 2);
    mesh_quad(&m, ww, 2);
    /* the step: up, across, up again (x in [-1, 1], at y = 20..24) */
    const float s1[4][3] = {{-1, 20, 0}, {1, 20, 0}, {1, 22, 0}, {-1, 22, 0}};
    const float s2[4][3] = {{-1, 22, 0}, {1, 22, 0}, {1, 22, 1}, {-1, 22, 1}};
    const float s3[4][3] = {{-1, 22, 1}, {1, 22, 1}, {1, 24, 1}, {-1, 24, 1}};
    mesh_quad(&m, s1, 3);
    mesh_quad(&m, s2, 3);
    mesh_quad(&m, s3, 3);
    vsgl_scene *scene = mesh_scene(ctx, &m, NULL, &fx);
    VT_REQUIRE(scene, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(vsgl__scene_part_count(scene) == 4, "parts: %u, want 4", vsgl__scene_part_count(scene));
    const uint32_t NONE = VSGL__PART_NONE;
    struct { float o[3], d[3]; int part; int inner; const char *what; } c[] = {
        {{0, -3, 0.3f}, {0, 1, 0}, 0, 0, "sphere from outside"},
        {{0, 0, 0}, {0.3f, 0.2f, 1}, 0, 1, "sphere from its centre"},
        {{5, -3, -0.2f}, {0, 1, 0}, 1, 0, "inward-wound soup sphere from outside"},
        {{5, 0, 0}, {1, 0.1f, 0.2f}, 1, 1, "inward-wound soup sphere from its centre"},
        {{0, 5, 1}, {0, 0, -1}, 2, 0, "flat quad from above"},
        {{0.2f, 5.3f, -1}, {0, 0, 1}, 2, 0, "flat quad from below"},
        {{0, 10.5f, 1}, {0, 0.3f, -1}, 3, 1, "wedge's floor from its corner"},
        {{0, 11, 1}, {0, 1, 0.1f}, 3, 1, "wedge's wall from its corner"},
        {{0, 11, -1}, {0, 0, 1}, 3, 0, "wedge's floor from below"},
        {{0, 13, 1}, {0, -1, 0}, 3, 0, "wedge's wall from behind"},
        {{0, 21, 2}, {0, 0, -1}, -1, 0, "step's lower tread"},
        {{0, 23, 2}, {0, 0, -1}, -1, 0, "step's upper tread"},
    };
    for (size_t i = 0; i < sizeof c / sizeof c[0]; ++i) {
        uint32_t k = key_at(scene, c[i].o, c[i].d);
        uint32_t want = c[i].part < 0 ? NONE : 2u * (uint32_t)c[i].part + (uint32_t)c[i].inner;
        VT_CHECK(k == want, "%s: key %#x, want %#x", c[i].what, k, want);
    }
    vsgl_scene_destroy(scene);
    mesh_free(&m);
    vsgl_context_destroy(ctx);
}

/* Render a sphere lit by a spot with nothing else in the scene: no light
 * can bounce onto it (every point of it lies behind every other's tangent
 * plane), so its indirect light is 0 in every preset. With the leak
 * correction off (the knob that turns the parts off) its clusters light
 * their own sphere. */
VT_TEST(render_a_convex_object_alone_receives_no_indirect_light)
{
    vsgl_context *ctx = fx_context(2);
    VT_REQUIRE(ctx, "context");
    fx_scene fx;
    fx_room(&fx, 48, 36, 0.3f, 200.0f);
    fx.materials[0].roughness = 0.25f;
    fx.materials[0].specular_f0 = 0.5f; /* a bright glossy sphere */
    mesh m = {0};
    mesh_sphere(&m, 0.0f, 0.0f, 0.8f, 0.5f, 48, 24, 0, 0);
    const float eye[3] = {1.2f, -1.5f, 2.2f}, at[3] = {0.0f, 0.0f, 0.8f};
    fx_spot(&fx, eye, at, 200.0f, 1.0f, 0.2f);
    const float ceye[3] = {-0.3f, -2.6f, 1.1f}, cat[3] = {0.0f, 0.0f, 0.8f};
    fx_camera(&fx, ceye, cat, 40.0f, 48, 36);
    float *cn = mesh_normals(&m, 0, 0.0f, 0.0f, 0.8f); /* smooth: radial */
    VT_REQUIRE(cn, "memory");
    vsgl_scene *scene = mesh_scene(ctx, &m, cn, &fx);
    VT_REQUIRE(scene, "%s", vsgl_context_last_error(ctx));
    const size_t n = 48 * 36 * 3;
    float *diff = malloc(n * sizeof *diff), *gl = malloc(n * sizeof *gl);
    VT_REQUIRE(diff && gl, "memory");
    const int32_t presets[3] = {VSGL_PRESET_PREVIEW, VSGL_PRESET_BALANCED, VSGL_PRESET_QUALITY};
    for (int p = 0; p < 4; ++p) {
        vsgl_render_settings s;
        vsgl_render_settings_preset(presets[p < 3 ? p : 1], &s);
        if (p == 3)
            s.leak_correction = VSGL_LEAK_OFF;
        vsgl_render_output o;
        memset(&o, 0, sizeof o);
        o.width = 48;
        o.height = 36;
        o.diffuse_light = diff;
        o.glossy_light = gl;
        VT_CHECK(vsgl_render(ctx, scene, &s, &o, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        double sd = 0.0, sg = 0.0;
        for (size_t i = 0; i < n; ++i)
            sd += diff[i], sg += gl[i];
        if (p < 3)
            VT_CHECK(sd == 0.0 && sg == 0.0, "preset %d: the sphere lights itself: diffuse %g, glossy %g", p, sd, sg);
        else
            VT_CHECK(sd > 0.0 && sg > 0.0, "leak correction off: diffuse %g, glossy %g (the parts are off with it)",
                     sd, sg);
    }
    free(diff), free(gl), free(cn);
    vsgl_scene_destroy(scene);
    mesh_free(&m);
    vsgl_context_destroy(ctx);
}

/* lattice_clusters_carry_their_parts_shares for the room and sphere of m,
 * the sphere smooth-shaded where cn is given. */
static void check_lattice_parts(vsgl_context *ctx, fx_scene *fx, const mesh *m, const float *cn)
{
    vsgl_scene *scene = mesh_scene(ctx, m, cn, fx);
    VT_REQUIRE(scene, "%s", vsgl_context_last_error(ctx));
    const int smooth = cn != NULL;
    VT_CHECK(vsgl__scene_part_count(scene) == 2, "parts: %u, want 2 (the room, the sphere)",
             vsgl__scene_part_count(scene));
    VT_CHECK(!vsgl__scene_part_curved(scene, 0) && vsgl__scene_part_curved(scene, 1) == smooth,
             "curved: room %d, sphere %d (smooth %d)", vsgl__scene_part_curved(scene, 0),
             vsgl__scene_part_curved(scene, 1), smooth);
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    vsgl_rsm rsm;
    VT_REQUIRE(vsgl__rsm_build(ctx, scene, 0, 128, &rsm) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    vsgl_vsgl_set set = {0};
    VT_REQUIRE(vsgl__fit_lattice(ctx, scene, &rsm, &s, &set) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    int room = 0, sphere = 0, other = 0;
    float h_room = 0.0f, h_sphere = 0.0f;
    for (size_t k = 0; k < set.count; ++k) {
        const vsgl_vsgl *v = &set.items[k];
        if (v->part == 0 && v->part_out == 0.0f && v->part_in > 0.999f)
            ++room, h_room = v->cell_h;
        else if (v->part == 1 && v->part_out > 0.999f && v->part_in == 0.0f)
            ++sphere, h_sphere = v->cell_h;
        else
            ++other;
    }
    VT_CHECK(room > 0 && sphere > 0 && other == 0, "smooth %d: clusters: room %d, sphere %d, neither %d", smooth,
             room, sphere, other);
    float want = smooth ? (float)(VSGL__LATTICE_CURVED * h_room) : h_room;
    VT_CHECK(fabsf(h_sphere - want) <= 1e-5f * h_room, "smooth %d: spacing room %g, sphere %g, want %g", smooth,
             h_room, h_sphere, want);
    vsgl__vsgl_set_free(&set);
    vsgl__rsm_free(&rsm);
    vsgl_scene_destroy(scene);
}

/* The fit's part shares: in the fixture's open box (one convex part, lit
 * and seen from inside) every cluster is all inside, so nothing of the
 * room's own light is dropped; a sphere standing in it has clusters all
 * outside. A smooth-shaded sphere is a curved part and takes the finer
 * lattice (VSGL__LATTICE_CURVED x the room's spacing); flat-shaded, the
 * room's. */
VT_TEST(lattice_clusters_carry_their_parts_shares)
{
    vsgl_context *ctx = fx_context(1);
    VT_REQUIRE(ctx, "context");
    fx_scene fx;
    fx_room(&fx, 8, 6, 0.3f, 100.0f);
    mesh m = {0};
    for (uint32_t t = 0; t < fx.triangle_count; ++t) {
        uint32_t v[3];
        for (int k = 0; k < 3; ++k) {
            const float *p = fx.positions + 3 * fx.indices[3 * t + k];
            v[k] = mesh_vertex(&m, p[0], p[1], p[2]);
        }
        mesh_tri(&m, v[0], v[1], v[2], fx.material_indices[t]);
    }
    uint32_t first = m.nt;
    mesh_sphere(&m, -0.5f, -0.1f, 0.4f, 0.3f, 32, 16, 0, 3);
    float *cn = mesh_normals(&m, first, -0.5f, -0.1f, 0.4f);
    VT_REQUIRE(cn, "memory");
    for (int smooth = 0; smooth < 2; ++smooth)
        check_lattice_parts(ctx, &fx, &m, smooth ? cn : NULL);
    free(cn);
    mesh_free(&m);
    vsgl_context_destroy(ctx);
}

/* The glossy light of balanced (brute 0) or of the brute force (RSM 128,
 * one sample per pixel, shadow rays) in the quality suite's sphere room
 * (tests/quality/scenes.py, glossy_sphere_floor): a 5 x 5 x 3 m box with
 * a polished floor (Lambert + GGX layer, roughness 0.2) and a glossy
 * plastic sphere (roughness 0.3, radius 0.5) lit by a spot from above. */
static void sheared_room_render(int brute, float *gl, uint32_t w, uint32_t h)
{
    vsgl_context *ctx = fx_context(0);
    VT_REQUIRE(ctx, "context");
    fx_scene fx;
    memset(&fx, 0, sizeof fx);
    mesh m = {0};
    const float x0 = -2.5f, x1 = 2.5f, y0 = -2.5f, y1 = 2.5f, z1 = 3.0f;
    const float q[6][4][3] = {
        {{x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}},     /* floor */
        {{x0, y0, z1}, {x0, y1, z1}, {x1, y1, z1}, {x1, y0, z1}}, /* ceiling */
        {{x0, y0, 0}, {x0, y1, 0}, {x0, y1, z1}, {x0, y0, z1}},   /* left */
        {{x1, y0, 0}, {x1, y0, z1}, {x1, y1, z1}, {x1, y1, 0}},   /* right */
        {{x0, y1, 0}, {x1, y1, 0}, {x1, y1, z1}, {x0, y1, z1}},   /* back */
        {{x0, y0, 0}, {x0, y0, z1}, {x1, y0, z1}, {x1, y0, 0}},   /* front */
    };
    for (int k = 0; k < 6; ++k)
        mesh_quad(&m, q[k], k == 0 ? 0 : 1);
    uint32_t first = m.nt;
    const float c[3] = {0.0f, 0.6f, 0.6f};
    mesh_sphere(&m, c[0], c[1], c[2], 0.5f, 48, 24, 0, 2);
    vsgl_material *mt = fx.materials;
    const float col[3][3] = {{0.5f, 0.5f, 0.5f}, {0.8f, 0.8f, 0.8f}, {0.8f, 0.35f, 0.1f}};
    const float rough[3] = {0.2f, 1.0f, 0.3f}, f0[3] = {0.04f, 0.0f, 0.04f};
    for (int k = 0; k < 3; ++k) {
        memcpy(mt[k].base_color, col[k], sizeof col[k]);
        mt[k].roughness = rough[k];
        mt[k].specular_f0 = f0[k];
    }
    const float eye[3] = {1.2f, -0.7f, 2.7f}, at[3] = {0.0f, 0.6f, 0.5f};
    fx_spot(&fx, eye, at, 2500.0f, 0.8727f, 0.3f);
    /* the suite's camera, zoomed in on the floor's reflection of the sphere's highlight */
    const float ceye[3] = {0.3137f, -2.3f, 1.3f}, cat[3] = {0.2f, -0.67f, 0.0f};
    fx_camera(&fx, ceye, cat, 100.0f, w, h);
    float *cn = mesh_normals(&m, first, c[0], c[1], c[2]);
    VT_REQUIRE(cn, "memory");
    vsgl_scene *scene = mesh_scene(ctx, &m, cn, &fx);
    VT_REQUIRE(scene, "%s", vsgl_context_last_error(ctx));
    if (brute) {
        VT_CHECK(vsgl_reference_render(ctx, scene, 128, 2, 1, NULL, gl, NULL, NULL, NULL) == VSGL_OK, "%s",
                 vsgl_context_last_error(ctx));
    } else {
        vsgl_render_settings s;
        vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
        vsgl_render_output o;
        memset(&o, 0, sizeof o);
        o.width = w;
        o.height = h;
        o.glossy_light = gl;
        VT_CHECK(vsgl_render(ctx, scene, &s, &o, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    }
    free(cn);
    vsgl_scene_destroy(scene);
    mesh_free(&m);
    vsgl_context_destroy(ctx);
}

VT_TEST(sheared_highlight_of_a_sphere_in_a_glossy_floor)
{
    enum { W = 32, H = 24 };
    float *a = calloc(W * H * 3, sizeof *a), *b = calloc(W * H * 3, sizeof *b);
    VT_REQUIRE(a && b, "memory");
    sheared_room_render(0, a, W, H);
    sheared_room_render(1, b, W, H);
    if (getenv("VSGL_TEST_VERBOSE"))
        for (int y = 0; y < H; ++y) {
            for (int x = 0; x < W; ++x)
                fprintf(stderr, "%4.0f", 100.0 * (a[3 * (y * W + x)] + a[3 * (y * W + x) + 1] + a[3 * (y * W + x) + 2]));
            fprintf(stderr, "   |");
            for (int x = 0; x < W; ++x)
                fprintf(stderr, "%4.0f", 100.0 * (b[3 * (y * W + x)] + b[3 * (y * W + x) + 1] + b[3 * (y * W + x) + 2]));
            fprintf(stderr, "\n");
        }
    /* the highlight: the pixels where the brute force has more than half its peak */
    float peak_b = 0.0f, peak_a = 0.0f;
    int at_b = 0, at_a = 0;
    for (int k = 0; k < W * H; ++k) {
        float va = a[3 * k] + a[3 * k + 1] + a[3 * k + 2], vb = b[3 * k] + b[3 * k + 1] + b[3 * k + 2];
        if (vb > peak_b)
            peak_b = vb, at_b = k;
        if (va > peak_a)
            peak_a = va, at_a = k;
    }
    double sa = 0.0, sb = 0.0;
    int n = 0;
    for (int k = 0; k < W * H; ++k) {
        float vb = b[3 * k] + b[3 * k + 1] + b[3 * k + 2];
        if (vb > 0.5f * peak_b) {
            sa += a[3 * k] + a[3 * k + 1] + a[3 * k + 2];
            sb += vb;
            ++n;
        }
    }
    const int dx = at_a % W - at_b % W, dy = at_a / W - at_b / W;
    if (getenv("VSGL_TEST_VERBOSE"))
        fprintf(stderr, "highlight: %d pixels, light over the brute force's %.3f, peak %.3f / %.3f at (%d, %d) / (%d, %d)\n",
                n, sa / sb, (double)peak_a, (double)peak_b, at_a % W, at_a / W, at_b % W, at_b / W);
    VT_CHECK(n >= 6, "the highlight has %d pixels: the view misses it", n);
    VT_CHECK(fabs(sa / sb - 1.0) < 0.1, "the highlight's light over the brute force's: %.3f (%d pixels)", sa / sb, n);
    VT_CHECK(fabs(peak_a / peak_b - 1.0f) < 0.1f, "its peak %.3f, the brute force's %.3f", (double)peak_a,
             (double)peak_b);
    VT_CHECK(dx * dx + dy * dy <= 2, "its peak at (%d, %d), the brute force's at (%d, %d)", at_a % W, at_a / W,
             at_b % W, at_b / W);
    free(a), free(b);
}
