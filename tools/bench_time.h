/* The C benchmark drivers' clock and median (tools/bench_gbuffer.c,
 * tools/live_edit.c). */
#ifndef VSGL_TOOLS_BENCH_TIME_H
#define VSGL_TOOLS_BENCH_TIME_H
#include <stdlib.h>
#include <time.h>

/* Seconds on clock c (CLOCK_MONOTONIC: wall; CLOCK_PROCESS_CPUTIME_ID: all threads' CPU). */
static inline double bench_now(clockid_t c)
{
    struct timespec t;
    clock_gettime(c, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static inline int bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median of v[0, n) (sorts v). */
static inline double bench_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, bench_cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
#endif
