/* Receivers' warped GGX lobes in float lanes (warp_lanes.h).
 *
 * vsgl_warp_ndf_asg (lobes.c) in the same steps, in float and without
 * branches, so that GCC vectorises the loop over lanes (-O3, cloned for
 * AVX-512 / AVX2 as the shading kernel is; Makefile). Every glossy
 * receiver of a frame warps its NDF once, and one at a time, in double,
 * the warp was a chain of seven dependent square roots and divisions that
 * no other work hid: ~14 % of the shade stage's per-receiver cost at 2
 * VSGLs (docs/performance.md). Differences to the double warp: ~1e-6
 * relative, 1e-3 at views within 0.1 degree of grazing (tests/c/test_lobes.c);
 * the smaller eigenvalue is the determinant over the larger, k^2 l m
 * det(P)^2 / e1, rather than mean - rad, which cancels in float for a sharp
 * anisotropic lobe, and k (up to 2.5e11 at a grazing view) multiplies only
 * the results, so that no sharpness (up to 2^41) is squared with it.
 *
 * Only +, -, *, / and square roots, in the same order in every lane and
 * with no contraction (ISO C), and maxima written as `a > b ? a : b`,
 * which the vector maximum computes exactly: a lane's result does not
 * depend on the ISA clone, the vector width or the other lanes. */
#include "math/warp_lanes.h"
#include "vsgl/lobes.h"
#include "vsgl/sg.h"
#include "math/constants.h"

#include <math.h>

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
#  define WARP_ATTR __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#  define WARP_ATTR
#endif

/* vsgl__sg_clamp_sharpness for finite x > 0: min(x, the cap) */
static inline float cap(float x) { return x < VSGL_SHARPNESS_MAX ? x : VSGL_SHARPNESS_MAX; }
static inline float max0(float x) { return x > 0.0f ? x : 0.0f; }
/* clamp_alpha (lobes.c) for finite alphas */
static inline float alpha_of(float a) { return a > VSGL_ALPHA_MIN ? (a < 1.0f ? a : 1.0f) : VSGL_ALPHA_MIN; }

WARP_ATTR void vsgl__warp_lanes(vsgl_warp_lanes *restrict w, size_t n)
{
    for (size_t i = 0; i < n; ++i) {
        const float ax = alpha_of(w->ax[i]), ay = alpha_of(w->ay[i]);
        const float l = cap(1.0f / (ax * ax)), m = cap(1.0f / (ay * ay));
        /* the NDF's frame: z_h the unit normal, x_h the tangent made
         * orthogonal to it (any completion where it is along the normal) */
        const float il = 1.0f / sqrtf(w->nx[i] * w->nx[i] + w->ny[i] * w->ny[i] + w->nz[i] * w->nz[i]);
        const float zx = w->nx[i] * il, zy = w->ny[i] * il, zz = w->nz[i] * il;
        const float td = w->tx[i] * zx + w->ty[i] * zy + w->tz[i] * zz;
        float ux = w->tx[i] - zx * td, uy = w->ty[i] - zy * td, uz = w->tz[i] - zz * td;
        const float ul2 = ux * ux + uy * uy + uz * uz;
        const float s = zz < 0.0f ? -1.0f : 1.0f, a = -1.0f / (s + zz), b = zx * zy * a; /* v3_basis */
        const int along = !(ul2 > 1e-12f);
        const float iu = along ? 1.0f : 1.0f / sqrtf(ul2);
        const float xhx = along ? 1.0f + s * zx * zx * a : ux * iu, xhy = along ? s * b : uy * iu,
                    xhz = along ? -s * zx : uz * iu;
        const float yhx = zy * xhz - zz * xhy, yhy = zz * xhx - zx * xhz, yhz = zx * xhy - zy * xhx;
        /* the view and the lobe's axis, the view's mirror image about z_h */
        const float io = 1.0f / sqrtf(w->ox[i] * w->ox[i] + w->oy[i] * w->oy[i] + w->oz[i] * w->oz[i]);
        const float ox = w->ox[i] * io, oy = w->oy[i] * io, oz = w->oz[i] * io;
        const float c = ox * zx + oy * zy + oz * zz;
        float zix = 2.0f * c * zx - ox, ziy = 2.0f * c * zy - oy, ziz = 2.0f * c * zz - oz;
        const float iz = 1.0f / sqrtf(zix * zix + ziy * ziy + ziz * ziz);
        zix *= iz;
        ziy *= iz;
        ziz *= iz;
        /* a tangent frame at z_i: x' perpendicular to the view where that
         * is defined (the lobe comes out the same in any frame) */
        float xpx = oy * ziz - oz * ziy, xpy = oz * zix - ox * ziz, xpz = ox * ziy - oy * zix;
        const float xl2 = xpx * xpx + xpy * xpy + xpz * xpz;
        const float si = ziz < 0.0f ? -1.0f : 1.0f, ai = -1.0f / (si + ziz), bi = zix * ziy * ai;
        const int normal = !(xl2 > 1e-8f);
        const float ix = normal ? 1.0f : 1.0f / sqrtf(xl2);
        xpx = normal ? 1.0f + si * zix * zix * ai : xpx * ix;
        xpy = normal ? si * bi : xpy * ix;
        xpz = normal ? -si * zix : xpz * ix;
        const float ypx = ziy * xpz - ziz * xpy, ypy = ziz * xpx - zix * xpz, ypz = zix * xpy - ziy * xpx;
        /* the half-vector Jacobian's quadratic form (vsgl_warp_ndf_asg,
         * docs/math.md) without its factor k = 1 / (4 c^2) */
        const float ac = c < 0.0f ? -c : c, cc = ac > 1e-6f ? ac : 1e-6f, k = 1.0f / (4.0f * cc * cc);
        const float p11 = xhx * xpx + xhy * xpy + xhz * xpz, p12 = xhx * ypx + xhy * ypy + xhz * ypz;
        const float p21 = yhx * xpx + yhy * xpy + yhz * xpz, p22 = yhx * ypx + yhy * ypy + yhz * ypz;
        const float q11 = l * p11 * p11 + m * p21 * p21, q12 = l * p11 * p12 + m * p21 * p22,
                    q22 = l * p12 * p12 + m * p22 * p22, dp = p11 * p22 - p12 * p21;
        const float half_diff = 0.5f * (q11 - q22), mean = 0.5f * (q11 + q22);
        const float rad = sqrtf(half_diff * half_diff + q12 * q12);
        const float c2 = rad > 0.0f ? half_diff / rad : 1.0f;
        const float cs = sqrtf(max0(0.5f * (1.0f + c2))), sa = sqrtf(max0(0.5f * (1.0f - c2)));
        const float sn = q12 < 0.0f ? -sa : sa;
        const float e1 = mean + rad, e2 = e1 > 0.0f ? l * m * dp * dp / e1 : 0.0f;
        w->Xx[i] = xpx * cs + ypx * sn;
        w->Xy[i] = xpy * cs + ypy * sn;
        w->Xz[i] = xpz * cs + ypz * sn;
        w->Yx[i] = ypx * cs - xpx * sn;
        w->Yy[i] = ypy * cs - xpy * sn;
        w->Yz[i] = ypz * cs - xpz * sn;
        w->Zx[i] = zix;
        w->Zy[i] = ziy;
        w->Zz[i] = ziz;
        w->lam[i] = cap(max0(k * e1));
        w->mu[i] = cap(max0(k * e2));
    }
}

void vsgl__warp_lane_set(vsgl_warp_lanes *w, size_t k, v3 n, v3 t, v3 o, float alpha_x, float alpha_y)
{
    w->nx[k] = n.x; w->ny[k] = n.y; w->nz[k] = n.z;
    w->tx[k] = t.x; w->ty[k] = t.y; w->tz[k] = t.z;
    w->ox[k] = o.x; w->oy[k] = o.y; w->oz[k] = o.z;
    w->ax[k] = alpha_x;
    w->ay[k] = alpha_y;
}

void vsgl__warp_lane_get(const vsgl_warp_lanes *w, size_t k, vsgl_asg *out)
{
    out->x = v3_make(w->Xx[k], w->Xy[k], w->Xz[k]);
    out->y = v3_make(w->Yx[k], w->Yy[k], w->Yz[k]);
    out->z = v3_make(w->Zx[k], w->Zy[k], w->Zz[k]);
    out->lambda = w->lam[k];
    out->mu = w->mu[k];
    out->log_amplitude = -VSGL__LOG_PI - logf(alpha_of(w->ax[k])) - logf(alpha_of(w->ay[k]));
}
