/* A context log callback for tests: counts the library's warnings and
 * keeps their text, one per line (cut at the buffer's end). */
#ifndef VSGL_TEST_LOG_CAPTURE_H
#define VSGL_TEST_LOG_CAPTURE_H

#include "vsgl.h"

#include <stdio.h>
#include <string.h>

typedef struct vt_warnings {
    int n;
    char text[2048];
} vt_warnings;

static inline void vt_capture_warnings(void *user, int32_t level, const char *message)
{
    vt_warnings *w = user;
    if (level != VSGL_LOG_WARNING)
        return;
    ++w->n;
    size_t used = strlen(w->text);
    snprintf(w->text + used, sizeof w->text - used, "%s\n", message);
}

#endif
