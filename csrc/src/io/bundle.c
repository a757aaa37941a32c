/* Scene bundle: versioned little-endian container of a vsgl_scene_desc and
 * vsgl_render_settings (docs/bundle-format.md). The reader trusts nothing:
 * every size is checked against the bytes present before allocating. */
#include "vsgl/io.h"
#include "core/versioned.h"
#include "core/context.h"
#include "io/atomic.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define HEADER_SIZE 40u
#define SECTION_HEADER_SIZE 24u
#define MAX_OUTPUT_PATH 4096u
#define MAX_SECTIONS 4096u

/* Fuzzing builds (libFuzzer convention) skip CRC checks so that mutated
 * inputs reach the structural checks behind them. */
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
#define IGNORE_CRC 1
#else
#define IGNORE_CRC 0
#endif

static const unsigned char magic[8] = {0x89, 'V', 'S', 'G', 'L', 'B', '\r', '\n'};

/* ---- little-endian helpers and CRC32 (IEEE 802.3, as zlib) -------------- */

static void put_u32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

static void put_u64(unsigned char *p, uint64_t v)
{
    put_u32(p, (uint32_t)v);
    put_u32(p + 4, (uint32_t)(v >> 32));
}

static uint32_t get_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t get_u64(const unsigned char *p)
{
    return (uint64_t)get_u32(p) | (uint64_t)get_u32(p + 4) << 32;
}

typedef struct crc_table { uint32_t t[256]; } crc_table;

static void crc_init(crc_table *c)
{
    for (uint32_t i = 0; i < 256; ++i) {
        uint32_t r = i;
        for (int k = 0; k < 8; ++k)
            r = (r >> 1) ^ (0xEDB88320u & (0u - (r & 1u)));
        c->t[i] = r;
    }
}

/* Streaming form: crc32_of(a ++ b) = crc32_more(c, crc32_of(c, a), b). */
static uint32_t crc32_more(const crc_table *c, uint32_t crc, const unsigned char *p, size_t n)
{
    uint32_t r = crc ^ 0xFFFFFFFFu;
    for (size_t i = 0; i < n; ++i)
        r = c->t[(r ^ p[i]) & 0xFFu] ^ (r >> 8);
    return r ^ 0xFFFFFFFFu;
}

static uint32_t crc32_of(const crc_table *c, const unsigned char *p, size_t n)
{
    return crc32_more(c, 0, p, n);
}

/* ---- record layouts ----------------------------------------------------- */

/* One field of a record: 'f' float (checked finite), 'i' int32, 'u' uint32. */
typedef struct field { const char *name; char kind; uint8_t count; uint16_t offset; } field;

#define F(type, member, kind, count) {#member, kind, count, (uint16_t)offsetof(type, member)}

static const field material_fields[] = {
    F(vsgl_material, base_color, 'f', 3), F(vsgl_material, metallic, 'f', 1),
    F(vsgl_material, roughness, 'f', 1), F(vsgl_material, specular_f0, 'f', 1),
    F(vsgl_material, anisotropy, 'f', 1), F(vsgl_material, anisotropic_rotation, 'f', 1),
    F(vsgl_material, flags, 'u', 1), F(vsgl_material, reserved, 'u', 1),
};
static const field light_fields[] = {
    F(vsgl_light, type, 'i', 1), F(vsgl_light, area_shape, 'i', 1), F(vsgl_light, color, 'f', 3),
    F(vsgl_light, power, 'f', 1), F(vsgl_light, world_from_light, 'f', 12), F(vsgl_light, radius, 'f', 1),
    F(vsgl_light, spot_size, 'f', 1), F(vsgl_light, spot_blend, 'f', 1), F(vsgl_light, sun_angle, 'f', 1),
    F(vsgl_light, size_x, 'f', 1), F(vsgl_light, size_y, 'f', 1), F(vsgl_light, spread, 'f', 1),
    F(vsgl_light, flags, 'u', 1),
};
static const field camera_fields[] = {
    F(vsgl_camera, type, 'i', 1), F(vsgl_camera, sensor_fit, 'i', 1), F(vsgl_camera, world_from_camera, 'f', 12),
    F(vsgl_camera, lens_mm, 'f', 1), F(vsgl_camera, sensor_width_mm, 'f', 1), F(vsgl_camera, sensor_height_mm, 'f', 1),
    F(vsgl_camera, ortho_scale, 'f', 1), F(vsgl_camera, shift_x, 'f', 1), F(vsgl_camera, shift_y, 'f', 1),
    F(vsgl_camera, clip_start, 'f', 1), F(vsgl_camera, clip_end, 'f', 1), F(vsgl_camera, width, 'u', 1),
    F(vsgl_camera, height, 'u', 1), F(vsgl_camera, pixel_aspect_x, 'f', 1), F(vsgl_camera, pixel_aspect_y, 'f', 1),
};
static const field settings_fields[] = {
    F(vsgl_render_settings, method, 'i', 1), F(vsgl_render_settings, aa_samples, 'u', 1),
    F(vsgl_render_settings, rsm_resolution, 'u', 1), F(vsgl_render_settings, fit_mode, 'i', 1),
    F(vsgl_render_settings, vsgl_count, 'u', 1), F(vsgl_render_settings, fis_iterations, 'u', 1),
    F(vsgl_render_settings, sharpness_estimator, 'i', 1), F(vsgl_render_settings, diffuse_mode, 'i', 1),
    F(vsgl_render_settings, glossy_mode, 'i', 1), F(vsgl_render_settings, visibility, 'i', 1),
    F(vsgl_render_settings, seed, 'u', 1),
    /* format 1.1 */
    F(vsgl_render_settings, leak_correction, 'i', 1), F(vsgl_render_settings, sample_merging, 'i', 1),
    /* format 1.3: without them a bundle's settings rendered at stride 1 and without edge
     * refinement where the add-on's own render used the preset's 2 and 8 */
    F(vsgl_render_settings, shade_stride, 'u', 1), F(vsgl_render_settings, edge_samples, 'u', 1),
    /* format 1.4: without it a bundle saved with the auto preset rendered with balanced's knobs */
    F(vsgl_render_settings, auto_target, 'i', 1),
    /* format 1.5: the MRP glossy modes' proxy size threshold */
    F(vsgl_render_settings, mrp_min_area, 'f', 1),
    /* format 1.6: the half-vector glossy model's lobe count (the quality preset's 5) */
    F(vsgl_render_settings, glossy_lobes, 'u', 1),
    /* format 1.7: the visibility rays' budget */
    F(vsgl_render_settings, visibility_budget, 'f', 1),
    /* format 1.8: one sample per pixel from this many pixels up (every preset's 76800) */
    F(vsgl_render_settings, aa_pixel_limit, 'u', 1),
    /* format 1.9: the image size shade_stride is meant for (every preset's 320 x 240) */
    F(vsgl_render_settings, stride_pixels, 'u', 1),
    /* format 1.10: where visibility rays aim, in cluster sigmas */
    F(vsgl_render_settings, visibility_spread, 'f', 1),
    /* format 1.11: rays per pair for a receiver's dominant pairs */
    F(vsgl_render_settings, dominant_rays, 'u', 1),
};
#define SLOT(m) F(vsgl_material_textures, m.texture, 'u', 1), F(vsgl_material_textures, m.filter, 'i', 1), \
    F(vsgl_material_textures, m.wrap, 'i', 1), F(vsgl_material_textures, m.channel, 'i', 1), \
    F(vsgl_material_textures, m.uv_transform, 'f', 6)
/* format 1.2 */
static const field mtex_fields[] = {
    SLOT(base_color), SLOT(roughness), SLOT(metallic),
    F(vsgl_material_textures, flags, 'u', 1), F(vsgl_material_textures, reserved, 'u', 1),
};
#undef SLOT
static const field texh_fields[] = {
    F(vsgl_texture, width, 'u', 1), F(vsgl_texture, height, 'u', 1),
    F(vsgl_texture, flags, 'u', 1), F(vsgl_texture, reserved, 'u', 1),
};
#undef F

typedef struct layout { const field *fields; size_t count; } layout;
#define LAYOUT(a) {a, sizeof a / sizeof a[0]}

static void encode_record(layout l, const void *rec, unsigned char *out)
{
    const unsigned char *base = rec;
    for (size_t i = 0; i < l.count; ++i)
        for (unsigned k = 0; k < l.fields[i].count; ++k) {
            uint32_t v;
            memcpy(&v, base + l.fields[i].offset + 4u * k, 4);
            put_u32(out, v);
            out += 4;
        }
}

/* Decode; on a non-finite float return the field index and component. */
/* Fields past `size` bytes (a record of an older minor version) keep the
 * destination's value (zero: the default). */
static int decode_record(layout l, const unsigned char *in, uint32_t size, void *rec, size_t *bad_field,
                         unsigned *bad_comp)
{
    unsigned char *base = rec;
    const unsigned char *end = in + size;
    for (size_t i = 0; i < l.count; ++i)
        for (unsigned k = 0; k < l.fields[i].count && in + 4 <= end; ++k) {
            uint32_t v = get_u32(in);
            in += 4;
            memcpy(base + l.fields[i].offset + 4u * k, &v, 4);
            if (l.fields[i].kind == 'f') {
                float f;
                memcpy(&f, &v, 4);
                if (!isfinite(f)) {
                    *bad_field = i;
                    *bad_comp = k;
                    return -1;
                }
            }
        }
    return 0;
}

static int record_finite(layout l, const void *rec, size_t *bad_field, unsigned *bad_comp)
{
    const unsigned char *base = rec;
    for (size_t i = 0; i < l.count; ++i)
        if (l.fields[i].kind == 'f')
            for (unsigned k = 0; k < l.fields[i].count; ++k) {
                float f;
                memcpy(&f, base + l.fields[i].offset + 4u * k, 4);
                if (!isfinite(f)) {
                    *bad_field = i;
                    *bad_comp = k;
                    return 0;
                }
            }
    return 1;
}

static const char *nonfinite_name(float f)
{
    return isnan(f) ? "NaN" : (f > 0 ? "+Inf" : "-Inf");
}

/* "[k]" for array fields, "" for scalars. */
typedef struct suffix { char s[8]; } suffix;
static suffix index_suffix(field f, unsigned k)
{
    suffix x = {""};
    if (f.count > 1)
        snprintf(x.s, sizeof x.s, "[%u]", k);
    return x;
}

/* ---- sections ----------------------------------------------------------- */

enum { S_POS, S_IDX, S_NRM, S_UV, S_TAN, S_MIDX, S_MATL, S_LGHT, S_CAM, S_RSET, S_OUTP, S_FRME,
       S_CCOL, S_MTEX, S_TEXH, S_TEXP, S_COUNT };

typedef struct section_kind {
    char tag[5];
    const char *what;      /* for messages */
    const char *element;   /* element noun */
    uint32_t element_size; /* exact (arrays) or written size (records) */
    int is_record;
    unsigned floats_per_element; /* arrays of floats: checked finite */
    uint32_t min_size;     /* records: smallest size read (older minor versions); 0 = element_size */
} section_kind;

static const section_kind kinds[S_COUNT] = {
    {"POS ", "positions", "vertex", 12, 0, 3, 0},
    {"IDX ", "indices", "triangle", 12, 0, 0, 0},
    {"NRM ", "corner normals", "triangle", 36, 0, 9, 0},
    {"UV  ", "corner uvs", "triangle", 24, 0, 6, 0},
    {"TAN ", "corner tangents", "triangle", 48, 0, 12, 0},
    {"MIDX", "material indices", "triangle", 4, 0, 0, 0},
    {"MATL", "materials", "material", 40, 1, 0, 0},
    {"LGHT", "lights", "light", 104, 1, 0, 0},
    {"CAM ", "camera", "camera", 104, 1, 0, 0},
    {"RSET", "render settings", "settings", 92, 1, 0, 44},
    {"OUTP", "output path", "byte", 1, 0, 0, 0},
    {"FRME", "frame", "frame", 4, 0, 0, 0},
    /* format 1.2: textures */
    {"CCOL", "corner colours", "triangle", 36, 0, 9, 0},
    {"MTEX", "material textures", "material", 128, 1, 0, 0},
    {"TEXH", "texture headers", "texture", 16, 1, 0, 0},
    {"TEXP", "texture pixels", "float", 4, 0, 1, 0},
};
/* Largest texture side a bundle may hold (as vsgl_scene_create). */
#define MAX_TEXTURE_SIDE 65536u

static uint64_t padded(uint64_t n)
{
    return (n + 7u) & ~(uint64_t)7u;
}

struct vsgl_bundle {
    vsgl_scene_desc desc;
    vsgl_camera camera;
    vsgl_render_settings settings;
    float *positions;
    uint32_t *indices;
    float *corner_normals, *corner_uvs, *corner_tangents;
    uint32_t *material_indices;
    vsgl_material *materials;
    vsgl_light *lights;
    float *corner_colors;
    vsgl_material_textures *material_textures;
    vsgl_texture *textures;
    float *texture_pixels;
    char *output_path;
    uint32_t version_major, version_minor;
    int32_t has_frame, frame;
    uint32_t has_settings;
};

/* ---- writer ------------------------------------------------------------- */

typedef struct out_section { int kind; uint64_t count; const void *data; } out_section;

static vsgl_result check_floats(vsgl_context *ctx, int kind, const float *v, uint64_t count)
{
    unsigned per = kinds[kind].floats_per_element;
    for (uint64_t i = 0; i < count * per; ++i)
        if (!isfinite(v[i]))
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "%s: %s %llu component %u is %s", kinds[kind].what,
                              kinds[kind].element, (unsigned long long)(i / per), (unsigned)(i % per), nonfinite_name(v[i]));
    return VSGL_OK;
}

static vsgl_result check_records(vsgl_context *ctx, int kind, layout l, const void *recs, size_t rec_size, uint64_t count)
{
    for (uint64_t i = 0; i < count; ++i) {
        size_t f;
        unsigned c;
        const unsigned char *rec = (const unsigned char *)recs + i * rec_size;
        if (!record_finite(l, rec, &f, &c)) {
            float v;
            memcpy(&v, rec + l.fields[f].offset + 4u * c, 4);
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "%s: %s %llu field %s%s is %s", kinds[kind].what,
                              kinds[kind].element, (unsigned long long)i, l.fields[f].name, index_suffix(l.fields[f], c).s,
                              nonfinite_name(v));
        }
    }
    return VSGL_OK;
}

/* The writer's inputs: pointers that go with their counts, the output
 * path's length. */
static vsgl_result check_write_inputs(vsgl_context *ctx, const vsgl_scene_desc *d, const vsgl_bundle_options *o,
                                      size_t *path_len)
{
    if (!d->camera)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: scene has no camera");
    if (d->vertex_count && !d->positions)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: %u vertices but positions is NULL", d->vertex_count);
    if (d->triangle_count && !d->indices)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: %u triangles but indices is NULL", d->triangle_count);
    if (d->material_count && !d->materials)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: %u materials but materials is NULL", d->material_count);
    if (d->light_count && !d->lights)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: %u lights but lights is NULL", d->light_count);
    if (d->texture_count && !d->textures)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: %u textures but textures is NULL", d->texture_count);
    *path_len = o->output_path ? strlen(o->output_path) : 0;
    if (*path_len > MAX_OUTPUT_PATH)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: output path longer than %u bytes", MAX_OUTPUT_PATH);
    return VSGL_OK;
}

/* Every float the bundle stores is finite (arrays and records), and every
 * texture has a size and pixels; *texel_floats = the textures' floats. */
static vsgl_result check_write_values(vsgl_context *ctx, const vsgl_scene_desc *d, uint64_t *texel_floats)
{
    vsgl_result r;
    uint32_t nt = d->triangle_count;
    if ((r = check_floats(ctx, S_POS, d->positions, d->vertex_count)))
        return r;
    if (d->corner_normals && (r = check_floats(ctx, S_NRM, d->corner_normals, nt)))
        return r;
    if (d->corner_uvs && (r = check_floats(ctx, S_UV, d->corner_uvs, nt)))
        return r;
    if (d->corner_tangents && (r = check_floats(ctx, S_TAN, d->corner_tangents, nt)))
        return r;
    if ((r = check_records(ctx, S_MATL, (layout)LAYOUT(material_fields), d->materials, sizeof(vsgl_material),
                           d->material_count)))
        return r;
    if ((r = check_records(ctx, S_LGHT, (layout)LAYOUT(light_fields), d->lights, sizeof(vsgl_light), d->light_count)))
        return r;
    if ((r = check_records(ctx, S_CAM, (layout)LAYOUT(camera_fields), d->camera, sizeof(vsgl_camera), 1)))
        return r;
    if (d->corner_colors && (r = check_floats(ctx, S_CCOL, d->corner_colors, nt)))
        return r;
    if (d->material_textures &&
        (r = check_records(ctx, S_MTEX, (layout)LAYOUT(mtex_fields), d->material_textures,
                           sizeof(vsgl_material_textures), d->material_count)))
        return r;
    *texel_floats = 0;
    for (uint32_t i = 0; i < d->texture_count; ++i) {
        const vsgl_texture *t = &d->textures[i];
        if (!t->pixels || t->width < 1 || t->height < 1 || t->width > MAX_TEXTURE_SIDE || t->height > MAX_TEXTURE_SIDE)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: texture %u is %ux%u with pixels %s", i, t->width,
                              t->height, t->pixels ? "given" : "NULL");
        uint64_t nf = (uint64_t)t->width * t->height * 4;
        if ((r = check_floats(ctx, S_TEXP, t->pixels, nf)))
            return r;
        *texel_floats += nf;
    }
    return VSGL_OK;
}

/* The sections to write, in file order; returns their number. `settings`
 * and `frame` point at the writer's copies (NULL settings: none stored). */
static int list_sections(const vsgl_scene_desc *d, const vsgl_bundle_options *o, const vsgl_render_settings *settings,
                         const int32_t *frame, size_t path_len, uint64_t texel_floats, out_section sec[S_COUNT])
{
    uint32_t nt = d->triangle_count;
    int ns = 0;
    sec[ns++] = (out_section){S_POS, d->vertex_count, d->positions};
    sec[ns++] = (out_section){S_IDX, nt, d->indices};
    if (d->corner_normals && nt)
        sec[ns++] = (out_section){S_NRM, nt, d->corner_normals};
    if (d->corner_uvs && nt)
        sec[ns++] = (out_section){S_UV, nt, d->corner_uvs};
    if (d->corner_tangents && nt)
        sec[ns++] = (out_section){S_TAN, nt, d->corner_tangents};
    if (d->material_indices && nt)
        sec[ns++] = (out_section){S_MIDX, nt, d->material_indices};
    sec[ns++] = (out_section){S_MATL, d->material_count, d->materials};
    sec[ns++] = (out_section){S_LGHT, d->light_count, d->lights};
    sec[ns++] = (out_section){S_CAM, 1, d->camera};
    if (settings)
        sec[ns++] = (out_section){S_RSET, 1, settings};
    if (o->output_path)
        sec[ns++] = (out_section){S_OUTP, path_len, o->output_path};
    if (o->has_frame)
        sec[ns++] = (out_section){S_FRME, 1, frame};
    if (d->corner_colors && nt)
        sec[ns++] = (out_section){S_CCOL, nt, d->corner_colors};
    if (d->material_textures && d->material_count)
        sec[ns++] = (out_section){S_MTEX, d->material_count, d->material_textures};
    if (d->texture_count) {
        sec[ns++] = (out_section){S_TEXH, d->texture_count, d->textures};
        sec[ns++] = (out_section){S_TEXP, texel_floats, d->textures}; /* the textures' pixels, in order */
    }
    return ns;
}

/* The field layout and in-memory size of a record section's element
 * (layout NULL for arrays). */
static layout record_layout(int kind, size_t *rec_size)
{
    switch (kind) {
    case S_MATL: *rec_size = sizeof(vsgl_material); return (layout)LAYOUT(material_fields);
    case S_LGHT: *rec_size = sizeof(vsgl_light); return (layout)LAYOUT(light_fields);
    case S_CAM: *rec_size = sizeof(vsgl_camera); return (layout)LAYOUT(camera_fields);
    case S_RSET: *rec_size = sizeof(vsgl_render_settings); return (layout)LAYOUT(settings_fields);
    case S_MTEX: *rec_size = sizeof(vsgl_material_textures); return (layout)LAYOUT(mtex_fields);
    case S_TEXH: *rec_size = sizeof(vsgl_texture); return (layout)LAYOUT(texh_fields);
    default: *rec_size = 0; return (layout){NULL, 0};
    }
}

/* Little-endian 32-bit words from memory. */
static unsigned char *put_words(unsigned char *p, const void *src, uint64_t words)
{
    for (uint64_t w = 0; w < words; ++w) {
        uint32_t v;
        memcpy(&v, (const unsigned char *)src + 4 * w, 4);
        put_u32(p, v);
        p += 4;
    }
    return p;
}

/* A section's payload at `p` (`bytes` long), encoded as the format says. */
static void encode_payload(const vsgl_scene_desc *d, const out_section *sec, uint64_t bytes, unsigned char *p)
{
    size_t rec_size;
    layout l = record_layout(sec->kind, &rec_size);
    if (sec->kind == S_TEXP) {
        for (uint32_t t = 0; t < d->texture_count; ++t)
            p = put_words(p, d->textures[t].pixels, (uint64_t)d->textures[t].width * d->textures[t].height * 4);
    } else if (l.fields) {
        for (uint64_t e = 0; e < sec->count; ++e)
            encode_record(l, (const unsigned char *)sec->data + e * rec_size, p + e * kinds[sec->kind].element_size);
    } else if (sec->kind == S_OUTP) {
        memcpy(p, sec->data, (size_t)bytes);
    } else { /* arrays of 32-bit words */
        put_words(p, sec->data, bytes / 4);
    }
}

/* The file header and every section with its header and CRC, into `b`
 * (`total` bytes). */
static void encode_bundle(const vsgl_scene_desc *d, const out_section *sec, int ns, uint64_t total, unsigned char *b)
{
    crc_table crc;
    crc_init(&crc);
    memset(b, 0, (size_t)total);
    memcpy(b, magic, 8);
    put_u32(b + 8, VSGL_BUNDLE_VERSION_MAJOR);
    put_u32(b + 12, VSGL_BUNDLE_VERSION_MINOR);
    put_u32(b + 16, HEADER_SIZE);
    put_u32(b + 20, (uint32_t)ns);
    put_u64(b + 24, total);
    put_u32(b + 32, 0);
    put_u32(b + 36, crc32_of(&crc, b, HEADER_SIZE - 4));
    uint64_t at = HEADER_SIZE;
    for (int i = 0; i < ns; ++i) {
        const section_kind *k = &kinds[sec[i].kind];
        unsigned char *h = b + at, *p = h + SECTION_HEADER_SIZE;
        uint64_t bytes = sec[i].count * k->element_size;
        memcpy(h, k->tag, 4);
        put_u32(h + 4, k->element_size);
        put_u64(h + 8, sec[i].count);
        encode_payload(d, &sec[i], bytes, p);
        put_u32(h + 16, 0); /* reserved */
        put_u32(h + 20, crc32_more(&crc, crc32_of(&crc, h, 20), p, (size_t)bytes));
        at += SECTION_HEADER_SIZE + padded(bytes);
    }
}

vsgl_result vsgl_bundle_write_memory(vsgl_context *ctx, const vsgl_scene_desc *scene,
                                     const vsgl_render_settings *settings, const vsgl_bundle_options *opt,
                                     void *buffer, size_t capacity, size_t *size)
{
    vsgl__clear_error(ctx);
    if (!scene || !size)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: scene and size must not be NULL");
    *size = 0;
    vsgl_scene_desc d;
    vsgl_render_settings s;
    vsgl_bundle_options o;
    size_t path_len = 0;
    uint64_t texel_floats = 0;
    vsgl_result r = vsgl__copy_versioned(ctx, &d, sizeof d, scene, "vsgl_scene_desc");
    if (r == VSGL_OK)
        r = vsgl__copy_versioned(ctx, &s, sizeof s, settings, "vsgl_render_settings");
    if (r == VSGL_OK)
        r = vsgl__copy_versioned(ctx, &o, sizeof o, opt, "vsgl_bundle_options");
    if (r == VSGL_OK)
        r = check_write_inputs(ctx, &d, &o, &path_len);
    if (r == VSGL_OK)
        r = check_write_values(ctx, &d, &texel_floats);
    if (r != VSGL_OK)
        return r;
    s.size = sizeof s;

    out_section sec[S_COUNT];
    int32_t frame = o.frame;
    int ns = list_sections(&d, &o, settings ? &s : NULL, &frame, path_len, texel_floats, sec);
    uint64_t total = HEADER_SIZE;
    for (int i = 0; i < ns; ++i)
        total += SECTION_HEADER_SIZE + padded(sec[i].count * kinds[sec[i].kind].element_size);
    if (total > (uint64_t)SIZE_MAX)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: %llu bytes do not fit in memory", (unsigned long long)total);
    *size = (size_t)total;
    if (!buffer)
        return VSGL_OK;
    if (capacity < total)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: buffer of %zu bytes, need %llu", capacity, (unsigned long long)total);
    encode_bundle(&d, sec, ns, total, buffer);
    return VSGL_OK;
}

vsgl_result vsgl_bundle_write(vsgl_context *ctx, const char *path, const vsgl_scene_desc *scene,
                              const vsgl_render_settings *settings, const vsgl_bundle_options *opt)
{
    size_t n = 0;
    vsgl_result r = vsgl_bundle_write_memory(ctx, scene, settings, opt, NULL, 0, &n);
    if (r)
        return r;
    if (!path || !*path)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle path is empty");
    void *buf = malloc(n);
    if (!buf)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "bundle: out of memory for %zu bytes", n);
    r = vsgl_bundle_write_memory(ctx, scene, settings, opt, buf, n, &n);
    if (!r)
        r = vsgl__atomic_write_all(ctx, path, buf, n);
    free(buf);
    return r;
}

/* ---- reader ------------------------------------------------------------- */

void vsgl_bundle_destroy(vsgl_bundle *b)
{
    if (!b)
        return;
    free(b->positions);
    free(b->indices);
    free(b->corner_normals);
    free(b->corner_uvs);
    free(b->corner_tangents);
    free(b->material_indices);
    free(b->materials);
    free(b->lights);
    free(b->corner_colors);
    free(b->material_textures);
    free(b->textures);
    free(b->texture_pixels);
    free(b->output_path);
    free(b);
}

#define ULL(x) ((unsigned long long)(x))
#define BAD(...) vsgl__fail(ctx, VSGL_ERROR_BAD_FORMAT, __VA_ARGS__)

/* Copy count*words little-endian 32-bit words into a new array; floats checked. */
static vsgl_result read_words(vsgl_context *ctx, int kind, const unsigned char *p, uint64_t count, void **out)
{
    const section_kind *k = &kinds[kind];
    uint64_t words = count * (k->element_size / 4);
    uint32_t *a = malloc(words ? (size_t)words * 4 : 4);
    if (!a)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "bundle: out of memory for section %s", k->tag);
    for (uint64_t w = 0; w < words; ++w) {
        a[w] = get_u32(p + 4 * w);
        if (k->floats_per_element) {
            float f;
            memcpy(&f, &a[w], 4);
            if (!isfinite(f)) {
                unsigned per = k->floats_per_element;
                free(a);
                return vsgl__fail(ctx, VSGL_ERROR_BAD_FORMAT, "bundle section %s (%s): %s %llu component %u is %s", k->tag,
                                  k->what, k->element, (unsigned long long)(w / per), (unsigned)(w % per), nonfinite_name(f));
            }
        }
    }
    *out = a;
    return VSGL_OK;
}

static vsgl_result read_records(vsgl_context *ctx, int kind, layout l, const unsigned char *p, uint64_t count,
                                uint32_t element_size, void *dst, size_t rec_size)
{
    const section_kind *k = &kinds[kind];
    for (uint64_t e = 0; e < count; ++e) {
        size_t f;
        unsigned c;
        if (decode_record(l, p + e * element_size, element_size, (unsigned char *)dst + e * rec_size, &f, &c) != 0) {
            float v;
            memcpy(&v, (unsigned char *)dst + e * rec_size + l.fields[f].offset + 4u * c, 4);
            return vsgl__fail(ctx, VSGL_ERROR_BAD_FORMAT, "bundle section %s (%s): %s %llu field %s%s is %s", k->tag,
                              k->what, k->element, (unsigned long long)e, l.fields[f].name, index_suffix(l.fields[f], c).s,
                              nonfinite_name(v));
        }
    }
    return VSGL_OK;
}

/* Where each known section's elements are, how many, of what size. */
typedef struct section_table {
    const unsigned char *where[S_COUNT];
    uint64_t counts[S_COUNT];
    uint32_t esizes[S_COUNT];
} section_table;

/* Magic, version, header size and CRC, file size, section count. */
static vsgl_result parse_header(vsgl_context *ctx, const unsigned char *b, size_t size, crc_table *crc,
                                uint32_t *header_size_out, uint32_t *section_count_out, vsgl_bundle *out)
{
    if (size < 16)
        return BAD("bundle truncated: %zu bytes, the header alone is %u", size, HEADER_SIZE);
    if (memcmp(b, magic, 8) != 0)
        return vsgl__fail(ctx, VSGL_ERROR_BAD_FORMAT, "not a VSGL scene bundle (wrong magic number)");
    uint32_t major = get_u32(b + 8), minor = get_u32(b + 12);
    if (major != VSGL_BUNDLE_VERSION_MAJOR)
        return vsgl__fail(ctx, VSGL_ERROR_VERSION_MISMATCH, "bundle format version %u.%u, this library reads %u.x",
                          major, minor, VSGL_BUNDLE_VERSION_MAJOR);
    if (size < HEADER_SIZE)
        return BAD("bundle truncated: %zu bytes, the header alone is %u", size, HEADER_SIZE);
    uint32_t header_size = get_u32(b + 16);
    if (header_size < HEADER_SIZE || header_size % 8u || header_size > size)
        return BAD("bundle header: size %u invalid or beyond the %zu bytes present", header_size, size);
    if (crc32_of(crc, b, header_size - 4) != get_u32(b + header_size - 4) && !IGNORE_CRC)
        return vsgl__fail(ctx, VSGL_ERROR_BAD_FORMAT, "bundle header is corrupt (CRC32 mismatch)");
    uint32_t section_count = get_u32(b + 20);
    uint64_t file_size = get_u64(b + 24);
    if (file_size > size)
        return BAD("bundle truncated: header says %llu bytes, only %zu present", ULL(file_size), size);
    if (file_size < size)
        return BAD("bundle has trailing data: header says %llu bytes, %zu present", ULL(file_size), size);
    if (section_count > MAX_SECTIONS)
        return BAD("bundle header: %u sections (at most %u)", section_count, MAX_SECTIONS);
    out->version_major = major;
    out->version_minor = minor;

    *header_size_out = header_size;
    *section_count_out = section_count;
    return VSGL_OK;
}

/* Every section: bounds, CRC, padding, kind, element size; known ones into t. */
static vsgl_result parse_sections(vsgl_context *ctx, const unsigned char *b, size_t size, const crc_table *crc,
                                  uint32_t header_size, uint32_t section_count, section_table *t)
{
    uint64_t at = header_size;
    for (uint32_t i = 0; i < section_count; ++i) {
        if (size - at < SECTION_HEADER_SIZE)
            return BAD("bundle truncated: section %u header at byte %llu", i, ULL(at));
        const unsigned char *h = b + at;
        char tag[5];
        for (int c = 0; c < 4; ++c)
            tag[c] = (h[c] >= 32 && h[c] < 127) ? (char)h[c] : '?';
        tag[4] = '\0';
        uint32_t esize = get_u32(h + 4);
        uint64_t count = get_u64(h + 8);
        uint64_t avail = size - at - SECTION_HEADER_SIZE;
        if (esize == 0 && count != 0)
            return BAD("bundle section %s: element size 0 with %llu elements", tag, ULL(count));
        if (esize != 0 && count > avail / esize)
            return BAD("bundle section %s: %llu elements of %u bytes exceed the file (truncated?)", tag, ULL(count), esize);
        uint64_t bytes = count * esize;
        if (padded(bytes) > avail)
            return BAD("bundle section %s: padding after %llu bytes exceeds the file", tag, ULL(bytes));
        const unsigned char *p = h + SECTION_HEADER_SIZE;
        if (crc32_more(crc, crc32_of(crc, h, 20), p, (size_t)bytes) != get_u32(h + 20) && !IGNORE_CRC)
            return BAD("bundle section %s is corrupt (CRC32 mismatch over %llu bytes)", tag, ULL(bytes));
        for (uint64_t z = bytes; z < padded(bytes); ++z)
            if (p[z])
                return BAD("bundle section %s: non-zero padding byte %llu", tag, ULL(z));
        at += SECTION_HEADER_SIZE + padded(bytes);
        int kind = -1;
        for (int k = 0; k < S_COUNT; ++k)
            if (memcmp(h, kinds[k].tag, 4) == 0)
                kind = k;
        if (kind < 0)
            continue; /* unknown section of a newer minor version: skipped */
        const section_kind *k = &kinds[kind];
        if (t->where[kind])
            return BAD("bundle section %s (%s) appears twice", k->tag, k->what);
        uint32_t min_size = k->min_size ? k->min_size : k->element_size;
        if (k->is_record ? esize < min_size : esize != k->element_size)
            return vsgl__fail(ctx, VSGL_ERROR_BAD_FORMAT, "bundle section %s (%s): element size %u, want %s%u", k->tag, k->what,
                              esize, k->is_record ? "at least " : "", k->is_record ? min_size : k->element_size);
        if (count > UINT32_MAX)
            return BAD("bundle section %s: %llu elements (at most %u)", k->tag, ULL(count), UINT32_MAX);
        t->where[kind] = p;
        t->counts[kind] = count;
        t->esizes[kind] = esize;
    }
    if (at != size)
        return BAD("bundle: %llu bytes after the last section", ULL(size - at));

    return VSGL_OK;
}

/* Counts that must agree between sections. */
static vsgl_result check_counts(vsgl_context *ctx, const section_table *t)
{
    if (!t->where[S_CAM] || t->counts[S_CAM] != 1)
        return BAD("bundle has %s camera (want exactly 1, got %llu)", t->where[S_CAM] ? "a bad" : "no", ULL(t->counts[S_CAM]));
    if (t->where[S_RSET] && t->counts[S_RSET] != 1)
        return BAD("bundle section RSET (render settings): %llu elements, want 1", ULL(t->counts[S_RSET]));
    if (t->where[S_FRME] && t->counts[S_FRME] != 1)
        return BAD("bundle section FRME (frame): %llu elements, want 1", ULL(t->counts[S_FRME]));
    if (t->where[S_OUTP] && t->counts[S_OUTP] > MAX_OUTPUT_PATH)
        return BAD("bundle section OUTP (output path): %llu bytes, at most %u", ULL(t->counts[S_OUTP]), MAX_OUTPUT_PATH);
    uint64_t nt = t->counts[S_IDX];
    static const int per_triangle[] = {S_NRM, S_UV, S_TAN, S_MIDX, S_CCOL};
    for (size_t i = 0; i < 5; ++i) {
        int kk = per_triangle[i];
        if (t->where[kk] && t->counts[kk] != nt)
            return vsgl__fail(ctx, VSGL_ERROR_BAD_FORMAT, "bundle section %s (%s): %llu elements, want %llu (one per triangle)",
                              kinds[kk].tag, kinds[kk].what, (unsigned long long)t->counts[kk], (unsigned long long)nt);
    }

    return VSGL_OK;
}

/* Geometry arrays, materials, lights and the camera. */
static vsgl_result read_scene(vsgl_context *ctx, const section_table *t, vsgl_bundle *out)
{
    uint64_t nt = t->counts[S_IDX];
    vsgl_result r;
    void *a = NULL;
    /* Arrays of zero elements stay NULL. */
    if (t->where[S_POS] && t->counts[S_POS] && (r = read_words(ctx, S_POS, t->where[S_POS], t->counts[S_POS], &a)))
        return r;
    out->positions = a;
    a = NULL;
    if (t->where[S_IDX] && nt && (r = read_words(ctx, S_IDX, t->where[S_IDX], nt, &a)))
        return r;
    out->indices = a;
    a = NULL;
    if (t->where[S_NRM] && nt && (r = read_words(ctx, S_NRM, t->where[S_NRM], nt, &a)))
        return r;
    out->corner_normals = a;
    a = NULL;
    if (t->where[S_UV] && nt && (r = read_words(ctx, S_UV, t->where[S_UV], nt, &a)))
        return r;
    out->corner_uvs = a;
    a = NULL;
    if (t->where[S_TAN] && nt && (r = read_words(ctx, S_TAN, t->where[S_TAN], nt, &a)))
        return r;
    out->corner_tangents = a;
    a = NULL;
    if (t->where[S_MIDX] && nt && (r = read_words(ctx, S_MIDX, t->where[S_MIDX], nt, &a)))
        return r;
    out->material_indices = a;

    uint64_t nm = t->counts[S_MATL], nl = t->counts[S_LGHT];
    out->materials = calloc(nm ? (size_t)nm : 1, sizeof(vsgl_material));
    out->lights = calloc(nl ? (size_t)nl : 1, sizeof(vsgl_light));
    if (!out->materials || !out->lights)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "bundle: out of memory for %llu materials and %llu lights",
                          (unsigned long long)nm, (unsigned long long)nl);
    if ((r = read_records(ctx, S_MATL, (layout)LAYOUT(material_fields), t->where[S_MATL], nm, t->esizes[S_MATL], out->materials, sizeof(vsgl_material))))
        return r;
    if ((r = read_records(ctx, S_LGHT, (layout)LAYOUT(light_fields), t->where[S_LGHT], nl, t->esizes[S_LGHT], out->lights, sizeof(vsgl_light))))
        return r;
    if ((r = read_records(ctx, S_CAM, (layout)LAYOUT(camera_fields), t->where[S_CAM], 1, t->esizes[S_CAM], &out->camera, sizeof(vsgl_camera))))
        return r;
    return VSGL_OK;
}

/* Format 1.2: corner colours, material texture slots, texture headers and pixels. */
static vsgl_result read_textures(vsgl_context *ctx, const section_table *t, vsgl_bundle *out)
{
    uint64_t nt = t->counts[S_IDX], nm = t->counts[S_MATL];
    vsgl_result r;
    void *a;
    a = NULL;
    if (t->where[S_CCOL] && nt && (r = read_words(ctx, S_CCOL, t->where[S_CCOL], nt, &a)))
        return r;
    out->corner_colors = a;
    if (t->where[S_MTEX]) {
        if (t->counts[S_MTEX] != nm)
            return BAD("bundle section MTEX (material textures): %llu elements, want %llu (one per material)",
                       ULL(t->counts[S_MTEX]), ULL(nm));
        out->material_textures = calloc(nm ? (size_t)nm : 1, sizeof(vsgl_material_textures));
        if (!out->material_textures)
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "bundle: out of memory for material textures");
        if ((r = read_records(ctx, S_MTEX, (layout)LAYOUT(mtex_fields), t->where[S_MTEX], nm, t->esizes[S_MTEX],
                              out->material_textures, sizeof(vsgl_material_textures))))
            return r;
    }
    uint64_t ntex = t->where[S_TEXH] ? t->counts[S_TEXH] : 0;
    if (ntex) {
        out->textures = calloc((size_t)ntex, sizeof(vsgl_texture));
        if (!out->textures)
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "bundle: out of memory for %llu textures", ULL(ntex));
        if ((r = read_records(ctx, S_TEXH, (layout)LAYOUT(texh_fields), t->where[S_TEXH], ntex, t->esizes[S_TEXH], out->textures,
                              sizeof(vsgl_texture))))
            return r;
        uint64_t want = 0;
        for (uint64_t i = 0; i < ntex; ++i) {
            const vsgl_texture *tx = &out->textures[i];
            if (tx->width < 1 || tx->height < 1 || tx->width > MAX_TEXTURE_SIDE || tx->height > MAX_TEXTURE_SIDE)
                return BAD("bundle section TEXH (texture headers): texture %llu is %ux%u (sides 1..%u)", ULL(i), tx->width,
                           tx->height, MAX_TEXTURE_SIDE);
            want += (uint64_t)tx->width * tx->height * 4;
        }
        if (!t->where[S_TEXP] || t->counts[S_TEXP] != want)
            return BAD("bundle section TEXP (texture pixels): %llu floats, the headers need %llu", ULL(t->counts[S_TEXP]),
                       ULL(want));
        a = NULL;
        if ((r = read_words(ctx, S_TEXP, t->where[S_TEXP], want, &a)))
            return r;
        out->texture_pixels = a;
        uint64_t off = 0;
        for (uint64_t i = 0; i < ntex; ++i) {
            out->textures[i].pixels = out->texture_pixels + off;
            off += (uint64_t)out->textures[i].width * out->textures[i].height * 4;
        }
    } else if (t->where[S_TEXP] && t->counts[S_TEXP]) {
        return BAD("bundle section TEXP (texture pixels) without TEXH (texture headers)");
    }
    return VSGL_OK;
}

/* Render settings, output path and frame. */
static vsgl_result read_extras(vsgl_context *ctx, const section_table *t, vsgl_bundle *out)
{
    vsgl_result r;
    if (t->where[S_RSET]) {
        if ((r = read_records(ctx, S_RSET, (layout)LAYOUT(settings_fields), t->where[S_RSET], 1, t->esizes[S_RSET], &out->settings,
                              sizeof(vsgl_render_settings))))
            return r;
        out->has_settings = 1;
    }
    out->settings.size = sizeof out->settings;
    size_t plen = t->where[S_OUTP] ? (size_t)t->counts[S_OUTP] : 0;
    out->output_path = malloc(plen + 1);
    if (!out->output_path)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "bundle: out of memory");
    if (plen) {
        if (memchr(t->where[S_OUTP], 0, plen))
            return vsgl__fail(ctx, VSGL_ERROR_BAD_FORMAT, "bundle section OUTP (output path): contains a NUL byte");
        memcpy(out->output_path, t->where[S_OUTP], plen);
    }
    out->output_path[plen] = '\0';
    if (t->where[S_FRME]) {
        out->has_frame = 1;
        uint32_t f = get_u32(t->where[S_FRME]);
        memcpy(&out->frame, &f, 4);
    }

    return VSGL_OK;
}

static void fill_desc(const section_table *t, vsgl_bundle *out)
{
    uint64_t nt = t->counts[S_IDX], nm = t->counts[S_MATL], nl = t->counts[S_LGHT];
    uint64_t ntex = t->where[S_TEXH] ? t->counts[S_TEXH] : 0;
    vsgl_scene_desc *d = &out->desc;
    d->size = sizeof *d;
    d->vertex_count = (uint32_t)t->counts[S_POS];
    d->positions = out->positions;
    d->triangle_count = (uint32_t)nt;
    d->indices = out->indices;
    d->corner_normals = out->corner_normals;
    d->corner_uvs = out->corner_uvs;
    d->corner_tangents = out->corner_tangents;
    d->material_indices = out->material_indices;
    d->material_count = (uint32_t)nm;
    d->materials = nm ? out->materials : NULL;
    d->light_count = (uint32_t)nl;
    d->lights = nl ? out->lights : NULL;
    d->camera = &out->camera;
    d->texture_count = (uint32_t)ntex;
    d->textures = ntex ? out->textures : NULL;
    d->material_textures = out->material_textures;
    d->corner_colors = out->corner_colors;
}

static vsgl_result parse(vsgl_context *ctx, const unsigned char *b, size_t size, vsgl_bundle *out)
{
    crc_table crc;
    crc_init(&crc);
    uint32_t header_size = 0, section_count = 0;
    section_table t;
    memset(&t, 0, sizeof t);
    vsgl_result r = parse_header(ctx, b, size, &crc, &header_size, &section_count, out);
    if (r == VSGL_OK)
        r = parse_sections(ctx, b, size, &crc, header_size, section_count, &t);
    if (r == VSGL_OK)
        r = check_counts(ctx, &t);
    if (r == VSGL_OK)
        r = read_scene(ctx, &t, out);
    if (r == VSGL_OK)
        r = read_textures(ctx, &t, out);
    if (r == VSGL_OK)
        r = read_extras(ctx, &t, out);
    if (r == VSGL_OK)
        fill_desc(&t, out);
    return r;
}

vsgl_result vsgl_bundle_read_memory(vsgl_context *ctx, const void *data, size_t size, vsgl_bundle **out)
{
    vsgl__clear_error(ctx);
    if (!out)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: out is NULL");
    *out = NULL;
    if (!data && size)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: data is NULL");
    vsgl_bundle *b = calloc(1, sizeof *b);
    if (!b)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "bundle: out of memory");
    vsgl_result r = parse(ctx, data ? data : (const void *)"", size, b);
    if (r) {
        vsgl_bundle_destroy(b);
        return r;
    }
    *out = b;
    return VSGL_OK;
}

vsgl_result vsgl_bundle_read(vsgl_context *ctx, const char *path, vsgl_bundle **out)
{
    vsgl__clear_error(ctx);
    if (!out)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle: out is NULL");
    *out = NULL;
    if (!path || !*path)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "bundle path is empty");
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return vsgl__fail(ctx, VSGL_ERROR_IO, "%s: %s", path, vsgl__strerror(errno).s);
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return vsgl__fail(ctx, VSGL_ERROR_IO, "%s: not a regular file", path);
    }
    if ((uint64_t)st.st_size > (uint64_t)SIZE_MAX / 2) {
        close(fd);
        return vsgl__fail(ctx, VSGL_ERROR_IO, "%s: too large (%lld bytes)", path, (long long)st.st_size);
    }
    size_t n = (size_t)st.st_size, got = 0;
    unsigned char *buf = malloc(n ? n : 1);
    if (!buf) {
        close(fd);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "%s: out of memory for %zu bytes", path, n);
    }
    while (got < n) {
        ssize_t k = read(fd, buf + got, n - got);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            break;
        got += (size_t)k;
    }
    int e = errno;
    close(fd);
    if (got < n) {
        free(buf);
        return vsgl__fail(ctx, VSGL_ERROR_IO, "%s: read failed: %s", path, vsgl__strerror(e).s);
    }
    vsgl_result r = vsgl_bundle_read_memory(ctx, buf, n, out);
    free(buf);
    if (r && ctx) {
        /* Prefix the file name to the reader's message. */
        char msg[VSGL__MESSAGE_MAX];
        snprintf(msg, sizeof msg, "%s", vsgl_context_last_error(ctx));
        vsgl__fail(ctx, r, "%s: %s", path, msg);
    }
    return r;
}

const vsgl_scene_desc *vsgl_bundle_scene(const vsgl_bundle *b)
{
    return b ? &b->desc : NULL;
}

const vsgl_render_settings *vsgl_bundle_settings(const vsgl_bundle *b)
{
    return b ? &b->settings : NULL;
}

vsgl_result vsgl_bundle_get_info(const vsgl_bundle *b, vsgl_bundle_info *info)
{
    if (!b || !info)
        return VSGL_ERROR_INVALID_ARGUMENT;
    const vsgl_bundle_info i = {
        .size = sizeof i,
        .version_major = b->version_major,
        .version_minor = b->version_minor,
        .output_path = b->output_path,
        .has_frame = b->has_frame,
        .frame = b->frame,
        .has_settings = b->has_settings,
    };
    return vsgl__return_versioned(NULL, info, &i, sizeof i, "vsgl_bundle_info");
}
