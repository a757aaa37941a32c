/* Generate csrc/src/math/broad_lobe_table.c: how a rough receiver's glossy
 * lobe is widened and scaled to be closest to GGX's (docs/math.md §5.4.4,
 * "Broad lobes").
 *
 *   make broad-lobe-table          (builds this and rewrites the table)
 *   build/gen_broad_lobe [--write] (prints the C file, or writes it)
 *
 * The shade stage's lobe (shade.c setup_receiver: the NDF as an ASG, its
 * warp to light directions, the cut at the horizon, GGX's core and tail,
 * the specular factor F G / (4 cos_o) at its axis) is Xu et al.'s ASG,
 * whose smooth term max(l.z, 0) is about 1 across a sharp lobe but falls
 * off across a broad one, and whose Gaussian is in sin(theta), not GGX's
 * tan(theta): at roughness 0.8 it held 0.58-0.72 of GGX's albedo under a
 * uniform sky, 0.46-0.68 at 0.9. For each roughness row this program
 * searches the sharpness scale s (applied to the warped lobe before the
 * cut) whose lobe, at the amplitude closest to the exact lobe f cos at
 * each view (L2 over the hemisphere), is closest summed over the views;
 * each entry holds that amplitude. Both are faded in from roughness 0.4
 * (unchanged) to 0.6, so sharp lobes are left as they were. Two tables: a
 * dielectric of F0 0.04, whose Fresnel rises towards grazing light, and a
 * white conductor (F = 1). The model
 * is the lobe as the shade stage takes it: with Smith's shadowing and the
 * dielectric Fresnel towards each direction over their values at the axis
 * (shade/kernel.h, vsgl__smooth_ratio). Until those ratios (2026-12-07)
 * the conductor was fitted by its amplitude alone: widened, it made a
 * rough metal sphere reflecting a spot-lit wall brighter still than
 * Cycles (1.17 -> 1.25), because the lobe kept the wall's light arriving
 * at grazing incidence, which the shadowing ratio now takes out; widened
 * with the ratios the sphere is 1.00 of Cycles' Gloss and the conductor's
 * L2 distance to GGX x cos 0.10-0.16 at roughness 0.87 (0.14-0.25
 * unwidened). Both for the presets' lobe (GGX's core and tail as two
 * ASGs) and for one ASG (VSGL_GLOSSY_ASG). Exact: vsgl__brdf_eval,
 * quadrature of the upper hemisphere crowded at the horizon. */
#include "hemi_quad.h"
#include "math/broad_lobe.h"
#include "math/sg_internal.h"
#include "scene/material.h"
#include "shade/kernel.h"
#include "vsgl/lobes.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* the sum of f(l) dl over the upper hemisphere (tests/c/hemi_quad.h) */
static double hemisphere(hemi_fn f, const void *user)
{
    return hemi_quad(f, user, 192, 192);
}

typedef struct lobe_q {
    const vsgl_brdf_params *bp;
    v3 o;
    int parts; /* 2: GGX's core and tail (ASG2, the presets), 1: one ASG */
    vsgl_asg a;
    double sf, amp; /* the specular factor at the axis, the amplitude tried */
    float fr[3];    /* its Fresnel towards each direction over the axis' (vsgl__fresnel_ratio) */
} lobe_q;

static double exact_f(const lobe_q *q, v3 l)
{
    float d[3], g[3];
    vsgl__brdf_eval(q->bp, v3_make(0, 0, 1), v3_make(1, 0, 0), l, q->o, d, g);
    return g[0];
}

static double model_f(const lobe_q *q, v3 l)
{
    double x = q->a.x.x * l.x + q->a.x.y * l.y + q->a.x.z * l.z, y = q->a.y.x * l.x + q->a.y.y * l.y + q->a.y.z * l.z,
           z = q->a.z.x * l.x + q->a.z.y * l.y + q->a.z.z * l.z;
    if (!(z > 0.0))
        return 0.0;
    double sum = 0.0;
    for (int p = 0; p < q->parts; ++p) {
        double k = q->parts == 1 ? 1.0 : p ? VSGL__GGX_TAIL_K : VSGL__GGX_CORE_K;
        double c = q->parts == 1 ? 1.0 : p ? VSGL__GGX_TAIL_C : VSGL__GGX_CORE_C;
        sum += c * exp(q->a.log_amplitude - k * (q->a.lambda * x * x + q->a.mu * y * y));
    }
    /* and Smith's shadowing towards l over the axis' (kernel.h, vsgl__shadow_ratio), as the kernel takes it
     * for light from a small source */
    const vsgl_smooth_lane sm = vsgl__shadow_lane(sqrtf(q->bp->alpha_x * q->bp->alpha_y), q->o.z, q->a.z.z, q->parts == 2);
    return sum * z * q->sf * vsgl__smooth_ratio_of(&sm, q->fr, (float)l.z, (float)v3_dot(q->o, l));
}

static double exact_h(const void *u, v3 l) { return exact_f(u, l); }
static double mm_h(const void *u, v3 l)
{
    double m = model_f(u, l);
    return m * m;
}
static double me_h(const void *u, v3 l) { return model_f(u, l) * exact_f(u, l); }
/* the amplitude closest to the exact lobe (L2): <m, e> / <m, m> */
static double amplitude(const lobe_q *q)
{
    return hemisphere(me_h, q) / hemisphere(mm_h, q);
}
static double l2_h(const void *u, v3 l)
{
    const lobe_q *q = u;
    double d = q->amp * model_f(q, l) - exact_f(q, l);
    return d * d;
}

/* The shade stage's lobe seen from o, its sharpness scaled by s before the cut */
static void lobe(lobe_q *q, float s)
{
    vsgl__receiver_asg(v3_make(0, 0, 1), v3_make(1, 0, 0), q->o, q->bp->alpha_x, q->bp->alpha_y, s, 1.0f, &q->a);
    float sf[3];
    vsgl__specular_factor(q->bp, v3_make(0, 0, 1), q->o, v3_make(q->a.z.x, q->a.z.y, q->a.z.z),
                          sqrtf(q->bp->alpha_x * q->bp->alpha_y), sf);
    q->sf = sf[0];
    vsgl__fresnel_ratio(q->bp, v3_make(0, 0, 1), q->o, v3_make(q->a.z.x, q->a.z.y, q->a.z.z), q->fr);
}

static v3 view(int k)
{
    float c = vsgl__broad_col_cosine(k);
    return v3_make(sqrtf(1.0f - c * c), 0.0f, c);
}

static double fade(double r)
{
    double w = (r - VSGL__BROAD_R0) / (VSGL__BROAD_R1 - VSGL__BROAD_R0);
    w = w < 0.0 ? 0.0 : (w > 1.0 ? 1.0 : w);
    return w * w * (3.0 - 2.0 * w);
}

/* One table: the sharpness scale per row and the amplitude per row and view
 * for the material of F0 f0 (1: a white conductor, whose Fresnel is 1;
 * 0.04: a dielectric, whose Fresnel rises towards grazing light) */
static void fit_table(int parts, float f0, int widen, float s_row[VSGL__BROAD_ROWS],
                      float amp[VSGL__BROAD_ROWS][VSGL__BROAD_COLS])
{
    float s_opt[VSGL__BROAD_ROWS];
    for (int j = 0; j < VSGL__BROAD_ROWS; ++j) {
        double r = vsgl__broad_row_roughness(j), w = fade(r);
        vsgl_material m = {{1.0f, 1.0f, 1.0f}, f0 >= 1.0f ? 1.0f : 0.0f, (float)r, f0, 0, 0, 0, 0};
        vsgl_brdf_params bp;
        vsgl__material_params(&m, &bp);
        double ex[VSGL__BROAD_COLS];
        for (int k = 0; k < VSGL__BROAD_COLS; ++k) {
            lobe_q q = {.bp = &bp, .o = view(k), .parts = parts};
            ex[k] = hemisphere(exact_h, &q);
        }
        /* the sharpness scale: least L2 over the views (each relative to its
         * albedo, weighted by the views' spacing in cos_o, 2 u du), never
         * sharper than the smoother row's */
        double best = INFINITY;
        s_opt[j] = 1.0f;
        for (float s = j ? s_opt[j - 1] : 1.0f; widen && w > 0.0 && s >= 0.199f; s -= 0.025f) {
            double sum = 0.0;
            for (int k = 0; k < VSGL__BROAD_COLS; ++k) {
                lobe_q q = {.bp = &bp, .o = view(k), .parts = parts};
                lobe(&q, s);
                q.amp = amplitude(&q);
                sum += sqrt(vsgl__broad_col_cosine(k)) * sqrt(hemisphere(l2_h, &q)) / ex[k];
            }
            if (sum < best) {
                best = sum;
                s_opt[j] = s;
            }
        }
        s_row[j] = (float)(1.0 + w * (s_opt[j] - 1.0));
        for (int k = 0; k < VSGL__BROAD_COLS; ++k) {
            lobe_q q = {.bp = &bp, .o = view(k), .parts = parts};
            lobe(&q, s_row[j]);
            amp[j][k] = (float)pow(amplitude(&q), w);
        }
        fprintf(stderr, "%s, F0 %.2f, roughness %.3f: scale %.3f, amplitude %.3f (grazing) .. %.3f (head-on)\n",
                parts == 2 ? "two ASGs" : "one ASG", f0, r,
                s_row[j], amp[j][0], amp[j][VSGL__BROAD_COLS - 1]);
    }
}

static void print_table(FILE *f, float s_row[VSGL__BROAD_ROWS],
                        float amp[VSGL__BROAD_ROWS][VSGL__BROAD_COLS], const char *what)
{
    fprintf(f, "        /* %s */\n        {{", what);
    for (int j = 0; j < VSGL__BROAD_ROWS; ++j)
        fprintf(f, "%s%.4ff", j ? ", " : "", s_row[j]);
    fprintf(f, "},\n         {\n");
    for (int j = 0; j < VSGL__BROAD_ROWS; ++j) {
        fprintf(f, "             {");
        for (int k = 0; k < VSGL__BROAD_COLS; ++k)
            fprintf(f, "%s%.4ff", k ? ", " : "", amp[j][k]);
        fprintf(f, "},\n");
    }
    fprintf(f, "         }},\n");
}

int main(int argc, char **argv)
{
    int write = argc > 1 && !strcmp(argv[1], "--write");
    static float s_row[2][2][VSGL__BROAD_ROWS], amp[2][2][VSGL__BROAD_ROWS][VSGL__BROAD_COLS];
    for (int l = 0; l < 2; ++l) {
        fit_table(2 - l, 1.0f, 1, s_row[l][0], amp[l][0]);
        fit_table(2 - l, VSGL__BROAD_DIELECTRIC_F0, 1, s_row[l][1], amp[l][1]);
    }
    FILE *f = write ? fopen("csrc/src/math/broad_lobe_table.c", "w") : stdout;
    if (!f) {
        perror("csrc/src/math/broad_lobe_table.c");
        return 1;
    }
    fprintf(f, "/* Broad receiver lobes: the sharpness scale per roughness row and the\n"
               " * amplitude per row and view, for a conductor and a dielectric\n"
               " * (math/broad_lobe.h). Generated by tools/gen_broad_lobe.c\n"
               " * (`make broad-lobe-table`; do not edit). */\n"
               "#include \"math/broad_lobe.h\"\n\n"
               "const vsgl_broad_table vsgl__broad_tables[2][2] = {\n");
    for (int l = 0; l < 2; ++l) {
        fprintf(f, "    {\n");
        print_table(f, s_row[l][0], amp[l][0], l ? "one ASG, a white conductor (F = 1)" : "GGX's core and tail, a white conductor (F = 1)");
        print_table(f, s_row[l][1], amp[l][1], l ? "one ASG, a dielectric of F0 VSGL__BROAD_DIELECTRIC_F0" : "GGX's core and tail, a dielectric of F0 VSGL__BROAD_DIELECTRIC_F0");
        fprintf(f, "    },\n");
    }
    fprintf(f, "};\n");
    if (write && fclose(f) != 0) {
        perror("csrc/src/math/broad_lobe_table.c");
        return 1;
    }
    return 0;
}
