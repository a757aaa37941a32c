/* Tiny test harness: tests register by name and can run one at a time.
 *
 *   VT_TEST(sg_integral_matches_quadrature) { VT_CHECK_REL(got, want, 1e-6, "lambda=%g", l); }
 *
 * Run: build/tests/vsgl_tests [substring ...]   (no argument = every test).
 * Each test passes when none of its checks failed; the runner ends with
 * the line "N passed, N failed" and exits non-zero on any failure. */
#ifndef VSGL_TEST_HARNESS_H
#define VSGL_TEST_HARNESS_H

#include <math.h>
#include <setjmp.h>
#include <stdio.h>

typedef void (*vt_fn)(void);
void vt_register(const char *name, const char *file, vt_fn fn);
void vt_fail_at(const char *file, int line);
extern int vt_current_failures;
extern const char *vt_current_name;
/* Where VT_REQUIRE jumps: back to the runner, the test counted as failed. */
extern jmp_buf vt_stop;
/* Print `indent` and the printf-style message on one line, while the
 * current test has printed fewer than VT_MAX_MESSAGES failures. */
void vt_note(const char *indent, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Print at most this many failure messages per test (all are counted). */
#define VT_MAX_MESSAGES 8

#define VT_TEST(name)                                                       \
    static void name(void);                                                 \
    __attribute__((constructor)) static void vt_register_##name(void)      \
    {                                                                       \
        vt_register(#name, __FILE__, name);                                 \
    }                                                                       \
    static void name(void)

#define VT_REPORT(...)                                                      \
    do {                                                                    \
        vt_fail_at(__FILE__, __LINE__);                                     \
        vt_note("    ", __VA_ARGS__);                                       \
    } while (0)

/* Check a condition; the message (printf-style) should print the inputs. */
#define VT_CHECK(cond, ...)                                                 \
    do {                                                                    \
        if (!(cond)) {                                                      \
            VT_REPORT("check failed: %s", #cond);                           \
            vt_note("      ", __VA_ARGS__);                                 \
        }                                                                   \
    } while (0)

/* VT_CHECK that ends the test when it fails (e.g. a create whose result
 * the rest of the test would use). What the test allocated before leaks:
 * use it where going on would crash, not in place of cleanup. */
#define VT_REQUIRE(cond, ...)                                               \
    do {                                                                    \
        if (!(cond)) {                                                      \
            VT_REPORT("required check failed (test stopped): %s", #cond);   \
            vt_note("      ", __VA_ARGS__);                                 \
            longjmp(vt_stop, 1);                                            \
        }                                                                   \
    } while (0)

/* |got - want| <= tol * max(|want|, floor) */
#define VT_CHECK_REL(got, want, tol, ...)                                   \
    do {                                                                    \
        double vt_g = (double)(got), vt_w = (double)(want);                 \
        double vt_s = fabs(vt_w) > 1e-300 ? fabs(vt_w) : 1e-300;            \
        if (!(fabs(vt_g - vt_w) <= (tol) * vt_s)) {                         \
            VT_REPORT("%s = %.9g, want %.9g (rel err %.3g > %.3g)", #got,   \
                      vt_g, vt_w, fabs(vt_g - vt_w) / vt_s, (double)(tol)); \
            vt_note("      ", __VA_ARGS__);                                 \
        }                                                                   \
    } while (0)

/* |got - want| <= tol */
#define VT_CHECK_ABS(got, want, tol, ...)                                   \
    do {                                                                    \
        double vt_g = (double)(got), vt_w = (double)(want);                 \
        if (!(fabs(vt_g - vt_w) <= (tol))) {                                \
            VT_REPORT("%s = %.9g, want %.9g (abs err %.3g > %.3g)", #got,   \
                      vt_g, vt_w, fabs(vt_g - vt_w), (double)(tol));        \
            vt_note("      ", __VA_ARGS__);                                 \
        }                                                                   \
    } while (0)

/* Seeded RNG for tests (splitmix64 -> doubles in [0,1)). */
typedef struct vt_rng { unsigned long long s; } vt_rng;
static inline unsigned long long vt_next(vt_rng *r)
{
    unsigned long long z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static inline double vt_uniform(vt_rng *r) { return (double)(vt_next(r) >> 11) * 0x1.0p-53; }

#endif
