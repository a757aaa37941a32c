/* VSGL fit: the two-VSGL mode against a direct double-precision evaluation
 * of the poster's equations on a hand-built RSM, FIS/k-means invariants. */
#include "harness.h"
#include "scene_fixture.h"
#include "fit/grid.h"
#include "scene/material.h"
#include "math/sg_internal.h"
#include "vsgl/lobes.h"

#include <stdlib.h>

#define PI_D 3.14159265358979323846

typedef struct hand_rsm {
    vsgl_rsm r;
    float *mem;
} hand_rsm;

/* A single-face RSM of res^2 texels with random VPLs around `offset`;
 * about one texel in six is empty. */
static void make_rsm(hand_rsm *h, uint32_t res, uint64_t seed, float offset, float spread)
{
    memset(h, 0, sizeof *h);
    vsgl_rsm *r = &h->r;
    r->faces = 1;
    r->res = res;
    r->count = (size_t)res * res;
    h->mem = calloc(r->count * 13, sizeof(float));
    r->area = h->mem + r->count * 12;
    for (int c = 0; c < 3; ++c) {
        r->pos[c] = h->mem + r->count * (size_t)c;
        r->nrm[c] = h->mem + r->count * (size_t)(3 + c);
        r->wi[c] = h->mem + r->count * (size_t)(6 + c);
        r->flux[c] = h->mem + r->count * (size_t)(9 + c);
    }
    r->material = calloc(r->count, sizeof(uint32_t));
    vt_rng rng = {seed};
    for (size_t t = 0; t < r->count; ++t) {
        if (vt_uniform(&rng) < 1.0 / 6.0) {
            r->material[t] = VSGL__RSM_EMPTY;
            continue;
        }
        r->material[t] = (uint32_t)(vt_uniform(&rng) * 4.0) % 4;
        double n[3] = {vt_uniform(&rng) - 0.5, vt_uniform(&rng) - 0.5, 1.0};
        double w[3] = {vt_uniform(&rng) - 0.5, vt_uniform(&rng) - 0.5, 0.7};
        double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double wl = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        for (int c = 0; c < 3; ++c) {
            r->pos[c][t] = offset + spread * (float)(vt_uniform(&rng) - 0.5);
            r->nrm[c][t] = (float)(n[c] / nl);
            r->wi[c][t] = (float)(w[c] / wl);
            r->flux[c][t] = (float)(0.1 + vt_uniform(&rng));
            r->total_flux[c] += r->flux[c][t];
        }
        r->area[t] = (float)(1e-4 + 1e-2 * vt_uniform(&rng)); /* texel footprint, m^2 */
    }
}

static void free_rsm(hand_rsm *h)
{
    free(h->mem);
    free(h->r.material);
}

/* The poster's sums (Sec. 2.1-2.2, errata docs/references.md §3) in double. */
typedef struct ref_vsgl { double power[3], axis[3], sharpness, mean[3], variance; int present; } ref_vsgl;

static void reference_two(const vsgl_scene *scene, const vsgl_rsm *r, int32_t est, ref_vsgl out[2])
{
    uint32_t mc;
    const vsgl_material *mats = vsgl__scene_materials(scene, &mc);
    double W[2] = {0, 0}, P[2][3] = {{0}}, D[2][3] = {{0}}, X[2][3] = {{0}}, X2[2] = {0, 0};
    for (size_t t = 0; t < r->count; ++t) {
        if (r->material[t] == VSGL__RSM_EMPTY)
            continue;
        vsgl_brdf_params bp;
        vsgl__material_params(&mats[r->material[t]], &bp);
        double n[3] = {r->nrm[0][t], r->nrm[1][t], r->nrm[2][t]};
        double wi[3] = {r->wi[0][t], r->wi[1][t], r->wi[2][t]};
        double x[3] = {r->pos[0][t], r->pos[1][t], r->pos[2][t]};
        double cosi = n[0] * wi[0] + n[1] * wi[1] + n[2] * wi[2];
        for (int lobe = 0; lobe < 2; ++lobe) {
            double pw[3], axis[3], lambda;
            if (lobe == 0) {
                /* Blender 4.x+ materials: times the dimming's cosine-weighted mean (test_material.c) */
                double dp = vsgl__scene_glossy_albedo(scene, r->material[t])->diffuse_power;
                for (int c = 0; c < 3; ++c) { pw[c] = r->flux[c][t] * (double)bp.diffuse[c] * dp; axis[c] = n[c]; }
                lambda = vsgl_sg_cosine_sharpness();
            } else {
                if (!bp.glossy || cosi <= 0)
                    continue;
                /* the emitted lobe: the warped NDF cut at the horizon, with the
                 * material's Fresnel along it (tested against quadrature in
                 * test_lobes.c) */
                vsgl_vec3 nf = {(float)n[0], (float)n[1], (float)n[2]}, wf = {(float)wi[0], (float)wi[1], (float)wi[2]};
                vsgl_sg ndf, em;
                vsgl_ndf_to_sg(&nf, sqrtf(bp.alpha_x * bp.alpha_y), VSGL_NDF_GGX, &ndf);
                vsgl__warp_ndf_sg_emitted_fresnel(&ndf, &wf, bp.eta, (bp.f0[0] + bp.f0[1] + bp.f0[2]) * (1.0f / 3.0f),
                                                  &em);
                double ea[3] = {em.axis.x, em.axis.y, em.axis.z};
                for (int c = 0; c < 3; ++c) {
                    /* R_s: the lobe's directional albedo (its table is tested in test_material.c) */
                    pw[c] = r->flux[c][t] * vsgl__glossy_albedo(vsgl__scene_glossy_albedo(scene, r->material[t]), c, (float)cosi);
                    axis[c] = ea[c];
                }
                lambda = em.sharpness;
            }
            double w = pw[0] + pw[1] + pw[2];
            double mlen = vsgl_mean_length_from_sharpness((float)lambda, est);
            W[lobe] += w;
            for (int c = 0; c < 3; ++c) {
                P[lobe][c] += pw[c];
                D[lobe][c] += w * mlen * axis[c];
                X[lobe][c] += w * x[c];
            }
            /* a texel is a patch: its own second moment a / (2 pi) (disk of area a) */
            X2[lobe] += w * (x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + r->area[t] / (2.0 * PI_D));
        }
    }
    for (int lobe = 0; lobe < 2; ++lobe) {
        ref_vsgl *o = &out[lobe];
        memset(o, 0, sizeof *o);
        if (!(W[lobe] > 0))
            continue;
        o->present = 1;
        double len = 0, mu2 = 0;
        for (int c = 0; c < 3; ++c) {
            o->power[c] = P[lobe][c];
            o->mean[c] = X[lobe][c] / W[lobe];
            len += (D[lobe][c] / W[lobe]) * (D[lobe][c] / W[lobe]);
            mu2 += o->mean[c] * o->mean[c];
        }
        len = sqrt(len);
        for (int c = 0; c < 3; ++c)
            o->axis[c] = D[lobe][c] / W[lobe] / len;
        o->sharpness = vsgl_sharpness_from_mean_length((float)len, est);
        o->variance = 0.5 * (X2[lobe] / W[lobe] - mu2);
    }
}

/* The room fixture's materials, behind a context and a scene (the fits read
 * materials and bounds from the scene). Returns 0 (and fails the test) if
 * the scene cannot be built. */
typedef struct room { fx_scene fx; vsgl_context *ctx; vsgl_scene *scene; } room;

static int room_open_flags(room *r, uint32_t material_flags)
{
    fx_room(&r->fx, 32, 24, 0.3f, 100.0f);
    for (int k = 0; k < 4; ++k)
        r->fx.materials[k].flags |= material_flags;
    r->ctx = NULL;
    r->scene = NULL;
    if (vsgl_context_create(NULL, &r->ctx) == VSGL_OK &&
        vsgl_scene_create(r->ctx, fx_desc(&r->fx), &r->scene) != VSGL_OK)
        fprintf(stderr, "scene: %s\n", vsgl_context_last_error(r->ctx));
    VT_CHECK(r->scene != NULL, "scene creation failed");
    if (!r->scene)
        vsgl_context_destroy(r->ctx);
    return r->scene != NULL;
}

static int room_open(room *r)
{
    return room_open_flags(r, 0);
}

static void room_close(room *r)
{
    vsgl_scene_destroy(r->scene);
    vsgl_context_destroy(r->ctx);
}

VT_TEST(fit_two_matches_poster_equations_on_hand_built_rsm)
{
    static room rm;
    for (int flags = 0; flags < 2; ++flags) { /* Blender 3.x, then 4.x+ materials */
    if (!room_open_flags(&rm, flags ? VSGL_MATERIAL_FLAG_BLENDER_4 : 0))
        return;
    vsgl_context *ctx = rm.ctx;
    vsgl_scene *scene = rm.scene;
    const float offsets[3] = {0.0f, 40.0f, 1000.0f};
    for (int est = 0; est < 2; ++est)
        for (int oi = 0; oi < 3; ++oi) {
            hand_rsm h;
            make_rsm(&h, 16, 7 + (uint64_t)oi, offsets[oi], 2.0f);
            vsgl_render_settings s;
            vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
            s.sharpness_estimator = est;
            vsgl_vsgl_set set = {0};
            VT_CHECK(vsgl__fit_two(ctx, scene, &h.r, &s, &set) == VSGL_OK, "fit");
            ref_vsgl ref[2];
            reference_two(scene, &h.r, est, ref);
            VT_CHECK(set.count == (size_t)(ref[0].present + ref[1].present), "count %zu", set.count);
            for (size_t k = 0; k < set.count; ++k) {
                const vsgl_vsgl *v = &set.items[k];
                const ref_vsgl *w = &ref[v->lobe];
                for (int c = 0; c < 3; ++c) {
                    VT_CHECK_REL(v->power[c], w->power[c], 1e-5, "est %d offset %g lobe %u", est, offsets[oi], v->lobe);
                    VT_CHECK_ABS((&v->axis.x)[c], w->axis[c], 2e-5, "est %d offset %g lobe %u", est, offsets[oi], v->lobe);
                    VT_CHECK_ABS((&v->mean.x)[c], w->mean[c], 1e-6 * (1.0 + offsets[oi]), "est %d offset %g", est, offsets[oi]);
                }
                VT_CHECK_REL(v->sharpness, w->sharpness, 1e-4, "est %d offset %g lobe %u", est, offsets[oi], v->lobe);
                /* the reference's E|x|^2 - |E x|^2 cancels at large offsets; the fit centres its sums */
                double tol = offsets[oi] > 100.0f ? 1e-2 : 1e-4;
                VT_CHECK_REL(v->variance, w->variance, tol, "est %d offset %g lobe %u", est, offsets[oi], v->lobe);
            }
            vsgl__vsgl_set_free(&set);
            free_rsm(&h);
        }
    room_close(&rm);
    }
}

VT_TEST(fit_fis_single_cluster_equals_two_and_top_mip_equals_total)
{
    static room rm;
    if (!room_open(&rm))
        return;
    vsgl_context *ctx = rm.ctx;
    vsgl_scene *scene = rm.scene;
    hand_rsm h;
    make_rsm(&h, 32, 3, 5.0f, 1.0f);
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    s.vsgl_count = 1;
    vsgl_vsgl_set two = {0}, fis = {0};
    VT_CHECK(vsgl__fit_two(ctx, scene, &h.r, &s, &two) == VSGL_OK, "two");
    VT_CHECK(vsgl__fit_fis(ctx, scene, &h.r, &s, &fis) == VSGL_OK, "fis");
    VT_CHECK(two.count == fis.count && two.count == 2, "counts %zu %zu", two.count, fis.count);
    for (size_t k = 0; k < two.count && k < fis.count; ++k) {
        const vsgl_vsgl *a = &two.items[k], *b = &fis.items[k];
        VT_CHECK(a->lobe == b->lobe, "lobe order");
        for (int c = 0; c < 3; ++c) {
            VT_CHECK_REL(b->power[c], a->power[c], 1e-5, "lobe %u", a->lobe);
            VT_CHECK_ABS((&b->axis.x)[c], (&a->axis.x)[c], 1e-5, "lobe %u", a->lobe);
            VT_CHECK_ABS((&b->mean.x)[c], (&a->mean.x)[c], 1e-5, "lobe %u", a->lobe);
        }
        VT_CHECK_REL(b->sharpness, a->sharpness, 1e-4, "lobe %u", a->lobe);
        VT_CHECK_REL(b->variance, a->variance, 1e-4, "lobe %u", a->lobe);
    }
    /* the pyramid's top level holds the whole map */
    vsgl_grid g;
    VT_CHECK(vsgl__grid_build(ctx, scene, &h.r, s.sharpness_estimator, 1, &g) == VSGL_OK, "grid");
    double top[VSGL__GRID_STRIDE];
    vsgl__grid_sample(&g, 0, 3.7f, 20.1f, (float)(g.levels - 1), top);
    for (int k = 0; k < VSGL__GRID_STRIDE; ++k)
        VT_CHECK_ABS(top[k], g.total[k], 1e-5 * (fabs(g.total[k]) + 1.0), "field %d", k);
    vsgl__grid_free(&g);
    vsgl__vsgl_set_free(&two);
    vsgl__vsgl_set_free(&fis);
    free_rsm(&h);
    room_close(&rm);
}

static double total_weight(const vsgl_vsgl_set *s)
{
    double w = 0;
    for (size_t k = 0; k < s->count; ++k)
        w += (double)s->items[k].power[0] + s->items[k].power[1] + s->items[k].power[2];
    return w;
}

/* k-means clusters stay on one side of a crease: an RSM of two lit walls
 * meeting at a right angle (columns u < 32 on the plane x = 0, normal +x;
 * the rest on y = 0, normal +y; neighbours in the image across the corner
 * line). A cluster spanning both had its mean off both walls and normals
 * too incoherent for the emitter clip (sun_opening: a wall lit ~85x too
 * brightly by the window). Every VSGL's coherence is ~1 with the normal
 * term in the assignment; without it, clusters along the corner mixed both
 * walls (coherence ~0.7-0.95). */
VT_TEST(fit_kmeans_clusters_do_not_straddle_a_crease)
{
    static room rm;
    if (!room_open(&rm))
        return;
    hand_rsm h;
    make_rsm(&h, 64, 5, 0.0f, 1.0f);
    vsgl_rsm *r = &h.r;
    for (int c = 0; c < 3; ++c)
        r->total_flux[c] = 0.01f * (float)r->count;
    for (size_t t = 0; t < r->count; ++t) {
        uint32_t u = (uint32_t)(t % 64), v = (uint32_t)(t / 64);
        int wall_x = u < 32;
        float a = 0.02f * (float)(wall_x ? 32 - u : u - 32) + 0.01f, z = 0.02f * (float)v + 0.01f;
        r->material[t] = 0;
        r->pos[0][t] = wall_x ? 0.0f : a;
        r->pos[1][t] = wall_x ? a : 0.0f;
        r->pos[2][t] = z;
        r->nrm[0][t] = r->wi[0][t] = wall_x ? 1.0f : 0.0f;
        r->nrm[1][t] = r->wi[1][t] = wall_x ? 0.0f : 1.0f;
        r->nrm[2][t] = r->wi[2][t] = 0.0f;
        for (int c = 0; c < 3; ++c)
            r->flux[c][t] = 0.01f;
    }
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    const uint32_t counts[3] = {8, 32, 128};
    for (int i = 0; i < 3; ++i) {
        s.vsgl_count = counts[i];
        vsgl_vsgl_set km = {0};
        VT_CHECK(vsgl__fit_kmeans(rm.ctx, rm.scene, r, &s, &km) == VSGL_OK, "kmeans N=%u", counts[i]);
        float worst = 1.0f;
        for (size_t k = 0; k < km.count; ++k)
            if (km.items[k].lobe == VSGL__LOBE_DIFFUSE && km.items[k].coherence < worst)
                worst = km.items[k].coherence;
        printf("    N=%u: %zu VSGLs, least coherent diffuse cluster %.4f\n", counts[i], km.count, worst);
        VT_CHECK(worst > 0.999f, "N=%u: a cluster mixes both walls (coherence %.4f)", counts[i], worst);
        vsgl__vsgl_set_free(&km);
    }
    free_rsm(&h);
    room_close(&rm);
}

VT_TEST(fit_fis_and_kmeans_conserve_total_power)
{
    static room rm;
    if (!room_open(&rm))
        return;
    vsgl_context *ctx = rm.ctx;
    vsgl_scene *scene = rm.scene;
    hand_rsm h;
    make_rsm(&h, 64, 11, 0.0f, 1.5f);
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &s);
    vsgl_vsgl_set two = {0};
    vsgl__fit_two(ctx, scene, &h.r, &s, &two);
    double want = total_weight(&two);
    const uint32_t counts[4] = {2, 16, 64, 512};
    for (int i = 0; i < 4; ++i) {
        s.vsgl_count = counts[i];
        vsgl_vsgl_set fis = {0}, km = {0};
        VT_CHECK(vsgl__fit_fis(ctx, scene, &h.r, &s, &fis) == VSGL_OK, "fis N=%u", counts[i]);
        VT_CHECK(vsgl__fit_kmeans(ctx, scene, &h.r, &s, &km) == VSGL_OK, "kmeans N=%u", counts[i]);
        /* FIS: sum_i W_i / (N W_i / W) = W exactly; k-means: a partition */
        VT_CHECK_REL(total_weight(&fis), want, 1e-4, "fis N=%u (%zu VSGLs)", counts[i], fis.count);
        VT_CHECK_REL(total_weight(&km), want, 1e-5, "kmeans N=%u (%zu VSGLs)", counts[i], km.count);
        VT_CHECK(fis.count <= 2 * (size_t)counts[i] && km.count <= 2 * (size_t)counts[i], "counts");
        for (size_t k = 0; k < fis.count; ++k)
            VT_CHECK(isfinite(fis.items[k].variance) && fis.items[k].variance >= 0 &&
                     isfinite(fis.items[k].sharpness), "fis VSGL %zu", k);
        vsgl__vsgl_set_free(&fis);
        vsgl__vsgl_set_free(&km);
    }
    vsgl__vsgl_set_free(&two);
    free_rsm(&h);
    room_close(&rm);
}
