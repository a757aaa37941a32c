/* MRP geometry on the rectangle: the specular peak (Eq. 12), the disk's
 * attenuation axes (Eq. 18) and the rectangle/disk overlap (Eq. 36, and the
 * exact area). docs/mrp.md. */
#include "mrp/mrp.h"
#include "mrp/geom.h"
#include "math/constants.h"

int vsgl__mrp_rect_make(d3 center, d3 normal, d3 u_dir, double half_u, double half_v, vsgl__mrp_rect *out)
{
    d3 n = d3_normalize(normal);
    d3 u = d3_normalize(d3_sub(u_dir, d3_scale(n, d3_dot(u_dir, n))));
    out->center = center;
    out->normal = n;
    out->u = u;
    out->v = d3_cross(n, u);
    out->half_u = half_u > 0.0 && half_u < INFINITY ? half_u : 0.0;
    out->half_v = half_v > 0.0 && half_v < INFINITY ? half_v : 0.0;
    if (d3_is_zero(n) || d3_is_zero(u)) {
        out->half_u = out->half_v = 0.0;
        return 0;
    }
    return 1;
}

d3 vsgl__mrp_reflect(d3 i, d3 n) { return d3_sub(d3_scale(n, 2.0 * d3_dot(i, n)), i); }

int vsgl__mrp_peak(const vsgl__mrp_rect *rc, d3 x, d3 r, d3 *y)
{
    *y = x;
    double h = d3_dot(d3_sub(x, rc->center), rc->normal), rn = d3_dot(r, rc->normal);
    if (!(h > 0.0) || !(rn > 0.0))
        return 0;
    double t = h / rn;
    d3 p = d3_sub(x, d3_scale(r, t));
    if (!(t < INFINITY) || !d3_finite(p))
        return 0;
    *y = p;
    return 1;
}

void vsgl__mrp_disk_axes(d3 yx, d3 n_r, d3 *u, d3 *v)
{
    d3 vv = d3_cross(yx, n_r);
    if (!(d3_length(vv) > 1e-9)) {
        d3_basis(n_r, u, v);
        return;
    }
    *v = d3_normalize(vv);
    *u = d3_normalize(d3_cross(n_r, *v));
}

/* The disk centre in the rectangle's coordinates. */
static void local(const vsgl__mrp_rect *rc, d3 y, double *cu, double *cv)
{
    d3 d = d3_sub(y, rc->center);
    *cu = d3_dot(d, rc->u);
    *cv = d3_dot(d, rc->v);
}

/* Box J of I = disk(c, r) intersect [-a, a] x [-b, b]: the disk's slice at
 * height s has half-width sqrt(r^2 - (s - c)^2), widest at the s of the
 * band closest to c. Returns 0 when I is empty. */
static int overlap_box(double cu, double cv, double r, double a, double b, double box[4])
{
    double du = fabs(cu) > a ? fabs(cu) - a : 0.0, dv = fabs(cv) > b ? fabs(cv) - b : 0.0;
    if (!(du * du + dv * dv < r * r) || !(a > 0.0) || !(b > 0.0))
        return 0;
    double wu = sqrt(r * r - dv * dv), wv = sqrt(r * r - du * du);
    box[0] = d_max(-a, cu - wu);
    box[1] = d_min(a, cu + wu);
    box[2] = d_max(-b, cv - wv);
    box[3] = d_min(b, cv + wv);
    return box[1] > box[0] && box[3] > box[2];
}

double vsgl__mrp_overlap_bbox(const vsgl__mrp_rect *rc, d3 y, double rd)
{
    double cu, cv, box[4];
    local(rc, y, &cu, &cv);
    if (!(rd > 0.0) || !(rd < INFINITY) || !overlap_box(cu, cv, rd, rc->half_u, rc->half_v, box))
        return 0.0;
    /* (b-a)/r in [0, 2] each (clamped: a centre far from the origin rounds) */
    double su = d_min((box[1] - box[0]) / rd, 2.0), sv = d_min((box[3] - box[2]) / rd, 2.0);
    return su * sv / VSGL__PI_D;
}

d3 vsgl__mrp_overlap_center(const vsgl__mrp_rect *rc, d3 y, double rd)
{
    double cu, cv, box[4];
    local(rc, y, &cu, &cv);
    if (!(rd > 0.0) || !(rd < INFINITY) || !overlap_box(cu, cv, rd, rc->half_u, rc->half_v, box))
        return y;
    double mu = 0.5 * (box[0] + box[1]), mv = 0.5 * (box[2] + box[3]);
    return d3_add(rc->center, d3_add(d3_scale(rc->u, mu), d3_scale(rc->v, mv)));
}

/* Primitive of sqrt(1 - x^2) on [-1, 1] (unit disk). */
static double circ_prim(double x)
{
    x = x < -1.0 ? -1.0 : (x > 1.0 ? 1.0 : x);
    return 0.5 * (x * sqrt(d_max(0.0, 1.0 - x * x)) + asin(x));
}

static void sort_small(double *v, int n)
{
    for (int i = 1; i < n; ++i)
        for (int j = i; j > 0 && v[j] < v[j - 1]; --j) {
            double t = v[j];
            v[j] = v[j - 1];
            v[j - 1] = t;
        }
}

/* Area of the unit disk intersect [x0, x1] x [y0, y1]: the integral over x of
 * the chord clipped to [y0, y1]; between consecutive break points (where
 * the circle crosses y0 or y1) each bound is either a constant or the
 * circle, so each piece integrates in closed form. */
static double unit_disk_box_area(double x0, double x1, double y0, double y1)
{
    x0 = d_max(x0, -1.0);
    x1 = d_min(x1, 1.0);
    y0 = d_max(y0, -1.0);
    y1 = d_min(y1, 1.0);
    if (!(x1 > x0) || !(y1 > y0))
        return 0.0;
    double br[6];
    int nb = 0;
    br[nb++] = x0;
    br[nb++] = x1;
    const double ys[2] = {y0, y1};
    for (int k = 0; k < 2; ++k) {
        double w = sqrt(d_max(0.0, 1.0 - ys[k] * ys[k]));
        if (w > x0 && w < x1)
            br[nb++] = w;
        if (-w > x0 && -w < x1)
            br[nb++] = -w;
    }
    sort_small(br, nb);
    double area = 0.0;
    for (int p = 0; p + 1 < nb; ++p) {
        double a = br[p], b = br[p + 1];
        if (!(b > a))
            continue;
        double m = 0.5 * (a + b), s = sqrt(d_max(0.0, 1.0 - m * m));
        int top_c = y1 < s, bot_c = y0 > -s; /* the bound is the constant y1 / y0 */
        double top = top_c ? y1 : s, bot = bot_c ? y0 : -s;
        if (!(top > bot))
            continue;
        double circ = circ_prim(b) - circ_prim(a);
        area += (top_c ? y1 * (b - a) : circ) - (bot_c ? y0 * (b - a) : -circ);
    }
    return area;
}

double vsgl__mrp_overlap_exact(const vsgl__mrp_rect *rc, d3 y, double rd)
{
    double cu, cv;
    local(rc, y, &cu, &cv);
    if (!(rd > 0.0) || !(rd < INFINITY) || !(rc->half_u > 0.0) || !(rc->half_v > 0.0))
        return 0.0;
    double a = rc->half_u / rd, b = rc->half_v / rd, u = cu / rd, v = cv / rd;
    double s = unit_disk_box_area(-a - u, a - u, -b - v, b - v) / VSGL__PI_D;
    return s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
}
