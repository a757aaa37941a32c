/* Internal: shading camera samples with VSGLs through SG/ASG product
 * integrals (poster Sec. 3, FIS supplement Sec. 4). */
#ifndef VSGL_SHADE_H
#define VSGL_SHADE_H

#include "fit/vsgl_set.h"
#include "gbuffer/gbuffer.h"
#include "vsgl/sg.h"
#include "vsgl/asg.h"
#include "shade/kernel.h"

/* Per-pixel accumulation planes (width*height*3 floats each, caller-owned,
 * zeroed by the callee): coloured contributions and the colours (DiffCol,
 * GlossCol), averaged over the pixel's samples, and coverage (w*h). */
typedef struct vsgl_pixel_planes {
    float *diffuse;        /* R_d * diffuse light */
    float *glossy;         /* glossy radiance (Fresnel included) */
    float *diffuse_color;
    float *glossy_color;
    float *coverage;
} vsgl_pixel_planes;

/* Incident radiance of VSGL v at receiver point x as one SG (Eq. 7):
 * L_in(w) = v->power * sg(w) (sg's log_amplitude carries 1/(2 pi var A)).
 * Returns 0 if the VSGL cannot be seen as a lobe from x (x at its centre
 * with zero spread).
 *
 * Eq. 7 multiplies the emission lobe (axis a, sharpness lv, as an incident
 * direction) with a round spread about the direction u to the mean, of
 * sharpness d^2 / var: the positions of a 3-D blob. A diffuse cluster's
 * VPLs lie on a plane (normal n_v), and two things differ there, weighted
 * by vsgl__foreshortening_weight (coherence^2 of a diffuse lobe, 0 for a
 * specular one, whose VPLs' directions follow their positions):
 *  - foreshortening: seen at cosine ce = -u.n_v, the plane's Gaussian spans
 *    ce times its round angular width across the plane's edge-on line.
 *    The emission lobe pulled the product's axis towards a, i.e. for a
 *    floor seen from the floor, below the floor's plane: a bumpy floor's
 *    slope received light from the slope facing it at the cosine of a
 *    direction under the horizon (dense_floor: 0.41 of the brute force's
 *    floor-to-floor light in the image's middle rows). The spread's
 *    sharpness along that pull is scaled (kernel.h, vsgl__plane_spread);
 *  - distance: the plane's VPLs nearer x's foot on it are nearer x, and
 *    1 / d^2 over the plane pulls the light towards the foot (-n_v): a
 *    third lobe (the same function's *kd). Without it the
 *    foreshortened model lost 1-5 % of a lit plane's light beside a
 *    junction (the round spread's pull towards a had stood in for it).
 * The product's axis and amplitude are those of the three lobes; its
 * sharpness (the lobe's width in the cosine and glossy integrals) stays
 * the round product's. Against a uniformly lit square's exact irradiance
 * (tests/c/test_lattice.c): far field within -1.5..+0.5 % (before:
 * -1.5..+0.1 %), a wall at its edge 30 cm up -2.0 % (-4.3 %), 10 cm up
 * -4.0 % (-3.2 %). */
int vsgl__vsgl_incident_sg(const vsgl_vsgl *v, v3 x, vsgl_sg *sg);
/* The same with the VSGL's vsgl__vsgl_lobe_integral given (the shade stage
 * computes it once per VSGL, shade_job.lobe_int) */
int vsgl__vsgl_incident_sg_with(const vsgl_vsgl *v, v3 x, float lobe_integral, vsgl_sg *sg);

/* The weight of v's plane spread above: coherence^2 of a diffuse lobe, 0
 * for a specular one (kernel.h vsgl__plane_spread's fore). */
float vsgl__foreshortening_weight(const vsgl_vsgl *v);

/* Shading paths: the vectorised kernel (default), the same kernel built
 * scalar (benchmark baseline), and the reference path through the public
 * operator functions (slow; exact ASG normalisation; SG glossy lobes). */
#define VSGL__SHADE_KERNEL        0
#define VSGL__SHADE_KERNEL_SCALAR 1
#define VSGL__SHADE_REFERENCE     2

/* 1 if settings s shade through the reference path whatever path is
 * asked: the kernel models ASG lobes, so glossy SG lobes take the scalar
 * path (every pixel, no stride: render/settings.c says so, render.c warns). */
static inline int vsgl__shades_by_reference(const vsgl_render_settings *s)
{
    return s->method == VSGL_METHOD_VSGL && s->glossy_mode == VSGL_GLOSSY_SG;
}

/* Emitter-hemisphere clip (the leak correction). A cluster's VPLs lie on
 * a surface and emit only in front of it, with a clamped cosine; the
 * papers' model emits an SG (lambda 2.29 for a diffuse lobe) with ~9 % of
 * its power behind the surface and a 15-25 % wrong falloff, and lets a
 * cluster light its own plane. For a cluster whose normals agree
 * (coherence k), the light reaching a receiver at x with normal n is
 * scaled by 1 - k^2 (1 - e), e = conv * behind * parallel:
 *  - behind: 0 behind or in the cluster's plane (height h = n_v.(x - mean)
 *    <= 0), 1 from h >= 0.02 sigma on (smoothstep);
 *  - parallel: 0 for a receiver facing the same way as the cluster (it
 *    cannot see that plane: a floor never lights the floor), 1 from
 *    1 - n.n_v >= 0.3 (smoothstep);
 *  - conv (diffuse lobes): the far-field ratio of the clamped cosine to
 *    the SG at the emission cosine c = h / |x - mean|,
 *    rho(c) = A(2.29)/pi c e^{2.29 (1 - c)}, blended towards 1 in the
 *    near field by w = s / (s + 4), s = |x - mean|^2 / var (the spread's
 *    sharpness), where the SG product is the better model.
 * docs/accuracy.md measures it against a planar emitter's exact irradiance. */
/* (VSGL__CLIP_* in shade/kernel.h) */

/* The clip factor of VSGL v for a receiver at x with unit normal n, in [0, 1]
 * (the kernel computes the same inline); `on` selects the clip. */
float vsgl__emitter_clip(const vsgl_vsgl *v, v3 x, v3 n, int on);

/* The share of v's light a receiver on convex part key `part` gets
 * (vsgl_vsgl.part; the kernel's vsgl__part_keep), in [0, 1]. */
float vsgl__vsgl_part_keep(const vsgl_vsgl *v, uint32_t part);

/* Where a visibility ray from receiver x (normal n, lift: gbuffer.h) to
 * `target` starts: o (x offset off its surface) plus the share of the lift
 * its direction takes (shade.c: near the horizon only). */
v3 vsgl__lifted_origin(v3 o, v3 x, v3 n, v3 lift, v3 target);
/* The point a receiver at x (unit normal n) aims its visibility ray at, for
 * its dithered point t of a cluster whose ray centre is c: never below its
 * horizon (shade.c). */
v3 vsgl__ray_aim(v3 x, v3 n, v3 c, v3 t);

/* Glossy light of a planar, Lambertian cluster (the lattice's diffuse
 * VSGLs) through a receiver lobe (ASG, amplitude included), per watt: the
 * cluster's plane has radiance N(y)/pi, N its 2-D Gaussian of variance
 * `variance` per axis about the mean; the lobe's axis meets the plane at
 * y0 = x + t z (t = h / -(n.z), nothing unless the receiver is in front,
 * h > 0, and the axis points at the plane's front); the lobe's angular
 * spread maps to a footprint of covariance J diag(1/2lambda, 1/2mu) J^T
 * there; the result is the lobe's integral pi / sqrt(lambda mu) times the
 * radiance blurred by the footprint, N(y0 - mean; variance I + footprint) / pi.
 * Where the lobe grazes the receiver's tangent plane (normal nr), the
 * part below that plane is dropped (kernel.h, VSGL__HORIZON_*).
 * The footprint is taken at the distance where the lobe meets the
 * cluster, not where its axis meets the plane (kernel.h,
 * vsgl__planar_reach): a linear footprint about a far hit reached back
 * past the receiver.
 * Unlike the round spread SG it sees a plane foreshortened (a cabinet's
 * face reflecting the floor beside it: 0.65 -> 1.08 of the brute force's
 * glossy light in the sun room) and never anything behind the plane.
 * A lattice cell cut by its surface's end (its VPLs' extent short of its
 * tent's, on a plane facing the cell's axis; the cuts vsgl_vsgl.cell_ends
 * marks) has its Gaussian folded back at each cut: an image mirrored
 * across it, each image's blurred density kept to the surface's side (the
 * 1-D product of the cluster's and the footprint's marginals, an erfc),
 * weighted by a smoothstep of the cut's depth. The Gaussians of a surface's last
 * lattice rows otherwise spill past the junction and the reflection of a
 * lit wall darkened towards its foot (35 % at the junction of the red-wall
 * room's floor; glossy structured error against Cycles 2-6x lower with the
 * fold, docs/quality.md).
 * Where the lobe meets the plane's horizon, only its share that points
 * into the plane counts, about an axis tilted towards the plane (kernel.h,
 * vsgl__planar_tilt). The shade stage also multiplies it by the
 * receiver's smooth-factor ratio towards the product's mean (kernel.h,
 * vsgl__smooth_ratio), which this lobe-only form leaves out. */
float vsgl__planar_glossy(const vsgl_vsgl *v, v3 x, v3 nr, const vsgl_asg *lobe);

/* The same for one part of a lobe (GGX's core or tail, of the same axes)
 * whose tilt at the horizon the whole lobe's spread sets, as the kernel's
 * (vsgl__planar_glossy is this with part = whole). */
float vsgl__planar_glossy_part(const vsgl_vsgl *v, v3 x, v3 nr, const vsgl_asg *part, const vsgl_asg *whole);

/* Shade every G-buffer sample with every VSGL; writes `planes`.
 * `pairs` receives the number of sample x VSGL evaluations. */
vsgl_result vsgl__shade(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_gbuffer *g,
                        const vsgl_vsgl_set *set, const vsgl_render_settings *s,
                        const vsgl_pixel_planes *planes, int path, uint64_t *pairs);

/* What shading a G-buffer needs that no light changes (shade_job.h). */
typedef struct vsgl_shade_plan vsgl_shade_plan;
void vsgl__shade_plan_free(vsgl_shade_plan *plan);

/* vsgl__shade through a shading plan kept by the caller with the G-buffer
 * (`*plan` NULL or a plan of this very G-buffer: the caller frees it when
 * the G-buffer changes). With shade_stride > 1 it replays a plan made
 * with the same stride and glossy mode, else records one into `*plan`
 * (replacing the old one; left as it was if memory is short). The planes
 * are bit-identical to vsgl__shade's either way. `counts` (NULL or)
 * receives what the call counts besides its pairs (below). */
typedef struct vsgl_shade_counts {
    uint64_t faint;          /* pairs whose VSGL was faint (vsgl__kernel_shade, VSGL__FAINT) */
    uint64_t dominant_pairs; /* pairs that traced dominant rays (vsgl_render_settings.dominant_rays) */
    uint64_t dominant_rays;  /* the rays those pairs traced beyond their first */
} vsgl_shade_counts;

vsgl_result vsgl__shade_planned(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_gbuffer *g,
                                const vsgl_vsgl_set *set, const vsgl_render_settings *s,
                                const vsgl_pixel_planes *planes, int path, uint64_t *pairs, vsgl_shade_counts *counts,
                                vsgl_shade_plan **plan);

#endif
