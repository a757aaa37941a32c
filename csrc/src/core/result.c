/* Result-code strings and version queries. */
#include "vsgl/base.h"

const char *vsgl_result_string(vsgl_result code)
{
    static const char *const names[VSGL_RESULT_COUNT] = {
        "success",
        "invalid argument",
        "out of memory",
        "input/output error",
        "bad file format",
        "version mismatch",
        "unsupported",
        "cancelled",
        "internal error",
    };
    if (code < 0 || code >= VSGL_RESULT_COUNT)
        return "unknown result code";
    return names[code];
}

int32_t vsgl_version(void)
{
    return VSGL_VERSION;
}

#define VSGL__STR2(x) #x
#define VSGL__STR(x) VSGL__STR2(x)

const char *vsgl_version_string(void)
{
    return VSGL__STR(VSGL_VERSION_MAJOR) "." VSGL__STR(VSGL_VERSION_MINOR) "." VSGL__STR(VSGL_VERSION_PATCH);
}
