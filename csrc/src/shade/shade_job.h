/* Internal: the state shared by the shading paths of one vsgl__shade call
 * (shade.c: the full-resolution paths and the per-sample helpers; sparse.c,
 * sparse_replay.c, sparse_plan.c: shading one pixel in S x S and
 * interpolating between them). */
#ifndef VSGL_SHADE_SHADE_JOB_H
#define VSGL_SHADE_SHADE_JOB_H

#include "shade/shade.h"
#include "shade/kernel.h"
#include "shade/ray_targets.h"
#include "shade/near_field.h"
#include "scene/material.h"

/* A kernel lane's receiver fields (26 floats, shade.c: lane_get/lane_put)
 * and what its visibility rays need beside them, the lift and the pick key
 * (a replay has no G-buffer sample to read them from: without the lift its
 * rays in a smooth-shaded scene started from uninitialised memory). */
typedef struct vsgl__plan_lane {
    float v[30];
    float lift[3];
    uint32_t key;
    uint32_t part;     /* the receiver's convex part key (scene_internal.h) */
} vsgl__plan_lane;

/* A shading plan (shade_stride > 1): what shading a G-buffer needs that no
 * light changes, recorded by one render and replayed by the next ones
 * through a vsgl_render_cache while the G-buffer stands still (a light
 * edit in the live viewport): every anchor's kernel lane, every sample's
 * interpolation weights and colour factors, every pixel's colours and
 * coverage. The interpolation test (which samples are shaded themselves
 * because their anchors' light bends) reads the light and runs in every
 * render; such samples take the lanes the record made, or make them from
 * the G-buffer. A replay
 * does the same arithmetic in the same order as a render without a plan:
 * bit-identical planes. */
struct vsgl_shade_plan {
    uint32_t stride, glossy_mode, width, height, aw, ah;
    size_t spp, count;
    size_t *anchor_sample;          /* aw x ah, as shade_job */
    vsgl__plan_lane *anchor_lane;   /* aw x ah: the lane of each shaded anchor */
    float *w4;                      /* 4 per sample: the weights of the anchors around it (0: not used) */
    int32_t *direct;                /* per sample: -2 miss, -3 shaded itself (no anchor shares its surface),
                                       -1 interpolated where the interpolation test passes (sparse.c) */
    float *cd;                      /* 4 per sample: diffuse colour x weight (RGB), the sample's weight */
    float *colour;                  /* 7 per pixel: DiffCol, GlossCol, coverage */
    unsigned char *row_ok;          /* per row, and for the anchors (at height): recorded */
    int32_t *dlane_of;              /* per sample: its lane in dlanes, or -1 (it was not shaded itself) */
    vsgl__plan_lane *dlanes;        /* the lanes of the samples the record shaded themselves */
    size_t ndlanes, dlanes_cap;
    /* what a replay reads instead of recomputing it (sparse_replay.c): */
    uint32_t *cell_x, *cell_y;      /* per (column, slot) and (row, slot): the anchor cell of a sample */
    float *cell_tx, *cell_ty;       /* its position in that cell, as sample_cell computes it */
    unsigned char *d2_ok;           /* per anchor: bit 0 (x), 1 (y): a second difference through its two
                                       neighbours on its surface is taken; bit 2 (x), 3 (y): it is beside a
                                       junction (sparse.h), and bit 4 (x), 5 (y): its neighbour on its
                                       surface is the next anchor, not the one before */
    float *geo;                     /* per anchor: 8 floats: its sample's normal, position, material (bits) */
    /* a replay's working memory, kept between renders (no page faults per render) */
    float *pack;                    /* per anchor: 12 floats: light (6), its sum per lobe (2), d2 (4) */
    float *interp;                  /* 6 per sample of a batch */
    float *blend;                   /* per sample of a batch shaded itself: its t (sparse.h) */
    const float *colours_in;        /* the planes (their diffuse_color) that hold this plan's DiffCol,
                                       GlossCol and coverage of every pixel since its last record or
                                       replay, or NULL; any other render clears it (shade.c) */
    int colours_kept;               /* this replay: they are in j->planes already, not rewritten */
    uint32_t *direct_of, *marks;    /* per sample of a batch */
    size_t scratch_ns;              /* the samples they hold */
};

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
    vsgl_shade_counts *counts; /* pairs whose VSGL was faint at every receiver of their block (k_faint),
                                  and the dominant rays' pairs and rays: summed atomically by every thread */
    const vsgl_kernel_light *klights; /* the VSGLs, kernel layout, in kernel order */
    const size_t *korder;             /* per kernel light: its index in set->items */
    const float *lobe_int;            /* per VSGL of the set: vsgl__vsgl_lobe_integral (fit/vsgl_set.h) */
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
    size_t *alist;           /* the anchors with a hit sample, in raster order */
    uint64_t *anchor_pairs;  /* per chunk of alist */
    float contrast_floor[2]; /* diffuse, glossy: the interpolation test's floor, a fraction of the frame's mean (sparse.c) */
    vsgl_shade_plan *plan;   /* NULL, or the plan being recorded (replay 0) or replayed (replay 1) */
    int replay;
    const vsgl_brdf_params *params; /* NULL, or per material (no sample has inputs of its own) */
    const vsgl_near_index *near;    /* the lattice clusters' near fields (near_field.h) */
    const unsigned char *ray_twin;  /* NULL, or per kernel light: 1 if its visibility rays are those of the
                                       light before it (a glossy cluster's core and tail: the same target
                                       and skip test), which block_visibility then does not trace again */
    const vsgl_ray_targets *targets; /* visibility rays: each VSGL's points (ray_targets.h); NULL without rays */
    unsigned tilt_dirs;   /* bit d: some kernel light takes the horizon tilt against axis plane d (kernel.h
                             VSGL__TILT_DIRS); only those rows of a block's tables are filled */
    const float *normal_cos; /* NULL, or per material (2 floats): the cosine above which two normals
                                count as one surface for sparse interpolation, and 1 / (1 - it)
                                (sparse.h sparse_normal_cos) */
} shade_job;

/* Receiver lobe of one sample, set up once and used for every VSGL. */
typedef struct receiver {
    v3 x, n, o;
    v3 lift;             /* visibility rays start at x + lift (gbuffer.h lift) */
    uint32_t key;        /* picks its visibility rays' points (ray_targets.h): a hash of its G-buffer sample */
    uint32_t part;       /* its convex part key (scene_internal.h) */
    vsgl_brdf_params bp;
    float alpha;
    int glossy;
    float ms[3];         /* multiple-scattering compensation towards o (1 unless 4.x+ Multiscatter GGX) */
    float fres[3];       /* the half-vector model's Fresnel ratio (material.h vsgl__fresnel_ratio) */
    vsgl_asg asg;        /* warped NDF (ASG mode) */
    vsgl_sg sg;          /* warped NDF (SG mode) */
    vsgl_smooth_lane sm; /* its smooth-factor ratio's constants (kernel.h vsgl__shadow_lane), glossy, reference path only */
    float fh;            /* the Fresnel shape at its lobe's axis (vsgl__fresnel_shape_at), glossy ASG modes only */
} receiver;

uint64_t vsgl__shade_list(const shade_job *j, const size_t *list, size_t n, const float *centroid, float *light,
                          vsgl__plan_lane *lanes);
void vsgl__sample_lane(const shade_job *j, size_t i, vsgl__plan_lane *lane);
uint64_t vsgl__shade_lanes(const shade_job *j, const vsgl__plan_lane *const *lanes, size_t n, float *light);
/* cd: NULL, or 4 floats per sample of the pixel that receive its colour factors (a plan's record) */
void vsgl__write_pixel(const shade_job *j, size_t px, const float *const *Ls, float *cd);
#if defined(__SSE2__)
/* vsgl__write_pixel of pixels px..px+3 at once, bit for bit, where the
 * G-buffer has one sample per pixel and j->params is set (pixel4.c); cd:
 * NULL or 16 floats (4 per pixel, a miss's left as they are). */
void vsgl__write_pixels4(const shade_job *j, size_t px, const float *const Ls[4], float *cd);
#endif

/* Shading plans (sparse_plan.c): a new empty plan to record (NULL if memory is
 * short), whether one fits this G-buffer and settings, whether a record
 * filled every row. */
vsgl_shade_plan *vsgl__shade_plan_new(const vsgl_gbuffer *g, const vsgl_render_settings *s, uint32_t aw,
                                      uint32_t ah);
int vsgl__shade_plan_matches(const vsgl_shade_plan *p, const vsgl_gbuffer *g, const vsgl_render_settings *s,
                             uint32_t aw, uint32_t ah);
int vsgl__shade_plan_complete(const vsgl_shade_plan *p);

/* Shade with shade_stride > 1 (sparse.c): the anchors first, then rows of
 * pixels [b, e) of the current batch, as vsgl__parallel_for's callback. */
vsgl_result vsgl__shade_anchors(vsgl_context *ctx, shade_job *j);
/* j->normal_cos of the count materials: out[2 k], out[2 k + 1] (sparse.h sparse_normal_cos). */
void vsgl__sparse_normal_cos(const vsgl_material *materials, uint32_t count, float *out);
/* Rows [row, end) with shade_stride > 1 (j->base = row * width, j->pairs
 * the batch's per-row pair counts): interpolate, shade what cannot be
 * interpolated in full kernel blocks, resolve the pixels. */
vsgl_result vsgl__shade_sparse_batch(vsgl_context *ctx, shade_job *j, size_t row, size_t end);

#endif
