/* Reflective shadow maps: one ray per texel from the light, the hit becomes
 * a VPL carrying the power the light emits into the texel (rsm_light.c).
 * Rows are traced in parallel (deterministic chunks of one row); progress
 * is reported between batches of rows from the calling thread. Each row's
 * flux is summed in row order: the same map for any thread count or batch. */
#include "rsm/rsm.h"

#include "core/context.h"
#include "core/parallel.h"
#include "rsm/rsm_light.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void vsgl__rsm_free(vsgl_rsm *r)
{
    if (!r)
        return;
    for (int k = 0; k < 3; ++k) {
        free(r->pos[k]);
        free(r->nrm[k]);
        free(r->tan[k]);
        free(r->wi[k]);
        free(r->flux[k]);
    }
    free(r->material);
    free(r->part);
    free(r->area);
    for (int k = 0; k < VSGL__SURF_N; ++k)
        free(r->surf[k]);
    memset(r, 0, sizeof *r);
}

void vsgl__rsm_material(const vsgl_rsm *r, const vsgl_material *materials, size_t i, vsgl_material *out)
{
    const vsgl_material *m = &materials[r->material[i]];
    if (!r->surf[0]) {
        *out = *m;
        return;
    }
    float in[VSGL__SURF_N];
    for (int q = 0; q < VSGL__SURF_N; ++q)
        in[q] = r->surf[q][i];
    vsgl__material_with_inputs(m, in, out);
}

typedef struct rsm_job {
    const vsgl_scene *scene;
    const vsgl_rsm_light *light;
    vsgl_rsm *out;
    size_t first_row;        /* global row (face * res + row) of chunk 0 */
    double *partial;         /* per row: flux sums (3) */
} rsm_job;

/* A texel at p whose surface faces out of the scene: every corner of the
 * scene's box lies behind its tangent plane (normal n, within tol), so
 * nothing is in front of it to light (the outside of a room's walls and
 * roof under a sun). */
int vsgl__rsm_faces_out(v3 p, v3 n, v3 lo, v3 hi, float tol)
{
    for (int c = 0; c < 8; ++c) {
        v3 q = v3_make(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
        if (v3_dot(v3_sub(q, p), n) > tol)
            return 0;
    }
    return 1;
}

void vsgl__rsm_clear_texel(vsgl_rsm *o, size_t i)
{
    for (int k = 0; k < 3; ++k)
        o->pos[k][i] = o->nrm[k][i] = o->tan[k][i] = o->wi[k][i] = o->flux[k][i] = 0.0f;
    o->material[i] = VSGL__RSM_EMPTY;
    if (o->part)
        o->part[i] = VSGL__PART_NONE;
    o->area[i] = 0.0f;
    if (o->surf[0])
        for (int q = 0; q < VSGL__SURF_N; ++q)
            o->surf[q][i] = 0.0f;
}

void vsgl__rsm_fill_texel(const vsgl_scene *scene, vsgl_rsm *o, size_t i, const vsgl_hit *hit, v3 dir,
                          const v3 *position, const double flux[3], double beam)
{
    vsgl_surface sf;
    vsgl__scene_surface(scene, hit, dir, &sf);
    v3 wi = v3_neg(dir), p = position ? *position : sf.position;
    o->pos[0][i] = p.x; o->pos[1][i] = p.y; o->pos[2][i] = p.z;
    o->nrm[0][i] = sf.normal.x; o->nrm[1][i] = sf.normal.y; o->nrm[2][i] = sf.normal.z;
    o->tan[0][i] = sf.tangent.x; o->tan[1][i] = sf.tangent.y; o->tan[2][i] = sf.tangent.z;
    o->wi[0][i] = wi.x; o->wi[1][i] = wi.y; o->wi[2][i] = wi.z;
    /* footprint: beam / cos at the surface */
    double cs = fabs((double)v3_dot(sf.geometric_normal, wi));
    o->area[i] = (float)(beam / fmax(cs, 1e-3));
    for (int k = 0; k < 3; ++k)
        o->flux[k][i] = (float)flux[k];
    o->material[i] = sf.material;
    if (o->part)
        o->part[i] = sf.part;
    if (o->surf[0]) {
        float in[VSGL__SURF_N];
        vsgl__scene_inputs(scene, hit, o->area[i], in);
        for (int q = 0; q < VSGL__SURF_N; ++q)
            o->surf[q][i] = in[q];
    }
}

static int32_t rsm_rows(void *user, size_t chunk, size_t begin, size_t end)
{
    (void)chunk;
    rsm_job *j = user;
    const vsgl_rsm_light *l = j->light;
    vsgl_rsm *o = j->out;
    uint32_t res = o->res;
    v3 *org = malloc(res * sizeof *org);
    v3 *dir = malloc(res * sizeof *dir);
    float *tmin = malloc(res * sizeof *tmin);
    float *tmax = malloc(res * sizeof *tmax);
    vsgl_hit *hits = malloc(res * sizeof *hits);
    double *fl = malloc(res * 4 * sizeof *fl);
    double *scratch = malloc(VSGL__RSM_ROW_SCRATCH(res) * sizeof *scratch);
    int *lit = malloc(res * sizeof *lit);
    if (!org || !dir || !tmin || !tmax || !hits || !fl || !scratch || !lit) {
        free(org); free(dir); free(tmin); free(tmax); free(hits); free(fl); free(scratch); free(lit);
        return VSGL_ERROR_OUT_OF_MEMORY;
    }
    for (size_t gr = begin; gr < end; ++gr) {
        size_t grow = j->first_row + gr;
        uint32_t face = (uint32_t)(grow / res), row = (uint32_t)(grow % res);
        vsgl__rsm_light_row(l, face, row, org, dir, fl, lit, scratch);
        for (uint32_t c = 0; c < res; ++c) {
            tmin[c] = 0.0f;
            tmax[c] = lit[c] ? (l->type == VSGL_LIGHT_SUN ? l->sun_tmax : INFINITY) : -1.0f;
        }
        vsgl__scene_intersect_many(j->scene, res, org, dir, tmin, tmax, 1, hits);
        double s[3] = {0, 0, 0};
        for (uint32_t c = 0; c < res; ++c) {
            size_t i = grow * res + c;
            if (hits[c].triangle == VSGL__HIT_NONE || !(tmax[c] >= 0.0f)) {
                vsgl__rsm_clear_texel(o, i);
                continue;
            }
            double t2 = l->type == VSGL_LIGHT_SUN ? 1.0 : (double)hits[c].t * hits[c].t;
            vsgl__rsm_fill_texel(j->scene, o, i, &hits[c], dir[c], NULL, &fl[4 * c], fl[4 * c + 3] * t2);
            for (int k = 0; k < 3; ++k)
                s[k] += (double)o->flux[k][i];
        }
        for (int k = 0; k < 3; ++k)
            j->partial[3 * (grow - j->first_row) + k] = s[k];
    }
    free(org); free(dir); free(tmin); free(tmax); free(hits); free(fl); free(scratch); free(lit);
    return 0;
}

/* The map of `light` over the window (zoom, col0, row0); lout (may be
 * NULL) receives the light as set up for it. */
static vsgl_result build(vsgl_context *ctx, const vsgl_scene *scene, uint32_t light, uint32_t res, uint32_t zoom,
                         int64_t col0, int64_t row0, vsgl_rsm *out, vsgl_rsm_light *lout)
{
    memset(out, 0, sizeof *out);
    uint32_t nl = 0;
    vsgl__scene_lights(scene, &nl);
    if (light >= nl)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "rsm: light %u out of range (%u lights)", light, nl);
    if (res < 1 || res > 16384)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "rsm: resolution %u (valid 1..16384)", res);
    vsgl_rsm_light l;
    vsgl__rsm_light_setup(scene, light, res, &l);
    vsgl__rsm_light_window(&l, zoom, col0, row0);
    if (lout)
        *lout = l;
    out->light = light;
    out->zoom = l.type == VSGL_LIGHT_SUN && zoom > 1 ? zoom : 1;
    out->faces = l.faces;
    out->res = res;
    out->count = (size_t)l.faces * res * res;
    size_t n = out->count;
    int ok = 1;
    for (int k = 0; k < 3; ++k) {
        ok &= (out->pos[k] = malloc(n * sizeof(float))) != NULL;
        ok &= (out->nrm[k] = malloc(n * sizeof(float))) != NULL;
        ok &= (out->tan[k] = malloc(n * sizeof(float))) != NULL;
        ok &= (out->wi[k] = malloc(n * sizeof(float))) != NULL;
        ok &= (out->flux[k] = malloc(n * sizeof(float))) != NULL;
    }
    ok &= (out->material = malloc(n * sizeof(uint32_t))) != NULL;
    ok &= (out->part = malloc(n * sizeof(uint32_t))) != NULL;
    ok &= (out->area = malloc(n * sizeof(float))) != NULL;
    if (vsgl__scene_textured(scene))
        for (int k = 0; k < VSGL__SURF_N; ++k)
            ok &= (out->surf[k] = malloc(n * sizeof(float))) != NULL;
    size_t rows = (size_t)l.faces * res;
    double *partial = ok ? malloc(rows * 3 * sizeof *partial) : NULL;
    if (!ok || !partial) {
        vsgl__rsm_free(out);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "rsm: out of memory for %zu texels", n);
    }
    /* batches of rows so that progress and cancel run on this thread: 16,
     * but none under 2^16 texels (each batch waits for its slowest row: a
     * live light edit's 128^2 map is one batch, not 16) */
    size_t batch = rows / 16 > 0 ? rows / 16 : 1, min_rows = ((size_t)1 << 16) / res + 1;
    if (batch < min_rows)
        batch = min_rows;
    vsgl_result r = VSGL_OK;
    for (size_t b = 0; b < rows && r == VSGL_OK; b += batch) {
        size_t e = b + batch < rows ? b + batch : rows;
        rsm_job j = {scene, &l, out, b, partial + 3 * b};
        r = vsgl__parallel_ctx(ctx, e - b, 1, rsm_rows, &j);
        if (r != VSGL_OK)
            r = vsgl__fail(ctx, r, "rsm: light %u: %s", light, vsgl_result_string(r));
        else if (vsgl__progress(ctx, "rsm", (float)e / (float)rows))
            r = vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "rsm: cancelled");
    }
    if (r != VSGL_OK) {
        free(partial);
        vsgl__rsm_free(out);
        return r;
    }
    /* sum in row order: bit-identical for any thread count */
    for (int k = 0; k < 3; ++k)
        out->total_flux[k] = 0.0;
    for (size_t i = 0; i < rows; ++i)
        for (int k = 0; k < 3; ++k)
            out->total_flux[k] += partial[3 * i + k];
    free(partial);
    return VSGL_OK;
}

vsgl_result vsgl__rsm_build(vsgl_context *ctx, const vsgl_scene *scene, uint32_t light, uint32_t res, vsgl_rsm *out)
{
    return build(ctx, scene, light, res, 1, 0, 0, out, NULL);
}

/* The edges of map `out` smoothed; l: its light as built. */
static vsgl_result smooth(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm_light *l, vsgl_rsm *out)
{
    size_t traced;
    vsgl_result r = vsgl__rsm_smooth_edges(ctx, scene, l, out, &traced);
    if (r != VSGL_OK)
        vsgl__rsm_free(out);
    else
        vsgl__log(ctx, VSGL_LOG_DEBUG, "rsm: light %u: %zu texels at the edge of its light traced again with %d rays "
                  "each", out->light, traced, VSGL__RSM_EDGE_RAYS);
    return r;
}

vsgl_result vsgl__rsm_build_inward(vsgl_context *ctx, const vsgl_scene *scene, uint32_t light, uint32_t res,
                                   vsgl_rsm *out, double dropped[3])
{
    vsgl_rsm_light l;
    vsgl_result r = build(ctx, scene, light, res, 1, 0, 0, out, &l);
    if (r != VSGL_OK)
        return r;
    vsgl__rsm_drop_outward(scene, out, dropped);
    uint32_t n = 0;
    if (vsgl__scene_lights(scene, &n)[light].type != VSGL_LIGHT_SUN || out->faces != 1)
        return VSGL_OK;
    /* the texels left: their bounding square, one texel wider on each side
     * (the region they sample ends within a texel of their centres) */
    int64_t c0 = res, c1 = -1, r0 = res, r1 = -1;
    for (uint32_t row = 0; row < res; ++row)
        for (uint32_t col = 0; col < res; ++col)
            if (out->material[(size_t)row * res + col] != VSGL__RSM_EMPTY) {
                c0 = col < c0 ? col : c0; c1 = col > c1 ? col : c1;
                r0 = row < r0 ? row : r0; r1 = row > r1 ? row : r1;
            }
    if (c1 < 0)
        return VSGL_OK;
    int64_t side = (c1 - c0 > r1 - r0 ? c1 - c0 : r1 - r0) + 3;
    uint32_t zoom = 1;
    while (zoom < VSGL__RSM_MAX_ZOOM && side * (int64_t)zoom * 2 <= (int64_t)res)
        zoom *= 2;
    if (zoom == 1)
        return smooth(ctx, scene, &l, out);
    /* the square centred on them, on the grid refined zoom times */
    int64_t pad_c = ((int64_t)res - (c1 - c0 + 3) * (int64_t)zoom) / 2,
            pad_r = ((int64_t)res - (r1 - r0 + 3) * (int64_t)zoom) / 2;
    int64_t col0 = (c0 - 1) * zoom - pad_c, row0 = (r0 - 1) * zoom - pad_r;
    vsgl_rsm fine_map;
    r = build(ctx, scene, light, res, zoom, col0, row0, &fine_map, &l);
    if (r != VSGL_OK) {
        vsgl__rsm_free(out);
        return r;
    }
    vsgl__rsm_free(out);
    *out = fine_map;
    double again[3]; /* the power dropped is the first map's: the same light on the same faces */
    vsgl__rsm_drop_outward(scene, out, again);
    return smooth(ctx, scene, &l, out);
}

void vsgl__rsm_drop_outward(const vsgl_scene *scene, vsgl_rsm *r, double dropped[3])
{
    v3 lo, hi;
    vsgl__scene_bounds(scene, &lo, &hi);
    float tol = 1e-5f * v3_length(v3_sub(hi, lo));
    for (int k = 0; k < 3; ++k)
        dropped[k] = 0.0;
    for (size_t i = 0; i < r->count; ++i) {
        if (r->material[i] == VSGL__RSM_EMPTY)
            continue;
        v3 p = v3_make(r->pos[0][i], r->pos[1][i], r->pos[2][i]), n = v3_make(r->nrm[0][i], r->nrm[1][i], r->nrm[2][i]);
        if (!vsgl__rsm_faces_out(p, n, lo, hi, tol))
            continue;
        for (int k = 0; k < 3; ++k)
            dropped[k] += (double)r->flux[k][i];
        vsgl__rsm_clear_texel(r, i);
    }
    if (!(dropped[0] + dropped[1] + dropped[2] > 0.0))
        return; /* nothing dropped: the total as built */
    vsgl__rsm_sum_flux(r); /* the sum of what is left, not a difference (no rounding residue) */
}

void vsgl__rsm_sum_flux(vsgl_rsm *r)
{
    for (int k = 0; k < 3; ++k)
        r->total_flux[k] = 0.0;
    for (size_t i = 0; i < r->count; ++i)
        for (int k = 0; k < 3; ++k)
            r->total_flux[k] += (double)r->flux[k][i];
}
