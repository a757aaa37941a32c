/* libFuzzer target: the scene-bundle reader on arbitrary bytes.
 *
 * Properties checked on every input (abort() = a finding):
 * - no crash, leak, out-of-bounds access or UB (ASan + UBSan);
 * - a failed read leaves *out NULL and a non-empty message;
 * - a successful read gives a view whose arrays are fully readable, and
 *   writing that view and reading it back gives the same scene.
 * Run: make fuzz  (FUZZ_SECONDS=60 by default). */
#include "vsgl.h"

#include <stdlib.h>
#include <string.h>

static int same(const void *a, const void *b, size_t n)
{
    if (!a || !b)
        return a == b;
    return memcmp(a, b, n) == 0;
}

static void check_same(const vsgl_scene_desc *x, const vsgl_scene_desc *y)
{
    if (x->vertex_count != y->vertex_count || x->triangle_count != y->triangle_count ||
        x->material_count != y->material_count || x->light_count != y->light_count)
        abort();
    size_t t = x->triangle_count;
    if (!same(x->positions, y->positions, 12u * x->vertex_count) || !same(x->indices, y->indices, 12u * t) ||
        !same(x->corner_normals, y->corner_normals, 36u * t) || !same(x->corner_uvs, y->corner_uvs, 24u * t) ||
        !same(x->corner_tangents, y->corner_tangents, 48u * t) ||
        !same(x->material_indices, y->material_indices, 4u * t) ||
        !same(x->materials, y->materials, sizeof(vsgl_material) * x->material_count) ||
        !same(x->lights, y->lights, sizeof(vsgl_light) * x->light_count) ||
        !same(x->camera, y->camera, sizeof(vsgl_camera)))
        abort();
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    vsgl_context *ctx = NULL;
    if (vsgl_context_create(NULL, &ctx) != VSGL_OK)
        return 0;
    vsgl_bundle *b = (vsgl_bundle *)&ctx; /* must be overwritten */
    vsgl_result r = vsgl_bundle_read_memory(ctx, data, size, &b);
    if (r != VSGL_OK) {
        if (b != NULL || !*vsgl_context_last_error(ctx))
            abort();
        vsgl_context_destroy(ctx);
        return 0;
    }
    const vsgl_scene_desc *d = vsgl_bundle_scene(b);
    vsgl_bundle_info info = {.size = sizeof info};
    if (!d || !d->camera || vsgl_bundle_get_info(b, &info) != VSGL_OK || !info.output_path)
        abort();
    /* Round trip through the writer. */
    vsgl_bundle_options opt;
    memset(&opt, 0, sizeof opt);
    opt.size = sizeof opt;
    opt.output_path = *info.output_path ? info.output_path : NULL;
    opt.has_frame = info.has_frame;
    opt.frame = info.frame;
    const vsgl_render_settings *settings = info.has_settings ? vsgl_bundle_settings(b) : NULL;
    size_t n = 0;
    if (vsgl_bundle_write_memory(ctx, d, settings, &opt, NULL, 0, &n) != VSGL_OK)
        abort();
    unsigned char *buf = malloc(n);
    if (!buf || vsgl_bundle_write_memory(ctx, d, settings, &opt, buf, n, &n) != VSGL_OK)
        abort();
    vsgl_bundle *b2 = NULL;
    if (vsgl_bundle_read_memory(ctx, buf, n, &b2) != VSGL_OK)
        abort();
    check_same(vsgl_bundle_scene(b2), d);
    if (memcmp(vsgl_bundle_settings(b2), vsgl_bundle_settings(b), sizeof(vsgl_render_settings)) != 0)
        abort();
    vsgl_bundle_destroy(b2);
    free(buf);
    vsgl_bundle_destroy(b);
    vsgl_context_destroy(ctx);
    return 0;
}
