/* Seed corpus for fuzz_bundle: a few valid bundles written by the library.
 * Usage: make_corpus DIR */
#include "vsgl.h"

#include <stdio.h>
#include <string.h>

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: make_corpus DIR\n");
        return 2;
    }
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    float pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0.5f};
    uint32_t idx[] = {0, 1, 2, 1, 3, 2};
    float nrm[18], uv[12], tan[24];
    for (int i = 0; i < 18; ++i) nrm[i] = (i % 3 == 2) ? 1.0f : 0.0f;
    for (int i = 0; i < 12; ++i) uv[i] = (float)i / 12.0f;
    for (int i = 0; i < 24; ++i) tan[i] = (i % 4 == 0 || i % 4 == 3) ? 1.0f : 0.0f;
    uint32_t midx[] = {0, 1};
    vsgl_material mat[2];
    memset(mat, 0, sizeof mat);
    mat[0].base_color[0] = 0.8f; mat[0].roughness = 0.5f; mat[0].specular_f0 = 0.04f;
    mat[1].base_color[1] = 0.5f; mat[1].roughness = 0.1f; mat[1].metallic = 1;
    vsgl_light light[2];
    memset(light, 0, sizeof light);
    for (int l = 0; l < 2; ++l) {
        light[l].type = l ? VSGL_LIGHT_SPOT : VSGL_LIGHT_POINT;
        light[l].color[0] = light[l].color[1] = light[l].color[2] = 1;
        light[l].power = 100;
        light[l].world_from_light[0] = light[l].world_from_light[5] = light[l].world_from_light[10] = 1;
        light[l].world_from_light[11] = 3;
        light[l].spot_size = 0.8f;
        light[l].spot_blend = 0.2f;
    }
    vsgl_camera cam;
    memset(&cam, 0, sizeof cam);
    cam.world_from_camera[0] = cam.world_from_camera[5] = cam.world_from_camera[10] = 1;
    cam.world_from_camera[11] = 5;
    cam.lens_mm = 50; cam.sensor_width_mm = 36; cam.sensor_height_mm = 24;
    cam.clip_start = 0.1f; cam.clip_end = 100; cam.width = 64; cam.height = 48;
    cam.pixel_aspect_x = cam.pixel_aspect_y = 1;
    vsgl_scene_desc full = {sizeof full, 4, pos, 2, idx, nrm, uv, tan, midx, 2, mat, 2, light, &cam};
    vsgl_scene_desc bare = {sizeof bare, 4, pos, 2, idx, NULL, NULL, NULL, NULL, 1, mat, 1, light, &cam};
    vsgl_scene_desc empty = {0, 0, NULL, 0, NULL, NULL, NULL, NULL, NULL, 0, NULL, 0, NULL, &cam};
    vsgl_render_settings s;
    memset(&s, 0, sizeof s);
    s.aa_samples = 2; s.rsm_resolution = 64; s.fit_mode = VSGL_FIT_FIS; s.vsgl_count = 16; s.seed = 7;
    vsgl_bundle_options opt = {sizeof opt, "out/frame.exr", 1, 17};
    struct { const char *name; const vsgl_scene_desc *d; const vsgl_render_settings *s; const vsgl_bundle_options *o; } items[] = {
        {"full.vsglb", &full, &s, &opt}, {"bare.vsglb", &bare, NULL, NULL}, {"empty.vsglb", &empty, &s, NULL}};
    for (size_t i = 0; i < sizeof items / sizeof items[0]; ++i) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", argv[1], items[i].name);
        if (vsgl_bundle_write(ctx, path, items[i].d, items[i].s, items[i].o) != VSGL_OK) {
            fprintf(stderr, "make_corpus: %s\n", vsgl_context_last_error(ctx));
            return 1;
        }
    }
    vsgl_context_destroy(ctx);
    return 0;
}
