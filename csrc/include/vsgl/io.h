/**
 * @file vsgl/io.h
 * @brief Files: the multilayer OpenEXR output (one socket per pass in
 * Blender's Image node) and the scene bundle (a self-contained, versioned
 * binary copy of a ::vsgl_scene_desc plus ::vsgl_render_settings).
 *
 * Every writer is atomic: it writes a uniquely named temporary file in
 * the target's directory, fsyncs it, renames it over the target and
 * fsyncs the directory. On any failure the temporary file is deleted and
 * a previous file at the target path is left untouched; a reader never
 * sees a half-written file. New files get mode 0666 minus the umask. (Only
 * a crash or kill mid-write can leave the hidden temporary file
 * `.NAME.tmp-PID-NS-TRY-HOST` beside the target; the next write into that
 * directory deletes such files of this host whose process is gone and logs
 * a warning naming each.)
 *
 * Readers never trust a file: every count is capped by the bytes actually
 * present before anything is allocated, every section is length- and
 * CRC32-checked, and non-finite floats are refused with a message naming
 * the section and element (see ::vsgl_context_last_error).
 *
 * Formats: docs/bundle-format.md (bundle), docs/references.md §5 and this header (EXR).
 */
#ifndef VSGL_IO_H
#define VSGL_IO_H

#include "render.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------ */
/* Output paths                                                              */
/* ------------------------------------------------------------------------ */

/**
 * @brief Check, before a long render, that @p path can be written by the
 * atomic writers: its directory exists and accepts a new file (a
 * temporary file is created and deleted), and @p path is not a directory.
 * Nothing at @p path is modified.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT (NULL or empty path),
 *         ::VSGL_ERROR_IO (message names the path and the reason).
 */
VSGL_API vsgl_result vsgl_check_output_path(vsgl_context *ctx, const char *path);

/* ------------------------------------------------------------------------ */
/* Multilayer OpenEXR                                                        */
/* ------------------------------------------------------------------------ */

#define VSGL_EXR_FLOAT 0 /**< 32-bit float samples (default) */
#define VSGL_EXR_HALF  1 /**< 16-bit half samples; finite values beyond +/-65504 are clamped to it */

#define VSGL_EXR_ZIP  0 /**< ZIP, 16 scanlines per block (default) */
#define VSGL_EXR_NONE 1 /**< uncompressed */
#define VSGL_EXR_ZIPS 2 /**< ZIP, one scanline per block */
#define VSGL_EXR_PIZ  3 /**< wavelet, good for noisy images */
#define VSGL_EXR_RLE  4 /**< run-length */
#define VSGL_EXR_PXR24 5 /**< lossy for float: 24-bit floats, then ZIP (half stored exactly) */
#define VSGL_EXR_B44  6 /**< lossy, half channels only (float channels stored uncompressed) */
#define VSGL_EXR_B44A 7 /**< B44, flat areas smaller */
/** Number of compressions: Blender's list but DWAA/DWAB, which OpenEXR Core
 *  3.1 (Debian 12's) cannot encode (docs/performance.md measures them). */
#define VSGL_EXR_COMPRESSION_COUNT 8

/** Largest number of channels of one pass. */
#define VSGL_EXR_MAX_CHANNELS 4

/**
 * One pass: 1 to 4 channels, each read from caller memory as
 * `data[c][(y * width + x) * stride[c]]`, rows from the top of the image
 * down (the renderer's layout). The file's channel is named
 * `Layer.Pass.Channel`, e.g. `VSGL.DiffInd.R`.
 */
typedef struct vsgl_exr_pass {
    const char *name;        /**< pass name: 1-63 chars of [A-Za-z0-9_-] (no dots), unique */
    const char *channels;    /**< one letter per channel, e.g. "RGB", "RGBA", "A", "V"; NULL = "RGB" */
    const float *data[VSGL_EXR_MAX_CHANNELS]; /**< per channel: its sample of pixel (0, 0) */
    uint32_t stride[VSGL_EXR_MAX_CHANNELS];   /**< per channel: floats between neighbouring pixels; 0 = number of channels (interleaved) */
} vsgl_exr_pass;

/** A string attribute written into the EXR header. */
typedef struct vsgl_exr_metadata {
    const char *key;         /**< 1-255 chars, not a standard EXR attribute name, unique */
    const char *value;       /**< any UTF-8 text (<= 65535 bytes) */
} vsgl_exr_metadata;

/** Writer options; zero-initialised (or a NULL pointer) means every default. */
typedef struct vsgl_exr_options {
    uint32_t size;           /**< sizeof(vsgl_exr_options) or 0 */
    const char *layer;       /**< layer name, same rules as a pass name; NULL = "VSGL" */
    int32_t pixel_type;      /**< VSGL_EXR_FLOAT (default) or VSGL_EXR_HALF */
    int32_t compression;     /**< VSGL_EXR_ZIP (default), NONE, ZIPS, PIZ, RLE, PXR24, B44, B44A */
    uint32_t metadata_count;
    const vsgl_exr_metadata *metadata; /**< copied into the header as string attributes */
    int32_t zip_level;       /**< deflate level 1..9 of ZIP and ZIPS (libdeflate's levels, which zlib's
                                  names; lossless either way: smaller files, slower writes as it rises);
                                  0 = VSGL_EXR_ZIP_LEVEL_DEFAULT */
} vsgl_exr_options;

/** vsgl_exr_options.zip_level when it is 0: level 1 of libdeflate, which writes the ZIP chunks'
 *  zlib streams since 2026-12-05 (docs/performance.md, "EXR writing"): a 1920 x 1080 balanced
 *  frame's 16 half channels in 0.23 s, 6.7 MB, where zlib's level 2 (the default before) took
 *  0.28-0.29 s for 7.1 MB and libdeflate's level 2 0.25-0.28 s for 6.3 MB. */
#define VSGL_EXR_ZIP_LEVEL_DEFAULT 1

/**
 * @brief Write a single-part scanline multilayer EXR, atomically.
 *
 * Channels are `Layer.Pass.Channel`, so Blender loads the file as a
 * MULTILAYER image whose Image node (with its layer set to the layer name)
 * shows one socket per pass; in Blender 3.4 an RGBA pass "Combined" gives
 * the sockets "Combined" and "Alpha" (checked by tests/c/test_exr.c).
 * The header also gets the string attribute `vsgl.version`. Chunks are
 * compressed on the context's worker threads; the file is identical for
 * any thread count.
 *
 * The context's progress callback is called with the stage "write" between
 * batches of chunks and before the file replaces the target; when it asks
 * to cancel, the temporary file is deleted, a previous file at @p path is
 * kept and ::VSGL_ERROR_CANCELLED is returned.
 *
 * Every sample is checked before anything is written: a NaN or infinity
 * fails with ::VSGL_ERROR_INVALID_ARGUMENT and a message naming the pass,
 * channel and pixel ("pass DiffInd channel G pixel (3, 7): NaN"); no file
 * is created.
 *
 * @param[in] path   target file; its directory must exist.
 * @param[in] width, height  pixels, each in [1, 65535].
 * @param[in] passes @p pass_count passes (1..64); read only during the call.
 * @param[in] opt    NULL for defaults.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT, ::VSGL_ERROR_IO (message
 *         names the path and the system error), ::VSGL_ERROR_OUT_OF_MEMORY,
 *         ::VSGL_ERROR_CANCELLED, ::VSGL_ERROR_INTERNAL (OpenEXR refused; its
 *         message is included).
 */
VSGL_API vsgl_result vsgl_exr_write(vsgl_context *ctx, const char *path,
                                    uint32_t width, uint32_t height,
                                    const vsgl_exr_pass *passes, uint32_t pass_count,
                                    const vsgl_exr_options *opt);

/**
 * @brief Write every non-NULL plane of a render output with the standard
 * pass names, atomically (see ::vsgl_exr_write):
 *
 * | plane           | pass       | channels |
 * |-----------------|------------|----------|
 * | diffuse_light   | `DiffInd`  | RGB      |
 * | glossy_light    | `GlossInd` | RGB      |
 * | diffuse_color   | `DiffCol`  | RGB      |
 * | glossy_color    | `GlossCol` | RGB      |
 * | diffuse         | `Diff`     | RGB (DiffInd * DiffCol) |
 * | glossy          | `Gloss`    | RGB (GlossInd * GlossCol) |
 * | combined, alpha | `Combined` | RGBA (A = alpha, or 1 without alpha) |
 * | alpha alone     | `Combined` | A    |
 *
 * @return as ::vsgl_exr_write; ::VSGL_ERROR_INVALID_ARGUMENT if every plane is NULL.
 */
VSGL_API vsgl_result vsgl_exr_write_render(vsgl_context *ctx, const char *path,
                                           const vsgl_render_output *out,
                                           const vsgl_exr_options *opt);

/* ------------------------------------------------------------------------ */
/* Scene bundle                                                               */
/* ------------------------------------------------------------------------ */

/** Bundle format version this library writes. Readers accept the same major and any minor. */
#define VSGL_BUNDLE_VERSION_MAJOR 1
#define VSGL_BUNDLE_VERSION_MINOR 11

/** Opaque bundle read from a file or memory; owns every array its views point to. */
typedef struct vsgl_bundle vsgl_bundle;

/** Optional extras stored in a bundle. Zero-initialised (or NULL) = none. */
typedef struct vsgl_bundle_options {
    uint32_t size;           /**< sizeof(vsgl_bundle_options) or 0 */
    const char *output_path; /**< where the caller meant to write the EXR (UTF-8); NULL = none */
    int32_t has_frame;       /**< non-zero: @p frame is stored */
    int32_t frame;           /**< Blender frame number */
} vsgl_bundle_options;

/** What a bundle holds besides the scene and settings. */
typedef struct vsgl_bundle_info {
    uint32_t size;           /**< sizeof(vsgl_bundle_info) or 0, set by the caller; read, not written */
    uint32_t version_major, version_minor; /**< of the file */
    const char *output_path; /**< "" if none; owned by the bundle */
    int32_t has_frame;
    int32_t frame;
    uint32_t has_settings;   /**< 0: the file had no settings section (all defaults) */
} vsgl_bundle_info;

/**
 * @brief Serialise a scene and settings into caller memory ("pass NULL to
 * learn the size").
 *
 * Structural checks only: counts against NULL arrays, a camera present,
 * non-finite floats (message names the array and element). Enum values
 * and index ranges are stored as given (::vsgl_scene_create checks them).
 *
 * @param[in]  scene     required (camera required).
 * @param[in]  settings  NULL = all defaults (stored as zeros).
 * @param[in]  opt       NULL = no extras.
 * @param[out] buffer    NULL to query; else @p capacity bytes.
 * @param[out] size      receives the exact byte size of the bundle.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT (also when @p capacity
 *         is too small: @p size still receives the size needed).
 */
VSGL_API vsgl_result vsgl_bundle_write_memory(vsgl_context *ctx, const vsgl_scene_desc *scene,
                                              const vsgl_render_settings *settings,
                                              const vsgl_bundle_options *opt,
                                              void *buffer, size_t capacity, size_t *size);

/**
 * @brief Write a bundle file atomically (see the top of this header).
 * @return as ::vsgl_bundle_write_memory, plus ::VSGL_ERROR_IO,
 *         ::VSGL_ERROR_OUT_OF_MEMORY.
 */
VSGL_API vsgl_result vsgl_bundle_write(vsgl_context *ctx, const char *path,
                                       const vsgl_scene_desc *scene,
                                       const vsgl_render_settings *settings,
                                       const vsgl_bundle_options *opt);

/**
 * @brief Read a bundle file.
 * @param[out] out receives the bundle (destroy with ::vsgl_bundle_destroy), NULL on failure.
 * @return ::VSGL_OK, ::VSGL_ERROR_IO (cannot open/read), ::VSGL_ERROR_BAD_FORMAT
 *         (truncated, wrong magic, bad CRC, inconsistent counts, non-finite
 *         value: the message names the section and element),
 *         ::VSGL_ERROR_VERSION_MISMATCH (another major version),
 *         ::VSGL_ERROR_OUT_OF_MEMORY, ::VSGL_ERROR_INVALID_ARGUMENT (NULL).
 */
VSGL_API vsgl_result vsgl_bundle_read(vsgl_context *ctx, const char *path, vsgl_bundle **out);

/**
 * @brief Read a bundle from memory (@p size bytes at @p data, read only
 * during the call; the bundle keeps its own copies). Results as ::vsgl_bundle_read.
 */
VSGL_API vsgl_result vsgl_bundle_read_memory(vsgl_context *ctx, const void *data, size_t size,
                                             vsgl_bundle **out);

/** @brief Release a bundle and every view obtained from it. NULL is allowed. */
VSGL_API void vsgl_bundle_destroy(vsgl_bundle *bundle);

/**
 * @brief The scene stored in @p bundle, ready for ::vsgl_scene_create.
 * Every pointer in it is owned by the bundle and valid until
 * ::vsgl_bundle_destroy. Never NULL for a non-NULL bundle.
 */
VSGL_API const vsgl_scene_desc *vsgl_bundle_scene(const vsgl_bundle *bundle);

/** @brief The render settings stored in @p bundle (owned by it). Never NULL for a non-NULL bundle. */
VSGL_API const vsgl_render_settings *vsgl_bundle_settings(const vsgl_bundle *bundle);

/**
 * @brief Fill @p info (strings owned by the bundle). Both pointers must be
 * non-NULL; set @p info->size to sizeof(vsgl_bundle_info) or 0 first.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT (also for a size this
 *         library does not know).
 */
VSGL_API vsgl_result vsgl_bundle_get_info(const vsgl_bundle *bundle, vsgl_bundle_info *info);

#ifdef __cplusplus
}
#endif
#endif /* VSGL_IO_H */
