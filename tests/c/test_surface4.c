/* The G-buffer's four-lane paths against their scalar functions, bit for
 * bit: vsgl__scene_surface4 against vsgl__scene_surface (random hits on
 * both sides of triangles whose corner normals are the face's, bent,
 * cancelling, or along the first edge so that the tangent degenerates;
 * an anisotropic rotation) and vsgl__camera_ray4 against vsgl__camera_ray
 * (perspective with shifts and both sensor fits, orthographic). */
#include "harness.h"
#include "rand_dir.h"
#include "scene_fixture.h"
#include "scene/camera.h"
#include "scene/scene_internal.h"

#include <string.h>

#if defined(__SSE2__)

static void check_surface4(int with_uvs);

VT_TEST(scene_surface4_equals_scene_surface_bit_for_bit)
{
    check_surface4(0);
}

/* with corner UVs: the tangent is dP/du where the UVs give one (random
 * UVs; every fifth triangle's degenerate, det 0: the edge's tangent) */
VT_TEST(scene_surface4_equals_scene_surface_with_uvs)
{
    check_surface4(1);
}

static void check_surface4(int with_uvs)
{
    fx_scene fx;
    fx_room(&fx, 16, 12, 0.3f, 50.0f);
    fx.materials[2].anisotropy = 0.5f;
    fx.materials[2].anisotropic_rotation = 0.3f; /* the green wall: the scalar lanes */
    if (with_uvs) /* rotated off the axes, so that no product in dP/du is exact by accident */
        for (uint32_t i = 0; i < fx.vertex_count; ++i) {
            float *p = fx.positions + i * 3, x = p[0], y = p[1], z = p[2];
            p[0] = 0.8f * x - 0.6f * y;
            p[1] = 0.48f * x + 0.64f * y - 0.6f * z;
            p[2] = 0.36f * x + 0.48f * y + 0.8f * z;
        }
    const vsgl_scene_desc *d0 = fx_desc(&fx);
    vsgl_scene_desc desc = *d0;
    static float cn[FX_MAX_TRIS * 9];
    vt_rng rng = {77};
    for (uint32_t t = 0; t < fx.triangle_count; ++t) {
        const uint32_t *ix = fx.indices + t * 3;
        const float *p0 = fx.positions + ix[0] * 3, *p1 = fx.positions + ix[1] * 3, *p2 = fx.positions + ix[2] * 3;
        v3 e1 = v3_make(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]);
        v3 e2 = v3_make(p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]);
        v3 f = v3_normalize(v3_cross(e1, e2));
        for (int c = 0; c < 3; ++c) {
            v3 n = f;
            if (t % 4 == 3) /* bent */
                n = v3_normalize(v3_add(f, v3_scale(rand_dir(&rng), 0.4f)));
            else if (t % 4 == 1) /* cancelling: corner 0 against corners 1 and 2 */
                n = c == 0 ? v3_neg(f) : f;
            else if (t % 4 == 2) /* along the first edge (axis-aligned: fx_quad's first triangle): no tangent */
                n = v3_normalize(e1);
            cn[t * 9 + c * 3] = n.x, cn[t * 9 + c * 3 + 1] = n.y, cn[t * 9 + c * 3 + 2] = n.z;
        }
    }
    desc.corner_normals = cn;
    static float uvs[FX_MAX_TRIS * 6];
    for (uint32_t t = 0; t < fx.triangle_count; ++t)
        for (int c = 0; c < 6; ++c)
            uvs[t * 6 + c] = t % 5 == 4 ? 0.25f : urand(&rng, -2.0f, 2.0f);
    if (with_uvs)
        desc.corner_uvs = uvs;
    vsgl_context *ctx = fx_context(1);
    vsgl_scene *scene = NULL;
    VT_REQUIRE(ctx && vsgl_scene_create(ctx, &desc, &scene) == VSGL_OK, "scene: %s",
               ctx ? vsgl_context_last_error(ctx) : "no context");
    size_t bad = 0, n = 0;
    for (int it = 0; it < 4000; ++it) {
        vsgl_hit h[4];
        v3 dir[4];
        for (int k = 0; k < 4; ++k) {
            float u = (float)vt_uniform(&rng), v = (float)vt_uniform(&rng);
            if (u + v > 1.0f)
                u = 1.0f - u, v = 1.0f - v;
            if (it % 7 == 0) /* where the cancelling normals sum to 0, the edge's stay exact */
                u = 0.25f, v = 0.25f;
            h[k].t = 1.0f;
            h[k].triangle = (uint32_t)(vt_uniform(&rng) * fx.triangle_count);
            h[k].u = u;
            h[k].v = v;
            dir[k] = rand_dir(&rng);
        }
        vsgl_surface a[4], b[4];
        memset(a, 0, sizeof a);
        memset(b, 0, sizeof b);
        for (int k = 0; k < 4; ++k)
            vsgl__scene_surface(scene, &h[k], dir[k], &a[k]);
        vsgl__scene_surface4(scene, h, dir, b);
        for (int k = 0; k < 4; ++k, ++n)
            if (memcmp(&a[k], &b[k], sizeof a[k]) && bad++ < 4)
                vt_note("    ", "triangle %u (u %.9g, v %.9g): normal %.9g %.9g %.9g vs %.9g %.9g %.9g", h[k].triangle,
                        h[k].u, h[k].v, a[k].normal.x, a[k].normal.y, a[k].normal.z, b[k].normal.x, b[k].normal.y,
                        b[k].normal.z);
    }
    VT_CHECK(bad == 0, "%zu of %zu surfaces differ", bad, n);
    vsgl_scene_destroy(scene);
    vsgl_context_destroy(ctx);
}

VT_TEST(camera_ray4_equals_camera_ray_bit_for_bit)
{
    vt_rng rng = {91};
    size_t bad = 0, n = 0;
    for (int cam_i = 0; cam_i < 6; ++cam_i) {
        fx_scene fx;
        fx_room(&fx, 320 + 17 * (uint32_t)cam_i, 180 + 31 * (uint32_t)cam_i, 0.3f, 50.0f);
        vsgl_camera c = fx.camera;
        c.type = cam_i == 5 ? VSGL_CAMERA_ORTHOGRAPHIC : VSGL_CAMERA_PERSPECTIVE;
        c.ortho_scale = 3.0f;
        c.sensor_fit = cam_i == 2 ? VSGL_SENSOR_FIT_VERTICAL : cam_i == 3 ? VSGL_SENSOR_FIT_HORIZONTAL : c.sensor_fit;
        c.shift_x = cam_i == 4 ? 0.13f : 0.0f;
        c.shift_y = cam_i == 4 ? -0.07f : 0.0f;
        c.clip_start = 0.1f;
        c.clip_end = 100.0f;
        vsgl_camera_model m;
        vsgl__camera_model(&c, &m);
        for (int it = 0; it < 2000; ++it) {
            float px[4], py[4], t0a[4], t1a[4], t0b[4], t1b[4];
            v3 oa[4], da[4], ob[4], db[4];
            for (int k = 0; k < 4; ++k) {
                px[k] = (float)(uint32_t)urand(&rng, 0.0f, (float)c.width) + urand(&rng, 0.0f, 1.0f);
                py[k] = (float)(uint32_t)urand(&rng, 0.0f, (float)c.height) + 0.5f;
                vsgl__camera_ray(&m, px[k], py[k], &oa[k], &da[k], &t0a[k], &t1a[k]);
            }
            vsgl__camera_ray4(&m, px, py, ob, db, t0b, t1b);
            for (int k = 0; k < 4; ++k, ++n)
                if (memcmp(&oa[k], &ob[k], sizeof oa[k]) || memcmp(&da[k], &db[k], sizeof da[k]) ||
                    memcmp(&t0a[k], &t0b[k], sizeof t0a[k]) || memcmp(&t1a[k], &t1b[k], sizeof t1a[k])) {
                    if (bad++ < 4)
                        vt_note("    ", "camera %d at (%.9g, %.9g): dir %.9g %.9g %.9g vs %.9g %.9g %.9g", cam_i,
                                px[k], py[k], da[k].x, da[k].y, da[k].z, db[k].x, db[k].y, db[k].z);
                }
        }
    }
    VT_CHECK(bad == 0, "%zu of %zu rays differ", bad, n);
}
#endif
