/* vsgl_scene_set_view: a scene whose camera and lights are replaced renders
 * exactly as a scene built with them; a refused view changes nothing. */
#include "harness.h"
#include "scene_fixture.h"

#include <stdlib.h>

enum { W = 40, H = 30 };

typedef struct img {
    float comb[W * H * 3];
} img;

static vsgl_result render(vsgl_context *ctx, const vsgl_scene *scene, img *out)
{
    vsgl_render_settings s;
    vsgl_render_settings_preset(VSGL_PRESET_PREVIEW, &s);
    vsgl_render_output o;
    memset(&o, 0, sizeof o);
    o.width = W;
    o.height = H;
    o.combined = out->comb;
    return vsgl_render(ctx, scene, &s, &o, NULL);
}

/* The fixture room seen from another place, lit by a moved spot plus a point light. */
static void other_view(fx_scene *fx)
{
    const float eye[3] = {0.6f, -2.5f, 1.4f}, at[3] = {-0.2f, 0.5f, 0.6f};
    fx_look_at(fx->camera.world_from_camera, eye, at);
    fx->lights[0].world_from_light[3] += 0.3f;
    fx->lights[1] = fx->lights[0];
    fx->lights[1].type = VSGL_LIGHT_POINT;
    fx->lights[1].power = 50.0f;
    fx_translation(fx->lights[1].world_from_light, 0.5f, 0.2f, 1.5f);
    fx->light_count = 2;
}

VT_TEST(scene_set_view_renders_as_a_new_scene)
{
    static img a, b, before, after;
    fx_scene fx;
    fx_room(&fx, W, H, 0.25f, 200.0f);
    vsgl_context *ctx = NULL;
    vsgl_scene *reused = NULL, *fresh = NULL;
    VT_CHECK(vsgl_context_create(NULL, &ctx) == VSGL_OK, "context");
    VT_CHECK(vsgl_scene_create(ctx, fx_desc(&fx), &reused) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(render(ctx, reused, &before) == VSGL_OK, "%s", vsgl_context_last_error(ctx));

    other_view(&fx);
    VT_CHECK(vsgl_scene_set_view(ctx, reused, &fx.camera, fx.lights, fx.light_count) == VSGL_OK, "%s",
             vsgl_context_last_error(ctx));
    VT_CHECK(vsgl_scene_create(ctx, fx_desc(&fx), &fresh) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(render(ctx, reused, &a) == VSGL_OK && render(ctx, fresh, &b) == VSGL_OK, "render");
    VT_CHECK(memcmp(&a, &b, sizeof a) == 0, "set_view differs from a scene built with the same view");
    VT_CHECK(memcmp(&a, &before, sizeof a) != 0, "the new view changed nothing (test cannot fail)");
    vsgl_scene_info info;
    VT_CHECK(vsgl_scene_get_info(reused, &info) == VSGL_OK && info.light_count == 2, "light count %u",
             info.light_count);

    /* a bad light: refused with its index named, the scene keeps its view */
    vsgl_light bad[2] = {fx.lights[0], fx.lights[1]};
    bad[1].power = NAN;
    VT_CHECK(vsgl_scene_set_view(ctx, reused, &fx.camera, bad, 2) == VSGL_ERROR_INVALID_ARGUMENT, "NaN power");
    VT_CHECK(strstr(vsgl_context_last_error(ctx), "light 1") != NULL, "message: %s", vsgl_context_last_error(ctx));
    VT_CHECK(vsgl_scene_set_view(ctx, reused, NULL, fx.lights, 1) == VSGL_ERROR_INVALID_ARGUMENT, "NULL camera");
    VT_CHECK(vsgl_scene_set_view(ctx, reused, &fx.camera, NULL, 1) == VSGL_ERROR_INVALID_ARGUMENT, "NULL lights");
    VT_CHECK(render(ctx, reused, &after) == VSGL_OK, "render after refusals");
    VT_CHECK(memcmp(&a, &after, sizeof a) == 0, "a refused view changed the scene");

    /* no lights: allowed, renders black */
    VT_CHECK(vsgl_scene_set_view(ctx, reused, &fx.camera, NULL, 0) == VSGL_OK, "%s", vsgl_context_last_error(ctx));
    VT_CHECK(render(ctx, reused, &after) == VSGL_OK, "render without lights");
    double sum = 0;
    for (size_t i = 0; i < sizeof after.comb / sizeof after.comb[0]; ++i)
        sum += after.comb[i];
    VT_CHECK(sum == 0.0, "no lights but light %g", sum);
    vsgl_scene_destroy(fresh);
    vsgl_scene_destroy(reused);
    vsgl_context_destroy(ctx);
}
