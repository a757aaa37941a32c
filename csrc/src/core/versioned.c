/* The one rule for size-prefixed structs (versioned.h). */
#include "core/versioned.h"
#include "core/context.h"

#include <string.h>

vsgl_result vsgl__copy_versioned(vsgl_context *ctx, void *dst, size_t dst_size, const void *src, const char *what)
{
    memset(dst, 0, dst_size);
    if (!src)
        return VSGL_OK;
    uint32_t size;
    memcpy(&size, src, sizeof size);
    if (size == 0)
        size = (uint32_t)dst_size;
    if (size > dst_size || size < sizeof size || size % 4 != 0) {
        if (ctx)
            return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT,
                              "%s.size is %u: this library knows multiples of 4 from %zu to %zu (0 = %zu)%s", what,
                              (unsigned)size, sizeof size, dst_size, dst_size,
                              size > dst_size ? " (a newer header?)" : "");
        return VSGL_ERROR_INVALID_ARGUMENT;
    }
    memcpy(dst, src, size);
    return VSGL_OK;
}
