/* Internal: mip-mapped textures and their filtered lookups (texture.c), and
 * the per-point material inputs a textured scene hands the stages.
 * Owner: csrc/src/scene. */
#ifndef VSGL_SCENE_TEXTURE_H
#define VSGL_SCENE_TEXTURE_H

#include "vsgl/scene.h"
#include "core/context.h"

#define VSGL__TEX_MAX_LEVELS 18

typedef struct vsgl_tex_level {
    uint32_t w, h;
    float *p;                /* w * h * 4, linear RGBA, rows bottom to top */
} vsgl_tex_level;

typedef struct vsgl_tex {
    int srgb;                /* level 0 holds the caller's sRGB values, decoded after filtering
                                (as Cycles does for 8-bit sRGB images); levels 1.. are linear */
    uint32_t levels;         /* level 0 = the image, each next 2 x 2 box-filtered, last 1 x 1 */
    vsgl_tex_level lv[VSGL__TEX_MAX_LEVELS];
} vsgl_tex;

/* Copy and mip-map one validated texture. An sRGB texture keeps level 0
 * encoded (decoded after the bilinear lookup, as Cycles' 8-bit images); its
 * coarser levels average decoded (linear) values. */
vsgl_result vsgl__texture_build(vsgl_context *ctx, uint32_t index, const vsgl_texture *in, vsgl_tex *out);
void vsgl__texture_free(vsgl_tex *t);

/* Filtered RGBA at (u, v) (after the slot's transform) for a footprint of
 * `lod` = log2 of its side in level-0 texels (<= 0: magnified): bilinear or
 * nearest within a level (VSGL_FILTER_*), linear between levels, wrap per
 * VSGL_WRAP_* (Clip: 0 outside [0, 1] and for taps past the edge, as
 * Cycles). */
void vsgl__texture_lookup(const vsgl_tex *t, float u, float v, float lod, int32_t filter, int32_t wrap, float out[4]);

/* The sRGB transfer function's inverse (IEC 61966-2-1), as OpenColorIO's
 * "sRGB" in Blender. */
float vsgl__srgb_to_linear(float c);

#endif
