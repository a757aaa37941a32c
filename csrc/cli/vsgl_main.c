/* build/vsgl: render a scene bundle into a multilayer EXR, or describe it.
 * Every failure prints exactly one line "vsgl: reason" on stderr. */
#include "options.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* Set by SIGINT/SIGTERM; the progress callback then cancels the render. */
static volatile sig_atomic_t interrupted;

static void on_signal(int sig)
{
    (void)sig;
    interrupted = 1;
}

static double now_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

typedef struct progress_state {
    int tty;            /* stderr is a terminal: one \r-updated line */
    int line_open;      /* a \r line is showing */
    char stage[32];
    int percent;
} progress_state;

static void progress_end(progress_state *p)
{
    if (p->line_open) {
        fputs("\r\033[K", stderr);
        p->line_open = 0;
    }
}

static int32_t on_progress(void *user, const char *stage, float fraction)
{
    progress_state *p = user;
    int pct = (int)lrintf(fminf(fmaxf(fraction, 0.0f), 1.0f) * 100.0f);
    int new_stage = strncmp(stage ? stage : "", p->stage, sizeof p->stage) != 0;
    if (p->tty) {
        if (new_stage || pct != p->percent) {
            fprintf(stderr, "\rvsgl: %-10s %3d%%", stage ? stage : "", pct);
            fflush(stderr);
            p->line_open = 1;
        }
    } else if (new_stage) {
        fprintf(stderr, "vsgl: %s (%d%%)\n", stage ? stage : "", pct);
    }
    snprintf(p->stage, sizeof p->stage, "%s", stage ? stage : "");
    p->percent = pct;
    return interrupted ? 1 : 0;
}

typedef struct log_state { progress_state *progress; } log_state;

static void on_log(void *user, int32_t level, const char *message)
{
    log_state *l = user;
    if (level == VSGL_LOG_ERROR)
        return; /* failures are reported once, by the caller, from the context */
    if (strncmp(message, "skipped: ", 9) == 0)
        return; /* reported once after the render, from vsgl_render_stats.skipped */
    progress_end(l->progress);
    fprintf(stderr, "vsgl: %s%s\n", level == VSGL_LOG_WARNING ? "warning: " : "", message);
}

/* The one failure line. */
static int fail(const vsgl_context *ctx, vsgl_result r, const char *what)
{
    const char *msg = ctx ? vsgl_context_last_error(ctx) : "";
    if (r == VSGL_ERROR_CANCELLED) {
        fprintf(stderr, "vsgl: cancelled\n");
        return 130;
    }
    if (msg && *msg)
        fprintf(stderr, "vsgl: %s\n", msg);
    else
        fprintf(stderr, "vsgl: %s: %s\n", what, vsgl_result_string(r));
    return 1;
}

static const char *light_type_name(int32_t t)
{
    switch (t) {
    case VSGL_LIGHT_POINT: return "point";
    case VSGL_LIGHT_SPOT: return "spot";
    case VSGL_LIGHT_SUN: return "sun";
    case VSGL_LIGHT_AREA: return "area";
    default: return "unknown";
    }
}

static int cmd_info(vsgl_context *ctx, const cli_options *o)
{
    vsgl_bundle *b = NULL;
    vsgl_result r = vsgl_bundle_read(ctx, o->scene_path, &b);
    if (r)
        return fail(ctx, r, o->scene_path);
    const vsgl_scene_desc *d = vsgl_bundle_scene(b);
    vsgl_bundle_info bi = {.size = sizeof bi};
    vsgl_bundle_get_info(b, &bi);
    printf("bundle: %s (format %u.%u)\n", o->scene_path, bi.version_major, bi.version_minor);
    printf("vertices: %u\ntriangles: %u\nmaterials: %u\nlights: %u\n", d->vertex_count, d->triangle_count,
           d->material_count, d->light_count);
    printf("corner normals: %s, uvs: %s, tangents: %s, material indices: %s\n", d->corner_normals ? "yes" : "no",
           d->corner_uvs ? "yes" : "no", d->corner_tangents ? "yes" : "no", d->material_indices ? "yes" : "no");
    if (d->vertex_count) {
        float lo[3], hi[3];
        for (int k = 0; k < 3; ++k)
            lo[k] = hi[k] = d->positions[k];
        for (uint32_t v = 1; v < d->vertex_count; ++v)
            for (int k = 0; k < 3; ++k) {
                float x = d->positions[3 * v + k];
                lo[k] = x < lo[k] ? x : lo[k];
                hi[k] = x > hi[k] ? x : hi[k];
            }
        printf("bounds: (%g, %g, %g) .. (%g, %g, %g) m\n", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    } else {
        printf("bounds: empty\n");
    }
    const vsgl_camera *c = d->camera;
    printf("camera: %s %ux%u, lens %g mm, sensor %g x %g mm, at (%g, %g, %g)\n",
           c->type == VSGL_CAMERA_ORTHOGRAPHIC ? "orthographic" : "perspective", c->width, c->height, c->lens_mm,
           c->sensor_width_mm, c->sensor_height_mm, c->world_from_camera[3], c->world_from_camera[7],
           c->world_from_camera[11]);
    for (uint32_t i = 0; i < d->light_count; ++i) {
        const vsgl_light *l = &d->lights[i];
        printf("light %u: %s, power %g %s, colour (%g, %g, %g), at (%g, %g, %g)\n", i, light_type_name(l->type), l->power,
               l->type == VSGL_LIGHT_SUN ? "W/m^2" : "W", l->color[0], l->color[1], l->color[2], l->world_from_light[3],
               l->world_from_light[7], l->world_from_light[11]);
    }
    char desc[512];
    if (bi.has_settings) {
        cli_describe_settings(vsgl_bundle_settings(b), desc, sizeof desc);
        printf("settings: %s\n", desc);
    } else {
        printf("settings: none stored (defaults)\n");
    }
    if (*bi.output_path)
        printf("output: %s\n", bi.output_path);
    if (bi.has_frame)
        printf("frame: %d\n", bi.frame);
    /* Validate like a render would; report what the scene stage drops. */
    vsgl_scene *scene = NULL;
    r = vsgl_scene_create(ctx, d, &scene);
    if (r) {
        vsgl_bundle_destroy(b);
        return fail(ctx, r, "scene");
    }
    vsgl_scene_info si = {.size = sizeof si};
    if (vsgl_scene_get_info(scene, &si) == VSGL_OK)
        printf("valid: yes (%u triangles kept, %u degenerate dropped)\n", si.triangle_count, si.dropped_triangles);
    vsgl_scene_destroy(scene);
    vsgl_bundle_destroy(b);
    return 0;
}

typedef struct planes { float *p[7]; float *alpha; } planes;

/* Floats per pixel of the planes cmd_render passes: 7 RGB planes + alpha. */
#define CLI_OUTPUT_FLOATS (7 * 3 + 1)

static void format_bytes(uint64_t b, char *buf, size_t n)
{
    if (b >= (1ull << 30))
        snprintf(buf, n, "%.1f GiB", (double)b / (double)(1ull << 30));
    else
        snprintf(buf, n, "%.1f MiB", (double)b / (double)(1ull << 20));
}

static int cmd_render(vsgl_context *ctx, const cli_options *o, progress_state *progress)
{
    double t_start = now_seconds();
    vsgl_bundle *b = NULL;
    vsgl_result r = vsgl_bundle_read(ctx, o->scene_path, &b);
    if (r)
        return fail(ctx, r, o->scene_path);
    vsgl_bundle_info bi = {.size = sizeof bi};
    vsgl_bundle_get_info(b, &bi);
    const char *out_path = o->output_path ? o->output_path : (*bi.output_path ? bi.output_path : NULL);
    if (!out_path) {
        vsgl_bundle_destroy(b);
        fprintf(stderr, "vsgl: no output path: give -o OUT.exr (the bundle stores none)\n");
        return 2;
    }
    int status = 0;
    vsgl_scene *scene = NULL;
    planes pl;
    memset(&pl, 0, sizeof pl);
    vsgl_render_settings s;
    cli_settings(o, bi.has_settings ? vsgl_bundle_settings(b) : NULL, &s);
    char desc[512];
    cli_describe_settings(&s, desc, sizeof desc);
    if (o->verbose)
        fprintf(stderr, "vsgl: settings: %s\n", desc);

    /* Fail fast on an unwritable output, before any long work. */
    if ((r = vsgl_check_output_path(ctx, out_path)) || (r = vsgl_scene_create(ctx, vsgl_bundle_scene(b), &scene))) {
        status = fail(ctx, r, out_path);
        goto done;
    }
    double t_loaded = now_seconds();
    const vsgl_camera *cam = vsgl_bundle_scene(b)->camera;
    /* The render's own validation of the settings and its memory estimate,
     * before the output planes are allocated (also for --dry-run). */
    vsgl_memory_estimate est;
    r = vsgl_render_estimate(ctx, scene, &s, CLI_OUTPUT_FLOATS, &est);
    if (r) {
        status = fail(ctx, r, "settings");
        goto done;
    }
    char need[32], limit[32];
    format_bytes(est.total, need, sizeof need);
    format_bytes(est.limit, limit, sizeof limit);
    if (o->verbose) {
        char parts[6][32];
        const uint64_t v[6] = {est.output, est.gbuffer, est.planes, est.rsm, est.fit, est.shade};
        for (int i = 0; i < 6; ++i)
            format_bytes(v[i], parts[i], sizeof parts[i]);
        fprintf(stderr, "vsgl: memory: about %s (output planes %s, G-buffer %s, planes %s, RSMs %s, fit %s, shading %s); "
                "limit %s\n", need, parts[0], parts[1], parts[2], parts[3], parts[4], parts[5], limit);
    }
    if (o->dry_run && vsgl_bundle_scene(b)->light_count == 0) /* a render says so itself */
        fprintf(stderr, "vsgl: warning: the scene has no lights: the indirect light will be black\n");
    if (o->dry_run) {
        printf("dry run: %s is valid; would render %ux%u to %s with %s; memory about %s (limit %s)\n", o->scene_path,
               cam->width, cam->height, out_path, desc, need, limit);
        goto done;
    }

    size_t pixels = (size_t)cam->width * cam->height;
    for (int i = 0; i < 7; ++i)
        if (!(pl.p[i] = malloc(pixels * 3 * sizeof(float)))) {
            fprintf(stderr, "vsgl: out of memory for %ux%u output planes\n", cam->width, cam->height);
            status = 1;
            goto done;
        }
    if (!(pl.alpha = malloc(pixels * sizeof(float)))) {
        fprintf(stderr, "vsgl: out of memory for %ux%u output planes\n", cam->width, cam->height);
        status = 1;
        goto done;
    }
    vsgl_render_output out = {sizeof out, cam->width, cam->height, pl.p[0], pl.p[1], pl.p[2], pl.p[3],
                              pl.p[4], pl.p[5], pl.p[6], pl.alpha};
    vsgl_render_stats stats = {.size = sizeof stats};
    r = vsgl_render(ctx, scene, &s, &out, &stats);
    progress_end(progress);
    if (r) {
        status = fail(ctx, r, "render");
        goto done;
    }
    /* What the renderer skipped, one line each (always shown). */
    for (const char *line = stats.skipped; *line;) {
        const char *nl = strchr(line, '\n');
        size_t n = nl ? (size_t)(nl - line) : strlen(line);
        if (n)
            fprintf(stderr, "vsgl: skipped: %.*s\n", (int)n, line);
        line += n + (nl ? 1 : 0);
    }

    double t_rendered = now_seconds();
    char timings[256], lights[64], version[64];
    snprintf(timings, sizeof timings, "total=%.3f scene_prep=%.3f gbuffer=%.3f rsm=%.3f fit=%.3f shade=%.3f", stats.seconds_total,
             stats.seconds_scene_prep, stats.seconds_gbuffer, stats.seconds_rsm, stats.seconds_fit, stats.seconds_shade);
    snprintf(lights, sizeof lights, "used=%u skipped=%u vsgls=%u", stats.lights_used, stats.lights_skipped, stats.vsgl_count);
    snprintf(version, sizeof version, "libvsgl %s", vsgl_version_string());
    vsgl_exr_metadata md[] = {
        {"vsgl.settings", desc}, {"vsgl.seconds", timings}, {"vsgl.lights", lights},
        {"vsgl.scene", o->scene_path}, {"software", version},
    };
    vsgl_exr_options eo;
    memset(&eo, 0, sizeof eo);
    eo.size = sizeof eo;
    eo.pixel_type = o->half ? VSGL_EXR_HALF : VSGL_EXR_FLOAT;
    eo.compression = o->compression;
    eo.zip_level = o->zip_level.set ? (int32_t)o->zip_level.value : 0; /* 0: the library's default */
    eo.metadata = md;
    eo.metadata_count = sizeof md / sizeof md[0];
    /* only the passes asked for (--passes): vsgl_exr_write_render writes the planes that are set */
    float **wanted[CLI_PASS_COUNT] = {&out.diffuse_light, &out.glossy_light, &out.diffuse_color, &out.glossy_color,
                         &out.diffuse, &out.glossy, &out.combined};
    for (int k = 0; k < CLI_PASS_COUNT; ++k)
        if (!(o->passes & (1u << k)))
            *wanted[k] = NULL;
    if (!(o->passes & CLI_PASS_COMBINED))
        out.alpha = NULL;
    r = vsgl_exr_write_render(ctx, out_path, &out, &eo); /* SIGINT/SIGTERM cancel it too */
    progress_end(progress);
    if (r) {
        status = fail(ctx, r, out_path);
        goto done;
    }
    double t_written = now_seconds();
    if (o->verbose) {
        fprintf(stderr, "vsgl: read+validate %.3f s\n", t_loaded - t_start);
        fprintf(stderr, "vsgl: render %.3f s (scene_prep %.3f, gbuffer %.3f, rsm %.3f, fit %.3f, shade %.3f)\n",
                stats.seconds_total, stats.seconds_scene_prep, stats.seconds_gbuffer, stats.seconds_rsm, stats.seconds_fit,
                stats.seconds_shade);
        fprintf(stderr, "vsgl: lights used %u, skipped %u; VSGLs %u; shading pairs %llu\n", stats.lights_used,
                stats.lights_skipped, stats.vsgl_count, (unsigned long long)stats.shading_pairs);
        /* several lights or the auto preset: what each light got of the budget, what auto chose, and why */
        for (const char *line = stats.budget; *line;) {
            const char *nl = strchr(line, '\n');
            size_t n = nl ? (size_t)(nl - line) : strlen(line);
            if (n)
                fprintf(stderr, "vsgl: budget: %.*s\n", (int)n, line);
            line += n + (nl ? 1 : 0);
        }
        fprintf(stderr, "vsgl: write %.3f s; wall %.3f s; wrote %s (%ux%u, %s, %s)\n", t_written - t_rendered,
                t_written - t_start, out_path, cam->width, cam->height, o->half ? "half" : "float",
                cli_compression_name(o->compression));
    }
done:
    for (int i = 0; i < 7; ++i)
        free(pl.p[i]);
    free(pl.alpha);
    vsgl_scene_destroy(scene);
    vsgl_bundle_destroy(b);
    return status;
}

int main(int argc, char **argv)
{
    cli_options o;
    char err[512];
    if (cli_parse(argc, argv, &o, err, sizeof err) != 0) {
        fprintf(stderr, "vsgl: %s\n", err);
        return 2;
    }
    if (o.command == CLI_HELP) {
        fputs(cli_usage, stdout);
        return 0;
    }
    if (o.command == CLI_VERSION) {
        printf("vsgl %s (libvsgl %s, bundle format %d.%d)\n", vsgl_version_string(), vsgl_version_string(),
               VSGL_BUNDLE_VERSION_MAJOR, VSGL_BUNDLE_VERSION_MINOR);
        return 0;
    }
    if (vsgl_version() / 100 != VSGL_VERSION / 100) {
        fprintf(stderr, "vsgl: libvsgl %s does not match this program (built for %d.%d)\n", vsgl_version_string(),
                VSGL_VERSION_MAJOR, VSGL_VERSION_MINOR);
        return 1;
    }
    progress_state progress;
    memset(&progress, 0, sizeof progress);
    progress.tty = isatty(STDERR_FILENO);
    progress.percent = -1;
    log_state log = {&progress};
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.size = sizeof cd;
    cd.thread_count = o.threads.set ? o.threads.value : 0;
    cd.log_level = o.verbose ? VSGL_LOG_INFO : VSGL_LOG_WARNING;
    cd.log = on_log;
    cd.log_user = &log;
    cd.progress = on_progress;
    cd.progress_user = &progress;
    cd.max_memory = o.max_memory;
    vsgl_context *ctx = NULL;
    vsgl_result r = vsgl_context_create(&cd, &ctx);
    if (r)
        return fail(NULL, r, "context");
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    int status = o.command == CLI_INFO ? cmd_info(ctx, &o) : cmd_render(ctx, &o, &progress);
    vsgl_context_destroy(ctx);
    return status;
}
