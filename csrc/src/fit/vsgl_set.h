/* Internal: virtual spherical Gaussian lights (VSGLs) and their fit from RSMs.
 *
 * A VSGL approximates a cluster of VPLs of one lobe kind (diffuse or
 * specular) by
 *   radiant intensity  I(w) = power * G(w; axis, sharpness) / A(sharpness)   [W/sr, RGB]
 *   position           isotropic Gaussian, mean `mean`, variance `variance` per axis [m^2]
 * (Tokuyoshi 2015 poster Sec. 2; FIS supplement Sec. 3). */
#ifndef VSGL_FIT_VSGL_SET_H
#define VSGL_FIT_VSGL_SET_H

#include "rsm/rsm.h"
#include "vsgl/render.h"

#define VSGL__LOBE_DIFFUSE  0
#define VSGL__LOBE_SPECULAR 1

typedef struct vsgl_vsgl {
    v3 mean;            /* mean VPL position, world */
    float variance;     /* positional variance per axis of the 2-D spread, m^2 (>= 0) */
    v3 axis;            /* unit lobe axis of the radiant intensity */
    float sharpness;    /* lambda_v */
    float power[3];     /* sum of Phi R over the cluster (RGB, W), after FIS weighting */
    v3 normal;          /* unit mean surface normal of the cluster's VPLs */
    float coherence;    /* |weighted mean normal| in [0, 1]: 1 = all VPLs coplanar-facing */
    float widen;        /* extra positional variance (m^2) for the planar glossy model only: the
                         * lattice's overlap of neighbouring clusters, VSGL__LATTICE_OVERLAP
                         * h^2 (0 for the other fits) */
    uint32_t light;     /* scene light index */
    uint32_t lobe;      /* VSGL_LOBE_* */
    /* The lattice cell (0 cell_h for the other fits): its VPLs lie on the
     * plane x[axis] = mean[axis], facing +axis (side 0) or -axis (side 1),
     * with tent weights around (centre[0], centre[1]) in the axes u = axis
     * + 1, v = axis + 2 (mod 3), spacing cell_h, within [lo, hi] there
     * (the VPLs' extent, padded by half a texel; where a wall rises at a
     * cut, the wall's face: fit/lattice.c surface_ends, for every specular
     * cell and the diffuse ones of one-lobe receivers). */
    float cell_h;
    float cell_centre[2], cell_lo[2], cell_hi[2];
    uint32_t cell_axis, cell_side;
    /* Bit 2 k + s: the VPLs' extent stops short of the tent on side s (0
     * low, 1 high) of in-plane axis k because the surface ends there (a
     * wall rises or the plane stops; probed in the scene), not at a
     * shadow's edge or a spot's rim where it goes on: the planar glossy
     * model's fold applies there (shade.h, vsgl__planar_glossy). */
    uint32_t cell_ends;
    /* The convex part (scene_internal.h, VSGL__PART_NONE) most of whose
     * VPLs lie on it, and the shares of the cluster's weight that lie on
     * its outside and inside: a receiver on that part keeps 1 - part_out
     * of the cluster's light, and 1 - part_out - part_in on its outside
     * (points of a convex surface light each other only inside to inside).
     * VSGL__PART_NONE (shares 0) for the fits other than the lattice. */
    uint32_t part;
    float part_out, part_in;
    /* The shear of a specular cluster on a curved part (the lattice's fine
     * cells; 0 elsewhere): its VPLs' mirror directions turn with their
     * positions, so a receiver is lit by the part of the cluster whose
     * emission points at it, not by all of it (a sphere's highlight in a
     * glossy floor). With positions x and mean vectors d of the VPLs
     * jointly Gaussian, the VPLs that send towards unit direction e (from
     * the mean) lie about mean + shear (e - axis), shear = lambda Cov(x, d)
     * (m per unit of direction, row-major), with positional variance
     * shear_variance = variance - lambda |Cov(x, d)|^2 / 2 (the variance
     * left given the direction; lambda/lambda_0 of it for a VPL lobe of
     * sharpness lambda_0), and the cluster's radiant intensity towards e
     * is its lobe's, as without the shear. fit/lattice.c, shear_of. The
     * kernel applies it (k_shift); the reference path (glossy mode SG),
     * the near field and the visibility rays' targets take the cluster
     * unsheared. */
    float shear[9];
    float shear_variance;
    uint32_t sheared; /* 1 where shear and shear_variance apply */
} vsgl_vsgl;

/* The lattice's overlap, in units of h^2 (vsgl_vsgl.widen): a sum of the
 * tents' Gaussians (variance h^2 / 6 per axis each) seen through a sharp
 * glossy lobe ripples by 7 %, by 0.6 % with h^2 / 8 more and 0.3 % with
 * h^2 / 6 more. h^2 / 6 was the first choice; h^2 / 8 has 11 % less
 * glossy structured error over the bundled rooms (the sphere's reflection
 * and the edges of a lit patch's reflection less blurred), and the stripes
 * a metal floor shows in the spot room's reflected ellipse stayed at 1.6 %
 * (they are not the lattice's: h^2 / 24 and 0 gave 1.9 %). */
#define VSGL__LATTICE_OVERLAP (1.0 / 8.0)

/* The outside of a curved convex part (a smooth-shaded sphere, a
 * cylinder: scene_internal.h vsgl__scene_part_curved) takes a lattice this
 * much finer (never below the texels' floor, fit/lattice.c). Its clusters
 * are curved patches whose Gaussians, seen through a sharp glossy lobe,
 * blur and break up its reflection by their size: the glossy floor under
 * the sphere room's sphere showed it at 0.47-0.53 where Cycles has
 * 0.75-0.87 (80 x 60, balanced; the brute force 0.75-0.93), in lumps that
 * did not look like a sphere. Flat parts keep the spacing: their cells are
 * planes, which the planar model draws sharply. Measured on the sphere
 * room at 80 x 60 (tests/quality/evaluate.py), 1 -> 0.7:
 *  - preview: glossy structured error 0.00154 -> 0.00107, diffuse 0.00347
 *    -> 0.00266, FLIP 0.167 -> 0.153; its light flicker (Gloss) 0.0098 ->
 *    0.0104, smaller clusters following the spot's edge;
 *  - balanced: glossy structured 0.00022 -> 0.00012, FLIP 0.107 -> 0.104;
 *  - quality: glossy structured 0.00011 -> 0.00011, FLIP 0.104 -> 0.099;
 *  - time at 960 x 540 (tools/preset_times.py): 1.03x, 1.21x, 1.21x.
 * 0.5 took balanced to 0.00009 (quality 0.00007) for 1.55x the time; 0.3
 * made the preview's light flicker 0.025. VSGLs: preview 459 -> 512,
 * balanced 1719 -> 2082, quality 2159 -> 2857. Rooms without a smooth-shaded convex part are
 * unchanged. */
#define VSGL__LATTICE_CURVED 0.7

typedef struct vsgl_vsgl_set {
    vsgl_vsgl *items;
    size_t count, capacity;
} vsgl_vsgl_set;

/* The integral a VSGL's lobe is normalised by (the shade stage's amplitude
 * power / it): A(sharpness), and for a specular lobe only its part above
 * the cluster's plane (vsgl__sg_fraction_above, blended to all of it as the
 * coherence falls; docs/math.md §5.4.1). A quadrature: once per VSGL, not
 * per receiver (moments.c). */
float vsgl__vsgl_lobe_integral(const vsgl_vsgl *v);

vsgl_result vsgl__vsgl_set_push(vsgl_vsgl_set *set, const vsgl_vsgl *v);
void vsgl__vsgl_set_free(vsgl_vsgl_set *set);

/* Per-lobe moment sums of a set of VPLs (double precision, positions
 * relative to `origin` so scenes far from the world origin keep digits). */
typedef struct vsgl_moments {
    double weight;      /* sum w_i, w_i = Phi_i R_i summed over RGB */
    double power[3];    /* sum Phi_i R_i (RGB) */
    double dir[3];      /* sum w_i * mean_vector_i (filtered directions, docs/references.md §3) */
    double pos[3];      /* sum w_i (x_i - origin) */
    double pos2;        /* sum w_i |x_i - origin|^2 */
    double nrm[3];      /* sum w_i n_i (surface normals) */
} vsgl_moments;

/* One VPL's contribution to the diffuse and specular moments: its lobes'
 * mean vectors, powers and positions (texel t of rsm). Returns 0 for an
 * empty or black texel. `estimator` selects the lobe's mean length. */
int vsgl__vpl_moments(const vsgl_scene *scene, const vsgl_rsm *rsm, size_t t, v3 origin,
                      int32_t estimator, vsgl_moments out[2]);

void vsgl__moments_add(vsgl_moments *acc, const vsgl_moments *m, double scale);

/* Turn moments into a VSGL (returns 0 if the moments carry no power). */
int vsgl__moments_to_vsgl(const vsgl_moments *m, v3 origin, int32_t estimator,
                          uint32_t light, uint32_t lobe, vsgl_vsgl *out);

/* Fit the VSGLs of one light's RSM in the settings' mode and append them. */
vsgl_result vsgl__fit_two(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm,
                          const vsgl_render_settings *s, vsgl_vsgl_set *out);
vsgl_result vsgl__fit_fis(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm,
                          const vsgl_render_settings *s, vsgl_vsgl_set *out);
vsgl_result vsgl__fit_lattice(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm,
                              const vsgl_render_settings *s, vsgl_vsgl_set *out);
/* The lattice with about `n_clusters` VSGLs (real: the spacing follows it
 * continuously; the per-light budget passes its share). */
vsgl_result vsgl__fit_lattice_n(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm,
                                const vsgl_render_settings *s, double n_clusters, vsgl_vsgl_set *out);
vsgl_result vsgl__fit_kmeans(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm,
                             const vsgl_render_settings *s, vsgl_vsgl_set *out);

/* Reference point for a light's moments (the RSM's first valid texel, or 0). */
v3 vsgl__rsm_origin(const vsgl_rsm *rsm);

#endif
