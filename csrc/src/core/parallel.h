/* Internal: deterministic parallel loops over index ranges (pthreads).
 * Work is split into fixed chunks whose boundaries depend only on the
 * count and chunk size, never on the thread count, so any reduction done
 * per chunk and combined in chunk order is bit-identical for any number
 * of threads. */
#ifndef VSGL_CORE_PARALLEL_H
#define VSGL_CORE_PARALLEL_H

#include <stddef.h>
#include <stdint.h>

/* fn(user, chunk_index, begin, end): process [begin, end). Returns 0 or a vsgl_result. */
typedef int32_t (*vsgl_range_fn)(void *user, size_t chunk, size_t begin, size_t end);

/* Run fn over [0, count) in chunks of `chunk` items on up to `threads`
 * threads. Chunks are claimed dynamically; the first non-zero return
 * (lowest chunk index among failures) is returned. */
int32_t vsgl__parallel_for(uint32_t threads, size_t count, size_t chunk, vsgl_range_fn fn, void *user);

/* Number of chunks vsgl__parallel_for uses for (count, chunk). */
size_t vsgl__chunk_count(size_t count, size_t chunk);

#endif
