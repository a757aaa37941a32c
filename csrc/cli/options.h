/* Command-line parsing of build/vsgl (pure: no I/O, no globals). */
#ifndef VSGL_CLI_OPTIONS_H
#define VSGL_CLI_OPTIONS_H

#include "vsgl.h"

#define CLI_HELP    0
#define CLI_VERSION 1
#define CLI_RENDER  2
#define CLI_INFO    3

/* The EXR's passes (--passes), in vsgl_exr_write_render's order. */
enum { CLI_PASS_DIFFIND = 1, CLI_PASS_GLOSSIND = 2, CLI_PASS_DIFFCOL = 4, CLI_PASS_GLOSSCOL = 8, CLI_PASS_DIFF = 16,
       CLI_PASS_GLOSS = 32, CLI_PASS_COMBINED = 64, CLI_PASSES_ALL = 127 };
/* The default: what the add-on's compositor setup reads (and writes itself),
 * DiffInd GlossInd Diff Gloss Combined. */
#define CLI_PASSES_COMPOSITOR (CLI_PASS_DIFFIND | CLI_PASS_GLOSSIND | CLI_PASS_DIFF | CLI_PASS_GLOSS | CLI_PASS_COMBINED)
/* The pass names, bit k = 1 << k. */
#define CLI_PASS_COUNT 7
extern const char *const cli_pass_names[CLI_PASS_COUNT];

/* An optional unsigned number given on the command line. */
typedef struct cli_u32 { int set; uint32_t value; } cli_u32;

typedef struct cli_options {
    int command;              /* CLI_* */
    const char *scene_path;   /* render/info: the bundle */
    const char *output_path;  /* -o; NULL = the bundle's output path */
    int preset;               /* VSGL_PRESET_*, -1 = not given */
    cli_u32 aa, aa_limit, stride_pixels, rsm, vsgls, threads, seed, stride, edge, lobes, zip_level, dominant;
    int fit, sharpness, diffuse, glossy, visibility, method;
    int leak, merge;          /* VSGL_LEAK_*, VSGL_MERGE_*; -1 = not given */
    int compression;          /* VSGL_EXR_*, default ZIP */
    int half, verbose, dry_run;
    int pixel_type_given;   /* --half or --float was given */
    uint64_t max_memory;      /* --max-memory in bytes; 0 = what the machine has available */
    uint32_t passes;          /* CLI_PASS_* bits of the EXR's passes; default CLI_PASSES_COMPOSITOR */
    int mrp_min_area_set;     /* --mrp-min-area was given */
    double mrp_min_area;      /* its value (m^2, finite, >= 0) */
} cli_options;

/* Parse a byte size: digits with an optional K, M, G or T (powers of 1024)
 * and an optional trailing B ("512M", "8G", "1073741824"). 0 or -1 (junk). */
int cli_parse_bytes(const char *s, uint64_t *out);

/* Parse argv. Returns 0, or 2 with a one-line reason in err (no "vsgl: " prefix). */
int cli_parse(int argc, char **argv, cli_options *o, char *err, size_t err_size);

/* Settings to render with: the preset if given, else the bundle's settings
 * (base), then every option given on the command line. */
void cli_settings(const cli_options *o, const vsgl_render_settings *base, vsgl_render_settings *out);

/* "method=vsgl aa=2 rsm=256 ..." for logs and EXR metadata. */
void cli_describe_settings(const vsgl_render_settings *s, char *buf, size_t size);

/* The --compression name of a VSGL_EXR_* compression ("?" if unknown). */
const char *cli_compression_name(int compression);

/* The --help text. */
extern const char cli_usage[];

#endif
