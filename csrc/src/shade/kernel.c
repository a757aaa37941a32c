/* Vectorised shading kernel: GCC vectorises the loop over receivers; the
 * function is cloned for AVX-512, AVX2 and baseline x86-64 and the best
 * clone is picked at load time (ifunc), so the shipped library runs on
 * any x86-64 machine. Built with -O3 -fno-math-errno (Makefile). */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#  define KERNEL_ATTR __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#  define KERNEL_ATTR
#endif
#include <string.h>

#define KERNEL_NAME vsgl__kernel_shade
#include "shade/kernel_impl.h"

/* e^y for y <= 0 within a few per cent (Schraudolph's exponent trick): an
 * order of importance needs no more; the kernel's k_exp made the budget's
 * weights cost 4 % of the sun room's shade stage more. */
static inline float rough_exp(float y)
{
    y = y < -80.0f ? -80.0f : y;
    union { float f; int32_t i; } u;
    u.i = (int32_t)(12102203.0f * y + 1065353216.0f);
    return u.f;
}

/* The pair weight of VSGL L at lane k of block b (vsgl__kernel_pair_weights);
 * glossy 0: the block has no glossy receiver (its glossy term is 0). */
static inline float pair_weight(const vsgl_kernel_block *b, const vsgl_kernel_light *L, float pw, size_t k,
                                int glossy)
{
    /* i: unit direction from the receiver to the VSGL */
    float dx = L->mx - b->x[k], dy = L->my - b->y[k], dz = L->mz - b->z[k];
    float d2 = dx * dx + dy * dy + dz * dz, id = d2 > 0.0f ? 1.0f / sqrtf(d2) : 0.0f;
    float ix = dx * id, iy = dy * id, iz = dz * id;
    float ce = L->ax * ix + L->ay * iy + L->az * iz; /* the VSGL's axis . (-i): -(a . -i) */
    float cr = b->nx[k] * ix + b->ny[k] * iy + b->nz[k] * iz;
    float gl = 0.0f;
    if (glossy) {
        float gx = b->Xx[k] * ix + b->Xy[k] * iy + b->Xz[k] * iz, gy = b->Yx[k] * ix + b->Yy[k] * iy + b->Yz[k] * iz;
        float gz = b->Zx[k] * ix + b->Zy[k] * iy + b->Zz[k] * iz;
        float spread = L->var * id * id; /* the VSGL's angular variance as seen from the receiver */
        gl = b->camp[k] * (gz > 0.0f ? gz : 0.0f) *
             rough_exp(-b->lam[k] * gx * gx / (1.0f + b->lam[k] * spread) -
                       b->mu[k] * gy * gy / (1.0f + b->mu[k] * spread));
    }
    float df = b->diffuse[k] * ((cr > 0.0f ? cr : 0.0f) + 0.05f) * (1.0f / 3.14159265f);
    return pw * vsgl__part_keep(b, k, L) * rough_exp(L->lv * (ce - 1.0f)) * (df + gl) / (d2 + L->var);
}

KERNEL_ATTR void vsgl__kernel_pair_weights(const vsgl_kernel_block *b, const vsgl_kernel_light *lights,
                                           size_t count, float *w, float *total)
{
    enum { B = VSGL__KERNEL_BLOCK };
    int glossy = 0;
    for (size_t k = 0; k < B; ++k)
        glossy |= b->camp[k] > 0.0f;
    for (size_t v = 0; v < count; ++v) {
        const vsgl_kernel_light *L = &lights[v];
        const float pw = (0.2126f * L->pr + 0.7152f * L->pg + 0.0722f * L->pb) * L->c0;
        float *wv = w + v * B;
        if (glossy) /* two loops, each vectorised without a branch */
            for (size_t k = 0; k < B; ++k) {
                wv[k] = pair_weight(b, L, pw, k, 1);
                total[k] += wv[k];
            }
        else
            for (size_t k = 0; k < B; ++k) {
                wv[k] = pair_weight(b, L, pw, k, 0);
                total[k] += wv[k];
            }
    }
}

/* Level l's threshold at receiver k: total[k] x 2^-(VSGL__VIS_LEVEL0 + l). */
static inline float level_threshold(float total, int l)
{
    return total * (1.0f / (float)(1u << (VSGL__VIS_LEVEL0 + l)));
}

/* The sums of the weights at most each receiver's threshold thr[q * B + k]
 * (-1: none), q < nq, over the VSGLs in order. */
static inline void threshold_sums(const float *w, size_t count, const float *thr, int nq, float *sums)
{
    enum { B = VSGL__KERNEL_BLOCK };
    for (int q = 0; q < nq; ++q)
        for (size_t k = 0; k < B; ++k)
            sums[q * B + k] = 0.0f;
    for (size_t v = 0; v < count; ++v) {
        const float *wv = w + v * B;
        for (int q = 0; q < nq; ++q)
            for (size_t k = 0; k < B; ++k)
                sums[q * B + k] += wv[k] <= thr[q * B + k] ? wv[k] : 0.0f;
    }
}

/* The cut at the first level whose sum fits the budget, searched in two passes: the
 * last level of each group of G first, then the levels before it in the
 * first group whose last fits. The sums only fall from level to level (each
 * holds the next one's weights and more, added in the same order), so this
 * is the level a pass over every level finds, from 6 sums per VSGL instead
 * of 12. */
KERNEL_ATTR void vsgl__kernel_weight_cut(const float *w, size_t count, const float *total, float budget,
                                         float *cut)
{
    enum { B = VSGL__KERNEL_BLOCK, NL = VSGL__VIS_LEVELS, G = 3, NG = NL / G };
    _Static_assert(NL % G == 0, "the levels split into groups of G");
    float thr[NG * B], sums[NG * B];
    int group[B];
    for (int g = 0; g < NG; ++g)
        for (size_t k = 0; k < B; ++k)
            thr[g * B + k] = level_threshold(total[k], G * g + G - 1);
    threshold_sums(w, count, thr, NG, sums);
    for (size_t k = 0; k < B; ++k) {
        group[k] = -1;
        for (int g = NG - 1; g >= 0; --g)
            if (sums[g * B + k] <= budget * total[k])
                group[k] = g;
    }
    for (int q = 0; q < G - 1; ++q)
        for (size_t k = 0; k < B; ++k)
            thr[q * B + k] = group[k] >= 0 ? level_threshold(total[k], G * group[k] + q) : -1.0f;
    threshold_sums(w, count, thr, G - 1, sums);
    for (size_t k = 0; k < B; ++k) {
        int l = group[k] >= 0 ? G * group[k] + G - 1 : -1;
        for (int q = G - 2; q >= 0 && l >= 0; --q)
            if (sums[q * B + k] <= budget * total[k])
                l = G * group[k] + q;
        cut[k] = l >= 0 ? level_threshold(total[k], l) : -1.0f;
    }
}

/* Lane masks and bytes: bit k of a mask is byte k (0 or 1) of 64 bytes.
 * Eight at a time: a multiply packs eight 0/1 bytes into their bits, and
 * one spreads eight bits into bytes (each bit lands in its byte, and
 * adding 0x7f carries it into the byte's top bit). */
_Static_assert(VSGL__KERNEL_BLOCK == 64, "lane masks are 64 bits");
static inline uint64_t pack_bytes(const unsigned char *m)
{
    uint64_t out = 0;
    for (int i = 0; i < 8; ++i) {
        uint64_t x;
        memcpy(&x, m + 8 * i, 8);
        out |= ((x * 0x0102040810204080ull) >> 56) << (8 * i);
    }
    return out;
}

static inline void spread_bits(uint64_t bits, unsigned char *m)
{
    for (int i = 0; i < 8; ++i) {
        uint64_t x = (((bits >> (8 * i)) & 0xffu) * 0x0101010101010101ull) & 0x8040201008040201ull;
        x = ((x + 0x7f7f7f7f7f7f7f7full) >> 7) & 0x0101010101010101ull;
        memcpy(m + 8 * i, &x, 8);
    }
}

KERNEL_ATTR uint64_t vsgl__kernel_lanes_within(const float *w, const float *cut)
{
    enum { B = VSGL__KERNEL_BLOCK };
    unsigned char m[B];
    for (size_t k = 0; k < B; ++k)
        m[k] = (unsigned char)((cut[k] >= 0.0f) & (w[k] <= cut[k]));
    return pack_bytes(m);
}

KERNEL_ATTR void vsgl__kernel_vis_accumulate(const float *w, uint64_t traced, uint64_t visible, double *seen,
                                             double *lit)
{
    enum { B = VSGL__KERNEL_BLOCK };
    unsigned char t[B], v[B];
    spread_bits(traced, t);
    spread_bits(traced & visible, v);
    for (size_t k = 0; k < B; ++k) {
        double x = (double)w[k];
        seen[k] += t[k] ? x : 0.0;
        lit[k] += v[k] ? x : 0.0;
    }
}

KERNEL_ATTR void vsgl__kernel_vis_fill(uint64_t skipped, uint64_t visible, const float *share, float *out)
{
    enum { B = VSGL__KERNEL_BLOCK };
    unsigned char s[B], v[B];
    spread_bits(skipped, s);
    spread_bits(visible, v);
    for (size_t k = 0; k < B; ++k)
        out[k] = s[k] ? share[k] : (float)v[k];
}

/* The near field's specular footprint (near_field.c, tent_mass): one side
 * of the tent in u, its VSGL__TENT_NODES Gauss-Legendre nodes at once
 * (vectorised: libm's expf is not). Per node u, the Gaussian's conditional
 * in v has mean pv + slope (u - pu) and sd sv; its integral against the
 * tent in v (1 -+ v / h on each side of 0, over [vb0, vb1] and [vb1, vb2])
 * times the linear irradiance 1 + grad . (y - centroid), in closed form
 * from the normal CDF and density at the three bounds. */
static inline __attribute__((always_inline)) void
k_lin_gauss(float al, float be, float o, float m, float s, float lo, float hi, float ca, float pa, float cb,
            float pb, float *o0, float *o1)
{
    float d0 = cb - ca;
    float d1 = m * d0 - s * (pb - pa);
    float d2 = (m * m + s * s) * d0 - s * ((m + hi) * pb - (m + lo) * pa);
    *o0 = al * d0 + be * d1;
    *o1 = (al - be * o) * d1 + be * d2 - al * o * d0;
}

KERNEL_ATTR float vsgl__kernel_tent_nodes(const vsgl_tent_nodes *restrict t)
{
    float sum = 0.0f;
    const float ih = t->ih, isv = t->isv, is_u = t->isu;
    const float side0 = t->side[0], side1 = t->side[1];
    for (int k = 0; k < VSGL__TENT_NODES; ++k) {
        const float u = t->u[k];
        const float mvu = t->pv + t->slope * (u - t->pu);
        float cdf[3], ps[3];
        for (int q = 0; q < 3; ++q) {
            float z = (t->vb[q] - mvu) * isv;
            z = z < -40.0f ? -40.0f : (z > 40.0f ? 40.0f : z);
            float e = k_exp(-0.5f * z * z);
            float tail = 0.5f * e * k_erfc_poly(fabsf(z) * 0.70710678f);
            cdf[q] = z < 0.0f ? tail : 1.0f - tail;
            ps[q] = 0.3989422804f * e;
        }
        float a0, a1, b0, b1;
        k_lin_gauss(1.0f, ih, t->cv, mvu, t->sv, t->vb[0], t->vb[1], cdf[0], ps[0], cdf[1], ps[1], &a0, &a1);
        k_lin_gauss(1.0f, -ih, t->cv, mvu, t->sv, t->vb[1], t->vb[2], cdf[1], ps[1], cdf[2], ps[2], &b0, &b1);
        const float in0 = side0 * a0 + side1 * b0, in1 = side0 * a1 + side1 * b1;
        float du = (u - t->pu) * is_u;
        du = du < -40.0f ? -40.0f : (du > 40.0f ? 40.0f : du);
        const float tu = 1.0f - fabsf(u) * ih;
        sum += t->w[k] * k_exp(-0.5f * du * du) * tu * ((1.0f + t->g[0] * (u - t->cu)) * in0 + t->g[1] * in1);
    }
    return sum;
}
