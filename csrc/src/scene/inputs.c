/* Material inputs at a surface point: the material's constants times its
 * textures (filtered over the asker's footprint) and corner colours. */
#include "scene/scene_data.h"

#include <math.h>
#include <string.h>

int vsgl__scene_textured(const vsgl_scene *scene)
{
    return scene->textured;
}

static float clamp01(float x) { return x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f; }

/* RGBA of a used slot at barycentrics (w, u, v) of triangle tri. */
static void slot_lookup(const vsgl_scene *s, const vsgl_texture_slot *slot, uint32_t tri, float w, float u, float v,
                        float area, float out[4])
{
    const vsgl_tex *t = &s->textures[slot->texture - 1];
    float tu = 0.0f, tv = 0.0f;
    if (s->corner_uvs) {
        const float *uv = s->corner_uvs + (size_t)tri * 6;
        tu = w * uv[0] + u * uv[2] + v * uv[4];
        tv = w * uv[1] + u * uv[3] + v * uv[5];
    }
    const float *m = slot->uv_transform;
    float det = 1.0f;
    if (m[0] != 0.0f || m[1] != 0.0f || m[2] != 0.0f || m[3] != 0.0f || m[4] != 0.0f || m[5] != 0.0f) {
        float a = m[0] * tu + m[1] * tv + m[2], b = m[3] * tu + m[4] * tv + m[5];
        tu = a;
        tv = b;
        det = fabsf(m[0] * m[4] - m[1] * m[3]);
    }
    /* footprint in level-0 texels: area x (uv area / world area) x texels per uv area */
    double texels = (double)area * (double)s->uv_density[tri] * det * (double)t->lv[0].w * (double)t->lv[0].h;
    float lod = texels > 1.0 ? (float)(0.5 * log2(texels)) : 0.0f;
    vsgl__texture_lookup(t, tu, tv, lod, slot->filter, slot->wrap, out);
}

void vsgl__scene_inputs(const vsgl_scene *s, const vsgl_hit *hit, float area, float out[VSGL__SURF_N])
{
    uint32_t tri = hit->triangle;
    uint32_t mat = s->tri_material[tri];
    const vsgl_material *m = &s->materials[mat];
    for (int c = 0; c < 3; ++c)
        out[VSGL__SURF_BASE + c] = m->base_color[c];
    out[VSGL__SURF_ROUGHNESS] = m->roughness;
    out[VSGL__SURF_METALLIC] = m->metallic;
    if (!s->material_textures)
        return;
    const vsgl_material_textures *mt = &s->material_textures[mat];
    float u = hit->u, v = hit->v, w = 1.0f - u - v;
    if (!(area >= 0.0f) || !(area < INFINITY))
        area = 0.0f;
    float px[4];
    if (mt->base_color.texture) {
        slot_lookup(s, &mt->base_color, tri, w, u, v, area, px);
        for (int c = 0; c < 3; ++c)
            out[VSGL__SURF_BASE + c] *= px[c];
    }
    if ((mt->flags & VSGL_MATERIAL_TEXTURES_VERTEX_COLOR) && s->corner_colors) {
        const float *cc = s->corner_colors + (size_t)tri * 9;
        for (int c = 0; c < 3; ++c)
            out[VSGL__SURF_BASE + c] *= w * cc[c] + u * cc[3 + c] + v * cc[6 + c];
    }
    if (mt->roughness.texture) {
        slot_lookup(s, &mt->roughness, tri, w, u, v, area, px);
        out[VSGL__SURF_ROUGHNESS] *= px[mt->roughness.channel];
    }
    if (mt->metallic.texture) {
        slot_lookup(s, &mt->metallic, tri, w, u, v, area, px);
        out[VSGL__SURF_METALLIC] *= px[mt->metallic.channel];
    }
    for (int k = 0; k < VSGL__SURF_N; ++k)
        out[k] = clamp01(out[k]);
}

void vsgl__material_with_inputs(const vsgl_material *m, const float in[VSGL__SURF_N], vsgl_material *out)
{
    *out = *m;
    for (int c = 0; c < 3; ++c)
        out->base_color[c] = in[VSGL__SURF_BASE + c];
    out->roughness = in[VSGL__SURF_ROUGHNESS];
    out->metallic = in[VSGL__SURF_METALLIC];
}
