/* libFuzzer target: the command-line parser of build/vsgl (csrc/cli/options.c)
 * on arbitrary argument vectors (issue 10). The input is split at NUL bytes
 * into at most 64 arguments after "vsgl".
 *
 * Properties (abort() = a finding): no crash or UB; cli_parse returns 0 or
 * 2; on 2 the reason is one non-empty line; on 0 a render/info command has
 * a scene; cli_settings and cli_describe_settings on the result (with and
 * without bundle settings) stay within their buffers; cli_parse_bytes on
 * every argument either fails or gives a value whose digits it read. */
#include "options.h"

#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    enum { MAX_ARGS = 64 };
    char *buf = malloc(size + 1);
    if (!buf)
        return 0;
    memcpy(buf, data, size);
    buf[size] = '\0';
    char *argv[MAX_ARGS + 2];
    int argc = 0;
    argv[argc++] = "vsgl";
    for (size_t i = 0; i <= size && argc < MAX_ARGS + 1;) {
        argv[argc++] = buf + i;
        i += strlen(buf + i) + 1;
    }
    argv[argc] = NULL;
    cli_options o;
    char err[512];
    int rc = cli_parse(argc, argv, &o, err, sizeof err);
    if (rc != 0 && rc != 2)
        abort();
    if (rc == 2 && (!err[0] || strchr(err, '\n')))
        abort();
    if (rc == 0) {
        if ((o.command == CLI_RENDER || o.command == CLI_INFO) && !o.scene_path)
            abort();
        vsgl_render_settings base, s;
        memset(&base, 0xA5, sizeof base); /* any bytes a bundle may hold */
        char desc[512];
        cli_settings(&o, NULL, &s);
        cli_describe_settings(&s, desc, sizeof desc);
        cli_settings(&o, &base, &s);
        cli_describe_settings(&s, desc, sizeof desc);
        if (strlen(desc) >= sizeof desc)
            abort();
    }
    for (int i = 1; i < argc; ++i) {
        uint64_t v = 0;
        if (cli_parse_bytes(argv[i], &v) == 0 && (argv[i][0] < '0' || argv[i][0] > '9'))
            abort();
    }
    free(buf);
    return 0;
}
