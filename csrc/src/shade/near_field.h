/* Internal: the near field of the lattice's clusters (fit/lattice.c).
 *
 * The far-field model (an SG of incident light per cluster) breaks within
 * a cluster's own extent: a Gaussian's tails spill past the junction where
 * its surface ends (a wall's foot), into space a receiver beside the
 * junction cannot see, and the Gaussians of a surface's last lattice row
 * sum to about half the surface's density at its edge. A floor beside a
 * lit wall came out 10-25 % dark in a strip along the wall (a dark seam
 * along every junction of a box). Near a cell, the cluster is instead its
 * tent of uniform radiosity over the cell, truncated to its VPLs' extent,
 * and its diffuse light the exact polygon form factor (Lambert) of the
 * tent's steps. */
#ifndef VSGL_SHADE_NEAR_FIELD_H
#define VSGL_SHADE_NEAR_FIELD_H

#include "fit/vsgl_set.h"
#include "math/vec.h"

/* A lattice cluster's cell, as the near-field model sees it. */
typedef struct vsgl_near_cell {
    v3 centre;            /* the lattice point on the cell's plane */
    float h;              /* lattice spacing, m */
    float za;             /* the plane: x[axis] = za */
    float fit;            /* how far the model applies: coherence^2 x facing x uniformity, [0, 1] */
    float flat;           /* how far it applies to receivers that face the cell's way too (a floor's
                             own points): 1 for a plane, 0 for a cell that bends (near_field.c) */
    float inv_area;       /* 1 / (pi x the steps' total area) */
    float rect[4][4];     /* the steps: u0 u1 v0 v1 (u = axis + 1, v = axis + 2 mod 3) */
    uint32_t axis, side;  /* the plane faces +axis (side 0) or -axis (side 1) */
    uint32_t nrect;       /* steps with any area */
    uint32_t vsgl;        /* its VSGL in the set */
    /* a specular cluster (a metal floor's reflection of a lit wall): its
     * lobe's axis and sharpness; lambda 0 for a Lambertian one */
    v3 lobe_axis;
    float lambda;
    /* its irradiance across the steps, linear: 1 + grad . (y - centroid)
     * (in-plane u, v; the steps' centroid), so that its mean is the VPLs' */
    float grad[2], centroid[2]; /* centroid: from the lattice point */
    float tlo[2], thi[2];  /* its tent's support (u, v) truncated to the VPLs' extent, from the lattice point */
} vsgl_near_cell;

/* The model applies to uniform radiosity: the steps' centroid within this
 * many spacings of the VPLs' mean, none from three times it (a shadow or a
 * spot's edge crossing the cell moves the mean; the steps cannot). The
 * planar glossy fold (shade.c, fold_mean) uses the same test. */
#define VSGL__NEAR_UNIFORM 0.05f

/* The tent 1 - |x - c| / h over [lo, hi]: its mass, mean and variance. */
void vsgl__tent_moments(double lo, double hi, double c, double h, double *mass, double *mean, double *var);

/* The cell of v; 0 if the model does not apply to v (not a lattice
 * cluster, no power, a curved surface, radiosity far from uniform, or a
 * specular lobe that does not leave its plane's front). */
int vsgl__near_cell(const vsgl_vsgl *v, uint32_t index, vsgl_near_cell *c);

/* The diffuse light per watt (irradiance / pi per W of the cluster's
 * power) at x, normal n, and in *weight how much of the pair the model
 * takes, in [0, 1]: the cell's fit, 1 within VSGL__NEAR_FULL spacings of
 * its centre and 0 beyond VSGL__NEAR_NONE, smooth between; for a cell
 * that bends (flat < 1), only for receivers turned across its plane (a
 * wall's foot, not its own floor's bumps: near_field.c
 * VSGL__NEAR_ACROSS_*). 0 and weight 0 behind or in the cell's plane
 * (where the far-field term is ~0 too: the emitter clip), and 0 wherever
 * the weight is 0.
 * A specular cell is its steps of uniform irradiance reflected through
 * its lobe G(w) = e^{lambda (w.axis - 1)}: x sees the lobe's mass that
 * falls in the steps as seen from x, the lobe's footprint on the plane
 * about where its axis through x meets it (linearised: covariance
 * (t^2 / lambda) (I + a a^T / cos^2 b), a the axis's in-plane part, t the
 * distance, b its angle to the plane's normal), so E = P cos_x sum_k
 * frac_k / (S cos b) with S the steps' area: a floor's caustic at a
 * wall's foot is the steps' image, where the far field drew one
 * lobe-sized blob per cluster. Its irradiance varies linearly across the
 * steps so that their mean is the VPLs' (a spot's spill on a floor rises
 * 5x towards the wall it lights; uniform, the caustic came out half as
 * bright). */
float vsgl__near_diffuse(const vsgl_near_cell *c, v3 x, v3 n, float *weight);

/* The cells whose near field reaches each cell of a uniform grid (CSR),
 * so that a receiver tests only those. */
typedef struct vsgl_near_index {
    vsgl_near_cell *cells;
    int32_t *cell_of;     /* per VSGL of the set: its cell, or -1 */
    uint32_t *start;      /* grid cells + 1 offsets into items */
    uint32_t *items;      /* indices into cells */
    int32_t dims[3];      /* 0 0 0: no cluster has a near field */
    v3 lo;
    float inv;            /* 1 / the grid's cell size */
} vsgl_near_index;

/* 0 if memory is short (ix is then empty: the far field everywhere). */
int vsgl__near_index_build(const vsgl_vsgl_set *set, vsgl_near_index *ix);
void vsgl__near_index_free(vsgl_near_index *ix);
/* The cells whose near field may reach x, in increasing order. */
const uint32_t *vsgl__near_candidates(const vsgl_near_index *ix, v3 x, size_t *n);

#endif
