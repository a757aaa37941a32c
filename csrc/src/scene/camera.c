/* Blender camera -> primary rays, matching Cycles' render camera:
 *
 *   xratio = width * pixel_aspect_x, yratio = height * pixel_aspect_y
 *   fit    = AUTO: horizontal if xratio > yratio (sensor size = sensor_width)
 *            HORIZONTAL: sensor_width; VERTICAL: sensor_height
 *   horizontal fit: aspect = xratio / yratio, plane x in [-aspect, aspect], y in [-1, 1]
 *   vertical fit:   aspect = yratio / xratio, plane x in [-1, 1], y in [-aspect, aspect]
 *   shift: plane += 2 * aspect * (shift_x, shift_y)
 *   perspective: plane scaled by tan(fov/2) = 0.5 * sensor / lens / aspect,
 *                i.e. the fitted side spans sensor/lens at distance 1
 *   orthographic: plane scaled by ortho_scale / (2 * aspect), i.e. the fitted
 *                side spans ortho_scale metres
 *   clipping: on depth along the view axis, [clip_start, clip_end]
 *   the object's scale is removed (axes normalised), as Cycles does.
 * Raster y grows downwards here (row 0 = top); Cycles' raster y grows up. */
#include "scene/camera.h"

static v3 column(const float m[12], int c)
{
    return v3_make(m[c], m[4 + c], m[8 + c]);
}

void vsgl__camera_model(const vsgl_camera *cam, vsgl_camera_model *out)
{
    out->ortho = cam->type == VSGL_CAMERA_ORTHOGRAPHIC;
    out->width = cam->width;
    out->height = cam->height;
    out->origin = v3_make(cam->world_from_camera[3], cam->world_from_camera[7], cam->world_from_camera[11]);
    out->right = v3_normalize(column(cam->world_from_camera, 0));
    out->up = v3_normalize(column(cam->world_from_camera, 1));
    out->forward = v3_neg(v3_normalize(column(cam->world_from_camera, 2)));

    double xratio = (double)cam->width * cam->pixel_aspect_x;
    double yratio = (double)cam->height * cam->pixel_aspect_y;
    int horizontal;
    double sensor;
    if (cam->sensor_fit == VSGL_SENSOR_FIT_AUTO) {
        horizontal = xratio > yratio;
        sensor = cam->sensor_width_mm;
    } else if (cam->sensor_fit == VSGL_SENSOR_FIT_HORIZONTAL) {
        horizontal = 1;
        sensor = cam->sensor_width_mm;
    } else {
        horizontal = 0;
        sensor = cam->sensor_height_mm;
    }
    double aspect, xa, ya;
    if (horizontal) {
        aspect = xratio / yratio;
        xa = aspect;
        ya = 1.0;
    } else {
        aspect = yratio / xratio;
        xa = 1.0;
        ya = aspect;
    }
    double dx = 2.0 * aspect * cam->shift_x;
    double dy = 2.0 * aspect * cam->shift_y;
    double scale = out->ortho ? cam->ortho_scale / (2.0 * aspect)
                              : 0.5 * sensor / cam->lens_mm / aspect;
    out->left = (float)((-xa + dx) * scale);
    out->right_edge = (float)((xa + dx) * scale);
    out->bottom = (float)((-ya + dy) * scale);
    out->top = (float)((ya + dy) * scale);
    out->clip_start = cam->clip_start;
    out->clip_end = cam->clip_end;
}

void vsgl__camera_ray(const vsgl_camera_model *m, float px, float py, v3 *org, v3 *dir,
                      float *tmin, float *tmax)
{
    float fx = px / (float)m->width, fy = py / (float)m->height;
    float x = m->left + fx * (m->right_edge - m->left);
    float y = m->top - fy * (m->top - m->bottom);
    if (m->ortho) {
        *org = v3_add(m->origin, v3_add(v3_scale(m->right, x), v3_scale(m->up, y)));
        *dir = m->forward;
        *tmin = m->clip_start;
        *tmax = m->clip_end;
        return;
    }
    v3 d = v3_add(m->forward, v3_add(v3_scale(m->right, x), v3_scale(m->up, y)));
    /* |(x, y, 1)| converts depth along the axis to distance along the ray */
    float len = sqrtf(x * x + y * y + 1.0f);
    *org = m->origin;
    *dir = v3_normalize(d);
    *tmin = m->clip_start * len;
    *tmax = m->clip_end * len;
}

#if defined(__SSE2__)
#  include <emmintrin.h>

void vsgl__camera_ray4(const vsgl_camera_model *m, const float *px, const float *py, v3 org[4], v3 dir[4],
                       float tmin[4], float tmax[4])
{
    if (m->ortho) {
        for (int k = 0; k < 4; ++k)
            vsgl__camera_ray(m, px[k], py[k], &org[k], &dir[k], &tmin[k], &tmax[k]);
        return;
    }
    /* vsgl__camera_ray's perspective branch, lane by lane the same operations */
    const __m128 fx = _mm_div_ps(_mm_loadu_ps(px), _mm_set1_ps((float)m->width));
    const __m128 fy = _mm_div_ps(_mm_loadu_ps(py), _mm_set1_ps((float)m->height));
    const __m128 x = _mm_add_ps(_mm_set1_ps(m->left), _mm_mul_ps(fx, _mm_set1_ps(m->right_edge - m->left)));
    const __m128 y = _mm_sub_ps(_mm_set1_ps(m->top), _mm_mul_ps(fy, _mm_set1_ps(m->top - m->bottom)));
    const __m128 dx = _mm_add_ps(_mm_set1_ps(m->forward.x), _mm_add_ps(_mm_mul_ps(_mm_set1_ps(m->right.x), x),
                                                                       _mm_mul_ps(_mm_set1_ps(m->up.x), y)));
    const __m128 dy = _mm_add_ps(_mm_set1_ps(m->forward.y), _mm_add_ps(_mm_mul_ps(_mm_set1_ps(m->right.y), x),
                                                                       _mm_mul_ps(_mm_set1_ps(m->up.y), y)));
    const __m128 dz = _mm_add_ps(_mm_set1_ps(m->forward.z), _mm_add_ps(_mm_mul_ps(_mm_set1_ps(m->right.z), x),
                                                                       _mm_mul_ps(_mm_set1_ps(m->up.z), y)));
    const __m128 len = _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y)), _mm_set1_ps(1.0f)));
    /* v3_normalize(d) */
    const __m128 l = _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz)));
    const __m128 ok = _mm_and_ps(_mm_cmpgt_ps(l, _mm_setzero_ps()), _mm_cmplt_ps(l, _mm_set1_ps(INFINITY)));
    const __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), l);
    float D[3][4];
    _mm_storeu_ps(D[0], _mm_and_ps(ok, _mm_mul_ps(dx, inv)));
    _mm_storeu_ps(D[1], _mm_and_ps(ok, _mm_mul_ps(dy, inv)));
    _mm_storeu_ps(D[2], _mm_and_ps(ok, _mm_mul_ps(dz, inv)));
    _mm_storeu_ps(tmin, _mm_mul_ps(_mm_set1_ps(m->clip_start), len));
    _mm_storeu_ps(tmax, _mm_mul_ps(_mm_set1_ps(m->clip_end), len));
    for (int k = 0; k < 4; ++k) {
        org[k] = m->origin;
        dir[k] = v3_make(D[0][k], D[1][k], D[2][k]);
    }
}
#endif
