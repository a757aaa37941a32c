/* Context lifetime, last-error message, logging and progress. */
#include "context.h"
#include "core/versioned.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static uint32_t online_cores(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1u : (uint32_t)n;
}

vsgl_result vsgl_context_create(const vsgl_context_desc *desc, vsgl_context **out)
{
    if (!out)
        return VSGL_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    vsgl_context_desc d;
    if (vsgl__copy_versioned(NULL, &d, sizeof d, desc, "vsgl_context_desc") != VSGL_OK)
        return VSGL_ERROR_INVALID_ARGUMENT;
    vsgl_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return VSGL_ERROR_OUT_OF_MEMORY;
    ctx->thread_count = d.thread_count ? d.thread_count : online_cores();
    if (ctx->thread_count > 1024)
        ctx->thread_count = 1024;
    ctx->log_level = d.log_level ? d.log_level : VSGL_LOG_WARNING;
    ctx->log = d.log;
    ctx->log_user = d.log_user;
    ctx->progress = d.progress;
    ctx->progress_user = d.progress_user;
    ctx->max_memory = d.max_memory;
    ctx->progress_base = 0.0f;
    ctx->progress_span = 1.0f;
    atomic_init(&ctx->pool, NULL);
    *out = ctx;
    return VSGL_OK;
}

void vsgl_context_destroy(vsgl_context *ctx)
{
    if (ctx)
        vsgl__pool_destroy(atomic_load(&ctx->pool));
    free(ctx);
}

const char *vsgl_context_last_error(const vsgl_context *ctx)
{
    return ctx ? ctx->last_error : "no context";
}

uint32_t vsgl_context_thread_count(const vsgl_context *ctx)
{
    return ctx ? ctx->thread_count : 1u;
}

void vsgl__clear_error(vsgl_context *ctx)
{
    if (ctx)
        ctx->last_error[0] = '\0';
}

vsgl_result vsgl__fail(vsgl_context *ctx, vsgl_result code, const char *fmt, ...)
{
    if (!ctx)
        return code;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(ctx->last_error, sizeof ctx->last_error, fmt, ap);
    va_end(ap);
    if (ctx->log)
        ctx->log(ctx->log_user, VSGL_LOG_ERROR, ctx->last_error);
    return code;
}

void vsgl__log(const vsgl_context *ctx, int32_t level, const char *fmt, ...)
{
    if (!ctx || !ctx->log || level > ctx->log_level)
        return;
    char line[VSGL__MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    ctx->log(ctx->log_user, level, line);
}

int vsgl__progress(const vsgl_context *ctx, const char *stage, float fraction)
{
    if (!ctx || !ctx->progress)
        return 0;
    float f = fraction < 0.0f ? 0.0f : (fraction > 1.0f ? 1.0f : fraction);
    return ctx->progress(ctx->progress_user, stage, ctx->progress_base + ctx->progress_span * f) != 0;
}

void vsgl__progress_window(vsgl_context *ctx, float base, float span)
{
    if (!ctx)
        return;
    ctx->progress_base = base;
    ctx->progress_span = span;
}
