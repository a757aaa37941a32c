/* Scene bundle: round trips (checked against an independent Python reader
 * of docs/bundle-format.md), and every kind of bad file. The bad-file tests
 * are meant to run under ASan/UBSan (make asan): the reader must never read
 * out of bounds or allocate by an untrusted count. */
#include "harness.h"
#include "vsgl.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

/* ---- an independent CRC32 (bitwise, reflected 0xEDB88320) ---------------- */

static uint32_t ref_crc32(uint32_t crc, const unsigned char *p, size_t n)
{
    crc = ~crc;
    for (size_t i = 0; i < n; ++i) {
        crc ^= p[i];
        for (int k = 0; k < 8; ++k)
            crc = (crc >> 1) ^ (0xEDB88320u & (uint32_t)-(int32_t)(crc & 1u));
    }
    return ~crc;
}

static uint32_t rd32(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static void wr32(unsigned char *p, uint32_t v) { p[0] = (unsigned char)v; p[1] = (unsigned char)(v >> 8); p[2] = (unsigned char)(v >> 16); p[3] = (unsigned char)(v >> 24); }
static uint64_t rd64(const unsigned char *p) { return rd32(p) | (uint64_t)rd32(p + 4) << 32; }
static void wr64(unsigned char *p, uint64_t v) { wr32(p, (uint32_t)v); wr32(p + 4, (uint32_t)(v >> 32)); }

/* Offset of the section with this tag, or 0. */
static size_t find_section(const unsigned char *b, size_t n, const char *tag)
{
    size_t at = rd32(b + 16);
    uint32_t ns = rd32(b + 20);
    for (uint32_t i = 0; i < ns && at + 24 <= n; ++i) {
        if (memcmp(b + at, tag, 4) == 0)
            return at;
        uint64_t bytes = rd32(b + at + 4) * rd64(b + at + 8);
        at += 24 + ((bytes + 7) & ~7ull);
    }
    return 0;
}

/* Recompute a section's CRC (after editing it) and the header's. */
static void fix_crcs(unsigned char *b, size_t sec)
{
    if (sec) {
        uint64_t bytes = rd32(b + sec + 4) * rd64(b + sec + 8);
        wr32(b + sec + 20, ref_crc32(ref_crc32(0, b + sec, 20), b + sec + 24, (size_t)bytes));
    }
    uint32_t hs = rd32(b + 16);
    wr32(b + hs - 4, ref_crc32(0, b, hs - 4));
}

/* ---- a test scene ------------------------------------------------------- */

enum { NV = 7, NT = 5, NM = 2, NL = 3 };

typedef struct test_scene {
    float pos[NV * 3];
    uint32_t idx[NT * 3];
    float nrm[NT * 9], uv[NT * 6], tan[NT * 12];
    uint32_t midx[NT];
    vsgl_material mat[NM];
    vsgl_light light[NL];
    vsgl_camera cam;
    vsgl_scene_desc desc;
    vsgl_render_settings settings;
} test_scene;

static void make_scene(test_scene *s, unsigned seed)
{
    memset(s, 0, sizeof *s);
    vt_rng r = {seed};
    for (int i = 0; i < NV * 3; ++i) s->pos[i] = (float)(vt_uniform(&r) * 20 - 10);
    for (int i = 0; i < NT * 3; ++i) s->idx[i] = (uint32_t)(vt_next(&r) % NV);
    for (int i = 0; i < NT * 9; ++i) s->nrm[i] = (float)(vt_uniform(&r) * 2 - 1);
    for (int i = 0; i < NT * 6; ++i) s->uv[i] = (float)vt_uniform(&r);
    for (int i = 0; i < NT * 12; ++i) s->tan[i] = (float)(vt_uniform(&r) * 2 - 1);
    for (int i = 0; i < NT; ++i) s->midx[i] = (uint32_t)(vt_next(&r) % NM);
    for (int m = 0; m < NM; ++m) {
        s->mat[m].base_color[0] = 0.8f; s->mat[m].base_color[1] = 0.5f * (float)m; s->mat[m].base_color[2] = 0.1f;
        s->mat[m].roughness = 0.25f + 0.5f * (float)m; s->mat[m].specular_f0 = 0.04f; s->mat[m].metallic = (float)m;
        s->mat[m].anisotropy = 0.125f; s->mat[m].anisotropic_rotation = 0.5f; s->mat[m].flags = (uint32_t)m;
    }
    for (int l = 0; l < NL; ++l) {
        vsgl_light *L = &s->light[l];
        L->type = l; L->area_shape = VSGL_AREA_DISK; L->color[0] = 1; L->color[1] = 0.9f; L->color[2] = 0.8f;
        L->power = 100.0f * (float)(l + 1);
        for (int k = 0; k < 12; ++k) L->world_from_light[k] = (k % 5 == 0) ? 1.0f : (float)k * 0.1f;
        L->radius = 0.1f; L->spot_size = 0.785398f; L->spot_blend = 0.15f; L->sun_angle = 0.00918f;
        L->size_x = 1; L->size_y = 2; L->spread = 3.14159265f;
    }
    s->cam.type = VSGL_CAMERA_PERSPECTIVE; s->cam.sensor_fit = VSGL_SENSOR_FIT_AUTO;
    for (int k = 0; k < 12; ++k) s->cam.world_from_camera[k] = (k % 5 == 0) ? 1.0f : 0.0f;
    s->cam.world_from_camera[11] = 5.0f;
    s->cam.lens_mm = 50; s->cam.sensor_width_mm = 36; s->cam.sensor_height_mm = 24; s->cam.ortho_scale = 6;
    s->cam.shift_x = 0.1f; s->cam.clip_start = 0.1f; s->cam.clip_end = 100; s->cam.width = 320; s->cam.height = 240;
    s->cam.pixel_aspect_x = 1; s->cam.pixel_aspect_y = 1;
    vsgl_scene_desc *d = &s->desc;
    d->size = sizeof *d;
    d->vertex_count = NV; d->positions = s->pos;
    d->triangle_count = NT; d->indices = s->idx;
    d->corner_normals = s->nrm; d->corner_uvs = s->uv; d->corner_tangents = s->tan; d->material_indices = s->midx;
    d->material_count = NM; d->materials = s->mat;
    d->light_count = NL; d->lights = s->light;
    d->camera = &s->cam;
    s->settings.size = sizeof s->settings;
    s->settings.method = VSGL_METHOD_VSGL;
    s->settings.aa_samples = 3;
    s->settings.rsm_resolution = 512;
    s->settings.fit_mode = VSGL_FIT_KMEANS;
    s->settings.vsgl_count = 128;
    s->settings.fis_iterations = 6;
    s->settings.sharpness_estimator = VSGL_SHARPNESS_BANERJEE;
    s->settings.diffuse_mode = VSGL_COSINE_PULLED_OUT;
    s->settings.glossy_mode = VSGL_GLOSSY_SG;
    s->settings.visibility = VSGL_VISIBILITY_RAY;
    s->settings.seed = 1234567;
    s->settings.shade_stride = 3; /* format 1.3 */
    s->settings.edge_samples = 6;
    s->settings.auto_target = VSGL_AUTO_BALANCED; /* format 1.4 */
    s->settings.mrp_min_area = 1.5f;               /* format 1.5 */
    s->settings.glossy_lobes = 5;                  /* format 1.6 */
    s->settings.visibility_budget = 0.1f;          /* format 1.7 */
    s->settings.aa_pixel_limit = 1000u;            /* format 1.8 */
    s->settings.stride_pixels = 2000u;             /* format 1.9 */
    s->settings.visibility_spread = 1.5f;          /* format 1.10 */
    s->settings.dominant_rays = 5u;                /* format 1.11 */
}

static int same_bytes(const void *a, const void *b, size_t n)
{
    if (!a || !b)
        return a == b;
    return memcmp(a, b, n) == 0;
}

static void check_same_scene(const vsgl_scene_desc *got, const vsgl_scene_desc *want)
{
    VT_CHECK(got->vertex_count == want->vertex_count && got->triangle_count == want->triangle_count &&
             got->material_count == want->material_count && got->light_count == want->light_count,
             "counts v%u t%u m%u l%u, want v%u t%u m%u l%u", got->vertex_count, got->triangle_count, got->material_count,
             got->light_count, want->vertex_count, want->triangle_count, want->material_count, want->light_count);
    size_t nt = want->triangle_count;
    VT_CHECK(same_bytes(got->positions, want->positions, 12u * want->vertex_count), "positions");
    VT_CHECK(same_bytes(got->indices, want->indices, 12u * nt), "indices");
    VT_CHECK(same_bytes(got->corner_normals, want->corner_normals, 36u * nt), "corner normals");
    VT_CHECK(same_bytes(got->corner_uvs, want->corner_uvs, 24u * nt), "corner uvs");
    VT_CHECK(same_bytes(got->corner_tangents, want->corner_tangents, 48u * nt), "corner tangents");
    VT_CHECK(same_bytes(got->material_indices, want->material_indices, 4u * nt), "material indices");
    VT_CHECK(same_bytes(got->materials, want->materials, sizeof(vsgl_material) * want->material_count), "materials");
    VT_CHECK(same_bytes(got->lights, want->lights, sizeof(vsgl_light) * want->light_count), "lights");
    VT_CHECK(same_bytes(got->camera, want->camera, sizeof(vsgl_camera)), "camera");
}

static unsigned char *to_memory(vsgl_context *ctx, const test_scene *s, const vsgl_bundle_options *opt, size_t *n)
{
    *n = 0;
    if (vsgl_bundle_write_memory(ctx, &s->desc, &s->settings, opt, NULL, 0, n) != VSGL_OK)
        return NULL;
    unsigned char *b = malloc(*n);
    if (vsgl_bundle_write_memory(ctx, &s->desc, &s->settings, opt, b, *n, n) != VSGL_OK) {
        free(b);
        return NULL;
    }
    return b;
}

/* ---- round trips -------------------------------------------------------- */

VT_TEST(bundle_roundtrip_memory_is_bit_exact)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    static test_scene s;
    make_scene(&s, 7);
    vsgl_bundle_options opt = {sizeof opt, "/tmp/out dir/frame_0042.exr", 1, -42};
    size_t n = 0;
    unsigned char *b = to_memory(ctx, &s, &opt, &n);
    VT_CHECK(b != NULL, "write: %s", vsgl_context_last_error(ctx));
    /* Documented size: 40 + sum over sections of 24 + bytes padded to 8. */
    size_t want = 40 + (24 + 88) + (24 + 64) + (24 + 184) + (24 + 120) + (24 + 240) + (24 + 24) + (24 + 80) + (24 + 312) +
                  (24 + 104) + (24 + 96) + (24 + 32) + (24 + 8); /* settings: 92 bytes, padded to 96 */
    VT_CHECK(n == want, "bundle size %zu, documented layout gives %zu", n, want);
    vsgl_bundle *bd = NULL;
    vsgl_result r = vsgl_bundle_read_memory(ctx, b, n, &bd);
    VT_CHECK(r == VSGL_OK && bd, "read: %d %s", r, vsgl_context_last_error(ctx));
    if (bd) {
        check_same_scene(vsgl_bundle_scene(bd), &s.desc);
        const vsgl_render_settings *st = vsgl_bundle_settings(bd);
        VT_CHECK(memcmp(st, &s.settings, sizeof *st) == 0, "settings seed %u aa %u stride %u edge %u auto %d mrp_min_area %g",
                 st->seed, st->aa_samples, st->shade_stride, st->edge_samples, st->auto_target, (double)st->mrp_min_area);
        vsgl_bundle_info info = {.size = sizeof info};
        VT_CHECK(vsgl_bundle_get_info(bd, &info) == VSGL_OK, "info");
        VT_CHECK(info.version_major == 1 && info.version_minor == VSGL_BUNDLE_VERSION_MINOR && info.has_frame && info.frame == -42 && info.has_settings &&
                     strcmp(info.output_path, "/tmp/out dir/frame_0042.exr") == 0,
                 "info %u.%u frame %d/%d settings %u path '%s'", info.version_major, info.version_minor, info.has_frame,
                 info.frame, info.has_settings, info.output_path);
        /* Re-writing the read scene gives the same bytes. */
        size_t n2 = 0;
        unsigned char *b2 = malloc(n);
        VT_CHECK(vsgl_bundle_write_memory(ctx, vsgl_bundle_scene(bd), vsgl_bundle_settings(bd), &opt, b2, n, &n2) == VSGL_OK &&
                     n2 == n && memcmp(b, b2, n) == 0, "rewrite differs (%zu vs %zu bytes)", n2, n);
        free(b2);
    }
    vsgl_bundle_destroy(bd);
    /* Capacity too small: size is still reported. */
    size_t need = 0;
    VT_CHECK(vsgl_bundle_write_memory(ctx, &s.desc, &s.settings, &opt, b, n - 1, &need) == VSGL_ERROR_INVALID_ARGUMENT && need == n,
             "short buffer: need %zu want %zu", need, n);
    free(b);
    vsgl_context_destroy(ctx);
}

VT_TEST(bundle_minimal_scene_without_optional_arrays)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    static test_scene s;
    make_scene(&s, 3);
    vsgl_scene_desc d;
    memset(&d, 0, sizeof d); /* empty scene: no triangles, materials or lights */
    d.camera = &s.cam;
    size_t n = 0;
    VT_CHECK(vsgl_bundle_write_memory(ctx, &d, NULL, NULL, NULL, 0, &n) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    unsigned char *b = malloc(n);
    vsgl_bundle_write_memory(ctx, &d, NULL, NULL, b, n, &n);
    vsgl_bundle *bd = NULL;
    VT_CHECK(vsgl_bundle_read_memory(ctx, b, n, &bd) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    if (bd) {
        const vsgl_scene_desc *g = vsgl_bundle_scene(bd);
        VT_CHECK(g->vertex_count == 0 && g->triangle_count == 0 && !g->corner_normals && !g->corner_uvs && !g->corner_tangents &&
                     !g->material_indices && !g->materials && !g->lights && g->camera && g->camera->width == 320,
                 "empty scene view: v%u t%u", g->vertex_count, g->triangle_count);
        vsgl_render_settings zero;
        memset(&zero, 0, sizeof zero);
        zero.size = sizeof zero;
        vsgl_bundle_info info = {.size = sizeof info};
        vsgl_bundle_get_info(bd, &info);
        VT_CHECK(!info.has_settings && !info.has_frame && info.output_path && !*info.output_path &&
                     memcmp(vsgl_bundle_settings(bd), &zero, sizeof zero) == 0,
                 "defaults: settings %u frame %d path '%s'", info.has_settings, info.has_frame, info.output_path);
    }
    vsgl_bundle_destroy(bd);
    free(b);
    vsgl_context_destroy(ctx);
}

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

VT_TEST(bundle_file_matches_independent_python_reader)
{
    const char *script = "tests/cli/bundle_ref.py";
    struct stat st;
    if (stat(script, &st) != 0 || stat("/usr/bin/python3", &st) != 0) {
        printf("    SKIP: run from the repository root with /usr/bin/python3 to compare with %s\n", script);
        return;
    }
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    static test_scene s;
    make_scene(&s, 11);
    char dir[] = "/tmp/vsgl_bundle_XXXXXX", path[64], cmd[256];
    static char out[1 << 16];
    VT_CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    snprintf(path, sizeof path, "%s/s.vsglb", dir);
    vsgl_bundle_options opt = {0, "out.exr", 1, 12};
    VT_CHECK(vsgl_bundle_write(ctx, path, &s.desc, &s.settings, &opt) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 %s '%s'", script, path);
    int rc = run_capture(cmd, out, sizeof out);
    VT_CHECK(rc == 0 && strstr(out, "\nok\n"), "reference reader exit %d:\n%s", rc, out);
    VT_CHECK(strstr(out, "version 1.11\n") && strstr(out, "section POS  esize 12 count 7 crc ok") &&
                 strstr(out, "section IDX  esize 12 count 5 crc ok") && strstr(out, "section LGHT esize 104 count 3 crc ok") &&
                 strstr(out, "camera type 0 fit 0 lens 50 size 320x240") && strstr(out, "light 2 type 2 power 300") &&
                 strstr(out, "output out.exr") && strstr(out, "frame 12") && strstr(out, "seed 1234567"),
             "reference reader output:\n%s", out);
    /* Every position, as the reference prints them (%.9g round-trips floats). */
    char want[1024] = "pos";
    for (int i = 0; i < NV * 3; ++i)
        snprintf(want + strlen(want), sizeof want - strlen(want), " %.9g", (double)s.pos[i]);
    VT_CHECK(strstr(out, want) != NULL, "positions line '%s' not in:\n%s", want, out);
    vsgl_context_destroy(ctx);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    VT_CHECK(system(cmd) == 0, "cleanup");
}

/* ---- bad files ---------------------------------------------------------- */

/* Read b; expect code and a message containing want; `what` names the case. */
#define EXPECT_READ(b, n, code, want, what)                                                                \
    do {                                                                                                   \
        vsgl_bundle *bd_ = NULL;                                                                           \
        vsgl_result r_ = vsgl_bundle_read_memory(ctx, (b), (n), &bd_);                                     \
        VT_CHECK(r_ == (code) && bd_ == NULL && strstr(vsgl_context_last_error(ctx), (want)),              \
                 "%s: got %d '%s', want %d '%s'", (what), r_, vsgl_context_last_error(ctx), (code), (want)); \
        vsgl_bundle_destroy(bd_);                                                                          \
    } while (0)

VT_TEST(bundle_rejects_every_truncation)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    static test_scene s;
    make_scene(&s, 5);
    size_t n = 0;
    unsigned char *b = to_memory(ctx, &s, NULL, &n);
    int failures = 0;
    for (size_t k = 0; k < n && failures < 3; ++k) {
        /* A copy of exactly k bytes, so ASan sees any read past the end. */
        unsigned char *t = malloc(k ? k : 1);
        memcpy(t, b, k);
        vsgl_bundle *bd = NULL;
        vsgl_result r = vsgl_bundle_read_memory(ctx, k ? t : NULL, k, &bd);
        if (r != VSGL_ERROR_BAD_FORMAT || bd) {
            ++failures;
            VT_CHECK(0, "truncated to %zu of %zu bytes: result %d '%s'", k, n, r, vsgl_context_last_error(ctx));
        }
        vsgl_bundle_destroy(bd);
        free(t);
    }
    EXPECT_READ(b, n - 8, VSGL_ERROR_BAD_FORMAT, "truncated: header says", "n-8");
    EXPECT_READ(b, 10, VSGL_ERROR_BAD_FORMAT, "truncated: 10 bytes", "10 bytes");
    free(b);
    vsgl_context_destroy(ctx);
}

VT_TEST(bundle_detects_every_single_bit_flip)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    static test_scene s;
    make_scene(&s, 9);
    vsgl_bundle_options opt = {0, "x.exr", 1, 3};
    size_t n = 0;
    unsigned char *b = to_memory(ctx, &s, &opt, &n);
    int failures = 0;
    for (size_t k = 0; k < n * 8 && failures < 3; ++k) {
        b[k / 8] ^= (unsigned char)(1u << (k % 8));
        vsgl_bundle *bd = NULL;
        vsgl_result r = vsgl_bundle_read_memory(ctx, b, n, &bd);
        if (r == VSGL_OK) {
            ++failures;
            VT_CHECK(0, "flip of bit %zu (byte %zu) went unnoticed", k % 8, k / 8);
        }
        vsgl_bundle_destroy(bd);
        b[k / 8] ^= (unsigned char)(1u << (k % 8));
    }
    free(b);
    vsgl_context_destroy(ctx);
}

VT_TEST(bundle_bad_headers_give_clear_errors)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    static test_scene s;
    make_scene(&s, 5);
    size_t n = 0;
    unsigned char *b = to_memory(ctx, &s, NULL, &n);
    unsigned char *t = malloc(n + 16);

    memcpy(t, b, n);
    memcpy(t, "PK\3\4", 4);
    EXPECT_READ(t, n, VSGL_ERROR_BAD_FORMAT, "wrong magic", "zip magic");

    memcpy(t, b, n);
    wr32(t + 8, 2);
    EXPECT_READ(t, n, VSGL_ERROR_VERSION_MISMATCH, "version 2.11, this library reads 1.x", "major 2");
    wr32(t + 8, 0);
    EXPECT_READ(t, n, VSGL_ERROR_VERSION_MISMATCH, "version 0.11", "major 0");

    memcpy(t, b, n);
    memset(t + n, 0, 16);
    EXPECT_READ(t, n + 16, VSGL_ERROR_BAD_FORMAT, "trailing data", "16 extra bytes");

    memcpy(t, b, n);
    t[30] ^= 1;
    EXPECT_READ(t, n, VSGL_ERROR_BAD_FORMAT, "header", "flipped file size");

    /* A newer minor version with an unknown section is read (section skipped). */
    {
        size_t extra = 24 + 8;
        unsigned char *u = malloc(n + extra);
        memcpy(u, b, n);
        unsigned char *sec = u + n;
        memcpy(sec, "ZZZZ", 4);
        wr32(sec + 4, 1);
        wr64(sec + 8, 5);
        wr32(sec + 16, 0);
        memcpy(sec + 24, "hello\0\0\0", 8);
        wr32(u + 12, 7);
        wr32(u + 20, rd32(u + 20) + 1);
        wr64(u + 24, n + extra);
        fix_crcs(u, n);
        vsgl_bundle *bd = NULL;
        VT_CHECK(vsgl_bundle_read_memory(ctx, u, n + extra, &bd) == VSGL_OK, "minor 7 with unknown section: %s", vsgl_context_last_error(ctx));
        vsgl_bundle_info info = {.size = sizeof info};
        if (bd && vsgl_bundle_get_info(bd, &info) == VSGL_OK)
            VT_CHECK(info.version_minor == 7, "minor %u", info.version_minor);
        vsgl_bundle_destroy(bd);
        free(u);
    }
    free(t);
    free(b);
    vsgl_context_destroy(ctx);
}

VT_TEST(bundle_huge_counts_are_capped_by_the_file_size)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    static test_scene s;
    make_scene(&s, 5);
    size_t n = 0;
    unsigned char *b = to_memory(ctx, &s, NULL, &n);
    size_t pos = find_section(b, n, "POS ");
    VT_CHECK(pos == 40, "POS section at %zu", pos);
    const uint64_t counts[] = {1ull << 40, 0xFFFFFFFFull, 0xFFFFFFFFFFFFFFFFull, 1ull << 61};
    for (size_t i = 0; i < sizeof counts / sizeof counts[0]; ++i) {
        unsigned char *t = malloc(n);
        memcpy(t, b, n);
        wr64(t + pos + 8, counts[i]);
        fix_crcs(t, 0);
        char what[64];
        snprintf(what, sizeof what, "count %llu", (unsigned long long)counts[i]);
        EXPECT_READ(t, n, VSGL_ERROR_BAD_FORMAT, "exceed the file", what);
        free(t);
    }
    /* Element size 2^31 with count 2: the product overflows 32 bits. */
    unsigned char *t = malloc(n);
    memcpy(t, b, n);
    wr32(t + pos + 4, 0x80000000u);
    wr64(t + pos + 8, 2);
    EXPECT_READ(t, n, VSGL_ERROR_BAD_FORMAT, "exceed the file", "esize 2^31");
    free(t);
    free(b);
    vsgl_context_destroy(ctx);
}

VT_TEST(bundle_nonfinite_values_name_section_and_element)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    static test_scene s;
    make_scene(&s, 5);
    size_t n = 0;
    unsigned char *b = to_memory(ctx, &s, NULL, &n);
    unsigned char *t = malloc(n);
    const uint32_t qnan = 0x7FC00000u, pinf = 0x7F800000u, ninf = 0xFF800000u;

    memcpy(t, b, n);
    size_t sec = find_section(t, n, "POS ");
    wr32(t + sec + 24 + 4 * (3 * 4 + 2), qnan); /* vertex 4, z */
    fix_crcs(t, sec);
    EXPECT_READ(t, n, VSGL_ERROR_BAD_FORMAT, "section POS  (positions): vertex 4 component 2 is NaN", "NaN position");

    memcpy(t, b, n);
    sec = find_section(t, n, "TAN ");
    wr32(t + sec + 24 + 4 * (12 * 3 + 7), pinf);
    fix_crcs(t, sec);
    EXPECT_READ(t, n, VSGL_ERROR_BAD_FORMAT, "section TAN  (corner tangents): triangle 3 component 7 is +Inf", "Inf tangent");

    memcpy(t, b, n);
    sec = find_section(t, n, "LGHT");
    wr32(t + sec + 24 + 104 * 1 + 4 * 5, qnan); /* light 1 power */
    fix_crcs(t, sec);
    EXPECT_READ(t, n, VSGL_ERROR_BAD_FORMAT, "section LGHT (lights): light 1 field power is NaN", "NaN power");

    memcpy(t, b, n);
    sec = find_section(t, n, "CAM ");
    wr32(t + sec + 24 + 4 * (2 + 11), ninf); /* world_from_camera[11] */
    fix_crcs(t, sec);
    EXPECT_READ(t, n, VSGL_ERROR_BAD_FORMAT, "section CAM  (camera): camera 0 field world_from_camera[11] is -Inf", "camera matrix");

    memcpy(t, b, n);
    sec = find_section(t, n, "MATL");
    wr32(t + sec + 24 + 40 * 1 + 4 * 4, qnan); /* material 1 roughness */
    fix_crcs(t, sec);
    EXPECT_READ(t, n, VSGL_ERROR_BAD_FORMAT, "section MATL (materials): material 1 field roughness is NaN", "material");

    /* The writer refuses the same, naming the array. */
    s.nrm[9 * 2 + 4] = (float)NAN;
    size_t m = 0;
    VT_CHECK(vsgl_bundle_write_memory(ctx, &s.desc, NULL, NULL, NULL, 0, &m) == VSGL_ERROR_INVALID_ARGUMENT &&
                 strcmp(vsgl_context_last_error(ctx), "corner normals: triangle 2 component 4 is NaN") == 0,
             "writer: '%s'", vsgl_context_last_error(ctx));
    s.nrm[9 * 2 + 4] = 0;
    s.light[2].world_from_light[3] = (float)INFINITY;
    VT_CHECK(vsgl_bundle_write_memory(ctx, &s.desc, NULL, NULL, NULL, 0, &m) == VSGL_ERROR_INVALID_ARGUMENT &&
                 strcmp(vsgl_context_last_error(ctx), "lights: light 2 field world_from_light[3] is +Inf") == 0,
             "writer: '%s'", vsgl_context_last_error(ctx));
    free(t);
    free(b);
    vsgl_context_destroy(ctx);
}

VT_TEST(bundle_structural_errors)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    static test_scene s;
    make_scene(&s, 5);
    size_t n = 0;
    unsigned char *b = to_memory(ctx, &s, NULL, &n);
    unsigned char *t = malloc(n);

    /* NRM with one element fewer than triangles (payload shrinks: rebuild the tail). */
    memcpy(t, b, n);
    size_t sec = find_section(t, n, "NRM ");
    wr64(t + sec + 8, NT - 1); /* 36 bytes fewer, padding: 180 -> 144 (both multiples of 8? 180 pads to 184) */
    size_t old_bytes = 184, new_bytes = 144;
    memmove(t + sec + 24 + new_bytes, t + sec + 24 + old_bytes, n - (sec + 24 + old_bytes));
    size_t m = n - (old_bytes - new_bytes);
    wr64(t + 24, m);
    fix_crcs(t, sec);
    EXPECT_READ(t, m, VSGL_ERROR_BAD_FORMAT, "section NRM  (corner normals): 4 elements, want 5 (one per triangle)", "short NRM");

    /* Rename MIDX to IDX : a duplicate section. */
    memcpy(t, b, n);
    sec = find_section(t, n, "MIDX");
    memcpy(t + sec, "IDX ", 4);
    fix_crcs(t, sec);
    EXPECT_READ(t, n, VSGL_ERROR_BAD_FORMAT, "section IDX  (indices) appears twice", "duplicate IDX");

    /* Rename the camera: no camera. */
    memcpy(t, b, n);
    sec = find_section(t, n, "CAM ");
    memcpy(t + sec, "CAMX", 4);
    fix_crcs(t, sec);
    EXPECT_READ(t, n, VSGL_ERROR_BAD_FORMAT, "bundle has no camera", "no camera");

    /* A light record shorter than this version's. */
    memcpy(t, b, n);
    sec = find_section(t, n, "LGHT");
    wr32(t + sec + 4, 52);
    wr64(t + sec + 8, NL * 2);
    fix_crcs(t, sec);
    EXPECT_READ(t, n, VSGL_ERROR_BAD_FORMAT, "element size 52, want at least 104", "short light records");

    /* Out-of-range vertex indices are stored as given (vsgl_scene_create rejects them). */
    s.idx[4] = 1000000;
    size_t k = 0;
    unsigned char *c = to_memory(ctx, &s, NULL, &k);
    vsgl_bundle *bd = NULL;
    VT_CHECK(c && vsgl_bundle_read_memory(ctx, c, k, &bd) == VSGL_OK && vsgl_bundle_scene(bd)->indices[4] == 1000000,
             "out-of-range index kept: %s", vsgl_context_last_error(ctx));
    vsgl_bundle_destroy(bd);
    free(c);

    /* Writer: count without array, no camera. */
    vsgl_scene_desc d = s.desc;
    d.lights = NULL;
    VT_CHECK(vsgl_bundle_write_memory(ctx, &d, NULL, NULL, NULL, 0, &k) == VSGL_ERROR_INVALID_ARGUMENT &&
                 strstr(vsgl_context_last_error(ctx), "3 lights but lights is NULL"), "'%s'", vsgl_context_last_error(ctx));
    d = s.desc;
    d.camera = NULL;
    VT_CHECK(vsgl_bundle_write_memory(ctx, &d, NULL, NULL, NULL, 0, &k) == VSGL_ERROR_INVALID_ARGUMENT &&
                 strstr(vsgl_context_last_error(ctx), "no camera"), "'%s'", vsgl_context_last_error(ctx));
    free(t);
    free(b);
    vsgl_context_destroy(ctx);
}

VT_TEST(bundle_file_errors_and_atomic_replace)
{
    vsgl_context *ctx = NULL;
    vsgl_context_create(NULL, &ctx);
    static test_scene s;
    make_scene(&s, 5);
    char dir[] = "/tmp/vsgl_bundle_XXXXXX", path[96], cmd[128];
    VT_CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    vsgl_bundle *bd = NULL;
    snprintf(path, sizeof path, "%s/none.vsglb", dir);
    VT_CHECK(vsgl_bundle_read(ctx, path, &bd) == VSGL_ERROR_IO && strstr(vsgl_context_last_error(ctx), "No such file"),
             "missing file: '%s'", vsgl_context_last_error(ctx));
    VT_CHECK(vsgl_bundle_read(ctx, dir, &bd) == VSGL_ERROR_IO, "directory: '%s'", vsgl_context_last_error(ctx));
    snprintf(path, sizeof path, "%s/s.vsglb", dir);
    VT_CHECK(vsgl_bundle_write(ctx, path, &s.desc, &s.settings, NULL) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(vsgl_bundle_read(ctx, path, &bd) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    if (bd)
        check_same_scene(vsgl_bundle_scene(bd), &s.desc);
    vsgl_bundle_destroy(bd);
    /* A refused write (NaN) leaves the previous bundle and no temp file. */
    s.pos[0] = (float)NAN;
    VT_CHECK(vsgl_bundle_write(ctx, path, &s.desc, &s.settings, NULL) == VSGL_ERROR_INVALID_ARGUMENT, "NaN write");
    s.pos[0] = 1;
    bd = NULL;
    VT_CHECK(vsgl_bundle_read(ctx, path, &bd) == VSGL_OK, "previous bundle intact: %s", vsgl_context_last_error(ctx));
    vsgl_bundle_destroy(bd);
    DIR *dd = opendir(dir);
    int entries = 0;
    for (struct dirent *e; dd && (e = readdir(dd));)
        entries += e->d_name[0] != '.';
    if (dd)
        closedir(dd);
    VT_CHECK(entries == 1, "%d visible entries in %s", entries, dir);
    /* A file with the right magic but garbage after: the message names the file. */
    FILE *f = fopen(path, "r+b");
    fseek(f, 60, SEEK_SET);
    fputc('x', f);
    fclose(f);
    VT_CHECK(vsgl_bundle_read(ctx, path, &bd) == VSGL_ERROR_BAD_FORMAT && strncmp(vsgl_context_last_error(ctx), path, strlen(path)) == 0 &&
                 strstr(vsgl_context_last_error(ctx), "CRC32"), "'%s'", vsgl_context_last_error(ctx));
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    VT_CHECK(system(cmd) == 0, "cleanup");
    vsgl_context_destroy(ctx);
}
