/* Broad receiver lobes (docs/math.md §5.4.4). The shade stage's glossy lobe
 * (Xu et al.'s ASG of GGX's NDF, warped to light directions and cut at the
 * horizon) holds GGX's light while it is sharp, but a rough one loses it:
 * its smooth term max(l.z, 0) falls off across a broad lobe and its
 * Gaussian is in sin(theta), not GGX's tan(theta); at roughness 0.8 it held
 * 0.58-0.72 of GGX's albedo under a uniform sky, 0.46-0.68 at 0.9. Above
 * roughness VSGL__BROAD_R0 the lobe's amplitude is set to be closest to
 * GGX's lobe (L2), per roughness and view, and a dielectric's sharpness
 * scaled (before the cut) where that is closer still (above roughness
 * 0.85; a conductor's is left: tools/gen_broad_lobe.c says why): the
 * generator's tables, faded in up to VSGL__BROAD_R1. */
#ifndef VSGL_MATH_BROAD_LOBE_H
#define VSGL_MATH_BROAD_LOBE_H

#include "math/vec.h"
#include "vsgl/asg.h"

#include <math.h>

#define VSGL__BROAD_R0 0.4f   /* Blender roughness below which lobes are unchanged */
#define VSGL__BROAD_R1 0.6f   /* ... and above which the fit is taken whole */
#define VSGL__BROAD_ROWS 13   /* roughness VSGL__BROAD_R0 .. 1 in steps of 0.05 */
#define VSGL__BROAD_COLS 16   /* views: sqrt(cos_o) evenly from sqrt(VSGL__BROAD_C0) to 1 */
#define VSGL__BROAD_C0 0.02f  /* the most grazing view in the table (clamped below) */

#define VSGL__BROAD_DIELECTRIC_F0 0.04f /* the dielectric table's F0 */

typedef struct vsgl_broad_table {
    float scale[VSGL__BROAD_ROWS];
    float amplitude[VSGL__BROAD_ROWS][VSGL__BROAD_COLS];
} vsgl_broad_table;
/* [lobe][material]: lobe 0 GGX's core and tail as two ASGs (VSGL_GLOSSY_ASG2
 * and the hybrid's VSGLs), 1 one ASG (VSGL_GLOSSY_ASG); material 0 a white
 * conductor (F = 1), 1 a dielectric of F0 VSGL__BROAD_DIELECTRIC_F0 */
extern const vsgl_broad_table vsgl__broad_tables[2][2];

/* How far a lobe of Blender roughness r takes a broad-lobe correction: 0
 * up to VSGL__BROAD_R0, 1 from VSGL__BROAD_R1, a smoothstep between (the
 * tables' rows are faded in so; the shade stage fades one ASG's
 * smooth-factor ratio the same way, shade/kernel.h vsgl__shadow_lane). */
static inline float vsgl__broad_fade(float r)
{
    float t = (r - VSGL__BROAD_R0) * (1.0f / (VSGL__BROAD_R1 - VSGL__BROAD_R0));
    t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    return t * t * (3.0f - 2.0f * t);
}

static inline float vsgl__broad_row_roughness(int j)
{
    return VSGL__BROAD_R0 + (1.0f - VSGL__BROAD_R0) * (float)j / (VSGL__BROAD_ROWS - 1);
}

static inline float vsgl__broad_col_cosine(int k)
{
    float u0 = sqrtf(VSGL__BROAD_C0), u = u0 + (1.0f - u0) * (float)k / (VSGL__BROAD_COLS - 1);
    return u * u;
}

/* The sharpness scale (for the warped lobe's lambda and mu, before the cut
 * at the horizon) and amplitude factor of a receiver of GGX alpha (the
 * geometric mean of an anisotropic pair) and mean F0 f0 seen at cosine
 * cos_o, its lobe GGX's two parts (two != 0) or one ASG: the material's
 * two tables mixed by how much the Fresnel varies, (1 - f0) / (1 -
 * VSGL__BROAD_DIELECTRIC_F0); {1, 1} below roughness VSGL__BROAD_R0. */
void vsgl__broad_lobe(float alpha, float f0, float cos_o, int two, float *scale, float *amplitude);

/* A receiver's glossy lobe as the shade stage takes it (shade.c
 * setup_receiver): GGX's NDF of alpha_x, alpha_y about normal n (tangent
 * t) as an ASG, warped to light directions seen from view o (in float,
 * math/warp_lanes.h, as the shade stage warps a block's receivers), its
 * sharpness times scale, cut at the horizon (vsgl__asg_cut_at_horizon
 * with the view), its amplitude times amplitude; {1, 1}: the plain lobe.
 * tools/gen_broad_lobe.c fits the tables to this very lobe. */
void vsgl__receiver_asg(v3 n, v3 t, v3 o, float alpha_x, float alpha_y, float scale, float amplitude,
                        vsgl_asg *out);
/* The steps of vsgl__receiver_asg after the warp (a lobe from
 * math/warp_lanes.h, many receivers at a time): sharpness times scale, the
 * cut at the horizon, amplitude times amplitude. */
void vsgl__receiver_asg_finish(v3 n, v3 o, float scale, float amplitude, vsgl_asg *a);

#endif
