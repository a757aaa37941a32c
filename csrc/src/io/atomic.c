/* Atomic file replacement: temp file beside the target, fsync, rename, fsync dir. */
#include "io/atomic.h"
#include "vsgl/io.h"
#include "core/context.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static char *dup_string(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* Directory part of path ("." if none); caller frees. */
static char *dir_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        return dup_string(".");
    if (slash == path)
        return dup_string("/");
    size_t n = (size_t)(slash - path);
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, path, n);
        d[n] = '\0';
    }
    return d;
}

vsgl__errstr vsgl__strerror(int e)
{
    vsgl__errstr r;
    r.s[0] = '\0';
#if defined(_GNU_SOURCE)
    const char *m = strerror_r(e, r.s, sizeof r.s); /* GNU: may return a static string */
    if (m != r.s)
        snprintf(r.s, sizeof r.s, "%s", m);
#else
    if (strerror_r(e, r.s, sizeof r.s) != 0)
        snprintf(r.s, sizeof r.s, "error %d", e);
#endif
    return r;
}

/* This host's name, reduced to [A-Za-z0-9._] (a temp name's last field). */
static void host_tag(char *buf, size_t n)
{
    char h[256] = {0};
    if (gethostname(h, sizeof h - 1) != 0 || !h[0])
        snprintf(h, sizeof h, "localhost");
    size_t k = 0;
    for (const char *p = h; *p && k + 1 < n && k < 63; ++p) {
        char c = *p;
        buf[k++] = ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.') ? c : '_';
    }
    buf[k] = '\0';
}

/* Parse "<digits>-" at *p, advancing past it; -1 if absent. */
static long long take_number(const char **p, char end)
{
    const char *s = *p;
    long long v = 0;
    if (*s < '0' || *s > '9')
        return -1;
    while (*s >= '0' && *s <= '9') {
        if (v > 100000000000000LL)
            return -1;
        v = v * 10 + (*s++ - '0');
    }
    if (*s != end)
        return -1;
    *p = s + (end ? 1 : 0);
    return v;
}

/* Is `name` a temporary file of these writers, ".<x>.tmp-<pid>-<ns>-<try>"
 * with an optional "-<host>"? Gives the pid and whether the host is ours. */
int vsgl__atomic_temp_owner(const char *name, const char *host, long *pid, int *this_host)
{
    if (name[0] != '.')
        return 0;
    const char *t = NULL;
    for (const char *q = strstr(name, ".tmp-"); q; q = strstr(q + 1, ".tmp-"))
        t = q; /* the last one: a target may itself contain ".tmp-" */
    if (!t || t == name)
        return 0;
    const char *p = t + 5;
    long long v = take_number(&p, '-');
    if (v <= 0 || take_number(&p, '-') < 0)
        return 0;
    const char *try_start = p;
    if (take_number(&p, '\0') >= 0) { /* no host field: an older writer, same machine */
        *this_host = 1;
    } else {
        p = try_start;
        if (take_number(&p, '-') < 0 || !*p)
            return 0;
        *this_host = strcmp(p, host) == 0;
    }
    *pid = (long)v;
    return 1;
}

/* Delete the temporary files a crashed or killed writer left in `dir`
 * (issue 10): only this host's, only if their process is gone, and say so. */
static void remove_stale_temps(vsgl_context *ctx, const char *dir, const char *host)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    long self = (long)getpid();
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        long pid = 0;
        int ours = 0;
        if (!vsgl__atomic_temp_owner(e->d_name, host, &pid, &ours) || !ours || pid == self)
            continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue; /* alive (or not ours to signal: EPERM means it exists) */
        size_t n = strlen(dir) + strlen(e->d_name) + 2;
        char *path = malloc(n);
        if (!path)
            break;
        snprintf(path, n, "%s/%s", dir, e->d_name);
        struct stat st;
        if (lstat(path, &st) == 0 && S_ISREG(st.st_mode) && unlink(path) == 0)
            vsgl__log(ctx, VSGL_LOG_WARNING, "removed %s: a temporary file (%lld bytes) left by an interrupted "
                      "write of process %ld, which is gone", path, (long long)st.st_size, pid);
        free(path);
    }
    closedir(d);
}

static void free_file(vsgl__atomic_file *f)
{
    free(f->target);
    free(f->temp);
    f->target = f->temp = NULL;
    f->fd = -1;
}

vsgl_result vsgl__atomic_open(vsgl_context *ctx, const char *path, vsgl__atomic_file *f)
{
    f->fd = -1;
    f->error = 0;
    f->target = f->temp = NULL;
    if (!path || !*path)
        return vsgl__fail(ctx, VSGL_ERROR_INVALID_ARGUMENT, "output path is empty");
    size_t len = strlen(path);
    if (path[len - 1] == '/')
        return vsgl__fail(ctx, VSGL_ERROR_IO, "%s: is a directory", path);
    struct stat st;
    if (stat(path, &st) == 0) {
        if (S_ISDIR(st.st_mode))
            return vsgl__fail(ctx, VSGL_ERROR_IO, "%s: is a directory", path);
        if (!S_ISREG(st.st_mode))
            return vsgl__fail(ctx, VSGL_ERROR_IO, "%s: exists and is not a regular file", path);
    }
    char *dir = dir_of(path);
    if (!dir)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "out of memory");
    const char *why = NULL;
    vsgl__errstr es;
    if (stat(dir, &st) != 0) {
        es = vsgl__strerror(errno);
        why = es.s;
    }
    else if (!S_ISDIR(st.st_mode))
        why = "is not a directory";
    if (why) {
        vsgl_result r = vsgl__fail(ctx, VSGL_ERROR_IO, "%s: directory %s: %s", path, dir, why);
        free(dir);
        return r;
    }
    char host[64];
    host_tag(host, sizeof host);
    remove_stale_temps(ctx, dir, host);
    free(dir);

    const char *base = strrchr(path, '/');
    size_t dir_len = base ? (size_t)(base - path) + 1 : 0;
    base = base ? base + 1 : path;
    size_t cap = len + 64 + sizeof host;
    f->target = dup_string(path);
    f->temp = malloc(cap);
    if (!f->target || !f->temp) {
        free_file(f);
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "out of memory");
    }
    /* ".<name>.tmp-<pid>-<ns>-<try>-<host>": unique per process and attempt (O_EXCL
     * guarantees it); the pid and host let a later write tell a stale one. */
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    int e = 0;
    for (unsigned attempt = 0; attempt < 100; ++attempt) {
        snprintf(f->temp, cap, "%.*s.%s.tmp-%ld-%09ld-%u-%s", (int)dir_len, path, base,
                 (long)getpid(), (long)ts.tv_nsec, attempt, host);
        f->fd = open(f->temp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (f->fd >= 0)
            return VSGL_OK;
        e = errno;
        if (e != EEXIST)
            break;
    }
    vsgl_result r = vsgl__fail(ctx, VSGL_ERROR_IO, "%s: cannot create a file in its directory: %s",
                               path, vsgl__strerror(e).s);
    free_file(f);
    return r;
}

int vsgl__atomic_pwrite(vsgl__atomic_file *f, const void *buf, size_t n, uint64_t offset)
{
    const unsigned char *p = buf;
    while (n > 0) {
        ssize_t w = pwrite(f->fd, p, n, (off_t)offset);
        if (w < 0) {
            if (errno == EINTR)
                continue;
            if (!f->error)
                f->error = errno;
            return -1;
        }
        if (w == 0) {
            if (!f->error)
                f->error = EIO;
            return -1;
        }
        p += w;
        n -= (size_t)w;
        offset += (uint64_t)w;
    }
    return 0;
}

void vsgl__atomic_abort(vsgl__atomic_file *f)
{
    if (f->fd >= 0)
        close(f->fd);
    if (f->temp)
        unlink(f->temp);
    free_file(f);
}

vsgl_result vsgl__atomic_commit(vsgl_context *ctx, vsgl__atomic_file *f)
{
    if (f->error) {
        vsgl_result r = vsgl__fail(ctx, VSGL_ERROR_IO, "%s: write failed: %s", f->target, vsgl__strerror(f->error).s);
        vsgl__atomic_abort(f);
        return r;
    }
    if (fsync(f->fd) != 0) {
        vsgl_result r = vsgl__fail(ctx, VSGL_ERROR_IO, "%s: fsync failed: %s", f->target, vsgl__strerror(errno).s);
        vsgl__atomic_abort(f);
        return r;
    }
    int fd = f->fd;
    f->fd = -1;
    if (close(fd) != 0) {
        vsgl_result r = vsgl__fail(ctx, VSGL_ERROR_IO, "%s: close failed: %s", f->target, vsgl__strerror(errno).s);
        vsgl__atomic_abort(f);
        return r;
    }
    if (rename(f->temp, f->target) != 0) {
        vsgl_result r = vsgl__fail(ctx, VSGL_ERROR_IO, "%s: cannot replace: %s", f->target, vsgl__strerror(errno).s);
        vsgl__atomic_abort(f);
        return r;
    }
    /* Make the rename durable; a failure here does not undo the (complete) file. */
    char *dir = dir_of(f->target);
    if (dir) {
        int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (dfd >= 0) {
            (void)fsync(dfd);
            close(dfd);
        }
        free(dir);
    }
    free_file(f);
    return VSGL_OK;
}

vsgl_result vsgl__atomic_write_all(vsgl_context *ctx, const char *path, const void *data, size_t n)
{
    vsgl__atomic_file f;
    vsgl_result r = vsgl__atomic_open(ctx, path, &f);
    if (r)
        return r;
    (void)vsgl__atomic_pwrite(&f, data, n, 0);
    return vsgl__atomic_commit(ctx, &f);
}

vsgl_result vsgl_check_output_path(vsgl_context *ctx, const char *path)
{
    vsgl__clear_error(ctx);
    vsgl__atomic_file f;
    vsgl_result r = vsgl__atomic_open(ctx, path, &f);
    if (r)
        return r;
    vsgl__atomic_abort(&f);
    return VSGL_OK;
}
