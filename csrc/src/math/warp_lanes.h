/* Receivers' glossy lobes many at a time: GGX's NDF as an ASG about a
 * normal and tangent, warped to light directions seen from a view
 * (vsgl_ndf_aniso_to_asg then vsgl_warp_ndf_asg), in float lanes that the
 * compiler vectorises (warp_lanes.c). The shade stage warps a block's
 * glossy receivers at once; one receiver alone (n = 1) takes the same
 * operations in the same order, so it gets the same lobe bit for bit. */
#ifndef VSGL_MATH_WARP_LANES_H
#define VSGL_MATH_WARP_LANES_H

#include "math/vec.h"
#include "vsgl/asg.h"

#include <stddef.h>

#define VSGL__WARP_LANES 64

typedef struct vsgl_warp_lanes {
    /* in: normal, tangent (made orthogonal to the normal here), view towards
     * the viewer, none need be unit (none zero); GGX alphas */
    float nx[VSGL__WARP_LANES], ny[VSGL__WARP_LANES], nz[VSGL__WARP_LANES];
    float tx[VSGL__WARP_LANES], ty[VSGL__WARP_LANES], tz[VSGL__WARP_LANES];
    float ox[VSGL__WARP_LANES], oy[VSGL__WARP_LANES], oz[VSGL__WARP_LANES];
    float ax[VSGL__WARP_LANES], ay[VSGL__WARP_LANES];
    /* out: the warped lobe's frame (x the sharper axis) and sharpnesses;
     * its log amplitude is the NDF's, -log(pi ax ay) (vsgl_ndf_aniso_to_asg) */
    float Xx[VSGL__WARP_LANES], Xy[VSGL__WARP_LANES], Xz[VSGL__WARP_LANES];
    float Yx[VSGL__WARP_LANES], Yy[VSGL__WARP_LANES], Yz[VSGL__WARP_LANES];
    float Zx[VSGL__WARP_LANES], Zy[VSGL__WARP_LANES], Zz[VSGL__WARP_LANES];
    float lam[VSGL__WARP_LANES], mu[VSGL__WARP_LANES];
} vsgl_warp_lanes;

/* Warp lanes [0, n), n <= VSGL__WARP_LANES. */
void vsgl__warp_lanes(vsgl_warp_lanes *w, size_t n);
/* Lane k's inputs: normal n, tangent t, view o, alphas. */
void vsgl__warp_lane_set(vsgl_warp_lanes *w, size_t k, v3 n, v3 t, v3 o, float alpha_x, float alpha_y);
/* Lane k's warped lobe as an ASG, with the NDF's amplitude. */
void vsgl__warp_lane_get(const vsgl_warp_lanes *w, size_t k, vsgl_asg *out);

#endif
