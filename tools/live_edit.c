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
 * --dump FILE writes the last frame's 22 planes as raw float32 (with
 * --no-hash only Combined, planes 18-20, is filled). Ends with the medians. --settings K replaces the bundle's knobs:
 * 0 as saved, 1 stride 2 + 2x2 AA + 8x8 edge rays, 2 stride 3 + 2x2 AA,
 * 3 stride 2 + 8x8 edge rays, 4 stride 1 (every pixel shaded).
 *
 * Navigation (the live preview while the view moves, docs/performance.md):
 * --coarse N renders each camera edit at 1/N of the bundle's size in each
 * direction (the image the add-on draws enlarged while the view moves),
 * --coarse-stride S at the full size with shade_stride S; either way every
 * --refine K-th edit (default 1) is followed by the full render of that
 * view through the same cache (the image after the view rests), timed
 * apart. The last refine is compared with an uncached render of the same
 * view bit for bit (Combined and, with hashes, every plane): "refine ==
 * plain render: yes" or the driver fails.
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
    const char *path = NULL, *dump = NULL;
    int edits = 9, camera = 0, knobs = 0, quiet = 0, hash = 1;
    uint32_t threads = 0, coarse = 1, coarse_stride = 0, stride = 0;
    int refine_every = 1;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--edits") && i + 1 < argc)
            edits = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--settings") && i + 1 < argc)
            knobs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--dump") && i + 1 < argc)
            dump = argv[++i];
        else if (!strcmp(argv[i], "--stride") && i + 1 < argc)
            stride = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--coarse") && i + 1 < argc)
            coarse = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--coarse-stride") && i + 1 < argc)
            coarse_stride = (uint32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--refine") && i + 1 < argc)
            refine_every = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--camera"))
            camera = 1;
        else if (!strcmp(argv[i], "--no-hash"))
            hash = 0;
        else if (!strcmp(argv[i], "--quiet"))
            quiet = 1;
        else
            path = argv[i];
    }
    const int navigating = coarse > 1 || coarse_stride > 0;
    if (!path || edits < 1 || edits > 1000 || coarse < 1 || coarse > 16 || coarse_stride > 8 || refine_every < 1) {
        fprintf(stderr, "usage: live_edit BUNDLE [--edits N] [--threads T] [--camera] [--settings K] [--quiet] "
                        "[--no-hash] [--coarse N | --coarse-stride S] [--refine K] [--stride S] [--dump FILE]\n");
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
    if (stride)
        s.shade_stride = stride;
    if (vsgl_scene_create(ctx, desc, &scene) != VSGL_OK || vsgl_render_cache_create(ctx, &cache) != VSGL_OK) {
        fprintf(stderr, "scene: %s\n", vsgl_context_last_error(ctx));
        return 1;
    }
    vsgl_camera cam = *desc->camera;
    uint32_t nl = desc->light_count;
    vsgl_light *lights = malloc((nl ? nl : 1) * sizeof *lights);
    memcpy(lights, desc->lights, nl * sizeof *lights);
    const uint32_t W = cam.width, H = cam.height;
    size_t px = (size_t)W * H;
    float *planes = malloc(px * 22 * sizeof(float));
    float *plain = navigating ? malloc(px * 22 * sizeof(float)) : NULL;
    /* the settings of an edit while the view moves (--coarse-stride), else the bundle's */
    vsgl_render_settings moving = s;
    if (coarse_stride)
        moving.shade_stride = coarse_stride;
    double *cpu = malloc((size_t)edits * sizeof *cpu), *wall = malloc((size_t)edits * sizeof *wall);
    double *rcpu = malloc((size_t)edits * sizeof *rcpu), *rwall = malloc((size_t)edits * sizeof *rwall);
    int refines = 0;
    uint64_t all = 1469598103934665603ull;
    for (int e = -1; e < edits; ++e) {
        /* with --coarse / --coarse-stride: the edit while moving, then (every
         * --refine K-th edit) the view's full render after the rest */
        for (int step = 0; step < (navigating && e >= 0 ? 2 : 1); ++step) {
            const int coarse_step = navigating && e >= 0 && step == 0;
            if (step == 1 && (e + 1) % refine_every != 0 && e != edits - 1)
                break;
            if (e >= 0 && step == 0) {
                if (camera)
                    cam.world_from_camera[3] += 0.01f;
                else if (nl)
                    lights[0].world_from_light[3] += 0.01f;
            }
            vsgl_camera c = cam;
            if (coarse_step && coarse > 1) { /* as the add-on's live.internal_size */
                c.width = (W + coarse - 1) / coarse > 8 ? (W + coarse - 1) / coarse : 8;
                c.height = (H + coarse - 1) / coarse > 8 ? (H + coarse - 1) / coarse : 8;
            }
            if (e >= 0 && vsgl_scene_set_view(ctx, scene, &c, lights, nl) != VSGL_OK) {
                fprintf(stderr, "set_view: %s\n", vsgl_context_last_error(ctx));
                return 1;
            }
            vsgl_render_output out;
            memset(&out, 0, sizeof out);
            out.size = sizeof out;
            out.width = c.width;
            out.height = c.height;
            size_t cpx = (size_t)c.width * c.height;
            float **rgb[7] = {&out.diffuse_light, &out.glossy_light, &out.diffuse_color, &out.glossy_color,
                              &out.diffuse, &out.glossy, &out.combined};
            for (int k = 0; k < 7; ++k) /* without a hash only Combined, as the live viewport asks */
                *rgb[k] = hash || k == 6 ? planes + (size_t)k * cpx * 3 : NULL;
            out.alpha = hash ? planes + 21 * cpx : NULL;
            vsgl_render_stats st;
            memset(&st, 0, sizeof st);
            st.size = sizeof st;
            double c0 = bench_now(CLOCK_PROCESS_CPUTIME_ID), w0 = bench_now(CLOCK_MONOTONIC);
            if (vsgl_render_cached(ctx, scene, coarse_step ? &moving : &s, cache, &out, &st) != VSGL_OK) {
                fprintf(stderr, "render: %s\n", vsgl_context_last_error(ctx));
                return 1;
            }
            double c1 = bench_now(CLOCK_PROCESS_CPUTIME_ID), w1 = bench_now(CLOCK_MONOTONIC);
            uint64_t h = hash ? fnv(1469598103934665603ull, planes, cpx * 22 * sizeof(float)) : 0;
            all = fnv(all, &h, sizeof h);
            if (!quiet)
                printf("%s %2d: cpu %.4f wall %.4f (%ux%u stride %u; gbuffer %.4f rsm %.4f fit %.4f shade %.4f) "
                       "%u VSGLs, %.3g pairs; hash %016llx\n", step ? "refine" : "edit  ", e, c1 - c0, w1 - w0, c.width, c.height,
                       coarse_step ? moving.shade_stride : s.shade_stride, st.seconds_gbuffer, st.seconds_rsm,
                       st.seconds_fit, st.seconds_shade, st.vsgl_count, (double)st.shading_pairs, (unsigned long long)h);
            if (e >= 0 && step == 0) {
                cpu[e] = c1 - c0;
                wall[e] = w1 - w0;
            } else if (step == 1) {
                rcpu[refines] = c1 - c0;
                rwall[refines++] = w1 - w0;
            }
        }
    }
    if (dump) { /* the last frame's planes, raw float32 (22 x pixels) */
        FILE *f = fopen(dump, "wb");
        if (!f || fwrite(planes, sizeof(float), px * 22, f) != px * 22 || fclose(f) != 0) {
            fprintf(stderr, "cannot write %s\n", dump);
            return 1;
        }
    }
    printf("%s edit%s, %ux%u, %d edits, threads %u: median cpu %.4f s, wall %.4f s; frames hash %016llx\n",
           camera ? "camera" : "light", !navigating ? "" : coarse > 1 ? " while moving (coarse)" : " while moving",
           navigating && coarse > 1 ? (W + coarse - 1) / coarse : W,
           navigating && coarse > 1 ? (H + coarse - 1) / coarse : H, edits, vsgl_context_thread_count(ctx),
           bench_median(cpu, edits), bench_median(wall, edits), (unsigned long long)all);
    if (navigating) {
        /* the last refine against an uncached render of the same view (the scene's view is the refine's) */
        vsgl_render_output out;
        memset(&out, 0, sizeof out);
        out.size = sizeof out;
        out.width = W;
        out.height = H;
        float **rgb[7] = {&out.diffuse_light, &out.glossy_light, &out.diffuse_color, &out.glossy_color,
                          &out.diffuse, &out.glossy, &out.combined};
        for (int k = 0; k < 7; ++k)
            *rgb[k] = hash || k == 6 ? plain + (size_t)k * px * 3 : NULL;
        out.alpha = hash ? plain + 21 * px : NULL;
        if (vsgl_render(ctx, scene, &s, &out, NULL) != VSGL_OK) {
            fprintf(stderr, "render: %s\n", vsgl_context_last_error(ctx));
            return 1;
        }
        int same = hash ? memcmp(planes, plain, px * 22 * sizeof(float)) == 0
                        : memcmp(planes + 18 * px, plain + 18 * px, px * 3 * sizeof(float)) == 0;
        printf("refine (full %ux%u after the edit%s), %d refines: median cpu %.4f s, wall %.4f s; "
               "refine == plain render: %s\n", W, H, refine_every > 1 ? "s" : "", refines,
               bench_median(rcpu, refines), bench_median(rwall, refines), same ? "yes" : "NO");
        if (!same)
            return 1;
    }
    free(rcpu);
    free(rwall);
    free(plain);
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
