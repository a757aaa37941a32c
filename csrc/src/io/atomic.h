/* Internal: atomic file replacement shared by the EXR and bundle writers.
 * Owner: csrc/src/io.
 *
 *   vsgl__atomic_file f;
 *   if (vsgl__atomic_open(ctx, path, &f)) return ...;      // temp file in path's dir
 *   ... vsgl__atomic_pwrite(&f, buf, n, offset) ...         // any number of writes
 *   return vsgl__atomic_commit(ctx, &f);                     // fsync, rename, fsync dir
 *   (on an error path: vsgl__atomic_abort(&f) deletes the temp file)
 */
#ifndef VSGL_IO_ATOMIC_H
#define VSGL_IO_ATOMIC_H

#include "vsgl/base.h"

typedef struct vsgl__atomic_file {
    int fd;            /* -1 when closed */
    int error;         /* first errno seen by vsgl__atomic_pwrite, 0 if none */
    char *target;      /* owned copies */
    char *temp;
} vsgl__atomic_file;

/* Create a uniquely named temporary file beside path. On failure f is
 * left closed (nothing to abort) and the context names the reason. */
vsgl_result vsgl__atomic_open(vsgl_context *ctx, const char *path, vsgl__atomic_file *f);

/* Write all n bytes at offset; returns 0 or -1 (errno kept in f->error). */
int vsgl__atomic_pwrite(vsgl__atomic_file *f, const void *buf, size_t n, uint64_t offset);

/* fsync, close, rename over the target, fsync the directory. On failure
 * the temporary file is deleted and the target untouched. Always frees f. */
vsgl_result vsgl__atomic_commit(vsgl_context *ctx, vsgl__atomic_file *f);

/* Close and delete the temporary file, free f. Safe on a closed f. */
void vsgl__atomic_abort(vsgl__atomic_file *f);

/* Thread-safe strerror: use as vsgl__strerror(e).s within one expression. */
typedef struct vsgl__errstr { char s[128]; } vsgl__errstr;
vsgl__errstr vsgl__strerror(int e);

/* Is directory entry `name` a temporary file of these writers
 * (".<target>.tmp-<pid>-<ns>-<try>[-<host>]")? Then *pid is its writer and
 * *this_host whether `host` (see atomic.c) wrote it. Returns 0 or 1. */
int vsgl__atomic_temp_owner(const char *name, const char *host, long *pid, int *this_host);

/* Write a whole buffer to path atomically. */
vsgl_result vsgl__atomic_write_all(vsgl_context *ctx, const char *path, const void *data, size_t n);

#endif
