/* Internal: the per-light budget. A render with two or more lights gives
 * each light VSGLs and RSM texels by the light it sends, after one bounce,
 * onto what the camera sees, measured before the fit on a 16^2 probe RSM
 * and a 32-wide grid of camera rays (budget_probe.c); the totals stay the
 * settings' (vsgl_count per light, rsm_resolution^2 x faces per light).
 * One light (or one that lights anything) takes the settings as they are:
 * single-light renders are bit-identical to a render without the budget. */
#ifndef VSGL_RENDER_BUDGET_H
#define VSGL_RENDER_BUDGET_H

#include "vsgl/render.h"

#include <stdint.h>

/* Probe RSM side (texels per face; the settings' resolution if smaller). */
#define VSGL__BUDGET_PROBE 16u
/* Every contributing light keeps at least this fraction of the uniform
 * share of VSGLs (its RSM follows: at least sqrt of it per side). */
#define VSGL__BUDGET_FLOOR 0.25
/* Exponent of a light's weight in its share: 0.5, the square root (a
 * cluster model whose error falls as 1/n is best spent so; measured on the
 * four multi-light scenes at 80 x 60, balanced: FLIP 0.0725 / 0.0947 /
 * 0.0541 / 0.1208 against 0.0745 / 0.0948 / 0.0549 / 0.1220 with 1). */
#define VSGL__BUDGET_POWER 0.5
/* Caps: at most this many times the uniform VSGL share, and this many
 * times the settings' RSM side (vsgl__memory_estimate counts them). */
#define VSGL__BUDGET_VSGL_CAP 4.0
#define VSGL__BUDGET_RSM_CAP 1.5

/* Each light's RSM side from its footprint (vsgl__footprint_rsm): the part
 * of its lit texels whose light reaches what the camera sees. A texel
 * counts when it sends at least this fraction of the light's mean lit
 * texel's light onto the probe's camera receivers. */
#define VSGL__FOOTPRINT_TEXEL 0.01

/* The auto budget (budget_auto.c, VSGL_AUTO_BALANCED). Texels per VSGL on
 * a light's footprint: 128^2 / 192, the balanced lattice on an RSM of 128,
 * which was as accurate as 256 and 512 with a full footprint (relMSE and
 * FLIP of the combined pass within 1 % in five of the six quality rooms
 * at 80 x 60; the sun room with a thick wall, whose sun lights mostly the
 * outside, lost 9 %: there the footprint is small and the side stays). */
#define VSGL__AUTO_TEXELS_PER_VSGL (128.0 * 128.0 / 192.0)
/* Glossy receivers sharper than this roughness (sqrt of the GGX alpha)
 * keep the two-lobe GGX (asg2); otherwise one ASG lobe. */
#define VSGL__AUTO_SHARP_ROUGHNESS 0.5f

typedef struct vsgl_light_share {
    double weight;           /* in: the probe's light on what the camera sees; 0: contributes nothing */
    double footprint;        /* in: fraction of its lit probe texels whose light reaches what the camera sees
                                (vsgl__budget_weights; 1 when the camera sees nothing) */
    uint32_t faces;          /* in: RSM faces of the light (6: cube map, 1: otherwise) */
    double fraction;         /* out: its share, weight^POWER / sum of weight^POWER */
    double vsgls;            /* out: VSGLs, real (the lattice's spacing follows it continuously) */
    uint32_t vsgl_count;     /* out: VSGLs, integer (largest remainder: the integers sum as the reals) */
    uint32_t rsm_resolution; /* out: RSM side, texels per face */
} vsgl_light_share;

/* Share `n_vsgl` VSGLs and `rsm` texels per side per light among `count`
 * lights. Lights of weight > 0 share count_positive x n_vsgl VSGLs: a floor
 * of VSGL__BUDGET_FLOOR x n_vsgl each and the rest in proportion to
 * weight^VSGL__BUDGET_POWER (capped at VSGL__BUDGET_VSGL_CAP x n_vsgl, the
 * excess to the others); their texels, sum of faces x rsm^2, in proportion
 * to faces x VSGLs / footprint (the same texels per VSGL on every light's
 * footprint: a light whose lit texels mostly light what the camera does
 * not see gets a finer RSM; footprint outside (0, 1] counts as 1), each
 * side within [rsm/4,
 * VSGL__BUDGET_RSM_CAP x rsm]. A light of weight 0 (or not
 * finite) gets the floor and rsm / 2 (its probe saw nothing: it may still
 * light something small). With one light of weight > 0, it gets exactly
 * n_vsgl and rsm. */
void vsgl__light_budget(vsgl_light_share *lights, uint32_t count, uint32_t n_vsgl, uint32_t rsm);

/* Each light's RSM side from its footprint for the auto budget: an absolute
 * density, sqrt(texels_per_vsgl x vsgls / footprint), i.e. `texels_per_vsgl` texels per VSGL on the part of the
 * light that reaches what the camera sees, within [max(rsm / 4,
 * VSGL_RSM_RESOLUTION_MIN), hi]. Lights of footprint 0 (or weight 0) keep
 * their side. */
void vsgl__footprint_rsm(vsgl_light_share *lights, uint32_t count, double texels_per_vsgl, uint32_t rsm,
                         uint32_t hi);

/* What the probe's camera rays see (budget_probe.c). */
typedef struct vsgl_budget_view {
    uint32_t receivers;        /* camera probe rays that hit something */
    uint32_t glossy;           /* of them, on a material whose glossy lobe contributes */
    float sharpest_roughness;  /* smallest roughness (sqrt of the GGX alpha; anisotropic: of the smaller)
                                  among the glossy ones (textures read); 1 if none */
} vsgl_budget_view;

/* The camera probe alone (the auto budget's glossy choice). */
vsgl_result vsgl__budget_view(vsgl_context *ctx, const vsgl_scene *scene, vsgl_budget_view *view);

/* The auto budget (budget_auto.c): chooses glossy_mode of *s for the
 * scene (at most as set) when s->auto_target is set, and says what and
 * why in st->budget and the log, with the anti-aliasing aa_pixel_limit
 * gave (aa_asked: the aa_samples it lowered to 1, else 0). */
vsgl_result vsgl__auto_choose(vsgl_context *ctx, const vsgl_scene *scene, uint32_t aa_asked,
                              vsgl_render_settings *s, vsgl_render_stats *st);

/* Each light's weight (render/budget_probe.c): the light its probe RSM's
 * VPLs send, unshadowed, onto what a sparse grid of camera rays sees (the
 * light's reflected power if the rays see nothing), its footprint and its
 * RSM faces. *receivers: the camera rays that hit something. */
vsgl_result vsgl__budget_weights(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                                 vsgl_light_share *sh, uint32_t *receivers);

/* Upper bounds of one light's budget (the memory estimate). */
uint32_t vsgl__budget_rsm_max(uint32_t rsm);
uint32_t vsgl__budget_vsgl_max(uint32_t n_vsgl);

#endif
