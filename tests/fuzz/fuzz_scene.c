/* libFuzzer target: scene validation and the render on whatever the bundle
 * reader accepts (issue 10: fuzz the other parsers).
 *
 * Properties checked on every input (abort() = a finding):
 * - no crash, leak, out-of-bounds access or UB (ASan + UBSan);
 * - vsgl_scene_create either fails with a message and *out NULL, or gives a
 *   scene whose kept + dropped triangles are the input's;
 * - vsgl_render_estimate either fails with a message or gives a total that
 *   is the sum of its parts and fits the limit;
 * - on small renders (<= 64 x 64 pixels, aa <= 2, RSM <= 64, <= 64 VSGLs per
 *   light, within a 256 MiB limit) the render itself
 *   succeeds or fails with a message, and every plane it writes is finite
 *   and non-negative.
 * The CRC check of the bundle is skipped in this build so mutations reach
 * the scene checks. Run: make fuzz (FUZZ_SECONDS each). */
#include "vsgl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

static void need_message(vsgl_context *ctx)
{
    if (!*vsgl_context_last_error(ctx))
        abort();
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.size = sizeof cd;
    cd.thread_count = 1;
    cd.max_memory = 256u << 20;
    vsgl_context *ctx = NULL;
    if (vsgl_context_create(&cd, &ctx) != VSGL_OK)
        return 0;
    vsgl_bundle *b = NULL;
    if (vsgl_bundle_read_memory(ctx, data, size, &b) != VSGL_OK) {
        vsgl_context_destroy(ctx);
        return 0;
    }
    const vsgl_scene_desc *d = vsgl_bundle_scene(b);
    vsgl_scene *scene = (vsgl_scene *)&ctx; /* must be overwritten */
    vsgl_result r = vsgl_scene_create(ctx, d, &scene);
    if (r != VSGL_OK) {
        if (scene != NULL)
            abort();
        need_message(ctx);
        goto done;
    }
    vsgl_scene_info info = {.size = sizeof info};
    if (vsgl_scene_get_info(scene, &info) != VSGL_OK || info.triangle_count + info.dropped_triangles != d->triangle_count)
        abort();
    vsgl_render_settings s = *vsgl_bundle_settings(b);
    vsgl_memory_estimate e;
    r = vsgl_render_estimate(ctx, scene, &s, 22, &e);
    if (r != VSGL_OK) {
        need_message(ctx);
    } else {
        if (e.total != e.output + e.gbuffer + e.planes + e.rsm + e.fit + e.shade || e.total > e.limit)
            abort();
        const vsgl_camera *cam = d->camera;
        size_t px = (size_t)cam->width * cam->height;
        if (px <= 64 * 64 && s.vsgl_count <= 64 && s.rsm_resolution <= 64 && s.aa_samples <= 2) {
            float *rgb = calloc(px * 7 * 3 + px, sizeof(float));
            if (!rgb)
                abort();
            vsgl_render_output o;
            memset(&o, 0, sizeof o);
            o.width = cam->width;
            o.height = cam->height;
            float **planes[7] = {&o.diffuse_light, &o.glossy_light, &o.diffuse_color, &o.glossy_color,
                                 &o.diffuse, &o.glossy, &o.combined};
            for (int i = 0; i < 7; ++i)
                *planes[i] = rgb + (size_t)i * px * 3;
            o.alpha = rgb + px * 21;
            r = vsgl_render(ctx, scene, &s, &o, NULL);
            if (r != VSGL_OK)
                need_message(ctx);
            else
                for (size_t i = 0; i < px * 22; ++i)
                    if (!isfinite(rgb[i]) || rgb[i] < 0.0f)
                        abort();
            free(rgb);
        }
    }
    vsgl_scene_destroy(scene);
done:
    vsgl_bundle_destroy(b);
    vsgl_context_destroy(ctx);
    return 0;
}
