/* The MRP glossy term end to end (csrc/src/mrp/glossy.c, docs/mrp.md §3):
 * a uniformly lit rectangle (a lit wall, radiance 1) reflected by a GGX
 * floor of roughness 0.1-0.3, against quadrature over the rectangle of the
 * library's exact BRDF (vsgl__brdf_eval: metal, F0 = 1, height-correlated
 * Smith; the same material the MRP smooth factor is evaluated with).
 * VSGL_TEST_TABLES=1 prints the tables of docs/mrp.md. */
#include "harness.h"
#include "sphere_quad.h"
#include "mrp/mrp.h"
#include "mrp/geom.h"
#include "scene/material.h"

#include <stdlib.h>

static int tables(void) { return getenv("VSGL_TEST_TABLES") != NULL; }

#define GL_N 8
static double gl_x[GL_N], gl_w[GL_N];
static void gl_init(void)
{
    sq_gauss_legendre(GL_N, gl_x, gl_w);
}

/* Panel edges on [-a, a] graded around c: c +- w 2^k, k = -4.., and the ends. */
static int graded_edges(double a, double c, double w, int refine, double *e)
{
    int n = 0;
    e[n++] = -a;
    for (int s = -1; s <= 1; s += 2)
        for (double t = w / 16.0 / refine; t < 4.0 * a; t *= 2.0 / (refine > 1 ? 1.4 : 1.0)) {
            double p = c + s * t;
            if (p > -a && p < a && n < 254)
                e[n++] = p;
        }
    if (c > -a && c < a)
        e[n++] = c;
    e[n++] = a;
    for (int i = 1; i < n; ++i) /* sort */
        for (int j = i; j > 0 && e[j] < e[j - 1]; --j) {
            double t = e[j];
            e[j] = e[j - 1];
            e[j - 1] = t;
        }
    return n;
}

typedef struct scene_case {
    vsgl__mrp_rect rc;
    vsgl_brdf_params bp;
    double alpha;
} scene_case;

/* Exact glossy radiance: integral over the rectangle of f cos_i cos_r / r^2. */
static double reference(const scene_case *sc, d3 x, d3 n, d3 o, int refine, int sg_ndf)
{
    vsgl_sg g;
    vsgl__mrp_receiver_sg(n, o, sc->alpha, &g);
    const vsgl__mrp_rect *rc = &sc->rc;
    /* the receiver's mirror point as the grading centre */
    d3 z = d3_sub(d3_scale(n, 2.0 * d3_dot(o, n)), o), y = x;
    double cu = 0.0, cv = 0.0, w = 0.05;
    if (vsgl__mrp_peak(rc, x, d3_scale(z, -1.0), &y)) {
        d3 dd = d3_sub(y, rc->center);
        cu = d3_dot(dd, rc->u);
        cv = d3_dot(dd, rc->v);
        w = fmax(1e-4, d3_length(d3_sub(y, x)) * sc->alpha);
    }
    double eu[256], ev[256];
    int nu = graded_edges(rc->half_u, cu, w, refine, eu), nv = graded_edges(rc->half_v, cv, w, refine, ev);
    v3 nf = d3_to_v3(n), of = d3_to_v3(o), tf;
    d3 t0, t1;
    d3_basis(n, &t0, &t1);
    tf = d3_to_v3(t0);
    double sum = 0.0;
    for (int a = 0; a + 1 < nu; ++a)
        for (int i = 0; i < GL_N; ++i) {
            double hu = 0.5 * (eu[a + 1] - eu[a]), pu = eu[a] + hu * (1.0 + gl_x[i]);
            for (int b = 0; b + 1 < nv; ++b)
                for (int j = 0; j < GL_N; ++j) {
                    double hv = 0.5 * (ev[b + 1] - ev[b]), pv = ev[b] + hv * (1.0 + gl_x[j]);
                    d3 p = d3_add(rc->center, d3_add(d3_scale(rc->u, pu), d3_scale(rc->v, pv)));
                    d3 wi = d3_sub(p, x);
                    double r2 = d3_dot(wi, wi), r = sqrt(r2);
                    wi = d3_scale(wi, 1.0 / r);
                    double cr = -d3_dot(wi, rc->normal);
                    if (!(cr > 0.0))
                        continue;
                    float dif[3], gl[3];
                    if (sg_ndf) { /* Eq. 9 with the exact rectangle: SG NDF x the exact smooth factor */
                        vsgl_vec3 wf = d3_to_v3(wi);
                        vsgl__specular_factor(&sc->bp, nf, of, wf, (float)sc->alpha, gl);
                        gl[0] *= vsgl_sg_eval(&g, &wf);
                    } else {
                        vsgl__brdf_eval(&sc->bp, nf, tf, d3_to_v3(wi), of, dif, gl);
                    }
                    sum += gl_w[i] * hu * gl_w[j] * hv * gl[0] * cr / r2;
                }
        }
    return sum;
}

static double mrp(const scene_case *sc, d3 x, d3 n, d3 o, const vsgl__mrp_options *opt)
{
    d3 axis[2];
    double v[2], sum = 0.0;
    int parts = vsgl__mrp_glossy_parts(&sc->rc, x, n, o, sc->alpha, opt, 0u, v, axis);
    for (int q = 0; q < parts; ++q) { /* each lobe's smooth factor at its own axis */
        if (!(v[q] > 0.0))
            continue;
        float m[3];
        vsgl__specular_factor(&sc->bp, d3_to_v3(n), d3_to_v3(o), d3_to_v3(axis[q]), (float)sc->alpha, m);
        sum += v[q] * m[0];
    }
    return sum;
}

static scene_case make_case(double roughness)
{
    scene_case sc;
    /* a wall at x = 0 facing +x, 2 m wide (y), 1.5 m tall from z = 0.25 */
    vsgl__mrp_rect_make(d3_make(0, 0, 1.0), d3_make(1, 0, 0), d3_make(0, 1, 0), 1.0, 0.75, &sc.rc);
    vsgl_material mat = {{1, 1, 1}, 1.0f, (float)roughness, 0.04f, 0.0f, 0.0f, VSGL_MATERIAL_FLAG_BLENDER_4, 0};
    vsgl__material_params(&mat, &sc.bp);
    sc.alpha = roughness * roughness;
    return sc;
}

#define NREC 48
/* Receivers on the floor z = 0 in front of the wall, a camera at (4, y, 1.6). */
static void receiver(int k, d3 *x, d3 *o)
{
    int i = k % 8, j = k / 8;
    *x = d3_make(0.25 + 0.35 * i, -1.5 + 0.6 * j, 0.0);
    *o = d3_normalize(d3_sub(d3_make(4.0, 0.3 * (j - 2.5), 1.6), *x));
}

typedef struct err_stats { double bias, rms, worst, l2; } err_stats;

/* Errors over the receivers whose reference is above 1 % of the largest:
 * bias = sum(mrp)/sum(ref) - 1, rms and worst of the relative error;
 * l2 = |mrp - ref| / |ref| over all receivers (weights bright ones). */
static err_stats measure(const double *ref, const double *got)
{
    double mx = 0.0;
    for (int k = 0; k < NREC; ++k)
        mx = fmax(mx, ref[k]);
    double sr = 0.0, sg = 0.0, s2 = 0.0, worst = 0.0, d2 = 0.0, r2 = 0.0;
    int cnt = 0;
    for (int k = 0; k < NREC; ++k) {
        d2 += (got[k] - ref[k]) * (got[k] - ref[k]);
        r2 += ref[k] * ref[k];
        if (!(ref[k] > 0.01 * mx))
            continue;
        double e = got[k] / ref[k] - 1.0;
        sr += ref[k];
        sg += got[k];
        s2 += e * e;
        worst = fmax(worst, fabs(e));
        ++cnt;
    }
    err_stats s = {sg / sr - 1.0, sqrt(s2 / (cnt ? cnt : 1)), worst, sqrt(d2 / r2)};
    return s;
}

VT_TEST(mrp_glossy_reference_quadrature_converges)
{
    gl_init();
    scene_case sc = make_case(0.1);
    for (int k = 0; k < NREC; k += 7) {
        d3 x, o, n = d3_make(0, 0, 1);
        receiver(k, &x, &o);
        double a = reference(&sc, x, n, o, 1, 0), b = reference(&sc, x, n, o, 2, 0);
        VT_CHECK(fabs(a - b) <= 1e-4 * fmax(b, 1e-3), "receiver %d: %g vs %g", k, a, b);
    }
}

VT_TEST(mrp_glossy_uniform_rectangle_against_quadrature)
{
    gl_init();
    const double rough[3] = {0.1, 0.2, 0.3};
    const double scales[6] = {0.7, 0.85, 1.0, 1.2, 1.4, 2.0};
    static double ref[3][NREC], refsg[3][NREC], got[NREC];
    for (int r = 0; r < 3; ++r) {
        scene_case sc = make_case(rough[r]);
        for (int k = 0; k < NREC; ++k) {
            d3 x, o;
            receiver(k, &x, &o);
            ref[r][k] = reference(&sc, x, d3_make(0, 0, 1), o, 1, 0);
            refsg[r][k] = reference(&sc, x, d3_make(0, 0, 1), o, 1, 1);
        }
    }
    if (tables()) {
        printf("    the SG NDF (Eq. 8) over the exact rectangle against GGX: L2, bias\n   ");
        for (int r = 0; r < 3; ++r) {
            err_stats e = measure(ref[r], refsg[r]);
            printf(" roughness %.1f: %.1f %%, %+.1f %%;", rough[r], 100 * e.l2, 100 * e.bias);
        }
        printf("\n    | variant | r_d scale | roughness 0.1: L2 vs GGX, bias vs GGX, L2 vs SG NDF | 0.2 | 0.3 |\n");
    }
    /* variants: 0 paper as printed, 1 the default, then one change each from the default */
    const char *names[] = {"paper (Eq. 36 bbox, Eq. 34, Eq. 26 cap, at y)", "default (exact A, solid angle, centred, ASG receiver)",
                           "default, Eq. 36 bbox", "default, not centred", "default, Eq. 26 cap",
                           "one lobe, SG-only (Eq. 37)", "one lobe, Eq. 8 SG receiver (not the warped ASG)",
                           "default, one lobe (no GGX tail)", "default, the light shrunk to a cell (shrink 1)"};
    double best_l2[3] = {1e9, 1e9, 1e9}, deflt_l2[3] = {0, 0, 0}, deflt_sg[3] = {0, 0, 0}, paper_l2[3] = {0, 0, 0}, deflt_bias[3] = {0, 0, 0};
    double one_l2[3] = {0, 0, 0}; /* the default with one lobe */
    const double dscale = vsgl__mrp_options_default().rd_scale;
    for (int v = 0; v < 9; ++v)
        for (int s = 0; s < 6; ++s) {
            vsgl__mrp_options opt = v == 0 ? vsgl__mrp_options_paper() : vsgl__mrp_options_default();
            if (v == 2) opt.overlap = 0;
            if (v == 3) opt.centred = 0;
            if (v == 4) opt.solid_angle = 0;
            if (v == 5) opt.sg_only = 1, opt.receiver_asg = 0, opt.lobes = 1;
            if (v == 6) opt.receiver_asg = 0, opt.lobes = 1;
            if (v == 7) opt.lobes = 1;
            if (v == 8) opt.shrink = 1.0;
            opt.rd_scale = scales[s];
            if (tables())
                printf("    | %s | %.2f |", names[v], scales[s]);
            for (int r = 0; r < 3; ++r) {
                scene_case sc = make_case(rough[r]);
                for (int k = 0; k < NREC; ++k) {
                    d3 x, o;
                    receiver(k, &x, &o);
                    got[k] = mrp(&sc, x, d3_make(0, 0, 1), o, &opt);
                    VT_CHECK(isfinite(got[k]) && got[k] >= 0.0, "variant %d receiver %d: %g", v, k, got[k]);
                }
                err_stats e = measure(ref[r], got), es = measure(refsg[r], got);
                if (v == 1)
                    best_l2[r] = fmin(best_l2[r], e.l2);
                if (v == 1 && scales[s] == dscale)
                    deflt_l2[r] = e.l2, deflt_bias[r] = e.bias;
                if (v == 6 && scales[s] == dscale) /* the same with Eq. 8's SG: against the SG-NDF quadrature */
                    deflt_sg[r] = es.l2;
                if (v == 0 && scales[s] == dscale)
                    paper_l2[r] = e.l2;
                if (v == 7 && scales[s] == dscale)
                    one_l2[r] = e.l2;
                if (tables())
                    printf(" %.1f %%, %+.1f %%, %.1f %% |", 100 * e.l2, 100 * e.bias, 100 * es.l2);
            }
            if (tables())
                printf("\n");
        }
    for (int r = 0; r < 3; ++r) {
        VT_CHECK(deflt_l2[r] <= best_l2[r] * 1.25, "roughness %g: default L2 %g, best r_d %g", rough[r], deflt_l2[r],
                 best_l2[r]);
        /* measured: 5.7 / 7.6 / 12.4 % against GGX (the SG NDF alone: 3.5 / 9.6 / 15.0 %);
         * with Eq. 8's SG receiver 0.0 / 3.2 / 8.2 % against the SG NDF over the exact rectangle */
        VT_CHECK(deflt_l2[r] < 0.2 && fabs(deflt_bias[r]) < 0.1, "roughness %g: L2 %g bias %g", rough[r],
                 deflt_l2[r], deflt_bias[r]);
        VT_CHECK(deflt_sg[r] < 0.1, "roughness %g: L2 against the SG NDF %g", rough[r], deflt_sg[r]);
        VT_CHECK(paper_l2[r] > deflt_l2[r], "roughness %g: paper %g default %g", rough[r], paper_l2[r], deflt_l2[r]);
        if (tables())
            printf("    roughness %.1f: two lobes L2 %.1f %%, one lobe %.1f %%\n", rough[r], 100 * deflt_l2[r], 100 * one_l2[r]);
        /* measured 5.7 / 7.6 / 12.4 % (two lobes) against 5.7 / 8.9 / 13.1 % (one): GGX's tail
         * matters at the wall's edges; inside, the single lobe already integrates to GGX's albedo */
        VT_CHECK(deflt_l2[r] <= one_l2[r] + 0.005, "roughness %g: two lobes L2 %g, one lobe %g", rough[r],
                 deflt_l2[r], one_l2[r]);
    }
}

/* The wall seen along its length (the quality suite's metal_floor_red_wall):
 * a camera at (1.2, -3.5, 1.5) looking along +y, floor receivers beside the
 * wall; the peak directions graze the wall (sigma 60-85 degrees). */
static void receiver_grazing(int k, d3 *x, d3 *o)
{
    int i = k % 8, j = k / 8;
    *x = d3_make(0.15 + 0.2 * i, -1.0 + 0.45 * j, 0.0);
    *o = d3_normalize(d3_sub(d3_make(1.2, -3.5, 1.5), *x));
}

VT_TEST(mrp_glossy_grazing_emitter_against_quadrature)
{
    gl_init();
    const double rough[3] = {0.1, 0.2, 0.3};
    static double ref[NREC], got[NREC], got_sg[NREC];
    vsgl__mrp_options def = vsgl__mrp_options_default(), sg = def;
    sg.receiver_asg = 0;
    double worst = 0.0;
    for (int r = 0; r < 3; ++r) {
        scene_case sc = make_case(rough[r]);
        double smax = 0.0, smin = 1.0;
        for (int k = 0; k < NREC; ++k) {
            d3 x, o, n = d3_make(0, 0, 1), y;
            receiver_grazing(k, &x, &o);
            ref[k] = reference(&sc, x, n, o, 1, 0);
            got[k] = mrp(&sc, x, n, o, &def);
            got_sg[k] = mrp(&sc, x, n, o, &sg);
            d3 z = d3_sub(d3_scale(n, 2.0 * d3_dot(o, n)), o);
            if (vsgl__mrp_peak(&sc.rc, x, d3_scale(z, -1.0), &y)) {
                double cs = d3_dot(d3_normalize(d3_sub(x, y)), sc.rc.normal);
                smax = fmax(smax, cs);
                smin = fmin(smin, cs);
            }
        }
        err_stats e = measure(ref, got), es = measure(ref, got_sg);
        worst = fmax(worst, e.l2);
        if (tables())
            printf("    grazing, roughness %.1f (cos sigma %.2f-%.2f): ASG receiver L2 %.1f %%, bias %+.1f %%; "
                   "SG receiver L2 %.1f %%, bias %+.1f %%\n", rough[r], smin, smax, 100 * e.l2, 100 * e.bias,
                   100 * es.l2, 100 * es.bias);
    }
    /* measured 18 / 26 / 28 % (ASG receiver): the disk rule and Eq. 29's
     * foreshortening are small-angle forms; docs/mrp.md §3 */
    VT_CHECK(worst < 0.4, "worst L2 at grazing %g", worst);
}
