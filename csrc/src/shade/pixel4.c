/* Four pixels' colours at a time: vsgl__write_pixel (shade.c) for a
 * G-buffer with one sample per pixel and no material inputs of its own
 * (untextured: the job's per-material BRDF table), as a camera edit of the
 * live viewport resolves every pixel. The Fresnel reflectance towards the
 * viewer (a square root and two divisions per sample, Blender 4.x+'s
 * GlossCol) in SSE2 lanes, the rest per lane; every value is the same
 * function of the same inputs in the same order of operations as
 * vsgl__write_pixel and vsgl__glossy_color (scene/material.c), so the
 * planes are bit for bit the same (tests/c/test_pixel4.c). */

#include "shade/shade_job.h"

#include <string.h>

#if defined(__SSE2__)
#  include <emmintrin.h>

/* material.c's fresnel_dielectric(cosi, eta) in four lanes. */
static inline __m128 fresnel4(__m128 cosi, __m128 eta)
{
    const __m128 one = _mm_set1_ps(1.0f);
    const __m128 c = _mm_and_ps(cosi, _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff)));
    __m128 g = _mm_add_ps(_mm_sub_ps(_mm_mul_ps(eta, eta), one), _mm_mul_ps(c, c));
    const __m128 tir = _mm_cmple_ps(g, _mm_setzero_ps());
    g = _mm_sqrt_ps(g);
    const __m128 gpc = _mm_add_ps(g, c), gmc = _mm_sub_ps(g, c);
    const __m128 A = _mm_div_ps(gmc, gpc);
    const __m128 B = _mm_div_ps(_mm_sub_ps(_mm_mul_ps(c, gpc), one), _mm_add_ps(_mm_mul_ps(c, gmc), one));
    const __m128 f = _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(_mm_set1_ps(0.5f), A), A), _mm_add_ps(one, _mm_mul_ps(B, B)));
    return _mm_or_ps(_mm_and_ps(tir, one), _mm_andnot_ps(tir, f));
}

/* clampf(x, 0, 1) in four lanes: x < 0 ? 0 : (x > 1 ? 1 : x). */
static inline __m128 clamp01_4(__m128 x)
{
    const __m128 one = _mm_set1_ps(1.0f);
    const __m128 hi = _mm_cmpgt_ps(x, one);
    return _mm_andnot_ps(_mm_cmplt_ps(x, _mm_setzero_ps()), _mm_or_ps(_mm_and_ps(hi, one), _mm_andnot_ps(hi, x)));
}

void vsgl__write_pixels4(const shade_job *j, size_t px, const float *const Ls[4], float *cd)
{
    const vsgl_gbuffer *g = j->g;
    const vsgl_pixel_planes *pl = j->planes;
    const vsgl_brdf_params *bp[4];
    float dot[4], fd[4] = {0.0f, 0.0f, 0.0f, 0.0f}, m5[4];
    int fresnel = 0; /* some lane's GlossCol takes the dielectric Fresnel (below) */
    for (int k = 0; k < 4; ++k) {
        const uint32_t mat = g->material[px + (size_t)k];
        bp[k] = mat == VSGL__GBUFFER_MISS ? NULL : &j->params[mat];
        fresnel |= bp[k] && bp[k]->glossy && bp[k]->height_correlated && bp[k]->f0_dielectric > 0.0f &&
                   bp[k]->eta > 1.0f;
    }
    /* eta's lanes built in registers: four scalar stores read back as one
     * vector cannot be forwarded, and stalled every call */
    const __m128 eta = _mm_setr_ps(bp[0] ? bp[0]->eta : 1.0f, bp[1] ? bp[1]->eta : 1.0f, bp[2] ? bp[2]->eta : 1.0f,
                                   bp[3] ? bp[3]->eta : 1.0f);
    /* v3_dot(n, o), then glossy_color's c = clampf(dot, 0, 1), its dielectric
     * Fresnel at c and (1 - c)^5, for every lane (used where the scalar
     * path would compute them) */
    const __m128 n0 = _mm_loadu_ps(g->nrm[0] + px), n1 = _mm_loadu_ps(g->nrm[1] + px), n2 = _mm_loadu_ps(g->nrm[2] + px);
    const __m128 o0 = _mm_loadu_ps(g->view[0] + px), o1 = _mm_loadu_ps(g->view[1] + px),
                 o2 = _mm_loadu_ps(g->view[2] + px);
    const __m128 d = _mm_add_ps(_mm_add_ps(_mm_mul_ps(n0, o0), _mm_mul_ps(n1, o1)), _mm_mul_ps(n2, o2));
    const __m128 c = clamp01_4(d);
    const __m128 m = _mm_sub_ps(_mm_set1_ps(1.0f), c);
    _mm_storeu_ps(dot, d);
    if (fresnel) /* a square root and two divisions per lane: only where a lane uses them */
        _mm_storeu_ps(fd, fresnel4(c, eta));
    _mm_storeu_ps(m5, _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(_mm_mul_ps(m, m), m), m), m));
    for (int k = 0; k < 4; ++k) {
        const size_t si = px + (size_t)k;
        float *D = pl->diffuse + si * 3, *G = pl->glossy + si * 3, *DC = pl->diffuse_color + si * 3,
              *GC = pl->glossy_color + si * 3;
        const float *L = Ls[k];
        if (!L || !bp[k]) { /* a miss: write_pixel's empty sums */
            for (int ch = 0; ch < 3; ++ch)
                D[ch] = G[ch] = DC[ch] = GC[ch] = 0.0f;
            pl->coverage[si] = 0.0f;
            continue;
        }
        const vsgl_brdf_params *p = bp[k];
        float gcol[3] = {0, 0, 0};
        if (p->glossy && dot[k] > 0.0f) { /* vsgl__glossy_color */
            if (!p->height_correlated) {
                gcol[0] = gcol[1] = gcol[2] = 1.0f;
            } else {
                const float f = p->f0_dielectric > 0.0f && p->eta > 1.0f ? fd[k] : p->f0_dielectric;
                for (int ch = 0; ch < 3; ++ch)
                    gcol[ch] = (1.0f - p->metallic) * f + p->metallic * (p->base[ch] + (1.0f - p->base[ch]) * m5[k]);
            }
        }
        const float w = vsgl__gbuffer_weight(g, si);
        const float wd = w * vsgl__scene_diffuse_weight(j->scene, g->material[si], dot[k]);
        if (cd) {
            for (int ch = 0; ch < 3; ++ch)
                cd[k * 4 + ch] = p->diffuse[ch] * wd;
            cd[k * 4 + 3] = w;
        }
        for (int ch = 0; ch < 3; ++ch) {
            D[ch] = 0.0f + p->diffuse[ch] * wd * L[ch];
            G[ch] = 0.0f + w * L[3 + ch];
            DC[ch] = 0.0f + p->diffuse[ch] * wd;
            GC[ch] = 0.0f + w * gcol[ch];
        }
        pl->coverage[si] = 0.0f + w;
    }
}
#endif
