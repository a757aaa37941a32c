/* Deterministic chunked parallel-for on pthreads: threads started per
 * loop (vsgl__parallel_for), or a context's pool of workers that sleep
 * between loops (vsgl__parallel_ctx). */
#include "parallel.h"
#include "core/context.h"

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

/* A context's workers (context.h: vsgl_context.pool). A loop is published
 * under the lock as `cur` with a new generation; a worker that wakes takes
 * chunks of it only while it is published, counted in `busy`. The caller
 * runs chunks too and, once none are left, unpublishes the loop and waits
 * only for the workers inside it: never for a worker that had not woken
 * yet (on a loaded machine a thread can wait milliseconds for a core, and
 * a per-loop thread had to be joined whether it took a chunk or not). */
struct vsgl__pool {
    pthread_mutex_t lock;
    pthread_cond_t wake, idle;
    atomic_flag in_use;     /* one loop at a time; a nested or concurrent one starts its own threads */
    job *cur;               /* the published loop, or NULL */
    uint64_t gen;           /* loops published so far */
    uint32_t busy;          /* workers inside cur */
    int quit;
    uint32_t count;         /* workers started */
    pthread_t ids[];
};

static void *pool_worker(void *arg)
{
    vsgl__pool *p = arg;
    uint64_t seen = 0;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        while (!p->quit && (!p->cur || p->gen == seen))
            pthread_cond_wait(&p->wake, &p->lock);
        if (p->quit)
            break;
        seen = p->gen;
        job *j = p->cur;
        ++p->busy;
        pthread_mutex_unlock(&p->lock);
        run_chunks(j);
        pthread_mutex_lock(&p->lock);
        if (--p->busy == 0)
            pthread_cond_signal(&p->idle);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

vsgl__pool *vsgl__pool_create(uint32_t workers)
{
    if (workers == 0)
        return NULL;
    vsgl__pool *p = calloc(1, sizeof *p + workers * sizeof(pthread_t));
    if (!p)
        return NULL;
    if (pthread_mutex_init(&p->lock, NULL) != 0) {
        free(p);
        return NULL;
    }
    pthread_cond_init(&p->wake, NULL);
    pthread_cond_init(&p->idle, NULL);
    atomic_flag_clear(&p->in_use);
    for (; p->count < workers; ++p->count)
        if (pthread_create(&p->ids[p->count], NULL, pool_worker, p) != 0)
            break;
    if (p->count == 0) {
        vsgl__pool_destroy(p);
        return NULL;
    }
    return p;
}

void vsgl__pool_destroy(vsgl__pool *p)
{
    if (!p)
        return;
    pthread_mutex_lock(&p->lock);
    p->quit = 1;
    pthread_cond_broadcast(&p->wake);
    pthread_mutex_unlock(&p->lock);
    for (uint32_t i = 0; i < p->count; ++i)
        pthread_join(p->ids[i], NULL);
    pthread_cond_destroy(&p->wake);
    pthread_cond_destroy(&p->idle);
    pthread_mutex_destroy(&p->lock);
    free(p);
}

int32_t vsgl__parallel_ctx(vsgl_context *ctx, size_t count, size_t chunk, vsgl_range_fn fn, void *user)
{
    const uint32_t threads = vsgl_context_thread_count(ctx);
    if (count == 0)
        return 0;
    if (chunk == 0)
        chunk = 1;
    const size_t chunks = vsgl__chunk_count(count, chunk);
    if (!ctx || threads < 2 || chunks < 2)
        return vsgl__parallel_for(threads < 2 || chunks < 2 ? 1 : threads, count, chunk, fn, user);
    vsgl__pool *p = atomic_load(&ctx->pool);
    if (!p) { /* the first loop of this context with two or more threads starts its workers */
        vsgl__pool *mine = vsgl__pool_create(threads - 1), *none = NULL;
        if (mine && !atomic_compare_exchange_strong(&ctx->pool, &none, mine)) {
            vsgl__pool_destroy(mine); /* another call made one first */
            mine = none;
        }
        p = mine;
    }
    if (!p || atomic_flag_test_and_set(&p->in_use)) /* no pool, or a loop inside a loop */
        return vsgl__parallel_for(threads, count, chunk, fn, user);
    job j;
    j.fn = fn;
    j.user = user;
    j.count = count;
    j.chunk = chunk;
    j.chunks = chunks;
    atomic_init(&j.next, 0);
    pthread_mutex_init(&j.lock, NULL);
    j.failed_code = 0;
    j.failed_chunk = (size_t)-1;
    pthread_mutex_lock(&p->lock);
    p->cur = &j;
    ++p->gen;
    pthread_cond_broadcast(&p->wake);
    pthread_mutex_unlock(&p->lock);
    run_chunks(&j);
    pthread_mutex_lock(&p->lock);
    p->cur = NULL;
    while (p->busy > 0)
        pthread_cond_wait(&p->idle, &p->lock);
    pthread_mutex_unlock(&p->lock);
    atomic_flag_clear(&p->in_use);
    pthread_mutex_destroy(&j.lock);
    return j.failed_code;
}
