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
    float s[2] = {v3_dot(h, t) / hn, v3_dot(h, u) / hn};
    v3 e[2] = {v3_sub(t, v3_scale(n, s[0])), v3_sub(u, v3_scale(n, s[1]))};
    v3 a[2];
    for (int i = 0; i < 2; ++i)
        a[i] = v3_scale(v3_sub(e[i], v3_scale(h, v3_dot(h, e[i]))), 1.0f / (hn * m));
    v3 p = v3_sub(v->normal, v3_scale(w, v3_dot(v->normal, w)));
    float cov[2][2];
    for (int i = 0; i < 2; ++i)
        for (int k = 0; k < 2; ++k)
            cov[i][k] = sv * (v3_dot(a[i], a[k]) - v3_dot(a[i], w) * v3_dot(a[k], w) - v3_dot(a[i], p) * v3_dot(a[k], p));
    const float *K, *C;
    const int nl = vsgl__hv_lobe_set(lobes, &K, &C);
    float ed = 0.0f; /* E[D] h.n^4 */
    for (int q = 0; q < nl; ++q) {
        float al2 = alpha * alpha * 0.5f / K[q];
        float c11 = al2 + cov[0][0], c22 = al2 + cov[1][1], c12 = cov[0][1];
        float det = c11 * c22 - c12 * c12;
        if (!(det > 0.0f))
            continue;
        float qf = (c22 * s[0] * s[0] - 2.0f * c12 * s[0] * s[1] + c11 * s[1] * s[1]) / det;
        ed += C[q] / K[q] * expf(-0.5f * fmaxf(qf, 0.0f)) / (VSGL__2PI * sqrtf(det));
    }
    float a2 = alpha * alpha;
    float co = fmaxf(v3_dot(o, n), 1e-4f), ci = fmaxf(v3_dot(w, n), 0.0f), ca = fmaxf(v3_dot(axis, n), 1e-4f);
    float g = smith_term(ci, co, a2) / smith_term(ca, co, a2);
    *weight = wgt;
    return (1.0f / VSGL__PI) * hgt * r * r * r * ed / (hn * hn * hn * hn) * g *
           (fres[1] + fres[2] * vsgl__fresnel_dielectric(v3_dot(w, h), fres[0]));
}
