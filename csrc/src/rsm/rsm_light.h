/* Internal to csrc/src/rsm: how each light type maps RSM texels to rays and
 * to emitted power (Cycles units, Blender 3.4 semantics and Blender 4.0+
 * spots; docs/units.md). */
#ifndef VSGL_RSM_LIGHT_H
#define VSGL_RSM_LIGHT_H

#include "rsm/rsm.h"

/* Light prepared for texel generation (all vectors world space). */
typedef struct vsgl_rsm_light {
    int type;
    uint32_t faces, res;
    v3 pos;                 /* point/spot/area centre */
    v3 ax, ay, az;          /* unit light frame; emission along -az (spot, sun, area) */
    double rgb[3];          /* colour x power, W (sun: W/m^2) */
    /* spot */
    double cos_half, smooth;/* cos(size/2), (1 - cos_half) * blend */
    double tan_half;        /* single-face spot: image half-width on the plane at distance 1 */
    int spot_v4;            /* Blender 4.0+ spot: no cos(theta), the cone in the scaled frame */
    double inv_scale[3];    /* 1 / the object's scale along the light frame's axes (spot_v4) */
    /* sun: orthographic map over the scene bounds */
    v3 sun_dir;             /* direction the light travels */
    v3 sun_origin;          /* ray origin of texel (0,0) corner */
    v3 sun_u, sun_v;        /* one texel step along the map's columns / rows (metres) */
    double sun_texel_area;  /* m^2, perpendicular to the beam */
    float sun_tmax;
    /* area */
    int shape;
    double size_x, size_y;  /* world-space extents of the emitting shape (scale applied) */
    double tan_half_spread; /* tan(spread/2); 0 = no spread limit (spread = pi) */
    double spread_norm;     /* normalisation of the spread mask (Cycles) */
    double area_power;      /* emitted power / P: pi/4 (Blender 3.x), 1 (4.x+) */
} vsgl_rsm_light;

/* Prepare light `index` of the scene for an RSM of `res` texels per side. */
void vsgl__rsm_light_setup(const vsgl_scene *scene, uint32_t index, uint32_t res, vsgl_rsm_light *out);

/* A sun's map (else nothing): the square of res x res texels at column
 * col0, row row0 of the same map at res * zoom texels per side, i.e. the
 * texel grid of the whole map refined `zoom` times (its phase kept: a window
 * that moves by whole texels samples the same points). */
void vsgl__rsm_light_window(vsgl_rsm_light *l, uint32_t zoom, int64_t col0, int64_t row0);
/* Texel (face, row, col): ray origin and unit direction, the power (W,
 * RGB) the light emits into the texel's cone / beam, and the beam's size:
 * solid angle (sr) for point/spot/area, cross-section (m^2) for a sun.
 * Returns 0 if the texel carries no power (outside a spot cone). */
int vsgl__rsm_light_texel(const vsgl_rsm_light *l, uint32_t face, uint32_t row, uint32_t col,
                          v3 *org, v3 *dir, double flux[3], double *beam);

/* vsgl__rsm_light_texel for every column of row `row` of face `face`:
 * org, dir, lit (its return value): res each; fl: 4 per column (flux RGB,
 * beam); scratch: VSGL__RSM_ROW_SCRATCH(res) doubles. The same values, bit
 * for bit; point and spot lights share what texels share (their corners). */
#define VSGL__RSM_ROW_SCRATCH(res) (5 * ((size_t)(res) + 1))
void vsgl__rsm_light_row(const vsgl_rsm_light *l, uint32_t face, uint32_t row, v3 *org, v3 *dir, double *fl,
                         int *lit, double *scratch);

/* Total power the light emits (W, RGB) as Cycles defines it; for a sun the
 * power crossing the map's footprint. Used by tests and docs/units.md. */
void vsgl__rsm_light_emitted(const vsgl_rsm_light *l, double out[3]);

/* Exact solid angle of the rectangle [x0,x1] x [y0,y1] on the plane at
 * distance 1 from the eye (Girard; atan2 form). */
double vsgl__rsm_rect_solid_angle(double x0, double x1, double y0, double y1);

#endif
