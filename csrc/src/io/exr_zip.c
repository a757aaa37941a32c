/* EXR ZIP / ZIPS chunks by libdeflate (exr_zip.h). */
#include "io/exr_zip.h"

#include <libdeflate.h>
#include <stdlib.h>
#include <string.h>

struct vsgl__zip_coder {
    struct libdeflate_compressor *c;
    unsigned char *scratch; /* 2 x cap bytes: the reordered bytes, then the predicted ones */
    size_t cap;
};

vsgl__zip_coder *vsgl__zip_coder_new(int level)
{
    vsgl__zip_coder *z = calloc(1, sizeof *z);
    if (!z)
        return NULL;
    z->c = libdeflate_alloc_compressor(level < 1 ? 1 : (level > 9 ? 9 : level));
    if (!z->c) {
        free(z);
        return NULL;
    }
    return z;
}

void vsgl__zip_coder_free(vsgl__zip_coder *z)
{
    if (!z)
        return;
    libdeflate_free_compressor(z->c);
    free(z->scratch);
    free(z);
}

int vsgl__zip_encode(vsgl__zip_coder *z, const unsigned char *packed, size_t n, unsigned char **out, uint64_t *size)
{
    *out = NULL;
    *size = 0;
    if (n > z->cap) {
        unsigned char *s = realloc(z->scratch, 2 * n);
        if (!s)
            return -1;
        z->scratch = s;
        z->cap = n;
    }
    /* even bytes first, then odd ones (OpenEXR's order: the first half takes
     * (n + 1) / 2), into t; then the predictor from t into p, every byte
     * against its unchanged predecessor (both loops vectorise) */
    unsigned char *t = z->scratch, *p = z->scratch + n;
    const size_t h = n / 2, first = (n + 1) / 2;
    for (size_t m = 0; m < h; ++m) {
        t[m] = packed[2 * m];
        t[first + m] = packed[2 * m + 1];
    }
    if (n & 1)
        t[h] = packed[n - 1];
    if (n)
        p[0] = t[0];
    for (size_t k = 1; k < n; ++k)
        p[k] = (unsigned char)(t[k] - t[k - 1] + 128u);
    size_t bound = libdeflate_zlib_compress_bound(z->c, n);
    unsigned char *buf = malloc(bound > n ? bound : (n ? n : 1));
    if (!buf)
        return -1;
    size_t got = n ? libdeflate_zlib_compress(z->c, p, n, buf, bound) : 0;
    if (got == 0 || got >= n) { /* not smaller: stored as packed, as readers expect */
        memcpy(buf, packed, n);
        got = n;
    }
    *out = buf;
    *size = got;
    return 0;
}
