/* The planar glossy model at a surface's end (shade.c, vsgl__planar_glossy):
 * a uniformly lit half-plane as lattice cells, seen through a glossy lobe
 * whose footprint lies at or near the edge, against quadrature of the
 * same radiance through the same ASG. With the fold the light holds up to
 * the edge; without it (the same cells marked uncut) it sags there. */
#include "harness.h"
#include "shade/shade.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CELL_H 0.25
/* the lattice's offset across the edge, in spacings (the fit anchors its
 * lattice at the scene's bounds, so a room's wall stands on a lattice line:
 * offset 0) */
static double cell_off = 0.3;

static double tent(double t)
{
    t = fabs(t);
    return t < 1.0 ? 1.0 - t : 0.0;
}

/* Cell (i, j) of a lattice on the plane z = 0 facing +z (u = x, v = y),
 * exitance 1 W/m^2 over y >= 0: its power, mean and variance by midpoint
 * quadrature of its tent over the surface, as the lattice fit sums its
 * VPLs. `mark_cut` 0 records the VPLs' extent as the whole tent (the fold
 * off). Returns 0 for a cell with no surface. */
static int make_cell(int i, int j, int mark_cut, vsgl_vsgl *v)
{
    const double cx = i * CELL_H, cy = (j + cell_off) * CELL_H, lo = fmax(cy - CELL_H, 0.0);
    if (!(cy + CELL_H > lo))
        return 0;
    const int n = 48;
    const double dx = 2.0 * CELL_H / n, dy = (cy + CELL_H - lo) / n;
    double w = 0.0, sx = 0.0, sy = 0.0, s2 = 0.0;
    for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
            double x = cx - CELL_H + (a + 0.5) * dx, y = lo + (b + 0.5) * dy;
            double t = tent((x - cx) / CELL_H) * tent((y - cy) / CELL_H) * dx * dy;
            w += t;
            sx += t * x;
            sy += t * y;
            s2 += t * (x * x + y * y);
        }
    if (!(w > 0.0))
        return 0;
    memset(v, 0, sizeof *v);
    double mx = sx / w, my = sy / w;
    v->mean = v3_make((float)mx, (float)my, 0.0f);
    v->variance = (float)(0.5 * (s2 / w - mx * mx - my * my));
    v->widen = (float)(CELL_H * CELL_H * VSGL__LATTICE_OVERLAP); /* the lattice's overlap (fit/vsgl_set.h) */
    v->normal = v3_make(0.0f, 0.0f, 1.0f);
    v->coherence = 1.0f;
    v->power[0] = v->power[1] = v->power[2] = (float)w;
    v->lobe = VSGL__LOBE_DIFFUSE;
    v->cell_h = (float)CELL_H;
    v->cell_axis = 2;
    v->cell_centre[0] = (float)cx;
    v->cell_centre[1] = (float)cy;
    v->cell_lo[0] = (float)(cx - CELL_H);
    v->cell_hi[0] = (float)(cx + CELL_H);
    v->cell_lo[1] = (float)(mark_cut ? lo : cy - CELL_H);
    v->cell_ends = mark_cut ? 1u << 2 : 0u; /* the plane ends at the cut, low side of v */
    v->cell_hi[1] = (float)(cy + CELL_H);
    return 1;
}

/* The model: the cells' glossy light per unit exitance at x through lobe. */
static double model(v3 x, const vsgl_asg *lobe, int mark_cut)
{
    double sum = 0.0;
    for (int i = -16; i <= 16; ++i)
        for (int j = -2; j <= 16; ++j) {
            vsgl_vsgl v;
            if (make_cell(i, j, mark_cut, &v))
                sum += v.power[0] * vsgl__planar_glossy(&v, x, v3_make(lobe->z.x, lobe->z.y, lobe->z.z), lobe);
        }
    return sum;
}

/* The truth: radiance 1/pi over y >= 0 through the ASG, by midpoint
 * quadrature over the plane within `reach` of y0 (step `step` m); with a
 * receiver normal nr (else NULL), only from above its tangent plane. */
static double quadrature(v3 x, const v3 *nr, const vsgl_asg *lobe, v3 y0, double reach, double step)
{
    double sum = 0.0;
    const int n = (int)(2.0 * reach / step);
    for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
            double px = y0.x - reach + (a + 0.5) * step, py = y0.y - reach + (b + 0.5) * step;
            if (py < 0.0)
                continue;
            double d[3] = {px - x.x, py - x.y, -x.z};
            if (nr && !(d[0] * nr->x + d[1] * nr->y + d[2] * nr->z > 0.0))
                continue;
            double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], r = sqrt(r2);
            vsgl_vec3 dir = {(float)(d[0] / r), (float)(d[1] / r), (float)(d[2] / r)};
            sum += vsgl_asg_eval(lobe, &dir) * (x.z / r) / r2 * step * step;
        }
    return sum / 3.14159265358979323846;
}

VT_TEST(planar_glossy_fold_holds_a_half_plane_up_to_its_edge)
{
    /* lobes looking back at the edge from beyond it, as a floor beside a
     * wall sees the wall's foot: isotropic and anisotropic */
    const float bands[2][2] = {{150.0f, 150.0f}, {400.0f, 60.0f}};
    const float edge[6] = {0.005f, 0.03f, 0.08f, 0.15f, 0.3f, 0.8f};
    double worst_fold = 0.0, worst_edge_nofold = 0.0, worst_inside_nofold = 0.0;
    /* the receiver 0.6 m back (a wide footprint) and 5 cm back (a floor
     * beside a wall, reading the wall's foot sharply); the edge between
     * lattice lines and on one */
    const double dist[2] = {0.6, 0.05}, offs[2] = {0.3, 0.0};
    for (int c = 0; c < 4; ++c)
    for (int l = 0; l < 2; ++l)
        for (int k = 0; k < 6; ++k) {
            cell_off = offs[c & 1];
            const double back = dist[c >> 1];
            vsgl_asg lobe;
            memset(&lobe, 0, sizeof lobe);
            v3 z = v3_normalize(v3_make(0.15f, 0.45f, -1.0f));
            v3 xa = v3_normalize(v3_cross(z, v3_make(0.0f, 0.0f, 1.0f))), ya = v3_cross(z, xa);
            lobe.x = (vsgl_vec3){xa.x, xa.y, xa.z};
            lobe.y = (vsgl_vec3){ya.x, ya.y, ya.z};
            lobe.z = (vsgl_vec3){z.x, z.y, z.z};
            lobe.lambda = bands[l][0];
            lobe.mu = bands[l][1];
            lobe.log_amplitude = 0.0f;
            v3 y0 = v3_make(0.1f, edge[k], 0.0f);
            v3 x = v3_sub(y0, v3_scale(z, (float)back)); /* back along the lobe's axis, above the plane */
            double step = (getenv("VSGL_TEST_QUICK") ? 0.004 : 0.002) * back / 0.6;
            double want = quadrature(x, NULL, &lobe, y0, back, step);
            double got = model(x, &lobe, 1), spill = model(x, &lobe, 0);
            double e = fabs(got / want - 1.0), e0 = fabs(spill / want - 1.0);
            if (getenv("VSGL_TEST_VERBOSE"))
                printf("    %.2f m back, lattice offset %.1f, bands %g/%g, footprint %.3f m inside the edge: "
                       "quadrature %.5f, fold %.5f (%+.1f %%), no fold %.5f (%+.1f %%)\n",
                       back, cell_off, bands[l][0], bands[l][1], edge[k], want, got, 100.0 * (got / want - 1.0), spill,
                       100.0 * (spill / want - 1.0));
            VT_CHECK(isfinite(got) && got > 0.0, "bands %g/%g at %g: %g", bands[l][0], bands[l][1], edge[k], got);
            worst_fold = e > worst_fold ? e : worst_fold;
            if (edge[k] < 0.1f)
                worst_edge_nofold = e0 > worst_edge_nofold ? e0 : worst_edge_nofold;
            if (edge[k] > 0.5f)
                worst_inside_nofold = e0 > worst_inside_nofold ? e0 : worst_inside_nofold;
        }
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    worst: fold %.3f; no fold %.3f at the edge, %.3f inside\n", worst_fold, worst_edge_nofold,
               worst_inside_nofold);
    /* measured 0.105 (+10.5 %: 0.6 m back, the edge between lattice lines,
     * the footprint 5 mm inside it; 0.092 with the lattice's overlap
     * h^2 / 6 before 2026-12-04, h^2 / 8 now: fit/vsgl_set.h); 5 cm back
     * with the edge on a lattice line, as a floor beside a room's wall,
     * -4.8 % at 5 mm (-8.0 % with h^2 / 6). Folding the cut cell's
     * Gaussian about its VPLs' mean instead of its tent's centre (shade.c,
     * fold_mean) gave -21.5 % there. Without the fold 0.504 (-50 %). */
    VT_CHECK(worst_fold < 0.11, "the fold's worst relative error %.3f", worst_fold);
    /* the test can fail: without the fold the edge sags, deep inside both agree */
    VT_CHECK(worst_edge_nofold > 0.2, "without the fold the edge is off by %.3f only", worst_edge_nofold);
    VT_CHECK(worst_inside_nofold < 0.06, "inside, without the fold: %.3f", worst_inside_nofold);
}

/* An ASG of axis z (unit), its x axis across z and ref, amplitude 1. */
static vsgl_asg lobe_about(v3 z, v3 ref, float lambda, float mu)
{
    v3 xa = v3_normalize(v3_cross(z, ref)), ya = v3_cross(z, xa);
    vsgl_asg lobe;
    memset(&lobe, 0, sizeof lobe);
    lobe.x = (vsgl_vec3){xa.x, xa.y, xa.z};
    lobe.y = (vsgl_vec3){ya.x, ya.y, ya.z};
    lobe.z = (vsgl_vec3){z.x, z.y, z.z};
    lobe.lambda = lambda;
    lobe.mu = mu;
    return lobe;
}

VT_TEST(planar_glossy_grazing_lobe_sees_nothing_below_the_horizon)
{
    /* a receiver 0.4 m above a lit plane, its normal tilted away from most
     * of it (a sphere's rim above a lit floor), its lobe grazing its
     * tangent plane (n.z = 0.05): the lobe's footprint on the plane lies
     * across the horizon line (y = 2.2), and only the far side may light it */
    const v3 x = v3_make(0.0f, 2.0f, 0.4f), nr = v3_normalize(v3_make(0.0f, 1.0f, 0.5f));
    const v3 t = v3_normalize(v3_make(0.0f, 0.5f, -1.0f)); /* in the tangent plane, towards the plane */
    const float bands[3][2] = {{20.0f, 20.0f}, {8.0f, 40.0f}, {60.0f, 60.0f}};
    double worst = 0.0, best_nocut = 1e30;
    for (int l = 0; l < 3; ++l) {
        v3 z = v3_normalize(v3_add(t, v3_scale(nr, 0.05f)));
        vsgl_asg lobe = lobe_about(z, v3_make(1.0f, 0.0f, 0.0f), bands[l][0], bands[l][1]);
        double want = quadrature(x, &nr, &lobe, x, 2.5, getenv("VSGL_TEST_QUICK") ? 0.01 : 0.005);
        double got = 0.0, nocut = 0.0;
        for (int i = -16; i <= 16; ++i)
            for (int j = -2; j <= 16; ++j) {
                vsgl_vsgl v;
                if (!make_cell(i, j, 1, &v))
                    continue;
                got += v.power[0] * vsgl__planar_glossy(&v, x, nr, &lobe);
                nocut += v.power[0] * vsgl__planar_glossy(&v, x, v3_make(z.x, z.y, z.z), &lobe); /* n = z: no cut */
            }
        double e = fabs(got / want - 1.0), e0 = fabs(nocut / want - 1.0);
        if (getenv("VSGL_TEST_VERBOSE"))
            printf("    bands %g/%g: quadrature %.5f, model %.5f (%+.1f %%), without the horizon %.5f (%+.1f %%)\n",
                   bands[l][0], bands[l][1], want, got, 100.0 * (got / want - 1.0), nocut,
                   100.0 * (nocut / want - 1.0));
        VT_CHECK(isfinite(got) && got > 0.0, "bands %g/%g: %g", bands[l][0], bands[l][1], got);
        worst = e > worst ? e : worst;
        best_nocut = e0 < best_nocut ? e0 : best_nocut;
    }
    /* measured: within 0.5 % with the horizon; +42 % to +73 % without it */
    VT_CHECK(worst < 0.05, "with the horizon, worst relative error %.3f", worst);
    VT_CHECK(best_nocut > 0.3, "without the horizon, the best relative error %.3f (the test would not fail)", best_nocut);
}

VT_TEST(planar_glossy_is_continuous_as_the_axis_leaves_the_plane)
{
    /* a receiver 0.5 mm in front of a lit cluster's plane and 1.5 sigma
     * from its mean (on a sphere's rim, a neighbouring cluster's plane
     * passes that close), its lobe's axis turning from along the plane
     * (n_v.z = -0.002) to 4.6 degrees into it: the axis then meets the
     * plane inside the cluster. The light must come in smoothly; a hard
     * bound on n_v.z switched it from 0 to most of its peak in one step
     * (a pixel of the sphere room's camera animation 0.002 -> 0.062 ->
     * 0.002). */
    vsgl_vsgl v;
    memset(&v, 0, sizeof v);
    v.mean = v3_make(0.0f, 0.0f, 0.0f);
    v.normal = v3_make(0.0f, 0.0f, 1.0f);
    v.variance = 0.01f;
    v.coherence = 1.0f;
    v.power[0] = v.power[1] = v.power[2] = 1.0f;
    v.lobe = VSGL__LOBE_DIFFUSE;
    const v3 x = v3_make(0.15f, 0.0f, 0.0005f), nr = v3_normalize(v3_make(-1.0f, 0.0f, 0.3f));
    double prev = -1.0, peak = 0.0, worst = 0.0;
    int steps = 0;
    for (double c = -0.002; c >= -0.08; c -= 0.0005, ++steps) {
        vsgl_asg lobe = lobe_about(v3_normalize(v3_make(-1.0f, 0.0f, (float)c)), v3_make(0.0f, 1.0f, 0.0f), 50.0f, 50.0f);
        double g = vsgl__planar_glossy(&v, x, nr, &lobe);
        VT_CHECK(isfinite(g) && g >= 0.0, "n_v.z %.4f: %g", c, g);
        peak = g > peak ? g : peak;
        if (prev >= 0.0) {
            double jump = fabs(g - prev);
            worst = jump > worst ? jump : worst;
        }
        prev = g;
    }
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    peak %.4g, largest change per step %.4f of it\n", peak, worst / peak);
    VT_CHECK(peak > 0.0, "the cluster lights the receiver somewhere on the sweep");
    /* measured: at most 3.7 % of the peak per step (2.0 % before the
     * footprint's reach fades with the cluster's size, kernel.h
     * vsgl__planar_reach); with a hard bound at 0.01, 45 % */
    VT_CHECK(worst < 0.05 * peak, "over %d steps of 0.0005, the largest change is %.3f of the peak", steps, worst / peak);
}

/* Exitance of the lattice of make_cell (its tents' sum, one row or column
 * beyond the last cell's centre falling to 0) at (px, py), per unit. */
static double lattice_exitance(double px, double py)
{
    if (py < 0.0)
        return 0.0;
    const double xe = 16 * CELL_H, ye = (16 + cell_off) * CELL_H;
    double fx = fabs(px) <= xe ? 1.0 : fmax(0.0, 1.0 - (fabs(px) - xe) / CELL_H);
    double fy = py <= ye ? 1.0 : fmax(0.0, 1.0 - (py - ye) / CELL_H);
    return fx * fy;
}

VT_TEST(planar_glossy_follows_a_lobe_across_the_plane_horizon)
{
    /* a receiver 0.4 m above a lit plane (4 m of it ahead), its lobe's
     * axis turning from 0.2 rad below the plane's horizon to 0.15 above it
     * (a glossy sphere's reflection of a floor, from its lower part up
     * past the floor's far end): the part of the lobe that meets the plane
     * shrinks smoothly, and so must the light. Quadrature of the same
     * radiance through the same ASG over the plane is the truth. */
    const v3 x = v3_make(0.0f, 0.0f, 0.4f);
    const double step = getenv("VSGL_TEST_QUICK") ? 0.02 : 0.01;
    const float bands[2][2] = {{50.0f, 50.0f}, {12.0f, 40.0f}};
    double worst = 0.0, worst_horizon = 0.0;
    for (int l = 0; l < 2; ++l) {
        double peak = 0.0, err = 0.0, prev = 1e30;
        for (int k = 0; k <= 7; ++k) {
            const double el = 0.2 - 0.05 * k;
            v3 z = v3_make(0.0f, (float)cos(el), (float)-sin(el));
            vsgl_asg lobe = lobe_about(z, v3_make(0.0f, 0.0f, 1.0f), bands[l][0], bands[l][1]);
            double want = 0.0;
            for (double py = 0.5 * step; py < 4.5; py += step)
                for (double px = -4.5 + 0.5 * step; px < 4.5; px += step) {
                    double e = lattice_exitance(px, py);
                    if (!(e > 0.0))
                        continue;
                    double d[3] = {px - x.x, py - x.y, -x.z}, r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2],
                           r = sqrt(r2);
                    vsgl_vec3 dir = {(float)(d[0] / r), (float)(d[1] / r), (float)(d[2] / r)};
                    want += e * vsgl_asg_eval(&lobe, &dir) * (x.z / r) / r2 * step * step;
                }
            want /= 3.14159265358979323846;
            double got = 0.0;
            for (int i = -16; i <= 16; ++i)
                for (int j = -2; j <= 16; ++j) {
                    vsgl_vsgl v;
                    if (make_cell(i, j, 1, &v))
                        got += v.power[0] * vsgl__planar_glossy(&v, x, v3_make(z.x, z.y, z.z), &lobe);
                }
            VT_CHECK(isfinite(got) && got >= 0.0, "elevation %.2f: %g", el, got);
            if (getenv("VSGL_TEST_VERBOSE"))
                printf("    bands %g/%g, axis %+.2f rad into the plane: quadrature %.5f, model %.5f (%+.0f %%)\n",
                       bands[l][0], bands[l][1], el, want, got, 100.0 * (got / want - 1.0));
            peak = want > peak ? want : peak;
            err = fmax(err, fabs(got - want));
            /* the light falls as the axis leaves the plane, and is there with the axis on the horizon */
            VT_CHECK(got < prev, "bands %g/%g: at %.2f rad the model does not fall (%g after %g)", bands[l][0],
                     bands[l][1], el, got, prev);
            prev = got;
            if (fabs(el) < 1e-9)
                worst_horizon = fmax(worst_horizon, fabs(got / want - 1.0));
        }
        worst = fmax(worst, err / peak);
    }
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    largest error %.3f of the peak; on the horizon %.3f\n", worst, worst_horizon);
    /* measured: 0.056 of the peak, on the horizon +28 %; before the
     * footprint's reach (kernel.h, vsgl__planar_reach) 0.120 (+12 % where
     * the axis meets the plane 2 m off) and -34 %; with the axis followed
     * to the plane alone (before 2026-12-05) 0.316 of the peak and nothing
     * from the horizon up */
    VT_CHECK(worst < 0.15, "the largest error is %.3f of the peak", worst);
    VT_CHECK(worst_horizon < 0.5, "with the axis on the horizon, off by %.3f", worst_horizon);
}

/* Exitance of a patch of whole tents, cells (i, j) for i in [i0, i1], j in
 * [j0, j1] at spacing CELL_H on z = 0: 1 inside, falling to 0 over the
 * cell beyond the last centre on each side. */
static double patch_exitance(double px, double py, int i0, int i1, int j0, int j1)
{
    double fx = 0.0, fy = 0.0;
    for (int i = i0; i <= i1; ++i)
        fx += tent(px / CELL_H - i);
    for (int j = j0; j <= j1; ++j)
        fy += tent(py / CELL_H - j);
    return fx * fy;
}

VT_TEST(planar_glossy_lobe_does_not_reach_back_past_its_receiver)
{
    /* A glossy sphere's lower half above a lit floor (the sphere room of
     * tests/quality): the receiver 0.6 m up, its lobe aimed away from the
     * lit patch at its foot and down at 0.1-0.6 rad, so that the axis meets
     * the floor 1-6 m off. The lattice's cells under it lie far out in the
     * linear footprint's tail, which reaches back past the receiver to
     * directions the lobe does not point at. Quadrature of the same
     * radiance (the cells' tents, whole) through the same ASG is the truth. */
    const v3 x = v3_make(0.0f, 0.0f, 0.6f);
    const int i0 = -3, i1 = 3, j0 = -2, j1 = 6; /* the patch: x in [-1, 1], y in [-0.75, 1.75] m */
    const double step = getenv("VSGL_TEST_QUICK") ? 0.01 : 0.005;
    /* round and moderately stretched lobes, then a brushed metal's (one
     * sharpness 30-50x the other, either way round) */
    const float bands[6][2] = {{50.0f, 50.0f}, {12.0f, 40.0f}, {2.0f, 60.0f}, {60.0f, 2.0f}, {4.0f, 200.0f}, {200.0f, 4.0f}};
    double worst = 0.0, worst_brushed = 0.0;
    for (int l = 0; l < 6; ++l) {
        for (int k = 0; k < 6; ++k) {
            const double el = 0.1 + 0.1 * k;
            v3 z = v3_make(0.0f, (float)-cos(el), (float)-sin(el));
            vsgl_asg lobe = lobe_about(z, v3_make(0.0f, 0.0f, 1.0f), bands[l][0], bands[l][1]);
            double want = 0.0;
            for (double py = (j0 - 1) * CELL_H + 0.5 * step; py < (j1 + 1) * CELL_H; py += step)
                for (double px = (i0 - 1) * CELL_H + 0.5 * step; px < (i1 + 1) * CELL_H; px += step) {
                    double d[3] = {px - x.x, py - x.y, -x.z}, r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2],
                           r = sqrt(r2);
                    vsgl_vec3 dir = {(float)(d[0] / r), (float)(d[1] / r), (float)(d[2] / r)};
                    want += patch_exitance(px, py, i0, i1, j0, j1) * vsgl_asg_eval(&lobe, &dir) * (x.z / r) / r2 *
                            step * step;
                }
            want /= 3.14159265358979323846;
            double got = 0.0;
            for (int i = i0; i <= i1; ++i)
                for (int j = j0; j <= j1; ++j) {
                    vsgl_vsgl v;
                    memset(&v, 0, sizeof v);
                    v.mean = v3_make((float)(i * CELL_H), (float)(j * CELL_H), 0.0f);
                    v.variance = (float)(CELL_H * CELL_H / 6.0); /* a tent's, per axis */
                    v.normal = v3_make(0.0f, 0.0f, 1.0f);
                    v.coherence = 1.0f;
                    v.power[0] = v.power[1] = v.power[2] = (float)(CELL_H * CELL_H);
                    v.lobe = VSGL__LOBE_DIFFUSE;
                    got += v.power[0] * vsgl__planar_glossy(&v, x, v3_make(z.x, z.y, z.z), &lobe);
                }
            VT_CHECK(isfinite(got) && got >= 0.0, "elevation %.2f: %g", el, got);
            /* against the lobe's whole integral over a uniformly lit plane (pi / sqrt(lam mu) / pi): the
             * error an artist sees next to the rest of the reflection */
            const double full = 1.0 / sqrt((double)bands[l][0] * bands[l][1]);
            if (getenv("VSGL_TEST_VERBOSE"))
                printf("    bands %g/%g, axis %.1f rad down: quadrature %.6f, model %.6f (%.3f of a lit plane's)\n",
                       bands[l][0], bands[l][1], el, want, got, (got - want) / full);
            if (l < 2)
                worst = fmax(worst, fabs(got - want) / full);
            else
                worst_brushed = fmax(worst_brushed, fabs(got - want) / full);
        }
    }
    if (getenv("VSGL_TEST_VERBOSE"))
        printf("    largest error %.4f of a lit plane's light (brushed %.4f)\n", worst, worst_brushed);
    /* measured: 0.0052; with the footprint linear about the axis's hit
     * (before vsgl__planar_reach) 0.073, up to 18x the truth */
    VT_CHECK(worst < 0.02, "the largest error is %.4f of a lit plane's light", worst);
    /* measured: 0.057 (the lobe's wide side along the plane overshoots
     * both ways); before vsgl__planar_reach 0.123 */
    VT_CHECK(worst_brushed < 0.08, "brushed lobes: the largest error is %.4f of a lit plane's light", worst_brushed);
}

VT_TEST(planar_glossy_broad_lobe_sees_nothing_behind_its_receiver)
{
    /* A rough metal sphere's side turned away from a lit floor (the sphere
     * room with a roughness-0.7 metal sphere, docs/accuracy.md): a receiver
     * 0.5 m above the floor, in front of the lit half-plane y >= 0, its
     * normal turned away from it (and a little up), its broad lobe aimed
     * 70 degrees off the normal, down at the floor: not grazing its
     * tangent plane (n.z 0.32 > VSGL__HORIZON_HI), yet the lobe reaches the
     * lit half-plane, all of which lies behind that plane. Truth:
     * quadrature of the same radiance through the same ASG from above the
     * tangent plane only, 0 here; the model must stay a small part of what
     * the lobe gathers from the whole plane. */
    const v3 x = v3_make(0.0f, -0.3f, 0.5f), nr = v3_normalize(v3_make(0.0f, -1.0f, 0.2f));
    const v3 z = v3_normalize(v3_make(0.0f, -0.5f, -0.866f));
    const double step = getenv("VSGL_TEST_QUICK") ? 0.02 : 0.01;
    const float bands[4][2] = {{2.0f, 2.0f}, {2.0f, 6.0f}, {6.0f, 2.0f}, {6.0f, 6.0f}};
    double worst = 0.0, seen = 1e30;
    for (int l = 0; l < 4; ++l) {
        vsgl_asg lobe = lobe_about(z, v3_make(1.0f, 0.0f, 0.0f), bands[l][0], bands[l][1]);
        const v3 centre = v3_make(0.0f, 1.0f, 0.0f);
        double want = quadrature(x, &nr, &lobe, centre, 3.5, step);
        double all = quadrature(x, NULL, &lobe, centre, 3.5, step);
        double got = 0.0;
        for (int i = -16; i <= 16; ++i)
            for (int j = -2; j <= 16; ++j) {
                vsgl_vsgl v;
                if (make_cell(i, j, 1, &v))
                    got += v.power[0] * vsgl__planar_glossy(&v, x, nr, &lobe);
            }
        if (getenv("VSGL_TEST_VERBOSE"))
            printf("    bands %g/%g: from above the tangent plane %.5f, from the whole plane %.5f, model %.5f "
                   "(%.3f of the whole)\n", bands[l][0], bands[l][1], want, all, got, got / all);
        VT_CHECK(isfinite(got) && got >= 0.0, "bands %g/%g: %g", bands[l][0], bands[l][1], got);
        worst = fmax(worst, fabs(got - want) / all);
        seen = fmin(seen, all);
    }
    VT_CHECK(worst < 0.15, "the model gathers %.3f of the whole plane's light from behind the receiver", worst);
    VT_CHECK(seen > 1e-4, "the lobe gathers only %g from the plane (the test would not fail)", seen);
}
