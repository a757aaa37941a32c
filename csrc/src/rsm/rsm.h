/* Internal: reflective shadow maps, one per light; texel = virtual point light.
 * Owner: csrc/src/rsm. Consumed by the VSGL fit and the brute-force gather. */
#ifndef VSGL_RSM_H
#define VSGL_RSM_H

#include "scene/scene_internal.h"

#define VSGL__RSM_EMPTY 0xFFFFFFFFu

/* Structure of arrays; texel index = (face * res + row) * res + col.
 * faces = 6 for point lights and spots wider than 120 degrees (cube map in
 * the light's frame), 1 otherwise (spot: perspective image over the cone;
 * sun: orthographic over the scene bounds or a window of it; area: concentric map of the
 * cosine-weighted hemisphere). Per-type details: rsm_light.c, docs/units.md.
 * Each texel's flux is
 * the RGB power (W) arriving on the surface patch it sees, with the
 * solid-angle/area Jacobian folded in, so that the sum over a closed box
 * equals the light's emitted power as Cycles defines it. */
typedef struct vsgl_rsm {
    uint32_t light;                /* scene light index */
    uint32_t faces, res;
    uint32_t zoom;                 /* sun: the map's texel is 1/zoom of the whole map's (vsgl__rsm_build_inward) */
    size_t count;                  /* faces * res * res */
    float *pos[3];                 /* VPL position, world */
    float *nrm[3];                 /* shading normal at the VPL, facing the light */
    float *tan[3];                 /* unit tangent at the VPL (anisotropy frame) */
    float *area;                   /* m^2: the texel's footprint on the surface
                                    * (solid angle x d^2 / cos, or beam area / cos) */
    float *wi[3];                  /* unit direction from the VPL towards the light */
    float *flux[3];                /* incident power on the texel's patch, W (RGB) */
    uint32_t *material;            /* VSGL__RSM_EMPTY where the texel saw nothing */
    uint32_t *part;                /* the convex part key of its surface (vsgl_surface.part); NULL: none */
    double total_flux[3];          /* sum of flux */
    float *surf[VSGL__SURF_N];      /* textured scenes only (else NULL): the material inputs at the VPL
                                      (VSGL_SURF_*), textures filtered over the texel's patch */
} vsgl_rsm;

/* Material of texel i with its own inputs (textured scenes), else its
 * material's constants. The texel must not be empty. */
void vsgl__rsm_material(const vsgl_rsm *r, const vsgl_material *materials, size_t i, vsgl_material *out);

/* Build the RSM of light `light` at `res` texels per side. */
vsgl_result vsgl__rsm_build(vsgl_context *ctx, const vsgl_scene *scene, uint32_t light, uint32_t res, vsgl_rsm *out);
void vsgl__rsm_free(vsgl_rsm *r);
/* Empties the texels whose surface faces out of the scene: every corner of
 * its bounding box lies behind their tangent plane, so nothing is in front
 * of them to light (the outside of a room's walls and roof under a sun;
 * the emitter clip gives them nothing to light, the exact gather no
 * receiver). Sets dropped to their power and total_flux to what is left. */
void vsgl__rsm_drop_outward(const vsgl_scene *scene, vsgl_rsm *r, double dropped[3]);
/* total_flux = the sum of the texels' flux, in texel order. */
void vsgl__rsm_sum_flux(vsgl_rsm *r);

/* Texel helpers shared by the map's builders (rsm.c, rsm_edges.c).
 * faces_out: a surface at p with normal n has every corner of the box
 * [lo, hi] behind its tangent plane (within tol). fill_texel: texel i sees
 * `hit` along unit `dir` (position overrides the hit's point when not
 * NULL), carries `flux` (W, RGB), its footprint = beam (m^2 across the
 * beam, times d^2 for a cone) over the cosine at the surface. */
int vsgl__rsm_faces_out(v3 p, v3 n, v3 lo, v3 hi, float tol);
void vsgl__rsm_clear_texel(vsgl_rsm *o, size_t i);
void vsgl__rsm_fill_texel(const vsgl_scene *scene, vsgl_rsm *o, size_t i, const vsgl_hit *hit, v3 dir,
                          const v3 *position, const double flux[3], double beam);

/* Refinement cap of vsgl__rsm_build_inward: a sun's window is at least
 * 1/VSGL__RSM_MAX_ZOOM of the scene's extent. */
#define VSGL__RSM_MAX_ZOOM 16u
/* vsgl__rsm_build, then vsgl__rsm_drop_outward (dropped: its power). A
 * sun's map then covers only the square around the texels left, at the
 * same res: a room lit through an opening gets its texels inside the room
 * (zoom in the result: the whole map's grid refined zoom times, a power of
 * two; 1 when the texels left span more than half the map). */
vsgl_result vsgl__rsm_build_inward(vsgl_context *ctx, const vsgl_scene *scene, uint32_t light, uint32_t res,
                                   vsgl_rsm *out, double dropped[3]);

/* A sun's map (else nothing): every texel that carries power next to one
 * that carries none, or the other way round, traced again with
 * VSGL__RSM_EDGE_RAYS rays across it; it keeps the fraction of its power
 * that lands on surfaces facing into the scene, at their mean position on
 * the surface nearest its centre (rsm_edges.c). vsgl__rsm_build_inward
 * does this to its result. traced: how many texels. */
#define VSGL__RSM_EDGE_RAYS 16
struct vsgl_rsm_light;
vsgl_result vsgl__rsm_smooth_edges(vsgl_context *ctx, const vsgl_scene *scene, const struct vsgl_rsm_light *l,
                                   vsgl_rsm *r, size_t *traced);
#endif
