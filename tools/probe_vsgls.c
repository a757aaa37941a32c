/* Which VSGLs light one pixel: the glossy (or diffuse) light each VSGL of a
 * scene bundle's fit gives pixel (x, y), shaded one VSGL at a time through
 * the library's internals (every pixel shaded, no visibility rays, no edge
 * rays: the model's own answer). Finds what makes a pixel jump between two
 * frames of an animation (tools/probe_frames.py runs it on each frame):
 * docs/accuracy.md, "A wall on a slab boundary".
 *
 *   probe_vsgls BUNDLE X Y [glossy|diffuse] [MIN]
 *
 * Prints the pixel's total, then one line per VSGL giving at least MIN
 * (default 1e-4): index, lobe, light, mean, power, coherence, variance and
 * its lattice cell (axis, side, spacing, centre, extent, cut bits). Built
 * by tools/bench.sh beside the benchmarks. */
#include "vsgl.h"
#include "vsgl/io.h"
#include "fit/vsgl_set.h"
#include "gbuffer/gbuffer.h"
#include "render/render_internal.h"
#include "shade/shade.h"

#include "scene/scene_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static float pixel_sum(const float *plane, size_t i)
{
    return plane[3 * i] + plane[3 * i + 1] + plane[3 * i + 2];
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: probe_vsgls BUNDLE X Y [glossy|diffuse] [MIN]\n");
        return 2;
    }
    const int diffuse = argc > 4 && strcmp(argv[4], "diffuse") == 0;
    const double min = argc > 5 ? atof(argv[5]) : 1e-4;
    vsgl_context *ctx = NULL;
    vsgl_bundle *b = NULL;
    vsgl_scene *scene = NULL;
    if (vsgl_context_create(NULL, &ctx) || vsgl_bundle_read(ctx, argv[1], &b) ||
        vsgl_scene_create(ctx, vsgl_bundle_scene(b), &scene)) {
        fprintf(stderr, "probe_vsgls: %s\n", ctx ? vsgl_context_last_error(ctx) : "no context");
        return 1;
    }
    vsgl_render_settings s;
    vsgl_gbuffer g;
    vsgl_vsgl_set set = {0};
    vsgl_render_stats st;
    memset(&st, 0, sizeof st);
    memset(&g, 0, sizeof g);
    if (vsgl__settings_resolve(ctx, vsgl_bundle_settings(b), &s) != VSGL_OK) {
        fprintf(stderr, "probe_vsgls: %s\n", vsgl_context_last_error(ctx));
        return 1;
    }
    s.shade_stride = 1;
    s.visibility = VSGL_VISIBILITY_NONE;
    s.edge_samples = 0;
    if (vsgl__gbuffer_build(ctx, scene, s.aa_samples, 0, &g) || vsgl__fit_lights(ctx, scene, &s, &set, &st)) {
        fprintf(stderr, "probe_vsgls: %s\n", vsgl_context_last_error(ctx));
        return 1;
    }
    const long x = atol(argv[2]), y = atol(argv[3]);
    if (x < 0 || y < 0 || x >= (long)g.width || y >= (long)g.height) {
        fprintf(stderr, "probe_vsgls: pixel (%ld, %ld) outside the %ux%u image\n", x, y, g.width, g.height);
        return 2;
    }
    const size_t n = (size_t)g.width * g.height, i = (size_t)y * g.width + (size_t)x;
    v3 lo, hi;
    vsgl__scene_bounds(scene, &lo, &hi);
    float *buf = calloc(n * 13, sizeof(float));
    if (!buf)
        return 1;
    vsgl_pixel_planes pl = {buf, buf + 3 * n, buf + 6 * n, buf + 9 * n, buf + 12 * n};
    const float *plane = diffuse ? pl.diffuse : pl.glossy;
    uint64_t pairs;
    vsgl__shade(ctx, scene, &g, &set, &s, &pl, VSGL__SHADE_KERNEL, &pairs);
    const size_t smp = i * g.spp; /* the pixel's first sample */
    const v3 rx = v3_make(g.pos[0][smp], g.pos[1][smp], g.pos[2][smp]);
    printf("pixel (%ld, %ld) %s %.5f from %zu VSGLs; its first sample at %.3f %.3f %.3f, normal %.3f %.3f %.3f\n", x,
           y, diffuse ? "diffuse" : "glossy", pixel_sum(plane, i), set.count, rx.x, rx.y, rx.z, g.nrm[0][smp],
           g.nrm[1][smp], g.nrm[2][smp]);
    for (size_t k = 0; k < set.count; ++k) {
        vsgl_vsgl_set one = {&set.items[k], 1, 1};
        vsgl__shade(ctx, scene, &g, &one, &s, &pl, VSGL__SHADE_KERNEL, &pairs);
        const float c = pixel_sum(plane, i);
        const vsgl_vsgl *v = &set.items[k];
        if (!(c >= min))
            continue;
        printf("%5zu lobe %u light %u  %.5f  mean %.3f %.3f %.3f  power %.4g  coh %.4f  var %.4g  axis %.3f %.3f %.3f"
               "  sharpness %.4g", k, v->lobe, v->light, c, v->mean.x, v->mean.y, v->mean.z,
               v->power[0] + v->power[1] + v->power[2], v->coherence, v->variance, v->axis.x, v->axis.y, v->axis.z,
               v->sharpness);
        { /* the sample seen from the cluster: its height over the cluster's plane, the lobe's value towards it */
            const v3 d = v3_sub(rx, v->mean);
            const float len = v3_length(d), cosl = len > 0.0f ? v3_dot(d, v->axis) / len : 1.0f;
            printf("  sample: %.3f m off the plane, %.3f m away, lobe e^(l(cos-1)) %.3g", v3_dot(d, v->normal), len,
                   expf(v->sharpness * (cosl - 1.0f)));
        }
        if (v->cell_h > 0.0f) { /* the cell's lattice indices: its centre from the bounds' low corner */
            const float lo3[3] = {lo.x, lo.y, lo.z};
            long ci = lroundf((v->cell_centre[0] - lo3[(v->cell_axis + 1) % 3]) / v->cell_h);
            long cj = lroundf((v->cell_centre[1] - lo3[(v->cell_axis + 2) % 3]) / v->cell_h);
            printf("  cell axis %u side %u at %ld %ld h %.3f centre %.3f %.3f lo %.3f %.3f hi %.3f %.3f ends %u",
                   v->cell_axis, v->cell_side, ci, cj, v->cell_h, v->cell_centre[0], v->cell_centre[1],
                   v->cell_lo[0], v->cell_lo[1], v->cell_hi[0], v->cell_hi[1], v->cell_ends);
        }
        printf("\n");
    }
    free(buf);
    vsgl__vsgl_set_free(&set);
    vsgl__gbuffer_free(&g);
    vsgl_scene_destroy(scene);
    vsgl_bundle_destroy(b);
    vsgl_context_destroy(ctx);
    return 0;
}
