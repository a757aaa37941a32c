/* Multilayer OpenEXR writer on OpenEXR Core's C API, written atomically. */
#include "vsgl/io.h"
#include "core/versioned.h"
#include "core/context.h"
#include "io/atomic.h"
#include "io/half.h"
#include "core/parallel.h"
#include "io/exr_zip.h"

#include <openexr.h>

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_PASSES 64
#define MAX_NAME 63
#define MAX_CHANNELS_TOTAL (MAX_PASSES * VSGL_EXR_MAX_CHANNELS)

/* Round-to-nearest-even float -> half. Finite inputs beyond the half range
 * are clamped to +/-65504 (the writer never stores an infinity). */
static uint16_t float_to_half(float f)
{
    uint32_t x;
    memcpy(&x, &f, sizeof x);
    uint32_t sign = (x >> 16) & 0x8000u;
    uint32_t ax = x & 0x7fffffffu;
    if (ax >= 0x477fe000u) /* >= 65520: would round to infinity */
        return (uint16_t)(sign | 0x7bffu);
    if (ax < 0x38800000u) { /* below 2^-14: half subnormal (or zero), unit 2^-24 */
        float a;
        memcpy(&a, &ax, sizeof a);
        return (uint16_t)(sign | (uint32_t)rintf(a * 0x1p24f)); /* 1024 = smallest normal, encoded right */
    }
    uint32_t h = ((((ax >> 23) - 127u + 15u) << 10) | ((ax & 0x7fffffu) >> 13));
    uint32_t rem = ax & 0x1fffu;
    if (rem > 0x1000u || (rem == 0x1000u && (h & 1u)))
        ++h; /* a carry into the exponent is the right result */
    return (uint16_t)(sign | h);
}

/* One row of w samples (stride floats apart) -> half, into d (2 bytes each). */
static void row_to_half_scalar(const float *row, size_t stride, uint32_t w, unsigned char *d)
{
    for (uint32_t x = 0; x < w; ++x) {
        uint16_t h = float_to_half(row[(size_t)x * stride]);
        memcpy(d + 2 * (size_t)x, &h, 2);
    }
}

#if defined(__x86_64__) && defined(__GNUC__)
#include <cpuid.h>
#include <immintrin.h>

/* CPUID's F16C and AVX bits, and the OS saving the AVX registers (XCR0
 * bits 1-2): the VEX-encoded conversion needs all three. Read through
 * <cpuid.h>, which gcc and clang both have (clang 14's
 * __builtin_cpu_supports does not know "f16c"). CPUID may trap to a
 * hypervisor, so a write asks once, not per row. */
int vsgl__exr_cpu_has_f16c(void)
{
    unsigned a, b, c, d;
    if (!__get_cpuid(1, &a, &b, &c, &d))
        return 0;
    if (!(c & bit_F16C) || !(c & bit_AVX) || !(c & bit_OSXSAVE))
        return 0;
    unsigned lo, hi;
    __asm__ volatile("xgetbv" : "=a"(lo), "=d"(hi) : "c"(0));
    (void)hi;
    return (lo & 6u) == 6u;
}

/* The same with the F16C instruction, 8 samples at a time: clamped to
 * +/-65504 first, then rounded to nearest even, which is float_to_half's
 * result bit for bit (subnormals and signed zeros included; the writer has
 * refused non-finite samples; exr_half_conversion_matches_exact_rounding
 * checks both paths against an exact reference). At 1920 x 1080 x 18
 * channels: ~4x less CPU than the scalar branches. */
__attribute__((target("avx,f16c"))) static void row_to_half_f16c(const float *row, size_t stride, uint32_t w,
                                                                 unsigned char *d)
{
    const __m256 hi = _mm256_set1_ps(65504.0f), lo = _mm256_set1_ps(-65504.0f);
    uint32_t x = 0;
    for (; x + 8 <= w; x += 8) {
        const float *r = row + (size_t)x * stride;
        __m256 v = stride == 1 ? _mm256_loadu_ps(r)
                               : _mm256_set_ps(r[7 * stride], r[6 * stride], r[5 * stride], r[4 * stride],
                                               r[3 * stride], r[2 * stride], r[stride], r[0]);
        v = _mm256_min_ps(_mm256_max_ps(v, lo), hi);
        _mm_storeu_si128((__m128i *)(void *)(d + 2 * (size_t)x), _mm256_cvtps_ph(v, _MM_FROUND_TO_NEAREST_INT));
    }
    row_to_half_scalar(row + (size_t)x * stride, stride, w - x, d + 2 * (size_t)x);
}
#else
int vsgl__exr_cpu_has_f16c(void)
{
    return 0;
}
#endif

void vsgl__exr_row_to_half(const float *row, size_t stride, uint32_t w, unsigned char *d, int f16c)
{
#if defined(__x86_64__) && defined(__GNUC__)
    if (f16c) {
        row_to_half_f16c(row, stride, w, d);
        return;
    }
#endif
    (void)f16c;
    row_to_half_scalar(row, stride, w, d);
}

static int valid_name(const char *s)
{
    if (!s || !*s || strlen(s) > MAX_NAME)
        return 0;
    for (; *s; ++s) {
        char c = *s;
        if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-'))
            return 0;
    }
    return 1;
}

/* One file channel: where its samples come from. */
typedef struct src_channel {
    char name[2 * MAX_NAME + 4];
    const float *data;
    size_t stride;
    const char *pass;
    char letter;
} src_channel;

typedef struct exr_sink {
    vsgl__atomic_file file;
    pthread_mutex_t lock; /* guards message: encoding threads may report errors */
    char message[256];
} exr_sink;

static int64_t sink_write(exr_const_context_t c, void *user, const void *buf, uint64_t sz,
                          uint64_t offset, exr_stream_error_func_ptr_t err)
{
    (void)c;
    (void)err;
    exr_sink *s = user;
    if (vsgl__atomic_pwrite(&s->file, buf, (size_t)sz, offset) != 0)
        return -1;
    return (int64_t)sz;
}

static void sink_error(exr_const_context_t c, exr_result_t code, const char *msg)
{
    void *user = NULL;
    if (exr_get_user_data(c, &user) == EXR_ERR_SUCCESS && user) {
        exr_sink *s = user;
        pthread_mutex_lock(&s->lock);
        if (!s->message[0])
            snprintf(s->message, sizeof s->message, "%s (%s)", msg ? msg : "", exr_get_error_code_as_string(code));
        pthread_mutex_unlock(&s->lock);
    }
}

static vsgl_result exr_failed(vsgl_context *ctx, exr_sink *s, const char *path, const char *what, exr_result_t rv)
{
    if (s->file.error)
        return vsgl__fail(ctx, VSGL_ERROR_IO, "%s: write failed: %s", path, vsgl__strerror(s->file.error).s);
    return vsgl__fail(ctx, VSGL_ERROR_INTERNAL, "%s: OpenEXR %s failed: %s", path, what,
                      s->message[0] ? s->message : exr_get_default_error_message(rv));
}

/* The rows [b, e) of every channel (row r: channel r / height, y = r % height)
 * that hold a non-finite sample, flagged in bad[r]. */
typedef struct finite_job {
    const src_channel *chans;
    uint32_t width, height;
    unsigned char *bad;
} finite_job;

static int32_t flag_rows(void *user, size_t chunk, size_t b, size_t e)
{
    (void)chunk;
    const finite_job *j = user;
    for (size_t r = b; r < e; ++r) {
        const src_channel *s = &j->chans[r / j->height];
        const float *row = s->data + (r % j->height) * j->width * s->stride;
        uint32_t any = 0;
        for (uint32_t x = 0; x < j->width; ++x) {
            uint32_t bits;
            memcpy(&bits, &row[(size_t)x * s->stride], sizeof bits);
            any |= (bits & 0x7f800000u) == 0x7f800000u;
        }
        j->bad[r] = (unsigned char)any;
    }
    return 0;
}

static vsgl_result check_args(vsgl_context *ctx, uint32_t width, uint32_t height,
                              const vsgl_exr_pass *passes, uint32_t pass_count,
                              const vsgl_exr_options *o, src_channel *chans, uint32_t *chan_count)
{
    if (width < 1 || width > 65535 || height < 1 || height > 65535)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR size %ux%u: width and height must be in [1, 65535]", width, height);
    if (!passes || pass_count < 1 || pass_count > MAX_PASSES)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR needs 1 to %d passes, got %u%s", MAX_PASSES, pass_count, passes ? "" : " (NULL)");
    const char *layer = o->layer ? o->layer : "VSGL";
    if (!valid_name(layer))
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR layer name '%s' must be 1-%d characters of [A-Za-z0-9_-]", layer, MAX_NAME);
    if (o->pixel_type != VSGL_EXR_FLOAT && o->pixel_type != VSGL_EXR_HALF)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR pixel type %d is not VSGL_EXR_FLOAT or VSGL_EXR_HALF", o->pixel_type);
    if (o->compression < VSGL_EXR_ZIP || o->compression >= VSGL_EXR_COMPRESSION_COUNT)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR compression %d is unknown", o->compression);
    if (o->zip_level < 0 || o->zip_level > 9)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR zip level %d is not 1..9 (0 = %d)", o->zip_level,
                          VSGL_EXR_ZIP_LEVEL_DEFAULT);
    if (o->metadata_count && !o->metadata)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR metadata: %u entries but NULL array", o->metadata_count);
    for (uint32_t i = 0; i < o->metadata_count; ++i) {
        const vsgl_exr_metadata *m = &o->metadata[i];
        if (!m->key || !*m->key || strlen(m->key) > 255 || !m->value || strlen(m->value) > 65535)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR metadata %u: key must be 1-255 characters and value non-NULL, <= 65535 bytes", i);
    }
    uint32_t n = 0;
    for (uint32_t p = 0; p < pass_count; ++p) {
        const vsgl_exr_pass *ps = &passes[p];
        if (!valid_name(ps->name))
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR pass %u: name '%s' must be 1-%d characters of [A-Za-z0-9_-]",
                              p, ps->name ? ps->name : "(null)", MAX_NAME);
        for (uint32_t q = 0; q < p; ++q)
            if (strcmp(passes[q].name, ps->name) == 0)
                return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR pass %u: name '%s' is used twice", p, ps->name);
        const char *letters = ps->channels ? ps->channels : "RGB";
        size_t nc = strlen(letters);
        if (nc < 1 || nc > VSGL_EXR_MAX_CHANNELS)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR pass %s: %zu channels, must be 1 to %d", ps->name, nc, VSGL_EXR_MAX_CHANNELS);
        for (size_t c = 0; c < nc; ++c) {
            char l = letters[c];
            if (!((l >= 'A' && l <= 'Z') || (l >= 'a' && l <= 'z')) || memchr(letters, l, c))
                return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR pass %s: channel letters '%s' must be distinct letters", ps->name, letters);
            if (!ps->data[c])
                return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR pass %s: channel %c has NULL data", ps->name, l);
            src_channel *s = &chans[n++];
            snprintf(s->name, sizeof s->name, "%s.%s.%c", layer, ps->name, l);
            s->data = ps->data[c];
            s->stride = ps->stride[c] ? ps->stride[c] : nc;
            s->pass = ps->name;
            s->letter = l;
        }
    }
    *chan_count = n;
    /* Refuse non-finite samples before any file exists: the rows checked
     * in parallel without a branch (an exponent of all ones), then the
     * first bad sample of the first flagged row, in order */
    size_t rows = (size_t)n * height;
    unsigned char *bad = calloc(rows ? rows : 1, 1);
    if (!bad)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "out of memory");
    finite_job fj = {chans, width, height, bad};
    vsgl__parallel_ctx(ctx, rows, 64, flag_rows, &fj);
    for (size_t r = 0; r < rows; ++r) {
        if (!bad[r])
            continue;
        const src_channel *s = &chans[r / height];
        uint32_t y = (uint32_t)(r % height);
        const float *row = s->data + (size_t)y * width * s->stride;
        for (uint32_t x = 0; x < width; ++x) {
            float v = row[(size_t)x * s->stride];
            if (!isfinite(v)) {
                free(bad);
                return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "pass %s channel %c pixel (%u, %u): %s",
                                  s->pass, s->letter, x, y, isnan(v) ? "NaN" : (v > 0 ? "+Inf" : "-Inf"));
            }
        }
    }
    free(bad);
    return VSGL_OK;
}

/* ---- chunk encoding, in parallel ------------------------------------------
 * Chunks (16 scanlines for ZIP) are converted and compressed by worker
 * threads, each with its own pipeline, into per-chunk buffers; the calling
 * thread then writes them in increasing y, as the line order requires. */

typedef struct chunk_out { unsigned char *data; uint64_t size; exr_result_t rv; } chunk_out;

typedef struct encode_job {
    exr_context_t e;
    int part;
    uint32_t width;
    size_t bpe;
    exr_pixel_type_t ptype;
    const src_channel *chans;
    uint32_t n;
    const exr_chunk_info_t *infos; /* every chunk */
    chunk_out *outs;               /* the current batch */
    size_t batch_begin;
    int f16c; /* vsgl__exr_cpu_has_f16c(), asked once per write */
    int zip_level;         /* ZIP / ZIPS: libdeflate's level (exr_zip.h), else 0 (OpenEXR Core's pipeline) */
    const uint32_t *order; /* with zip_level: the file's channel k is chans[order[k]] */
} encode_job;

/* The pipeline's last step: keep the compressed bytes instead of writing. */
static exr_result_t capture_chunk(exr_encode_pipeline_t *enc)
{
    chunk_out *out = enc->encoding_user_data;
    const void *src = enc->compressed_buffer;
    uint64_t size = enc->compressed_bytes;
    if (!src || !size) {
        src = enc->packed_buffer;
        size = enc->packed_bytes;
    }
    out->data = malloc(size ? (size_t)size : 1);
    if (!out->data)
        return EXR_ERR_OUT_OF_MEMORY;
    memcpy(out->data, src, (size_t)size);
    out->size = size;
    return EXR_ERR_SUCCESS;
}

static exr_result_t no_wait(exr_encode_pipeline_t *enc)
{
    (void)enc;
    return EXR_ERR_SUCCESS;
}

/* Row y of channel s as the file stores it: half or float samples, packed. */
static void pack_row(const encode_job *j, const src_channel *s, uint32_t y, unsigned char *d)
{
    const float *row = s->data + (size_t)y * j->width * s->stride;
    if (j->bpe == 2) {
        vsgl__exr_row_to_half(row, s->stride, j->width, d, j->f16c);
    } else {
        for (uint32_t x = 0; x < j->width; ++x)
            memcpy(d + 4 * (size_t)x, &row[(size_t)x * s->stride], 4);
    }
}

/* Chunks [begin, end) packed in the file's line layout (per line, the
 * channels in file order, each a row of samples) and deflated by libdeflate
 * (exr_zip.h). */
static int32_t zip_chunks(encode_job *j, size_t begin, size_t end)
{
    vsgl__zip_coder *z = vsgl__zip_coder_new(j->zip_level);
    unsigned char *packed = NULL;
    size_t cap = 0;
    int32_t failed = z ? 0 : 1;
    for (size_t k = begin; k < end && !failed; ++k) {
        chunk_out *out = &j->outs[k - j->batch_begin];
        const exr_chunk_info_t *ci = &j->infos[k];
        uint32_t rows = (uint32_t)ci->height, y0 = (uint32_t)ci->start_y;
        size_t line = (size_t)j->width * j->bpe, n = line * j->n * rows;
        if (n > cap) {
            unsigned char *p = realloc(packed, n);
            if (!p) {
                failed = 1;
                break;
            }
            packed = p;
            cap = n;
        }
        unsigned char *d = packed;
        for (uint32_t r = 0; r < rows; ++r)
            for (uint32_t c = 0; c < j->n; ++c, d += line)
                pack_row(j, &j->chans[j->order[c]], y0 + r, d);
        if (vsgl__zip_encode(z, packed, n, &out->data, &out->size) != 0)
            failed = 1;
    }
    if (failed)
        j->outs[begin - j->batch_begin].rv = EXR_ERR_OUT_OF_MEMORY;
    free(packed);
    vsgl__zip_coder_free(z);
    return failed;
}

static int32_t encode_chunks(void *user, size_t chunk, size_t begin, size_t end)
{
    (void)chunk;
    encode_job *j = user;
    if (j->zip_level)
        return zip_chunks(j, begin, end);
    for (size_t k = begin; k < end; ++k) {
        chunk_out *out = &j->outs[k - j->batch_begin];
        const exr_chunk_info_t *ci = &j->infos[k];
        exr_encode_pipeline_t enc;
        memset(&enc, 0, sizeof enc);
        exr_result_t rv = exr_encoding_initialize(j->e, j->part, ci, &enc);
        if (rv) {
            out->rv = rv;
            return 1;
        }
        uint32_t rows = (uint32_t)ci->height, y0 = (uint32_t)ci->start_y;
        size_t plane = (size_t)j->width * rows * j->bpe;
        unsigned char *scratch = malloc(plane * j->n);
        if (!scratch)
            rv = EXR_ERR_OUT_OF_MEMORY;
        for (int16_t c = 0; c < enc.channel_count && !rv; ++c) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            uint32_t i = 0;
            while (i < j->n && strcmp(j->chans[i].name, ch->channel_name) != 0)
                ++i;
            if (i == j->n) {
                rv = EXR_ERR_INVALID_ARGUMENT;
                break;
            }
            unsigned char *dst = scratch + (size_t)i * plane;
            const src_channel *s = &j->chans[i];
            for (uint32_t r = 0; r < rows; ++r)
                pack_row(j, s, y0 + r, dst + (size_t)r * j->width * j->bpe);
            ch->encode_from_ptr = dst;
            ch->user_pixel_stride = (int32_t)j->bpe;
            ch->user_line_stride = (int32_t)(j->width * j->bpe);
            ch->user_bytes_per_element = (int16_t)j->bpe;
            ch->user_data_type = (uint16_t)j->ptype;
        }
        if (!rv)
            rv = exr_encoding_choose_default_routines(j->e, j->part, &enc);
        if (!rv) {
            enc.write_fn = capture_chunk;
            enc.yield_until_ready_fn = no_wait; /* order is kept by the writing thread */
            enc.encoding_user_data = out;
            rv = exr_encoding_run(j->e, j->part, &enc);
        }
        exr_encoding_destroy(j->e, &enc);
        free(scratch);
        if (rv) {
            out->rv = rv;
            return 1;
        }
    }
    return 0;
}

static int32_t encode_chunks_batch(void *user, size_t chunk, size_t begin, size_t end)
{
    encode_job *j = user;
    return encode_chunks(user, chunk, j->batch_begin + begin, j->batch_begin + end);
}

/* Header and pixels into an open sink. */
static vsgl_result write_exr(vsgl_context *ctx, exr_sink *sink, const char *path, uint32_t width, uint32_t height,
                             const src_channel *chans, uint32_t n, const vsgl_exr_options *o)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = sink_error;
    init.user_data = sink;
    init.write_fn = sink_write;
    init.zip_level = o->zip_level ? o->zip_level : VSGL_EXR_ZIP_LEVEL_DEFAULT; /* ZIP, ZIPS: not in the file */
    exr_context_t e = NULL;
    exr_result_t rv = exr_start_write(&e, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv != EXR_ERR_SUCCESS)
        return exr_failed(ctx, sink, path, "start", rv);

    static const exr_compression_t comp[VSGL_EXR_COMPRESSION_COUNT] = {
        EXR_COMPRESSION_ZIP, EXR_COMPRESSION_NONE, EXR_COMPRESSION_ZIPS, EXR_COMPRESSION_PIZ, EXR_COMPRESSION_RLE,
        EXR_COMPRESSION_PXR24, EXR_COMPRESSION_B44, EXR_COMPRESSION_B44A};
    exr_pixel_type_t ptype = o->pixel_type == VSGL_EXR_HALF ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT;
    int part = 0;
    const char *what = "header";
    vsgl_result result = VSGL_OK;
    exr_chunk_info_t *infos = NULL;
    chunk_out *outs = NULL;
    size_t batch = 0;

    rv = exr_add_part(e, NULL, EXR_STORAGE_SCANLINE, &part);
    if (!rv)
        rv = exr_initialize_required_attr_simple(e, part, (int32_t)width, (int32_t)height, comp[o->compression]);
    for (uint32_t i = 0; i < n && !rv; ++i)
        rv = exr_add_channel(e, part, chans[i].name, ptype, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (!rv)
        rv = exr_attr_set_string(e, part, "vsgl.version", vsgl_version_string());
    for (uint32_t i = 0; i < o->metadata_count && !rv; ++i) {
        const exr_attribute_t *a = NULL;
        if (exr_get_attribute_by_name(e, part, o->metadata[i].key, &a) == EXR_ERR_SUCCESS) {
            result = vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR metadata key '%s' is used twice or is a standard attribute",
                                o->metadata[i].key);
            goto done;
        }
        rv = exr_attr_set_string(e, part, o->metadata[i].key, o->metadata[i].value);
    }
    if (!rv)
        rv = exr_write_header(e);
    if (rv)
        goto exr_error;

    what = "pixels";
    int32_t lines = 0;
    rv = exr_get_scanlines_per_chunk(e, part, &lines);
    if (rv)
        goto exr_error;
    size_t nchunks = (height + (uint32_t)lines - 1) / (uint32_t)lines;
    uint32_t threads = vsgl_context_thread_count(ctx);
    batch = 8u * threads;
    infos = calloc(nchunks, sizeof *infos);
    outs = calloc(batch, sizeof *outs);
    if (!infos || !outs) {
        result = vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
        goto done;
    }
    for (size_t k = 0; k < nchunks; ++k) {
        rv = exr_write_scanline_chunk_info(e, part, (int)(k * (uint32_t)lines), &infos[k]);
        if (rv)
            goto exr_error;
    }
    /* ZIP and ZIPS: libdeflate (exr_zip.h) on the file's channel order */
    uint32_t order[MAX_CHANNELS_TOTAL];
    int zip = o->compression == VSGL_EXR_ZIP || o->compression == VSGL_EXR_ZIPS;
    if (zip) {
        const exr_attr_chlist_t *cl = NULL;
        rv = exr_get_channels(e, part, &cl);
        if (!rv && cl->num_channels != (int)n)
            rv = EXR_ERR_INVALID_ARGUMENT; /* the header holds every channel added above, and no other */
        if (rv)
            goto exr_error;
        for (int k = 0; k < cl->num_channels; ++k) {
            uint32_t i = 0;
            while (i < n && strcmp(chans[i].name, cl->entries[k].name.str) != 0)
                ++i;
            if (i == n) {
                rv = EXR_ERR_INVALID_ARGUMENT;
                goto exr_error;
            }
            order[k] = i;
        }
    }
    encode_job job = {e, part, width, ptype == EXR_PIXEL_HALF ? 2u : 4u, ptype, chans, n, infos, outs, 0,
                      vsgl__exr_cpu_has_f16c(), zip ? (o->zip_level ? o->zip_level : VSGL_EXR_ZIP_LEVEL_DEFAULT) : 0,
                      order};
    for (size_t b0 = 0; b0 < nchunks; b0 += batch) {
        size_t b1 = b0 + batch < nchunks ? b0 + batch : nchunks;
        /* SIGINT in the CLI, Esc in the add-on: stop between batches (a 4K
         * write takes 12-15 s); the caller deletes the temporary file. */
        if (vsgl__progress(ctx, "write", (float)b0 / (float)nchunks)) {
            result = vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "%s: write cancelled; a previous file there is kept", path);
            goto done;
        }
        job.batch_begin = b0;
        int32_t failed = vsgl__parallel_ctx(ctx, b1 - b0, 1, encode_chunks_batch, &job);
        for (size_t k = b0; k < b1 && !rv; ++k) {
            chunk_out *out = &outs[k - b0];
            if (failed && (out->rv || !out->data))
                rv = out->rv ? out->rv : EXR_ERR_OUT_OF_MEMORY;
            else
                rv = exr_write_scanline_chunk(e, part, infos[k].start_y, out->data, out->size);
        }
        for (size_t k = 0; k < batch; ++k) {
            free(outs[k].data);
            memset(&outs[k], 0, sizeof outs[k]);
        }
        if (rv)
            goto exr_error;
    }
    what = "finish";
    rv = exr_finish(&e);
    e = NULL;
    if (rv)
        goto exr_error;
    goto done;

exr_error:
    result = exr_failed(ctx, sink, path, what, rv);
done:
    if (e)
        exr_finish(&e);
    if (outs)
        for (size_t k = 0; k < batch; ++k)
            free(outs[k].data);
    free(outs);
    free(infos);
    return result;
}

vsgl_result vsgl_exr_write(vsgl_context *ctx, const char *path, uint32_t width, uint32_t height,
                           const vsgl_exr_pass *passes, uint32_t pass_count, const vsgl_exr_options *opt)
{
    vsgl__clear_error(ctx);
    vsgl_exr_options o;
    vsgl_result rv = vsgl__copy_versioned(ctx, &o, sizeof o, opt, "vsgl_exr_options");
    if (rv != VSGL_OK)
        return rv;
    if (!path || !*path)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "EXR path is empty");
    src_channel *chans = calloc(MAX_CHANNELS_TOTAL, sizeof *chans);
    if (!chans)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "out of memory");
    uint32_t n = 0;
    vsgl_result r = check_args(ctx, width, height, passes, pass_count, &o, chans, &n);
    if (r) {
        free(chans);
        return r;
    }
    exr_sink sink;
    memset(&sink, 0, sizeof sink);
    r = vsgl__atomic_open(ctx, path, &sink.file);
    if (r) {
        free(chans);
        return r;
    }
    pthread_mutex_init(&sink.lock, NULL);
    r = write_exr(ctx, &sink, path, width, height, chans, n, &o);
    pthread_mutex_destroy(&sink.lock);
    free(chans);
    if (!r && vsgl__progress(ctx, "write", 1.0f))
        r = vsgl__fail(ctx, VSGL_ERROR_CANCELLED, "%s: write cancelled; a previous file there is kept", path);
    if (r) {
        vsgl__atomic_abort(&sink.file);
        return r;
    }
    return vsgl__atomic_commit(ctx, &sink.file);
}

vsgl_result vsgl_exr_write_render(vsgl_context *ctx, const char *path, const vsgl_render_output *caller_out,
                                  const vsgl_exr_options *opt)
{
    vsgl__clear_error(ctx);
    if (!caller_out)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "render output is NULL");
    vsgl_render_output o;
    const vsgl_render_output *out = &o;
    vsgl_result rv = vsgl__copy_versioned(ctx, &o, sizeof o, caller_out, "vsgl_render_output");
    if (rv != VSGL_OK)
        return rv;
    vsgl_exr_pass passes[7];
    memset(passes, 0, sizeof passes);
    uint32_t n = 0;
    const struct { const char *name; const float *data; } rgb[6] = {
        {"DiffInd", out->diffuse_light}, {"GlossInd", out->glossy_light},
        {"DiffCol", out->diffuse_color}, {"GlossCol", out->glossy_color},
        {"Diff", out->diffuse},          {"Gloss", out->glossy},
    };
    for (int i = 0; i < 6; ++i) {
        if (!rgb[i].data)
            continue;
        vsgl_exr_pass *p = &passes[n++];
        p->name = rgb[i].name;
        p->channels = "RGB";
        for (int c = 0; c < 3; ++c)
            p->data[c] = rgb[i].data + c;
    }
    /* Combined: RGB from `combined`, A from `alpha` (a buffer of ones when absent). */
    float *ones = NULL;
    if (out->combined) {
        vsgl_exr_pass *p = &passes[n++];
        p->name = "Combined";
        p->channels = "RGBA";
        for (int c = 0; c < 3; ++c) {
            p->data[c] = out->combined + c;
            p->stride[c] = 3;
        }
        if (!out->alpha) {
            size_t count = (size_t)out->width * out->height;
            ones = malloc((count ? count : 1) * sizeof *ones);
            if (!ones)
                return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "out of memory");
            for (size_t i = 0; i < count; ++i)
                ones[i] = 1.0f;
        }
        p->data[3] = out->alpha ? out->alpha : ones;
        p->stride[3] = 1;
    } else if (out->alpha) {
        vsgl_exr_pass *p = &passes[n++];
        p->name = "Combined";
        p->channels = "A";
        p->data[0] = out->alpha;
        p->stride[0] = 1;
    }
    if (n == 0)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "render output has no planes to write");
    vsgl_result r = vsgl_exr_write(ctx, path, out->width, out->height, passes, n, opt);
    free(ones);
    return r;
}
