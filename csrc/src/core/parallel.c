/* Deterministic chunked parallel-for on pthreads. */
#include "parallel.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>

typedef struct job {
    vsgl_range_fn fn;
    void *user;
    size_t count, chunk, chunks;
    atomic_size_t next;
    pthread_mutex_t lock;
    int32_t failed_code;   /* code of the lowest failing chunk, under lock */
    size_t failed_chunk;
} job;

size_t vsgl__chunk_count(size_t count, size_t chunk)
{
    if (chunk == 0)
        chunk = 1;
    return (count + chunk - 1) / chunk;
}

static void run_chunks(job *j)
{
    for (;;) {
        size_t c = atomic_fetch_add(&j->next, 1);
        if (c >= j->chunks)
            return;
        size_t b = c * j->chunk;
        size_t e = b + j->chunk < j->count ? b + j->chunk : j->count;
        int32_t r = j->fn(j->user, c, b, e);
        if (r != 0) {
            /* keep the failure of the lowest chunk for a deterministic result */
            pthread_mutex_lock(&j->lock);
            if (c < j->failed_chunk) {
                j->failed_chunk = c;
                j->failed_code = r;
            }
            pthread_mutex_unlock(&j->lock);
        }
    }
}

static void *worker(void *arg)
{
    run_chunks((job *)arg);
    return NULL;
}

int32_t vsgl__parallel_for(uint32_t threads, size_t count, size_t chunk, vsgl_range_fn fn, void *user)
{
    if (count == 0)
        return 0;
    if (chunk == 0)
        chunk = 1;
    job j;
    j.fn = fn;
    j.user = user;
    j.count = count;
    j.chunk = chunk;
    j.chunks = vsgl__chunk_count(count, chunk);
    atomic_init(&j.next, 0);
    pthread_mutex_init(&j.lock, NULL);
    j.failed_code = 0;
    j.failed_chunk = (size_t)-1;
    size_t want = threads ? threads : 1;
    if (want > j.chunks)
        want = j.chunks;
    pthread_t *ids = NULL;
    size_t started = 0;
    if (want > 1) {
        ids = malloc((want - 1) * sizeof *ids);
        if (ids)
            for (; started < want - 1; ++started)
                if (pthread_create(&ids[started], NULL, worker, &j) != 0)
                    break;
    }
    run_chunks(&j);
    for (size_t i = 0; i < started; ++i)
        pthread_join(ids[i], NULL);
    free(ids);
    pthread_mutex_destroy(&j.lock);
    return j.failed_code;
}
