/* A receiver's glossy lobe at a grazing view (the warp, the horizon cut
 * and its fan, docs/math.md §5.4.3) against the exact GGX BRDF under a
 * uniform sky: the light it reflects towards the viewer (its directional
 * albedo), by quadrature of vsgl__brdf_eval over the hemisphere, against
 * the lobe's own integral times the specular factor at its axis, as the
 * shade stage takes them (GGX's core and tail as two ASGs). */
#include "harness.h"
#include "hemi_quad.h"
#include "math/broad_lobe.h"
#include "math/sg_internal.h"
#include "scene/material.h"
#include "shade/kernel.h"
#include "vsgl/lobes.h"

#include <math.h>
#include <stdlib.h>


/* the sum of f(l) dl over the upper hemisphere (hemi_quad.h) */
static double hemisphere(hemi_fn f, const void *user)
{
    return hemi_quad(f, user, 768, 768);
}

/* A receiver's BRDF of colour (r, g, b), metallic 0 or 1, F0 0.04 */
static vsgl_brdf_params lobe_material(float r, float g, float b, int metal, float rough)
{
    vsgl_material m = {{r, g, b}, metal ? 1.0f : 0.0f, rough, 0.04f, 0, 0, 0, 0};
    vsgl_brdf_params bp;
    vsgl__material_params(&m, &bp);
    return bp;
}

/* The view in the xz plane at cosine c to the normal +z */
static v3 view_at(float c)
{
    return v3_make(sqrtf(1.0f - c * c), 0.0f, c);
}

typedef struct exact_q { const vsgl_brdf_params *bp; v3 o; } exact_q;
static double exact_f(const void *user, v3 l)
{
    const exact_q *q = user;
    float d[3], g[3];
    vsgl__brdf_eval(q->bp, v3_make(0, 0, 1), v3_make(1, 0, 0), l, q->o, d, g);
    return g[0];
}

/* GGX's core and tail as ASGs of the lobe a (shade.c ggx_part; one ASG
 * where one is set), times the specular factor sf at its axis: the glossy
 * radiance from direction l */
typedef struct model_q {
    vsgl_asg a;
    double sf;
    int one;
    /* ratio: also the shadowing and Fresnel towards l over the axis'
     * (kernel.h, vsgl__smooth_ratio), as the shade stage takes them */
    int ratio;
    vsgl_smooth_lane sm;
    float fr[3];
    v3 o;
} model_q;
static double model_f(const void *user, v3 l)
{
    const model_q *q = user;
    double x = q->a.x.x * l.x + q->a.x.y * l.y + q->a.x.z * l.z, y = q->a.y.x * l.x + q->a.y.y * l.y + q->a.y.z * l.z,
           z = q->a.z.x * l.x + q->a.z.y * l.y + q->a.z.z * l.z;
    if (!(z > 0.0))
        return 0.0;
    double sum = 0.0;
    for (int p = 0; p < (q->one ? 1 : 2); ++p) {
        double k = q->one ? 1.0 : p ? VSGL__GGX_TAIL_K : VSGL__GGX_CORE_K;
        double c = q->one ? 1.0 : p ? VSGL__GGX_TAIL_C : VSGL__GGX_CORE_C;
        sum += c * exp(q->a.log_amplitude - k * (q->a.lambda * x * x + q->a.mu * y * y));
    }
    if (q->ratio)
        sum *= vsgl__smooth_ratio_of(&q->sm, q->fr, (float)l.z,
                                  (float)v3_dot(q->o, l));
    return sum * z * q->sf;
}

/* The light the exact BRDF reflects towards o from a uniform sky of
 * radiance 1 over the upper hemisphere (channel 0): its albedo. */
static double exact_albedo(const vsgl_brdf_params *bp, v3 o)
{
    exact_q q = {bp, o};
    return hemisphere(exact_f, &q);
}

/* The same through the shade stage's lobe (shade.c setup_receiver) seen
 * from o. view NULL: the cut alone. */
static double model_albedo(const vsgl_brdf_params *bp, v3 o, const vsgl_vec3 *view)
{
    vsgl_vec3 n = {0, 0, 1}, t = {1, 0, 0}, ov = {o.x, o.y, o.z};
    vsgl_asg ndf;
    model_q q = {0};
    vsgl_ndf_aniso_to_asg(&n, &t, bp->alpha_x, bp->alpha_y, &ndf);
    vsgl_warp_ndf_asg(&ndf, &ov, &q.a);
    q.one = 0;
    vsgl__asg_cut_at_horizon(&q.a, &n, view);
    float sf[3];
    vsgl__specular_factor(bp, v3_make(0, 0, 1), o, v3_make(q.a.z.x, q.a.z.y, q.a.z.z),
                          sqrtf(bp->alpha_x * bp->alpha_y), sf);
    q.sf = sf[0];
    return hemisphere(model_f, &q);
}

VT_TEST(lobe_fan_keeps_a_grazing_views_light)
{
    /* A glossy sphere's rim and a far floor see their reflection along
     * their tangent plane. Cut at the horizon alone, the lobe kept 0.58 of
     * GGX's light at cos_o = 0.05 (roughness 0.3, dielectric), 0.40 of a
     * metal's: its width across the plane of incidence was the one at the
     * mirror direction, the fan's narrowest. With the fan: a dielectric's
     * within 0.95-1.11 of the exact albedo from cos_o 0.9 down to 0.05, a
     * metal's at least 0.68 there (0.40 alone), never over 1.11 anywhere,
     * never below the cut alone, and views clear of the horizon unchanged.
     * Below cos_o 0.05 both lose light (0.41-0.92 at 0.02, 0.08-0.19
     * alone). The cut alone is checked to lose over a third somewhere,
     * which the test must see. */
    const float roughs[] = {0.2f, 0.3f}, cosines[] = {0.9f, 0.5f, 0.3f, 0.2f, 0.1f, 0.05f, 0.02f};
    double worst_alone = 1.0;
    for (int metal = 0; metal < 2; ++metal)
        for (int ir = 0; ir < 2; ++ir) {
            const vsgl_brdf_params bp = lobe_material(0.8f, 0.35f, 0.1f, metal, roughs[ir]);
            for (int ic = 0; ic < 7; ++ic) {
                float c = cosines[ic];
                if (getenv("VSGL_TEST_QUICK") && ic % 2 && ic != 5)
                    continue;
                v3 o = view_at(c);
                vsgl_vec3 ov = {o.x, o.y, o.z};
                double ex = exact_albedo(&bp, o), with = model_albedo(&bp, o, &ov) / ex,
                       alone = model_albedo(&bp, o, NULL) / ex;
                if (getenv("VSGL_TEST_TABLES"))
                    printf("roughness %.1f %s cos_o %.2f: exact %.4f, lobe with its fan %.3f, cut alone %.3f\n",
                           roughs[ir], metal ? "metal" : "dielectric", c, ex, with, alone);
                VT_CHECK(with < 1.11, "roughness %g metal %d cos_o %g: %.3f of the exact albedo", roughs[ir], metal,
                         c, with);
                VT_CHECK(with >= alone - 1e-6, "cos_o %g: the fan takes light away (%.3f < %.3f)", c, with, alone);
                if (c >= 0.05f)
                    VT_CHECK(with > (metal ? 0.68 : 0.95), "roughness %g metal %d cos_o %g: %.3f of the exact albedo",
                             roughs[ir], metal, c, with);
                if (c >= 0.5f)
                    VT_CHECK_ABS(with, alone, 1e-6, "cos_o %g: a view clear of the horizon is unchanged", c);
                worst_alone = fmin(worst_alone, alone);
            }
        }
    VT_CHECK(worst_alone < 0.65, "the cut alone keeps at least %.3f at every view: the test must see its loss",
             worst_alone);
}

/* The same through the lobe with the broad-lobe fit (math/broad_lobe.h),
 * as setup_receiver takes it: the sharpness scaled before the cut, the
 * amplitude after; and its L2 distance to the exact lobe over the exact
 * albedo. */
typedef struct l2_q { model_q m; exact_q e; } l2_q;
static double l2_f(const void *user, v3 l)
{
    const l2_q *q = user;
    double d = model_f(&q->m, l) - exact_f(&q->e, l);
    return d * d;
}

static void rough_lobe(const vsgl_brdf_params *bp, v3 o, int broad, int one, model_q *q)
{
    q->one = one;
    float scale = 1.0f, amp = 1.0f, alpha = sqrtf(bp->alpha_x * bp->alpha_y);
    if (broad)
        vsgl__broad_lobe(alpha, (bp->f0[0] + bp->f0[1] + bp->f0[2]) / 3.0f, o.z, !one, &scale, &amp);
    vsgl__receiver_asg(v3_make(0, 0, 1), v3_make(1, 0, 0), o, bp->alpha_x, bp->alpha_y, scale, amp, &q->a);
    float sf[3];
    vsgl__specular_factor(bp, v3_make(0, 0, 1), o, v3_make(q->a.z.x, q->a.z.y, q->a.z.z), alpha, sf);
    q->sf = sf[0];
    /* the fitted lobe as the shade stage takes it: with the ratios */
    q->ratio = broad;
    q->o = o;
    q->sm = vsgl__shadow_lane(alpha, o.z, q->a.z.z, !one);
    vsgl__fresnel_ratio(bp, v3_make(0, 0, 1), o, v3_make(q->a.z.x, q->a.z.y, q->a.z.z), q->fr);
}

VT_TEST(broad_lobe_holds_a_rough_receivers_light)
{
    /* A rough receiver (roughness 0.8-0.9: the demo's walls and ceiling)
     * under a uniform sky: Xu et al.'s lobe held 0.58-0.72 of GGX's albedo
     * at roughness 0.8, 0.46-0.68 at 0.9 (its smooth term max(l.z, 0) falls
     * off across a broad lobe; its Gaussian is in sin(theta)). With the fit
     * (tools/gen_broad_lobe.c: closest to the exact lobe in L2) at
     * roughness and views between the table's entries, for GGX as two ASGs
     * and as one, the lobe as the shade stage takes it (with the shadowing
     * and Fresnel ratios towards each direction, kernel.h
     * vsgl__smooth_ratio): its L2 distance to the exact lobe below the
     * unfitted one's, its albedo below 1.05 of GGX's everywhere, a
     * dielectric's at least 0.78 of it, a conductor's at least 0.65 and
     * 0.75 head-on, and the lobe unchanged below roughness 0.4. The fit
     * is closest in L2, not in energy: where it reshapes a lobe its albedo
     * may end below the unfitted one's (a dielectric at roughness 0.67
     * seen at cos_o 0.15: 0.796 against 0.812, L2 0.255 against 0.453).
     * Measured: a dielectric of F0 0.04 0.80-0.88 of GGX's albedo
     * (0.40-0.81 unfitted), a white conductor 0.67-0.94 (0.32-0.85). */
    const float roughs[] = {0.67f, 0.77f, 0.87f, 0.97f}, cosines[] = {0.95f, 0.62f, 0.37f, 0.15f};
    double worst_before = 1.0, lo_d = 2.0, hi_d = 0.0, lo_m = 2.0, hi_m = 0.0;
    for (int one = 0; one < 2; ++one)
    for (int metal = 0; metal < 2; ++metal)
        for (int ir = one; ir < 4; ir += 1 + one) { /* one ASG (VSGL_GLOSSY_ASG): roughness 0.77, 0.97 */
            const vsgl_brdf_params bp = lobe_material(1.0f, 1.0f, 1.0f, metal, roughs[ir]);
            for (int ic = 0; ic < 4; ++ic) {
                if (getenv("VSGL_TEST_QUICK") && (ir + ic) % 2)
                    continue;
                float c = cosines[ic];
                v3 o = view_at(c);
                double ex = exact_albedo(&bp, o);
                l2_q before, after;
                before.e = after.e = (exact_q){&bp, o};
                rough_lobe(&bp, o, 0, one, &before.m);
                rough_lobe(&bp, o, 1, one, &after.m);
                double e0 = hemisphere(model_f, &before.m) / ex, e1 = hemisphere(model_f, &after.m) / ex;
                double d0 = sqrt(hemisphere(l2_f, &before)) / ex, d1 = sqrt(hemisphere(l2_f, &after)) / ex;
                if (getenv("VSGL_TEST_TABLES"))
                    printf("%s, roughness %.2f %s cos_o %.2f: albedo %.3f -> %.3f of GGX's, L2 %.3f -> %.3f\n",
                           one ? "one ASG" : "two ASGs", roughs[ir], metal ? "metal" : "dielectric", c, e0, e1, d0,
                           d1);
                /* a dielectric's albedo within 0.78-1.05 of GGX's; a conductor's
                 * at least 0.65, 0.75 head-on */
                const double lo_ok = metal ? (c > 0.9f ? 0.75 : 0.65) : 0.78;
                VT_CHECK(e1 > lo_ok && e1 < 1.05, "one %d roughness %g metal %d cos_o %g: %.3f of GGX's albedo", one,
                         roughs[ir], metal, c, e1);
                if (metal) {
                    lo_m = fmin(lo_m, e1);
                    hi_m = fmax(hi_m, e1);
                } else {
                    lo_d = fmin(lo_d, e1);
                    hi_d = fmax(hi_d, e1);
                }
                VT_CHECK(d1 < d0, "one %d roughness %g metal %d cos_o %g: L2 %.3f, unfitted %.3f", one, roughs[ir],
                         metal, c, d1, d0);
                worst_before = fmin(worst_before, e0);
            }
        }
    vt_note("    ", "roughness 0.67-0.97, cos_o 0.15-0.95: of GGX's albedo, a dielectric %.3f-%.3f, a conductor "
            "%.3f-%.3f (unfitted from %.3f)", lo_d, hi_d, lo_m, hi_m, worst_before);
    VT_CHECK(worst_before < 0.75, "the unfitted lobe keeps %.3f at least: the test must see its loss", worst_before);
    for (float r = 0.0f; r <= 0.4f; r += 0.05f) {
        float s, a;
        for (int two = 0; two < 2; ++two) {
            vsgl__broad_lobe(r * r, 0.04f, 0.5f, two, &s, &a);
            VT_CHECK(s == 1.0f && a == 1.0f, "roughness %g: scale %g amplitude %g, not 1", r, s, a);
        }
    }
}


VT_TEST(broad_lobe_takes_little_light_from_its_horizon)
{
    /* A rough receiver (roughness 0.7-0.85: rough_room's metal sphere and
     * walls) lit from near its horizon on the far side from its view,
     * where its lobe points: GGX x cos takes that light through Smith's
     * shadowing G2(l, o), which falls to 0 at the horizon, while the
     * lobe's smooth factor at its axis does not (the sphere's band facing a
     * lit wall at grazing: 1.2-1.6x Cycles' Gloss). Per direction within
     * 2-14 degrees of the horizon and 45 degrees of the mirror side, the
     * presets' two-lobe GGX with the broad-lobe fit (as the shade stage
     * takes it) over GGX x cos: with the shadowing and Fresnel ratios
     * (kernel.h vsgl__smooth_ratio) at most 1.1 at views cos_o >= 0.6 (the
     * sphere's) and under 0.8 of the same lobe's without them at every
     * view; without them over 2 somewhere (the test would not fail
     * otherwise). Measured: at cos_o >= 0.6 0.10-1.01 with them, up to 6.3
     * without; at grazing views (cos_o 0.15-0.37) still up to 3.2 (12.4
     * without). Left as it is (docs/math.md 5.4.5): that grazing
     * overshoot, and sideways (90 degrees from the mirror side) the lobe
     * with the ratios takes 0.09-0.4 of GGX's light within 10 degrees of
     * the horizon (0.65-0.75 without): Xu et al.'s smooth term max(l.z, 0)
     * falls off there as well. */
    const float roughs[] = {0.7f, 0.85f}, cosines[] = {0.95f, 0.83f, 0.62f, 0.37f, 0.15f};
    const double pi = 3.14159265358979;
    double lo = 1e9, hi = 0.0, hi_without = 0.0;
    for (int metal = 0; metal < 2; ++metal)
        for (int ir = 0; ir < 2; ++ir) {
            const vsgl_brdf_params bp = lobe_material(1.0f, 1.0f, 1.0f, metal, roughs[ir]);
            for (int ic = 0; ic < 5; ++ic) {
                float c = cosines[ic];
                v3 o = view_at(c);
                exact_q e = {&bp, o};
                model_q with, without;
                rough_lobe(&bp, o, 1, 0, &with);
                without = with;
                without.ratio = 0;
                double w_hi = 0.0, w_lo = 1e9, o_hi = 0.0;
                for (int el = 2; el <= 14; el += 4)
                    for (int az = 135; az <= 225; az += 15) { /* o lies at azimuth 0 */
                        double t = (90 - el) * pi / 180.0, ph = az * pi / 180.0;
                        v3 l = v3_make((float)(sin(t) * cos(ph)), (float)(sin(t) * sin(ph)), (float)cos(t));
                        double ex = exact_f(&e, l);
                        if (!(ex > 0.0))
                            continue;
                        double rw = model_f(&with, l) / ex, ro = model_f(&without, l) / ex;
                        w_hi = fmax(w_hi, rw);
                        w_lo = fmin(w_lo, rw);
                        o_hi = fmax(o_hi, ro);
                    }
                if (getenv("VSGL_TEST_TABLES"))
                    printf("roughness %.2f %s cos_o %.2f: near the horizon on the mirror side, lobe / GGX x cos "
                           "%.2f-%.2f (without the ratios up to %.2f)\n", roughs[ir], metal ? "metal" : "dielectric",
                           c, w_lo, w_hi, o_hi);
                VT_CHECK(c < 0.6f || w_hi < 1.1, "roughness %g metal %d cos_o %g: %.3f of GGX x cos near the horizon",
                         roughs[ir], metal, c, w_hi);
                VT_CHECK(w_hi < 0.8 * o_hi, "roughness %g metal %d cos_o %g: %.3f of GGX x cos near the horizon, "
                         "%.3f without the ratios", roughs[ir], metal, c, w_hi, o_hi);
                lo = fmin(lo, w_lo);
                hi = fmax(hi, w_hi);
                hi_without = fmax(hi_without, o_hi);
            }
        }
    vt_note("    ", "near the horizon on the mirror side, the lobe over GGX x cos: %.2f-%.2f (without the ratios up "
            "to %.2f)", lo, hi, hi_without);
    VT_CHECK(hi_without > 2.0, "without the ratios at most %.3f: the test would not fail", hi_without);
}
