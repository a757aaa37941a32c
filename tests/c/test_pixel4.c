/* vsgl__write_pixels4 (shade/pixel4.c) against vsgl__write_pixel: four
 * pixels' colours at once, bit for bit, over random normals, views and
 * lights on materials that take every branch of the pixel's colours
 * (Blender 4.x+ dielectric and metal, 3.x, no specular layer, F0 0),
 * with misses, grazing and back-facing views, unnormalised normals past
 * the clamp and signed zeros in the light. */
#include "harness.h"
#include "rand_dir.h"
#include "scene_fixture.h"
#include "shade/shade_job.h"

#include <stdlib.h>
#include <string.h>

#if defined(__SSE2__)
enum { NPX = 4096 };


typedef struct planes_buf {
    float d[NPX * 3], gl[NPX * 3], dc[NPX * 3], gc[NPX * 3], cov[NPX], cd[NPX * 4];
    vsgl_pixel_planes pl;
} planes_buf;

static void planes_init(planes_buf *b)
{
    memset(b, 0x7f, sizeof *b); /* a sentinel every write must replace (cd: kept for misses) */
    b->pl.diffuse = b->d;
    b->pl.glossy = b->gl;
    b->pl.diffuse_color = b->dc;
    b->pl.glossy_color = b->gc;
    b->pl.coverage = b->cov;
}

VT_TEST(shade_write_pixels4_equals_write_pixel_bit_for_bit)
{
    fx_scene fx;
    fx_room(&fx, 16, 12, 0.3f, 50.0f);
    vsgl_material *m = fx.materials;
    m[0].flags = VSGL_MATERIAL_FLAG_BLENDER_4 | VSGL_MATERIAL_FLAG_MULTISCATTER; /* dielectric, 4.x */
    m[1].metallic = 1.0f, m[1].roughness = 0.2f, m[1].flags = VSGL_MATERIAL_FLAG_BLENDER_4; /* metal, 4.x */
    m[2].metallic = 0.4f, m[2].specular_f0 = 0.0f, m[2].flags = VSGL_MATERIAL_FLAG_BLENDER_4; /* F0 0: no eta */
    m[3].specular_f0 = 0.0f; /* no specular layer: not glossy (and 3.x) */
    vsgl_context *ctx = fx_context(1);
    vsgl_scene *scene = NULL;
    VT_REQUIRE(ctx && vsgl_scene_create(ctx, fx_desc(&fx), &scene) == VSGL_OK, "scene");
    uint32_t nm = 0;
    const vsgl_material *mats = vsgl__scene_materials(scene, &nm);
    VT_REQUIRE(nm == 4, "materials %u", (unsigned)nm);
    vsgl_brdf_params params[5];
    for (uint32_t k = 0; k < nm; ++k)
        vsgl__material_params(&mats[k], &params[k]);
    params[4] = params[1];
    params[4].height_correlated = 0; /* a 3.x metal: GlossCol 1 */
    /* m[2]'s dielectric part has no Fresnel curve, m[3] no glossy lobe: the branches are taken */
    VT_CHECK(params[0].glossy && params[0].height_correlated && params[0].eta > 1.0f, "material 0");
    VT_CHECK(params[2].glossy && params[2].f0_dielectric == 0.0f, "material 2");
    VT_CHECK(!params[3].glossy, "material 3");

    static float nrm[3][NPX], view[3][NPX], light[NPX * 6];
    static uint32_t mat[NPX];
    vt_rng rng = {1234};
    for (size_t i = 0; i < NPX; ++i) {
        v3 n = rand_dir(&rng), o = rand_dir(&rng);
        int kind = (int)(vt_uniform(&rng) * 8.0);
        if (kind == 0) /* grazing: n.o = 0 exactly */
            o = v3_make(-n.y, n.x, 0.0f);
        else if (kind == 1) /* past the clamp: n.o > 1 */
            o = v3_scale(n, 1.0f + urand(&rng, 0.0f, 1e-3f));
        else if (kind == 2) /* facing the view */
            o = v3_dot(n, o) < 0.0f ? v3_neg(o) : o;
        for (int c = 0; c < 3; ++c) {
            nrm[c][i] = c == 0 ? n.x : c == 1 ? n.y : n.z;
            view[c][i] = c == 0 ? o.x : c == 1 ? o.y : o.z;
        }
        /* material 4 stands for a 3.x material in the params table only */
        mat[i] = vt_uniform(&rng) < 0.1 ? VSGL__GBUFFER_MISS : (uint32_t)(vt_uniform(&rng) * 4.0);
        for (int c = 0; c < 6; ++c)
            light[i * 6 + c] = vt_uniform(&rng) < 0.1 ? -0.0f : urand(&rng, 0.0f, 3.0f);
    }
    vsgl_gbuffer g;
    memset(&g, 0, sizeof g);
    g.width = NPX;
    g.height = 1;
    g.spp = 1;
    g.aa = 1;
    g.count = NPX;
    for (int c = 0; c < 3; ++c) {
        g.nrm[c] = nrm[c];
        g.view[c] = view[c];
    }
    g.material = mat;
    static planes_buf a, b;
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 1) /* the same pixels with the 3.x metal in material 1's place */
            params[1] = params[4];
        planes_init(&a);
        planes_init(&b);
        shade_job j;
        memset(&j, 0, sizeof j);
        j.scene = scene;
        j.g = &g;
        j.params = params;
        j.materials = mats;
        for (size_t px = 0; px < NPX; px += 4) {
            const float *Ls[4];
            for (size_t k = 0; k < 4; ++k) {
                const float *L = mat[px + k] == VSGL__GBUFFER_MISS ? NULL : light + (px + k) * 6;
                j.planes = &a.pl;
                vsgl__write_pixel(&j, px + k, &L, a.cd + (px + k) * 4);
                Ls[k] = L;
            }
            j.planes = &b.pl;
            vsgl__write_pixels4(&j, px, Ls, b.cd + px * 4);
        }
        size_t bad = 0, first = SIZE_MAX;
        for (size_t i = 0; i < NPX; ++i) {
            int same = !memcmp(a.d + i * 3, b.d + i * 3, 12) && !memcmp(a.gl + i * 3, b.gl + i * 3, 12) &&
                       !memcmp(a.dc + i * 3, b.dc + i * 3, 12) && !memcmp(a.gc + i * 3, b.gc + i * 3, 12) &&
                       !memcmp(a.cov + i, b.cov + i, 4) && !memcmp(a.cd + i * 4, b.cd + i * 4, 16);
            if (!same && bad++ == 0)
                first = i;
        }
        VT_CHECK(bad == 0, "pass %d: %zu of %d pixels differ, first %zu (material %u, glossy colour %.9g vs %.9g)",
                 pass, bad, NPX, first, first < NPX ? (unsigned)mat[first] : 0u, first < NPX ? a.gc[first * 3] : 0.0,
                 first < NPX ? b.gc[first * 3] : 0.0);
    }
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}
#endif
