/* Brute-force VPL gathering with the exact BRDF (see brute_force.h). */
#include "shade/brute_force.h"
#include "shade/shade.h"
#include "math/constants.h"

#include "core/context.h"
#include "core/parallel.h"
#include "scene/material.h"

#include <stdlib.h>
#include <string.h>

typedef struct bf_vpl {
    v3 p, n, t, wi;
    float flux[3];
    float area;
    uint32_t material;
} bf_vpl;

typedef struct bf_job {
    const vsgl_scene *scene;
    const vsgl_gbuffer *g;
    const bf_vpl *vpl;
    size_t vpl_count;
    const vsgl_brdf_params *params;
    const vsgl_brdf_params *vpl_params; /* textured scenes: per VPL (else NULL: params[material]) */
    const vsgl_material *materials;
    uint32_t material_count;
    int visibility;
    float eps;
    size_t first;            /* first sample of this batch */
    float *dl, *gl, *dc, *gc;
} bf_job;

static v3 load(float *const a[3], size_t i) { return v3_make(a[0][i], a[1][i], a[2][i]); }

/* Is VPL point p hidden from ray origin o (a receiver, lifted onto its
 * smooth surface: gbuffer.h lift)? The segment stops short of p, measured
 * from o: from the receiver's own point it overshot p by the lift and hit
 * the VPL's own surface behind it (the sphere room's brute force lost a
 * quarter of its glossy light). */
static int occluded_from(const bf_job *j, v3 o, v3 p)
{
    v3 d = v3_sub(p, o);
    float len = v3_length(d);
    if (!(len > j->eps))
        return 0;
    return vsgl__scene_occluded(j->scene, o, v3_scale(d, 1.0f / len), j->eps, len * (1.0f - 1e-4f) - j->eps);
}

static void put3(float *plane, size_t i, const float v[3])
{
    if (plane) {
        plane[3 * i] = v[0];
        plane[3 * i + 1] = v[1];
        plane[3 * i + 2] = v[2];
    }
}

static int32_t bf_chunk(void *user, size_t chunk, size_t begin, size_t end)
{
    (void)chunk;
    const bf_job *j = user;
    const vsgl_gbuffer *g = j->g;
    for (size_t s = j->first + begin; s < j->first + end; ++s) {
        float dcol[3] = {0, 0, 0}, gcol[3] = {0, 0, 0}, dl[3] = {0, 0, 0}, gl[3] = {0, 0, 0};
        uint32_t m = g->material[s];
        if (m != VSGL__GBUFFER_MISS && m < j->material_count) {
            vsgl_brdf_params own;
            const vsgl_brdf_params *P = &j->params[m];
            if (g->surf[0]) {
                vsgl_material tm;
                vsgl__gbuffer_material(g, j->materials, s, &tm);
                vsgl__material_params(&tm, &own);
                P = &own;
            }
            v3 x = load(g->pos, s), n = load(g->nrm, s), v = load(g->view, s), t = load(g->tan, s);
            /* grazing visibility rays from the smooth surface (gbuffer.h lift) */
            const v3 lift = g->lift[0] ? load(g->lift, s) : v3_make(0.0f, 0.0f, 0.0f);
            memcpy(dcol, P->diffuse, sizeof dcol);
            float ms[3]; /* the receiver's glossy compensation towards the viewer */
            for (int c = 0; c < 3; ++c)
                ms[c] = vsgl__ms_scale(P, c, v3_dot(n, v));
            vsgl__glossy_color(P, n, v, gcol);
            double sd[3] = {0, 0, 0}, sg[3] = {0, 0, 0};
            for (size_t k = 0; k < j->vpl_count; ++k) {
                const bf_vpl *q = &j->vpl[k];
                v3 d = v3_sub(q->p, x);
                float d2 = v3_dot(d, d);
                if (!(d2 > 0.0f))
                    continue;
                float dist = sqrtf(d2);
                v3 w = v3_scale(d, 1.0f / dist);
                if (!(v3_dot(n, w) > 0.0f) || !(v3_dot(q->n, w) < 0.0f))
                    continue;
                float vd[3], vg[3], rd[3], rg[3];
                const vsgl_brdf_params *Q = j->vpl_params ? &j->vpl_params[k] : &j->params[q->material];
                vsgl__brdf_eval(Q, q->n, q->t, v3_neg(w), q->wi, vd, vg);
                /* Blender 4.x+: the VPL's diffuse base dimmed and its glossy lobe
                 * compensated as seen from x (its view) */
                float cq = -v3_dot(q->n, w);
                float wq = vsgl__scene_diffuse_weight(j->scene, q->material, cq);
                float e[3];
                for (int c = 0; c < 3; ++c)
                    e[c] = q->flux[c] * (vd[c] * wq + vg[c] * vsgl__ms_scale(Q, c, cq));
                if (!(e[0] + e[1] + e[2] > 0.0f))
                    continue;
                vsgl__brdf_eval(P, n, t, w, v, rd, rg);
                if (!(rd[0] + rd[1] + rd[2] + rg[0] + rg[1] + rg[2] > 0.0f))
                    continue;
                if (j->visibility && occluded_from(j, vsgl__lifted_origin(x, x, n, lift, q->p), q->p))
                    continue;
                double inv = 1.0 / ((double)d2 + (double)q->area * (1.0 / VSGL__PI_D));
                for (int c = 0; c < 3; ++c) {
                    sd[c] += (double)e[c] * rd[c] * inv;
                    sg[c] += (double)e[c] * rg[c] * ms[c] * inv;
                }
            }
            /* Blender 4.x+: the colour of the diffuse base seen from v (the light stays) */
            float wd = vsgl__scene_diffuse_weight(j->scene, m, v3_dot(n, v));
            for (int c = 0; c < 3; ++c) {
                dl[c] = dcol[c] > 0.0f ? (float)(sd[c] / dcol[c]) : 0.0f;
                gl[c] = gcol[c] > 0.0f ? (float)(sg[c] / gcol[c]) : 0.0f;
                dcol[c] *= wd;
            }
        }
        put3(j->dl, s, dl);
        put3(j->gl, s, gl);
        put3(j->dc, s, dcol);
        put3(j->gc, s, gcol);
    }
    return 0;
}

vsgl_result vsgl__brute_force_shade(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_gbuffer *g,
                                    const vsgl_rsm *rsms, uint32_t rsm_count, int visibility,
                                    float *diffuse_light, float *glossy_light,
                                    float *diffuse_color, float *glossy_color)
{
    uint32_t mc = 0;
    const vsgl_material *mats = vsgl__scene_materials(scene, &mc);
    size_t nv = 0;
    for (uint32_t r = 0; r < rsm_count; ++r)
        for (size_t i = 0; i < rsms[r].count; ++i)
            nv += rsms[r].material[i] != VSGL__RSM_EMPTY && rsms[r].material[i] < mc &&
                  rsms[r].flux[0][i] + rsms[r].flux[1][i] + rsms[r].flux[2][i] > 0.0f;
    vsgl_brdf_params *params = malloc((mc ? mc : 1) * sizeof *params);
    bf_vpl *vpl = malloc((nv ? nv : 1) * sizeof *vpl);
    if (!params || !vpl) {
        free(params);
        free(vpl);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "gather: out of memory for %zu VPLs", nv);
    }
    for (uint32_t i = 0; i < mc; ++i)
        vsgl__material_params(&mats[i], &params[i]);
    vsgl_brdf_params *vpl_params = NULL;
    if (vsgl__scene_textured(scene)) {
        vpl_params = malloc((nv ? nv : 1) * sizeof *vpl_params);
        if (!vpl_params) {
            free(params);
            free(vpl);
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "gather: out of memory for %zu VPLs", nv);
        }
    }
    size_t k = 0;
    for (uint32_t r = 0; r < rsm_count; ++r) {
        const vsgl_rsm *R = &rsms[r];
        for (size_t i = 0; i < R->count; ++i) {
            if (!(R->material[i] != VSGL__RSM_EMPTY && R->material[i] < mc &&
                  R->flux[0][i] + R->flux[1][i] + R->flux[2][i] > 0.0f))
                continue;
            bf_vpl *q = &vpl[k++];
            q->p = load(R->pos, i);
            q->n = load(R->nrm, i);
            q->t = load(R->tan, i);
            q->wi = load(R->wi, i);
            for (int c = 0; c < 3; ++c)
                q->flux[c] = R->flux[c][i];
            q->area = R->area[i];
            q->material = R->material[i];
            if (vpl_params) {
                vsgl_material tm;
                vsgl__rsm_material(R, mats, i, &tm);
                vsgl__material_params(&tm, &vpl_params[k - 1]);
            }
        }
    }
    v3 lo, hi;
    vsgl__scene_bounds(scene, &lo, &hi);
    float ext = fmaxf(fmaxf(hi.x - lo.x, hi.y - lo.y), hi.z - lo.z);
    float mag = fmaxf(fmaxf(fmaxf(fabsf(lo.x), fabsf(hi.x)), fmaxf(fabsf(lo.y), fabsf(hi.y))), fmaxf(fabsf(lo.z), fabsf(hi.z)));
    float eps = 1e-4f * fmaxf(ext, 1e-3f) + 1e-6f * mag;
    if (!(eps < INFINITY))
        eps = 1e-4f;

    size_t n = g->count, batch = n / 32 > 256 ? n / 32 : 256;
    uint32_t threads = vsgl_context_thread_count(ctx);
    vsgl_result res = VSGL_OK;
    for (size_t b = 0; b < n && res == VSGL_OK; b += batch) {
        size_t e = b + batch < n ? b + batch : n;
        bf_job j = {scene, g, vpl, nv, params, vpl_params, mats, mc, visibility, eps, b,
                    diffuse_light, glossy_light, diffuse_color, glossy_color};
        res = vsgl__parallel_for(threads, e - b, 64, bf_chunk, &j);
        if (res != VSGL_OK)
            res = vsgl__fail(ctx, res, "gather: %s", vsgl_result_string(res));
        else if (vsgl__progress(ctx, "gather", (float)e / (float)n))
            res = vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "gather: cancelled");
    }
    free(params);
    free(vpl_params);
    free(vpl);
    return res;
}

void vsgl__brute_force_resolve(const vsgl_gbuffer *g, const float *sample_light, const float *sample_color,
                               float *pixel_light, float *pixel_color)
{
    if (!sample_light || !sample_color)
        return;
    size_t px = (size_t)g->width * g->height, spp = g->spp ? g->spp : 1;
    for (size_t p = 0; p < px; ++p)
        for (int c = 0; c < 3; ++c) {
            double lc = 0, col = 0;
            for (size_t s = 0; s < spp; ++s) {
                size_t i = 3 * (p * spp + s) + (size_t)c;
                double w = vsgl__gbuffer_weight(g, p * spp + s);
                lc += w * sample_light[i] * sample_color[i];
                col += w * sample_color[i];
            }
            if (pixel_color)
                pixel_color[3 * p + (size_t)c] = (float)col;
            if (pixel_light)
                pixel_light[3 * p + (size_t)c] = col > 0 ? (float)(lc / col) : 0.0f;
        }
}
