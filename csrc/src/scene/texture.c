/* Textures: a caller's float RGBA image copied into a mip pyramid (2 x 2
 * box filter, odd sizes rounded up with the edge texel repeated), looked up
 * bilinearly (or nearest) within a level and linearly between levels, with
 * Blender's Repeat / Extend / Clip extensions. Reads only: thread-safe. */
#include "scene/texture.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

float vsgl__srgb_to_linear(float c)
{
    if (!(c > 0.04045f))
        return c < 0.0f ? c : c * (1.0f / 12.92f);
    return powf((c + 0.055f) * (1.0f / 1.055f), 2.4f);
}

void vsgl__texture_free(vsgl_tex *t)
{
    if (!t)
        return;
    for (uint32_t l = 0; l < t->levels; ++l)
        free(t->lv[l].p);
    memset(t, 0, sizeof *t);
}

vsgl_result vsgl__texture_build(vsgl_context *ctx, uint32_t index, const vsgl_texture *in, vsgl_tex *out)
{
    memset(out, 0, sizeof *out);
    uint32_t w = in->width, h = in->height;
    size_t n = (size_t)w * h * 4;
    float *p = malloc(n * sizeof(float));
    if (!p)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "texture %u: out of memory for %ux%u texels", (unsigned)index,
                          (unsigned)w, (unsigned)h);
    memcpy(p, in->pixels, n * sizeof(float));
    out->lv[0] = (vsgl_tex_level){w, h, p};
    out->levels = 1;
    out->srgb = (in->flags & VSGL_TEXTURE_FLAG_SRGB) != 0;
    /* the source of level 1: level 0, decoded for sRGB textures */
    float *lin = NULL;
    if (out->srgb && (w > 1 || h > 1)) {
        lin = malloc(n * sizeof(float));
        if (!lin) {
            vsgl__texture_free(out); /* frees p: it is out->lv[0].p */
            // cppcheck-suppress memleak
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "texture %u: out of memory for %ux%u texels", (unsigned)index,
                              (unsigned)w, (unsigned)h);
        }
        for (size_t i = 0; i < n; ++i)
            lin[i] = (i & 3) == 3 ? p[i] : vsgl__srgb_to_linear(p[i]);
    }
    while ((w > 1 || h > 1) && out->levels < VSGL__TEX_MAX_LEVELS) {
        vsgl_tex_level src0 = out->lv[out->levels - 1];
        if (out->levels == 1 && lin)
            src0.p = lin;
        const vsgl_tex_level *s = &src0;
        uint32_t nw = (s->w + 1) / 2, nh = (s->h + 1) / 2;
        float *q = malloc((size_t)nw * nh * 4 * sizeof(float));
        if (!q) {
            free(lin);
            vsgl__texture_free(out);
            return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "texture %u: out of memory for its mip levels", (unsigned)index);
        }
        for (uint32_t y = 0; y < nh; ++y) {
            uint32_t y0 = 2 * y, y1 = 2 * y + 1 < s->h ? 2 * y + 1 : s->h - 1;
            for (uint32_t x = 0; x < nw; ++x) {
                uint32_t x0 = 2 * x, x1 = 2 * x + 1 < s->w ? 2 * x + 1 : s->w - 1;
                const float *a = s->p + ((size_t)y0 * s->w + x0) * 4, *b = s->p + ((size_t)y0 * s->w + x1) * 4;
                const float *c = s->p + ((size_t)y1 * s->w + x0) * 4, *d = s->p + ((size_t)y1 * s->w + x1) * 4;
                float *o = q + ((size_t)y * nw + x) * 4;
                for (int k = 0; k < 4; ++k)
                    o[k] = 0.25f * ((a[k] + b[k]) + (c[k] + d[k]));
            }
        }
        out->lv[out->levels++] = (vsgl_tex_level){nw, nh, q};
        w = nw;
        h = nh;
    }
    free(lin);
    return VSGL_OK;
}

/* Texel index along an axis of n texels, or -1 (Clip, outside). */
static long wrap_index(long i, long n, int32_t wrap)
{
    if (wrap == VSGL_WRAP_REPEAT) {
        i %= n;
        return i < 0 ? i + n : i;
    }
    if (wrap == VSGL_WRAP_CLIP)
        return (i < 0 || i >= n) ? -1 : i;
    return i < 0 ? 0 : (i >= n ? n - 1 : i);
}

static void level_lookup(const vsgl_tex_level *L, float u, float v, int nearest, int32_t wrap, float out[4])
{
    long w = (long)L->w, h = (long)L->h;
    if (nearest) {
        long i = wrap_index((long)floorf(u * (float)w), w, wrap), j = wrap_index((long)floorf(v * (float)h), h, wrap);
        if (i < 0 || j < 0) {
            out[0] = out[1] = out[2] = out[3] = 0.0f;
            return;
        }
        memcpy(out, L->p + ((size_t)j * (size_t)w + (size_t)i) * 4, 4 * sizeof(float));
        return;
    }
    float x = u * (float)w - 0.5f, y = v * (float)h - 0.5f;
    float fx0 = floorf(x), fy0 = floorf(y);
    float fx = x - fx0, fy = y - fy0;
    long x0 = (long)fx0, y0 = (long)fy0;
    long xs[2] = {wrap_index(x0, w, wrap), wrap_index(x0 + 1, w, wrap)};
    long ys[2] = {wrap_index(y0, h, wrap), wrap_index(y0 + 1, h, wrap)};
    float wx[2] = {1.0f - fx, fx}, wy[2] = {1.0f - fy, fy};
    out[0] = out[1] = out[2] = out[3] = 0.0f;
    for (int b = 0; b < 2; ++b) {
        if (ys[b] < 0)
            continue;
        for (int a = 0; a < 2; ++a) {
            if (xs[a] < 0)
                continue;
            const float *t = L->p + ((size_t)ys[b] * (size_t)w + (size_t)xs[a]) * 4;
            float k = wx[a] * wy[b];
            for (int c = 0; c < 4; ++c)
                out[c] += k * t[c];
        }
    }
}

void vsgl__texture_lookup(const vsgl_tex *t, float u, float v, float lod, int32_t filter, int32_t wrap, float out[4])
{
    if (!(u == u) || !(v == v) || t->levels == 0) {
        out[0] = out[1] = out[2] = out[3] = 0.0f;
        return;
    }
    if (wrap == VSGL_WRAP_CLIP) {
        if (u < 0.0f || u > 1.0f || v < 0.0f || v > 1.0f) {
            out[0] = out[1] = out[2] = out[3] = 0.0f;
            return;
        }
    } else if (wrap == VSGL_WRAP_REPEAT) {
        u -= floorf(u); /* keeps far-away coordinates in range of the index arithmetic */
        v -= floorf(v);
    } else {
        u = u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
        v = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
    }
    if (!(lod > 0.0f))
        lod = 0.0f;
    float top = (float)(t->levels - 1);
    if (lod > top)
        lod = top;
    if (filter == VSGL_FILTER_CLOSEST && lod < 0.5f) {
        level_lookup(&t->lv[0], u, v, 1, wrap, out);
        if (t->srgb)
            for (int c = 0; c < 3; ++c)
                out[c] = vsgl__srgb_to_linear(out[c]);
        return;
    }
    uint32_t l0 = (uint32_t)lod;
    float f = lod - (float)l0;
    level_lookup(&t->lv[l0], u, v, 0, wrap, out);
    if (l0 == 0 && t->srgb)
        for (int c = 0; c < 3; ++c)
            out[c] = vsgl__srgb_to_linear(out[c]);
    if (f > 0.0f && l0 + 1 < t->levels) {
        float b[4];
        level_lookup(&t->lv[l0 + 1], u, v, 0, wrap, b);
        for (int c = 0; c < 4; ++c)
            out[c] += f * (b[c] - out[c]);
    }
}
