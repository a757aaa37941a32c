/* The vectorised shading kernel: its exp against libm, and shading through
 * the kernel (vectorised and scalar builds) against the reference path
 * through the public operator functions. */
#include "harness.h"
#include "scene_fixture.h"
#include "shade/shade.h"
#include "render/render_internal.h"

#define KERNEL_ATTR static __attribute__((unused))
#define KERNEL_NAME test_kernel_copy
#include "shade/kernel_impl.h"

#include "kernel_isa.h"

#include <stdlib.h>

VT_TEST(kernel_exp_matches_libm)
{
    double worst = 0.0;
    for (double x = -87.0; x <= 88.0; x += 0.001) {
        double got = k_exp((float)x), want = exp((double)(float)x);
        double rel = fabs(got - want) / want;
        worst = rel > worst ? rel : worst;
    }
    VT_CHECK(worst < 3e-7, "worst relative error %.3g over [-87, 88]", worst);
    VT_CHECK(k_exp(-88.0f) == 0.0f && k_exp(-1e30f) == 0.0f, "underflow to 0");
    VT_CHECK(isfinite(k_exp(1e30f)) && k_exp(1e30f) > 1e38f, "overflow clamps to e^88 (finite)");
}

VT_TEST(kernel_cosine_matches_library_accurate_form)
{
    vt_rng r = {9};
    for (int i = 0; i < 20000; ++i) {
        float l = (float)pow(10.0, -6.0 + 12.0 * vt_uniform(&r));
        float c = (float)(2.0 * vt_uniform(&r) - 1.0);
        vsgl_sg g = {{0, 0, 1}, l, 0.0f};
        vsgl_vec3 n = {sqrtf(1 - c * c), 0, c};
        float want = vsgl_sg_cosine_integral(&g, &n, VSGL_COSINE_ACCURATE);
        float got = k_cosine_accurate(l, c);
        VT_CHECK(fabsf(got - want) <= 2e-5f * fmaxf(want, 1e-3f), "lambda %g c %g: kernel %g library %g", l, c, got, want);
    }
}

/* The short form for sharp lobes (no exp, no series) against the full one. */
VT_TEST(kernel_sharp_cosine_matches_full_form)
{
    vt_rng r = {11};
    double worst = 0.0;
    for (int i = 0; i < 200000; ++i) {
        float l = (float)(K_SHARP_COSINE * pow(10.0, 11.0 * vt_uniform(&r)));
        float c = (float)(2.0 * vt_uniform(&r) - 1.0);
        if (i % 7 == 0)
            c = (float)(1e-3 * (2.0 * vt_uniform(&r) - 1.0)); /* the horizon, where the terms dropped live */
        float full = k_cosine_cpart(l, c, k_cosine_lpart(l));
        float sharp = k_cosine_cpart_s(l, c, k_cosine_lpart_sharp(l), 1);
        float a = (float)(2.0 * 3.14159265358979 / l); /* A(l) for large l */
        double e = fabs((double)sharp - full) / a;
        worst = e > worst ? e : worst;
    }
    VT_CHECK(worst < 2e-6, "worst |sharp - full| / A(lambda) = %.3g", worst);
    /* and a lambda below the switch would be wrong: the test can fail */
    float l = 4.0f, c = 0.0f;
    float full = k_cosine_cpart(l, c, k_cosine_lpart(l)), sharp = k_cosine_cpart_s(l, c, k_cosine_lpart_sharp(l), 1);
    VT_CHECK(fabsf(sharp - full) > 1e-3f * full, "lambda 4: the short form differs (%g vs %g)", sharp, full);
}

typedef struct bundle {
    vsgl_context *ctx;
    vsgl_scene *scene;
    vsgl_gbuffer g;
    vsgl_vsgl_set set;
    vsgl_render_settings s;
    fx_scene fx;
} bundle;

static int setup_as(bundle *b, float roughness, uint32_t vsgls, int32_t fit, int32_t leak, uint32_t flags)
{
    memset(b, 0, sizeof *b);
    fx_room(&b->fx, 40, 30, roughness, 100.0f);
    for (int m = 0; m < 4; ++m)
        b->fx.materials[m].flags |= flags;
    vsgl_render_settings in;
    vsgl_render_settings_preset(VSGL_PRESET_BALANCED, &in);
    in.shade_stride = 1; /* every pixel shaded, no visibility rays: the model alone */
    in.visibility = VSGL_VISIBILITY_NONE;
    in.vsgl_count = vsgls;
    in.rsm_resolution = 32;
    in.leak_correction = leak;
    in.fit_mode = fit;
    vsgl_rsm rsm;
    if (vsgl_context_create(NULL, &b->ctx) || vsgl_scene_create(b->ctx, fx_desc(&b->fx), &b->scene) ||
        vsgl__settings_resolve(b->ctx, &in, &b->s) || vsgl__gbuffer_build(b->ctx, b->scene, 1, 0, &b->g) ||
        vsgl__rsm_build(b->ctx, b->scene, 0, 32, &rsm))
        return 0;
    int ok = (fit == VSGL_FIT_LATTICE ? vsgl__fit_lattice : vsgl__fit_fis)(b->ctx, b->scene, &rsm, &b->s, &b->set) == VSGL_OK;
    vsgl__rsm_free(&rsm);
    return ok;
}

static void teardown(bundle *b)
{
    vsgl__vsgl_set_free(&b->set);
    vsgl__gbuffer_free(&b->g);
    vsgl_scene_destroy(b->scene);
    vsgl_context_destroy(b->ctx);
}

static float *shade(bundle *b, int path)
{
    size_t px = (size_t)b->g.width * b->g.height;
    float *buf = calloc(px * 13, sizeof(float));
    vsgl_pixel_planes pl = {buf, buf + 3 * px, buf + 6 * px, buf + 9 * px, buf + 12 * px};
    uint64_t pairs;
    vsgl__shade(b->ctx, b->scene, &b->g, &b->set, &b->s, &pl, path, &pairs);
    return buf;
}

static double relmse(const float *a, const float *ref, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; ++i)
        s += ((double)a[i] - ref[i]) * ((double)a[i] - ref[i]) / ((double)ref[i] * ref[i] + 1e-4);
    return s / (double)n;
}

VT_TEST(kernel_shading_matches_reference_path)
{
    /* FIS without the emitter clip; the lattice with it (shade.h) */
    const float rough[3] = {0.15f, 0.4f, 0.8f};
    for (int k = 0; k < 6; ++k) {
        bundle b;
        int clip = k >= 3;
        /* Blender 3.x's Burley diffuse (per pair in both paths) in half the rooms */
        VT_CHECK(setup_as(&b, rough[k % 3], 32, clip ? VSGL_FIT_LATTICE : VSGL_FIT_FIS, clip ? VSGL_LEAK_ON : VSGL_LEAK_OFF,
                          k % 2 ? VSGL_MATERIAL_FLAG_BURLEY : 0u),
                 "setup: %s", b.ctx ? vsgl_context_last_error(b.ctx) : "");
        size_t px = (size_t)b.g.width * b.g.height;
        for (int mode = 0; mode < 3; ++mode) {
            b.s.diffuse_mode = mode;
            /* the glossy lobe as one ASG, or as GGX's core and tail */
            b.s.glossy_mode = (k + mode) % 2 ? VSGL_GLOSSY_ASG2 : VSGL_GLOSSY_ASG;
            /* the half-vector model's four lobes and the quality preset's five, both on the lattice */
            b.s.glossy_lobes = 4u + (unsigned)((k / 2 + mode) % 2);
            float *ref = shade(&b, VSGL__SHADE_REFERENCE);
            float *vec = shade(&b, VSGL__SHADE_KERNEL);
            float *sca = shade(&b, VSGL__SHADE_KERNEL_SCALAR);
            double ed = relmse(vec, ref, 3 * px), eg = relmse(vec + 3 * px, ref + 3 * px, 3 * px);
            double sd = relmse(sca, ref, 3 * px), sg = relmse(sca + 3 * px, ref + 3 * px, 3 * px);
            VT_CHECK(ed < 1e-10 && sd < 1e-10, "roughness %g mode %d: diffuse relMSE vec %.3g scalar %.3g", rough[k % 3], mode, ed, sd);
            /* glossy: the kernel normalises the ASG x SG integral as Eq. 18
             * (pi / sqrt(...)), the reference path by the exact Eq. 10 form;
             * they differ for broad lobes */
            double tol = rough[k % 3] < 0.3f ? 1e-10 : (rough[k % 3] < 0.5f ? 1e-7 : 1e-4); /* GGX's tail part is ~4x broader */
            if (getenv("VSGL_TEST_VERBOSE"))
                printf("    roughness %g mode %d: relMSE diffuse %.3g glossy %.3g (scalar build %.3g %.3g)\n", rough[k % 3], mode, ed, eg, sd, sg);
            VT_CHECK(eg < tol && sg < tol, "roughness %g mode %d: glossy relMSE vec %.3g scalar %.3g (tol %g)",
                     rough[k % 3], mode, eg, sg, tol);
            free(ref);
            free(vec);
            free(sca);
        }
        teardown(&b);
    }
}

/* A random block of receivers (mixed diffuse / glossy lanes, random
 * orthonormal lobe frames) and a random VSGL, from broad and near to sharp
 * and far, in the kernel's layout. */
static void random_block(vt_rng *r, vsgl_kernel_block *b)
{
    memset(b, 0, sizeof *b);
    for (int k = 0; k < VSGL__KERNEL_BLOCK; ++k) {
        b->x[k] = (float)(4.0 * vt_uniform(r) - 2.0);
        b->y[k] = (float)(4.0 * vt_uniform(r) - 2.0);
        b->z[k] = (float)(4.0 * vt_uniform(r) - 2.0);
        double th = acos(2.0 * vt_uniform(r) - 1.0), ph = 6.283185307 * vt_uniform(r);
        vsgl_vec3 z = {(float)(sin(th) * cos(ph)), (float)(sin(th) * sin(ph)), (float)cos(th)};
        vsgl_vec3 t = fabsf(z.x) < 0.9f ? (vsgl_vec3){1, 0, 0} : (vsgl_vec3){0, 1, 0};
        float d = t.x * z.x + t.y * z.y + t.z * z.z;
        vsgl_vec3 x = {t.x - d * z.x, t.y - d * z.y, t.z - d * z.z};
        float n = sqrtf(x.x * x.x + x.y * x.y + x.z * x.z);
        x.x /= n; x.y /= n; x.z /= n;
        vsgl_vec3 y = {z.y * x.z - z.z * x.y, z.z * x.x - z.x * x.z, z.x * x.y - z.y * x.x};
        b->nx[k] = z.x; b->ny[k] = z.y; b->nz[k] = z.z;
        b->diffuse[k] = vt_uniform(r) < 0.8 ? 1.0f : 0.0f;
        /* Blender 3.x's Burley diffuse on half the lanes (VSGL__KERNEL_BURLEY blocks) */
        b->burley[k] = vt_uniform(r) < 0.5 ? (float)vt_uniform(r) : -1.0f;
        { /* a view above the lane's plane (Burley's factor reads it) */
            float ox = z.x + (float)(1.6 * vt_uniform(r) - 0.8), oy = z.y + (float)(1.6 * vt_uniform(r) - 0.8);
            float oz = z.z + (float)(1.6 * vt_uniform(r) - 0.8), on = sqrtf(ox * ox + oy * oy + oz * oz);
            b->ox[k] = ox / on; b->oy[k] = oy / on; b->oz[k] = oz / on;
        }
        b->Xx[k] = x.x; b->Xy[k] = x.y; b->Xz[k] = x.z;
        b->Yx[k] = y.x; b->Yy[k] = y.y; b->Yz[k] = y.z;
        b->Zx[k] = z.x; b->Zy[k] = z.y; b->Zz[k] = z.z;
        if (vt_uniform(r) < 0.7) {
            b->lam[k] = (float)pow(10.0, 4.0 * vt_uniform(r) - 0.5);
            b->mu[k] = (float)pow(10.0, 4.0 * vt_uniform(r) - 0.5);
            b->camp[k] = (float)(1.0 + 100.0 * vt_uniform(r));
            b->f0r[k] = b->f0g[k] = b->f0b[k] = (float)vt_uniform(r);
            /* the half-vector model's Fresnel ratio (scene/material.h
             * vsgl__fresnel_ratio): a dielectric's on half the lanes, 1 on
             * the rest (0, the block's memset, would zero that model) */
            b->fa[k] = 1.0f;
            if (vt_uniform(r) < 0.5) {
                b->fe[k] = 1.5f;
                b->fa[k] = (float)(0.2 + vt_uniform(r));
                b->fb[k] = (float)(2.0 * vt_uniform(r));
            }
            /* the smooth-factor ratio (kernel.h vsgl__smooth_ratio) at a
             * random alpha, as for GGX's two lobes or one */
            const float a = (float)(0.01 + 0.99 * vt_uniform(r));
            vsgl__kernel_set_smooth(b, k, vsgl__shadow_lane(a, b->nx[k] * b->ox[k] + b->ny[k] * b->oy[k] +
                                                               b->nz[k] * b->oz[k], 1.0f, vt_uniform(r) < 0.5));
        }
        /* convex parts (kernel.h vsgl__part_keep): none, 0 or 1, outside or in */
        b->part[k] = (float)((int)(3.0 * vt_uniform(r)) - 1);
        b->pouter[k] = vt_uniform(r) < 0.5 ? 1.0f : 0.0f;
    }
}

static void random_light(vt_rng *r, vsgl_kernel_light *o, int sharp)
{
    memset(o, 0, sizeof *o);
    o->mx = (float)(4.0 * vt_uniform(r) - 2.0);
    o->my = (float)(4.0 * vt_uniform(r) - 2.0);
    o->mz = (float)(4.0 * vt_uniform(r) - 2.0);
    o->var = (float)pow(10.0, sharp ? -7.0 + 2.0 * vt_uniform(r) : -3.0 + 3.0 * vt_uniform(r));
    o->pvar = o->var * (vt_uniform(r) < 0.5 ? 1.0f : 2.0f);
    o->var2 = 2.0f * o->var;
    o->ivar = 1.0f / o->var;
    o->valid = 1.0f;
    o->az = 1.0f;
    o->lv = (float)(3.0 * vt_uniform(r));
    o->lax = o->lv * o->ax; o->lay = o->lv * o->ay; o->laz = o->lv * o->az;
    o->c0 = 1.0f / (6.2831853f * vsgl_sg_integral(o->lv));
    o->pr = 1.0f; o->pg = 0.5f; o->pb = 0.25f;
    o->nz = -1.0f;
    o->clip = (float)vt_uniform(r);
    o->conv = vt_uniform(r) < 0.5 ? 1.0f : 0.0f;
    o->ibehind = 1.0f / (0.02f * sqrtf(o->var));
    /* a planar cluster (its normal -z) for half the lights: the planar glossy stage */
    o->planar = vt_uniform(r) < 0.5 ? (vt_uniform(r) < 0.5 ? 1.0f : (float)vt_uniform(r)) : 0.0f;
    o->u1x = 1.0f; o->u2y = 1.0f;
    /* on convex part 0 or 1 for two thirds of the lights, with shares out and in */
    int part = (int)(3.0 * vt_uniform(r)) - 1;
    o->part = part < 0 ? -2.0f : (float)part;
    o->pout = (float)(0.6 * vt_uniform(r));
    o->pin = (float)((1.0 - o->pout) * vt_uniform(r));
    /* half the specular ones sheared (vsgl_vsgl.shear): shifts of up to a
     * few sigma per unit of direction, the variance given the direction a
     * share of the cluster's */
    if (o->conv == 0.0f && o->planar == 0.0f && vt_uniform(r) < 0.5) {
        const float sigma = sqrtf(o->var);
        for (int e = 0; e < 9; ++e)
            o->sh[e] = (float)(3.0 * (2.0 * vt_uniform(r) - 1.0)) * sigma;
        o->ishift = 0.25f / o->var;
        o->shear = 1.0f;
        o->var *= (float)(0.05 + 0.95 * vt_uniform(r));
        o->var2 = 2.0f * o->var;
        o->ivar = 1.0f / o->var;
    }
}

/* Every ISA copy (AVX-512, AVX2, baseline) and the library's scalar build
 * accumulate the same light, for every diffuse form, with and without
 * visibility, in blocks of broad and of sharp lobes (the short forms). */
VT_TEST(kernel_isa_clones_agree_with_scalar_build)
{
#if KERNEL_ISA_CLONES
    typedef size_t (*kfn)(vsgl_kernel_block *, const vsgl_kernel_light *, size_t, const float *, int32_t, int32_t,
                           float);
    kfn fns[3] = {test_kernel_isa_base, test_kernel_isa_v3, test_kernel_isa_v4};
    const char *names[3] = {"x86-64", "x86-64-v3", "x86-64-v4"};
    int have[3] = {1, __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"),
                   __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                       __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl")};
    vt_rng r = {2024};
    static vsgl_kernel_block base, ref, got;
    static float vis[8 * VSGL__KERNEL_BLOCK];
    double worst[3] = {0, 0, 0}, worst_c[3] = {0, 0, 0};
    for (int trial = 0; trial < 60; ++trial) {
        random_block(&r, &base);
        vsgl_kernel_light L[8];
        /* half the trials without the emitter clip and the planar model: the
         * strict tolerance; the clip's fades scale with the height above a
         * cluster's plane, a difference of coordinates that any order of
         * operations rounds differently near the plane */
        int plain = trial % 4 < 2;
        /* every third trial with the glossy lobe as GGX's core and tail */
        const int32_t lob = VSGL__KERNEL_DIFFUSE | VSGL__KERNEL_GLOSSY | (trial % 3 == 0 ? VSGL__KERNEL_GGX_TAIL : 0) |
                            (trial % 2 ? VSGL__KERNEL_GRAZE : 0) | /* the horizon cut in half the trials */
                            (trial % 5 < 2 ? VSGL__KERNEL_BURLEY : 0); /* Burley's diffuse in two of five */
        for (int k = 0; k < 8; ++k) {
            random_light(&r, &L[k], trial % 2);
            if (plain)
                L[k].clip = L[k].planar = 0.0f;
        }
        for (int k = 0; k < 8 * VSGL__KERNEL_BLOCK; ++k)
            vis[k] = (float)vt_uniform(&r);
        for (int mode = 0; mode < 3; ++mode)
            for (int withvis = 0; withvis < 2; ++withvis) {
                ref = base;
                for (int k = 0; k < 8; ++k) /* one at a time */
                    vsgl__kernel_shade_scalar(&ref, &L[k], 1, withvis ? vis + k * VSGL__KERNEL_BLOCK : NULL, mode, lob,
                                              0.0f);
                double scale = 0.0;
                for (int c = 0; c < 3; ++c)
                    for (int k = 0; k < VSGL__KERNEL_BLOCK; ++k)
                        scale = fmax(scale, fmax(ref.ld[c][k], ref.ls[c][k]));
                for (int f = 0; f < 3; ++f) {
                    if (!have[f])
                        continue;
                    got = base;
                    fns[f](&got, L, 7, withvis ? vis : NULL, mode, lob, 0.0f); /* in pairs, one left over */
                    fns[f](&got, L + 7, 1, withvis ? vis + 7 * VSGL__KERNEL_BLOCK : NULL, mode, lob, 0.0f);
                    for (int c = 0; c < 3; ++c)
                        for (int k = 0; k < VSGL__KERNEL_BLOCK; ++k) {
                            double ed = fabs((double)got.ld[c][k] - ref.ld[c][k]) / (fabs(ref.ld[c][k]) + 1e-6 * scale);
                            double es = fabs((double)got.ls[c][k] - ref.ls[c][k]) / (fabs(ref.ls[c][k]) + 1e-6 * scale);
                            VT_CHECK(isfinite(got.ld[c][k]) && isfinite(got.ls[c][k]), "%s: non-finite", names[f]);
                            if (plain)
                                worst[f] = fmax(worst[f], fmax(ed, es));
                            else
                                worst_c[f] = fmax(worst_c[f], fmax(ed, es));
                        }
                }
            }
    }
    for (int f = 0; f < 3; ++f) {
        if (getenv("VSGL_TEST_VERBOSE"))
            printf("    %s: %s, worst relative difference to the scalar build %.3g (with the clip and planar model %.3g)\n",
                   names[f], have[f] ? "run" : "not supported here", worst[f], worst_c[f]);
        VT_CHECK(worst[f] < 2e-4, "%s: worst relative difference %.3g", names[f], worst[f]);
        /* the clip's fades near a cluster's plane and the planar model's
         * quadratic form for the most anisotropic lobes (lambda / mu up to
         * 10^4) are ill-conditioned: rounding of ~5e-4 of values far below
         * what a pixel shows */
        VT_CHECK(worst_c[f] < 2e-3, "%s: with the clip: worst relative difference %.3g", names[f], worst_c[f]);
    }
#else
    printf("    (skipped: the ISA clones are built by GCC on x86-64 only)\n");
#endif
}

/* A glossy receiver at a planar cluster's very mean (d = 0: a scene 1e5 m
 * from the origin quantises positions to 8 mm, so a G-buffer sample can
 * land on a cluster's mean exactly), in a block whose other lanes take the
 * half-vector model: every output finite. The cluster's slope spread var /
 * d^2 was ~1e23 there, the half-vector lobe's determinant overflowed, and
 * the pixel's glossy light was NaN (the render refused it). */
VT_TEST(kernel_receiver_at_a_planar_clusters_mean_is_finite)
{
    vt_rng r = {77};
    static vsgl_kernel_block b, ref;
    vsgl_kernel_light L;
    memset(&L, 0, sizeof L);
    L.mx = 0.3f; L.my = 0.2f; L.mz = 1.0f;  /* a ceiling patch facing down */
    L.var = 0.01f; L.pvar = L.var; L.var2 = 2.0f * L.var; L.ivar = 1.0f / L.var; L.valid = 1.0f;
    L.az = 1.0f; L.nz = -1.0f; L.u1x = 1.0f; L.u2y = 1.0f;
    L.c0 = 1.0f / (6.2831853f * vsgl_sg_integral(0.0f));
    L.pr = L.pg = L.pb = 1.0f;
    L.clip = 1.0f; L.planar = 1.0f; L.conv = 1.0f;
    L.ibehind = 1.0f / (0.02f * sqrtf(L.var));
    memset(&b, 0, sizeof b);
    for (int k = 0; k < VSGL__KERNEL_BLOCK; ++k) {
        /* a floor below it, seen from above at random; lane 0 at the mean */
        float x = k ? (float)(2.0 * vt_uniform(&r) - 1.0) : L.mx, y = k ? (float)(2.0 * vt_uniform(&r) - 1.0) : L.my;
        b.x[k] = x; b.y[k] = y; b.z[k] = k ? 0.0f : L.mz;
        b.nz[k] = 1.0f;
        double ph = 6.283185307 * vt_uniform(&r), el = 0.3 + 1.2 * vt_uniform(&r);
        b.ox[k] = (float)(cos(el) * cos(ph)); b.oy[k] = (float)(cos(el) * sin(ph)); b.oz[k] = (float)sin(el);
        /* the lobe's axis: the view mirrored about the normal */
        b.Zx[k] = -b.ox[k]; b.Zy[k] = -b.oy[k]; b.Zz[k] = b.oz[k];
        b.Xx[k] = 1.0f; b.Yy[k] = 1.0f;
        b.lam[k] = b.mu[k] = 200.0f;
        b.camp[k] = 10.0f;
        b.alpha[k] = 0.05f;
        b.f0r[k] = b.f0g[k] = b.f0b[k] = 0.5f;
        b.fa[k] = 1.0f; /* no Fresnel ratio (scene/material.h vsgl__fresnel_ratio) */
        vsgl__kernel_set_smooth(&b, k, vsgl__shadow_lane(b.alpha[k], b.oz[k], b.Zz[k], 1));
        b.diffuse[k] = 1.0f;
    }
    const int32_t lob = VSGL__KERNEL_DIFFUSE | VSGL__KERNEL_GLOSSY | VSGL__KERNEL_GGX_TAIL;
    ref = b;
    vsgl__kernel_shade(&b, &L, 1, NULL, VSGL_COSINE_PULLED_OUT, lob, 0.0f);
    vsgl__kernel_shade_scalar(&ref, &L, 1, NULL, VSGL_COSINE_PULLED_OUT, lob, 0.0f);
    int bad = 0, lit = 0;
    for (int k = 0; k < VSGL__KERNEL_BLOCK; ++k)
        for (int c = 0; c < 3; ++c) {
            bad += !isfinite(b.ls[c][k]) || !isfinite(b.ld[c][k]) || !isfinite(ref.ls[c][k]) || !isfinite(ref.ld[c][k]);
            lit += b.ls[c][k] > 0.0f;
        }
    VT_CHECK(bad == 0, "%d non-finite outputs (lane 0 glossy %g, scalar build %g)", bad, b.ls[0][0], ref.ls[0][0]);
    VT_CHECK(lit > 0, "no lane got glossy light: the block does not reach the half-vector model");
}

/* The faint skip (VSGL__FAINT, kernel_impl.h k_faint): a small specular
 * cluster with a sharp lobe aimed away from a block of diffuse receivers
 * that face it is skipped there, and what it skips is at most about that
 * share of what it gives each receiver when aimed at it; aimed at the
 * block it is shaded exactly as without the skip; a planar cluster is never
 * skipped. Far receivers of a small cluster (ls >> lv): the incident lobe's
 * sharpness is the same whichever way the lobe points, so the amplitude's
 * share is the light's. */
VT_TEST(kernel_faint_vsgls_skip_at_most_their_share)
{
    static vsgl_kernel_block base, b, off, peak;
    vsgl_kernel_light L;
    memset(&L, 0, sizeof L);
    L.mx = 0.0f; L.my = 0.0f; L.mz = 2.0f;
    L.var = 1e-6f; L.pvar = L.var; L.var2 = 2.0f * L.var; L.ivar = 1.0f / L.var; L.valid = 1.0f;
    L.nz = -1.0f; L.u1x = 1.0f; L.u2y = 1.0f;
    L.lv = 500.0f;
    L.c0 = 1.0f / (6.2831853f * vsgl_sg_integral(L.lv));
    L.pr = L.pg = L.pb = 1.0f;
    L.ibehind = 1.0f / (0.02f * sqrtf(L.var));
    memset(&base, 0, sizeof base);
    vt_rng r = {5};
    for (int k = 0; k < VSGL__KERNEL_BLOCK; ++k) { /* a patch of floor below it, facing up */
        base.x[k] = (float)(0.4 * vt_uniform(&r) - 0.2);
        base.y[k] = (float)(0.4 * vt_uniform(&r) - 0.2);
        base.nz[k] = 1.0f;
        base.diffuse[k] = 1.0f;
        base.Xx[k] = 1.0f; base.Yy[k] = 1.0f; base.Zz[k] = 1.0f;
    }
    const int32_t lob = VSGL__KERNEL_DIFFUSE;
    int checked = 0;
    for (int aim = 0; aim < 8; ++aim) {
        /* the lobe tilted off the block's centre by 10..45 degrees */
        double th = (10.0 + 5.0 * aim) * 3.14159265 / 180.0;
        vsgl_kernel_light A = L;
        A.ax = (float)sin(th); A.az = (float)cos(th); /* -axis: the block sees the lobe's axis at th */
        A.lax = A.lv * A.ax; A.laz = A.lv * A.az;
        b = base; off = base;
        size_t sk = vsgl__kernel_shade(&b, &A, 1, NULL, VSGL_COSINE_PULLED_OUT, lob, VSGL__FAINT);
        size_t sk0 = vsgl__kernel_shade(&off, &A, 1, NULL, VSGL_COSINE_PULLED_OUT, lob, 0.0f);
        VT_CHECK(sk0 == 0, "faint 0 skipped %zu VSGLs", sk0);
        /* the largest share over the lanes, each against the lobe aimed at it */
        double share = 0.0;
        for (int k = 0; k < VSGL__KERNEL_BLOCK; ++k) {
            vsgl_kernel_light P = L;
            float dx = L.mx - base.x[k], dy = L.my - base.y[k], dz = L.mz - base.z[k];
            float dn = sqrtf(dx * dx + dy * dy + dz * dz);
            P.ax = dx / dn; P.ay = dy / dn; P.az = dz / dn;
            P.lax = P.lv * P.ax; P.lay = P.lv * P.ay; P.laz = P.lv * P.az;
            peak = base;
            vsgl__kernel_shade(&peak, &P, 1, NULL, VSGL_COSINE_PULLED_OUT, lob, 0.0f);
            share = fmax(share, off.ld[0][k] / peak.ld[0][k]);
        }
        if (share < 0.5 * VSGL__FAINT) {
            VT_CHECK(sk == 1, "aim %d: the lobe gives at most %.3g of its peak at every lane, not skipped", aim, share);
        }
        if (sk == 1) {
            ++checked;
            VT_CHECK(share <= 1.05 * VSGL__FAINT, "aim %d: skipped, yet a lane gets %.3g of its peak (> %g)", aim,
                     share, (double)VSGL__FAINT);
            double sum = 0.0;
            for (int k = 0; k < VSGL__KERNEL_BLOCK; ++k)
                sum += b.ld[0][k] + b.ld[1][k] + b.ld[2][k];
            VT_CHECK(sum == 0.0, "aim %d: skipped, yet the block got light %g", aim, sum);
        } else {
            VT_CHECK(memcmp(&b, &off, sizeof b) == 0, "aim %d: not skipped, yet the block differs from faint 0", aim);
        }
    }
    VT_CHECK(checked >= 3, "only %d of the 8 aims were skipped: the test no longer reaches the skip", checked);
    /* aimed at the block: shaded, bit for bit as without the skip */
    vsgl_kernel_light A = L;
    A.az = 1.0f; A.laz = A.lv;
    b = base; off = base;
    VT_CHECK(vsgl__kernel_shade(&b, &A, 1, NULL, VSGL_COSINE_PULLED_OUT, lob, VSGL__FAINT) == 0,
             "a lobe aimed at the block was skipped");
    vsgl__kernel_shade(&off, &A, 1, NULL, VSGL_COSINE_PULLED_OUT, lob, 0.0f);
    VT_CHECK(memcmp(&b, &off, sizeof b) == 0, "aimed at the block: the skip changed the light");
    /* a planar cluster aimed away: never skipped (its planar model does not scale with the amplitude) */
    A = L;
    A.ax = 1.0f; A.lax = A.lv;
    A.planar = 1.0f; A.clip = 1.0f; A.conv = 1.0f;
    b = base;
    VT_CHECK(vsgl__kernel_shade(&b, &A, 1, NULL, VSGL_COSINE_PULLED_OUT, lob | VSGL__KERNEL_GLOSSY, VSGL__FAINT) == 0,
             "a planar cluster was skipped");
}
