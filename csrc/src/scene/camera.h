/* Internal: Blender/Cycles camera model -> world-space primary rays.
 * Owner: csrc/src/scene. Used by the G-buffer (and any stage that needs to
 * project into the camera). Semantics follow Cycles' blender camera sync
 * (intern/cycles/blender/camera.cpp, blender_camera_viewplane): see
 * docs/scene.md "Camera". */
#ifndef VSGL_SCENE_CAMERA_H
#define VSGL_SCENE_CAMERA_H

#include "vsgl/scene.h"
#include "math/vec.h"

typedef struct vsgl_camera_model {
    int ortho;                 /* 1 = orthographic */
    uint32_t width, height;    /* pixels */
    v3 origin;                 /* camera position, world */
    v3 right, up, forward;     /* world axes: local +X, +Y, -Z with scale removed (Cycles) */
    /* View plane: perspective at distance 1 in front of the camera
     * (tangent units), orthographic in metres. */
    float left, right_edge, bottom, top;
    float clip_start, clip_end;
} vsgl_camera_model;

/* Precompute the model of a validated camera. */
void vsgl__camera_model(const vsgl_camera *cam, vsgl_camera_model *out);

/* Ray through raster position (px, py) in pixels: px = col + sx, py = row + sy,
 * row 0 at the top, (0.5, 0.5) the centre of the top-left pixel. The ray is
 * org + t*dir, dir unit, for t in [*tmin, *tmax] (the clip range measured
 * along the view axis, as Cycles clips). */
void vsgl__camera_ray(const vsgl_camera_model *m, float px, float py, v3 *org, v3 *dir,
                      float *tmin, float *tmax);

#if defined(__SSE2__)
/* vsgl__camera_ray at raster positions (px[k], py[k]), k < 4, bit for bit
 * (perspective in SSE2 lanes; orthographic one ray at a time). */
void vsgl__camera_ray4(const vsgl_camera_model *m, const float *px, const float *py, v3 org[4], v3 dir[4],
                       float tmin[4], float tmax[4]);
#endif

#endif
