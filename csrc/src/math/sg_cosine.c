/* Integral of an SG times the clamped cosine max(w.n, 0), three modes
 * (docs/math.md, "SG x clamped cosine"). Fit: tools/fit_cosine_sharpness.py. */
#include "vsgl/sg.h"
#include "math/constants.h"
#include "math/normal.h"
#include "math/sg_internal.h"

/* Shorthands for the fitted constants (sg_internal.h, shared with the
 * shading kernel). */
#define T_A VSGL__COS_T_A
#define T_B VSGL__COS_T_B
#define T_C VSGL__COS_T_C
#define T_D VSGL__COS_T_D
#define T_E VSGL__COS_T_E
#define K_A1 VSGL__COS_K_A1
#define K_A2 VSGL__COS_K_A2
#define K_B1 VSGL__COS_K_B1
#define K_B2 VSGL__COS_K_B2
#define K_PSI VSGL__COS_K_PSI


float vsgl__sg_cosine_accurate(float l, float c)
{
    if (!(l > 0.0f))
        return VSGL__PI;
    /* Exact hemispherical integrals about the lobe axis, over 2 pi:
     *   up  = (l - 1 + e^{-l}) / l^2            (n = xi; up = low + u)
     *   low = e^{-l} (1 - e^{-l} (1 + l)) / l^2 (n = -xi; Taylor below 0.5)
     *   u   = up - low = A(l) m(l) / (2 pi)     (the unclamped first moment) */
    float em = expm1f(-l), e1 = 1.0f + em;
    float q;
    if (l < 0.5f) {
        q = 0.5f + l * (-1.0f / 3.0f + l * (1.0f / 8.0f + l * (-1.0f / 30.0f + l * (1.0f / 144.0f + l * (-1.0f / 840.0f + l * (1.0f / 5760.0f))))));
    } else {
        float il2 = 1.0f / (l * l);
        q = (-em - l * e1) * il2;
    }
    float low = e1 * q;
    float u = (-em * (2.0f + em) / l) * vsgl__sg_mean_length(l);

    /* Interpolation weight s(c) in [0, 1], s(1) = 1, s(-1) = 0, odd part c/2
     * exact; even part from a Gaussian model of w.n with fitted t(l), plus
     * an even correction kappa (psi(t c) - psi(t)) that keeps all three
     * constraints (docs/math.md 3.2). */
    float t = l * sqrtf(0.5f * ((l + T_A) * l + T_B) / (((l + T_C) * l + T_D) * l + T_E));
    t = t > VSGL__TINY ? t : VSGL__TINY;
    float ac = fabsf(c);
    float x = t * ac;
    float ex = expf(-x * x);
    float et = expf(-t * t);
    float omc2 = (1.0f - ac) * (1.0f + ac);
    float s = (c > 0.0f ? c : 0.0f) - 0.5f * ac * vsgl__erfc_poly(x) * ex + 0.5f * vsgl__erfc_poly(t) * et
            + (ex - et) * (0.28209479177387814f / t); /* 1 / (2 sqrt(pi)) */
    float kappa = -((K_A1 + K_A2 * l) / (1.0f + l * (K_B1 + K_B2 * l))) / t;
    s += kappa * ((x * x - K_PSI) * ex - (t * t - K_PSI) * et);
    s = s > 0.0f ? (s < 1.0f ? s : 1.0f) : 0.0f;
    float r = VSGL__2PI * (low + u * s);

    /* Never above pi * max of the SG over the hemisphere w.n >= 0, reached
     * on the horizon when c < 0: exp(-l c^2 / (1 + sqrt(1 - c^2))). */
    if (c < 0.0f) {
        float bound = VSGL__PI * expf(-l * c * c / (1.0f + sqrtf(omc2)));
        r = r < bound ? r : bound;
    }
    return r;
}

float vsgl_sg_cosine_sharpness(void)
{
    return VSGL__COSINE_SHARPNESS;
}

float vsgl_sg_cosine_integral(const vsgl_sg *g, const vsgl_vec3 *n, int32_t mode)
{
    v3 xi = v3_normalize(g->axis), nn = v3_normalize(*n);
    if ((xi.x == 0.0f && xi.y == 0.0f && xi.z == 0.0f) || (nn.x == 0.0f && nn.y == 0.0f && nn.z == 0.0f)
        || g->log_amplitude == -INFINITY)
        return 0.0f;
    float l = vsgl__sg_clamp_sharpness(g->sharpness);
    float c = clampf(v3_dot(xi, nn), -1.0f, 1.0f);
    if (mode == VSGL_COSINE_SG) {
        /* pi * integral of G(w) G(w; n, l_d) / A(l_d) (exact product integral) */
        vsgl_sg d;
        d.axis = nn;
        d.sharpness = VSGL__COSINE_SHARPNESS;
        d.log_amplitude = VSGL__LOG_PI - vsgl__sg_log_integral(VSGL__COSINE_SHARPNESS);
        vsgl_sg a = *g;
        a.axis = xi;
        a.sharpness = l;
        return vsgl_sg_product_integral(&a, &d);
    }
    if (mode == VSGL_COSINE_PULLED_OUT) {
        if (!(c > 0.0f))
            return 0.0f;
        return c * expf(g->log_amplitude + vsgl__sg_log_integral(l));
    }
    float r = vsgl__sg_cosine_accurate(l, c);
    return r > 0.0f ? expf(g->log_amplitude + logf(r)) : 0.0f;
}
