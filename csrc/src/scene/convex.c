/* Is the scene a convex shell? Every triangle's plane has every vertex of
 * the scene on one side (within a tolerance): then all surfaces lie on the
 * boundary of their convex hull, and the segment between two surface points
 * runs through the hull's inside, meeting the surfaces only at its ends
 * (or within one face's plane, where the cosines are 0). Nothing can block
 * light between two surfaces: visibility rays find nothing (render.c skips
 * them). Empty closed rooms (a box, a room without furniture) are such
 * scenes; a window hole, an object or a second room is not. */
#include "scene/scene_data.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Above this many triangles the test is not run (answer: not convex): it
 * costs triangles x vertices in the worst case. */
#define VSGL__CONVEX_MAX_TRIANGLES 2048u

/* Where vertices verts[0, m) (NULL: vertices 0 .. m - 1) lie against the
 * plane of triangle t: bit 1 some lie in front of its face normal by more
 * than eps, bit 2 some behind (3: on both sides; the scan stops there).
 * *tested: how many vertices were tested. The shell and the parts' test. */
#define SIDE_FRONT 1
#define SIDE_BEHIND 2
static int plane_sides(const vsgl_scene *s, uint32_t t, const uint32_t *verts, uint32_t m, double eps,
                       uint32_t *tested)
{
    const float *n = s->face_normals + 3 * (size_t)t;
    const float *p = s->positions + 3 * (size_t)s->indices[3 * (size_t)t];
    int sides = 0;
    uint32_t k = 0;
    for (; k < m && sides != (SIDE_FRONT | SIDE_BEHIND); ++k) {
        const float *q = s->positions + 3 * (size_t)(verts ? verts[k] : k);
        double d = (double)n[0] * ((double)q[0] - p[0]) + (double)n[1] * ((double)q[1] - p[1]) +
                   (double)n[2] * ((double)q[2] - p[2]);
        sides |= (d > eps ? SIDE_FRONT : 0) | (d < -eps ? SIDE_BEHIND : 0);
    }
    *tested = k;
    return sides;
}

int vsgl__scene_test_convex_shell(const vsgl_scene *scene)
{
    uint32_t t_count = scene->triangle_count, v_count = scene->vertex_count;
    if (t_count == 0 || t_count > VSGL__CONVEX_MAX_TRIANGLES)
        return 0;
    double ext = sqrt((double)(scene->hi.x - scene->lo.x) * (scene->hi.x - scene->lo.x) +
                      (double)(scene->hi.y - scene->lo.y) * (scene->hi.y - scene->lo.y) +
                      (double)(scene->hi.z - scene->lo.z) * (scene->hi.z - scene->lo.z));
    double eps = 1e-5 * (ext > 0.0 ? ext : 1.0);
    uint32_t tested;
    for (uint32_t t = 0; t < t_count; ++t)
        if (plane_sides(scene, t, NULL, v_count, eps, &tested) == (SIDE_FRONT | SIDE_BEHIND))
            return 0;
    return 1;
}

int vsgl__scene_convex_shell(const vsgl_scene *scene)
{
    return scene->convex_shell;
}

/* ---- Convex parts (scene_internal.h, VSGL__PART_NONE) ---- */

/* Vertex-plane tests the part search may spend over the whole scene (a
 * convex part of T triangles and V vertices costs T V; a concave one
 * stops at its first triangle with vertices on both sides). A mesh whose
 * T V exceeds what is left is not tested (no part): ~0.1 s at most on
 * this machine. */
#define VSGL__PARTS_BUDGET 100000000.0

static uint32_t uf_find(uint32_t *parent, uint32_t a)
{
    while (parent[a] != a) {
        parent[a] = parent[parent[a]];
        a = parent[a];
    }
    return a;
}

static void uf_union(uint32_t *parent, uint32_t a, uint32_t b)
{
    a = uf_find(parent, a);
    b = uf_find(parent, b);
    if (a != b)
        parent[a > b ? a : b] = a < b ? a : b; /* the smaller index is the root: deterministic */
}

typedef struct vertex_key {
    float p[3];
    uint32_t index;
} vertex_key;

static int vertex_key_cmp(const void *a, const void *b)
{
    const vertex_key *x = a, *y = b;
    for (int k = 0; k < 3; ++k)
        if (x->p[k] != y->p[k])
            return x->p[k] < y->p[k] ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index;
}

/* A sliver: its edges at p meet at under ~0.006 degrees, so rounding
 * decides its face normal (a UV sphere's pole built of distinct points a
 * few ulps apart). The test skips it and leaves it out of the part. */
#define VSGL__PART_SLIVER 1e-4
#define VSGL__SIDE_SLIVER 2

static int sliver(const vsgl_scene *s, uint32_t t)
{
    const uint32_t *ix = s->indices + 3 * (size_t)t;
    const float *a = s->positions + 3 * (size_t)ix[0], *b = s->positions + 3 * (size_t)ix[1],
                *c = s->positions + 3 * (size_t)ix[2];
    double e1[3], e2[3];
    for (int k = 0; k < 3; ++k)
        e1[k] = (double)b[k] - a[k], e2[k] = (double)c[k] - a[k];
    double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2], z = e1[0] * e2[1] - e1[1] * e2[0];
    double l1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2], l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    return x * x + y * y + z * z < VSGL__PART_SLIVER * VSGL__PART_SLIVER * l1 * l2;
}

/* Outward side of each triangle of part `tris` (count n) over its vertices
 * `verts` (count m): +1 / -1 where every vertex lies behind the face
 * normal / in front of it (within eps), 0 where all lie in its plane,
 * VSGL__SIDE_SLIVER for a sliver. Returns 0 (and stops) at the first
 * triangle with vertices on both sides. */
static int part_sides(const vsgl_scene *s, const uint32_t *tris, uint32_t n, const uint32_t *verts, uint32_t m,
                      double eps, signed char *side, double *work)
{
    for (uint32_t i = 0; i < n; ++i) {
        uint32_t t = tris[i];
        if (sliver(s, t)) {
            side[t] = VSGL__SIDE_SLIVER;
            continue;
        }
        uint32_t tested;
        int sides = plane_sides(s, t, verts, m, eps, &tested);
        *work += tested;
        if (sides == (SIDE_FRONT | SIDE_BEHIND))
            return 0;
        side[t] = (signed char)(sides == SIDE_BEHIND ? 1 : sides == SIDE_FRONT ? -1 : 0);
    }
    return 1;
}

vsgl_result vsgl__scene_build_parts(vsgl_context *ctx, vsgl_scene *s)
{
    uint32_t nt = s->triangle_count, nv = s->vertex_count;
    s->part_count = 0;
    if (nt == 0 || nv == 0)
        return VSGL_OK;
    uint32_t *parent = malloc((size_t)nv * sizeof *parent);
    vertex_key *keys = malloc((size_t)nv * sizeof *keys);
    uint32_t *comp = malloc((size_t)nt * sizeof *comp);   /* triangle -> its component's root vertex */
    uint32_t *order = malloc((size_t)nt * sizeof *order);  /* triangles grouped by component */
    uint32_t *start = malloc(((size_t)nv + 1) * sizeof *start);
    uint32_t *stamp = malloc((size_t)nv * sizeof *stamp);
    uint32_t *verts = malloc((size_t)nv * sizeof *verts);
    s->tri_part = malloc((size_t)nt * sizeof *s->tri_part);
    s->tri_side = calloc(nt, 1);
    if (!parent || !keys || !comp || !order || !start || !stamp || !verts || !s->tri_part || !s->tri_side) {
        free(parent), free(keys), free(comp), free(order), free(start), free(stamp), free(verts);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: out of memory for the convex parts");
    }
    /* components: triangles sharing a vertex, or a vertex position */
    for (uint32_t v = 0; v < nv; ++v) {
        parent[v] = v;
        keys[v].index = v;
        for (int k = 0; k < 3; ++k)
            keys[v].p[k] = s->positions[3 * (size_t)v + k];
    }
    qsort(keys, nv, sizeof *keys, vertex_key_cmp);
    for (uint32_t v = 1; v < nv; ++v)
        if (keys[v].p[0] == keys[v - 1].p[0] && keys[v].p[1] == keys[v - 1].p[1] && keys[v].p[2] == keys[v - 1].p[2])
            uf_union(parent, keys[v].index, keys[v - 1].index);
    for (uint32_t t = 0; t < nt; ++t) {
        const uint32_t *ix = s->indices + 3 * (size_t)t;
        uf_union(parent, ix[0], ix[1]);
        uf_union(parent, ix[0], ix[2]);
    }
    /* group the triangles by root (counting sort: the parts' order follows their smallest vertex) */
    memset(start, 0, ((size_t)nv + 1) * sizeof *start);
    for (uint32_t t = 0; t < nt; ++t) {
        comp[t] = uf_find(parent, s->indices[3 * (size_t)t]);
        start[comp[t] + 1]++;
    }
    for (uint32_t v = 0; v < nv; ++v)
        start[v + 1] += start[v];
    memcpy(parent, start, (size_t)nv * sizeof *parent); /* reused as the fill cursor */
    for (uint32_t t = 0; t < nt; ++t)
        order[parent[comp[t]]++] = t;
    for (uint32_t v = 0; v < nv; ++v)
        stamp[v] = UINT32_MAX;
    double budget = VSGL__PARTS_BUDGET;
    uint32_t untested = 0;
    for (uint32_t root = 0; root < nv; ++root) {
        uint32_t b = start[root], e = start[root + 1];
        if (b == e)
            continue;
        uint32_t m = 0;
        v3 lo = v3_make(INFINITY, INFINITY, INFINITY), hi = v3_make(-INFINITY, -INFINITY, -INFINITY);
        for (uint32_t i = b; i < e; ++i)
            for (int c = 0; c < 3; ++c) {
                uint32_t v = s->indices[3 * (size_t)order[i] + c];
                if (stamp[v] == root)
                    continue;
                stamp[v] = root;
                verts[m++] = v;
                const float *q = s->positions + 3 * (size_t)v;
                lo = v3_make(fminf(lo.x, q[0]), fminf(lo.y, q[1]), fminf(lo.z, q[2]));
                hi = v3_make(fmaxf(hi.x, q[0]), fmaxf(hi.y, q[1]), fmaxf(hi.z, q[2]));
            }
        double cost = (double)(e - b) * (double)m;
        int convex = 0;
        /* ids stay exact as the kernel's floats (shade/kernel.h vsgl__part_keep) */
        if (cost <= budget && s->part_count < (1u << 24)) {
            double ext = sqrt((double)v3_dot(v3_sub(hi, lo), v3_sub(hi, lo)));
            double eps = 1e-5 * (ext > 0.0 ? ext : 1.0);
            double work = 0.0; /* a concave mesh stops at its first triangle with vertices on both sides */
            convex = part_sides(s, order + b, e - b, verts, m, eps, s->tri_side, &work);
            budget -= work;
        } else {
            ++untested;
        }
        for (uint32_t i = b; i < e; ++i) {
            uint32_t t = order[i];
            int keep = convex && s->tri_side[t] != VSGL__SIDE_SLIVER;
            s->tri_part[t] = keep ? s->part_count : VSGL__PART_NONE;
            if (!keep)
                s->tri_side[t] = 0;
        }
        s->part_count += (uint32_t)convex;
    }
    free(parent), free(keys), free(comp), free(order), free(start), free(stamp), free(verts);
    s->part_curved = calloc(s->part_count + 1, 1);
    if (!s->part_curved)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "scene: out of memory for the convex parts");
    for (uint32_t t = 0; t < nt; ++t) {
        uint32_t p = s->tri_part[t];
        if (p == VSGL__PART_NONE || s->part_curved[p])
            continue;
        const float *cn = s->corner_normals + 9 * (size_t)t, *fn = s->face_normals + 3 * (size_t)t;
        for (int c = 0; c < 3; ++c) {
            float d = cn[3 * c] * fn[0] + cn[3 * c + 1] * fn[1] + cn[3 * c + 2] * fn[2];
            s->part_curved[p] |= fabsf(d) < 1.0f - 1e-6f; /* either winding */
        }
    }
    vsgl__log(ctx, VSGL_LOG_DEBUG, "scene: %u convex parts (their clusters do not light their own outside); "
              "%u meshes past the test's budget not tested", s->part_count, untested);
    return VSGL_OK;
}

uint32_t vsgl__scene_part_count(const vsgl_scene *scene)
{
    return scene->part_count;
}

int vsgl__scene_part_curved(const vsgl_scene *scene, uint32_t part)
{
    return part < scene->part_count && scene->part_curved && scene->part_curved[part];
}
