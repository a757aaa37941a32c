/* Live edit driver: the library alone, as the live viewport calls it.
 *
 *   cc -O2 -Icsrc/include tools/live_edit.c -Lbuild -lvsgl -Wl,-rpath,build -o build/live_edit
 *   python3 tools/bench_live.py --quality LIVE --save-bundle room.vsglb
 *   build/live_edit room.vsglb [--edits N] [--threads T] [--camera] [--settings K] [--quiet]
 *
 * Renders the bundle's scene with its settings through a vsgl_render_cache,
 * then moves its first light (or with --camera its camera) by 1 cm along x
 * N times (default 9), rendering each edit. Prints per edit the CPU time of
 * the process (all threads) and the wall time of vsgl_render_cached, and a
 * hash (FNV-1a over the 64-bit words of all eight planes; --no-hash: none,
 * and only Combined is asked for, as the live viewport does) of every frame: two
 * builds that print the same hashes rendered the same pixels bit for bit.
 * Ends with the medians. --settings K replaces the bundle's knobs:
 * 0 as saved, 1 stride 2 + 2x2 AA + 8x8 edge rays, 2 stride 3 + 2x2 AA,
 * 3 stride 2 + 8x8 edge rays, 4 stride 1 (every pixel shaded).
 */
#include "vsgl.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_time.h"

/* FNV-1a over 64-bit words (n a multiple of 8) */
static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i + 8 <= n; i += 8) {
        uint64_t w;
        memcpy(&w, b + i, 8);
        h = (h ^ w) * 1099511628211ull;
    }
    return h;
}

int main(int argc, char **argv)
{
    const char *path = NULL;
    int edits = 9, camera = 0, knobs = 0, quiet = 0, hash = 1;
    uint32_t threads = 0;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--edits") && i + 1 < argc)
            edits = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--settings") && i + 1 < argc)
            knobs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--camera"))
            camera = 1;
        else if (!strcmp(argv[i], "--no-hash"))
            hash = 0;
        else if (!strcmp(argv[i], "--quiet"))
            quiet = 1;
        else
            path = argv[i];
    }
    if (!path || edits < 1 || edits > 1000) {
        fprintf(stderr, "usage: live_edit BUNDLE [--edits N] [--threads T] [--camera] [--settings K] [--quiet] [--no-hash]\n");
        return 2;
    }
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.size = sizeof cd;
    cd.thread_count = threads;
    vsgl_context *ctx = NULL;
    vsgl_bundle *b = NULL;
    vsgl_scene *scene = NULL;
    vsgl_render_cache *cache = NULL;
    if (vsgl_context_create(&cd, &ctx) != VSGL_OK || vsgl_bundle_read(ctx, path, &b) != VSGL_OK) {
        fprintf(stderr, "cannot read %s: %s\n", path, ctx ? vsgl_context_last_error(ctx) : "no context");
        return 1;
    }
    const vsgl_scene_desc *desc = vsgl_bundle_scene(b);
    vsgl_render_settings s = *vsgl_bundle_settings(b);
    if (knobs == 1) {
        s.shade_stride = 2, s.aa_samples = 2, s.edge_samples = 8;
    } else if (knobs == 2) {
        s.shade_stride = 3, s.aa_samples = 2, s.edge_samples = 0;
    } else if (knobs == 3) {
        s.shade_stride = 2, s.aa_samples = 1, s.edge_samples = 8;
    } else if (knobs == 4) {
        s.shade_stride = 1;
    }
    if (vsgl_scene_create(ctx, desc, &scene) != VSGL_OK || vsgl_render_cache_create(ctx, &cache) != VSGL_OK) {
        fprintf(stderr, "scene: %s\n", vsgl_context_last_error(ctx));
        return 1;
    }
    vsgl_camera cam = *desc->camera;
    uint32_t nl = desc->light_count;
    vsgl_light *lights = malloc((nl ? nl : 1) * sizeof *lights);
    memcpy(lights, desc->lights, nl * sizeof *lights);
    size_t px = (size_t)cam.width * cam.height;
    float *planes = malloc(px * 22 * sizeof(float));
    vsgl_render_output out;
    memset(&out, 0, sizeof out);
    out.size = sizeof out;
    out.width = cam.width;
    out.height = cam.height;
    float **rgb[7] = {&out.diffuse_light, &out.glossy_light, &out.diffuse_color, &out.glossy_color,
                      &out.diffuse, &out.glossy, &out.combined};
    for (int k = 0; k < 7; ++k) /* without a hash only Combined, as the live viewport asks */
        *rgb[k] = hash || k == 6 ? planes + (size_t)k * px * 3 : NULL;
    out.alpha = hash ? planes + 21 * px : NULL;
    double *cpu = malloc((size_t)edits * sizeof *cpu), *wall = malloc((size_t)edits * sizeof *wall);
    uint64_t all = 1469598103934665603ull;
    for (int e = -1; e < edits; ++e) {
        if (e >= 0) {
            if (camera)
                cam.world_from_camera[3] += 0.01f;
            else if (nl)
                lights[0].world_from_light[3] += 0.01f;
            if (vsgl_scene_set_view(ctx, scene, &cam, lights, nl) != VSGL_OK) {
                fprintf(stderr, "set_view: %s\n", vsgl_context_last_error(ctx));
                return 1;
            }
        }
        vsgl_render_stats st;
        memset(&st, 0, sizeof st);
        st.size = sizeof st;
        double c0 = bench_now(CLOCK_PROCESS_CPUTIME_ID), w0 = bench_now(CLOCK_MONOTONIC);
        if (vsgl_render_cached(ctx, scene, &s, cache, &out, &st) != VSGL_OK) {
            fprintf(stderr, "render: %s\n", vsgl_context_last_error(ctx));
            return 1;
        }
        double c1 = bench_now(CLOCK_PROCESS_CPUTIME_ID), w1 = bench_now(CLOCK_MONOTONIC);
        uint64_t h = hash ? fnv(1469598103934665603ull, planes, px * 22 * sizeof(float)) : 0;
        all = fnv(all, &h, sizeof h);
        if (!quiet)
            printf("edit %2d: cpu %.4f wall %.4f (gbuffer %.4f rsm %.4f fit %.4f shade %.4f) hash %016llx\n", e,
                   c1 - c0, w1 - w0, st.seconds_gbuffer, st.seconds_rsm, st.seconds_fit, st.seconds_shade,
                   (unsigned long long)h);
        if (e >= 0) {
            cpu[e] = c1 - c0;
            wall[e] = w1 - w0;
        }
    }
    printf("%s edit, %ux%u, %d edits, threads %u: median cpu %.4f s, wall %.4f s; frames hash %016llx\n",
           camera ? "camera" : "light", cam.width, cam.height, edits, vsgl_context_thread_count(ctx),
           bench_median(cpu, edits), bench_median(wall, edits), (unsigned long long)all);
    free(cpu);
    free(wall);
    free(planes);
    free(lights);
    vsgl_render_cache_destroy(cache);
    vsgl_scene_destroy(scene);
    vsgl_bundle_destroy(b);
    vsgl_context_destroy(ctx);
    return 0;
}
