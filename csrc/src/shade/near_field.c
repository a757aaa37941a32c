/* The near field of a lattice cluster: its cell as the four nested
 * rectangles whose indicators, a quarter each, step-approximate the tent
 * (half-widths 3h/4 and h/4 per axis). Neighbouring cells' steps sum to 1
 * everywhere, as the tents do, so a uniformly lit plane is uniform again;
 * truncated to the VPLs' extent, the cells at a junction end where the
 * surface ends, where the Gaussians' tails spill past it. */
#include "shade/near_field.h"
#include "shade/kernel.h"
#include "math/constants.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Cell spacings from the cell's centre where the near field takes all of
 * the pair, and none of it. The far field agrees with it there: 1-2, 1.5-
 * 2.5, 2-3.5 and 3-5 gave the same errors in the box, red-wall and sun
 * rooms within 0.00004 (structured relMSE of the diffuse pass). */
#define VSGL__NEAR_FULL 1.0f
#define VSGL__NEAR_NONE 2.0f
/* ... and within this many spacings of the cell's plane, none from the
 * second: further out the Gaussians' sum is smooth and in the far field
 * (the same errors in those rooms, a quarter of the pairs). */
#define VSGL__NEAR_HEIGHT_FULL 0.5f
#define VSGL__NEAR_HEIGHT_NONE 1.0f
/* The fade-in in front of the plane, in spacings: a thin wall's back face
 * lies in its front face's plane, and saw it as a lit hemisphere. */
#define VSGL__NEAR_BEHIND 0.01f
/* The model applies to a plane facing its cell's axis within these cosines
 * (times coherence: a sphere's cells are not planes) ... A gently bumped
 * floor's cells are nearly planes: a 500k-triangle heightfield (bumps of
 * 10 cm on a 0.9 m wavelength, dense_floor) has them at 0.97-0.995, and a
 * fade over 0.98-0.995 left most of them in the far field: a dark seam
 * where the lit floor meets a wall. The fade is 0.90-0.97 ... */
#define VSGL__NEAR_FACING_LO 0.90f
#define VSGL__NEAR_FACING_HI 0.97f
/* ... for receivers across the cell's plane (a wall's foot), and
 * 0.98-0.995 (VSGL__NEAR_FLAT_*: a plane) for receivers facing the cell's
 * way, within VSGL__NEAR_ACROSS_* of 1 - n.axis (a bump of the same floor):
 * a bump's point a few millimetres in front of its neighbour cell's mean
 * plane, and turned towards it, took that plane's full form factor, and
 * the near field drew bright arcs along every line where the floor
 * crossed a cell's plane (320 x 240, balanced). */
#define VSGL__NEAR_FLAT_LO 0.98f
#define VSGL__NEAR_FLAT_HI 0.995f
#define VSGL__NEAR_ACROSS_LO 0.3f
#define VSGL__NEAR_ACROSS_HI 0.6f
/* A specular cell's lobe leaves its plane at this cosine at least (the
 * footprint's linearisation grows with 1 / cos). */
#define VSGL__NEAR_SPECULAR_COS 0.1f
/* Gauss-Legendre nodes of the footprint's mass over a step (per axis). */
#define VSGL__NEAR_GL 8
/* Grid cells per axis of the index at most. */
#define VSGL__NEAR_GRID_MAX 64

static float axis_of(v3 p, uint32_t a)
{
    return a == 0 ? p.x : a == 1 ? p.y : p.z;
}

static v3 point_on(uint32_t a, float za, float pu, float pv)
{
    float c[3];
    c[a] = za;
    c[(a + 1) % 3] = pu;
    c[(a + 2) % 3] = pv;
    return v3_make(c[0], c[1], c[2]);
}

/* atan2(y, x) for y >= 0, in [0, pi], within 2e-6 rad (a minimax
 * polynomial for atan on [0, 1]): libm's atan2f was a third of the near
 * field's time. */
static float angle_of(float y, float x)
{
    float ax = fabsf(x), big = fmaxf(ax, y), small = fminf(ax, y);
    if (!(big > 0.0f))
        return 0.0f;
    float t = small / big, t2 = t * t;
    float a = t * (0.99997726f + t2 * (-0.33262347f + t2 * (0.19354346f + t2 * (-0.11643287f +
                   t2 * (0.05265332f + t2 * -0.01172120f)))));
    if (y > ax)
        a = 0.5f * VSGL__PI - a;
    return x < 0.0f ? VSGL__PI - a : a;
}

/* Lambert's form factor of polygon p[0, m) seen from x with normal n,
 * clipped to the half-space in front of x (dimensionless, in [0, 1]). */
static float polygon_form_factor(v3 x, v3 n, const v3 *p, int m)
{
    v3 q[8];
    int k = 0;
    for (int i = 0; i < m; ++i) {
        v3 a = p[i], b = p[(i + 1) % m];
        float da = v3_dot(n, v3_sub(a, x)), db = v3_dot(n, v3_sub(b, x));
        if (da >= 0.0f)
            q[k++] = a;
        if ((da >= 0.0f) != (db >= 0.0f))
            q[k++] = v3_add(a, v3_scale(v3_sub(b, a), da / (da - db)));
    }
    float sum = 0.0f;
    v3 u[8];
    for (int i = 0; i < k; ++i) {
        v3 d = v3_sub(q[i], x);
        float l2 = v3_dot(d, d);
        if (!(l2 > 0.0f))
            return 0.0f; /* x on the polygon's outline: the plane's own receivers, weight 0 anyway */
        u[i] = v3_scale(d, 1.0f / sqrtf(l2));
    }
    for (int i = 0; i < k; ++i) {
        v3 a = u[i], b = u[(i + 1) % k];
        v3 c = v3_cross(a, b);
        float lc = v3_length(c);
        if (!(lc > 0.0f))
            continue;
        sum += angle_of(lc, v3_dot(a, b)) * v3_dot(n, c) / lc;
    }
    return fabsf(sum) * (0.5f * VSGL__INV_PI);
}

/* The tent 1 - |x - c| / h over [lo, hi]: its mass, mean and variance. */
void vsgl__tent_moments(double lo, double hi, double c, double h, double *mass, double *mean, double *var)
{
    double m0 = 0.0, m1 = 0.0, m2 = 0.0;
    double a = fmin(hi, c) - c, b = lo - c; /* the rising side, y = x - c in [b, a] */
    if (a > b) {
        m0 += (a - b) + (a * a - b * b) / (2.0 * h);
        m1 += (a * a - b * b) / 2.0 + (a * a * a - b * b * b) / (3.0 * h);
        m2 += (a * a * a - b * b * b) / 3.0 + (a * a * a * a - b * b * b * b) / (4.0 * h);
    }
    a = fmax(lo, c) - c;
    b = hi - c; /* the falling side, y in [a, b] */
    if (b > a) {
        m0 += (b - a) - (b * b - a * a) / (2.0 * h);
        m1 += (b * b - a * a) / 2.0 - (b * b * b - a * a * a) / (3.0 * h);
        m2 += (b * b * b - a * a * a) / 3.0 - (b * b * b * b - a * a * a * a) / (4.0 * h);
    }
    *mass = m0;
    *mean = m0 > 0.0 ? c + m1 / m0 : c;
    *var = m0 > 0.0 ? fmax(m2 / m0 - (m1 / m0) * (m1 / m0), 0.0) : 0.0;
}

int vsgl__near_cell(const vsgl_vsgl *v, uint32_t index, vsgl_near_cell *c)
{
    memset(c, 0, sizeof *c);
    if (!(v->cell_h > 0.0f) || !(v->power[0] + v->power[1] + v->power[2] > 0.0f))
        return 0;
    uint32_t a = v->cell_axis;
    if (v->lobe == VSGL__LOBE_SPECULAR) {
        /* a lobe that leaves the plane's front by more than ~6 degrees */
        float out = axis_of(v->axis, a) * (v->cell_side ? -1.0f : 1.0f);
        if (!(v->sharpness > 0.0f) || !(out > VSGL__NEAR_SPECULAR_COS))
            return 0;
        c->lobe_axis = v->axis;
        c->lambda = v->sharpness;
    } else if (v->lobe != VSGL__LOBE_DIFFUSE) {
        return 0;
    }
    float h = v->cell_h;
    c->h = h;
    c->axis = a;
    c->side = v->cell_side;
    c->za = axis_of(v->mean, a);
    c->centre = point_on(a, c->za, v->cell_centre[0], v->cell_centre[1]);
    c->vsgl = index;
    static const float half[2] = {0.75f, 0.25f};
    float area = 0.0f, su = 0.0f, sv = 0.0f;
    for (int iu = 0; iu < 2; ++iu)
        for (int iv = 0; iv < 2; ++iv) {
            float *r = c->rect[c->nrect];
            r[0] = fmaxf(v->cell_centre[0] - half[iu] * h, v->cell_lo[0]);
            r[1] = fminf(v->cell_centre[0] + half[iu] * h, v->cell_hi[0]);
            r[2] = fmaxf(v->cell_centre[1] - half[iv] * h, v->cell_lo[1]);
            r[3] = fminf(v->cell_centre[1] + half[iv] * h, v->cell_hi[1]);
            if (!(r[1] > r[0]) || !(r[3] > r[2]))
                continue;
            float ar = (r[1] - r[0]) * (r[3] - r[2]);
            area += ar;
            su += ar * 0.5f * (r[0] + r[1]);
            sv += ar * 0.5f * (r[2] + r[3]);
            ++c->nrect;
        }
    if (!(area > 0.0f))
        return 0;
    c->inv_area = 1.0f / (VSGL__PI * area);
    float facing = axis_of(v->normal, a) * (c->side ? -1.0f : 1.0f) * v->coherence;
    float du = su / area - axis_of(v->mean, (a + 1) % 3), dv = sv / area - axis_of(v->mean, (a + 2) % 3);
    float off = sqrtf(du * du + dv * dv) / h;
    c->fit = v->coherence * v->coherence *
             smoothstep01f((facing - VSGL__NEAR_FACING_LO) / (VSGL__NEAR_FACING_HI - VSGL__NEAR_FACING_LO));
    c->flat = smoothstep01f((facing - VSGL__NEAR_FLAT_LO) / (VSGL__NEAR_FLAT_HI - VSGL__NEAR_FLAT_LO));
    if (c->lambda > 0.0f) {
        /* a specular cell: its tent, truncated to the VPLs' extent, times
         * an irradiance linear across it whose mean is the VPLs' (per axis:
         * the tent is separable, so grad = (mean - the tent's) / its
         * variance), scaled down to stay >= 0 at the corners (a sliver
         * cell's mean can be off by more than a line can move it) */
        double mass[2], mean[2], var[2];
        const float mv[2] = {axis_of(v->mean, (a + 1) % 3), axis_of(v->mean, (a + 2) % 3)};
        double lowest = 1.0, g[2];
        for (int k = 0; k < 2; ++k) {
            /* relative to the lattice point (near_specular) */
            const double ck = v->cell_centre[k];
            double lo = fmax((double)v->cell_lo[k] - ck, -(double)h), hi = fmin((double)v->cell_hi[k] - ck, (double)h);
            c->tlo[k] = (float)lo;
            c->thi[k] = (float)hi;
            vsgl__tent_moments(lo, hi, 0.0, h, &mass[k], &mean[k], &var[k]);
            g[k] = var[k] > 1e-12 * (double)h * h ? ((double)mv[k] - ck - mean[k]) / var[k] : 0.0;
            c->centroid[k] = (float)mean[k];
        }
        if (!(mass[0] > 0.0) || !(mass[1] > 0.0))
            return 0;
        for (int q = 0; q < 4; ++q) {
            double l = 1.0 + g[0] * ((q & 1 ? c->thi[0] : c->tlo[0]) - mean[0]) +
                       g[1] * ((q & 2 ? c->thi[1] : c->tlo[1]) - mean[1]);
            lowest = l < lowest ? l : lowest;
        }
        float scale = lowest < 0.0 ? (float)(1.0 / (1.0 - lowest)) : 1.0f;
        c->grad[0] = (float)g[0] * scale;
        c->grad[1] = (float)g[1] * scale;
        c->inv_area = (float)(1.0 / (VSGL__PI * mass[0] * mass[1]));
    } else {
        c->fit *= 1.0f - smoothstep01f((off - VSGL__NEAR_UNIFORM) / (2.0f * VSGL__NEAR_UNIFORM));
    }
    return c->fit > 0.0f;
}

/* A specular cell's footprint mass: the 2-D Gaussian of mean (pu, pv) and
 * covariance (cuu, cuv; cuv, cvv) over the cell's truncated tent times its
 * linear irradiance, 1 + grad . (y - centroid): Gauss-Legendre over u on
 * each side of the tent's peak (within 6 sigma of the mean), the
 * conditional integral in v in closed form on each side of its peak. */
static float tent_mass(const vsgl_near_cell *c, float pu, float pv, float cuu, float cuv, float cvv)
{
    static const float gx[VSGL__NEAR_GL / 2] = {0.1834346425f, 0.5255324099f, 0.7966664774f, 0.9602898565f};
    static const float gw[VSGL__NEAR_GL / 2] = {0.3626837834f, 0.3137066459f, 0.2223810345f, 0.1012285363f};
    static const float gx4[2] = {0.3399810436f, 0.8611363116f}, gw4[2] = {0.6521451549f, 0.3478548451f};
    _Static_assert(VSGL__TENT_NODES == VSGL__NEAR_GL, "one kernel pass per side");
    /* (pu, pv), the tent's support and the centroid are relative to the
     * lattice point: a scene 100 km from the origin keeps its digits */
    const float h = c->h;
    float su = sqrtf(cuu);
    if (!(su > 0.0f))
        return 0.0f;
    float slope = cuv / cuu, sv = sqrtf(fmaxf(cvv - cuv * slope, 1e-12f * cvv));
    const float ubreak[3] = {c->tlo[0], fminf(fmaxf(0.0f, c->tlo[0]), c->thi[0]), c->thi[0]};
    vsgl_tent_nodes t = {.pu = pu, .pv = pv, .isu = 1.0f / su, .slope = slope, .sv = sv, .isv = 1.0f / sv,
                         .ih = 1.0f / h, .cu = c->centroid[0], .cv = c->centroid[1]};
    t.vb[0] = c->tlo[1];
    t.vb[1] = fminf(fmaxf(0.0f, c->tlo[1]), c->thi[1]);
    t.vb[2] = c->thi[1];
    t.side[0] = t.vb[1] > t.vb[0] ? 1.0f : 0.0f;
    t.side[1] = t.vb[2] > t.vb[1] ? 1.0f : 0.0f;
    t.g[0] = c->grad[0];
    t.g[1] = c->grad[1];
    float sum = 0.0f;
    for (int side = 0; side < 2; ++side) {
        float u0 = fmaxf(ubreak[side], pu - 6.0f * su), u1 = fminf(ubreak[side + 1], pu + 6.0f * su);
        if (!(u1 > u0))
            continue;
        float mid = 0.5f * (u0 + u1), half = 0.5f * (u1 - u0);
        /* 4 nodes where the piece spans at most 3 sigma, 8 where it holds the peak and tails */
        const int nodes = u1 - u0 <= 3.0f * su ? 4 : VSGL__NEAR_GL;
        const float *xs = nodes == 4 ? gx4 : gx, *ws = nodes == 4 ? gw4 : gw;
        for (int k = 0; k < VSGL__NEAR_GL; ++k) {
            t.u[k] = k < nodes ? mid + (k & 1 ? -half : half) * xs[k >> 1] : mid;
            t.w[k] = k < nodes ? ws[k >> 1] : 0.0f;
        }
        sum += vsgl__kernel_tent_nodes(&t) * half;
    }
    return sum / (su * 2.5066282746f);
}

/* A specular cell's light per watt at x (height above its plane), normal n
 * (near_field.h). */
static float near_specular(const vsgl_near_cell *c, v3 x, v3 n, float height)
{
    uint32_t a = c->axis;
    float up = c->side ? -1.0f : 1.0f;
    float cb = axis_of(c->lobe_axis, a) * up, cx = -v3_dot(c->lobe_axis, n);
    if (!(cb > 0.0f) || !(cx > 0.0f))
        return 0.0f;
    float t = height / cb;
    v3 p = v3_sub(x, v3_scale(c->lobe_axis, t));
    uint32_t iu = (a + 1) % 3, iv = (a + 2) % 3;
    float au = axis_of(c->lobe_axis, iu), av = axis_of(c->lobe_axis, iv), s = t * t / c->lambda, k = 1.0f / (cb * cb);
    float cuu = s * (1.0f + au * au * k), cvv = s * (1.0f + av * av * k), cuv = s * au * av * k;
    float pu = axis_of(p, iu) - axis_of(c->centre, iu), pv = axis_of(p, iv) - axis_of(c->centre, iv);
    /* nothing where the footprint (6 sigma) misses the tent */
    float su6 = 6.0f * sqrtf(cuu), sv6 = 6.0f * sqrtf(cvv);
    if (pu + su6 < c->tlo[0] || pu - su6 > c->thi[0] || pv + sv6 < c->tlo[1] || pv - sv6 > c->thi[1])
        return 0.0f;
    /* inv_area = 1 / (pi x the truncated tent's mass) */
    return cx * tent_mass(c, pu, pv, cuu, cuv, cvv) * c->inv_area / cb;
}

float vsgl__near_diffuse(const vsgl_near_cell *c, v3 x, v3 n, float *weight)
{
    *weight = 0.0f;
    uint32_t a = c->axis;
    float height = axis_of(x, a) - c->za;
    if (c->side)
        height = -height;
    if (!(height > 0.0f))
        return 0.0f;
    float r = v3_length(v3_sub(x, c->centre)) / c->h;
    if (!(r < VSGL__NEAR_NONE) || !(height < VSGL__NEAR_HEIGHT_NONE * c->h))
        return 0.0f;
    *weight = c->fit * (1.0f - smoothstep01f((r - VSGL__NEAR_FULL) / (VSGL__NEAR_NONE - VSGL__NEAR_FULL))) *
              (1.0f - smoothstep01f((height / c->h - VSGL__NEAR_HEIGHT_FULL) /
                               (VSGL__NEAR_HEIGHT_NONE - VSGL__NEAR_HEIGHT_FULL)));
    if (c->flat < 1.0f) { /* a cell that bends: receivers across its plane (above) */
        const float along = axis_of(n, a) * (c->side ? -1.0f : 1.0f);
        const float across = smoothstep01f((1.0f - along - VSGL__NEAR_ACROSS_LO) /
                                           (VSGL__NEAR_ACROSS_HI - VSGL__NEAR_ACROSS_LO));
        *weight *= c->flat + (1.0f - c->flat) * across;
    }
    if (!(*weight > 0.0f)) /* callers skip it: no form factor (a bumpy floor's own points) */
        return 0.0f;
    float front = smoothstep01f(height / (VSGL__NEAR_BEHIND * c->h));
    if (c->lambda > 0.0f)
        return front * near_specular(c, x, n, height);
    float ff = 0.0f;
    for (uint32_t k = 0; k < c->nrect; ++k) {
        const float *q = c->rect[k];
        v3 p[4] = {point_on(a, c->za, q[0], q[2]), point_on(a, c->za, q[1], q[2]), point_on(a, c->za, q[1], q[3]),
                   point_on(a, c->za, q[0], q[3])};
        if (v3_dot(n, v3_sub(p[0], x)) <= 0.0f && v3_dot(n, v3_sub(p[1], x)) <= 0.0f &&
            v3_dot(n, v3_sub(p[2], x)) <= 0.0f && v3_dot(n, v3_sub(p[3], x)) <= 0.0f)
            continue; /* wholly behind the receiver */
        ff += polygon_form_factor(x, n, p, 4);
    }
    /* exitance P / A over the steps (a quarter each, in ff and A alike) */
    return front * ff * c->inv_area;
}

/* The box where cell c's near field has any weight: NONE spacings around
 * its centre across its axis, HEIGHT_NONE in front of its plane along it. */
static void region(const vsgl_near_cell *c, float lo[3], float hi[3])
{
    const float p[3] = {c->centre.x, c->centre.y, c->centre.z};
    for (int a = 0; a < 3; ++a) {
        lo[a] = p[a] - VSGL__NEAR_NONE * c->h;
        hi[a] = p[a] + VSGL__NEAR_NONE * c->h;
    }
    float depth = VSGL__NEAR_HEIGHT_NONE * c->h;
    if (c->side) {
        lo[c->axis] = c->za - depth;
        hi[c->axis] = c->za;
    } else {
        lo[c->axis] = c->za;
        hi[c->axis] = c->za + depth;
    }
}

static void cell_range(const vsgl_near_index *ix, const vsgl_near_cell *cell, int32_t lo[3], int32_t hi[3])
{
    float rl[3], rh[3];
    region(cell, rl, rh);
    const float o[3] = {ix->lo.x, ix->lo.y, ix->lo.z};
    for (int a = 0; a < 3; ++a) {
        float l = floorf((rl[a] - o[a]) * ix->inv), h = floorf((rh[a] - o[a]) * ix->inv);
        lo[a] = l < 0.0f ? 0 : l > (float)(ix->dims[a] - 1) ? ix->dims[a] - 1 : (int32_t)l;
        hi[a] = h < 0.0f ? 0 : h > (float)(ix->dims[a] - 1) ? ix->dims[a] - 1 : (int32_t)h;
    }
}

int vsgl__near_index_build(const vsgl_vsgl_set *set, vsgl_near_index *ix)
{
    memset(ix, 0, sizeof *ix);
    ix->cells = malloc((set->count + 1) * sizeof *ix->cells);
    ix->cell_of = malloc((set->count + 1) * sizeof *ix->cell_of);
    if (!ix->cells || !ix->cell_of) {
        vsgl__near_index_free(ix);
        return 0;
    }
    v3 lo = v3_make(INFINITY, INFINITY, INFINITY), hi = v3_neg(lo);
    float rmax = 0.0f;
    size_t n = 0;
    for (size_t k = 0; k < set->count; ++k) {
        ix->cell_of[k] = -1;
        vsgl_near_cell *c = &ix->cells[n];
        if (!vsgl__near_cell(&set->items[k], (uint32_t)k, c))
            continue;
        float rl[3], rh[3];
        region(c, rl, rh);
        lo = v3_make(fminf(lo.x, rl[0]), fminf(lo.y, rl[1]), fminf(lo.z, rl[2]));
        hi = v3_make(fmaxf(hi.x, rh[0]), fmaxf(hi.y, rh[1]), fmaxf(hi.z, rh[2]));
        rmax = fmaxf(rmax, c->h);
        ix->cell_of[k] = (int32_t)n++;
    }
    v3 ext = v3_sub(hi, lo);
    if (!n || !(rmax > 0.0f) || !(ext.x < INFINITY) || !(ext.y < INFINITY) || !(ext.z < INFINITY))
        return 1; /* no near field: an empty grid */
    /* grid cells of half the largest spacing (a receiver then tests about the cells whose region holds it) */
    float size = fmaxf(0.5f * rmax, fmaxf(ext.x, fmaxf(ext.y, ext.z)) / (float)VSGL__NEAR_GRID_MAX);
    ix->lo = lo;
    ix->inv = 1.0f / size;
    const float e[3] = {ext.x, ext.y, ext.z};
    size_t cells = 1;
    for (int a = 0; a < 3; ++a) {
        float d = ceilf(e[a] * ix->inv);
        ix->dims[a] = d < 1.0f ? 1 : d > (float)VSGL__NEAR_GRID_MAX ? VSGL__NEAR_GRID_MAX : (int32_t)d;
        cells *= (size_t)ix->dims[a];
    }
    ix->start = calloc(cells + 1, sizeof *ix->start);
    if (!ix->start) {
        vsgl__near_index_free(ix);
        return 0;
    }
    /* two passes: count per grid cell, then fill */
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t k = 0; k < n; ++k) {
            const vsgl_near_cell *c = &ix->cells[k];
            int32_t l[3], h[3];
            cell_range(ix, c, l, h);
            for (int32_t z = l[2]; z <= h[2]; ++z)
                for (int32_t y = l[1]; y <= h[1]; ++y)
                    for (int32_t x = l[0]; x <= h[0]; ++x) {
                        size_t g = ((size_t)z * ix->dims[1] + y) * ix->dims[0] + x;
                        if (pass == 0)
                            ++ix->start[g + 1];
                        else
                            ix->items[ix->start[g]++] = (uint32_t)k;
                    }
        }
        if (pass == 0) {
            for (size_t g = 0; g < cells; ++g)
                ix->start[g + 1] += ix->start[g];
            ix->items = malloc(((size_t)ix->start[cells] + 1) * sizeof *ix->items);
            if (!ix->items) {
                vsgl__near_index_free(ix);
                return 0;
            }
        }
    }
    /* the fill moved each start to the next grid cell's: shift back */
    for (size_t g = cells; g > 0; --g)
        ix->start[g] = ix->start[g - 1];
    ix->start[0] = 0;
    return 1;
}

void vsgl__near_index_free(vsgl_near_index *ix)
{
    free(ix->cells);
    free(ix->cell_of);
    free(ix->start);
    free(ix->items);
    memset(ix, 0, sizeof *ix);
}

const uint32_t *vsgl__near_candidates(const vsgl_near_index *ix, v3 x, size_t *n)
{
    *n = 0;
    if (!ix->start)
        return NULL;
    const float p[3] = {(x.x - ix->lo.x) * ix->inv, (x.y - ix->lo.y) * ix->inv, (x.z - ix->lo.z) * ix->inv};
    int32_t c[3];
    for (int a = 0; a < 3; ++a) {
        if (!(p[a] >= 0.0f) || !(p[a] < (float)ix->dims[a]))
            return NULL;
        c[a] = (int32_t)p[a];
    }
    size_t g = ((size_t)c[2] * ix->dims[1] + c[1]) * ix->dims[0] + c[0];
    *n = ix->start[g + 1] - ix->start[g];
    return ix->items + ix->start[g];
}
