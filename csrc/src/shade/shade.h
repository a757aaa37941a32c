/* Internal: shading camera samples with VSGLs through SG/ASG product
 * integrals (poster Sec. 3, FIS supplement Sec. 4). */
#ifndef VSGL_SHADE_H
#define VSGL_SHADE_H

#include "fit/vsgl_set.h"
#include "gbuffer/gbuffer.h"
#include "vsgl/sg.h"

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
 * with zero spread). */
int vsgl__vsgl_incident_sg(const vsgl_vsgl *v, v3 x, vsgl_sg *sg);

/* Shading paths: the vectorised kernel (default), the same kernel built
 * scalar (benchmark baseline), and the reference path through the public
 * operator functions (slow; exact ASG normalisation; SG glossy lobes). */
#define VSGL_SHADE_KERNEL        0
#define VSGL_SHADE_KERNEL_SCALAR 1
#define VSGL_SHADE_REFERENCE     2

/* Emission cosine below which the leak correction fades a VSGL out. */
#define VSGL_LEAK_COSINE 0.05f

/* Emitter-hemisphere (leak) correction factor of VSGL v at receiver x, in
 * [0, 1] (the kernel computes the same inline). */
float vsgl__leak_factor(const vsgl_vsgl *v, v3 x);

/* Shade every G-buffer sample with every VSGL; writes `planes`.
 * `pairs` receives the number of sample x VSGL evaluations. */
vsgl_result vsgl__shade(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_gbuffer *g,
                        const vsgl_vsgl_set *set, const vsgl_render_settings *s,
                        const vsgl_pixel_planes *planes, int path, uint64_t *pairs);

#endif
