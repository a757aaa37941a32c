/* Benchmark (not a test): scene build (validation + copy + Embree BVH) and
 * a 1920x1080 camera G-buffer with aa = 2 (4 samples per pixel) on a
 * ~1M-triangle scene (tessellated heightfield plus boxes).
 *
 * Build and run (links the library's objects: internal functions are used):
 *   make build/libvsgl.so && cc -std=c11 -O2 -D_POSIX_C_SOURCE=200809L -Icsrc/include -Icsrc/src \
 *     -o build/bench_gbuffer tools/bench_gbuffer.c build/obj/csrc/src/core/{context,parallel,result}.o \
 *     build/obj/csrc/src/scene/scene.o build/obj/csrc/src/scene/validate.o \
 *     build/obj/csrc/src/scene/raytrace.o build/obj/csrc/src/scene/camera.o \
 *     build/obj/csrc/src/gbuffer/gbuffer.o -lembree3 -lpthread -lm
 *   build/bench_gbuffer [grid_side=707] [runs=3] [aa=2] [threads=0 (all cores)]
 * Prints the median of `runs` runs of each stage. */
#include "vsgl.h"
#include "core/context.h"
#include "gbuffer/gbuffer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_time.h"

int main(int argc, char **argv)
{
    uint32_t side = argc > 1 ? (uint32_t)atoi(argv[1]) : 707;
    int runs = argc > 2 ? atoi(argv[2]) : 3;
    uint32_t aa = argc > 3 ? (uint32_t)atoi(argv[3]) : 2;
    uint32_t threads = argc > 4 ? (uint32_t)atoi(argv[4]) : 0; /* 0 = all cores */
    if (side < 2 || runs < 1 || runs > 50 || aa < 1 || aa > 16) {
        fprintf(stderr, "usage: bench_gbuffer [grid_side>=2] [runs 1..50] [aa 1..16] [threads]\n");
        return 2;
    }
    const uint32_t boxes = 200;
    size_t nv = (size_t)side * side + (size_t)boxes * 8;
    size_t nt = (size_t)(side - 1) * (side - 1) * 2 + (size_t)boxes * 12;
    float *pos = malloc(nv * 3 * sizeof(float));
    uint32_t *ix = malloc(nt * 3 * sizeof(uint32_t));
    float *cn = malloc(nt * 9 * sizeof(float));
    if (!pos || !ix || !cn) {
        fprintf(stderr, "out of memory\n");
        return 1;
    }
    /* heightfield over [-50, 50]^2 with smooth analytic normals */
    const float ext = 100.0f;
    for (uint32_t j = 0; j < side; ++j)
        for (uint32_t i = 0; i < side; ++i) {
            float x = ext * ((float)i / (float)(side - 1) - 0.5f), y = ext * ((float)j / (float)(side - 1) - 0.5f);
            float *p = pos + ((size_t)j * side + i) * 3;
            p[0] = x;
            p[1] = y;
            p[2] = 2.0f * sinf(0.3f * x) * cosf(0.23f * y) + 0.5f * sinf(1.7f * x + 0.9f * y);
        }
    size_t t = 0;
    for (uint32_t j = 0; j + 1 < side; ++j)
        for (uint32_t i = 0; i + 1 < side; ++i) {
            uint32_t a = j * side + i, b = a + 1, c = a + side, d = c + 1;
            uint32_t q[6] = {a, b, d, a, d, c};
            memcpy(ix + t * 3, q, sizeof q);
            t += 2;
        }
    for (size_t k = 0; k < t * 3; ++k) {
        const float *p = pos + (size_t)ix[k] * 3;
        float x = p[0], y = p[1];
        float dzdx = 0.6f * cosf(0.3f * x) * cosf(0.23f * y) + 0.85f * cosf(1.7f * x + 0.9f * y);
        float dzdy = -0.46f * sinf(0.3f * x) * sinf(0.23f * y) + 0.45f * cosf(1.7f * x + 0.9f * y);
        float l = sqrtf(dzdx * dzdx + dzdy * dzdy + 1.0f);
        cn[k * 3 + 0] = -dzdx / l;
        cn[k * 3 + 1] = -dzdy / l;
        cn[k * 3 + 2] = 1.0f / l;
    }
    /* boxes on a pseudo-random scatter */
    unsigned long long rng = 12345;
    static const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (uint32_t bidx = 0; bidx < boxes; ++bidx) {
        float c[3], h[3];
        for (int k = 0; k < 3; ++k) {
            rng = rng * 6364136223846793005ull + 1442695040888963407ull;
            c[k] = (float)((rng >> 11) * 0x1.0p-53);
        }
        c[0] = ext * (c[0] - 0.5f);
        c[1] = ext * (c[1] - 0.5f);
        h[0] = h[1] = 0.5f + 1.5f * c[2];
        h[2] = 1.0f + 3.0f * c[2];
        c[2] = 2.0f;
        uint32_t base = side * side + bidx * 8;
        for (uint32_t v = 0; v < 8; ++v) {
            float *p = pos + ((size_t)base + v) * 3;
            p[0] = c[0] + ((v & 1) ? h[0] : -h[0]);
            p[1] = c[1] + ((v & 2) ? h[1] : -h[1]);
            p[2] = c[2] + ((v & 4) ? h[2] : -h[2]);
        }
        for (int f = 0; f < 6; ++f) {
            uint32_t q[6] = {base + quads[f][0], base + quads[f][1], base + quads[f][2],
                             base + quads[f][0], base + quads[f][2], base + quads[f][3]};
            memcpy(ix + t * 3, q, sizeof q);
            for (int k = 0; k < 6; ++k) { /* face normals for box corners */
                const float *p0 = pos + (size_t)q[(k / 3) * 3] * 3, *p1 = pos + (size_t)q[(k / 3) * 3 + 1] * 3,
                            *p2 = pos + (size_t)q[(k / 3) * 3 + 2] * 3;
                float e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
                float e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
                float *n = cn + (t * 3 + (size_t)k) * 3;
                n[0] = e1[1] * e2[2] - e1[2] * e2[1];
                n[1] = e1[2] * e2[0] - e1[0] * e2[2];
                n[2] = e1[0] * e2[1] - e1[1] * e2[0];
            }
            t += 2;
        }
    }
    vsgl_material mat;
    memset(&mat, 0, sizeof mat);
    mat.base_color[0] = mat.base_color[1] = mat.base_color[2] = 0.5f;
    mat.roughness = 0.4f;
    vsgl_camera cam;
    memset(&cam, 0, sizeof cam);
    cam.type = VSGL_CAMERA_PERSPECTIVE;
    /* at (0, -60, 25) looking at the origin: rotation about X by ~67 degrees */
    float ang = atan2f(60.0f, 25.0f);
    float m[12] = {1, 0, 0, 0, 0, cosf(ang), -sinf(ang), -60.0f, 0, sinf(ang), cosf(ang), 25.0f};
    memcpy(cam.world_from_camera, m, sizeof m);
    cam.lens_mm = 30.0f;
    cam.sensor_width_mm = 36.0f;
    cam.sensor_height_mm = 24.0f;
    cam.clip_start = 0.1f;
    cam.clip_end = 1000.0f;
    cam.width = 1920;
    cam.height = 1080;
    cam.pixel_aspect_x = cam.pixel_aspect_y = 1.0f;
    vsgl_scene_desc d;
    memset(&d, 0, sizeof d);
    d.vertex_count = (uint32_t)nv;
    d.positions = pos;
    d.triangle_count = (uint32_t)t;
    d.indices = ix;
    d.corner_normals = cn;
    d.material_count = 1;
    d.materials = &mat;
    d.camera = &cam;

    vsgl_context *ctx = NULL;
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.thread_count = threads;
    vsgl_context_create(&cd, &ctx);
    double tb[50], tg[50], cb[50], cg[50];
    size_t hits = 0, count = 0;
    for (int r = 0; r < runs; ++r) {
        vsgl_scene *s = NULL;
        double t0 = bench_now(CLOCK_MONOTONIC), c0 = bench_now(CLOCK_PROCESS_CPUTIME_ID);
        vsgl_result res = vsgl_scene_create(ctx, &d, &s);
        double t1 = bench_now(CLOCK_MONOTONIC), c1 = bench_now(CLOCK_PROCESS_CPUTIME_ID);
        if (res != VSGL_OK) {
            fprintf(stderr, "scene: %s\n", vsgl_context_last_error(ctx));
            return 1;
        }
        vsgl_gbuffer g;
        res = vsgl__gbuffer_build(ctx, s, aa, 0, &g);
        double t2 = bench_now(CLOCK_MONOTONIC), c2 = bench_now(CLOCK_PROCESS_CPUTIME_ID);
        cb[r] = c1 - c0;
        cg[r] = c2 - c1;
        if (res != VSGL_OK) {
            fprintf(stderr, "gbuffer: %s\n", vsgl_context_last_error(ctx));
            return 1;
        }
        tb[r] = t1 - t0;
        tg[r] = t2 - t1;
        hits = 0;
        count = g.count;
        for (size_t e = 0; e < g.count; ++e)
            hits += g.material[e] != VSGL__GBUFFER_MISS;
        vsgl__gbuffer_free(&g);
        vsgl_scene_destroy(s);
    }
    double mb = bench_median(tb, runs), mg = bench_median(tg, runs), mcb = bench_median(cb, runs), mcg = bench_median(cg, runs);
    printf("threads %u, triangles %zu, vertices %zu\n", vsgl_context_thread_count(ctx), t, nv);
    printf("scene build (validate + copy + BVH): %.3f s (median of %d), CPU time %.3f s\n", mb, runs, mcb);
    printf("gbuffer %ux%u aa=%u: %zu rays, %.1f%% hit, %.3f s (median of %d), %.2f Mrays/s; CPU time %.3f s (%.2f Mrays per CPU-second)\n",
           cam.width, cam.height, aa, count, 100.0 * (double)hits / (double)count, mg, runs, (double)count / mg * 1e-6, mcg,
           (double)count / mcg * 1e-6);
    vsgl_context_destroy(ctx);
    free(pos);
    free(ix);
    free(cn);
    return 0;
}
