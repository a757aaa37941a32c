/* Internal: the context's layout, error reporting and logging helpers. */
#ifndef VSGL_CORE_CONTEXT_H
#define VSGL_CORE_CONTEXT_H

#include "vsgl/base.h"
#include "core/parallel.h"

#include <stdatomic.h>

#define VSGL__MESSAGE_MAX 512

struct vsgl_context {
    uint32_t thread_count;
    int32_t log_level;
    vsgl_log_fn log;
    void *log_user;
    vsgl_progress_fn progress;
    void *progress_user;
    char last_error[VSGL__MESSAGE_MAX];
    float progress_base, progress_span; /* stage window of the overall progress */
    uint64_t max_memory;    /* 0 = what the machine has available (render/memory.c) */
    _Atomic(vsgl__pool *) pool; /* worker threads of vsgl__parallel_ctx, started by its first loop */
};

#if defined(__GNUC__)
#  define VSGL_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#  define VSGL_PRINTF(a, b)
#endif

/* Record "message" as the context's last error, log it, return code. ctx may be NULL. */
vsgl_result vsgl__fail(vsgl_context *ctx, vsgl_result code, const char *fmt, ...) VSGL_PRINTF(3, 4);

/* Log one line at level (no-op below the context's level or without a callback). */
void vsgl__log(const vsgl_context *ctx, int32_t level, const char *fmt, ...) VSGL_PRINTF(3, 4);

/* Report progress of the current stage (fraction in [0, 1] of the stage,
 * mapped into the window set by vsgl__progress_window so the caller sees
 * overall progress); returns non-zero if the caller asked to cancel. */
int vsgl__progress(const vsgl_context *ctx, const char *stage, float fraction);

/* The part [base, base + span] of the overall progress that the stages
 * called next fill; (0, 1) by default. */
void vsgl__progress_window(vsgl_context *ctx, float base, float span);

/* Clear the last error at the start of a fallible public call. */
void vsgl__clear_error(vsgl_context *ctx);

#endif
