/* Test runner: runs the registered tests whose names contain any argument. */
#include "harness.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct entry { const char *name, *file; vt_fn fn; } entry;
static entry tests[1024];
static int test_count, test_dropped;
int vt_current_failures;
const char *vt_current_name;
jmp_buf vt_stop;

void vt_register(const char *name, const char *file, vt_fn fn)
{
    if (test_count < (int)(sizeof tests / sizeof tests[0]))
        tests[test_count++] = (entry){name, file, fn};
    else
        ++test_dropped; /* main() fails: a test that cannot run must not pass silently */
}

void vt_note(const char *indent, const char *fmt, ...)
{
    if (vt_current_failures > VT_MAX_MESSAGES)
        return;
    va_list ap;
    va_start(ap, fmt);
    fputs(indent, stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

void vt_fail_at(const char *file, int line)
{
    if (++vt_current_failures <= VT_MAX_MESSAGES)
        fprintf(stderr, "  %s:%d: in %s\n", file, line, vt_current_name);
}

static int by_name(const void *a, const void *b)
{
    return strcmp(((const entry *)a)->name, ((const entry *)b)->name);
}

int main(int argc, char **argv)
{
    if (test_dropped) {
        fprintf(stderr, "vsgl_tests: %d tests beyond the runner's %d slots were not registered: enlarge "
                        "tests[] in tests/c/main.c\n", test_dropped, (int)(sizeof tests / sizeof tests[0]));
        return 1;
    }
    qsort(tests, (size_t)test_count, sizeof tests[0], by_name);
    int passed = 0, failed = 0, list = argc > 1 && strcmp(argv[1], "--list") == 0;
    for (int i = 0; i < test_count; ++i) {
        int selected = argc <= 1 || list;
        for (int a = 1; a < argc && !selected; ++a)
            selected = strstr(tests[i].name, argv[a]) != NULL;
        if (!selected)
            continue;
        if (list) {
            printf("%s\n", tests[i].name);
            continue;
        }
        vt_current_name = tests[i].name;
        vt_current_failures = 0;
        struct timespec t0, t1;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        if (setjmp(vt_stop) == 0)
            tests[i].fn();
        clock_gettime(CLOCK_MONOTONIC, &t1);
        double ms = (t1.tv_sec - t0.tv_sec) * 1e3 + (t1.tv_nsec - t0.tv_nsec) / 1e6;
        if (vt_current_failures == 0) {
            ++passed;
            printf("PASS %-50s %8.1f ms\n", tests[i].name, ms);
        } else {
            ++failed;
            printf("FAIL %-50s (%d failed checks)\n", tests[i].name, vt_current_failures);
        }
        fflush(stdout);
    }
    if (list)
        return 0;
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : (passed ? 0 : 5);
}
