/* Accuracy helpers shared by the accuracy test and tools/accuracy.c:
 * scenes with each light type, rendering into planes, and the relative
 * MSE of docs/references.md §6: mean((a - b)^2 / (b^2 + 0.01)) over pixels and
 * channels. */
#ifndef VSGL_TEST_ACCURACY_H
#define VSGL_TEST_ACCURACY_H

#include "scene_fixture.h"

#include <stdio.h>
#include <stdlib.h>

#define ACC_SCENES 3

/* Scene k: 0 spot + glossy dielectric floor, 1 point light (cube RSM) +
 * sharper floor, 2 disk area light + anisotropic metal floor. */
static inline void acc_scene(fx_scene *fx, int k, uint32_t w, uint32_t h, const char **name)
{
    fx_room(fx, w, h, 0.3f, 150.0f);
    vsgl_light *L = &fx->lights[0];
    if (k == 1) {
        *name = "point light, floor roughness 0.2";
        fx->materials[0].roughness = 0.2f;
        L->type = VSGL_LIGHT_POINT;
        fx_translation(L->world_from_light, -0.6f, 0.2f, 1.2f);
        L->radius = 0.05f;
    } else if (k == 2) {
        *name = "disk area light, anisotropic metal floor";
        fx->materials[0].metallic = 1.0f;
        fx->materials[0].roughness = 0.4f;
        fx->materials[0].anisotropy = 0.6f;
        fx->materials[0].base_color[0] = 0.9f;
        fx->materials[0].base_color[1] = 0.7f;
        fx->materials[0].base_color[2] = 0.5f;
        L->type = VSGL_LIGHT_AREA;
        L->area_shape = VSGL_AREA_DISK;
        L->size_x = L->size_y = 0.3f;
        L->spread = 3.14159265f;
        const float eye[3] = {-0.5f, 0.3f, 1.6f}, at[3] = {-1.0f, 0.3f, 0.8f};
        fx_look_at(L->world_from_light, eye, at);
    } else {
        *name = "spot light, floor roughness 0.3";
    }
}

typedef struct acc_planes {
    uint32_t w, h;
    float *diffuse, *glossy;  /* coloured contributions DiffInd*DiffCol, GlossInd*GlossCol */
} acc_planes;

static inline int acc_render(int k, uint32_t w, uint32_t h, const vsgl_render_settings *s, acc_planes *p,
                             vsgl_render_stats *st)
{
    fx_scene fx;
    const char *name;
    acc_scene(&fx, k, w, h, &name);
    vsgl_context *ctx = NULL;
    vsgl_scene *scene = NULL;
    p->w = w;
    p->h = h;
    p->diffuse = calloc((size_t)w * h * 3, sizeof(float));
    p->glossy = calloc((size_t)w * h * 3, sizeof(float));
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = w;
    o.height = h;
    o.diffuse = p->diffuse;
    o.glossy = p->glossy;
    vsgl_result r = vsgl_context_create(NULL, &ctx);
    if (r == VSGL_OK)
        r = vsgl_scene_create(ctx, fx_desc(&fx), &scene);
    if (r == VSGL_OK)
        r = vsgl_render(ctx, scene, s, &o, st);
    if (r != VSGL_OK)
        fprintf(stderr, "accuracy: scene %d: %s\n", k, vsgl_context_last_error(ctx));
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
    return r == VSGL_OK;
}

static inline void acc_free(acc_planes *p)
{
    free(p->diffuse);
    free(p->glossy);
}

static inline double acc_relmse(const float *a, const float *b, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double d = (double)a[i] - b[i];
        s += d * d / ((double)b[i] * b[i] + 0.01);
    }
    return s / (double)n;
}

#endif
