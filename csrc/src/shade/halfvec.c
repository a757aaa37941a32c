/* The half-vector model of a planar cluster's glossy light (halfvec.h). */
#include "shade/halfvec.h"
#include "shade/kernel.h"
#include "math/constants.h"

#include <math.h>

/* Smith's height-correlated G2 / (4 ci co) times 4 ci, without the
 * constant: ci / (ci So + co Si) (scene/material.c vsgl__specular_factor). */
static float smith_term(float ci, float co, float a2)
{
    float so = sqrtf(a2 + (1.0f - a2) * co * co), si = sqrtf(a2 + (1.0f - a2) * ci * ci);
    return ci / (ci * so + co * si);
}

/* Row e of the slope's Jacobian at half vector h, |o + l| = m: ds_e =
 * row . dl, row = (I - h h^T)(e - s_e n) / (h.n m). */
static v3 hv_row(v3 h, float m, v3 n, v3 e, float se)
{
    v3 a = v3_sub(e, v3_scale(n, se));
    return v3_scale(v3_sub(a, v3_scale(h, v3_dot(h, a))), 1.0f / (v3_dot(h, n) * m));
}

/* The slope s of h in the frame (t, u, n), the Jacobian's rows a there and
 * the slope covariance cov of a cluster of directions about w (variance sv
 * per axis, off w and off its projected normal p) through them. */
static void hv_linearise(v3 h, float m, v3 n, v3 t, v3 u, v3 w, v3 p, float sv, float s[2], v3 a[2],
                         float cov[2][2])
{
    float hn = v3_dot(h, n);
    s[0] = v3_dot(h, t) / hn;
    s[1] = v3_dot(h, u) / hn;
    a[0] = hv_row(h, m, n, t, s[0]);
    a[1] = hv_row(h, m, n, u, s[1]);
    for (int i = 0; i < 2; ++i)
        for (int k = 0; k < 2; ++k)
            cov[i][k] = sv * (v3_dot(a[i], a[k]) - v3_dot(a[i], w) * v3_dot(a[k], w) - v3_dot(a[i], p) * v3_dot(a[k], p));
}

float vsgl__halfvec_glossy(const vsgl_vsgl *v, v3 x, v3 n, v3 o, v3 axis, float alpha, int lobes,
                           const float fres[3], float *weight)
{
    *weight = 0.0f;
    v3 d = v3_sub(v->mean, x);
    float d2 = v3_dot(d, d);
    float hgt = v3_dot(v->normal, v3_neg(d)); /* the receiver's height above the cluster's plane */
    if (!(alpha > 0.0f) || !(d2 > 0.0f) || !(hgt > 0.0f))
        return 0.0f;
    float r = 1.0f / sqrtf(d2);
    v3 w = v3_scale(d, r);
    v3 hs = v3_add(o, w);
    float m = sqrtf(v3_dot(hs, hs));
    if (!(m > 0.0f))
        return 0.0f;
    v3 h = v3_scale(hs, 1.0f / m);
    float hn = v3_dot(h, n);
    float sv = v->variance * r * r;
    float wgt = smoothstep01f((VSGL__HV_SPREAD_HI - sv) / (VSGL__HV_SPREAD_HI - VSGL__HV_SPREAD_LO)) *
                smoothstep01f((hn - VSGL__HV_HN_LO) / (VSGL__HV_HN_HI - VSGL__HV_HN_LO));
    if (!(wgt > 0.0f))
        return 0.0f;
    v3 t, u;
    v3_basis(n, &t, &u);
    v3 p = v3_sub(v->normal, v3_scale(w, v3_dot(v->normal, w)));
    float s[2], cov[2][2];
    v3 rows[2];
    hv_linearise(h, m, n, t, u, w, p, sv, s, rows, cov);
    /* Linearised at w alone, a wide cluster seen at a grazing view was
     * wrong by orders of magnitude: the slope is (o + l).t / (o + l).n, and
     * where (o + l).n is small the cluster's spread moves it a lot and not
     * linearly (a corridor floor at cos_o 0.04 took 100-700x the light of a
     * wall's cluster 10 degrees to the side). Each sharp lobe (the first
     * VSGL__HV_RELIN) linearises again where its product with the
     * cluster's slope Gaussian peaks, se = al2 (al2 I + cov)^-1 s: w itself
     * for a cluster small against the lobe, the mirror direction for a
     * wide one; D's 1/h.n^4, G and F are taken there. */
    const float *K, *C;
    const int nl = vsgl__hv_lobe_set(lobes, &K, &C);
    const float a2 = alpha * alpha, co = fmaxf(v3_dot(o, n), 1e-4f), ca = fmaxf(v3_dot(axis, n), 1e-4f);
    float sum = 0.0f; /* E[D] G F over G and F at the axis */
    for (int q = 0; q < nl; ++q) {
        float al2 = a2 * 0.5f / K[q];
        float sl[2] = {s[0], s[1]}, cl[2][2] = {{cov[0][0], cov[0][1]}, {cov[1][0], cov[1][1]}};
        v3 hl = h, le = w;
        float m11 = al2 + cov[0][0], m22 = al2 + cov[1][1], m12 = cov[0][1], md = m11 * m22 - m12 * m12;
        if (q < VSGL__HV_RELIN && md > 1e-30f) {
            float se0 = al2 * (m22 * s[0] - m12 * s[1]) / md, se1 = al2 * (m11 * s[1] - m12 * s[0]) / md;
            v3 he = v3_normalize(v3_add(n, v3_add(v3_scale(t, se0), v3_scale(u, se1))));
            float oh = v3_dot(o, he);
            if (oh > 1e-4f) {
                float me = 2.0f * oh, sw[2];
                v3 ae[2];
                hl = he;
                le = v3_sub(v3_scale(he, me), o); /* the mirror of o about he */
                hv_linearise(he, me, n, t, u, w, p, sv, sw, ae, cl);
                v3 dl = v3_sub(w, le); /* w's slope through the linearisation at le */
                sl[0] = sw[0] + v3_dot(ae[0], dl);
                sl[1] = sw[1] + v3_dot(ae[1], dl);
            }
        }
        float c11 = al2 + cl[0][0], c22 = al2 + cl[1][1], c12 = cl[0][1];
        float det = c11 * c22 - c12 * c12;
        if (!(det > 0.0f))
            continue;
        float qf = (c22 * sl[0] * sl[0] - 2.0f * c12 * sl[0] * sl[1] + c11 * sl[1] * sl[1]) / det;
        float hnl = v3_dot(hl, n), ci = fmaxf(v3_dot(le, n), 0.0f);
        sum += C[q] / K[q] * expf(-0.5f * fmaxf(qf, 0.0f)) / (VSGL__2PI * sqrtf(det)) / (hnl * hnl * hnl * hnl) *
               smith_term(ci, co, a2) * (fres[1] + fres[2] * vsgl__fresnel_dielectric(v3_dot(le, hl), fres[0]));
    }
    *weight = wgt;
    return (1.0f / VSGL__PI) * hgt * r * r * r * sum / smith_term(ca, co, a2);
}
