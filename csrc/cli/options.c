/* Command-line parsing of build/vsgl. */
#include "options.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char cli_usage[] =
    "usage: vsgl render SCENE.vsglb [-o OUT.exr] [options]\n"
    "       vsgl info SCENE.vsglb\n"
    "       vsgl --version | --help\n"
    "\n"
    "Renders one-bounce diffuse + glossy indirect light of a scene bundle into a\n"
    "multilayer EXR (layer VSGL; passes DiffInd GlossInd Diff Gloss Combined, and\n"
    "DiffCol GlossCol with --passes). Settings: the bundle's (or --preset), then the\n"
    "options below.\n"
    "\n"
    "  -o, --output PATH     EXR to write (default: the bundle's output path)\n"
    "  --preset NAME         preview | balanced | quality | auto   (auto: balanced's knobs as ceilings;\n"
    "                        aa, the glossy model and each light's RSM chosen for the scene; -v says what)\n"
    "  --aa N                N x N camera samples per pixel (1..16)\n"
    "  --aa-pixel-limit N    from N pixels up, one sample per pixel whatever --aa says (edge pixels keep\n"
    "                        their edge rays); 0 = no limit (every preset: 76800 = 320 x 240)\n"
    "  --rsm N               reflective shadow map side in texels (2..8192)\n"
    "  --fit NAME            two | fis | kmeans | lattice   (VSGL fit)\n"
    "  --vsgls N             VSGLs per light (fis, kmeans; 1..65536)\n"
    "  --sharpness NAME      toksvig | banerjee\n"
    "  --diffuse NAME        sg | pulled-out | accurate   (receiver cosine)\n"
    "  --glossy NAME         asg | sg | asg2 | mrp | hybrid   (one ASG, one SG, GGX core + tail as two\n"
    "                        ASGs, rectangle proxies: the MRP paper, MRP per pixel where it applies;\n"
    "                        sg: the scalar reference path, every pixel, 45-85x the time: a check)\n"
    "  --glossy-lobes N      4 | 5             (GGX as N lobes where --glossy asg2 reflects a small lit\n"
    "                        surface; 5: closer to GGX's peak, one lobe more per such pair)\n"
    "  --mrp-min-area A      smallest planar face made a rectangle proxy by --glossy mrp | hybrid\n"
    "                        (m^2, >= 0; 0 = the default 0.25)\n"
    "  --visibility NAME     none | ray\n"
    "  --leak NAME           auto | off | on | clip   (emitter clip and near field; clip: without the near field)\n"
    "  --merge NAME          auto | off        (share light between a pixel's samples on one surface)\n"
    "  --shade-stride N      1..8              (shade one pixel in N x N, interpolate the rest)\n"
    "  --stride-pixels N     the image size (pixels) --shade-stride is meant for: larger images scale the\n"
    "                        stride by sqrt(pixels / N), up to 8; 0 = the stride at every size (the\n"
    "                        presets: 76800 = 320 x 240)\n"
    "  --edge-samples N      0..16             (N x N rays in pixels a geometric edge crosses; 0 = off)\n"
    "  --dominant-rays N     1..16             (--visibility ray: rays per pair where a VSGL carries 0.5 % or\n"
    "                        more of a pixel's light near a shadow's edge; every preset: 4)\n"
    "  --method NAME         vsgl | brute-force   (brute-force: every RSM texel, the reference)\n"
    "  --threads N           worker threads (0 = all cores)\n"
    "  --max-memory SIZE     refuse a render estimated to need more (e.g. 8G, 512M;\n"
    "                        default: the memory available on this machine)\n"
    "  --seed N              seed of FIS / k-means sampling\n"
    "  --half                16-bit half EXR samples (the default, as Blender's)\n"
    "  --float               32-bit float EXR samples\n"
    "  --compression NAME    zip | zips | piz | none | rle | pxr24 | b44 | b44a\n"
    "                        (EXR compression, default zip; pxr24 and b44* are lossy)\n"
    "  --zip-level N         deflate level 1..9 of zip and zips (lossless: higher is smaller and slower;\n"
    "                        default 1)\n"
    "  --passes LIST         the EXR's passes, comma-separated: DiffInd GlossInd DiffCol GlossCol Diff\n"
    "                        Gloss Combined, or all (default: DiffInd,GlossInd,Diff,Gloss,Combined,\n"
    "                        what the add-on's compositor setup reads)\n"
    "  --dry-run             read and validate the scene and settings, estimate the\n"
    "                        memory, check the output path; do not render\n"
    "  -v, --verbose         per-stage timings and statistics on stderr\n"
    "\n"
    "Exit status: 0 success, 1 failure (one line 'vsgl: reason' on stderr),\n"
    "2 bad command line, 130 interrupted.\n";

static int set_err(char *err, size_t n, const char *fmt, const char *a, const char *b)
{
    snprintf(err, n, fmt, a, b);
    return 2;
}

static int parse_u32(const char *s, uint32_t lo, cli_u32 *out)
{
    if (!s || !*s || *s == '-' || *s == '+')
        return -1;
    errno = 0;
    char *end = NULL;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || *end || v > UINT32_MAX || v < lo)
        return -1;
    out->set = 1;
    out->value = (uint32_t)v;
    return 0;
}

int cli_parse_bytes(const char *s, uint64_t *out)
{
    if (!s || *s < '0' || *s > '9')
        return -1;
    errno = 0;
    char *end = NULL;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno)
        return -1;
    unsigned shift = 0;
    switch (*end) {
    case 'K': case 'k': shift = 10; ++end; break;
    case 'M': case 'm': shift = 20; ++end; break;
    case 'G': case 'g': shift = 30; ++end; break;
    case 'T': case 't': shift = 40; ++end; break;
    default: break;
    }
    if (*end == 'B' || *end == 'b')
        ++end;
    if (*end || (shift && v > (UINT64_MAX >> shift)))
        return -1;
    *out = (uint64_t)v << shift;
    return 0;
}

static int parse_enum(const char *s, const char *const *names, const int *values, int *out)
{
    for (int i = 0; names[i]; ++i)
        if (s && strcmp(s, names[i]) == 0) {
            *out = values[i];
            return 0;
        }
    return -1;
}

typedef struct enum_opt { const char *name; const char *const *names; const int *values; size_t offset; } enum_opt;
typedef struct num_opt { const char *name; uint32_t min; size_t offset; } num_opt;

static const char *const preset_names[] = {"preview", "balanced", "quality", "auto", NULL};
static const int preset_values[] = {VSGL_PRESET_PREVIEW, VSGL_PRESET_BALANCED, VSGL_PRESET_QUALITY,
                                    VSGL_PRESET_AUTO};
static const char *const fit_names[] = {"two", "fis", "kmeans", "lattice", NULL};
static const int fit_values[] = {VSGL_FIT_TWO, VSGL_FIT_FIS, VSGL_FIT_KMEANS, VSGL_FIT_LATTICE};
static const char *const sharp_names[] = {"toksvig", "banerjee", NULL};
static const int sharp_values[] = {VSGL_SHARPNESS_TOKSVIG, VSGL_SHARPNESS_BANERJEE};
/* The add-on's enum names in lower case with '-' (PULLED_OUT -> pulled-out);
 * the older short spellings stay accepted after them. */
static const char *const diffuse_names[] = {"sg", "pulled-out", "accurate", "pulled", NULL};
static const int diffuse_values[] = {VSGL_COSINE_SG, VSGL_COSINE_PULLED_OUT, VSGL_COSINE_ACCURATE,
                                     VSGL_COSINE_PULLED_OUT};
static const char *const glossy_names[] = {"asg", "sg", "asg2", "mrp", "hybrid", NULL};
static const int glossy_values[] = {VSGL_GLOSSY_ASG, VSGL_GLOSSY_SG, VSGL_GLOSSY_ASG2, VSGL_GLOSSY_MRP,
                                    VSGL_GLOSSY_HYBRID};
static const char *const vis_names[] = {"none", "ray", NULL};
static const int vis_values[] = {VSGL_VISIBILITY_NONE, VSGL_VISIBILITY_RAY};
static const char *const leak_names[] = {"auto", "off", "on", "clip", NULL};
static const int leak_values[] = {VSGL_LEAK_AUTO, VSGL_LEAK_OFF, VSGL_LEAK_ON, VSGL_LEAK_CLIP};
static const char *const merge_names[] = {"auto", "off", NULL};
static const int merge_values[] = {VSGL_MERGE_AUTO, VSGL_MERGE_OFF};
static const char *const method_names[] = {"vsgl", "brute-force", "brute", NULL};
static const int method_values[] = {VSGL_METHOD_VSGL, VSGL_METHOD_BRUTE_FORCE, VSGL_METHOD_BRUTE_FORCE};

static const char *const comp_names[] = {"zip", "zips", "piz", "none", "rle", "pxr24", "b44", "b44a", NULL};
static const int comp_values[] = {VSGL_EXR_ZIP, VSGL_EXR_ZIPS, VSGL_EXR_PIZ, VSGL_EXR_NONE, VSGL_EXR_RLE, VSGL_EXR_PXR24,
                                  VSGL_EXR_B44, VSGL_EXR_B44A};

const char *cli_compression_name(int compression)
{
    for (int i = 0; comp_names[i]; ++i)
        if (comp_values[i] == compression)
            return comp_names[i];
    return "?";
}

static const enum_opt enum_opts[] = {
    {"--compression", comp_names, comp_values, offsetof(cli_options, compression)},
    {"--preset", preset_names, preset_values, offsetof(cli_options, preset)},
    {"--fit", fit_names, fit_values, offsetof(cli_options, fit)},
    {"--sharpness", sharp_names, sharp_values, offsetof(cli_options, sharpness)},
    {"--diffuse", diffuse_names, diffuse_values, offsetof(cli_options, diffuse)},
    {"--glossy", glossy_names, glossy_values, offsetof(cli_options, glossy)},
    {"--visibility", vis_names, vis_values, offsetof(cli_options, visibility)},
    {"--method", method_names, method_values, offsetof(cli_options, method)},
    {"--leak", leak_names, leak_values, offsetof(cli_options, leak)},
    {"--merge", merge_names, merge_values, offsetof(cli_options, merge)},
};

static const num_opt num_opts[] = {
    {"--aa", 1, offsetof(cli_options, aa)},
    {"--aa-pixel-limit", 0, offsetof(cli_options, aa_limit)},
    {"--rsm", 1, offsetof(cli_options, rsm)},
    {"--vsgls", 1, offsetof(cli_options, vsgls)},
    {"--shade-stride", 1, offsetof(cli_options, stride)},
    {"--stride-pixels", 0, offsetof(cli_options, stride_pixels)},
    {"--zip-level", 1, offsetof(cli_options, zip_level)},
    {"--edge-samples", 0, offsetof(cli_options, edge)},
    {"--dominant-rays", 0, offsetof(cli_options, dominant)},
    {"--glossy-lobes", 0, offsetof(cli_options, lobes)},
    {"--threads", 0, offsetof(cli_options, threads)},
    {"--seed", 0, offsetof(cli_options, seed)},
};

static void join_names(const char *const *names, char *buf, size_t n)
{
    buf[0] = '\0';
    for (int i = 0; names[i]; ++i)
        snprintf(buf + strlen(buf), n - strlen(buf), "%s%s", i ? "|" : "", names[i]);
}

static int parse_args(int argc, char **argv, cli_options *o, char *err, size_t err_size);

/* The reason is printed as one line "vsgl: ...": an argument quoted in it
 * must not break it (found by tests/fuzz/fuzz_cli.c: a newline in an option
 * name gave a two-line message). Control characters become '?'. */
int cli_parse(int argc, char **argv, cli_options *o, char *err, size_t err_size)
{
    int rc = parse_args(argc, argv, o, err, err_size);
    for (char *p = err; rc && *p; ++p)
        if ((unsigned char)*p < 0x20 || *p == 0x7f)
            *p = '?';
    return rc;
}

const char *const cli_pass_names[CLI_PASS_COUNT] = {"DiffInd", "GlossInd", "DiffCol", "GlossCol", "Diff", "Gloss", "Combined"};

/* "Diff,Gloss" or "all" -> CLI_PASS_* bits; 0 if a name is unknown or the
 * list is empty (bad: the first unknown name, up to its comma). */
static uint32_t parse_passes(const char *value, char *bad, size_t bad_size)
{
    if (!strcmp(value, "all"))
        return CLI_PASSES_ALL;
    uint32_t mask = 0;
    for (const char *p = value;;) {
        const char *comma = strchr(p, ',');
        size_t n = comma ? (size_t)(comma - p) : strlen(p);
        int k = 0;
        while (k < CLI_PASS_COUNT && !(strlen(cli_pass_names[k]) == n && !strncmp(p, cli_pass_names[k], n)))
            ++k;
        if (k == CLI_PASS_COUNT) {
            snprintf(bad, bad_size, "%.*s", (int)(n < 40 ? n : 40), p);
            return 0;
        }
        mask |= 1u << k;
        if (!comma)
            return mask;
        p = comma + 1;
    }
}

static int parse_args(int argc, char **argv, cli_options *o, char *err, size_t err_size)
{
    memset(o, 0, sizeof *o);
    /* Blender's own EXR defaults: half, ZIP. At 1080p with 22 channels ZIP
     * half wrote 3.3 MB in 0.8-0.9 s here, PIZ float 65 MB in 2.0 s
     * (tools/bench_exr.sh, docs/performance.md). */
    o->compression = VSGL_EXR_ZIP;
    o->half = 1;
    o->passes = CLI_PASSES_COMPOSITOR;
    o->command = CLI_HELP;
    o->preset = o->fit = o->sharpness = o->diffuse = o->glossy = o->visibility = o->method = o->leak = o->merge = -1;
    err[0] = '\0';
    if (argc < 2)
        return set_err(err, err_size, "no command given%s%s (see vsgl --help)", "", "");
    const char *cmd = argv[1];
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
        o->command = CLI_HELP;
        return 0;
    }
    if (!strcmp(cmd, "--version") || !strcmp(cmd, "version")) {
        o->command = CLI_VERSION;
        return 0;
    }
    if (!strcmp(cmd, "render"))
        o->command = CLI_RENDER;
    else if (!strcmp(cmd, "info"))
        o->command = CLI_INFO;
    else
        return set_err(err, err_size, "unknown command '%s'%s (see vsgl --help)", cmd, "");

    int only_dashes = 0;
    for (int i = 2; i < argc; ++i) {
        const char *a = argv[i];
        if (only_dashes || a[0] != '-' || a[1] == '\0') {
            if (o->scene_path)
                return set_err(err, err_size, "unexpected argument '%s' (the scene is '%s')", a, o->scene_path);
            o->scene_path = a;
            continue;
        }
        if (!strcmp(a, "--")) {
            only_dashes = 1;
            continue;
        }
        /* --name=value or --name value */
        char name[64];
        const char *value = NULL;
        const char *eq = strchr(a, '=');
        if (eq && a[1] == '-') {
            size_t n = (size_t)(eq - a);
            if (n >= sizeof name)
                return set_err(err, err_size, "unknown option '%s'%s (see vsgl --help)", a, "");
            memcpy(name, a, n);
            name[n] = '\0';
            value = eq + 1;
        } else {
            snprintf(name, sizeof name, "%s", a);
        }
        int is_flag = 1;
        if (!strcmp(name, "--help") || !strcmp(name, "-h")) {
            o->command = CLI_HELP;
            return 0;
        } else if (!strcmp(name, "-v") || !strcmp(name, "--verbose")) {
            o->verbose = 1;
        } else if (!strcmp(name, "--half")) {
            o->half = 1;
            o->pixel_type_given = 1;
        } else if (!strcmp(name, "--float")) {
            o->half = 0;
            o->pixel_type_given = 1;
        } else if (!strcmp(name, "--dry-run")) {
            o->dry_run = 1;
        } else {
            is_flag = 0;
        }
        if (is_flag) {
            if (value)
                return set_err(err, err_size, "option %s takes no value (got '%s')", name, value);
            continue;
        }
        /* Options with a value. */
        int known = !strcmp(name, "-o") || !strcmp(name, "--output") || !strcmp(name, "--max-memory") ||
                    !strcmp(name, "--mrp-min-area") || !strcmp(name, "--passes");
        for (size_t k = 0; k < sizeof enum_opts / sizeof enum_opts[0]; ++k)
            known |= !strcmp(name, enum_opts[k].name);
        for (size_t k = 0; k < sizeof num_opts / sizeof num_opts[0]; ++k)
            known |= !strcmp(name, num_opts[k].name);
        if (!known)
            return set_err(err, err_size, "unknown option '%s'%s (see vsgl --help)", name, "");
        if (!value) {
            if (i + 1 >= argc)
                return set_err(err, err_size, "option %s needs a value%s", name, "");
            value = argv[++i];
        }
        if (!strcmp(name, "-o") || !strcmp(name, "--output")) {
            if (!*value)
                return set_err(err, err_size, "option %s needs a non-empty path%s", name, "");
            o->output_path = value;
            continue;
        }
        if (!strcmp(name, "--mrp-min-area")) {
            char *end = NULL;
            errno = 0;
            double area = *value ? strtod(value, &end) : -1.0;
            if (!end || *end || errno || !(area >= 0.0) || !(area <= 3.4e38))
                return set_err(err, err_size, "option --mrp-min-area: '%s' is not an area in m^2 >= 0%s", value, "");
            o->mrp_min_area_set = 1;
            o->mrp_min_area = area;
            continue;
        }
        if (!strcmp(name, "--passes")) {
            char bad[48];
            bad[0] = '\0';
            if (!(o->passes = parse_passes(value, bad, sizeof bad)))
                return set_err(err, err_size, "option --passes: '%s' is not a pass (DiffInd GlossInd DiffCol GlossCol "
                               "Diff Gloss Combined, comma-separated, or all)%s", bad, "");
            continue;
        }
        if (!strcmp(name, "--max-memory")) {
            if (cli_parse_bytes(value, &o->max_memory) != 0 || o->max_memory == 0)
                return set_err(err, err_size, "option --max-memory: '%s' is not a size such as 8G, 512M or a byte count > 0%s",
                               value, "");
            continue;
        }
        int done = 0;
        for (size_t k = 0; k < sizeof enum_opts / sizeof enum_opts[0] && !done; ++k) {
            const enum_opt *e = &enum_opts[k];
            if (strcmp(name, e->name))
                continue;
            done = 1;
            if (parse_enum(value, e->names, e->values, (int *)((char *)o + e->offset)) != 0) {
                char list[128];
                join_names(e->names, list, sizeof list);
                snprintf(err, err_size, "option %s: '%s' is not one of %s", name, value, list);
                return 2;
            }
        }
        for (size_t k = 0; k < sizeof num_opts / sizeof num_opts[0] && !done; ++k) {
            const num_opt *n = &num_opts[k];
            if (strcmp(name, n->name))
                continue;
            done = 1;
            if (parse_u32(value, n->min, (cli_u32 *)((char *)o + n->offset)) != 0) {
                snprintf(err, err_size, "option %s: '%s' is not a whole number %s %u", name, value,
                         n->min ? ">=" : "in 0 ..", n->min ? n->min : UINT32_MAX);
                return 2;
            }
        }
    }
    if (o->zip_level.set && o->zip_level.value > 9) { /* refused before a render is spent on it */
        snprintf(err, err_size, "option --zip-level: '%u' is not a deflate level 1..9", o->zip_level.value);
        return 2;
    }
    if (!o->scene_path)
        return set_err(err, err_size, "%s: no scene bundle given%s (see vsgl --help)", cmd, "");
    if (o->command == CLI_INFO && (o->output_path || o->pixel_type_given || o->dry_run))
        return set_err(err, err_size, "info takes only a scene bundle (and -v)%s%s", "", "");
    return 0;
}

void cli_settings(const cli_options *o, const vsgl_render_settings *base, vsgl_render_settings *s)
{
    if (o->preset >= 0 || !base)
        vsgl_render_settings_preset(o->preset >= 0 ? o->preset : VSGL_PRESET_BALANCED, s);
    else
        *s = *base;
    s->size = sizeof *s;
    if (o->aa.set) s->aa_samples = o->aa.value;
    if (o->aa_limit.set) s->aa_pixel_limit = o->aa_limit.value;
    if (o->stride_pixels.set) s->stride_pixels = o->stride_pixels.value;
    if (o->rsm.set) s->rsm_resolution = o->rsm.value;
    if (o->vsgls.set) s->vsgl_count = o->vsgls.value;
    if (o->stride.set) s->shade_stride = o->stride.value;
    if (o->edge.set) s->edge_samples = o->edge.value;
    if (o->dominant.set) s->dominant_rays = o->dominant.value;
    if (o->lobes.set) s->glossy_lobes = o->lobes.value;
    if (o->seed.set) s->seed = o->seed.value;
    if (o->fit >= 0) s->fit_mode = o->fit;
    if (o->sharpness >= 0) s->sharpness_estimator = o->sharpness;
    if (o->diffuse >= 0) s->diffuse_mode = o->diffuse;
    if (o->glossy >= 0) s->glossy_mode = o->glossy;
    if (o->visibility >= 0) s->visibility = o->visibility;
    if (o->method >= 0) s->method = o->method;
    if (o->leak >= 0) s->leak_correction = o->leak;
    if (o->merge >= 0) s->sample_merging = o->merge;
    if (o->mrp_min_area_set) s->mrp_min_area = (float)o->mrp_min_area;
}

static const char *name_of(const char *const *names, const int *values, int v)
{
    for (int i = 0; names[i]; ++i)
        if (values[i] == v)
            return names[i];
    return "?";
}

void cli_describe_settings(const vsgl_render_settings *s, char *buf, size_t size)
{
    snprintf(buf, size, "method=%s aa=%u rsm=%u fit=%s vsgls=%u fis_iterations=%u sharpness=%s diffuse=%s glossy=%s visibility=%s seed=%u leak=%s merge=%s stride=%u edge=%u mrp_min_area=%g glossy_lobes=%u aa_pixel_limit=%u stride_pixels=%u dominant_rays=%u",
             name_of(method_names, method_values, s->method), s->aa_samples, s->rsm_resolution,
             name_of(fit_names, fit_values, s->fit_mode), s->vsgl_count, s->fis_iterations,
             name_of(sharp_names, sharp_values, s->sharpness_estimator), name_of(diffuse_names, diffuse_values, s->diffuse_mode),
             name_of(glossy_names, glossy_values, s->glossy_mode), name_of(vis_names, vis_values, s->visibility), s->seed,
             name_of(leak_names, leak_values, s->leak_correction), name_of(merge_names, merge_values, s->sample_merging), s->shade_stride, s->edge_samples,
             (double)s->mrp_min_area, s->glossy_lobes, s->aa_pixel_limit, s->stride_pixels, s->dominant_rays);
}
