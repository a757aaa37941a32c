/* The one rule for size-prefixed structs (versioned.h). */
#include "core/versioned.h"
#include "core/context.h"

#include <string.h>

vsgl_result vsgl__versioned_size(vsgl_context *ctx, const void *s, size_t full, size_t *bytes, const char *what)
{
    uint32_t size;
    memcpy(&size, s, sizeof size);
    if (size == 0)
        size = (uint32_t)full;
    if (size > full || size < sizeof size || size % 4 != 0) {
        if (ctx)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT,
                              "%s.size is %u: this library knows multiples of 4 from %zu to %zu (0 = %zu)%s", what,
                              (unsigned)size, sizeof size, full, full, size > full ? " (a newer header?)" : "");
        return VSGL_ERROR_INVALID_ARGUMENT;
    }
    *bytes = size;
    return VSGL_OK;
}

vsgl_result vsgl__copy_versioned(vsgl_context *ctx, void *dst, size_t dst_size, const void *src, const char *what)
{
    memset(dst, 0, dst_size);
    if (!src)
        return VSGL_OK;
    size_t bytes = 0;
    vsgl_result r = vsgl__versioned_size(ctx, src, dst_size, &bytes, what);
    if (r == VSGL_OK)
        memcpy(dst, src, bytes);
    return r;
}

vsgl_result vsgl__return_versioned(vsgl_context *ctx, void *dst, const void *src, size_t src_size, const char *what)
{
    size_t bytes = 0;
    vsgl_result r = vsgl__versioned_size(ctx, dst, src_size, &bytes, what);
    if (r == VSGL_OK)
        memcpy((char *)dst + sizeof(uint32_t), (const char *)src + sizeof(uint32_t), bytes - sizeof(uint32_t));
    return r;
}
