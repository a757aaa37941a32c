/* Multilayer EXR writer: read back with OpenEXR Core's reader (independent
 * of the writer's packing code), with OpenImageIO's oiiotool, and with
 * Blender 3.4; atomicity and failure cases. */
#include "harness.h"
#include "log_capture.h"
#include "io/half.h"
#include "vsgl.h"
#include "io/atomic.h"

#include <openexr.h>

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

/* ---- helpers ------------------------------------------------------------ */

static void make_temp_dir(char *dir, size_t cap)
{
    snprintf(dir, cap, "/tmp/vsgl_exr_XXXXXX");
    if (!mkdtemp(dir))
        dir[0] = '\0';
}

/* A render output of w x h with no planes set. */
static vsgl_render_output blank_output(uint32_t w, uint32_t h)
{
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = w;
    o.height = h;
    return o;
}

static void remove_tree(const char *dir)
{
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "    (could not remove %s)\n", dir);
}

/* Number of entries in dir other than . and .. */
static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    if (!d)
        return -1;
    for (struct dirent *e; (e = readdir(d));)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
            ++n;
    closedir(d);
    return n;
}

/* Run a shell command, capture up to cap-1 bytes of stdout; returns exit status or -1. */
static int run_capture(const char *cmd, char *out, size_t cap)
{
    FILE *p = popen(cmd, "r");
    if (!p)
        return -1;
    size_t n = fread(out, 1, cap - 1, p);
    out[n] = '\0';
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int have_tool(const char *name)
{
    char cmd[256], out[256];
    snprintf(cmd, sizeof cmd, "command -v %s >/dev/null 2>&1 && echo yes", name);
    return run_capture(cmd, out, sizeof out) == 0 && strncmp(out, "yes", 3) == 0;
}

static int read_file(const char *path, unsigned char **data, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    *data = malloc((size_t)n + 1);
    *size = fread(*data, 1, (size_t)n, f);
    fclose(f);
    return 0;
}

/* A test image: value of pass p, channel c at (x, y); exactly representable in half. */
static float pattern(int p, int c, int x, int y)
{
    return (float)(p * 16 + c * 4) + (float)x * 0.25f + (float)y * 0.125f;
}

enum { W = 37, H = 23, NP = 3 };

typedef struct image { float rgb[NP - 1][W * H * 3]; float combined[W * H * 3]; float alpha[W * H]; } image;

static void fill(image *im)
{
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            for (int p = 0; p < NP - 1; ++p)
                for (int c = 0; c < 3; ++c)
                    im->rgb[p][(y * W + x) * 3 + c] = pattern(p, c, x, y);
            for (int c = 0; c < 3; ++c)
                im->combined[(y * W + x) * 3 + c] = pattern(2, c, x, y);
            im->alpha[y * W + x] = pattern(2, 3, x, y);
        }
}

static vsgl_render_output output_of(image *im)
{
    vsgl_render_output o = blank_output(W, H);
    o.diffuse_light = im->rgb[0];
    o.glossy_light = im->rgb[1];
    o.combined = im->combined;
    o.alpha = im->alpha;
    return o;
}

/* Decode every channel of part 0 as float into planes[channel][y*w+x] (channel order of the file). */
typedef struct decoded { int count; char names[16][64]; float *planes[16]; int w, h; } decoded;

static int decode_exr(const char *path, decoded *d)
{
    memset(d, 0, sizeof *d);
    exr_context_t e = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    if (exr_start_read(&e, path, &init) != EXR_ERR_SUCCESS)
        return -1;
    const exr_attr_chlist_t *cl = NULL;
    exr_attr_box2i_t dw;
    int32_t lines = 0;
    if (exr_get_channels(e, 0, &cl) || exr_get_data_window(e, 0, &dw) || exr_get_scanlines_per_chunk(e, 0, &lines)) {
        exr_finish(&e);
        return -2;
    }
    d->w = dw.max.x - dw.min.x + 1;
    d->h = dw.max.y - dw.min.y + 1;
    d->count = cl->num_channels < 16 ? cl->num_channels : 16;
    for (int c = 0; c < d->count; ++c) {
        snprintf(d->names[c], sizeof d->names[c], "%s", cl->entries[c].name.str);
        d->planes[c] = calloc((size_t)d->w * d->h, sizeof(float));
    }
    exr_decode_pipeline_t dec;
    memset(&dec, 0, sizeof dec);
    int live = 0, rc = 0;
    for (int y = dw.min.y; y <= dw.max.y && !rc; y += lines) {
        exr_chunk_info_t ci;
        if (exr_read_scanline_chunk_info(e, 0, y, &ci)) { rc = -3; break; }
        if ((live ? exr_decoding_update(e, 0, &ci, &dec) : exr_decoding_initialize(e, 0, &ci, &dec))) { rc = -4; break; }
        int first = !live;
        live = 1;
        for (int c = 0; c < dec.channel_count; ++c) {
            int k = 0;
            while (k < d->count && strcmp(d->names[k], dec.channels[c].channel_name))
                ++k;
            dec.channels[c].decode_to_ptr = (uint8_t *)(d->planes[k] + (size_t)(y - dw.min.y) * d->w);
            dec.channels[c].user_pixel_stride = 4;
            dec.channels[c].user_line_stride = 4 * d->w;
            dec.channels[c].user_bytes_per_element = 4;
            dec.channels[c].user_data_type = EXR_PIXEL_FLOAT;
        }
        if (first && exr_decoding_choose_default_routines(e, 0, &dec)) { rc = -5; break; }
        if (exr_decoding_run(e, 0, &dec)) rc = -6;
    }
    if (live)
        exr_decoding_destroy(e, &dec);
    exr_finish(&e);
    return rc;
}

static void free_decoded(decoded *d)
{
    for (int c = 0; c < d->count; ++c)
        free(d->planes[c]);
}

/* 0, 1, 2 for a channel name ending in R, G, B (the last letter; B for any other). */
static int rgb_index(const char *name)
{
    const char last = name[strlen(name) - 1];
    return last == 'R' ? 0 : last == 'G' ? 1 : 2;
}

static int channel_index(const decoded *d, const char *name)
{
    for (int c = 0; c < d->count; ++c)
        if (strcmp(d->names[c], name) == 0)
            return c;
    return -1;
}

/* ---- round trips -------------------------------------------------------- */

static void check_roundtrip_with(int pixel_type, int compression, double tol)
{
    char dir[64], path[128];
    make_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/out.exr", dir);
    static image im;
    fill(&im);
    vsgl_render_output o = output_of(&im);
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    vsgl_exr_metadata md[2] = {{"vsgl.settings", "aa=2 rsm=256"}, {"vsgl.seconds", "0.125"}};
    vsgl_exr_options opt;
    memset(&opt, 0, sizeof opt);
    opt.size = sizeof opt;
    opt.pixel_type = pixel_type;
    opt.compression = compression;
    opt.metadata = md;
    opt.metadata_count = 2;
    vsgl_result r = vsgl_exr_write_render(ctx, path, &o, &opt);
    VT_CHECK(r == VSGL_OK, "write %s: %s", path, vsgl_context_last_error(ctx));

    decoded d;
    int rc = decode_exr(path, &d);
    VT_CHECK(rc == 0, "decode %s: %d", path, rc);
    VT_CHECK(d.w == W && d.h == H, "size %dx%d want %dx%d", d.w, d.h, W, H);
    static const char *const want[] = {
        "VSGL.Combined.A", "VSGL.Combined.B", "VSGL.Combined.G", "VSGL.Combined.R",
        "VSGL.DiffInd.B", "VSGL.DiffInd.G", "VSGL.DiffInd.R",
        "VSGL.GlossInd.B", "VSGL.GlossInd.G", "VSGL.GlossInd.R"};
    VT_CHECK(d.count == 10, "channel count %d", d.count);
    for (int i = 0; i < 10 && i < d.count; ++i)
        VT_CHECK(strcmp(d.names[i], want[i]) == 0, "channel %d: %s want %s", i, d.names[i], want[i]);
    const char *passes[3] = {"DiffInd", "GlossInd", "Combined"};
    int bad = 0;
    for (int p = 0; p < 3; ++p)
        for (int c = 0; c < (p == 2 ? 4 : 3); ++c) {
            char name[64];
            snprintf(name, sizeof name, "VSGL.%s.%c", passes[p], "RGBA"[c]);
            int k = channel_index(&d, name);
            VT_CHECK(k >= 0, "missing %s", name);
            if (k < 0)
                continue;
            for (int y = 0; y < H && bad < 4; ++y)
                for (int x = 0; x < W && bad < 4; ++x) {
                    double got = d.planes[k][y * W + x], w = pattern(p, c, x, y);
                    double allowed = tol * fmax(fabs(w), 1e-3); /* relative; lossy codecs near 0 too */
                    if (fabs(got - w) > allowed) {
                        ++bad;
                        VT_CHECK_ABS(got, w, allowed, "%s pixel (%d, %d) type %d compression %d", name, x, y,
                                     pixel_type, compression);
                    }
                }
        }
    free_decoded(&d);

    /* Header attributes. */
    exr_context_t e = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    if (exr_start_read(&e, path, &init) == EXR_ERR_SUCCESS) {
        const char *s = NULL;
        int32_t len = 0;
        VT_CHECK(exr_attr_get_string(e, 0, "vsgl.settings", &len, &s) == 0 && s && strncmp(s, "aa=2 rsm=256", (size_t)len) == 0,
                 "vsgl.settings = %.*s", len, s ? s : "");
        VT_CHECK(exr_attr_get_string(e, 0, "vsgl.version", &len, &s) == 0 && s && strncmp(s, vsgl_version_string(), (size_t)len) == 0,
                 "vsgl.version = %.*s", len, s ? s : "");
        exr_compression_t comp;
        static const exr_compression_t file_comp[VSGL_EXR_COMPRESSION_COUNT] = {
            EXR_COMPRESSION_ZIP, EXR_COMPRESSION_NONE, EXR_COMPRESSION_ZIPS, EXR_COMPRESSION_PIZ, EXR_COMPRESSION_RLE,
            EXR_COMPRESSION_PXR24, EXR_COMPRESSION_B44, EXR_COMPRESSION_B44A};
        VT_CHECK(exr_get_compression(e, 0, &comp) == 0 && comp == file_comp[compression], "compression %d want %d",
                 (int)comp, (int)file_comp[compression]);
        const exr_attr_chlist_t *cl = NULL;
        exr_get_channels(e, 0, &cl);
        VT_CHECK(cl && cl->entries[0].pixel_type == (pixel_type == VSGL_EXR_HALF ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT),
                 "pixel type %d", cl ? (int)cl->entries[0].pixel_type : -1);
        exr_finish(&e);
    }
    VT_CHECK(count_entries(dir) == 1, "only out.exr left in %s, found %d entries", dir, count_entries(dir));
    vsgl_context_destroy(ctx);
    remove_tree(dir);
}

static void check_roundtrip(int pixel_type, double tol)
{
    check_roundtrip_with(pixel_type, VSGL_EXR_ZIP, tol);
}

/* Every compression Blender offers that OpenEXR Core 3.1 encodes, read
 * back by OpenEXR's own decoder: the lossless ones exactly, PXR24 floats
 * within its 24-bit precision (half exact), B44 halves within its
 * quantisation: the test pattern's sharp steps inside 4 x 4 blocks lose up
 * to 12.5 % (0.5 -> 0.5625), so B44 is for previews, not grading (float
 * channels are stored uncompressed by B44). */
VT_TEST(exr_every_compression_reads_back_with_openexr_core)
{
    static const int lossless[] = {VSGL_EXR_NONE, VSGL_EXR_ZIPS, VSGL_EXR_ZIP, VSGL_EXR_PIZ, VSGL_EXR_RLE};
    for (size_t i = 0; i < sizeof lossless / sizeof lossless[0]; ++i) {
        check_roundtrip_with(VSGL_EXR_FLOAT, lossless[i], 0.0);
        check_roundtrip_with(VSGL_EXR_HALF, lossless[i], 0.0);
    }
    check_roundtrip_with(VSGL_EXR_FLOAT, VSGL_EXR_PXR24, 1.0 / 32768.0);
    check_roundtrip_with(VSGL_EXR_HALF, VSGL_EXR_PXR24, 0.0);
    check_roundtrip_with(VSGL_EXR_FLOAT, VSGL_EXR_B44, 0.0);
    check_roundtrip_with(VSGL_EXR_HALF, VSGL_EXR_B44, 0.15);
    check_roundtrip_with(VSGL_EXR_HALF, VSGL_EXR_B44A, 0.15);
}

VT_TEST(exr_float_roundtrip_reads_back_exactly_with_openexr_core)
{
    check_roundtrip(VSGL_EXR_FLOAT, 0.0);
}

VT_TEST(exr_half_roundtrip_reads_back_with_openexr_core)
{
    /* The pattern values are multiples of 1/8 below 64: exact in half. */
    check_roundtrip(VSGL_EXR_HALF, 0.0);
}

VT_TEST(exr_half_rounding_and_clamping_match_openexr)
{
    /* Values chosen across the half range; OpenEXR's decoder converts back. */
    static const float v[] = {0.0f, -0.0f, 1.0f, 0.1f, 1.0f / 3.0f, 65504.0f, 65519.0f, 65520.0f, 1e6f, -1e30f,
                              6.1035156e-05f, 5.9604645e-08f, 2.9802322e-08f, 1e-9f, 3.14159265f, -2.71828f};
    enum { N = sizeof v / sizeof v[0] };
    /* want: round-to-nearest-even in half, clamped to +/-65504 */
    static const float want[N] = {0.0f, -0.0f, 1.0f, 0.0999755859375f, 0.333251953125f, 65504.0f, 65504.0f, 65504.0f, 65504.0f, -65504.0f,
                                  6.1035156e-05f, 5.9604645e-08f, 0.0f, 0.0f, 3.140625f, -2.71875f};
    char dir[64], path[128];
    make_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/h.exr", dir);
    vsgl_exr_pass pass;
    memset(&pass, 0, sizeof pass);
    pass.name = "Test";
    pass.channels = "V";
    pass.data[0] = v;
    vsgl_exr_options opt;
    memset(&opt, 0, sizeof opt);
    opt.pixel_type = VSGL_EXR_HALF;
    opt.compression = VSGL_EXR_NONE;
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    VT_CHECK(vsgl_exr_write(ctx, path, N, 1, &pass, 1, &opt) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    decoded d;
    VT_CHECK(decode_exr(path, &d) == 0 && d.count == 1, "decode");
    if (d.count == 1)
        for (int i = 0; i < N; ++i)
            VT_CHECK(memcmp(&d.planes[0][i], &want[i], 4) == 0, "in %.9g: half %.9g want %.9g", v[i], d.planes[0][i], want[i]);
    free_decoded(&d);
    vsgl_context_destroy(ctx);
    remove_tree(dir);
}

VT_TEST(exr_oiiotool_sees_channel_names_and_values)
{
    if (!have_tool("oiiotool")) {
        printf("    SKIP: oiiotool not installed (apt-get install openimageio-tools)\n");
        return;
    }
    char dir[64], path[128], cmd[512];
    static char out[1 << 20];
    make_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/o.exr", dir);
    static image im;
    fill(&im);
    vsgl_render_output o = output_of(&im);
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    VT_CHECK(vsgl_exr_write_render(ctx, path, &o, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    snprintf(cmd, sizeof cmd, "oiiotool --info -v '%s' 2>&1", path);
    VT_CHECK(run_capture(cmd, out, sizeof out) == 0, "%s failed: %s", cmd, out);
    VT_CHECK(strstr(out, "37 x   23, 10 channel, float openexr") != NULL, "oiiotool header line: %.300s", out);
    /* OpenImageIO lists each pass's channels in RGBA order */
    VT_CHECK(strstr(out, "channel list: VSGL.Combined.R, VSGL.Combined.G, VSGL.Combined.B, VSGL.Combined.A, VSGL.DiffInd.R, "
                         "VSGL.DiffInd.G, VSGL.DiffInd.B, VSGL.GlossInd.R, VSGL.GlossInd.G, VSGL.GlossInd.B") != NULL,
             "channel list in: %.600s", out);
    VT_CHECK(strstr(out, "compression: \"zip\"") != NULL, "compression in: %.600s", out);
    /* Pixel values: oiiotool's dump of pixel (5, 7) of every channel. */
    snprintf(cmd, sizeof cmd, "oiiotool --dumpdata '%s' 2>&1", path);
    VT_CHECK(run_capture(cmd, out, sizeof out) == 0, "%s failed: %s", cmd, out);
    const char *line = strstr(out, "Pixel (5, 7):");
    VT_CHECK(line != NULL, "no pixel line in: %.500s", out);
    if (line) {
        /* channel order as oiiotool lists it: Combined R G B A, DiffInd R G B, GlossInd R G B */
        const int pc[10][2] = {{2, 0}, {2, 1}, {2, 2}, {2, 3}, {0, 0}, {0, 1}, {0, 2}, {1, 0}, {1, 1}, {1, 2}};
        const char *s = line + strlen("Pixel (5, 7):");
        for (int i = 0; i < 10; ++i) {
            char *end;
            double got = strtod(s, &end);
            VT_CHECK(end != s, "channel %d unparsable in: %s", i, line);
            VT_CHECK_ABS(got, pattern(pc[i][0], pc[i][1], 5, 7), 1e-6, "channel %d at (5, 7) from: %.200s", i, line);
            s = end;
        }
    }
    vsgl_context_destroy(ctx);
    remove_tree(dir);
}

/* ---- Blender ------------------------------------------------------------ */

VT_TEST(exr_blender_loads_multilayer_with_one_socket_per_pass)
{
    if (getenv("VSGL_TEST_QUICK")) {
        printf("    SKIP: VSGL_TEST_QUICK is set (Blender start-up takes seconds)\n");
        return;
    }
    if (!have_tool("blender")) {
        printf("    SKIP: blender not installed; cannot check the Image node sockets\n");
        return;
    }
    char dir[64], path[128], script[128], cmd[1024];
    static char out[65536];
    make_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/b.exr", dir);
    snprintf(script, sizeof script, "%s/check.py", dir);
    static image im;
    fill(&im);
    static float dcol[W * H * 3], gcol[W * H * 3], diff[W * H * 3], gloss[W * H * 3];
    vsgl_render_output o = output_of(&im);
    o.diffuse_color = dcol;
    o.glossy_color = gcol;
    o.diffuse = diff;
    o.glossy = gloss;
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    VT_CHECK(vsgl_exr_write_render(ctx, path, &o, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    FILE *f = fopen(script, "w");
    fputs("import bpy, sys\n"
          "path = sys.argv[sys.argv.index('--') + 1]\n"
          "img = bpy.data.images.load(path)\n"
          "img.reload()\n"
          "_ = img.size[0]\n"
          "scene = bpy.context.scene\n"
          "scene.use_nodes = True\n"
          "node = scene.node_tree.nodes.new('CompositorNodeImage')\n"
          "node.image = img\n"
          "print('VSGLTYPE', img.type)\n"
          "print('VSGLLAYER', node.layer)\n"
          "print('VSGLSOCKETS', ','.join(s.name for s in node.outputs if s.enabled))\n",
          f);
    fclose(f);
    snprintf(cmd, sizeof cmd, "blender -b --factory-startup --python-exit-code 1 --python '%s' -- '%s' 2>&1", script, path);
    int rc = run_capture(cmd, out, sizeof out);
    VT_CHECK(rc == 0, "blender exit %d: %.2000s", rc, out);
    VT_CHECK(strstr(out, "VSGLTYPE MULTILAYER") != NULL, "image type: %.2000s", out);
    VT_CHECK(strstr(out, "VSGLLAYER VSGL") != NULL, "node layer: %.2000s", out);
    const char *sock = strstr(out, "VSGLSOCKETS ");
    VT_CHECK(sock != NULL, "no socket line: %.2000s", out);
    if (sock) {
        static const char *const want[] = {"Combined", "Alpha", "DiffInd", "GlossInd", "DiffCol", "GlossCol", "Diff", "Gloss"};
        char line[1024];
        sscanf(sock + strlen("VSGLSOCKETS "), "%1023s", line);
        for (size_t i = 0; i < sizeof want / sizeof want[0]; ++i) {
            char tok[64];
            snprintf(tok, sizeof tok, ",%s,", want[i]);
            char padded[1100];
            snprintf(padded, sizeof padded, ",%s,", line);
            VT_CHECK(strstr(padded, tok) != NULL, "socket %s missing from %s", want[i], line);
        }
    }
    vsgl_context_destroy(ctx);
    remove_tree(dir);
}

/* ---- invalid input ------------------------------------------------------ */

VT_TEST(exr_refuses_non_finite_samples_naming_pass_and_pixel)
{
    char dir[64], path[128];
    make_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/nan.exr", dir);
    static image im;
    fill(&im);
    im.rgb[1][(7 * W + 3) * 3 + 1] = NAN;
    vsgl_render_output o = output_of(&im);
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    vsgl_result r = vsgl_exr_write_render(ctx, path, &o, NULL);
    VT_CHECK(r == VSGL_ERROR_INVALID_ARGUMENT, "result %d", r);
    VT_CHECK(strcmp(vsgl_context_last_error(ctx), "pass GlossInd channel G pixel (3, 7): NaN") == 0, "message '%s'",
             vsgl_context_last_error(ctx));
    im.rgb[1][(7 * W + 3) * 3 + 1] = 0;
    im.alpha[W * H - 1] = -INFINITY;
    r = vsgl_exr_write_render(ctx, path, &o, NULL);
    VT_CHECK(r == VSGL_ERROR_INVALID_ARGUMENT && strcmp(vsgl_context_last_error(ctx), "pass Combined channel A pixel (36, 22): -Inf") == 0,
             "result %d message '%s'", r, vsgl_context_last_error(ctx));
    VT_CHECK(count_entries(dir) == 0, "no file may be created, found %d entries", count_entries(dir));
    vsgl_context_destroy(ctx);
    remove_tree(dir);
}

VT_TEST(exr_refuses_bad_arguments_with_messages)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    float px[12] = {0};
    vsgl_exr_pass p;
    memset(&p, 0, sizeof p);
    p.name = "DiffInd";
    p.data[0] = px; p.data[1] = px + 1; p.data[2] = px + 2;
    vsgl_exr_pass two[2] = {p, p};
    vsgl_exr_options bad_layer;
    memset(&bad_layer, 0, sizeof bad_layer);
    bad_layer.layer = "View.Layer";
    vsgl_exr_pass dotted = p;
    dotted.name = "Diff.Ind";
    vsgl_exr_pass nulldata = p;
    nulldata.data[2] = NULL;
    vsgl_exr_pass dup = p;
    dup.channels = "RGR";
    vsgl_exr_metadata md = {"compression", "none"};
    vsgl_exr_options bad_md;
    memset(&bad_md, 0, sizeof bad_md);
    bad_md.metadata = &md;
    bad_md.metadata_count = 1;
    struct { const char *what; vsgl_result r; const char *msg; } cases[] = {
        {"zero width", vsgl_exr_write(ctx, "/tmp/x.exr", 0, 2, &p, 1, NULL), "width and height"},
        {"no passes", vsgl_exr_write(ctx, "/tmp/x.exr", 2, 2, &p, 0, NULL), "passes"},
        {"dotted layer", vsgl_exr_write(ctx, "/tmp/x.exr", 2, 2, &p, 1, &bad_layer), "layer name 'View.Layer'"},
        {"dotted pass", vsgl_exr_write(ctx, "/tmp/x.exr", 2, 2, &dotted, 1, NULL), "name 'Diff.Ind'"},
        {"duplicate pass", vsgl_exr_write(ctx, "/tmp/x.exr", 2, 2, two, 2, NULL), "used twice"},
        {"NULL channel", vsgl_exr_write(ctx, "/tmp/x.exr", 2, 2, &nulldata, 1, NULL), "channel B has NULL data"},
        {"repeated letter", vsgl_exr_write(ctx, "/tmp/x.exr", 2, 2, &dup, 1, NULL), "distinct letters"},
        {"reserved metadata", vsgl_exr_write(ctx, "/tmp/vsgl_exr_reserved_md.exr", 2, 2, &p, 1, &bad_md), "standard attribute"},
        {"empty path", vsgl_exr_write(ctx, "", 2, 2, &p, 1, NULL), "empty"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i)
        VT_CHECK(cases[i].r == VSGL_ERROR_INVALID_ARGUMENT, "%s: result %d", cases[i].what, cases[i].r);
    /* Messages are checked one call at a time (the context keeps the last). */
    const char *want[] = {"width and height", "layer name 'View.Layer'", "channel B has NULL data", "standard attribute"};
    vsgl_exr_write(ctx, "/tmp/x.exr", 0, 2, &p, 1, NULL);
    VT_CHECK(strstr(vsgl_context_last_error(ctx), want[0]), "'%s'", vsgl_context_last_error(ctx));
    vsgl_exr_write(ctx, "/tmp/x.exr", 2, 2, &p, 1, &bad_layer);
    VT_CHECK(strstr(vsgl_context_last_error(ctx), want[1]), "'%s'", vsgl_context_last_error(ctx));
    vsgl_exr_write(ctx, "/tmp/x.exr", 2, 2, &nulldata, 1, NULL);
    VT_CHECK(strstr(vsgl_context_last_error(ctx), want[2]), "'%s'", vsgl_context_last_error(ctx));
    vsgl_exr_write(ctx, "/tmp/vsgl_exr_reserved_md.exr", 2, 2, &p, 1, &bad_md);
    VT_CHECK(strstr(vsgl_context_last_error(ctx), want[3]), "'%s'", vsgl_context_last_error(ctx));
    struct stat st;
    VT_CHECK(stat("/tmp/vsgl_exr_reserved_md.exr", &st) != 0, "a refused write must not leave a file");
    vsgl_context_destroy(ctx);
}

/* ---- I/O failures and atomicity ----------------------------------------- */

VT_TEST(exr_io_failures_name_the_path_and_leave_no_files)
{
    char dir[64], path[256];
    make_temp_dir(dir, sizeof dir);
    static image im;
    fill(&im);
    vsgl_render_output o = output_of(&im);
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);

    snprintf(path, sizeof path, "%s/missing/out.exr", dir);
    vsgl_result r = vsgl_exr_write_render(ctx, path, &o, NULL);
    VT_CHECK(r == VSGL_ERROR_IO && strstr(vsgl_context_last_error(ctx), "No such file or directory"), "missing dir: %d '%s'", r,
             vsgl_context_last_error(ctx));
    VT_CHECK(vsgl_check_output_path(ctx, path) == VSGL_ERROR_IO, "check: missing dir");

    snprintf(path, sizeof path, "%s/adir", dir);
    mkdir(path, 0755);
    r = vsgl_exr_write_render(ctx, path, &o, NULL);
    VT_CHECK(r == VSGL_ERROR_IO && strstr(vsgl_context_last_error(ctx), "is a directory"), "directory: %d '%s'", r,
             vsgl_context_last_error(ctx));
    VT_CHECK(vsgl_check_output_path(ctx, path) == VSGL_ERROR_IO, "check: directory");
    VT_CHECK(count_entries(path) == 0, "nothing created inside %s", path);

    snprintf(path, sizeof path, "%s/afile", dir);
    FILE *f = fopen(path, "w");
    fclose(f);
    snprintf(path, sizeof path, "%s/afile/out.exr", dir);
    r = vsgl_exr_write_render(ctx, path, &o, NULL);
    VT_CHECK(r == VSGL_ERROR_IO && strstr(vsgl_context_last_error(ctx), "ot a directory"), "under a file: %d '%s'", r,
             vsgl_context_last_error(ctx));

    snprintf(path, sizeof path, "%s/ok.exr", dir);
    VT_CHECK(vsgl_check_output_path(ctx, path) == VSGL_OK, "check ok: %s", vsgl_context_last_error(ctx));
    VT_CHECK(count_entries(dir) == 2, "check_output_path leaves nothing behind: %d entries", count_entries(dir));
    vsgl_context_destroy(ctx);
    remove_tree(dir);
}

/* In a child: optionally drop root, limit the file size, write; exit with the result. */
static int write_in_child(const char *path, const vsgl_render_output *o, rlim_t fsize, int drop_root)
{
    pid_t pid = fork();
    if (pid == 0) {
        if (drop_root && geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0))
            _exit(100);
        if (fsize) {
            signal(SIGXFSZ, SIG_IGN);
            struct rlimit rl = {fsize, fsize};
            setrlimit(RLIMIT_FSIZE, &rl);
        }
        vsgl_context *ctx = NULL;
        vsgl_context_create(NULL, &ctx);
        vsgl_result r = vsgl_exr_write_render(ctx, path, o, NULL);
        if (r)
            fprintf(stderr, "    (child, expected failure: %s)\n", vsgl_context_last_error(ctx));
        _exit((int)r);
    }
    int st = 0;
    waitpid(pid, &st, 0);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

VT_TEST(exr_failed_write_keeps_previous_file_and_deletes_temp)
{
    char dir[64], path[128];
    make_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/keep.exr", dir);
    static image im;
    fill(&im);
    vsgl_render_output o = output_of(&im);
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    VT_CHECK(vsgl_exr_write_render(ctx, path, &o, NULL) == VSGL_OK, "first write: %s", vsgl_context_last_error(ctx));
    unsigned char *before = NULL, *after = NULL;
    size_t nb = 0, na = 0;
    read_file(path, &before, &nb);

    /* A different image whose write fails part way (file size limit 1 KiB). */
    for (int i = 0; i < W * H * 3; ++i)
        im.rgb[0][i] = (float)i * 1.37f;
    int rc = write_in_child(path, &o, 1024, 0);
    VT_CHECK(rc == VSGL_ERROR_IO, "write over the size limit: exit %d, want %d", rc, VSGL_ERROR_IO);
    read_file(path, &after, &na);
    VT_CHECK(nb > 1024 && na == nb && before && after && memcmp(before, after, nb) == 0, "previous file changed: %zu -> %zu bytes", nb, na);
    VT_CHECK(count_entries(dir) == 1, "temporary file left: %d entries in %s", count_entries(dir), dir);
    free(after);

    /* A directory the writer may not write into (as nobody when run as root). */
    char ro[128], ropath[160];
    snprintf(ro, sizeof ro, "%s/ro", dir);
    mkdir(ro, 0755);
    snprintf(ropath, sizeof ropath, "%s/x.exr", ro);
    chmod(ro, 0555);
    chmod(dir, 0755);
    rc = write_in_child(ropath, &o, 0, 1);
    VT_CHECK(rc == VSGL_ERROR_IO, "unwritable directory: exit %d", rc);
    VT_CHECK(count_entries(ro) == 0, "nothing created in %s", ro);

    /* A successful second write replaces the file completely. */
    VT_CHECK(vsgl_exr_write_render(ctx, path, &o, NULL) == VSGL_OK, "second write: %s", vsgl_context_last_error(ctx));
    decoded d;
    VT_CHECK(decode_exr(path, &d) == 0, "decode");
    int k = channel_index(&d, "VSGL.DiffInd.G");
    VT_CHECK(k >= 0 && d.planes[k][5] == (float)(5 * 3 + 1) * 1.37f, "new value at pixel 5: %g", k >= 0 ? d.planes[k][5] : -1.0);
    free_decoded(&d);
    free(before);
    vsgl_context_destroy(ctx);
    remove_tree(dir);
}

/* Issue 10: `kill -9` during a write left `.NAME.tmp-*` files that no later
 * run removed. The next write into the folder deletes this host's temporary
 * files whose process is gone, and logs each; live writers', other hosts'
 * and unrelated files stay. */

static void this_host(char *buf, size_t n)
{
    char h[256] = {0};
    gethostname(h, sizeof h - 1);
    size_t k = 0;
    for (const char *p = h; *p && k + 1 < n && k < 63; ++p)
        buf[k++] = ((*p >= 'A' && *p <= 'Z') || (*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') || *p == '.') ? *p : '_';
    buf[k] = '\0';
}

static void touch(const char *dir, const char *name, size_t bytes)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    for (size_t i = 0; f && i < bytes; ++i)
        fputc('x', f);
    if (f)
        fclose(f);
}

static int exists_in(const char *dir, const char *name)
{
    char path[512];
    struct stat st;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return stat(path, &st) == 0;
}

VT_TEST(exr_write_removes_stale_temp_files_of_dead_writers)
{
    char dir[64], path[128], host[64];
    make_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/frame.exr", dir);
    this_host(host, sizeof host);
    pid_t child = fork();
    if (child == 0)
        _exit(0);
    waitpid(child, NULL, 0); /* its pid is now gone */
    char dead[160], dead_old[160], alive[160], other[160], unrelated[] = ".frame.exr.tmp-notapid";
    snprintf(dead, sizeof dead, ".frame.exr.tmp-%ld-000000123-0-%s", (long)child, host);
    snprintf(dead_old, sizeof dead_old, ".other.exr.tmp-%ld-000000456-1", (long)child); /* before host tags */
    snprintf(alive, sizeof alive, ".frame.exr.tmp-%ld-000000789-0-%s", (long)getppid(), host);
    snprintf(other, sizeof other, ".frame.exr.tmp-%ld-000000001-0-%s", (long)child, "some-other-host");
    touch(dir, dead, 5000);
    touch(dir, dead_old, 10);
    touch(dir, alive, 10);
    touch(dir, other, 10);
    touch(dir, unrelated, 10);
    vt_warnings w;
    memset(&w, 0, sizeof w);
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.log = vt_capture_warnings;
    cd.log_user = &w;
    vsgl_context *ctx = NULL;
    vsgl_context_create(&cd, &ctx);
    static image im;
    fill(&im);
    vsgl_render_output o = output_of(&im);
    VT_CHECK(vsgl_exr_write_render(ctx, path, &o, NULL) == VSGL_OK, "write: %s", vsgl_context_last_error(ctx));
    VT_CHECK(!exists_in(dir, dead) && !exists_in(dir, dead_old), "stale temp files kept");
    VT_CHECK(exists_in(dir, alive) && exists_in(dir, other) && exists_in(dir, unrelated),
             "a live writer's, another host's or an unrelated file was removed");
    VT_CHECK(w.n == 2 && strstr(w.text, dead) && strstr(w.text, "(5000 bytes) left by an interrupted write of process") &&
                 strstr(w.text, "which is gone"), "%d warnings: %s", w.n, w.text);
    long pid = 0;
    int ours = 0;
    VT_CHECK(vsgl__atomic_temp_owner(other, host, &pid, &ours) == 1 && pid == (long)child && !ours, "parse other");
    VT_CHECK(vsgl__atomic_temp_owner("frame.exr", host, &pid, &ours) == 0 &&
                 vsgl__atomic_temp_owner(".a.tmp-12-x-0", host, &pid, &ours) == 0, "parse junk");
    vsgl_context_destroy(ctx);
    remove_tree(dir);
}

/* Issue 10: SIGINT during a long EXR write was ignored (the CLI wrote on,
 * exited 0 and replaced the file). The writer asks the progress callback
 * between batches of chunks; a cancel keeps the previous file. */
typedef struct cancel_state { int calls, write_calls; } cancel_state;
static int32_t cancel_in_write(void *user, const char *stage, float fraction)
{
    cancel_state *c = user;
    (void)fraction;
    ++c->calls;
    if (stage && strcmp(stage, "write") == 0)
        return ++c->write_calls >= 2; /* let the first batch through */
    return 0;
}

VT_TEST(exr_write_is_cancelled_by_the_progress_callback)
{
    char dir[64], path[128];
    make_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/big.exr", dir);
    enum { BW = 256, BH = 512 };
    float *plane = calloc((size_t)BW * BH * 3, sizeof(float));
    vsgl_render_output o = blank_output(BW, BH);
    o.diffuse_light = o.glossy_light = o.combined = plane;
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    VT_CHECK(plane && vsgl_exr_write_render(ctx, path, &o, NULL) == VSGL_OK, "first write");
    vsgl_context_destroy(ctx);
    unsigned char *before = NULL, *after = NULL;
    size_t nb = 0, na = 0;
    read_file(path, &before, &nb);
    cancel_state c = {0, 0};
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.thread_count = 1;
    cd.progress = cancel_in_write;
    cd.progress_user = &c;
    vsgl_context_create(&cd, &ctx);
    for (size_t i = 0; plane && i < (size_t)BW * BH * 3; ++i)
        plane[i] = (float)i;
    vsgl_exr_options eo;
    memset(&eo, 0, sizeof eo);
    eo.compression = VSGL_EXR_ZIPS; /* one scanline per chunk: many batches */
    vsgl_result r = vsgl_exr_write_render(ctx, path, &o, &eo);
    VT_CHECK(r == VSGL_ERROR_CANCELLED, "result %d '%s' after %d write progress calls", r, vsgl_context_last_error(ctx),
             c.write_calls);
    read_file(path, &after, &na);
    VT_CHECK(nb > 0 && na == nb && before && after && memcmp(before, after, nb) == 0, "previous file changed");
    VT_CHECK(count_entries(dir) == 1, "temporary file left: %d entries", count_entries(dir));
    free(before);
    free(after);
    free(plane);
    vsgl_context_destroy(ctx);
    remove_tree(dir);
}

VT_TEST(exr_parallel_encoding_is_identical_for_any_thread_count)
{
    /* 300 rows = 19 ZIP chunks: more than one batch of parallel encoding. */
    enum { PW = 29, PH = 300 };
    static float px[PW * PH * 3];
    vt_rng rng = {99};
    for (int i = 0; i < PW * PH * 3; ++i)
        px[i] = (float)(vt_uniform(&rng) * 4.0);
    char dir[64];
    make_temp_dir(dir, sizeof dir);
    unsigned char *first = NULL;
    size_t first_n = 0;
    for (uint32_t threads = 1; threads <= 3; ++threads) {
        vsgl_context_desc cd;
        memset(&cd, 0, sizeof cd);
        cd.thread_count = threads;
        vsgl_context *ctx = NULL;
        vsgl_context_create(&cd, &ctx);
        vsgl_render_output o = blank_output(PW, PH);
        o.glossy_light = px;
        char path[128];
        snprintf(path, sizeof path, "%s/t%u.exr", dir, threads);
        VT_CHECK(vsgl_exr_write_render(ctx, path, &o, NULL) == VSGL_OK, "threads %u: %s", threads, vsgl_context_last_error(ctx));
        decoded d;
        VT_CHECK(decode_exr(path, &d) == 0 && d.count == 3, "decode threads %u", threads);
        int bad = 0;
        for (int c = 0; c < d.count; ++c) {
            int ch = rgb_index(d.names[c]);
            for (int i = 0; i < PW * PH && bad < 3; ++i)
                if (d.planes[c][i] != px[i * 3 + ch]) {
                    ++bad;
                    VT_CHECK(0, "threads %u %s pixel %d: %g want %g", threads, d.names[c], i, d.planes[c][i], px[i * 3 + ch]);
                }
        }
        free_decoded(&d);
        unsigned char *bytes = NULL;
        size_t n = 0;
        read_file(path, &bytes, &n);
        if (threads == 1) {
            first = bytes;
            first_n = n;
        } else {
            VT_CHECK(n == first_n && bytes && first && memcmp(bytes, first, n) == 0, "threads %u: file differs from 1 thread (%zu vs %zu bytes)",
                     threads, n, first_n);
            free(bytes);
        }
        vsgl_context_destroy(ctx);
    }
    free(first);
    remove_tree(dir);
}

VT_TEST(exr_render_combined_alpha_cases)
{
    enum { CW = 3, CH = 2 };
    float comb[CW * CH * 3], alpha[CW * CH];
    for (int i = 0; i < CW * CH * 3; ++i)
        comb[i] = 0.5f * (float)i;
    for (int i = 0; i < CW * CH; ++i)
        alpha[i] = 0.25f * (float)i;
    char dir[64], path[128];
    make_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/c.exr", dir);
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    vsgl_render_output o = blank_output(CW, CH);
    VT_CHECK(vsgl_exr_write_render(ctx, path, &o, NULL) == VSGL_ERROR_INVALID_ARGUMENT &&
                 strstr(vsgl_context_last_error(ctx), "no planes"), "no planes: '%s'", vsgl_context_last_error(ctx));
    /* Combined without alpha: A = 1. */
    o.combined = comb;
    VT_CHECK(vsgl_exr_write_render(ctx, path, &o, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    decoded d;
    VT_CHECK(decode_exr(path, &d) == 0 && d.count == 4, "decode: %d channels", d.count);
    int a = channel_index(&d, "VSGL.Combined.A"), g = channel_index(&d, "VSGL.Combined.G");
    for (int i = 0; i < CW * CH && a >= 0 && g >= 0; ++i) {
        VT_CHECK(d.planes[a][i] == 1.0f, "A at %d = %g", i, d.planes[a][i]);
        VT_CHECK(d.planes[g][i] == comb[3 * i + 1], "G at %d = %g want %g", i, d.planes[g][i], comb[3 * i + 1]);
    }
    free_decoded(&d);
    /* Alpha alone: a single channel VSGL.Combined.A. */
    o.combined = NULL;
    o.alpha = alpha;
    VT_CHECK(vsgl_exr_write_render(ctx, path, &o, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(decode_exr(path, &d) == 0 && d.count == 1 && strcmp(d.names[0], "VSGL.Combined.A") == 0, "alpha only: %d channels, %s",
             d.count, d.count ? d.names[0] : "-");
    for (int i = 0; i < CW * CH && d.count == 1; ++i)
        VT_CHECK(d.planes[0][i] == alpha[i], "alpha at %d = %g want %g", i, d.planes[0][i], alpha[i]);
    free_decoded(&d);
    vsgl_context_destroy(ctx);
    remove_tree(dir);
}

/* The ZIP tests' set-up: a temporary folder, a context and a render
 * output of w x h whose diffuse light is px. */
static vsgl_render_output zip_fixture(char *dir, size_t dir_size, vsgl_context **ctx, uint32_t w, uint32_t h,
                                      float *px)
{
    make_temp_dir(dir, dir_size);
    *ctx = NULL;
    vsgl_context_create(NULL, ctx);
    vsgl_render_output o = blank_output(w, h);
    o.diffuse_light = px;
    return o;
}

/* vsgl_exr_options.zip_level: lossless at every level (the pixels read back
 * by OpenEXR are the same), the default level's file of a smooth image is
 * no larger than level 1's and larger than 6's and 9's, 0 is the documented default
 * (the same bytes as VSGL_EXR_ZIP_LEVEL_DEFAULT), and 10 is refused by name. */
VT_TEST(exr_zip_level_is_lossless_and_trades_size)
{
    enum { ZW = 64, ZH = 96 };
    static float px[ZW * ZH * 3];
    for (int y = 0; y < ZH; ++y) /* smooth, with a little structure: what deflate's levels differ on */
        for (int x = 0; x < ZW; ++x)
            for (int c = 0; c < 3; ++c)
                px[(y * ZW + x) * 3 + c] = 0.2f + 0.5f * sinf(0.07f * (float)(x + 2 * c)) * cosf(0.05f * (float)y) +
                                           0.01f * (float)((x * 7 + y * 13) % 5);
    char dir[64];
    vsgl_context *ctx;
    vsgl_render_output o = zip_fixture(dir, sizeof dir, &ctx, ZW, ZH, px);
    const int32_t levels[5] = {1, VSGL_EXR_ZIP_LEVEL_DEFAULT, 6, 9, 0};
    size_t sizes[5] = {0};
    unsigned char *bytes[5] = {NULL};
    static decoded dec[5];
    for (int k = 0; k < 5; ++k) {
        vsgl_exr_options opt;
        memset(&opt, 0, sizeof opt);
        opt.size = sizeof opt;
        opt.pixel_type = VSGL_EXR_HALF;
        opt.compression = VSGL_EXR_ZIP;
        opt.zip_level = levels[k];
        char path[128];
        snprintf(path, sizeof path, "%s/z%d.exr", dir, k);
        VT_REQUIRE(vsgl_exr_write_render(ctx, path, &o, &opt) == VSGL_OK, "level %d: %s", levels[k],
                   vsgl_context_last_error(ctx));
        decoded *d = &dec[k];
        VT_REQUIRE(decode_exr(path, d) == 0 && d->count == 3, "decode level %d", levels[k]);
        int bad = 0; /* half precision of what was written, and bit for bit level 1's pixels */
        for (int c = 0; c < d->count; ++c) {
            const int ch = rgb_index(d->names[c]);
            for (int i = 0; i < ZW * ZH && !bad; ++i)
                bad = fabsf(d->planes[c][i] - px[i * 3 + ch]) > 1e-3f * fabsf(px[i * 3 + ch]) + 1e-6f ||
                      d->planes[c][i] != dec[0].planes[c][i];
        }
        VT_CHECK(!bad, "level %d: pixels differ from the half values written or from level 1's", levels[k]);
        read_file(path, &bytes[k], &sizes[k]);
    }
    /* (deflate's levels are not strictly ordered: 9 may write a byte more than 6) */
    VT_CHECK(sizes[1] <= sizes[0] && sizes[2] < sizes[1] && sizes[3] < sizes[1],
             "file sizes by level 1 / %d / 6 / 9: %zu / %zu / %zu / %zu", VSGL_EXR_ZIP_LEVEL_DEFAULT, sizes[0], sizes[1],
             sizes[2], sizes[3]);
    VT_CHECK(sizes[4] == sizes[1] && bytes[4] && bytes[1] && memcmp(bytes[4], bytes[1], sizes[1]) == 0,
             "level 0 is not the default level %d (%zu vs %zu bytes)", VSGL_EXR_ZIP_LEVEL_DEFAULT, sizes[4], sizes[1]);
    for (int k = 0; k < 5; ++k) {
        free(bytes[k]);
        free_decoded(&dec[k]);
    }
    vsgl_exr_options bad;
    memset(&bad, 0, sizeof bad);
    bad.size = sizeof bad;
    bad.zip_level = 10;
    char path[128];
    snprintf(path, sizeof path, "%s/bad.exr", dir);
    char want[64];
    snprintf(want, sizeof want, "EXR zip level 10 is not 1..9 (0 = %d)", VSGL_EXR_ZIP_LEVEL_DEFAULT);
    VT_CHECK(vsgl_exr_write_render(ctx, path, &o, &bad) == VSGL_ERROR_INVALID_ARGUMENT &&
                 strstr(vsgl_context_last_error(ctx), want),
             "zip level 10: %s", vsgl_context_last_error(ctx));
    vsgl_context_destroy(ctx);
    remove_tree(dir);
}

/* A chunk deflate cannot shrink (float noise: every mantissa bit random)
 * is stored as its packed bytes, which OpenEXR reads as uncompressed: the
 * file is about the raw size and reads back exactly, ZIP and ZIPS alike. */
VT_TEST(exr_zip_stores_incompressible_chunks_as_packed)
{
    enum { NW = 40, NH = 37 }; /* a last ZIP chunk of 5 lines */
    static float px[NW * NH * 3];
    uint32_t h = 12345u;
    for (int i = 0; i < NW * NH * 3; ++i) {
        h = h * 1664525u + 1013904223u;
        uint32_t b = 0x3f800000u | (h >> 9); /* [1, 2): 23 random mantissa bits */
        memcpy(&px[i], &b, sizeof b);
    }
    char dir[64];
    vsgl_context *ctx;
    vsgl_render_output o = zip_fixture(dir, sizeof dir, &ctx, NW, NH, px);
    const int32_t comp[2] = {VSGL_EXR_ZIP, VSGL_EXR_ZIPS};
    for (int k = 0; k < 2; ++k) {
        vsgl_exr_options opt;
        memset(&opt, 0, sizeof opt);
        opt.size = sizeof opt;
        opt.pixel_type = VSGL_EXR_FLOAT;
        opt.compression = comp[k];
        char path[128];
        snprintf(path, sizeof path, "%s/noise%d.exr", dir, k);
        VT_REQUIRE(vsgl_exr_write_render(ctx, path, &o, &opt) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
        unsigned char *bytes = NULL;
        size_t size = 0;
        read_file(path, &bytes, &size);
        VT_CHECK(size >= (size_t)NW * NH * 3 * 4, "compression %d: %zu bytes, below the raw %d", comp[k], size,
                 NW * NH * 3 * 4);
        free(bytes);
        decoded d;
        VT_REQUIRE(decode_exr(path, &d) == 0 && d.count == 3, "decode compression %d", comp[k]);
        int bad = 0;
        for (int c = 0; c < d.count; ++c) {
            const int ch = rgb_index(d.names[c]);
            for (int i = 0; i < NW * NH && !bad; ++i)
                bad = d.planes[c][i] != px[i * 3 + ch];
        }
        VT_CHECK(!bad, "compression %d: the pixels read back differ", comp[k]);
        free_decoded(&d);
    }
    vsgl_context_destroy(ctx);
    remove_tree(dir);
}

/* An exact reference for the writer's float -> half packing: the finite
 * half nearest to v (ties to the even code), from every half's exact value
 * (decoded here by its definition), clamped to +/-65504. */
static double half_value(uint16_t h)
{
    int e = (h >> 10) & 31, m = h & 1023;
    double v = e ? ldexp(1.0 + m / 1024.0, e - 15) : ldexp(m / 1024.0, -14);
    return h & 0x8000u ? -v : v;
}

static uint16_t half_nearest(float v)
{
    /* the positive finite codes 0 .. 0x7bff increase with their value: the
     * largest code at or below |v|, then it or the next, whichever is
     * nearer, the even one on a tie */
    const double a = fabs((double)v);
    uint16_t lo = 0, hi = 0x7bff;
    if (a >= half_value(hi)) {
        lo = hi;
    } else {
        while (hi - lo > 1) { /* half_value(lo) <= a < half_value(hi) */
            uint16_t mid = (uint16_t)((lo + hi) / 2);
            if (half_value(mid) <= a)
                lo = mid;
            else
                hi = mid;
        }
        double dl = a - half_value(lo), dh = half_value(hi) - a;
        if (dh < dl || (dh == dl && (hi & 1u) == 0))
            lo = hi;
    }
    return (uint16_t)(lo | (signbit(v) ? 0x8000u : 0u));
}

/* vsgl__exr_row_to_half: the F16C form (where the CPU has it) and the
 * scalar one give the same bits, the nearest half (ties to even), across
 * the range: normals, subnormals, ties, signed zeros, values past 65504,
 * strided rows and a tail that is not a multiple of 8. */
VT_TEST(exr_half_conversion_matches_exact_rounding)
{
    enum { NV = 1003 };
    static float v[NV * 3];
    vt_rng rng = {7};
    for (int i = 0; i < NV; ++i) {
        double u = vt_uniform(&rng);
        float x;
        if (i % 7 == 0) /* an exact tie between two halves of magnitude ~2^k */
            x = (float)((1.0 + (2.0 * (i % 1024) + 1.0) / 2048.0) * ldexp(1.0, i % 30 - 15));
        else
            x = (float)(exp(-30.0 + 43.0 * u)); /* 1e-13 .. 5e5 */
        v[i * 3] = i % 2 ? -x : x;
        v[i * 3 + 1] = i % 11 == 0 ? (i % 2 ? -0.0f : 0.0f) : (float)(u * 70000.0 - 35000.0);
        v[i * 3 + 2] = (float)ldexp(u, -20); /* subnormal halves */
    }
    static unsigned char vec[NV * 2], sca[NV * 2];
    const int f16c = vsgl__exr_cpu_has_f16c();
    int bad = 0;
    for (int c = 0; c < 3 && bad < 5; ++c) {
        vsgl__exr_row_to_half(v + c, 3, NV, vec, f16c);
        vsgl__exr_row_to_half(v + c, 3, NV, sca, 0);
        for (int i = 0; i < NV && bad < 5; ++i) {
            uint16_t a, b, want = half_nearest(v[i * 3 + c]);
            memcpy(&a, vec + 2 * i, 2);
            memcpy(&b, sca + 2 * i, 2);
            if (a != want || b != want) {
                ++bad;
                VT_CHECK(0, "%.9g: vector 0x%04x, scalar 0x%04x, nearest 0x%04x", (double)v[i * 3 + c], a, b, want);
            }
        }
    }
    /* contiguous rows take the vector form's unit-stride load */
    static float flat[NV];
    for (int i = 0; i < NV; ++i)
        flat[i] = v[i * 3];
    vsgl__exr_row_to_half(flat, 1, NV, vec, f16c);
    vsgl__exr_row_to_half(v, 3, NV, sca, f16c);
    VT_CHECK(memcmp(vec, sca, sizeof vec) == 0, "a unit-stride row packs differently from the same values strided");
}
