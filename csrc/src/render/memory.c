/* Memory of a render, estimated before anything is allocated, and the
 * limit it is checked against (issue 10: a 16384^2 render grew to 23 GB
 * and was killed by the kernel without a message).
 *
 * The byte counts follow the allocations of each stage (gbuffer.c, rsm.c,
 * fit/grid.c, fit/kmeans.c, fit/fis.c, shade.c, brute_force.c, render.c);
 * tests/cli/run_cli.sh compares the estimate with the peak RSS of real
 * renders. */
#include "render/render_internal.h"
#include "render/budget.h"
#include "shade/kernel.h"
#include "fit/grid.h"
#include "gbuffer/gbuffer.h"
#include "fit/vsgl_set.h"
#include "rsm/rsm_light.h"
#include "core/context.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#define GBUFFER_BYTES_PER_SAMPLE (12u * 4u + 8u)    /* pos, nrm, view, tan; material, part */
#define PLANE_BYTES_PER_PIXEL (13u * 4u)             /* render.c's accumulation planes */
#define RSM_BYTES_PER_TEXEL (15u * 4u + 8u + 4u)     /* pos, nrm, tan, wi, flux; material, part; area */
#define SHADE_BYTES_PER_SAMPLE (8u + 4u + 24u + 16u) /* shade.c's per-row scratch of a worker */
#define BRUTE_BYTES_PER_SAMPLE (12u * 4u)            /* brute_force's per-sample light/colour */
#define BRUTE_BYTES_PER_VPL 68u                      /* bf_vpl */

/* "name: value kB" from a /proc-style file, in bytes; 0 if absent. */
static uint64_t read_kb_field(const char *path, const char *name)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    char line[256];
    uint64_t v = 0;
    size_t n = strlen(name);
    while (fgets(line, sizeof line, f))
        if (strncmp(line, name, n) == 0 && line[n] == ':') {
            v = strtoull(line + n + 1, NULL, 10) * 1024u;
            break;
        }
    fclose(f);
    return v;
}

/* One number from a file ("max" or absent = 0). */
static uint64_t read_number(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    char buf[64] = {0};
    uint64_t v = 0;
    if (fgets(buf, sizeof buf, f) && buf[0] >= '0' && buf[0] <= '9')
        v = strtoull(buf, NULL, 10);
    fclose(f);
    return v;
}

/* What this process can still allocate: MemAvailable, capped by the cgroup
 * v2 limit and RLIMIT_AS (less what is already used under each). */
static uint64_t machine_available(void)
{
    uint64_t avail = read_kb_field("/proc/meminfo", "MemAvailable");
    if (!avail) {
        long pages = sysconf(_SC_AVPHYS_PAGES), size = sysconf(_SC_PAGESIZE);
        avail = pages > 0 && size > 0 ? (uint64_t)pages * (uint64_t)size : UINT64_MAX;
    }
    uint64_t cg_max = read_number("/sys/fs/cgroup/memory.max");
    if (cg_max) {
        uint64_t used = read_number("/sys/fs/cgroup/memory.current");
        uint64_t left = cg_max > used ? cg_max - used : 0;
        if (left < avail)
            avail = left;
    }
    struct rlimit rl;
    if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
        uint64_t used = read_kb_field("/proc/self/status", "VmSize");
        uint64_t left = (uint64_t)rl.rlim_cur > used ? (uint64_t)rl.rlim_cur - used : 0;
        if (left < avail)
            avail = left;
    }
    return avail;
}

static void format_bytes(uint64_t b, char *buf, size_t n)
{
    if (b >= (1ull << 30))
        snprintf(buf, n, "%.1f GiB", (double)b / (double)(1ull << 30));
    else
        snprintf(buf, n, "%.1f MiB", (double)b / (double)(1ull << 20));
}

/* a * b, saturating (sizes of 65535^2 x 256 samples overflow nothing in
 * 64 bits, but a caller's settings should never wrap the estimate) */
static uint64_t mul(uint64_t a, uint64_t b)
{
    return (b && a > UINT64_MAX / b) ? UINT64_MAX : a * b;
}

static uint64_t add(uint64_t a, uint64_t b)
{
    return a > UINT64_MAX - b ? UINT64_MAX : a + b;
}

vsgl_result vsgl__memory_estimate(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *s,
                                  uint64_t output_bytes, vsgl_memory_estimate *e)
{
    memset(e, 0, sizeof *e);
    const vsgl_camera *cam = vsgl__scene_camera(scene);
    uint64_t pixels = (uint64_t)cam->width * cam->height;
    /* edge refinement: a weight and a normal spread per sample, an edge mask per pixel, and
     * three slots per pixel at one sample per pixel */
    int refined = s->edge_samples > s->aa_samples;
    uint64_t spp = vsgl__gbuffer_slots(s->aa_samples, refined);
    uint64_t samples = mul(pixels, spp);
    uint64_t threads = vsgl_context_thread_count(ctx);
    e->output = output_bytes;
    /* + the lift on scenes with smooth-shaded meshes (gbuffer.h) */
    const uint32_t extra = (refined ? 8u : 0u) + (vsgl__scene_smooth(scene) ? 12u : 0u);
    e->gbuffer = add(mul(samples, GBUFFER_BYTES_PER_SAMPLE + extra), refined ? pixels : 0);
    e->planes = mul(pixels, PLANE_BYTES_PER_PIXEL);

    uint32_t light_count = 0;
    const vsgl_light *lights = vsgl__scene_lights(scene, &light_count);
    /* with two or more lights the budget may give one light more than the
     * settings (render/budget.h): count its caps */
    uint32_t powered = 0;
    for (uint32_t l = 0; l < light_count; ++l)
        powered += lights[l].power * (lights[l].color[0] + lights[l].color[1] + lights[l].color[2]) > 0.0f;
    int shared = powered >= 2 && s->fit_mode != VSGL_FIT_TWO && s->method != VSGL_METHOD_BRUTE_FORCE;
    uint64_t res = shared ? vsgl__budget_rsm_max(s->rsm_resolution) : s->rsm_resolution, side = 1;
    uint64_t per_light_vsgls = shared ? vsgl__budget_vsgl_max(s->vsgl_count) : s->vsgl_count;
    while (side < res)
        side *= 2;
    uint64_t lit = 0, rsm_max = 0, rsm_sum = 0, texels_sum = 0, fit_max = 0;
    for (uint32_t l = 0; l < light_count; ++l) {
        const vsgl_light *L = &lights[l];
        if (!(L->power * (L->color[0] + L->color[1] + L->color[2]) > 0.0f))
            continue; /* skipped by the render before its RSM is built */
        ++lit;
        vsgl_rsm_light rl;
        vsgl__rsm_light_setup(scene, l, s->rsm_resolution, &rl);
        uint64_t texels = (uint64_t)rl.faces * res * res;
        uint64_t rsm = add(mul(texels, RSM_BYTES_PER_TEXEL), res * 128u); /* + one row of ray scratch */
        rsm_max = rsm > rsm_max ? rsm : rsm_max;
        rsm_sum = add(rsm_sum, rsm);
        texels_sum = add(texels_sum, texels);
        uint64_t fit = 0;
        if (s->fit_mode != VSGL_FIT_TWO) {
            uint64_t cells = (uint64_t)rl.faces * side * side;
            uint64_t grid = mul(cells, VSGL__GRID_STRIDE * sizeof(float));
            if (s->fit_mode == VSGL_FIT_FIS) {
                fit = add(grid + grid / 3u, mul(cells + 1u, sizeof(double))); /* mips; importance CDF */
            } else if (s->fit_mode == VSGL_FIT_LATTICE) {
                /* fit/lattice.c: a hash map of lattice cells, each with its sums; a texel's
                 * tent weights reach 4 cells, and there are a few cells per cluster */
                uint64_t lattice_cells = mul(per_light_vsgls, 16u);
                if (lattice_cells > mul(texels, 4u))
                    lattice_cells = mul(texels, 4u);
                fit = add(grid, mul(lattice_cells, VSGL__GRID_STRIDE * sizeof(double) + 2u * 12u));
            } else {
                fit = add(grid, add(mul(texels, sizeof(uint32_t)), /* labels, centres, sums */
                                    mul(per_light_vsgls, 64u + VSGL__GRID_STRIDE * sizeof(double))));
            }
        }
        fit_max = fit > fit_max ? fit : fit_max;
    }
    uint64_t vsgls = mul(lit, (uint64_t)(s->fit_mode == VSGL_FIT_TWO ? 2u : 2u * s->vsgl_count));
    if (s->method == VSGL_METHOD_BRUTE_FORCE) {
        e->rsm = rsm_sum; /* every light's RSM is kept */
        e->shade = add(mul(samples, BRUTE_BYTES_PER_SAMPLE), mul(texels_sum, BRUTE_BYTES_PER_VPL));
    } else {
        e->rsm = rsm_max; /* one light at a time */
        e->fit = fit_max;
        e->shade = add(mul(mul(threads, (uint64_t)cam->width * spp), SHADE_BYTES_PER_SAMPLE),
                       add(mul(vsgls, sizeof(vsgl_vsgl) + sizeof(vsgl_kernel_light)), (uint64_t)cam->height * 8u));
    }
    e->total = add(add(add(e->output, e->gbuffer), add(e->planes, e->rsm)), add(e->fit, e->shade));
    e->limit = ctx->max_memory ? ctx->max_memory : machine_available();
    if (e->total <= e->limit)
        return VSGL_OK;
    char total[32], limit[32], out[32], gb[32], pl[32], rs[32], fi[32], sh[32];
    format_bytes(e->total, total, sizeof total);
    format_bytes(e->limit, limit, sizeof limit);
    format_bytes(e->output, out, sizeof out);
    format_bytes(e->gbuffer, gb, sizeof gb);
    format_bytes(e->planes, pl, sizeof pl);
    format_bytes(e->rsm, rs, sizeof rs);
    format_bytes(e->fit, fi, sizeof fi);
    format_bytes(e->shade, sh, sizeof sh);
    return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY,
                      "render: %ux%u with aa %u and RSM %u needs about %s (output planes %s, G-buffer %s, "
                      "planes %s, RSMs %s, fit %s, shading %s), more than the memory limit of %s (%s)",
                      cam->width, cam->height, s->aa_samples, s->rsm_resolution, total, out, gb, pl, rs, fi, sh,
                      limit, ctx->max_memory ? "max_memory" : "memory available on this machine");
}

vsgl_result vsgl_render_estimate(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_render_settings *settings,
                                 uint32_t output_floats_per_pixel, vsgl_memory_estimate *out)
{
    vsgl__clear_error(ctx);
    if (out)
        memset(out, 0, sizeof *out);
    if (!ctx || !scene)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "render estimate: %s is NULL", !ctx ? "context" : "scene");
    vsgl_render_settings s;
    vsgl__image_rules rules;
    vsgl_result r = vsgl__settings_resolve_for(ctx, settings, scene, &s, &rules);
    if (r != VSGL_OK)
        return r;
    const vsgl_camera *cam = vsgl__scene_camera(scene);
    vsgl_memory_estimate e;
    r = vsgl__memory_estimate(ctx, scene, &s,
                              mul((uint64_t)cam->width * cam->height, (uint64_t)output_floats_per_pixel * sizeof(float)), &e);
    if (out)
        *out = e;
    return r;
}
