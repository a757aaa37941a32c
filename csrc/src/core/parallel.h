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

/* vsgl__parallel_for on the context's thread count, with the context's
 * pool of workers (started by its first such loop, ended by
 * vsgl_context_destroy): no thread is started or joined per loop, and the
 * caller waits only for workers that took a chunk. The same chunks: the
 * same results. A loop started inside another (a chunk's callback), or
 * by a second thread using the context at the same time, falls back to
 * vsgl__parallel_for. ctx NULL: one thread. */
struct vsgl_context;
int32_t vsgl__parallel_ctx(struct vsgl_context *ctx, size_t count, size_t chunk, vsgl_range_fn fn, void *user);

/* A pool of `workers` threads (NULL if none could start) and its end. */
typedef struct vsgl__pool vsgl__pool;
vsgl__pool *vsgl__pool_create(uint32_t workers);
void vsgl__pool_destroy(vsgl__pool *p);

/* Number of chunks vsgl__parallel_for uses for (count, chunk). */
size_t vsgl__chunk_count(size_t count, size_t chunk);

#endif
