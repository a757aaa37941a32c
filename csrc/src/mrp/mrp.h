/* Internal: the most-representative-point (MRP) rectangle-proxy glossy
 * interreflection of ../shared/papers/mrp-rectangle-glossy-interreflection.md
 * ("the MRP paper"), equation by equation. docs/mrp.md gives every formula,
 * the errata applied, the measured errors and the degenerate cases.
 *
 * Conventions: world space, metres; directions unit length unless said.
 * A rectangle proxy (RP) emits from its front side (the side its normal
 * points to). Everything is pure and thread-safe, double precision inside;
 * no function fails: degenerate input gives a zero (documented) result,
 * never NaN or inf for finite input.
 *
 * Files: peak.c (Eq. 12, 18, 36), disk.c (Eq. 23-27), light.c (Eq. 28-35,
 * 11, 37), glossy.c (Eq. 10: one lit rectangle seen by a GGX receiver). */
#ifndef VSGL_MRP_H
#define VSGL_MRP_H

#include "vsgl/asg.h"
#include "math/vec.h"

/* An oriented rectangle: centre, unit normal (front side), unit in-plane
 * axes u, v (v = n x u) and half extents along them (m, >= 0). */
typedef struct vsgl__mrp_rect {
    d3 center, normal, u, v;
    double half_u, half_v;
} vsgl__mrp_rect;

/* ---------------------------------------------------------------- peak.c */

/* Build a rectangle from a centre, a normal and an in-plane direction
 * (made orthogonal to the normal). Returns 0 (and a zero-size rectangle)
 * when the normal is zero or the direction parallel to it. */
int vsgl__mrp_rect_make(d3 center, d3 normal, d3 u_dir, double half_u, double half_v, vsgl__mrp_rect *out);

/* Eq. 12, the specular peak: the point y of the rectangle's plane from which
 * direction @p r (unit, from y towards x) reaches the shading point x:
 *   y = x - r ((x - c).n) / (r.n)        (the paper's i.n equals r.n, r the mirror of i)
 * For the paper's distant light i, r = 2 (i.n) n - i; for a receiver's
 * glossy lobe of axis z (towards the rectangle), r = -z.
 * Returns 0 (y = x) when x is on or behind the plane ((x - c).n <= 0),
 * when r.n <= 0 (the paper's i.n_r <= 0: no peak), or when y would not be
 * finite (grazing r). */
int vsgl__mrp_peak(const vsgl__mrp_rect *rc, d3 x, d3 r, d3 *y);

/* The paper's distant-light reflected direction r = 2 (i.n) n - i. */
d3 vsgl__mrp_reflect(d3 i, d3 n);

/* Eq. 18: the representative attenuation axes at the peak,
 *   v = yx x n_r,  u = n_r x v   (normalised; yx the unit direction y -> x).
 * When yx is along n_r (no plane of incidence) u, v are any completion.
 * u lies in the plane of incidence, v across it. */
void vsgl__mrp_disk_axes(d3 yx, d3 n_r, d3 *u, d3 *v);

/* Eq. 36 as printed: A = S_J / (pi r_d^2), J the rectangle's-axis-aligned
 * bounding box of I = disk(y, r_d) intersect rectangle. In [0, 4/pi]: a disk
 * wholly inside the rectangle gives 4/pi, not 1 (docs/mrp.md). */
double vsgl__mrp_overlap_bbox(const vsgl__mrp_rect *rc, d3 y, double rd);

/* The exact S_I / (pi r_d^2) (closed form, piecewise circular segments), in [0, 1]. */
double vsgl__mrp_overlap_exact(const vsgl__mrp_rect *rc, d3 y, double rd);

/* The centre of J (the box of Eq. 36) in world space; y itself when I is
 * empty. Used to move the lobe onto the part of the disk the rectangle
 * covers (docs/mrp.md, "centred" variant). */
d3 vsgl__mrp_overlap_center(const vsgl__mrp_rect *rc, d3 y, double rd);

/* ---------------------------------------------------------------- disk.c */

/* Eq. 24: psi(theta) = -sigma/2 + atan(sec^2(sigma) tan(theta) + tan(sigma)) / 2,
 * theta in [0, pi/2), sigma in [0, pi/2). */
double vsgl__mrp_psi(double theta, double sigma);

/* Eq. 23: f = D(psi, m) / D(0, m) = m^4 / (1 - (1 - m^2) cos^2 psi)^2 for GGX,
 * m the reflector's alpha, with psi from Eq. 24: what Eq. 25 fits. */
double vsgl__mrp_f_ggx(double theta, double sigma, double m);

/* Eq. 25's fitted exponent k = 0.288 cos(sigma) / m^2 - 0.673, as printed
 * (<= 0 for rough or grazing reflectors: cos(sigma) / m^2 <= 2.34). */
double vsgl__mrp_k(double cos_sigma, double m);

/* Eq. 25: exp(-k sin^2 theta) cos theta. */
double vsgl__mrp_f_fit(double theta, double k);

/* Eq. 26/27's t = sin^2(alpha) = 1 - 1 / (1 + l^2 cos^2 sigma), l = r_d / |x - y|,
 * computed as q / (1 + q), q = (l cos sigma)^2. */
double vsgl__mrp_cap_t(double l, double cos_sigma);

/* Eq. 26 per unit L_y: E / L_y = (pi / k) (1 - e^{-k t}), written
 * pi t (-expm1(-k t)) / (k t) so k -> 0 gives the limit pi t. k <= 0
 * (Eq. 25 then claims the radiance grows away from the peak, which GGX
 * never does: f <= 1) is clamped to 0, i.e. f = cos(theta). */
double vsgl__mrp_disk_integral(double k, double t);

/* Eq. 27: C = A (pi / k) (1 - e^{-k t}) L_y with the clamped k above. */
double vsgl__mrp_disk_radiance(double overlap, double k, double t, double L_y);

/* ---------------------------------------------------------------- light.c */

/* Eq. 32 (from Eq. 31, epsilon = 0.05; 2.996 = -ln 0.05): the bandwidth
 * whose ASG falls to epsilon at the tangent length l (disk edge over the
 * distance): (1 + 1/l^2)(2.996 - ln(1 + l^2)/2). Clamped to
 * [0, VSGL_SHARPNESS_MAX]: 0 from l ~ 19.97 (a disk subtending more than
 * ~87 degrees: cos(theta) alone is below epsilon at its edge), the cap as
 * l -> 0. */
double vsgl__mrp_bandwidth(double l);

/* The integral of the unit ASG (vsgl__asg_integral_unit) within 1e-9 of
 * it, faster: for min(lambda, mu) >= VSGL__ASG_EQ10_MIN_MU Eq. 10's small
 * second term (<= e^{-min} sqrt(max / min) of the first) with a polynomial
 * Bessel function, and none where it is below 2^-54 of the first (the
 * same double); vsgl__asg_integral_unit below. */
double vsgl__mrp_asg_integral_unit(double lambda, double mu);

/* How the ASG light's amplitude is normalised (Eq. 33-35). */
#define VSGL__MRP_NORM_PAPER 0 /* Eq. 34-35: t = sqrt(lambda mu) C / pi (0 when a bandwidth is 0) */
#define VSGL__MRP_NORM_EXACT 1 /* t = C / (exact integral of the unit ASG), finite for any bandwidths */

/* Eq. 28-35: the ASG light of a sampling disk of radius @p rd, centre @p y,
 * normal @p n_d, seen from @p x, carrying total radiance C (W/m^2/sr x sr):
 * z = (y - x)/|y - x|, x-axis m = v (Eq. 18, across the plane of
 * incidence) with l_m = r_d / d, y-axis n = yx x v with
 * l_n = r_d (n_d . yx) / d (Eq. 29 at distance d), bandwidths Eq. 32,
 * amplitude by @p norm. Returns 0 (zero lobe, log_amplitude -inf) when
 * x is on or behind the disk's plane, x = y, C <= 0 or not finite. */
int vsgl__mrp_asg_light(d3 x, d3 y, d3 n_d, double rd, double C, int norm, vsgl_asg *out);

/* The same light in double: its frame (rows: x = m, y, z), bandwidths and
 * log amplitude, as vsgl__mrp_asg_light rounds them to its float ASG.
 * Returns 0 (outputs untouched) where vsgl__mrp_asg_light returns 0. */
int vsgl__mrp_asg_light_d(d3 x, d3 y, d3 n_d, double rd, double C, int norm, double frame[3][3], double *lambda,
                          double *mu, double *log_amplitude);

/* Eq. 8: the receiver's NDF as an SG in light-direction space: axis
 * reflect(o, n), sharpness 2 / (4 |o.n| alpha^2), amplitude 1 / (pi alpha^2)
 * (the library's vsgl_ndf_to_sg + vsgl_warp_ndf_sg). */
void vsgl__mrp_receiver_sg(d3 n, d3 o, double alpha, vsgl_sg *out);

/* Eq. 11: integral of ASG x SG over the sphere, both amplitudes included,
 * by Xu et al.'s convolution evaluated at the SG's axis, with nu = SG
 * sharpness / 2 (GUIDE.md: the MRP paper prints Xu's nu; in its own SG
 * convention e^{nu (v.p - 1)} it is half the sharpness) and the printed
 * normalisation pi / sqrt((lambda + nu)(mu + nu)). */
double vsgl__mrp_convolve(const vsgl_asg *light, const vsgl_sg *g);

/* Eq. 37, the SG-only variant: the ASG light as an SG of axis z. As
 * printed (@p geometric_mean 0): sharpness 2 max(lambda, mu), amplitude
 * kept (the peak is kept, the energy falls to sqrt(min/max) of the ASG's).
 * @p geometric_mean 1: sharpness 2 sqrt(lambda mu), amplitude scaled so the
 * integral is the ASG's (keeps both for large bandwidths). */
void vsgl__mrp_asg_to_sg(const vsgl_asg *a, int geometric_mean, vsgl_sg *out);

/* Eq. 37's product integral by Iwasaki et al. (vsgl_sg_product_integral_iwasaki). */
double vsgl__mrp_convolve_sg(const vsgl_sg *light, const vsgl_sg *g);

/* --------------------------------------------------------------- glossy.c */

/* Choices for vsgl__mrp_glossy_uniform (docs/mrp.md measures each). */
typedef struct vsgl__mrp_options {
    int norm;        /* VSGL__MRP_NORM_* */
    int overlap;     /* 0: Eq. 36 as printed (bbox), 1: exact area */
    int centred;     /* 1: the lobe's axis through the centre of J, not y */
    int sg_only;     /* 1: Eq. 37 (geometric-mean SG, Iwasaki product) */
    int solid_angle; /* 0: Eq. 26's cap of aperture atan(l cos sigma) (paper), 1: the disk's own solid angle */
    double rd_scale; /* r_d = rd_scale x the rule of glossy.c (disk_radius); 1 = the rule */
    int receiver_asg; /* 1: the receiver's NDF as the library's warped ASG (vsgl_warp_ndf_asg: stretched
                         at grazing views) and the ASG x ASG product integral, not Eq. 8's isotropic SG */
    int lobes;        /* 1: the receiver's NDF as one Gaussian (Wang et al.: GGX's peak and integral, no tails);
                         2: GGX as a core and a tail lobe (VSGL__GGX_{CORE,TAIL}_{K,C} of shade/kernel.h, as
                         VSGL_GLOSSY_ASG2 does for VSGLs), each with its own disk (the rule scales with the
                         lobe's width) */
    double shrink;    /* > 0: when the rectangle covers less than the disk (a small cell of a proxy), the ASG
                         light spans at most shrink x the radius of the disk of the overlap's area
                         (r_d sqrt(A)), not the whole disk; 0: the whole disk */
} vsgl__mrp_options;

/* The options docs/mrp.md recommends (the best measured). */
vsgl__mrp_options vsgl__mrp_options_default(void);
/* The paper as printed (bbox overlap, paper normalisation, cap). */
vsgl__mrp_options vsgl__mrp_options_paper(void);

/* Eq. 10 for a Lambertian rectangle of uniform outgoing radiance L (per
 * unit, scale by the RGB radiance) seen by a GGX receiver at x (normal n,
 * view o, alpha): the glossy radiance towards o divided by L and by the
 * smooth factor M(z) cos (which the caller evaluates at the returned
 * @p axis with the receiver's own Fresnel and shadowing). The peak (Eq. 12)
 * is where the receiver lobe's axis z = reflect(o, n) meets the plane; if
 * it misses the rectangle the peak is clamped onto it. Returns 0 when the
 * receiver is on or behind the plane or its lobe axis does not point at
 * the plane's front. */
double vsgl__mrp_glossy_uniform(const vsgl__mrp_rect *rc, d3 x, d3 n, d3 o, double alpha,
                                const vsgl__mrp_options *opt, d3 *axis);

/* The same per receiver lobe: value[q] and axis[q] for each of the
 * opt->lobes parts (q 0 the core, 1 the tail; the unused one 0 with axis
 * n), so the caller evaluates the smooth factor at each part's own axis;
 * part q is not evaluated (left 0) when bit q of @p skip is set (a cell
 * beyond the core's reach). Returns the number of parts (1 or 2).
 * vsgl__mrp_glossy_uniform returns their sum with the core's axis. */
int vsgl__mrp_glossy_parts(const vsgl__mrp_rect *rc, d3 x, d3 n, d3 o, double alpha, const vsgl__mrp_options *opt,
                           unsigned skip, double value[2], d3 axis[2]);

/* A receiver's lobes, computed once per shading point (normal n, view o,
 * alpha) and shared by every rectangle it visits: Eq. 8's SG and the
 * warped ASG per part (core, tail), and the warped ASG itself. */
typedef struct vsgl__mrp_receiver {
    d3 n;
    int parts;       /* 1 or 2 (opt->lobes) */
    vsgl_sg sg[2];   /* Eq. 8 per part (bandwidth x K, amplitude x C of shade/kernel.h) */
    vsgl_asg asg[2]; /* the warped ASG per part (zero unless opt->receiver_asg) */
    vsgl_asg warped; /* the warped ASG of the whole NDF (vsgl_warp_ndf_asg) */
    int framed[2];           /* 1: frame[q] holds asg[q]'s frame (rows x, y, z) in double */
    double frame[2][3][3];
} vsgl__mrp_receiver;

void vsgl__mrp_receiver_make(d3 n, d3 o, double alpha, const vsgl__mrp_options *opt, vsgl__mrp_receiver *out);

/* The sampling disk's radius (docs/mrp.md §3, step 3) that part @p q of
 * the receiver uses for a rectangle whose clamped peak is at distance @p d,
 * cos(sigma) @p cs. */
double vsgl__mrp_lobe_disk_radius(const vsgl__mrp_receiver *rcv, int q, const vsgl__mrp_options *opt, double d,
                                  double cs);

/* vsgl__mrp_glossy_parts with the receiver's lobes made beforehand: the
 * same values, bit for bit. */
int vsgl__mrp_glossy_parts_at(const vsgl__mrp_rect *rc, d3 x, const vsgl__mrp_receiver *rcv,
                              const vsgl__mrp_options *opt, unsigned skip, double value[2], d3 axis[2]);

#endif
