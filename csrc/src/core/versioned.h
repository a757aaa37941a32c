/* Size-prefixed public structs (every `size` field of the headers): one
 * rule for all of them. */
#ifndef VSGL_CORE_VERSIONED_H
#define VSGL_CORE_VERSIONED_H

#include "vsgl/base.h"

#include <stddef.h>
#include <stdint.h>

/* The rule: the caller's struct `s` (its first field the uint32_t `size`)
 * holds *bytes bytes of this library's `full`-byte version. Size 0 means
 * this library's size; a smaller size is an older, shorter version; a
 * larger one (a newer header), one that cannot hold the size field itself
 * or one that ends inside a field (not a multiple of 4: every field is 4
 * or 8 bytes) is refused with VSGL_ERROR_INVALID_ARGUMENT and a message
 * naming `what`. `ctx` may be NULL (no message). */
vsgl_result vsgl__versioned_size(vsgl_context *ctx, const void *s, size_t full, size_t *bytes, const char *what);

/* In (descriptions, settings, options, output pointers): copy the caller's
 * struct `src` into `dst` of `dst_size` bytes, zeroed first, so an older
 * caller's missing tail stays zero (the defaults). `src` NULL leaves `dst`
 * zeroed. */
vsgl_result vsgl__copy_versioned(vsgl_context *ctx, void *dst, size_t dst_size, const void *src, const char *what);

/* Out (stats, infos): copy the library's filled struct `src` of `src_size`
 * bytes into the caller's `dst` as far as `dst`'s size says it reaches;
 * dst's `size` field itself is left as the caller set it. */
vsgl_result vsgl__return_versioned(vsgl_context *ctx, void *dst, const void *src, size_t src_size, const char *what);

#endif
