/* Internal: the state shared by the shading paths of one vsgl__shade call
 * (shade.c: the full-resolution paths and the per-sample helpers; sparse.c:
 * shading one pixel in S x S and interpolating between them). */
#ifndef VSGL_SHADE_SHADE_JOB_H
#define VSGL_SHADE_SHADE_JOB_H

#include "shade/shade.h"
#include "shade/kernel.h"
#include "scene/material.h"

typedef struct shade_job {
    const vsgl_scene *scene;
    const vsgl_gbuffer *g;
    const vsgl_vsgl_set *set;
    const vsgl_render_settings *s;
    const vsgl_pixel_planes *planes;
    const vsgl_material *materials;
    float eps;            /* ray offset, metres */
    size_t base;          /* first pixel of the current batch */
    uint64_t *pairs;      /* per chunk of the current batch */
    const vsgl_kernel_light *klights; /* the VSGLs, kernel layout */
    int path;             /* VSGL_SHADE_* */
    int leak;             /* apply the emitter-hemisphere correction */
    int merge;            /* share light between samples of one surface in a pixel */
    float plane_tol;      /* step along the normal that separates surfaces, metres */
    /* shade_stride > 1 (sparse.c): the anchor lattice, aw x ah */
    uint32_t stride, aw, ah;
    size_t *anchor_sample;   /* per anchor: its shaded sample, SIZE_MAX if its pixel missed */
    float *anchor_light;     /* per anchor: 6 floats */
    float *anchor_d2;        /* per anchor: |second difference| of its light (diffuse x, y, glossy x, y)
                                through it and its two neighbours on its surface, -1 where there is none */
    uint64_t *anchor_pairs;  /* per anchor row */
    float contrast_floor[2]; /* diffuse, glossy: the interpolation test's floor, a fraction of the frame's mean (sparse.c) */
} shade_job;

/* Receiver lobe of one sample, set up once and used for every VSGL. */
typedef struct receiver {
    v3 x, n, o;
    vsgl_brdf_params bp;
    float alpha;
    int glossy;
    float ms[3];         /* multiple-scattering compensation towards o (1 unless 4.x+ Multiscatter GGX) */
    vsgl_asg asg;        /* warped NDF (ASG mode) */
    vsgl_sg sg;          /* warped NDF (SG mode) */
} receiver;

uint64_t vsgl__shade_list(const shade_job *j, const size_t *list, size_t n, const float *centroid, float *light);
void vsgl__write_pixel(const shade_job *j, size_t px, const float *const *Ls);

/* Shade with shade_stride > 1 (sparse.c): the anchors first, then rows of
 * pixels [b, e) of the current batch, as vsgl__parallel_for's callback. */
vsgl_result vsgl__shade_anchors(vsgl_context *ctx, shade_job *j);
int32_t vsgl__shade_chunk_sparse(void *user, size_t chunk, size_t b, size_t e);

#endif
