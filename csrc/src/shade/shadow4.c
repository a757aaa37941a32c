/* A kernel block's shadowing constants (kernel.h, vsgl__shadow_lane) for
 * all its lanes at once, four at a time: per lane two square roots and two
 * divisions in a dependent chain, which as one call per lane was a sixth
 * of the shade stage's fixed per-receiver cost (a 1080p frame against 2
 * VSGLs, tools/bench/bench_shade.c). Every value is the same function of
 * the same inputs in the same order of operations as vsgl__shadow_lane
 * (IEEE square roots and divisions are exact in any lane), so the block is
 * bit for bit the same as lane by lane (tests/c/test_shadow4.c). */

#include "shade/kernel.h"
#include "math/broad_lobe.h"

#include <math.h>

/* Lane k from its fields: |alpha| (negative for an anisotropic receiver,
 * which the half-vector model does not take), the normal, the view and
 * the lobe's axis. */
static void shadow_lane(vsgl_kernel_block *b, size_t k, int two)
{
    vsgl__kernel_set_smooth(b, k, vsgl__shadow_lane(fabsf(b->alpha[k]), b->nx[k] * b->ox[k] + b->ny[k] * b->oy[k] +
                                                    b->nz[k] * b->oz[k], b->nx[k] * b->Zx[k] + b->ny[k] * b->Zy[k] +
                                                    b->nz[k] * b->Zz[k], two));
}

#if defined(__SSE2__)
#  include <emmintrin.h>

/* x > lo ? x : lo (a NaN takes lo, as the scalar select does). */
static inline __m128 at_least(__m128 x, __m128 lo)
{
    const __m128 m = _mm_cmpgt_ps(x, lo);
    return _mm_or_ps(_mm_and_ps(m, x), _mm_andnot_ps(m, lo));
}

static inline __m128 dot4(const float *ax, const float *ay, const float *az, const float *bx, const float *by,
                          const float *bz, size_t k)
{
    const __m128 xy = _mm_add_ps(_mm_mul_ps(_mm_loadu_ps(ax + k), _mm_loadu_ps(bx + k)),
                                 _mm_mul_ps(_mm_loadu_ps(ay + k), _mm_loadu_ps(by + k)));
    return _mm_add_ps(xy, _mm_mul_ps(_mm_loadu_ps(az + k), _mm_loadu_ps(bz + k)));
}

void vsgl__shadow_lanes(vsgl_kernel_block *b, size_t n, int two)
{
    const __m128 one = _mm_set1_ps(1.0f), lo = _mm_set1_ps(1e-4f);
    const __m128 absmask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        const __m128 a = _mm_and_ps(_mm_loadu_ps(b->alpha + k), absmask);
        const __m128 co = at_least(dot4(b->nx, b->ny, b->nz, b->ox, b->oy, b->oz, k), lo);
        const __m128 ca = at_least(dot4(b->nx, b->ny, b->nz, b->Zx, b->Zy, b->Zz, k), lo);
        const __m128 a2 = _mm_mul_ps(a, a), ra = _mm_sub_ps(one, a2);
        const __m128 so = _mm_sqrt_ps(_mm_add_ps(a2, _mm_mul_ps(_mm_mul_ps(ra, co), co)));
        const __m128 sa = _mm_sqrt_ps(_mm_add_ps(a2, _mm_mul_ps(_mm_mul_ps(ra, ca), ca)));
        const __m128 ga = _mm_div_ps(ca, _mm_add_ps(_mm_mul_ps(ca, so), _mm_mul_ps(co, sa)));
        _mm_storeu_ps(b->ga2 + k, a2);
        _mm_storeu_ps(b->gso + k, so);
        _mm_storeu_ps(b->gco + k, co);
        _mm_storeu_ps(b->gia + k, _mm_div_ps(one, ga));
        if (two) {
            _mm_storeu_ps(b->gw + k, one);
        } else {
            for (size_t q = k; q < k + 4; ++q)
                b->gw[q] = vsgl__broad_fade(sqrtf(fabsf(b->alpha[q])));
        }
    }
    for (; k < n; ++k)
        shadow_lane(b, k, two);
}

#else

void vsgl__shadow_lanes(vsgl_kernel_block *b, size_t n, int two)
{
    for (size_t k = 0; k < n; ++k)
        shadow_lane(b, k, two);
}

#endif
