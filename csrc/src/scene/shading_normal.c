/* The shading normal of a camera sample (scene_internal.h
 * vsgl__valid_reflection_normal).
 *
 * In the frame z = ng, x = the part of n orthogonal to ng, the wanted
 * normal is m = (sqrt(1 - u), 0, sqrt(u)) with u = m.z^2, and the height of
 * the reflection r = 2 (m.i) m - i above the face is
 *     r.z = 2 (m.x ix + m.z iz) m.z - iz = t.
 * Moving iz to the right and squaring,
 *     4 u (1 - u) ix^2 = (t + iz - 2 u iz)^2,
 * a quadratic in u,
 *     a u^2 - c u + (t + iz)^2 / 4 = 0,  a = ix^2 + iz^2,  c = a + t iz,
 * whose roots are u = (c +- b) / (2 a), with
 *     b^2 = c^2 - a (t + iz)^2 = ix^2 (a - t^2).
 * Squaring admits roots where m.x ix has the other sign; of the roots that
 * are normals (0 < u <= 1) and reflect upwards, the one with the lower
 * reflection is the smaller turn away from n; Cycles' choice, and its
 * fallbacks (the higher reflection if none rises, ng if no root is a
 * normal). */
#include "scene/scene_internal.h"

#include <math.h>

v3 vsgl__valid_reflection_normal(v3 ng, v3 i, v3 n)
{
    const float iz = v3_dot(ng, i);
    const float t = fminf(0.9f * iz, 0.01f);
    if (v3_dot(ng, v3_reflect(i, n)) >= t)
        return n;
    v3 x = v3_sub(n, v3_scale(ng, v3_dot(n, ng)));
    const float xl = v3_length(x);
    if (!(xl > 1e-12f))
        return ng; /* n along -ng: no plane to turn in */
    x = v3_scale(x, 1.0f / xl);
    const float ix = v3_dot(i, x);
    const float a = ix * ix + iz * iz;
    if (!(a > 0.0f))
        return ng;
    const float b = sqrtf(fmaxf(ix * ix * (a - t * t), 0.0f)), c = a + t * iz;
    const float u[2] = {(c + b) / (2.0f * a), (c - b) / (2.0f * a)};
    /* of the normals (0 < u <= 1): the lowest reflection that rises, else
     * the highest */
    int found = 0, up = 0;
    float best = 0.0f, mx = 0.0f, mz = 1.0f;
    for (int k = 0; k < 2; ++k) {
        if (!(u[k] > 1e-5f && u[k] <= 1.0f + 1e-5f))
            continue;
        const float z = sqrtf(fminf(u[k], 1.0f)), xx = sqrtf(fmaxf(1.0f - u[k], 0.0f));
        const float h = 2.0f * (xx * ix + z * iz) * z - iz; /* the reflection's height */
        const int rises = h >= 1e-5f;
        if (!found || (rises && (!up || h < best)) || (!rises && !up && h > best)) {
            found = 1, up = rises, best = h, mx = xx, mz = z;
        }
    }
    if (!found)
        return ng;
    return v3_normalize(v3_add(v3_scale(x, mx), v3_scale(ng, mz)));
}

void vsgl__surface_valid_reflection(vsgl_surface *sf, v3 i)
{
    v3 n = vsgl__valid_reflection_normal(sf->geometric_normal, i, sf->normal), t = sf->tangent;
    if (n.x == sf->normal.x && n.y == sf->normal.y && n.z == sf->normal.z)
        return;
    v3 tt = v3_sub(t, v3_scale(n, v3_dot(t, n)));
    float l = v3_length(tt);
    if (l > 1e-6f)
        t = v3_scale(tt, 1.0f / l);
    else
        v3_basis(n, &t, &tt);
    sf->normal = n;
    sf->tangent = t;
}
