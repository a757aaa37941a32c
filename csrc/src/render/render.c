/* vsgl_render: G-buffer -> per-light RSM -> VSGL fit -> shading -> planes.
 * Lights that contribute nothing are skipped and reported; outputs are
 * written only when everything succeeded. */
#include "mrp/proxies.h"
#include "render/budget.h"
#include "render/render_internal.h"
#include "shade/shade.h"
#include "shade/brute_force.h"
#include "shade/kernel.h" /* VSGL__FAINT, VSGL__KERNEL_BLOCK */
#include "core/context.h"
#include "core/versioned.h"
#include "core/parallel.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Logs one formatted line (at most line_max - 1 characters) as "tag: line"
 * and appends it to `text` (capacity cap), whole lines only. With `more`,
 * room for it is always kept: when a line does not fit, `more` is appended
 * once instead, saying the rest is in the log. */
static void append_note(vsgl_context *ctx, const char *tag, char *text, size_t cap, size_t line_max, const char *more,
                        const char *fmt, va_list ap) VSGL_PRINTF(7, 0);
static void append_note(vsgl_context *ctx, const char *tag, char *text, size_t cap, size_t line_max, const char *more,
                        const char *fmt, va_list ap)
{
    char line[256];
    vsnprintf(line, line_max < sizeof line ? line_max : sizeof line, fmt, ap);
    vsgl__log(ctx, VSGL_LOG_INFO, "%s: %s", tag, line);
    size_t used = strlen(text), room = cap - (more ? strlen(more) + 1 : 0);
    if (used + strlen(line) + 1 < room)
        snprintf(text + used, cap - used, "%s\n", line);
    else if (more && !strstr(text, more))
        snprintf(text + used, cap - used, "%s", more);
}

static void note_skip(vsgl_context *ctx, vsgl_render_stats *st, const char *fmt, ...) VSGL_PRINTF(3, 4);
static void note_skip(vsgl_context *ctx, vsgl_render_stats *st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    append_note(ctx, "skipped", st->skipped, sizeof st->skipped, 256,
                "(more: every skipped item is logged at level INFO)\n", fmt, ap);
    va_end(ap);
}

/* Appends one line to the stats' budget text (whole lines only). */
static void note_budget(vsgl_context *ctx, vsgl_render_stats *st, const char *fmt, ...) VSGL_PRINTF(3, 4);
static void note_budget(vsgl_context *ctx, vsgl_render_stats *st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    append_note(ctx, "budget", st->budget, sizeof st->budget, 192, NULL, fmt, ap);
    va_end(ap);
}

/* The RSM of light `l`, or a noted skip: *lit = 0 when the light has no
 * power or its RSM is empty (then `rsm` holds nothing to free). The
 * progress window of the step is [p0, p0 + dp). */
static vsgl_result light_rsm(vsgl_context *ctx, const vsgl_scene *scene, uint32_t l, uint32_t resolution,
                             int drop_outward, float p0, float dp, vsgl_rsm *rsm, int *lit, vsgl_render_stats *st)
{
    uint32_t light_count = 0;
    const vsgl_light *L = &vsgl__scene_lights(scene, &light_count)[l];
    *lit = 0;
    memset(rsm, 0, sizeof *rsm);
    if (!(L->power * (L->color[0] + L->color[1] + L->color[2]) > 0.0f)) {
        note_skip(ctx, st, "light %u: zero power or black colour", l);
        ++st->lights_skipped;
        return VSGL_OK;
    }
    double t0 = now_seconds();
    vsgl__progress_window(ctx, p0, dp);
    double out[3] = {0, 0, 0};
    vsgl_result r = drop_outward ? vsgl__rsm_build_inward(ctx, scene, l, resolution, rsm, out)
                                 : vsgl__rsm_build(ctx, scene, l, resolution, rsm);
    st->seconds_rsm += now_seconds() - t0;
    if (r != VSGL_OK)
        return r;
    if (out[0] + out[1] + out[2] > 0.0) {
        double kept = rsm->total_flux[0] + rsm->total_flux[1] + rsm->total_flux[2];
        note_skip(ctx, st, "light %u: %.1f %% of its power falls on surfaces facing out of the scene (the "
                  "outside of walls or a roof: nothing in front of them to light): not modelled", l,
                  100.0 * (out[0] + out[1] + out[2]) / (out[0] + out[1] + out[2] + kept));
    }
    if (rsm->zoom > 1)
        note_budget(ctx, st, "light %u: its RSM covers the 1/%u of the scene's extent that the rest of its "
                    "light falls on, at %u x the texel density", l, rsm->zoom, rsm->zoom * rsm->zoom);
    if (!(rsm->total_flux[0] + rsm->total_flux[1] + rsm->total_flux[2] > 0.0)) {
        note_skip(ctx, st, "light %u: lights no geometry (its RSM is empty)", l);
        ++st->lights_skipped;
        vsgl__rsm_free(rsm);
        return VSGL_OK;
    }
    *lit = 1;
    return VSGL_OK;
}


/* The per-light budget (budget.h): each powered light's reflected power and
 * footprint on a probe RSM, then the shares, and each light's RSM side from
 * its footprint. Without the auto budget, 0 lights or 1 powered light:
 * `shares` is left NULL and every light takes the settings as they are;
 * with it, a single light too gets its RSM side from its footprint. */
static vsgl_result light_budget(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                                vsgl_light_share **shares_out, vsgl_render_stats *st)
{
    uint32_t light_count = 0;
    const vsgl_light *lights = vsgl__scene_lights(scene, &light_count);
    *shares_out = NULL;
    if (s->fit_mode == VSGL_FIT_TWO) /* two VSGLs per light whatever the budget */
        return VSGL_OK;
    const int automatic = s->auto_target != VSGL_AUTO_OFF;
    uint32_t powered = 0;
    for (uint32_t l = 0; l < light_count; ++l)
        powered += lights[l].power * (lights[l].color[0] + lights[l].color[1] + lights[l].color[2]) > 0.0f;
    if (powered < (automatic ? 1u : 2u))
        return VSGL_OK;
    vsgl_light_share *sh = calloc(light_count, sizeof *sh);
    if (!sh)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "render: out of memory for the light budget");
    double t0 = now_seconds();
    uint32_t receivers = 0;
    vsgl__progress_window(ctx, 0.1f, 0.0f);
    vsgl_result r = vsgl__budget_weights(ctx, scene, s, sh, &receivers);
    if (r != VSGL_OK) {
        free(sh);
        return r;
    }
    vsgl__light_budget(sh, light_count, s->vsgl_count, s->rsm_resolution);
    /* the auto budget: each RSM side from the footprint at the measured
     * texels per VSGL, never above the settings' side (vsgl__light_budget
     * already split the settings' texels by footprint) */
    const double density = automatic ? VSGL__AUTO_TEXELS_PER_VSGL
                                     : (double)s->rsm_resolution * s->rsm_resolution / (double)s->vsgl_count;
    if (automatic)
        vsgl__footprint_rsm(sh, light_count, density, s->rsm_resolution, s->rsm_resolution);
    double t_probe = now_seconds() - t0;
    st->seconds_rsm += t_probe;
    uint32_t contributing = 0;
    for (uint32_t l = 0; l < light_count; ++l)
        contributing += sh[l].fraction > 0.0;
    if (contributing < (automatic ? 1u : 2u)) { /* one light reflects anything: the settings as they are */
        free(sh);
        return VSGL_OK;
    }
    double texels = 0.0, uniform = 0.0;
    for (uint32_t l = 0; l < light_count; ++l) {
        if (!(lights[l].power * (lights[l].color[0] + lights[l].color[1] + lights[l].color[2]) > 0.0f))
            continue;
        texels += (double)sh[l].faces * sh[l].rsm_resolution * sh[l].rsm_resolution;
        uniform += (double)sh[l].faces * s->rsm_resolution * s->rsm_resolution;
        if (sh[l].fraction > 0.0)
            note_budget(ctx, st, "light %u: %.0f %% of the light on what the camera sees: %u VSGLs, RSM %u "
                        "(uniform %u, %u; footprint %.0f %%)", l,
                        100.0 * sh[l].fraction, sh[l].vsgl_count, sh[l].rsm_resolution, s->vsgl_count,
                        s->rsm_resolution, 100.0 * sh[l].footprint);
        else
            note_budget(ctx, st, "light %u: sends nothing the camera sees on a %u^2 probe: floor %u VSGLs, RSM %u",
                        l, s->rsm_resolution < VSGL__BUDGET_PROBE ? s->rsm_resolution : VSGL__BUDGET_PROBE,
                        sh[l].vsgl_count, sh[l].rsm_resolution);
    }
    if (automatic)
        note_budget(ctx, st, "RSM sides by footprint (%.0f texels per VSGL on it): %.0f %% of the uniform %u^2 "
                    "texels", density, 100.0 * texels / uniform, s->rsm_resolution);
    else
        note_budget(ctx, st, "RSM texels split by VSGLs / footprint: %.0f %% of the uniform %u^2", 
                    100.0 * texels / uniform, s->rsm_resolution);
    vsgl__log(ctx, VSGL_LOG_INFO, "budget: %u lights shared %u VSGLs and %u^2 RSM texels each by the light they "
              "send onto what the camera sees (%u probe receivers; probe %.4f s)", contributing, s->vsgl_count,
              s->rsm_resolution, receivers, t_probe);
    *shares_out = sh;
    return VSGL_OK;
}

/* Specular VSGLs whose peak intensity is below this fraction of their
 * light's mean VSGL's are dropped, and faded in up to twice it (a hard cut
 * popped lobes in and out as a light moved: second differences 0.034x the
 * first in test_fit_stability.py, 0.0085x with the fade): slivers of
 * lattice tents and grazing texels of glossy emitters. The peak, not the power: a sharp lobe of
 * little power still lights a spot (a power rule dropped the fill light's
 * sharp metal-floor lobes in spot_fill_metal_floor: relMSE 0.0070 ->
 * 0.0073). Peak intensity relative to a diffuse lobe's: power x max(1,
 * sharpness / 2) (an SG's peak is power x sharpness / (2 pi) for sharp
 * lobes, ~power / (4 pi) x 2.3 for the diffuse lobe). */
#define VSGL__SPECULAR_NEGLIGIBLE 0.01

static double peak_weight(const vsgl_vsgl *v)
{
    double p = (double)v->power[0] + v->power[1] + v->power[2];
    double k = 0.5 * (double)v->sharpness;
    return p * (k > 1.0 ? k : 1.0);
}

/* Drops the negligible specular VSGLs of items [first, count) (one light's),
 * keeping the order; returns how many, their power in *dropped_power and
 * the light's in *light_power (RGB sums). */
static size_t drop_negligible_specular(vsgl_vsgl_set *set, size_t first, double *dropped_power, double *light_power)
{
    double total = 0.0, peaks = 0.0;
    size_t n = set->count - first;
    for (size_t k = first; k < set->count; ++k) {
        const float *p = set->items[k].power;
        total += (double)p[0] + p[1] + p[2];
        peaks += peak_weight(&set->items[k]);
    }
    *light_power = total;
    *dropped_power = 0.0;
    if (!(total > 0.0) || !(peaks > 0.0 && peaks < INFINITY) || n == 0)
        return 0;
    double limit = VSGL__SPECULAR_NEGLIGIBLE * peaks / (double)n;
    size_t out = first;
    for (size_t k = first; k < set->count; ++k) {
        const vsgl_vsgl *v = &set->items[k];
        /* faded in from the limit to twice it: a lobe near the limit does
         * not pop in and out as a light moves */
        double pk = v->lobe == VSGL__LOBE_SPECULAR ? peak_weight(v) : INFINITY;
        float w = pk >= 2.0 * limit ? 1.0f : pk > limit ? smoothstep01f((float)(pk / limit - 1.0)) : 0.0f;
        for (int c = 0; c < 3; ++c)
            *dropped_power += (double)v->power[c] * (1.0 - w);
        if (!(w > 0.0f))
            continue;
        set->items[out] = *v;
        for (int c = 0; w < 1.0f && c < 3; ++c)
            set->items[out].power[c] *= w;
        ++out;
    }
    size_t dropped = set->count - out;
    set->count = out;
    return dropped;
}

vsgl_result vsgl__fit_lights(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                             vsgl_vsgl_set *set, vsgl_render_stats *st)
{
    return vsgl__fit_lights_mrp(ctx, scene, s, set, st, NULL, NULL);
}

vsgl_result vsgl__fit_lights_mrp(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                                 vsgl_vsgl_set *set, vsgl_render_stats *st, vsgl__mrp_proxy_set *mrp, int *mrp_lit)
{
    if (mrp_lit)
        *mrp_lit = mrp != NULL;
    uint32_t light_count = 0;
    (void)vsgl__scene_lights(scene, &light_count);
    vsgl_light_share *shares = NULL;
    vsgl_result r = light_budget(ctx, scene, s, &shares, st);
    if (r != VSGL_OK)
        return r;
    for (uint32_t l = 0; l < light_count; ++l) {
        vsgl_render_settings ls = *s; /* this light's budget */
        if (shares) {
            ls.vsgl_count = shares[l].vsgl_count;
            ls.rsm_resolution = shares[l].rsm_resolution;
        }
        vsgl_rsm rsm;
        int lit;
        /* the papers' model (leak correction off) lets the outside's clusters leak in: kept */
        r = light_rsm(ctx, scene, l, ls.rsm_resolution, ls.leak_correction != VSGL_LEAK_OFF,
                      0.1f + 0.3f * (float)l / (float)light_count,
                      0.3f / (float)light_count, &rsm, &lit, st);
        if (r != VSGL_OK)
            break;
        if (!lit)
            continue;
        if (mrp && mrp_lit && *mrp_lit) { /* the MRP pass's proxies take this RSM's light (before the fit) */
            if (ls.rsm_resolution == s->rsm_resolution)
                vsgl__mrp_proxies_add_rsm(mrp, scene, &rsm);
            else
                *mrp_lit = 0; /* the auto budget's own RSM size: the MRP pass builds its own */
        }
        double t0 = now_seconds();
        size_t before = set->count;
        switch (s->fit_mode) {
        case VSGL_FIT_FIS: r = vsgl__fit_fis(ctx, scene, &rsm, &ls, set); break;
        case VSGL_FIT_KMEANS: r = vsgl__fit_kmeans(ctx, scene, &rsm, &ls, set); break;
        case VSGL_FIT_LATTICE:
            r = shares ? vsgl__fit_lattice_n(ctx, scene, &rsm, &ls, shares[l].vsgls, set)
                       : vsgl__fit_lattice(ctx, scene, &rsm, &ls, set);
            break;
        default: r = vsgl__fit_two(ctx, scene, &rsm, &ls, set); break;
        }
        st->seconds_fit += now_seconds() - t0;
        vsgl__rsm_free(&rsm);
        if (r != VSGL_OK)
            break;
        size_t spec = 0, fitted = set->count - before;
        for (size_t k = before; k < set->count; ++k)
            spec += set->items[k].lobe == VSGL__LOBE_SPECULAR;
        if (spec == 0)
            note_skip(ctx, st, "light %u: no glossy surface it lights: specular VSGLs skipped", l);
        double dropped_power = 0.0, light_power = 0.0;
        size_t dropped = spec ? drop_negligible_specular(set, before, &dropped_power, &light_power) : 0;
        if (dropped)
            note_skip(ctx, st, "light %u: %zu of its %zu specular VSGLs under %g %% of its mean VSGL peak intensity "
                      "(%.2g %% of its light, with the fade of those under twice that): "
                      "%.1f %% of its VSGLs and shading pairs saved", l, dropped, spec,
                      100.0 * VSGL__SPECULAR_NEGLIGIBLE, 100.0 * dropped_power / light_power,
                      100.0 * (double)dropped / (double)fitted);
        if (set->count == before) {
            note_skip(ctx, st, "light %u: lit surfaces reflect nothing (black materials)", l);
            ++st->lights_skipped;
        } else {
            ++st->lights_used;
        }
        if (vsgl__progress(ctx, "fit", 1.0f)) {
            r = vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "fit: cancelled");
            break;
        }
    }
    free(shares);
    return r;
}


/* The brute-force method: every RSM texel of every light as a VPL with the
 * exact BRDF (the internal ground truth). All RSMs are kept at once. */
static vsgl_result brute_force(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                               const vsgl_gbuffer *g, const vsgl_pixel_planes *planes, vsgl_render_stats *st)
{
    uint32_t light_count = 0;
    (void)vsgl__scene_lights(scene, &light_count);
    vsgl_rsm *rsms = calloc(light_count + 1, sizeof *rsms);
    float *sample = calloc(g->count * 12 + 1, sizeof(float));
    uint32_t used = 0;
    vsgl_result r = VSGL_OK;
    if (!rsms || !sample) {
        r = vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "render: out of memory for %zu samples", g->count);
        goto done;
    }
    for (uint32_t l = 0; l < light_count && r == VSGL_OK; ++l) {
        int lit;
        r = light_rsm(ctx, scene, l, s->rsm_resolution, 1, 0.1f + 0.2f * (float)l / (float)light_count,
                      0.2f / (float)light_count, &rsms[used], &lit, st);
        if (r == VSGL_OK && lit) {
            ++used;
            ++st->lights_used;
        }
    }
    if (r == VSGL_OK) {
        double t0 = now_seconds();
        vsgl__progress_window(ctx, 0.3f, 0.7f);
        float *dl = sample, *gl = sample + 3 * g->count, *dc = sample + 6 * g->count, *gc = sample + 9 * g->count;
        r = vsgl__brute_force_shade(ctx, scene, g, rsms, used, s->visibility == VSGL_VISIBILITY_RAY, dl, gl, dc, gc);
        st->seconds_shade = now_seconds() - t0;
        if (r == VSGL_OK) {
            size_t pixels = (size_t)g->width * g->height;
            /* light planes first into the contribution slots, then colour them */
            vsgl__brute_force_resolve(g, dl, dc, planes->diffuse, planes->diffuse_color);
            vsgl__brute_force_resolve(g, gl, gc, planes->glossy, planes->glossy_color);
            for (size_t i = 0; i < pixels * 3; ++i) {
                planes->diffuse[i] *= planes->diffuse_color[i];
                planes->glossy[i] *= planes->glossy_color[i];
            }
            for (size_t p = 0; p < pixels; ++p) {
                float hits = 0.0f;
                for (size_t k = 0; k < g->spp; ++k)
                    if (g->material[p * g->spp + k] != VSGL__GBUFFER_MISS)
                        hits += vsgl__gbuffer_weight(g, p * g->spp + k);
                planes->coverage[p] = hits;
            }
            for (uint32_t k = 0; k < used; ++k)
                st->shading_pairs += (uint64_t)g->count * rsms[k].count;
        }
    }
done:
    if (rsms)
        for (uint32_t k = 0; k < used; ++k)
            vsgl__rsm_free(&rsms[k]);
    free(rsms);
    free(sample);
    return r;
}

/* light = contribution / colour, 0 where the colour is 0 (as Cycles). */
static float divide_or_zero(float num, float den)
{
    return den > 1e-8f ? num / den : 0.0f;
}

/* write_outputs in parallel: rows of pixels [b, e) checked (pass 0) or written (pass 1). */
typedef struct output_job {
    const vsgl_pixel_planes *p;
    const vsgl_render_output *out;
    int pass;
} output_job;

static int bad_value(const vsgl_pixel_planes *p, size_t i)
{
    return !isfinite(p->diffuse[i]) || !isfinite(p->glossy[i]) || !isfinite(p->diffuse_color[i]) ||
           !isfinite(p->glossy_color[i]) || p->diffuse[i] < 0.0f || p->glossy[i] < 0.0f;
}

static int32_t output_chunk(void *user, size_t chunk, size_t b, size_t e)
{
    const output_job *oj = user;
    const vsgl_pixel_planes *p = oj->p;
    const vsgl_render_output *out = oj->out;
    (void)chunk;
    /* (loops over fixed blocks of 16 with a tail: -O2 vectorises a loop only
     * when its trip count is a multiple of the vector length) */
    const size_t i0 = b * 3, i1 = e * 3, blocks = i0 + (i1 - i0) / 16 * 16;
    if (oj->pass == 0) { /* bad_value as compares (NaN compares false) */
        const float *d = p->diffuse, *g = p->glossy, *dc = p->diffuse_color, *gc = p->glossy_color;
        int ok = 1;
        for (size_t i = i0; i < i1; i += 16) {
            const size_t n = i < blocks ? 16 : i1 - i;
            int okb = 1;
            if (n == 16) {
                for (size_t k = i; k < i + 16; ++k)
                    okb &= (d[k] >= 0.0f) & (d[k] <= FLT_MAX) & (g[k] >= 0.0f) & (g[k] <= FLT_MAX) &
                           (fabsf(dc[k]) <= FLT_MAX) & (fabsf(gc[k]) <= FLT_MAX);
            } else {
                for (size_t k = i; k < i + n; ++k)
                    okb &= !bad_value(p, k);
            }
            ok &= okb;
        }
        return ok ? 0 : VSGL_ERROR_INTERNAL;
    }
    /* plane by plane, only those asked for (the live viewport asks for one) */
    if (out->diffuse_light)
        for (size_t i = b * 3; i < e * 3; ++i)
            out->diffuse_light[i] = divide_or_zero(p->diffuse[i], p->diffuse_color[i]);
    if (out->glossy_light)
        for (size_t i = b * 3; i < e * 3; ++i)
            out->glossy_light[i] = divide_or_zero(p->glossy[i], p->glossy_color[i]);
    if (out->diffuse_color)
        memcpy(out->diffuse_color + b * 3, p->diffuse_color + b * 3, (e - b) * 3 * sizeof(float));
    if (out->glossy_color)
        memcpy(out->glossy_color + b * 3, p->glossy_color + b * 3, (e - b) * 3 * sizeof(float));
    if (out->diffuse)
        memcpy(out->diffuse + b * 3, p->diffuse + b * 3, (e - b) * 3 * sizeof(float));
    if (out->glossy)
        memcpy(out->glossy + b * 3, p->glossy + b * 3, (e - b) * 3 * sizeof(float));
    if (out->combined) {
        float *c = out->combined;
        const float *d = p->diffuse, *g = p->glossy;
        size_t i = i0;
        for (; i < blocks; i += 16) {
            float x[16], y[16];
            memcpy(x, d + i, sizeof x);
            memcpy(y, g + i, sizeof y);
            for (int k = 0; k < 16; ++k)
                x[k] += y[k];
            memcpy(c + i, x, sizeof x);
        }
        for (; i < i1; ++i)
            c[i] = d[i] + g[i];
    }
    if (out->alpha)
        memcpy(out->alpha + b, p->coverage + b, (e - b) * sizeof(float));
    return 0;
}

static vsgl_result write_outputs(vsgl_context *ctx, const vsgl_pixel_planes *p, size_t pixels,
                                 const vsgl_render_output *out)
{
    /* Refuse to hand out a non-finite value: that would be a bug. Every
     * value is checked before any output is written. */
    const size_t chunk = 16384; /* pixels */
    output_job oj = {p, out, 0};
    if (vsgl__parallel_ctx(ctx, pixels, chunk, output_chunk, &oj) != 0) {
        for (size_t i = 0; i < pixels * 3; ++i)
            if (bad_value(p, i))
                return vsgl__fail(ctx, VSGL_ERROR_INTERNAL,
                                  "render: pixel %zu channel %zu is not finite and non-negative "
                                  "(diffuse %g, glossy %g): please report this scene",
                                  i / 3, i % 3, (double)p->diffuse[i], (double)p->glossy[i]);
    }
    oj.pass = 1;
    (void)vsgl__parallel_ctx(ctx, pixels, chunk, output_chunk, &oj);
    return VSGL_OK;
}

static vsgl_result check_output(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_output *out)
{
    const vsgl_camera *cam = vsgl__scene_camera(scene);
    if (out->width != cam->width || out->height != cam->height)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT,
                          "output: planes are %ux%u but the camera renders %ux%u",
                          out->width, out->height, cam->width, cam->height);
    if (!out->diffuse_light && !out->glossy_light && !out->diffuse_color && !out->glossy_color &&
        !out->diffuse && !out->glossy && !out->combined && !out->alpha)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "output: no plane requested (all pointers are NULL)");
    return VSGL_OK;
}

vsgl_result vsgl_render(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *settings,
                        vsgl_render_output *out, vsgl_render_stats *stats)
{
    return vsgl_render_cached(ctx, scene, settings, NULL, out, stats);
}

vsgl_result vsgl_render_cached(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *settings,
                               vsgl_render_cache *cache, vsgl_render_output *caller_out, vsgl_render_stats *stats)
{
    double t_start = now_seconds();
    vsgl__clear_error(ctx);
    if (!ctx || !scene || !caller_out)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "render: %s is NULL",
                          !ctx ? "context" : (!scene ? "scene" : "output"));
    vsgl_render_output o; /* the caller's, an older one's missing planes NULL */
    const vsgl_render_output *out = &o;
    vsgl_render_settings s;
    size_t stats_bytes = 0;
    vsgl_result r = vsgl__copy_versioned(ctx, &o, sizeof o, caller_out, "vsgl_render_output");
    if (r == VSGL_OK && stats)
        r = vsgl__versioned_size(ctx, stats, sizeof *stats, &stats_bytes, "vsgl_render_stats");
    vsgl__image_rules rules = {0}; /* what the image-size rules changed (said at the end) */
    if (r == VSGL_OK)
        r = vsgl__settings_resolve_for(ctx, settings, scene, &s, &rules);
    if (r == VSGL_OK)
        r = check_output(ctx, scene, out);
    if (r == VSGL_OK) { /* refuse what cannot fit before allocating (render/memory.c) */
        const float *const rgb[7] = {out->diffuse_light, out->glossy_light, out->diffuse_color, out->glossy_color,
                                     out->diffuse, out->glossy, out->combined};
        uint64_t floats = out->alpha ? 1u : 0u;
        for (int i = 0; i < 7; ++i)
            floats += rgb[i] ? 3u : 0u;
        vsgl_memory_estimate est;
        r = vsgl__memory_estimate(ctx, scene, &s, (uint64_t)out->width * out->height * floats * sizeof(float), &est);
    }
    if (r != VSGL_OK)
        return r;
    /* before the wait, not after it */
    if (vsgl__shades_by_reference(&s))
        vsgl__log(ctx, VSGL_LOG_WARNING, "render: glossy sg shades through the scalar reference path (a check of "
                  "the vectorised kernel, which models ASG lobes): every pixel%s, every pair in scalar code%s; "
                  "balanced with it took 45-85x balanced's time on the bundled rooms at 960 x 540 "
                  "(docs/performance.md). For renders use asg2 or asg",
                  rules.stride_ignored ? " (shade_stride ignored)" : "",
                  s.visibility == VSGL_VISIBILITY_RAY ? " with a visibility ray of its own" : "");

    vsgl_render_stats st;
    memset(&st, 0, sizeof st);
    /* the auto budget: anti-aliasing and the glossy model for this scene (budget_auto.c) */
    if (s.auto_target != VSGL_AUTO_OFF && (r = vsgl__auto_choose(ctx, scene, rules.aa_asked, &s, &st)) != VSGL_OK)
        return r;
    /* a convex shell (an empty closed room): visibility rays cannot find anything */
    int rays_skipped = 0;
    vsgl_shade_counts counts = {0, 0, 0}; /* the shade stage's faint pairs (VSGL__FAINT) and dominant rays */
    if (s.method == VSGL_METHOD_VSGL && s.visibility == VSGL_VISIBILITY_RAY && vsgl__scene_convex_shell(scene)) {
        s.visibility = VSGL_VISIBILITY_NONE;
        rays_skipped = 1;
    }
    vsgl_gbuffer g;
    memset(&g, 0, sizeof g);
    vsgl_vsgl_set set;
    memset(&set, 0, sizeof set);
    size_t pixels = (size_t)out->width * out->height;
    float *buf = NULL;
    int own_buf = 1;

    double t0 = now_seconds();
    st.seconds_scene_prep = t0 - t_start;
    /* overall progress: G-buffer 0-10 %, RSMs and fits 10-40 % (brute force 10-30 %), shading the rest */
    vsgl__progress_window(ctx, 0.0f, 0.1f);
    const vsgl_gbuffer *gb = &g; /* the cache's, or this render's own */
    int built_g = 0, built_set = 0;
    vsgl__mrp_proxy_set mrp_set; /* MRP, hybrid: the proxies, lit by the fit's RSMs when mrp_lit */
    memset(&mrp_set, 0, sizeof mrp_set);
    int has_mrp_set = 0, mrp_lit = 0;
    vsgl_shade_plan *plan = NULL; /* the shading plan recorded for a G-buffer this render builds */
    if (vsgl__cache_gbuffer_hit(cache, scene, s.aa_samples, s.edge_samples)) {
        gb = &cache->g;
        st.reused |= VSGL_REUSED_GBUFFER;
    } else {
        r = vsgl__gbuffer_build(ctx, scene, s.aa_samples, s.edge_samples, &g);
        built_g = 1;
    }
    st.seconds_gbuffer = now_seconds() - t0;
    if (r != VSGL_OK)
        goto done;
    /* through a cache, the VSGL method's planes are the cache's: every shading
     * path writes every pixel of all five, so they need no zeroing */
    if (cache && s.method == VSGL_METHOD_VSGL && (buf = vsgl__cache_planes(cache, pixels * 13)) != NULL)
        own_buf = 0;
    else
        buf = calloc(pixels * 13, sizeof(float));
    if (!buf) {
        r = vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "render: out of memory for %zu pixels", pixels);
        goto done;
    }
    vsgl_pixel_planes planes = {buf, buf + 3 * pixels, buf + 6 * pixels, buf + 9 * pixels, buf + 12 * pixels};
    if (s.method == VSGL_METHOD_BRUTE_FORCE) {
        r = brute_force(ctx, scene, &s, gb, &planes, &st);
    } else {
        const vsgl_vsgl_set *vs = &set;
        if (vsgl__cache_fit_hit(cache, scene, &s)) {
            vs = &cache->set;
            st.reused |= VSGL_REUSED_FIT;
            st.lights_used = cache->f_lights_used;
            st.lights_skipped = cache->f_lights_skipped;
            memcpy(st.skipped, cache->f_skipped, sizeof st.skipped);
            memcpy(st.budget, cache->f_budget, sizeof st.budget);
        } else {
            /* MRP and the hybrid: the proxies take each light's RSM as the fit builds it (their
             * pass would build every RSM again) */
            if (s.glossy_mode == VSGL_GLOSSY_MRP || s.glossy_mode == VSGL_GLOSSY_HYBRID) {
                double area = s.glossy_mode == VSGL_GLOSSY_MRP ? (double)s.mrp_min_area
                              : s.mrp_min_area > 0.0f           ? (double)s.mrp_min_area
                                                                : VSGL__MRP_MIN_AREA;
                r = vsgl__mrp_proxies_build(ctx, scene, area, VSGL__MRP_CELLS, &mrp_set);
                has_mrp_set = r == VSGL_OK;
            }
            if (r == VSGL_OK)
                r = vsgl__fit_lights_mrp(ctx, scene, &s, &set, &st, has_mrp_set ? &mrp_set : NULL, &mrp_lit);
            built_set = 1;
        }
        st.vsgl_count = (uint32_t)vs->count;
        if (r == VSGL_OK) {
            t0 = now_seconds();
            vsgl__progress_window(ctx, 0.4f, 0.6f);
            /* through a cache: a light edit replays the shading plan of the G-buffer */
            r = vsgl__shade_planned(ctx, scene, gb, vs, &s, &planes, VSGL__SHADE_KERNEL, &st.shading_pairs,
                                    &counts, !cache ? NULL : built_g ? &plan : &cache->plan);
            if (r == VSGL_OK && s.glossy_mode == VSGL_GLOSSY_MRP) /* the glossy plane from rectangle proxies */
                r = vsgl__mrp_glossy_pass(ctx, scene, s.rsm_resolution, s.mrp_min_area, VSGL__MRP_CELLS, gb,
                                          &planes, NULL, mrp_lit ? &mrp_set : NULL);
            else if (r == VSGL_OK && s.glossy_mode == VSGL_GLOSSY_HYBRID) /* MRP per pixel where it applies */
                r = vsgl__mrp_hybrid_pass(ctx, scene, &s, gb, vs, &planes, NULL, mrp_lit ? &mrp_set : NULL);
            st.seconds_shade = now_seconds() - t0;
        }
    }
    if (r == VSGL_OK)
        r = write_outputs(ctx, &planes, pixels, out);
    if (r == VSGL_OK && st.lights_used == 0) {
        uint32_t light_count = 0;
        (void)vsgl__scene_lights(scene, &light_count);
        if (light_count == 0)
            vsgl__log(ctx, VSGL_LOG_WARNING, "render: the scene has no lights: the indirect light is black");
        else
            vsgl__log(ctx, VSGL_LOG_WARNING, "render: none of the %u lights lights anything (all skipped): "
                      "the indirect light is black", light_count);
    }
done:
    if (has_mrp_set)
        vsgl__mrp_proxies_free(&mrp_set);
    vsgl__progress_window(ctx, 0.0f, 1.0f);
    if (own_buf)
        free(buf);
    if (cache && r != VSGL_OK) {
        vsgl__cache_clear(cache);
    } else if (cache) {
        if (built_g) {
            vsgl__cache_keep_gbuffer(cache, scene, s.aa_samples, s.edge_samples, &g, plan);
            plan = NULL;
        }
        if (built_set)
            vsgl__cache_keep_fit(cache, scene, &s, &set, &st);
    }
    if (r == VSGL_OK && counts.faint)
        note_skip(ctx, &st, "faint pairs: %llu of %llu (%.1f %%) shaded nothing: a specular VSGL whose radiant "
                  "intensity towards every receiver of a block of %d is below %g of its peak skips its diffuse and "
                  "glossy stages there", (unsigned long long)counts.faint, (unsigned long long)st.shading_pairs,
                  100.0 * (double)counts.faint / (double)(st.shading_pairs ? st.shading_pairs : 1),
                  VSGL__KERNEL_BLOCK, (double)VSGL__FAINT);
    if (r == VSGL_OK && counts.dominant_pairs)
        note_budget(ctx, &st, "visibility: %llu of %llu pairs (%.2f %%) carry %g %% or more of their receiver's "
                    "light near a shadow's edge and traced %u rays, not one (dominant_rays): %llu rays more",
                    (unsigned long long)counts.dominant_pairs, (unsigned long long)st.shading_pairs,
                    100.0 * (double)counts.dominant_pairs / (double)(st.shading_pairs ? st.shading_pairs : 1),
                    100.0 * (double)VSGL_DOMINANT_SHARE, s.dominant_rays, (unsigned long long)counts.dominant_rays);
    if (r == VSGL_OK && rays_skipped) /* after the cache kept the fit's notes: said on every render */
        note_skip(ctx, &st, "visibility rays: every surface lies on the scene's convex hull (an empty closed "
                  "room), so nothing can block light between two surfaces: %llu rays saved",
                  (unsigned long long)st.shading_pairs);
    if (r == VSGL_OK && rules.aa_asked)
        note_skip(ctx, &st, "anti-aliasing: 1 sample per pixel, not %u x %u: %u x %u is at least aa_pixel_limit "
                  "(%u pixels)%s", rules.aa_asked, rules.aa_asked, out->width, out->height, s.aa_pixel_limit,
                  s.edge_samples > 1 ? "; edge pixels keep their edge rays" : "");
    if (r == VSGL_OK && rules.stride_asked)
        note_skip(ctx, &st, "shading: one pixel in %u x %u shaded, not %u x %u: %u x %u is %.1fx stride_pixels "
                  "(%u pixels), so the stride grows with the image's side; the others interpolated where the "
                  "light is smooth", s.shade_stride, s.shade_stride, rules.stride_asked, rules.stride_asked,
                  out->width, out->height, (double)out->width * out->height / s.stride_pixels, s.stride_pixels);
    vsgl__shade_plan_free(plan);
    vsgl__vsgl_set_free(&set);
    vsgl__gbuffer_free(&g);
    st.seconds_total = now_seconds() - t_start;
    if (stats) /* its size was checked up front */
        (void)vsgl__return_versioned(ctx, stats, &st, sizeof st, "vsgl_render_stats");
    return r;
}
