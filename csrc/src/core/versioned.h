/* Size-prefixed public structs (every `size` field of the headers): one
 * rule for all of them. */
#ifndef VSGL_CORE_VERSIONED_H
#define VSGL_CORE_VERSIONED_H

#include "vsgl/base.h"

#include <stddef.h>
#include <stdint.h>

/* Copy the caller's struct `src` (its first field the uint32_t `size`)
 * into `dst` of `dst_size` bytes, zeroed first. Size 0 means this
 * library's size; a smaller size is an older, shorter version whose
 * missing tail stays zero (the defaults); a larger one (a newer header),
 * one that cannot hold the size field itself or one that ends inside a
 * field (not a multiple of 4: every field is 4 or 8 bytes) is refused with
 * VSGL_ERROR_INVALID_ARGUMENT and a message naming `what`. `ctx` may be
 * NULL (no message). `src` NULL leaves `dst` zeroed. */
vsgl_result vsgl__copy_versioned(vsgl_context *ctx, void *dst, size_t dst_size, const void *src, const char *what);

#endif
