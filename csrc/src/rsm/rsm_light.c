/* Per-light-type RSM parameterisations with Cycles' light units
 * (Blender 3.4 semantics, measured; docs/units.md):
 *
 * - point: cube map (6 faces) in the light's frame, intensity P/(4 pi) W/sr;
 *   soft radius ignored (VPLs are seen from the centre).
 * - spot: intensity P/(4 pi) cos(theta) smoothstep((cos(theta) - cos(size/2))
 *   / ((1 - cos(size/2)) blend)); the extra cos(theta) and the cone ignoring
 *   the object's scale are Blender 3.4's behaviour (measured). Blender 4.0+
 *   (VSGL_LIGHT_FLAG_BLENDER_4, measured in 5.0): no cos(theta), and theta is
 *   taken in the light's frame divided by the object's scale per axis (an
 *   elliptical cone for a non-uniform scale). One perspective face over the
 *   cone when its widest half-angle is <= 60 degrees, else a cube.
 * - sun: orthographic map over the scene bounds, W/m^2 times the texel's
 *   area across the beam; sun angle ignored (parallel rays). A window
 *   (vsgl__rsm_light_window) takes a square of the map at a finer step of
 *   the same grid.
 * - area: one face, concentric (Shirley-Chiu) map of the cosine-weighted
 *   hemisphere below the light: every texel carries the same projected
 *   solid angle pi/res^2, so the flux is L A (pi/res^2) times the spread
 *   mask, L A = P/4 (Blender 3.x) or P/pi (4.x+). Ray origins are stratified over the emitting shape (every
 *   aligned 2^k x 2^k texel block covers a 2^k x 2^k grid on the light) (a large light is
 *   sampled over its area, not as a point).
 *
 * Texel weights are integrated exactly (rectangle solid angles) and the
 * masks are supersampled 4x4 per texel; rays go through texel centres. */
#include "rsm/rsm_light.h"
#include "math/constants.h"

#include <math.h>
#include <string.h>

#define SUB 4 /* mask supersampling per texel axis */

double vsgl__rsm_rect_solid_angle(double x0, double x1, double y0, double y1)
{
#define F(x, y) atan2((x) * (y), sqrt(1.0 + (x) * (x) + (y) * (y)))
    return F(x1, y1) - F(x0, y1) - F(x1, y0) + F(x0, y0);
#undef F
}

static v3 col3(const float *m, int c) { return v3_make(m[c], m[4 + c], m[8 + c]); }

static double smoothstep01(double f)
{
    f = f < 0 ? 0 : (f > 1 ? 1 : f);
    return f * f * (3.0 - 2.0 * f);
}

/* Relative spot intensity at cosine c to the axis (Blender 3.4: the
 * smoothstep blend times c; 4.0+: the blend alone). */
static double spot_mask(const vsgl_rsm_light *l, double c)
{
    if (c <= l->cos_half)
        return 0.0;
    double t = c - l->cos_half, a = l->spot_v4 ? 1.0 : c;
    if (t < l->smooth && l->smooth != 0.0)
        a *= smoothstep01(t / l->smooth);
    return a;
}

/* The cosine the mask sees for a local direction (x, y, z) of the light
 * frame (the spot points along -z): 3.4 the plain one, 4.0+ the one in the
 * frame divided by the object's scale. */
static double spot_cos(const vsgl_rsm_light *l, double x, double y, double z)
{
    if (l->spot_v4) {
        x *= l->inv_scale[0];
        y *= l->inv_scale[1];
        z *= l->inv_scale[2];
    }
    return -z / sqrt(x * x + y * y + z * z);
}

/* Area spread: fraction of a soft box's slat grid left open at angle theta
 * (tan t), normalised so that the light's total power does not depend on
 * the spread (docs/units.md gives the measured check). */
static double spread_mask(const vsgl_rsm_light *l, double cos_t)
{
    if (l->tan_half_spread <= 0.0)
        return 1.0;
    if (cos_t <= 0.0)
        return 0.0;
    double tan_t = sqrt(fmax(0.0, 1.0 - cos_t * cos_t)) / cos_t;
    return fmax(0.0, 1.0 - tan_t / l->tan_half_spread) * l->spread_norm;
}

/* Cube face f: direction = major + u U + v V (light-frame axes). */
static void cube_face(int f, int *axis, double *sign, int *ua, int *va)
{
    *axis = f / 2;
    *sign = (f & 1) ? -1.0 : 1.0;
    *ua = (*axis + 1) % 3;
    *va = (*axis + 2) % 3;
}

static v3 frame_dir(const vsgl_rsm_light *l, double x, double y, double z)
{
    return v3_add(v3_add(v3_scale(l->ax, (float)x), v3_scale(l->ay, (float)y)), v3_scale(l->az, (float)z));
}

void vsgl__rsm_light_setup(const vsgl_scene *scene, uint32_t index, uint32_t res, vsgl_rsm_light *out)
{
    uint32_t n;
    const vsgl_light *L = &vsgl__scene_lights(scene, &n)[index];
    memset(out, 0, sizeof *out);
    out->type = L->type;
    out->res = res;
    out->faces = 1;
    const float *m = L->world_from_light;
    out->pos = v3_make(m[3], m[7], m[11]);
    v3 sx = col3(m, 0), sy = col3(m, 1), sz = col3(m, 2);
    out->az = v3_normalize(sz);
    out->ax = v3_normalize(v3_sub(sx, v3_scale(out->az, v3_dot(sx, out->az))));
    if (v3_length(out->ax) == 0.0f)
        v3_basis(out->az, &out->ax, &out->ay);
    else
        out->ay = v3_cross(out->az, out->ax);
    for (int c = 0; c < 3; ++c)
        out->rgb[c] = (double)L->color[c] * (double)L->power;
    switch (L->type) {
    case VSGL_LIGHT_POINT:
        out->faces = 6;
        break;
    case VSGL_LIGHT_SPOT: {
        double half = 0.5 * (double)L->spot_size;
        out->cos_half = cos(half);
        out->smooth = (1.0 - out->cos_half) * (double)L->spot_blend;
        out->inv_scale[0] = out->inv_scale[1] = out->inv_scale[2] = 1.0;
        double widest = half; /* the cone's widest half-angle in the light frame */
        if (L->flags & VSGL_LIGHT_FLAG_BLENDER_4) {
            out->spot_v4 = 1;
            double s3[3] = {v3_dot(sx, out->ax), v3_dot(sy, out->ay), v3_length(sz)};
            for (int k = 0; k < 3; ++k)
                out->inv_scale[k] = s3[k] > 0.0 ? 1.0 / fabs(s3[k]) : 1.0;
            if (half < 0.5 * VSGL__PI_D) {
                double t = tan(half) * fmax(s3[0], s3[1]) / s3[2];
                widest = atan(t);
            } else {
                widest = VSGL__PI_D; /* a cone past the horizon stays past it */
            }
        }
        if (widest <= VSGL__PI_D / 3.0)
            out->tan_half = tan(widest) * (1.0 + 1e-6);
        else
            out->faces = 6;
        break;
    }
    case VSGL_LIGHT_SUN: {
        v3 d = v3_neg(out->az);
        out->sun_dir = d;
        v3 lo, hi, u, v;
        vsgl__scene_bounds(scene, &lo, &hi);
        v3_basis(d, &u, &v);
        double umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY, dmin = INFINITY, dmax = -INFINITY;
        for (int k = 0; k < 8; ++k) {
            v3 p = v3_make((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
            double pu = v3_dot(p, u), pv = v3_dot(p, v), pd = v3_dot(p, d);
            umin = fmin(umin, pu); umax = fmax(umax, pu);
            vmin = fmin(vmin, pv); vmax = fmax(vmax, pv);
            dmin = fmin(dmin, pd); dmax = fmax(dmax, pd);
        }
        if (!(umin <= umax)) { /* empty scene */
            umin = vmin = dmin = 0;
            umax = vmax = dmax = 1;
        }
        double pad = 1e-4 * fmax(fmax(umax - umin, vmax - vmin), 1e-6);
        umin -= pad; umax += pad; vmin -= pad; vmax += pad;
        double depth = dmax - dmin;
        double back = dmin - 0.01 * depth - pad;
        out->sun_u = v3_scale(u, (float)((umax - umin) / res));
        out->sun_v = v3_scale(v, (float)(-(vmax - vmin) / res)); /* row 0 at +v */
        out->sun_origin = v3_add(v3_add(v3_scale(u, (float)umin), v3_scale(v, (float)vmax)), v3_scale(d, (float)back));
        out->sun_texel_area = (umax - umin) * (vmax - vmin) / ((double)res * res);
        out->sun_tmax = (float)(1.1 * depth + 4 * pad + 1.0);
        break;
    }
    case VSGL_LIGHT_AREA: {
        out->shape = L->area_shape;
        out->area_power = (L->flags & VSGL_LIGHT_FLAG_BLENDER_4) ? 1.0 : 0.25 * VSGL__PI_D;
        int square = L->area_shape == VSGL_AREA_SQUARE || L->area_shape == VSGL_AREA_DISK;
        out->size_x = (double)L->size_x * v3_length(sx);
        out->size_y = (double)(square ? L->size_x : L->size_y) * v3_length(sy);
        double half = 0.5 * (double)L->spread;
        if (half < 0.5 * VSGL__PI_D - 1e-6) {
            double T = tan(half);
            out->tan_half_spread = T;
            out->spread_norm = T / (T - half);
        }
        break;
    }
    default:
        break;
    }
}

void vsgl__rsm_light_window(vsgl_rsm_light *l, uint32_t zoom, int64_t col0, int64_t row0)
{
    if (l->type != VSGL_LIGHT_SUN || zoom <= 1)
        return;
    l->sun_u = v3_scale(l->sun_u, 1.0f / (float)zoom);
    l->sun_v = v3_scale(l->sun_v, 1.0f / (float)zoom);
    l->sun_origin = v3_add(l->sun_origin, v3_add(v3_scale(l->sun_u, (float)col0), v3_scale(l->sun_v, (float)row0)));
    l->sun_texel_area /= (double)zoom * zoom;
}

/* Concentric map of [0,1]^2 to the unit disk (Shirley & Chiu 1997). */
static void concentric(double a, double b, double *x, double *y)
{
    a = 2.0 * a - 1.0;
    b = 2.0 * b - 1.0;
    if (a == 0.0 && b == 0.0) {
        *x = *y = 0.0;
        return;
    }
    double r, phi;
    if (fabs(a) > fabs(b)) {
        r = a;
        phi = (VSGL__PI_D / 4.0) * (b / a);
    } else {
        r = b;
        phi = (VSGL__PI_D / 2.0) - (VSGL__PI_D / 4.0) * (a / b);
    }
    *x = r * cos(phi);
    *y = r * sin(phi);
}

/* A texel of a point/spot face: the rectangle [x0, x1] x [y0, y1] it covers
 * on the face's plane at distance 1, and which local axes that plane spans
 * (the face looks along `sign` x axis `axis`; u and v are axes `ua`, `va`). */
typedef struct face_texel {
    double x0, x1, y0, y1;
    int axis, ua, va;
    double sign;
} face_texel;

static face_texel point_spot_texel(const vsgl_rsm_light *l, uint32_t face, uint32_t row, uint32_t col)
{
    double res = (double)l->res;
    face_texel t = {0, 0, 0, 0, 2, 0, 1, -1.0};
    if (l->faces == 6) {
        t.x0 = 2.0 * col / res - 1.0;
        t.x1 = 2.0 * (col + 1) / res - 1.0;
        t.y1 = 1.0 - 2.0 * row / res;
        t.y0 = 1.0 - 2.0 * (row + 1) / res;
        cube_face((int)face, &t.axis, &t.sign, &t.ua, &t.va);
    } else {
        t.x0 = l->tan_half * (2.0 * col / res - 1.0);
        t.x1 = l->tan_half * (2.0 * (col + 1) / res - 1.0);
        t.y1 = l->tan_half * (1.0 - 2.0 * row / res);
        t.y0 = l->tan_half * (1.0 - 2.0 * (row + 1) / res);
    }
    return t;
}

/* The spot mask's cosine for point (x, y) of the texel's face plane. */
static double face_spot_cos(const vsgl_rsm_light *l, const face_texel *t, double x, double y)
{
    double loc[3];
    loc[t->axis] = t->sign;
    loc[t->ua] = x;
    loc[t->va] = y;
    return spot_cos(l, loc[0], loc[1], loc[2]);
}

/* The spot's share of a texel of solid angle `beam`, over 4 pi, from the
 * mask's cosines at its corners (c00 at (x0, y0), c01 at (x0, y1), ...). */
static double spot_texel_weight_c(const vsgl_rsm_light *l, const face_texel *t, double beam, double c00, double c01,
                                  double c10, double c11)
{
    double x0 = t->x0, x1 = t->x1, y0 = t->y0, y1 = t->y1;
    double xc = 0.5 * (x0 + x1), yc = 0.5 * (y0 + y1);
    double cc = face_spot_cos(l, t, xc, yc);
    double cmin = fmin(fmin(fmin(c00, c01), fmin(c10, c11)), cc);
    double cmax = fmax(fmax(fmax(c00, c01), fmax(c10, c11)), cc);
    if (cmax <= l->cos_half)
        return 0.0; /* wholly outside the cone */
    if (cmin >= l->cos_half + l->smooth) /* inside the blend: the mask is 1 (4.0+) or the cosine to the axis (3.4), smooth */
        return (l->spot_v4 ? 1.0 : cc) * beam / (4.0 * VSGL__PI_D);
    /* straddles the cone edge or the blend: supersample the mask,
     * sub-rectangle solid angles from the (SUB+1)^2 corner values */
    double F[SUB + 1][SUB + 1], w = 0.0;
    for (int j = 0; j <= SUB; ++j)
        for (int i = 0; i <= SUB; ++i) {
            double a = x0 + (x1 - x0) * i / SUB, b = y0 + (y1 - y0) * j / SUB;
            F[j][i] = atan2(a * b, sqrt(1.0 + a * a + b * b));
        }
    for (int j = 0; j < SUB; ++j)
        for (int i = 0; i < SUB; ++i) {
            double xm = x0 + (x1 - x0) * (i + 0.5) / SUB, ym = y0 + (y1 - y0) * (j + 0.5) / SUB;
            double mk = spot_mask(l, face_spot_cos(l, t, xm, ym));
            if (mk > 0.0)
                w += mk * (F[j + 1][i + 1] - F[j][i + 1] - F[j + 1][i] + F[j][i]);
        }
    return w / (4.0 * VSGL__PI_D);
}

/* The spot's share of a texel of solid angle `beam`, over 4 pi. */
static double spot_texel_weight(const vsgl_rsm_light *l, const face_texel *t, double beam)
{
    return spot_texel_weight_c(l, t, beam, face_spot_cos(l, t, t->x0, t->y0), face_spot_cos(l, t, t->x0, t->y1),
                               face_spot_cos(l, t, t->x1, t->y0), face_spot_cos(l, t, t->x1, t->y1));
}

/* Point and spot texels: rays from the centre through the texel's centre. */
static double point_spot_texel_ray(const vsgl_rsm_light *l, uint32_t face, uint32_t row, uint32_t col, v3 *org,
                                   v3 *dir, double *beam)
{
    face_texel t = point_spot_texel(l, face, row, col);
    double loc[3];
    loc[t.axis] = t.sign;
    loc[t.ua] = 0.5 * (t.x0 + t.x1);
    loc[t.va] = 0.5 * (t.y0 + t.y1);
    *dir = v3_normalize(frame_dir(l, loc[0], loc[1], loc[2]));
    *org = l->pos;
    *beam = vsgl__rsm_rect_solid_angle(t.x0, t.x1, t.y0, t.y1);
    return l->type == VSGL_LIGHT_POINT ? *beam / (4.0 * VSGL__PI_D) : spot_texel_weight(l, &t, *beam);
}

/* Sun texels: parallel rays from the map's plane. */
static double sun_texel_ray(const vsgl_rsm_light *l, uint32_t row, uint32_t col, v3 *org, v3 *dir, double *beam)
{
    *dir = l->sun_dir;
    *org = v3_add(l->sun_origin, v3_add(v3_scale(l->sun_u, (float)(col + 0.5)), v3_scale(l->sun_v, (float)(row + 0.5))));
    *beam = l->sun_texel_area;
    return l->sun_texel_area;
}

/* The area light's spread mask averaged over a texel (the cosine is
 * already in the measure). */
static double area_texel_mask(const vsgl_rsm_light *l, uint32_t row, uint32_t col)
{
    if (!(l->tan_half_spread > 0.0))
        return 1.0;
    double res = (double)l->res, mk = 0.0;
    for (int j = 0; j < SUB; ++j)
        for (int i = 0; i < SUB; ++i) {
            double sx, sy;
            concentric((col + (i + 0.5) / SUB) / res, 1.0 - (row + (j + 0.5) / SUB) / res, &sx, &sy);
            mk += spread_mask(l, sqrt(fmax(0.0, 1.0 - sx * sx - sy * sy)));
        }
    return mk / (SUB * SUB);
}

/* A texel's ray origin on the area light's shape: point k of the first two
 * Sobol dimensions (a (0,2)-sequence in base 2: van der Corput and the Pascal
 * matrix), k the texel's Morton index within its aligned 8x8 block. An
 * aligned 2^j x 2^j block of texels (j <= 3; nearly one direction) holds 4^j
 * consecutive points, a (0,2j,2)-net: one origin in every elementary
 * rectangle of area 4^-j of the light (2^j x 2^j strata, 4^j distinct
 * coordinates along either axis: 64 per 8x8 block), and neighbours
 * alternate at the finest scale. Alternatives measured against Cycles
 * (kernel 0.3 m): an R2 sequence over the texel index made a 2 % density
 * modulation; origins marching monotonically with the direction in 8x8
 * blocks a comb of period 8 texels, 1.6 % off near a light's horizon;
 * random jitter or per-block scrambling 0.6-2.7 % noise; 16x16 blocks
 * (period 16) 1.0 % at a corner. The strata (bitrev(col & 7), bitrev(row &
 * 7)) of an 8x8 grid, separable, gave the light's axes only 8 distinct
 * coordinates: on a wall far off near the light's horizon, where an
 * origin's offset moves its hit by several texel spacings, the hits piled
 * up in 8 shifted copies of every 8th texel's grid, bands of 0 to 3x the
 * density 0.1 m apart (the demo room's lamp panel on the window wall, RSM
 * 128), which a glossy floor reflected as dark and bright stripes
 * (docs/validation.md; tests/c/test_rsm.c rsm_area_light_lights_a_far_wall_evenly). */
#define VSGL__AREA_BLOCK_BITS 3 /* 8x8 blocks */
static uint32_t morton2(uint32_t row, uint32_t col)
{
    uint32_t k = 0;
    for (int b = 0; b < VSGL__AREA_BLOCK_BITS; ++b)
        k |= ((col >> b) & 1u) << (2 * b) | ((row >> b) & 1u) << (2 * b + 1);
    return k;
}

static void sobol02(uint32_t k, double *s, double *t)
{
    const int bits = 2 * VSGL__AREA_BLOCK_BITS; /* k < 2^bits: that many bits of each coordinate */
    uint32_t a = 0, c = 0;
    for (int b = 0; b < bits; ++b) /* van der Corput: k's bits reversed */
        a |= ((k >> b) & 1u) << (bits - 1 - b);
    for (uint32_t v = 1u << (bits - 1), i = k; i; i >>= 1, v ^= v >> 1) /* the Pascal matrix, column by column */
        if (i & 1u)
            c ^= v;
    *s = ((double)a + 0.5) / (double)(1u << bits);
    *t = ((double)c + 0.5) / (double)(1u << bits);
}

static v3 area_texel_origin(const vsgl_rsm_light *l, uint32_t row, uint32_t col)
{
    double s, t;
    const uint32_t m = (1u << VSGL__AREA_BLOCK_BITS) - 1u;
    sobol02(morton2(row & m, col & m), &s, &t);
    double px, py;
    if (l->shape == VSGL_AREA_DISK || l->shape == VSGL_AREA_ELLIPSE) {
        concentric(s, t, &px, &py);
        px *= 0.5;
        py *= 0.5;
    } else {
        px = s - 0.5;
        py = t - 0.5;
    }
    return v3_add(l->pos, frame_dir(l, px * l->size_x, py * l->size_y, 0.0));
}

/* Area texels: the concentric map's direction, from a stratified point on the shape. */
static double area_texel_ray(const vsgl_rsm_light *l, uint32_t row, uint32_t col, v3 *org, v3 *dir, double *beam)
{
    double res = (double)l->res, x, y;
    concentric((col + 0.5) / res, 1.0 - (row + 0.5) / res, &x, &y);
    double z = sqrt(fmax(0.0, 1.0 - x * x - y * y));
    *dir = v3_normalize(frame_dir(l, x, y, -z));
    *beam = VSGL__PI_D / (res * res) / fmax(z, 0.5 / res); /* solid angle = projected / cos */
    *org = area_texel_origin(l, row, col);
    return l->area_power / (res * res) * area_texel_mask(l, row, col); /* radiance x area x projected solid angle pi/res^2 */
}

int vsgl__rsm_light_texel(const vsgl_rsm_light *l, uint32_t face, uint32_t row, uint32_t col,
                          v3 *org, v3 *dir, double flux[3], double *beam)
{
    double w = 0.0;
    *beam = 0.0;
    flux[0] = flux[1] = flux[2] = 0.0;
    switch (l->type) {
    case VSGL_LIGHT_POINT:
    case VSGL_LIGHT_SPOT: w = point_spot_texel_ray(l, face, row, col, org, dir, beam); break;
    case VSGL_LIGHT_SUN: w = sun_texel_ray(l, row, col, org, dir, beam); break;
    case VSGL_LIGHT_AREA: w = area_texel_ray(l, row, col, org, dir, beam); break;
    default: return 0;
    }
    if (!(w > 0.0))
        return 0;
    for (int c = 0; c < 3; ++c)
        flux[c] = l->rgb[c] * w;
    return 1;
}

/* A row of a point/spot face: vsgl__rsm_light_texel for every column, with
 * the values that depend on a texel corner alone (the solid-angle terms
 * F(x, y) and the spot mask's cosines) computed once per corner and shared
 * by the texels that meet there: the same functions of the same arguments,
 * so the same results (a texel whose corners do not equal the table's, bit
 * for bit, computes its own). */
static void point_spot_row(const vsgl_rsm_light *l, uint32_t face, uint32_t row, v3 *org, v3 *dir, double *fl,
                           int *lit, double *scratch)
{
    const uint32_t res = l->res;
    double *X = scratch, *Ft = X + (res + 1), *Fb = Ft + (res + 1), *Ct = Fb + (res + 1), *Cb = Ct + (res + 1);
    const int spot = l->type == VSGL_LIGHT_SPOT;
    face_texel t = point_spot_texel(l, face, row, 0);
    for (uint32_t i = 0; i <= res; ++i) {
        face_texel ti = point_spot_texel(l, face, row, i < res ? i : res - 1);
        X[i] = i < res ? ti.x0 : ti.x1;
#define F(x, y) atan2((x) * (y), sqrt(1.0 + (x) * (x) + (y) * (y)))
        Ft[i] = F(X[i], t.y1);
        Fb[i] = F(X[i], t.y0);
#undef F
        if (spot) {
            Ct[i] = face_spot_cos(l, &t, X[i], t.y1);
            Cb[i] = face_spot_cos(l, &t, X[i], t.y0);
        }
    }
    for (uint32_t c = 0; c < res; ++c) {
        double *f = fl + 4 * c;
        t = point_spot_texel(l, face, row, c);
        if (!(t.x0 == X[c] && t.x1 == X[c + 1])) { /* (not expected: the same expressions) */
            lit[c] = vsgl__rsm_light_texel(l, face, row, c, &org[c], &dir[c], f, &f[3]);
            continue;
        }
        double loc[3];
        loc[t.axis] = t.sign;
        loc[t.ua] = 0.5 * (t.x0 + t.x1);
        loc[t.va] = 0.5 * (t.y0 + t.y1);
        dir[c] = v3_normalize(frame_dir(l, loc[0], loc[1], loc[2]));
        org[c] = l->pos;
        /* vsgl__rsm_rect_solid_angle(x0, x1, y0, y1): F(x1, y1) - F(x0, y1) - F(x1, y0) + F(x0, y0) */
        const double beam = Ft[c + 1] - Ft[c] - Fb[c + 1] + Fb[c];
        const double w = spot ? spot_texel_weight_c(l, &t, beam, Cb[c], Ct[c], Cb[c + 1], Ct[c + 1])
                              : beam / (4.0 * VSGL__PI_D);
        f[3] = beam;
        f[0] = f[1] = f[2] = 0.0;
        lit[c] = w > 0.0;
        if (lit[c])
            for (int k = 0; k < 3; ++k)
                f[k] = l->rgb[k] * w;
    }
}

void vsgl__rsm_light_row(const vsgl_rsm_light *l, uint32_t face, uint32_t row, v3 *org, v3 *dir, double *fl,
                         int *lit, double *scratch)
{
    if (l->type == VSGL_LIGHT_POINT || l->type == VSGL_LIGHT_SPOT) {
        point_spot_row(l, face, row, org, dir, fl, lit, scratch);
        return;
    }
    for (uint32_t c = 0; c < l->res; ++c)
        lit[c] = vsgl__rsm_light_texel(l, face, row, c, &org[c], &dir[c], &fl[4 * c], &fl[4 * c + 3]);
}

void vsgl__rsm_light_emitted(const vsgl_rsm_light *l, double out[3])
{
    double w = 0.0;
    switch (l->type) {
    case VSGL_LIGHT_POINT:
        w = 1.0;
        break;
    case VSGL_LIGHT_SPOT:
        if (!l->spot_v4 || (l->inv_scale[0] == l->inv_scale[1] && l->inv_scale[1] == l->inv_scale[2])) {
            /* (1/4pi) * 2pi * int_{cos_half}^1 mask(c) dc, midpoint rule */
            enum { N = 200000 };
            double s = 0.0, a = l->cos_half, h = (1.0 - a) / N;
            for (int i = 0; i < N; ++i)
                s += spot_mask(l, a + (i + 0.5) * h);
            w = 0.5 * s * h;
        } else {
            /* elliptical cone: (1/4pi) int mask dw over the sphere in the
             * light frame, midpoint rule in (cos theta, phi) about the axis */
            enum { NT = 2000, NP = 720 };
            double s = 0.0, ht = 2.0 / NT, hp = 2.0 * VSGL__PI_D / NP;
            for (int i = 0; i < NT; ++i) {
                double c = 1.0 - (i + 0.5) * ht, r = sqrt(fmax(0.0, 1.0 - c * c));
                for (int j = 0; j < NP; ++j) {
                    double ph = (j + 0.5) * hp;
                    s += spot_mask(l, spot_cos(l, r * cos(ph), r * sin(ph), -c));
                }
            }
            w = s * ht * hp / (4.0 * VSGL__PI_D);
        }
        break;
    case VSGL_LIGHT_SUN:
        w = l->sun_texel_area * (double)l->res * l->res;
        break;
    case VSGL_LIGHT_AREA: {
        if (l->tan_half_spread <= 0.0) {
            w = l->area_power;
        } else {
            /* (L A / P) * 2 pi * int_0^{pi/2} mask cos sin dtheta, L A / P = area_power / pi */
            enum { N = 200000 };
            double s = 0.0, h = 0.5 * VSGL__PI_D / N;
            for (int i = 0; i < N; ++i) {
                double th = (i + 0.5) * h;
                s += spread_mask(l, cos(th)) * cos(th) * sin(th);
            }
            w = l->area_power * 2.0 * s * h;
        }
        break;
    }
    default:
        break;
    }
    for (int c = 0; c < 3; ++c)
        out[c] = l->rgb[c] * w;
}
