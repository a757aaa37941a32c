/* Internal: rectangle proxies (RPs) built from a scene's planar faces, their
 * outgoing radiance from this frame's RSMs, and the MRP glossy shading of
 * the G-buffer from them (docs/mrp.md §4). Owner: csrc/src/mrp. */
#ifndef VSGL_MRP_PROXIES_H
#define VSGL_MRP_PROXIES_H

#include "mrp/mrp.h"
#include "rsm/rsm.h"
#include "gbuffer/gbuffer.h"
#include "shade/shade.h"

/* One proxy: a rectangle fitted to a group of coplanar triangles, split
 * into cells_u x cells_v cells, each a Lambertian rectangle of uniform
 * radiance on either side (side 0 = along rect.normal, 1 = against it). */
typedef struct vsgl__mrp_proxy {
    vsgl__mrp_rect rect;
    double coverage;     /* the group's triangle area / the rectangle's */
    uint32_t nu, nv;     /* cells along u and v (>= 1): square-ish cells, `cells` along the longer side */
    float *power;        /* [2][cells_v][cells_u][3]: sum of RSM flux x diffuse albedo (W), then radiance */
    float side_total[2]; /* sum over cells of the luminance-ish sum of channels, per side */
    /* The cell pyramid (vsgl__mrp_proxies_finish): level l > 0 merges 2^l x 2^l cells (fewer at the
     * far edges), its radiance the mean of the cells it covers, and their contrast; levels 1 .. levels - 1 of both sides,
     * the last one a single cell. vsgl__mrp_level reads it (level 0 is power). */
    uint32_t levels;
    float *pyramid;
} vsgl__mrp_proxy;

/* Levels of the cell pyramid above level 0 (cells <= 64: at most 7 levels in all). */
#define VSGL__MRP_MAX_LEVELS 8

/* Level @p level (0 .. p->levels - 1) of side @p side of proxy @p p:
 * [nv][nu][stride] with *nu = ceil(p->nu / 2^level),
 * *nv = ceil(p->nv / 2^level): RGB radiance, and at levels > 0
 * (*stride 4) the contrast (max - min) / (max + min) of its cells' sums of
 * channels. Block (bu, bv) covers the cells
 * [bu 2^level, min((bu + 1) 2^level, p->nu)) along u, likewise along v. */
const float *vsgl__mrp_level(const vsgl__mrp_proxy *p, int side, uint32_t level, uint32_t *nu, uint32_t *nv,
                             uint32_t *stride);

typedef struct vsgl__mrp_proxy_set {
    vsgl__mrp_proxy *items;
    size_t count;
    float *storage;      /* all proxies' power arrays */
    double plane_tol;    /* how far from the plane a texel may lie (m) */
} vsgl__mrp_proxy_set;

/* Group the scene's triangles by plane (normal within ~0.06 degrees,
 * offset within 1e-4 of the scene's diagonal), fit each group a rectangle
 * (axes along its largest triangle's longest edge; the bounds of its
 * vertices) and keep those of area >= @p min_area (m^2) whose triangles
 * cover >= 70 % of it, at most 256, largest first. @p cells: cells along a
 * proxy's longer side (1..64). */
vsgl_result vsgl__mrp_proxies_build(vsgl_context *ctx, const vsgl_scene *scene, double min_area, uint32_t cells,
                                    vsgl__mrp_proxy_set *out);

/* Add the light an RSM puts on the proxies: each lit texel on a proxy (its
 * position within plane_tol of the plane and inside the rectangle, its
 * normal within ~18 degrees of the plane's) adds flux x diffuse albedo to
 * its cell on the side its normal faces. Each texel counts once (first proxy). */
void vsgl__mrp_proxies_add_rsm(vsgl__mrp_proxy_set *set, const vsgl_scene *scene, const vsgl_rsm *rsm);

/* Turn the accumulated power into radiance: P / (pi * cell area). */
void vsgl__mrp_proxies_finish(vsgl__mrp_proxy_set *set);

void vsgl__mrp_proxies_free(vsgl__mrp_proxy_set *set);

/* The glossy plane from the proxies: for every hit sample with a glossy
 * lobe, the sum over proxies and lit cells of the MRP term
 * (vsgl__mrp_glossy_parts, default options) x the smooth factor x the
 * cell's radiance; planes->glossy (per pixel, sample-weighted as the VSGL
 * shading) is overwritten.
 * Hybrid (@p glossy_q not NULL: the VSGL glossy plane of the clusters off
 * every proxy): a pixel whose glossy samples all have alpha <= @p max_alpha
 * and receive MRP light gets glossy_q + MRP's light where that is above
 * VSGL__MRP_HYBRID_RATIO (shade_mrp.c) times the on-proxy clusters'
 * (planes->glossy - glossy_q), else keeps planes->glossy; every other pixel
 * keeps the VSGL glossy light already in planes->glossy (docs/mrp.md §4). */
vsgl_result vsgl__mrp_shade_glossy(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_gbuffer *g,
                                   const vsgl__mrp_proxy_set *set, const vsgl_pixel_planes *planes,
                                   const float *glossy_q, double max_alpha);

/* The hybrid's rule: receivers up to this GGX alpha (roughness 0.5) take MRP. */
#define VSGL__MRP_HYBRID_MAX_ALPHA 0.25
/* A cluster lies on a proxy when its mean is within this many plane_tol of
 * the proxy's plane and inside its rectangle, its mean normal within ~18
 * degrees of the plane's. */
#define VSGL__MRP_ON_PROXY_TOL 4.0

/* 1 if VSGL v is a diffuse cluster lying on a proxy of @p set (whose light
 * the proxy's cells carry), else 0. */
int vsgl__mrp_on_proxy(const vsgl__mrp_proxy_set *set, const vsgl_vsgl *v);

/* Defaults of the proxy pass: proxies of at least VSGL__MRP_MIN_AREA m^2
 * (the setting vsgl_render_settings.mrp_min_area's default),
 * VSGL__MRP_CELLS cells along their longer side (a constant). */
#define VSGL__MRP_MIN_AREA ((double)VSGL_MRP_MIN_AREA_DEFAULT)
#ifndef VSGL__MRP_CELLS
#define VSGL__MRP_CELLS 32
#endif

/* The whole glossy_mode = VSGL_GLOSSY_MRP pass: proxies from the scene, one
 * RSM per light at @p rsm_resolution (built again: the fit frees its own),
 * proxies of at least @p min_area m^2 with @p cells cells on their longer side,
 * radiance, then vsgl__mrp_shade_glossy into planes->glossy. Writes the
 * proxy count to *proxies (may be NULL). Reports progress as stage "mrp"
 * (after each light's RSM and after shading); a cancel there returns
 * VSGL_ERROR_CANCELLED.
 * @p lit (may be NULL): proxies built with the same @p min_area and
 * @p cells to which every light's RSM at @p rsm_resolution was already
 * added (vsgl__mrp_proxies_add_rsm, as the fit builds them:
 * vsgl__fit_lights_mrp); the pass then builds neither proxies nor RSMs and
 * finishes and shades @p lit (the caller frees it). The same planes. */
vsgl_result vsgl__mrp_glossy_pass(vsgl_context *ctx, const vsgl_scene *scene, uint32_t rsm_resolution,
                                  double min_area, uint32_t cells, const vsgl_gbuffer *g,
                                  const vsgl_pixel_planes *planes, size_t *proxies, vsgl__mrp_proxy_set *lit);

/* VSGL_GLOSSY_HYBRID: planes holds the VSGL pass of @p vsgls (two-lobe
 * glossy). Builds the proxies, shades the VSGLs off every proxy again into
 * a scratch plane (their glossy light; *excluded receives the number left
 * out, may be NULL) and runs the MRP pass with the hybrid rule of
 * vsgl__mrp_shade_glossy. @p lit: as for vsgl__mrp_glossy_pass (its proxies
 * of the settings' mrp_min_area, VSGL__MRP_CELLS cells), or NULL. */
vsgl_result vsgl__mrp_hybrid_pass(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                                  const vsgl_gbuffer *g, const vsgl_vsgl_set *vsgls, const vsgl_pixel_planes *planes,
                                  size_t *excluded, vsgl__mrp_proxy_set *lit);

#endif
