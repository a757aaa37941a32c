/* Result codes, version, context lifetime and the deterministic parallel-for. */
#include "harness.h"
#include "vsgl.h"
#include "core/context.h"
#include "core/parallel.h"
#include "core/versioned.h"

#include <string.h>

VT_TEST(core_result_strings_cover_every_code)
{
    for (int c = 0; c < VSGL_RESULT_COUNT; ++c) {
        const char *s = vsgl_result_string(c);
        VT_CHECK(s && *s && strcmp(s, "unknown result code") != 0, "code %d", c);
    }
    VT_CHECK(strcmp(vsgl_result_string(-1), "unknown result code") == 0, "code -1");
    VT_CHECK(strcmp(vsgl_result_string(VSGL_RESULT_COUNT), "unknown result code") == 0, "past end");
}

VT_TEST(core_version_matches_header)
{
    VT_CHECK(vsgl_version() == VSGL_VERSION, "runtime %d header %d", vsgl_version(), VSGL_VERSION);
    char want[32];
    snprintf(want, sizeof want, "%d.%d.%d", VSGL_VERSION_MAJOR, VSGL_VERSION_MINOR, VSGL_VERSION_PATCH);
    VT_CHECK(strcmp(vsgl_version_string(), want) == 0, "%s vs %s", vsgl_version_string(), want);
}

VT_TEST(core_context_create_and_errors)
{
    vsgl_context *ctx = NULL;
    VT_CHECK(vsgl_context_create(NULL, NULL) == VSGL_ERROR_INVALID_ARGUMENT, "NULL out");
    vsgl_context_desc big;
    memset(&big, 0, sizeof big);
    big.size = sizeof big + 64;
    VT_CHECK(vsgl_context_create(&big, &ctx) == VSGL_ERROR_INVALID_ARGUMENT && ctx == NULL, "desc from the future");
    VT_CHECK(vsgl_context_create(NULL, &ctx) == VSGL_OK && ctx, "defaults");
    VT_CHECK(vsgl_context_thread_count(ctx) >= 1, "threads");
    VT_CHECK(strcmp(vsgl_context_last_error(ctx), "") == 0, "fresh context has no error");
    VT_CHECK(vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "light %d: spot size is 0", 3) == VSGL_ERROR_INVALID_ARGUMENT, "code passes through");
    VT_CHECK(strcmp(vsgl_context_last_error(ctx), "light 3: spot size is 0") == 0, "got '%s'", vsgl_context_last_error(ctx));
    vsgl_context_destroy(ctx);
    vsgl_context_destroy(NULL);
}

typedef struct sum_job { const double *v; double *partial; } sum_job;
static int32_t sum_chunk(void *user, size_t chunk, size_t b, size_t e)
{
    sum_job *j = user;
    double s = 0;
    for (size_t i = b; i < e; ++i)
        s += j->v[i];
    j->partial[chunk] = s;
    return 0;
}

VT_TEST(core_parallel_for_is_bit_identical_for_any_thread_count)
{
    enum { N = 100003, CH = 997 };
    static double v[N], partial[N / CH + 1];
    vt_rng r = {42};
    for (int i = 0; i < N; ++i)
        v[i] = vt_uniform(&r) * 1e6 - 5e5;
    double first = 0;
    for (uint32_t t = 1; t <= 8; ++t) {
        sum_job j = {v, partial};
        VT_CHECK(vsgl__parallel_for(t, N, CH, sum_chunk, &j) == 0, "threads %u", t);
        double s = 0;
        for (size_t c = 0; c < vsgl__chunk_count(N, CH); ++c)
            s += partial[c];
        if (t == 1)
            first = s;
        VT_CHECK(memcmp(&s, &first, sizeof s) == 0, "threads %u: %.17g vs %.17g", t, s, first);
    }
}

static int32_t fail_some(void *user, size_t chunk, size_t b, size_t e)
{
    (void)user; (void)b; (void)e;
    return chunk == 5 ? 7 : (chunk == 9 ? 3 : 0);
}

VT_TEST(core_parallel_for_reports_lowest_failing_chunk)
{
    for (uint32_t t = 1; t <= 4; ++t)
        VT_CHECK(vsgl__parallel_for(t, 100, 7, fail_some, NULL) == 7, "threads %u", t);
}

/* The context's pool (vsgl__parallel_ctx): every chunk once, the same sums
 * and failure codes as vsgl__parallel_for, for many loops in a row (each
 * a new generation the workers must not miss or repeat), a loop inside a
 * chunk of another (it falls back to threads of its own), and a pool
 * ended by vsgl_context_destroy. */
typedef struct pool_job {
    vsgl_context *ctx;
    unsigned char *seen;
    double *partial;
    const double *v;
    int nest;
} pool_job;

static int32_t pool_chunk(void *user, size_t chunk, size_t b, size_t e)
{
    pool_job *j = user;
    double s = 0;
    for (size_t i = b; i < e; ++i) {
        j->seen[i]++;
        s += j->v[i];
    }
    j->partial[chunk] = s;
    if (j->nest && chunk == 1) { /* a loop inside this one */
        static double inner_partial[64];
        static unsigned char inner_seen[1000];
        pool_job in = {j->ctx, inner_seen, inner_partial, j->v, 0};
        memset(inner_seen, 0, sizeof inner_seen);
        if (vsgl__parallel_ctx(j->ctx, 1000, 17, pool_chunk, &in) != 0)
            return 99;
        for (int i = 0; i < 1000; ++i)
            if (inner_seen[i] != 1)
                return 98;
    }
    return 0;
}

VT_TEST(core_parallel_ctx_pool_matches_parallel_for)
{
    enum { N = 20011, CH = 97, NC = N / CH + 1 };
    static double v[N], want[NC], got[NC];
    static unsigned char seen[N];
    vt_rng r = {7};
    for (int i = 0; i < N; ++i)
        v[i] = vt_uniform(&r) * 1e3 - 5e2;
    pool_job ref = {NULL, seen, want, v, 0};
    VT_REQUIRE(vsgl__parallel_for(1, N, CH, pool_chunk, &ref) == 0, "reference");
    for (uint32_t t = 1; t <= 4; ++t) {
        vsgl_context_desc d;
        memset(&d, 0, sizeof d);
        d.size = sizeof d;
        d.thread_count = t;
        vsgl_context *ctx = NULL;
        VT_REQUIRE(vsgl_context_create(&d, &ctx) == VSGL_OK, "context");
        for (int loop = 0; loop < 200; ++loop) {
            memset(seen, 0, sizeof seen);
            memset(got, 0, sizeof got);
            pool_job j = {ctx, seen, got, v, loop % 50 == 3};
            size_t count = loop % 7 == 0 ? (size_t)CH / 2 : N; /* one chunk now and then */
            VT_CHECK(vsgl__parallel_ctx(ctx, count, CH, pool_chunk, &j) == 0, "threads %u loop %d", t, loop);
            size_t bad = 0;
            for (size_t i = 0; i < count; ++i)
                bad += seen[i] != 1;
            VT_CHECK(bad == 0, "threads %u loop %d: %zu items not run exactly once", t, loop, bad);
            if (count == N)
                VT_CHECK(memcmp(got, want, sizeof got) == 0, "threads %u loop %d: partial sums differ", t, loop);
            VT_CHECK(vsgl__parallel_ctx(ctx, 100, 7, fail_some, NULL) == 7, "threads %u loop %d: failure", t, loop);
        }
        VT_CHECK(vsgl__parallel_ctx(ctx, 0, 7, fail_some, NULL) == 0, "empty loop");
        vsgl_context_destroy(ctx);
    }
    VT_CHECK(vsgl__parallel_ctx(NULL, 100, 7, fail_some, NULL) == 7, "no context");
}

/* One rule for every size-prefixed struct: 0 = current, smaller = older
 * (tail zero), larger or shorter than the size field = refused, named. */
VT_TEST(core_versioned_structs_follow_one_rule)
{
    vsgl_context *ctx = NULL;
    VT_REQUIRE(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    vsgl_render_settings in, out;
    memset(&in, 0x5a, sizeof in);
    in.size = 0;
    VT_CHECK(vsgl__copy_versioned(ctx, &out, sizeof out, &in, "vsgl_render_settings") == VSGL_OK, "size 0");
    VT_CHECK(memcmp(&in, &out, sizeof in) == 0, "size 0 copies the whole struct");
    in.size = (uint32_t)offsetof(vsgl_render_settings, aa_samples) + sizeof in.aa_samples;
    VT_CHECK(vsgl__copy_versioned(ctx, &out, sizeof out, &in, "vsgl_render_settings") == VSGL_OK, "older size");
    VT_CHECK(out.aa_samples == in.aa_samples && out.shade_stride == 0, "older: prefix copied, tail zero");
    in.size = sizeof in + 4;
    VT_CHECK(vsgl__copy_versioned(ctx, &out, sizeof out, &in, "vsgl_render_settings") == VSGL_ERROR_INVALID_ARGUMENT,
             "newer size accepted");
    VT_CHECK(strstr(vsgl_context_last_error(ctx), "vsgl_render_settings.size") != NULL, "message: %s",
             vsgl_context_last_error(ctx));
    in.size = 2;
    VT_CHECK(vsgl__copy_versioned(ctx, &out, sizeof out, &in, "x") == VSGL_ERROR_INVALID_ARGUMENT, "size 2");
    in.size = 10; /* ends inside a field */
    VT_CHECK(vsgl__copy_versioned(ctx, &out, sizeof out, &in, "x") == VSGL_ERROR_INVALID_ARGUMENT, "size 10");
    VT_CHECK(vsgl__copy_versioned(ctx, &out, sizeof out, NULL, "x") == VSGL_OK && out.size == 0, "NULL = zeros");
    /* the public entry points use it: a newer render settings struct is refused by vsgl_render_settings checks */
    vsgl_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.size = sizeof cd + 8;
    vsgl_context *c2 = NULL;
    VT_CHECK(vsgl_context_create(&cd, &c2) == VSGL_ERROR_INVALID_ARGUMENT && c2 == NULL, "newer context desc");
    vsgl_context_destroy(ctx);
}
