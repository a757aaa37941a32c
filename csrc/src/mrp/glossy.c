/* Eq. 10 for one Lambertian rectangle of uniform radiance seen by a GGX
 * receiver: the MRP pipeline (peak, disk, overlap, ASG light, convolution
 * with the warped NDF) put together. docs/mrp.md measures it against
 * quadrature of the exact BRDF over the rectangle (tests/c/test_mrp_glossy.c). */
#include "mrp/mrp.h"
#include "mrp/geom.h"
#include "math/asg_internal.h"
#include "math/eigen3.h"
#include "math/constants.h"
#include "vsgl/lobes.h"
#include "shade/kernel.h"

#include <string.h>

/* The receiver's lobe count, the disk rule's scale and the light's shrink
 * of the default options (docs/mrp.md §4 compares the variants:
 * tools/mrp_quality.sh builds the library with -DVSGL__MRP_LOBES=1 /
 * -DVSGL__MRP_SHRINK=1 to measure them; r_d x 1.04 / 1.08 moved the quality
 * scenes' glossy bias by +0.4-1.5 % and their relMSE by -5 % to +14 %). */
#ifndef VSGL__MRP_LOBES
#define VSGL__MRP_LOBES 2
#endif
#ifndef VSGL__MRP_RD_SCALE
#define VSGL__MRP_RD_SCALE 1.0
#endif
#ifndef VSGL__MRP_SHRINK
#define VSGL__MRP_SHRINK 0.0
#endif

vsgl__mrp_options vsgl__mrp_options_default(void)
{
    vsgl__mrp_options o = {VSGL__MRP_NORM_EXACT, 1, 1, 0, 1, VSGL__MRP_RD_SCALE, 1, VSGL__MRP_LOBES, VSGL__MRP_SHRINK};
    return o;
}

vsgl__mrp_options vsgl__mrp_options_paper(void)
{
    vsgl__mrp_options o = {VSGL__MRP_NORM_PAPER, 0, 0, 0, 0, 1.0, 0, 1, 0};
    return o;
}

/* The sampling disk's radius (the paper leaves r_d to the user). For a disk
 * inside the rectangle, small against its distance d, Eq. 32 gives
 * bandwidths lambda ~ E / l^2 and mu ~ E / (l cs)^2 (E = 2.996,
 * l = r_d / d), its solid angle is ~ pi l^2 cs, so the energy-keeping ASG
 * convolved with the receiver's SG (Eq. 11, nu = its sharpness / 2) is
 * E pi / sqrt((lambda + nu)(mu + nu)) per unit radiance at the axis, where
 * the exact value for a uniform plane is pi / nu. They agree when
 * lambda = a nu with (a + 1)(a / cs^2 + 1) = E^2:
 *   a = (sqrt((1 + cs^2)^2 + 4 (E^2 - 1) cs^2) - (1 + cs^2)) / 2,
 * i.e. r_d = d sqrt(E / (a nu)) (a = 1.996 head-on: r_d = 1.23 d / sqrt(nu)).
 * @p scale multiplies it (1 = the rule; docs/mrp.md measures 0.7-1.4). */
static double disk_radius(double d, double cs, double nu, double scale)
{
    const double E = 2.996;
    double c2 = cs * cs, b = 1.0 + c2;
    double a = 0.5 * (sqrt(b * b + 4.0 * (E * E - 1.0) * c2) - b);
    a = a > 1e-12 ? a : 1e-12;
    nu = nu > 1e-30 ? nu : 1e-30;
    double r = scale * d * sqrt(E / (a * nu));
    return r < 1e30 ? r : 1e30;
}

double vsgl__mrp_lobe_disk_radius(const vsgl__mrp_receiver *rcv, int q, const vsgl__mrp_options *opt, double d,
                                  double cs)
{
    double nu = opt->receiver_asg ? sqrt((double)rcv->asg[q].lambda * rcv->asg[q].mu) : 0.5 * rcv->sg[q].sharpness;
    return disk_radius(d, cs, nu, opt->rd_scale);
}

/* y clamped onto the rectangle (in its plane). */
static d3 clamp_to_rect(const vsgl__mrp_rect *rc, d3 y)
{
    d3 d = d3_sub(y, rc->center);
    double cu = d3_dot(d, rc->u), cv = d3_dot(d, rc->v);
    cu = cu < -rc->half_u ? -rc->half_u : (cu > rc->half_u ? rc->half_u : cu);
    cv = cv < -rc->half_v ? -rc->half_v : (cv > rc->half_v ? rc->half_v : cv);
    return d3_add(rc->center, d3_add(d3_scale(rc->u, cu), d3_scale(rc->v, cv)));
}

/* vsgl_asg_product of the ASGs (frame rows x, y, z; bandwidths; log
 * amplitudes) a and b, integrated (vsgl_asg_integral with the faster unit
 * integral): Xu et al.'s Eq. 13, in double from the frames the callers
 * already hold (not through float ASGs and their frames again), and only the
 * smallest eigenpair of the summed quadratic form (the integral needs no
 * other axis). -1 where the closed-form eigenvalues are not well separated
 * (vsgl__eigen_sym3_smallest): the caller takes the library's product. */
static double product_integral(const double (*fa)[3], double la, double ma, double aa, const double (*fb)[3],
                               double lb, double mb, double ab)
{
    const double cap = (double)VSGL_SHARPNESS_MAX;
    la = la > 0.0 ? (la < cap ? la : cap) : 0.0, ma = ma > 0.0 ? (ma < cap ? ma : cap) : 0.0;
    lb = lb > 0.0 ? (lb < cap ? lb : cap) : 0.0, mb = mb > 0.0 ? (mb < cap ? mb : cap) : 0.0;
    double m[3][3], w[3], z[3];
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j)
            m[i][j] = m[j][i] = la * fa[0][i] * fa[0][j] + ma * fa[1][i] * fa[1][j] + lb * fb[0][i] * fb[0][j] +
                                mb * fb[1][i] * fb[1][j];
    if (vsgl__eigen_sym3_smallest(m, w, z) != 0)
        return -1.0;
    /* z's sign: the hemisphere of z_a + z_b; the smooth terms at z */
    double zs = 0.0, ca = 0.0, cb = 0.0;
    for (int r = 0; r < 3; ++r) {
        zs += z[r] * (fa[2][r] + fb[2][r]);
        ca += z[r] * fa[2][r];
        cb += z[r] * fb[2][r];
    }
    if (zs < 0.0)
        ca = -ca, cb = -cb;
    if (!(ca > 0.0) || !(cb > 0.0) || !(ca * cb > 0.0))
        return 0.0;
    double lam = w[0] - w[2], mu = w[1] - w[2];
    lam = lam < cap ? (lam > 0.0 ? lam : 0.0) : cap;
    mu = mu < cap ? (mu > 0.0 ? mu : 0.0) : cap;
    return exp(aa + ab - w[2]) * ca * cb * vsgl__mrp_asg_integral_unit(lam, mu);
}

/* One Gaussian receiver lobe (g: Eq. 8's SG, ra: the warped ASG; the
 * active one per opt->receiver_asg; rf: ra's frame in double, or NULL)
 * against the rectangle: steps 2-6 of docs/mrp.md §3. h > 0 is x's height
 * over the plane. */
static double glossy_lobe(const vsgl__mrp_rect *rc, d3 x, double h, const vsgl_sg *g, const vsgl_asg *ra,
                          const double (*rf)[3], const vsgl__mrp_options *opt, d3 *axis)
{
    d3 z = d3_of_v3(g->axis), y;
    if (g->log_amplitude == -INFINITY || !vsgl__mrp_peak(rc, x, d3_scale(z, -1.0), &y))
        return 0.0;                                        /* Eq. 12 */
    y = clamp_to_rect(rc, y);
    d3 xy = d3_sub(y, x);
    double d = d3_length(xy);
    if (!(d > 0.0) || !(d < INFINITY))
        return 0.0;
    double cs = h / d;                                     /* cos(sigma) = n_r . yx */
    /* the rule below takes the receiver's (geometric-mean) bandwidth */
    double nu = opt->receiver_asg ? sqrt((double)ra->lambda * ra->mu) : 0.5 * g->sharpness;
    double rd = disk_radius(d, cs, nu, opt->rd_scale);
    double A = opt->overlap ? vsgl__mrp_overlap_exact(rc, y, rd) : vsgl__mrp_overlap_bbox(rc, y, rd);
    if (!(A > 0.0))
        return 0.0;
    double l = rd / d, omega;
    if (opt->solid_angle) /* the equal-area cap of the projected disk (semi-axes l, l cos sigma) */
        omega = 2.0 * VSGL__PI_D * (1.0 - 1.0 / sqrt(1.0 + l * l * cs));
    else                  /* Eq. 26 with k = 0 (uniform radiance) */
        omega = vsgl__mrp_disk_integral(0.0, vsgl__mrp_cap_t(l, cs));
    double C = A * omega;                                  /* Eq. 14/27, per unit L */
    d3 p = opt->centred ? vsgl__mrp_overlap_center(rc, y, rd) : y;
    *axis = d3_normalize(d3_sub(p, x));
    vsgl_asg light;
    /* the light's extent: the disk, or the disk of the overlap's area (a cell smaller than the disk) */
    double rl = opt->shrink > 0.0 && A < 1.0 ? fmin(rd, opt->shrink * rd * sqrt(A)) : rd;
    double v = -1.0;
    if (rf && opt->receiver_asg && !opt->sg_only) {        /* Eq. 28-35, ASG x ASG in double */
        double lf[3][3], ll, lm, laa;
        if (!vsgl__mrp_asg_light_d(x, p, rc->normal, rl, C, opt->norm, lf, &ll, &lm, &laa))
            return 0.0;
        v = product_integral((const double(*)[3])lf, ll, lm, laa, rf, (double)ra->lambda, (double)ra->mu, (double)ra->log_amplitude);
        if (v >= 0.0)
            return v > 0.0 && v < INFINITY ? v : 0.0;
    }
    if (!vsgl__mrp_asg_light(x, p, rc->normal, rl, C, opt->norm, &light))
        return 0.0;                                        /* Eq. 28-35 */
    if (opt->sg_only) {                                    /* Eq. 37 */
        vsgl_sg ls;
        vsgl__mrp_asg_to_sg(&light, 1, &ls);
        v = vsgl__mrp_convolve_sg(&ls, g);
    } else if (opt->receiver_asg) {                        /* ASG x ASG (Xu Eq. 13), integrated */
        vsgl_asg prod;
        vsgl_asg_product(&light, ra, &prod);
        /* vsgl_asg_integral, its float included (the product's frame is orthonormal, or its
         * amplitude 0), with the faster unit integral */
        v = prod.log_amplitude == -INFINITY
                ? 0.0
                : (float)(exp((double)prod.log_amplitude) *
                          vsgl__mrp_asg_integral_unit(vsgl__asg_clamp_bw(prod.lambda), vsgl__asg_clamp_bw(prod.mu)));
    } else {
        v = vsgl__mrp_convolve(&light, g);                 /* Eq. 11 */
    }
    return v > 0.0 && v < INFINITY ? v : 0.0;
}

void vsgl__mrp_receiver_make(d3 n, d3 o, double alpha, const vsgl__mrp_options *opt, vsgl__mrp_receiver *out)
{
    memset(out, 0, sizeof *out);
    out->n = n;
    out->parts = opt->lobes == 2 ? 2 : 1;
    vsgl_sg g;
    vsgl__mrp_receiver_sg(n, o, alpha, &g);                /* Eq. 8 */
    { /* the library's warped ASG (stretched at grazing views) */
        vsgl_vec3 nf = d3_to_v3(n), of = d3_to_v3(o), t;
        d3 t0, t1;
        d3_basis(n, &t0, &t1);
        t = d3_to_v3(t0);
        vsgl_asg ndf;
        vsgl_ndf_aniso_to_asg(&nf, &t, (float)alpha, (float)alpha, &ndf);
        vsgl_warp_ndf_asg(&ndf, &of, &out->warped);
    }
    vsgl_asg ra;
    memset(&ra, 0, sizeof ra);
    if (opt->receiver_asg)
        ra = out->warped;
    for (int q = 0; q < out->parts; ++q) {
        vsgl_sg gq = g;
        vsgl_asg aq = ra;
        if (out->parts == 2) { /* GGX's core (q 0) or tail (q 1): bandwidths x K, amplitude x C */
            float k = q ? VSGL__GGX_TAIL_K : VSGL__GGX_CORE_K, c = q ? VSGL__GGX_TAIL_C : VSGL__GGX_CORE_C;
            gq.sharpness *= k;
            gq.log_amplitude += logf(c);
            aq.lambda *= k;
            aq.mu *= k;
            aq.log_amplitude += logf(c);
        }
        out->sg[q] = gq;
        out->asg[q] = aq;
        vsgl__frame f; /* the ASG's frame as vsgl_asg_product would make it, once */
        out->framed[q] = opt->receiver_asg && vsgl__asg_frame(&aq, &f);
        for (int r = 0; r < 3; ++r)
            out->frame[q][0][r] = f.x[r], out->frame[q][1][r] = f.y[r], out->frame[q][2][r] = f.z[r];
    }
}

int vsgl__mrp_glossy_parts_at(const vsgl__mrp_rect *rc, d3 x, const vsgl__mrp_receiver *rcv,
                              const vsgl__mrp_options *opt, unsigned skip, double value[2], d3 axis[2])
{
    for (int q = 0; q < 2; ++q) {
        value[q] = 0.0;
        axis[q] = rcv->n;
    }
    double h = d3_dot(d3_sub(x, rc->center), rc->normal);
    if (!(h > 0.0) || !(rc->half_u > 0.0) || !(rc->half_v > 0.0))
        return rcv->parts;
    for (int q = 0; q < rcv->parts; ++q)
        if (!(skip & (1u << q)))
            value[q] = glossy_lobe(rc, x, h, &rcv->sg[q], &rcv->asg[q], rcv->framed[q] ? rcv->frame[q] : NULL, opt,
                                   &axis[q]);
    return rcv->parts;
}

int vsgl__mrp_glossy_parts(const vsgl__mrp_rect *rc, d3 x, d3 n, d3 o, double alpha, const vsgl__mrp_options *opt,
                           unsigned skip, double value[2], d3 axis[2])
{
    vsgl__mrp_receiver rcv;
    vsgl__mrp_receiver_make(n, o, alpha, opt, &rcv);
    return vsgl__mrp_glossy_parts_at(rc, x, &rcv, opt, skip, value, axis);
}

double vsgl__mrp_glossy_uniform(const vsgl__mrp_rect *rc, d3 x, d3 n, d3 o, double alpha,
                                const vsgl__mrp_options *opt, d3 *axis)
{
    double v[2];
    d3 ax[2];
    int parts = vsgl__mrp_glossy_parts(rc, x, n, o, alpha, opt, 0u, v, ax);
    *axis = ax[0];
    return parts == 2 ? v[0] + v[1] : v[0];
}
