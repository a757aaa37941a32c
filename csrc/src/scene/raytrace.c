/* Ray queries on a built scene (Embree 3) and surface attributes at hits. */
#include "scene/scene_data.h"
#include "math/constants.h"

#include <math.h>
#include <string.h>


static void fill_ray(struct RTCRay *r, v3 org, v3 dir, float tmin, float tmax)
{
    r->org_x = org.x;
    r->org_y = org.y;
    r->org_z = org.z;
    r->tnear = tmin;
    r->dir_x = dir.x;
    r->dir_y = dir.y;
    r->dir_z = dir.z;
    r->time = 0.0f;
    r->tfar = tmax;
    r->mask = 0xFFFFFFFFu;
    r->id = 0;
    r->flags = 0;
}

int vsgl__scene_intersect(const vsgl_scene *scene, v3 org, v3 dir, float tmin, float tmax, vsgl_hit *hit)
{
    if (scene->triangle_count == 0 || !(tmin <= tmax))
        return 0;
    struct RTCIntersectContext ic;
    rtcInitIntersectContext(&ic);
    struct RTCRayHit rh;
    fill_ray(&rh.ray, org, dir, tmin, tmax);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene->rtc, &ic, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    hit->t = rh.ray.tfar;
    hit->triangle = rh.hit.primID;
    hit->u = rh.hit.u;
    hit->v = rh.hit.v;
    return 1;
}

/* 1 if the segment org + [tmin, tmax] dir is proven unblocked from bounds
 * (scene/occluders.c); 0: trace it. */
static int proven_clear(const vsgl_scene *scene, v3 org, v3 dir, float tmin, float tmax)
{
    return vsgl__scene_segment_clear(scene, v3_add(org, v3_scale(dir, tmin)), v3_add(org, v3_scale(dir, tmax)));
}

int vsgl__scene_occluded(const vsgl_scene *scene, v3 org, v3 dir, float tmin, float tmax)
{
    if (scene->triangle_count == 0 || !(tmin <= tmax) || proven_clear(scene, org, dir, tmin, tmax))
        return 0;
    struct RTCIntersectContext ic;
    rtcInitIntersectContext(&ic);
    struct RTCRay r;
    fill_ray(&r, org, dir, tmin, tmax);
    rtcOccluded1(scene->rtc, &ic, &r);
    return r.tfar == -INFINITY;
}

void vsgl__scene_intersect_many(const vsgl_scene *scene, uint32_t n, const v3 *org, const v3 *dir,
                                const float *tmin, const float *tmax, int coherent, vsgl_hit *hits)
{
    enum { BATCH = 64 };
    struct RTCRayHit rh[BATCH];
    struct RTCIntersectContext ic;
    rtcInitIntersectContext(&ic);
    ic.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    for (uint32_t b = 0; b < n; b += BATCH) {
        uint32_t m = n - b < BATCH ? n - b : BATCH;
        for (uint32_t i = 0; i < m; ++i) {
            float lo = tmin[b + i], hi = tmax[b + i];
            if (!(lo <= hi) || scene->triangle_count == 0) { /* an empty interval never hits */
                lo = 0.0f;
                hi = -INFINITY;
            }
            fill_ray(&rh[i].ray, org[b + i], dir[b + i], lo, hi < lo ? lo : hi);
            if (hi < lo)
                rh[i].ray.tfar = -INFINITY;
            rh[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh[i].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        }
        if (scene->triangle_count > 0)
            rtcIntersect1M(scene->rtc, &ic, rh, m, sizeof(struct RTCRayHit));
        for (uint32_t i = 0; i < m; ++i) {
            vsgl_hit *h = &hits[b + i];
            if (rh[i].hit.geomID == RTC_INVALID_GEOMETRY_ID) {
                h->t = INFINITY;
                h->triangle = VSGL__HIT_NONE;
                h->u = h->v = 0.0f;
            } else {
                h->t = rh[i].ray.tfar;
                h->triangle = rh[i].hit.primID;
                h->u = rh[i].hit.u;
                h->v = rh[i].hit.v;
            }
        }
    }
}

void vsgl__scene_occluded_many(const vsgl_scene *scene, uint32_t n, const v3 *org, const v3 *dir,
                               const float *tmin, const float *tmax, int coherent, unsigned char *blocked)
{
    enum { BATCH = 64 };
    struct RTCRay r[BATCH];
    struct RTCIntersectContext ic;
    rtcInitIntersectContext(&ic);
    ic.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    uint32_t idx[BATCH];
    uint32_t b = 0;
    while (b < n) {
        /* the next up to BATCH rays that need tracing: empty intervals are
         * unblocked without a ray. Not the bounds test of the single query:
         * in a coherent stream Embree's ray costs less than the test (the
         * balanced shade stage at 960 x 540: sun room 1.61 -> 1.38 s, sphere
         * room 3.44 -> 3.34 s, a 500k-triangle floor 8.97 -> 8.90 s without
         * it, once the visibility budget had cut the rays) */
        uint32_t m = 0;
        for (; b < n && m < BATCH; ++b) {
            float lo = tmin[b], hi = tmax[b];
            blocked[b] = 0;
            if (scene->triangle_count == 0 || !(lo <= hi))
                continue;
            fill_ray(&r[m], org[b], dir[b], lo, hi);
            idx[m++] = b;
        }
        if (m == 0)
            continue;
        rtcOccluded1M(scene->rtc, &ic, r, m, sizeof(struct RTCRay)); /* a blocked ray gets tfar = -inf */
        for (uint32_t i = 0; i < m; ++i)
            blocked[idx[i]] = (unsigned char)(r[i].tfar == -INFINITY);
    }
}

/* Segments strictly inside the bounds of a scene whose occluders are none
 * or few (occluders.c): those go to the occluders' own test (occlude_few.c),
 * or are clear when there are none; the rest are traced (blocked[] as
 * vsgl__scene_occluded_towards_each). */
static void occluded_few_towards_each(const vsgl_scene *scene, uint32_t n, const uint32_t *lane, const float *ox,
                                      const float *oy, const float *oz, const float *const tgt[3], float eps,
                                      unsigned char *blocked)
{
    enum { BATCH = VSGL__OCC_STREAM };
    float sx[BATCH], sy[BATCH], sz[BATCH], ex[BATCH], ey[BATCH], ez[BATCH], inv[BATCH], reach[BATCH];
    int route[BATCH];
    unsigned char hit[BATCH];
    v3 org[BATCH], dir[BATCH];
    float t0[BATCH], t1[BATCH];
    uint32_t idx[BATCH];
    unsigned char traced[BATCH];
    for (uint32_t b = 0; b < n;) {
        uint32_t c = n - b < BATCH ? n - b : BATCH, m = 0;
        for (uint32_t i = 0; i < c; ++i) { /* gather */
            uint32_t k = lane[b + i];
            sx[i] = ox[k], sy[i] = oy[k], sz[i] = oz[k];
            ex[i] = tgt[0][k] - ox[k], ey[i] = tgt[1][k] - oy[k], ez[i] = tgt[2][k] - oz[k];
        }
        vsgl__scene_segments_route(scene, c, sx, sy, sz, ex, ey, ez, eps, inv, reach, route);
        if (scene->occ_few)
            vsgl__scene_occluded_few(scene, c, sx, sy, sz, ex, ey, ez, reach, hit);
        for (uint32_t i = 0; i < c; ++i) {
            blocked[b + i] = route[i] == 2 && scene->occ_few ? hit[i] : 0;
            if (route[i] == 1) { /* an end at or past the bounds: the whole scene */
                org[m] = v3_make(sx[i], sy[i], sz[i]);
                dir[m] = v3_make(ex[i] * inv[i], ey[i] * inv[i], ez[i] * inv[i]);
                t0[m] = 0.0f;
                t1[m] = 1.0f / inv[i] - eps;
                idx[m++] = b + i;
            }
        }
        if (m) {
            vsgl__scene_occluded_many(scene, m, org, dir, t0, t1, 1, traced);
            for (uint32_t i = 0; i < m; ++i)
                blocked[idx[i]] = traced[i];
        }
        b += c;
    }
}

void vsgl__scene_occluded_towards_each(const vsgl_scene *scene, uint32_t n, const uint32_t *lane, const float *ox,
                                       const float *oy, const float *oz, const float *const tgt[3], float eps,
                                       unsigned char *blocked)
{
    if (scene->triangle_count > 0 && (scene->occ_few || scene->occ_triangles == 0)) {
        occluded_few_towards_each(scene, n, lane, ox, oy, oz, tgt, eps, blocked);
        return;
    }
    enum { BATCH = 64 };
    float rx[BATCH], ry[BATCH], rz[BATCH], dx[BATCH], dy[BATCH], dz[BATCH], t0[BATCH], t1[BATCH], tm[BATCH];
    unsigned int mask[BATCH], id[BATCH], flags[BATCH];
    uint32_t idx[BATCH];
    struct RTCRayNp rays = {rx, ry, rz, t0, dx, dy, dz, tm, t1, mask, id, flags};
    struct RTCIntersectContext ic;
    rtcInitIntersectContext(&ic);
    ic.flags = scene->triangle_count >= VSGL__RAY_INCOHERENT_MIN ? RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT
                                                                 : RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    for (uint32_t b = 0; b < n;) {
        uint32_t c = n - b < BATCH ? n - b : BATCH, m = 0;
        /* the segments longer than eps, packed to the front */
        for (uint32_t i = 0; i < c; ++i) {
            uint32_t k = lane[b + i];
            float ex = tgt[0][k] - ox[k], ey = tgt[1][k] - oy[k], ez = tgt[2][k] - oz[k];
            float dist = sqrtf(ex * ex + ey * ey + ez * ez), inv = 1.0f / dist;
            blocked[b + i] = 0;
            if (scene->triangle_count == 0 || !(dist > eps))
                continue;
            rx[m] = ox[k]; ry[m] = oy[k]; rz[m] = oz[k];
            dx[m] = ex * inv; dy[m] = ey * inv; dz[m] = ez * inv;
            t0[m] = 0.0f; t1[m] = dist - eps; tm[m] = 0.0f;
            mask[m] = 0xFFFFFFFFu; id[m] = 0; flags[m] = 0;
            idx[m++] = b + i;
        }
        b += c;
        if (m == 0)
            continue;
        rtcOccludedNp(scene->rtc, &ic, &rays, m);
        for (uint32_t i = 0; i < m; ++i)
            blocked[idx[i]] = (unsigned char)(t1[i] == -INFINITY);
    }
}

static v3 load3(const float *p) { return v3_make(p[0], p[1], p[2]); }

static v3 interp(v3 a, v3 b, v3 c, float w, float u, float v)
{
    return v3_add(v3_add(v3_scale(a, w), v3_scale(b, u)), v3_scale(c, v));
}

/* Component of t orthogonal to unit n, normalised; zero if degenerate. */
static v3 orthogonalize(v3 t, v3 n)
{
    return v3_normalize(v3_sub(t, v3_scale(n, v3_dot(n, t))));
}

v3 vsgl__scene_smooth_point(const vsgl_scene *scene, const vsgl_hit *hit, const vsgl_surface *sf)
{
    uint32_t tri = hit->triangle;
    const uint32_t *ix = scene->indices + (size_t)tri * 3;
    const float *cn = scene->corner_normals + (size_t)tri * 9;
    const float b[3] = {1.0f - hit->u - hit->v, hit->u, hit->v};
    const float side = v3_dot(load3(scene->face_normals + (size_t)tri * 3), sf->geometric_normal) < 0.0f ? -1.0f : 1.0f;
    v3 p = sf->position, lift = v3_make(0.0f, 0.0f, 0.0f);
    for (int k = 0; k < 3; ++k) {
        v3 n = v3_scale(load3(cn + 3 * k), side);
        float below = v3_dot(v3_sub(p, load3(scene->positions + (size_t)ix[k] * 3)), n);
        if (below < 0.0f)
            lift = v3_sub(lift, v3_scale(n, b[k] * below));
    }
    return v3_add(p, lift);
}

int vsgl__scene_smooth(const vsgl_scene *scene)
{
    return scene->smooth;
}

void vsgl__scene_surface(const vsgl_scene *scene, const vsgl_hit *hit, v3 dir, vsgl_surface *out)
{
    uint32_t tri = hit->triangle;
    const uint32_t *ix = scene->indices + (size_t)tri * 3;
    float u = hit->u, v = hit->v, w = 1.0f - u - v;
    v3 p0 = load3(scene->positions + (size_t)ix[0] * 3);
    v3 p1 = load3(scene->positions + (size_t)ix[1] * 3);
    v3 p2 = load3(scene->positions + (size_t)ix[2] * 3);
    out->position = interp(p0, p1, p2, w, u, v);

    v3 ng = load3(scene->face_normals + (size_t)tri * 3);
    const float *cn = scene->corner_normals + (size_t)tri * 9;
    v3 n = v3_normalize(interp(load3(cn), load3(cn + 3), load3(cn + 6), w, u, v));
    if (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f)
        n = ng; /* opposite corner normals cancelled: fall back to the face */
    /* back-facing: flip both to the side the ray came from (as Cycles does) */
    int back = v3_dot(ng, dir) > 0.0f;
    if (back) {
        ng = v3_neg(ng);
        n = v3_neg(n);
    }
    out->part = vsgl__scene_part_key(scene, tri, back);
    out->normal = n;
    out->geometric_normal = ng;

    v3 t = v3_make(0.0f, 0.0f, 0.0f);
    if (scene->corner_tangents) {
        const float *ct = scene->corner_tangents + (size_t)tri * 12;
        t = orthogonalize(interp(load3(ct), load3(ct + 4), load3(ct + 8), w, u, v), n);
    }
    if (t.x == 0.0f && t.y == 0.0f && t.z == 0.0f && scene->corner_uvs) {
        /* dP/du from the triangle's UV parametrisation */
        const float *uv = scene->corner_uvs + (size_t)tri * 6;
        float du1 = uv[2] - uv[0], dv1 = uv[3] - uv[1];
        float du2 = uv[4] - uv[0], dv2 = uv[5] - uv[1];
        float det = du1 * dv2 - du2 * dv1;
        if (det != 0.0f && isfinite(1.0f / det)) {
            v3 e1 = v3_sub(p1, p0), e2 = v3_sub(p2, p0);
            v3 dpdu = v3_scale(v3_sub(v3_scale(e1, dv2), v3_scale(e2, dv1)), 1.0f / det);
            t = orthogonalize(dpdu, n);
        }
    }
    if (t.x == 0.0f && t.y == 0.0f && t.z == 0.0f)
        t = orthogonalize(v3_sub(p1, p0), n);
    if (t.x == 0.0f && t.y == 0.0f && t.z == 0.0f) {
        v3 b;
        v3_basis(n, &t, &b);
    }
    uint32_t mat = scene->tri_material[tri];
    float rot = scene->materials[mat].anisotropic_rotation;
    if (rot != 0.0f) {
        /* rotate about n by 2 pi rot, counter-clockwise (Rodrigues, t orthogonal to n) */
        float a = VSGL__2PI * rot;
        t = v3_normalize(v3_add(v3_scale(t, cosf(a)), v3_scale(v3_cross(n, t), sinf(a))));
    }
    out->tangent = t;
    out->material = mat;
}

uint32_t vsgl__scene_source_triangle(const vsgl_scene *scene, uint32_t triangle)
{
    return scene->source_triangle[triangle];
}
