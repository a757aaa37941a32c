/* Internal: EXR ZIP / ZIPS chunks deflated by libdeflate (exr_zip.c).
 *
 * OpenEXR Core deflates ZIP chunks with zlib, which took ~0.3 CPU-s of a
 * 1920 x 1080 frame's 16 half channels at levels 1 and 2 alike: the write
 * was 15.8 % of a balanced frame against issue 12's 15 % (docs/
 * performance.md). The chunk format is OpenEXR's (and Blender's, and any
 * reader's): the packed bytes split into their even and odd halves, a
 * delta predictor (d = b[i] - b[i-1] + 128, modulo 256), then one zlib
 * stream (RFC 1950); a chunk that does not shrink is stored as packed.
 * libdeflate writes the same stream format faster. */
#ifndef VSGL_IO_EXR_ZIP_H
#define VSGL_IO_EXR_ZIP_H

#include <stddef.h>
#include <stdint.h>

typedef struct vsgl__zip_coder vsgl__zip_coder;

/* A coder at zlib-style level 1..9 (libdeflate's levels of the same
 * names), for one thread; NULL when out of memory. */
vsgl__zip_coder *vsgl__zip_coder_new(int level);
void vsgl__zip_coder_free(vsgl__zip_coder *z);

/* One chunk: its n packed bytes (the file's line layout) to *out (malloc'd,
 * the caller frees) and *size: the zlib stream, or the packed bytes
 * themselves where the stream would not be smaller. 0 on success, -1 when
 * out of memory. */
int vsgl__zip_encode(vsgl__zip_coder *z, const unsigned char *packed, size_t n, unsigned char **out, uint64_t *size);

#endif
