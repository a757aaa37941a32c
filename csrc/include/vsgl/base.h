/**
 * @file vsgl/base.h
 * @brief Result codes, version, vector type, export macro and the context.
 *
 * Conventions used by every vsgl header:
 * - World space is Blender's: right-handed, +Z up, metres.
 * - Directions are unit vectors unless a parameter says otherwise.
 * - Colours are linear, scene-referred RGB; power in watts, radiance in
 *   W/(m^2 sr) with Cycles' light-unit conventions (docs/units.md).
 * - Every fallible function returns a ::vsgl_result. Pure maths functions
 *   cannot fail: they return their value and have a defined result for
 *   every input (NaN in gives NaN out unless the function documents another
 *   value, e.g. ::vsgl_sharpness_from_mean_length's 0; otherwise finite, or
 *   +/-inf only where documented).
 * - The library keeps no global mutable state. A ::vsgl_context holds the
 *   thread count, callbacks and the last error message of calls made with
 *   it; use one context per thread that calls the library concurrently.
 * - Buffers are caller-owned: the library never keeps a pointer to caller
 *   memory past the call that received it unless a function says so.
 * - A struct whose first field is `uint32_t size` is versioned, in or out:
 *   the caller sets it to sizeof(the struct) or 0 (= this version's). The
 *   library reads an older, shorter struct as far as it reaches (the rest
 *   takes its default) and writes an output struct only that far; a size
 *   it does not know is ::VSGL_ERROR_INVALID_ARGUMENT.
 */
#ifndef VSGL_BASE_H
#define VSGL_BASE_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#  if defined(VSGL_BUILDING)
#    define VSGL_API __declspec(dllexport)
#  else
#    define VSGL_API __declspec(dllimport)
#  endif
#elif defined(__GNUC__)
#  define VSGL_API __attribute__((visibility("default")))
#else
#  define VSGL_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** Library version. The add-on refuses a library whose major.minor differ. */
#define VSGL_VERSION_MAJOR 0
#define VSGL_VERSION_MINOR 3
#define VSGL_VERSION_PATCH 0
/** Version packed as major*10000 + minor*100 + patch. */
#define VSGL_VERSION (VSGL_VERSION_MAJOR * 10000 + VSGL_VERSION_MINOR * 100 + VSGL_VERSION_PATCH)

/** Fixed-width result code returned by every fallible call. */
typedef int32_t vsgl_result;

#define VSGL_OK                      0  /**< success */
#define VSGL_ERROR_INVALID_ARGUMENT  1  /**< a parameter or input array is invalid (message names it) */
#define VSGL_ERROR_OUT_OF_MEMORY     2  /**< an allocation failed */
#define VSGL_ERROR_IO                3  /**< a file could not be read or written */
#define VSGL_ERROR_BAD_FORMAT        4  /**< a file is truncated, corrupt or not of the expected kind */
#define VSGL_ERROR_VERSION_MISMATCH  5  /**< a file or caller was made for another version */
#define VSGL_ERROR_UNSUPPORTED       6  /**< reserved for a valid request a build does not implement; no 0.x function returns it */
#define VSGL_ERROR_CANCELLED         7  /**< the progress callback asked to stop */
#define VSGL_ERROR_INTERNAL          8  /**< a bug or a failure of a dependency (Embree, OpenEXR) */
#define VSGL_RESULT_COUNT            9

/**
 * @brief Static English description of a result code ("invalid argument").
 * @return Never NULL; unknown codes give "unknown result code". Thread-safe.
 */
VSGL_API const char *vsgl_result_string(vsgl_result code);

/** @brief Runtime version (::VSGL_VERSION of the built library). Thread-safe. */
VSGL_API int32_t vsgl_version(void);

/** @brief Runtime version as "major.minor.patch" (static string). Thread-safe. */
VSGL_API const char *vsgl_version_string(void);

/** A 3-vector of floats: a point in metres or a direction. 12 bytes, no padding. */
typedef struct vsgl_vec3 {
    float x, y, z;
} vsgl_vec3;

/* ------------------------------------------------------------------------ */
/* Context                                                                   */
/* ------------------------------------------------------------------------ */

/** Opaque per-caller state: threads, callbacks, last error message. */
typedef struct vsgl_context vsgl_context;

/** Log levels passed to ::vsgl_log_fn. */
#define VSGL_LOG_ERROR   0
#define VSGL_LOG_WARNING 1
#define VSGL_LOG_INFO    2
#define VSGL_LOG_DEBUG   3

/**
 * Log callback: @p message is a NUL-terminated line without a trailing
 * newline, valid only during the call. May be called from the thread that
 * called the library, never from a worker thread.
 */
typedef void (*vsgl_log_fn)(void *user, int32_t level, const char *message);

/**
 * Progress callback: @p stage is a short static name ("rsm", "shade"),
 * @p fraction in [0,1] the overall progress. Return non-zero to cancel:
 * the running call then returns ::VSGL_ERROR_CANCELLED and writes no output.
 * Called only from the thread that called the library.
 */
typedef int32_t (*vsgl_progress_fn)(void *user, const char *stage, float fraction);

/**
 * Context description. Zero-initialised means defaults; set @p size to
 * sizeof(vsgl_context_desc) so later versions can extend it.
 */
typedef struct vsgl_context_desc {
    uint32_t size;            /**< sizeof(vsgl_context_desc); 0 is accepted as "current" */
    uint32_t thread_count;    /**< worker threads; 0 = all online cores */
    int32_t log_level;        /**< most verbose level passed to @p log; 0 = the default,
                                   VSGL_LOG_WARNING (errors only cannot be selected: filter in the callback) */
    vsgl_log_fn log;          /**< NULL = no logging */
    void *log_user;
    vsgl_progress_fn progress;/**< NULL = no progress reports */
    void *progress_user;
    uint64_t max_memory;      /**< bytes a render may allocate (::vsgl_render_estimate);
                                   0 = the memory this machine has available when the render
                                   starts (MemAvailable, capped by the cgroup and RLIMIT_AS limits) */
} vsgl_context_desc;

/**
 * @brief Create a context.
 * @param[in]  desc  NULL for defaults.
 * @param[out] out   receives the context; set to NULL on failure.
 * @return ::VSGL_OK, ::VSGL_ERROR_INVALID_ARGUMENT (out is NULL or desc->size
 *         is larger than this library knows), ::VSGL_ERROR_OUT_OF_MEMORY.
 */
VSGL_API vsgl_result vsgl_context_create(const vsgl_context_desc *desc, vsgl_context **out);

/** @brief Destroy a context. NULL is allowed and does nothing. */
VSGL_API void vsgl_context_destroy(vsgl_context *ctx);

/**
 * @brief Message of the last call on @p ctx that failed, naming the element
 * at fault ("light 3: spot size is 0"), or "" if none failed yet.
 * @return Owned by the context, valid until the next call with @p ctx.
 *         Never NULL (a NULL ctx gives a static message).
 */
VSGL_API const char *vsgl_context_last_error(const vsgl_context *ctx);

/** @brief Number of worker threads the context uses (>= 1). */
VSGL_API uint32_t vsgl_context_thread_count(const vsgl_context *ctx);

#ifdef __cplusplus
}
#endif
#endif /* VSGL_BASE_H */
