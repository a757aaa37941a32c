/* Surface attributes of four hits at once: vsgl__scene_surface (raytrace.c)
 * in SSE2 lanes, for the camera G-buffer (a camera edit of the live
 * viewport computes them for every pixel). Its chain of a normalised
 * shading normal and a tangent (dP/du from the corner UVs, else from the
 * triangle's first edge: square roots and divisions, each waiting on the
 * last) runs for four hits side by side. Every lane does the same operations in the same
 * order as the scalar function, so the results are bit for bit the same
 * (tests/c/test_surface4.c); a lane that leaves the common path (its
 * tangent degenerate, an anisotropic rotation) and scenes with corner
 * tangents (exported for anisotropic materials) take the scalar function. */
#include "scene/scene_data.h"

#if defined(__SSE2__)
#  include <emmintrin.h>

typedef struct v3x4 {
    __m128 x, y, z;
} v3x4;

/* Three consecutive floats at base + i[k] * stride + off, one vector per component. */
static inline v3x4 gather3(const float *base, const uint32_t i[4], size_t stride, size_t off)
{
    const float *p0 = base + (size_t)i[0] * stride + off, *p1 = base + (size_t)i[1] * stride + off,
                *p2 = base + (size_t)i[2] * stride + off, *p3 = base + (size_t)i[3] * stride + off;
    v3x4 r = {_mm_setr_ps(p0[0], p1[0], p2[0], p3[0]), _mm_setr_ps(p0[1], p1[1], p2[1], p3[1]),
              _mm_setr_ps(p0[2], p1[2], p2[2], p3[2])};
    return r;
}

static inline __m128 dot4(v3x4 a, v3x4 b)
{
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(a.x, b.x), _mm_mul_ps(a.y, b.y)), _mm_mul_ps(a.z, b.z));
}

/* interp(a, b, c, w, u, v) = a w + b u + c v, as raytrace.c adds them. */
static inline v3x4 interp4(v3x4 a, v3x4 b, v3x4 c, __m128 w, __m128 u, __m128 v)
{
    v3x4 r = {_mm_add_ps(_mm_add_ps(_mm_mul_ps(a.x, w), _mm_mul_ps(b.x, u)), _mm_mul_ps(c.x, v)),
              _mm_add_ps(_mm_add_ps(_mm_mul_ps(a.y, w), _mm_mul_ps(b.y, u)), _mm_mul_ps(c.y, v)),
              _mm_add_ps(_mm_add_ps(_mm_mul_ps(a.z, w), _mm_mul_ps(b.z, u)), _mm_mul_ps(c.z, v))};
    return r;
}

/* v3_normalize: a * (1 / |a|), zero where |a| is 0 or not finite. */
static inline v3x4 normalize4(v3x4 a)
{
    const __m128 l = _mm_sqrt_ps(dot4(a, a));
    const __m128 ok = _mm_and_ps(_mm_cmpgt_ps(l, _mm_setzero_ps()), _mm_cmplt_ps(l, _mm_set1_ps(INFINITY)));
    const __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), l);
    v3x4 r = {_mm_and_ps(ok, _mm_mul_ps(a.x, inv)), _mm_and_ps(ok, _mm_mul_ps(a.y, inv)),
              _mm_and_ps(ok, _mm_mul_ps(a.z, inv))};
    return r;
}

static inline __m128 is_zero4(v3x4 a)
{
    const __m128 z = _mm_setzero_ps();
    return _mm_and_ps(_mm_and_ps(_mm_cmpeq_ps(a.x, z), _mm_cmpeq_ps(a.y, z)), _mm_cmpeq_ps(a.z, z));
}

static inline __m128 select4(__m128 mask, __m128 a, __m128 b)
{
    return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}

/* orthogonalize(t, n): the component of t orthogonal to unit n, normalised (raytrace.c). */
static inline v3x4 orthogonalize4(v3x4 t, v3x4 n)
{
    const __m128 d = dot4(n, t);
    const v3x4 o = {_mm_sub_ps(t.x, _mm_mul_ps(n.x, d)), _mm_sub_ps(t.y, _mm_mul_ps(n.y, d)),
                    _mm_sub_ps(t.z, _mm_mul_ps(n.z, d))};
    return normalize4(o);
}

void vsgl__scene_surface4(const vsgl_scene *scene, const vsgl_hit hit[4], const v3 dir[4], vsgl_surface out[4])
{
    if (scene->corner_tangents) {
        for (int k = 0; k < 4; ++k)
            vsgl__scene_surface(scene, &hit[k], dir[k], &out[k]);
        return;
    }
    const uint32_t tri[4] = {hit[0].triangle, hit[1].triangle, hit[2].triangle, hit[3].triangle};
    uint32_t i0[4], i1[4], i2[4];
    for (int k = 0; k < 4; ++k) {
        const uint32_t *ix = scene->indices + (size_t)tri[k] * 3;
        i0[k] = ix[0];
        i1[k] = ix[1];
        i2[k] = ix[2];
    }
    const __m128 u = _mm_setr_ps(hit[0].u, hit[1].u, hit[2].u, hit[3].u);
    const __m128 v = _mm_setr_ps(hit[0].v, hit[1].v, hit[2].v, hit[3].v);
    const __m128 w = _mm_sub_ps(_mm_sub_ps(_mm_set1_ps(1.0f), u), v);
    const v3x4 p0 = gather3(scene->positions, i0, 3, 0), p1 = gather3(scene->positions, i1, 3, 0),
               p2 = gather3(scene->positions, i2, 3, 0);
    const v3x4 pos = interp4(p0, p1, p2, w, u, v);
    v3x4 ng = gather3(scene->face_normals, tri, 3, 0);
    v3x4 n = normalize4(interp4(gather3(scene->corner_normals, tri, 9, 0), gather3(scene->corner_normals, tri, 9, 3),
                                gather3(scene->corner_normals, tri, 9, 6), w, u, v));
    const __m128 nz = is_zero4(n); /* opposite corner normals cancelled: the face's */
    n.x = select4(nz, ng.x, n.x);
    n.y = select4(nz, ng.y, n.y);
    n.z = select4(nz, ng.z, n.z);
    /* back-facing: both flipped to the side the ray came from */
    const v3x4 d = {_mm_setr_ps(dir[0].x, dir[1].x, dir[2].x, dir[3].x), _mm_setr_ps(dir[0].y, dir[1].y, dir[2].y, dir[3].y),
                    _mm_setr_ps(dir[0].z, dir[1].z, dir[2].z, dir[3].z)};
    const __m128 flip = _mm_and_ps(_mm_cmpgt_ps(dot4(ng, d), _mm_setzero_ps()), _mm_set1_ps(-0.0f));
    ng.x = _mm_xor_ps(ng.x, flip), ng.y = _mm_xor_ps(ng.y, flip), ng.z = _mm_xor_ps(ng.z, flip);
    n.x = _mm_xor_ps(n.x, flip), n.y = _mm_xor_ps(n.y, flip), n.z = _mm_xor_ps(n.z, flip);
    /* no corner tangents: dP/du from the UVs where they give one, else orthogonalize(p1 - p0, n) */
    const v3x4 e = {_mm_sub_ps(p1.x, p0.x), _mm_sub_ps(p1.y, p0.y), _mm_sub_ps(p1.z, p0.z)};
    v3x4 t = orthogonalize4(e, n);
    if (scene->corner_uvs) {
        const float *uv[4];
        for (int k = 0; k < 4; ++k)
            uv[k] = scene->corner_uvs + (size_t)tri[k] * 6;
        const __m128 u0 = _mm_setr_ps(uv[0][0], uv[1][0], uv[2][0], uv[3][0]),
                     v0 = _mm_setr_ps(uv[0][1], uv[1][1], uv[2][1], uv[3][1]);
        const __m128 du1 = _mm_sub_ps(_mm_setr_ps(uv[0][2], uv[1][2], uv[2][2], uv[3][2]), u0),
                     dv1 = _mm_sub_ps(_mm_setr_ps(uv[0][3], uv[1][3], uv[2][3], uv[3][3]), v0),
                     du2 = _mm_sub_ps(_mm_setr_ps(uv[0][4], uv[1][4], uv[2][4], uv[3][4]), u0),
                     dv2 = _mm_sub_ps(_mm_setr_ps(uv[0][5], uv[1][5], uv[2][5], uv[3][5]), v0);
        const __m128 det = _mm_sub_ps(_mm_mul_ps(du1, dv2), _mm_mul_ps(du2, dv1));
        const __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), det);
        /* det != 0 && isfinite(1 / det) */
        const __m128 ok = _mm_and_ps(_mm_cmpneq_ps(det, _mm_setzero_ps()),
                                     _mm_cmplt_ps(_mm_and_ps(inv, _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff))),
                                                  _mm_set1_ps(INFINITY)));
        const v3x4 e2 = {_mm_sub_ps(p2.x, p0.x), _mm_sub_ps(p2.y, p0.y), _mm_sub_ps(p2.z, p0.z)};
        const v3x4 dpdu = {_mm_mul_ps(_mm_sub_ps(_mm_mul_ps(e.x, dv2), _mm_mul_ps(e2.x, dv1)), inv),
                           _mm_mul_ps(_mm_sub_ps(_mm_mul_ps(e.y, dv2), _mm_mul_ps(e2.y, dv1)), inv),
                           _mm_mul_ps(_mm_sub_ps(_mm_mul_ps(e.z, dv2), _mm_mul_ps(e2.z, dv1)), inv)};
        v3x4 tu = orthogonalize4(dpdu, n);
        tu.x = _mm_and_ps(ok, tu.x), tu.y = _mm_and_ps(ok, tu.y), tu.z = _mm_and_ps(ok, tu.z);
        const __m128 from_edge = is_zero4(tu); /* no usable UVs, or dP/du along n */
        t.x = select4(from_edge, t.x, tu.x);
        t.y = select4(from_edge, t.y, tu.y);
        t.z = select4(from_edge, t.z, tu.z);
    }
    const unsigned back = (unsigned)_mm_movemask_ps(flip);
    const unsigned scalar = (unsigned)_mm_movemask_ps(is_zero4(t)); /* v3_basis: the scalar function */
    float f[12][4];
    _mm_storeu_ps(f[0], pos.x), _mm_storeu_ps(f[1], pos.y), _mm_storeu_ps(f[2], pos.z);
    _mm_storeu_ps(f[3], n.x), _mm_storeu_ps(f[4], n.y), _mm_storeu_ps(f[5], n.z);
    _mm_storeu_ps(f[6], ng.x), _mm_storeu_ps(f[7], ng.y), _mm_storeu_ps(f[8], ng.z);
    _mm_storeu_ps(f[9], t.x), _mm_storeu_ps(f[10], t.y), _mm_storeu_ps(f[11], t.z);
    for (int k = 0; k < 4; ++k) {
        const uint32_t mat = scene->tri_material[tri[k]];
        if ((scalar >> k & 1u) || scene->materials[mat].anisotropic_rotation != 0.0f) {
            vsgl__scene_surface(scene, &hit[k], dir[k], &out[k]);
            continue;
        }
        out[k].position = v3_make(f[0][k], f[1][k], f[2][k]);
        out[k].normal = v3_make(f[3][k], f[4][k], f[5][k]);
        out[k].geometric_normal = v3_make(f[6][k], f[7][k], f[8][k]);
        out[k].tangent = v3_make(f[9][k], f[10][k], f[11][k]);
        out[k].material = mat;
        out[k].part = vsgl__scene_part_key(scene, tri[k], (int)(back >> k & 1u));
    }
}
#endif
