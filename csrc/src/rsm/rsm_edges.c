/* A sun's map at the edge of what it lights: the texels where a lit region
 * meets texels that carry nothing (the sun's ray missed, or hit a surface
 * that faces out of the scene and was dropped) are traced again with
 * VSGL__RSM_EDGE_RAYS (N) parallel rays across the texel, on a rank-1
 * lattice (ray s at ((s + 1/2) / N, ((5 s mod N) + 1/2) / N) of the
 * texel: every ray in its own column and row, so that an edge along the
 * map's rows or columns is resolved to 1/N of a texel, not the 1/4 of a
 * 4 x 4 grid). Each keeps the fraction of its power that lands inside,
 * placed at the mean of those landing points on one surface. The map's
 * one-ray texels switch on and off whole as the edge of a window's light
 * patch slides across them (the patch's indirect and glossy light step
 * with them); these fade in and out in steps of 1/N of a texel, where the
 * light's own edge is. */
#include "rsm/rsm.h"

#include "core/context.h"
#include "core/parallel.h"
#include "rsm/rsm_light.h"

#include <math.h>
#include <stdlib.h>

#define NR VSGL__RSM_EDGE_RAYS
#define CHUNK 16 /* edge texels per job: CHUNK * NR rays per ray stream */

/* Ray s of a texel: its offset across the texel's columns (a) and rows (b). */
static double lattice_a(int s) { return (s + 0.5) / NR; }
static double lattice_b(int s) { return ((5 * s) % NR + 0.5) / NR; }

typedef struct edge_job {
    const vsgl_scene *scene;
    const vsgl_rsm_light *light;
    vsgl_rsm *map;
    const uint32_t *texels; /* the edge texels, ascending */
    v3 lo, hi;              /* the scene's box (faces_out) */
    float tol;
} edge_job;

/* Texel i of the map: 1 if it carries power. */
static int kept(const vsgl_rsm *r, size_t i) { return r->material[i] != VSGL__RSM_EMPTY; }

static int32_t edge_texels(void *user, size_t chunk, size_t begin, size_t end)
{
    (void)chunk;
    const edge_job *j = user;
    const vsgl_rsm_light *l = j->light;
    enum { N = CHUNK * NR };
    v3 org[N] = {{0}}, dir[N] = {{0}};
    float tmin[N] = {0}, tmax[N] = {0};
    vsgl_hit hits[N];
    size_t n = (end - begin) * NR;
    for (size_t e = begin; e < end; ++e) {
        uint32_t i = j->texels[e], row = i / l->res, col = i % l->res;
        for (int k = 0; k < NR; ++k) {
            size_t s = (e - begin) * NR + (size_t)k;
            org[s] = v3_add(l->sun_origin, v3_add(v3_scale(l->sun_u, (float)(col + lattice_a(k))),
                                                  v3_scale(l->sun_v, (float)(row + lattice_b(k)))));
            dir[s] = l->sun_dir;
            tmin[s] = 0.0f;
            tmax[s] = l->sun_tmax;
        }
    }
    vsgl__scene_intersect_many(j->scene, (uint32_t)n, org, dir, tmin, tmax, 1, hits);
    for (size_t e = begin; e < end; ++e) {
        uint32_t i = j->texels[e];
        const vsgl_hit *h = &hits[(e - begin) * NR];
        vsgl_surface sf[NR];
        int in[NR], count = 0, rep = -1;
        double best = INFINITY;
        for (int s = 0; s < NR; ++s) {
            in[s] = h[s].triangle != VSGL__HIT_NONE;
            if (!in[s])
                continue;
            vsgl__scene_surface(j->scene, &h[s], l->sun_dir, &sf[s]);
            in[s] = !vsgl__rsm_faces_out(sf[s].position, sf[s].normal, j->lo, j->hi, j->tol);
            if (!in[s])
                continue;
            ++count;
            double da = lattice_a(s) - 0.5, db = lattice_b(s) - 0.5, d2 = da * da + db * db;
            if (d2 < best) { /* the landing point nearest the texel's centre: its surface */
                best = d2;
                rep = s;
            }
        }
        if (count == 0) {
            vsgl__rsm_clear_texel(j->map, i);
            continue;
        }
        /* the mean of the points on the representative's plane */
        v3 pr = sf[rep].position, nr = sf[rep].geometric_normal, sum = v3_make(0, 0, 0);
        float near = 0.25f * v3_length(l->sun_u) + j->tol;
        int on = 0;
        for (int s = 0; s < NR; ++s)
            if (in[s] && v3_dot(sf[s].geometric_normal, nr) > 0.98f &&
                fabsf(v3_dot(v3_sub(sf[s].position, pr), nr)) <= near) {
                sum = v3_add(sum, sf[s].position);
                ++on;
            }
        v3 p = v3_scale(sum, 1.0f / (float)on);
        v3 o, d;
        double flux[3], beam;
        vsgl__rsm_light_texel(l, 0, i / l->res, i % l->res, &o, &d, flux, &beam);
        double frac = (double)count / NR;
        for (int k = 0; k < 3; ++k)
            flux[k] *= frac;
        vsgl__rsm_fill_texel(j->scene, j->map, i, &h[rep], l->sun_dir, &p, flux, beam * frac);
    }
    return 0;
}

vsgl_result vsgl__rsm_smooth_edges(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm_light *l,
                                   vsgl_rsm *r, size_t *traced)
{
    *traced = 0;
    if (l->type != VSGL_LIGHT_SUN || r->faces != 1)
        return VSGL_OK;
    const uint32_t res = r->res;
    size_t n = 0;
    uint32_t *texels = malloc((size_t)res * res * sizeof *texels);
    if (!texels)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "rsm: out of memory for the edges of a %u^2 map", res);
    for (uint32_t row = 0; row < res; ++row)
        for (uint32_t col = 0; col < res; ++col) {
            size_t i = (size_t)row * res + col;
            int k = kept(r, i);
            if ((col > 0 && kept(r, i - 1) != k) || (col + 1 < res && kept(r, i + 1) != k) ||
                (row > 0 && kept(r, i - res) != k) || (row + 1 < res && kept(r, i + res) != k))
                texels[n++] = (uint32_t)i;
        }
    edge_job j = {scene, l, r, texels, {0, 0, 0}, {0, 0, 0}, 0.0f};
    vsgl__scene_bounds(scene, &j.lo, &j.hi);
    j.tol = 1e-5f * v3_length(v3_sub(j.hi, j.lo));
    vsgl_result rc = n ? vsgl__parallel_ctx(ctx, n, CHUNK, edge_texels, &j) : VSGL_OK;
    free(texels);
    if (rc != VSGL_OK)
        return vsgl__fail(ctx, rc, "rsm: the edges of light %u: %s", r->light, vsgl_result_string(rc));
    vsgl__rsm_sum_flux(r); /* in texel order: the same for any thread count */
    *traced = n;
    return VSGL_OK;
}
