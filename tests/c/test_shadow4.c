/* vsgl__shadow_lanes (shade/shadow4.c) against vsgl__shadow_lane lane by
 * lane: a block's shadowing constants four lanes at a time, bit for bit,
 * over random normals, views and lobe axes (grazing, back-facing and past
 * the clamp), isotropic, anisotropic (negative) and zero alpha, NaN
 * fields, one- and two-lobe GGX, and every block length (the scalar tail). */
#include "harness.h"
#include "rand_dir.h"
#include "shade/kernel.h"

#include <math.h>
#include <string.h>

static void lane_fields(vsgl_kernel_block *b, size_t k, vt_rng *rng)
{
    v3 n = rand_dir(rng), o = rand_dir(rng), z = rand_dir(rng);
    int kind = (int)(vt_uniform(rng) * 8.0);
    if (kind == 0) /* grazing: n.o = 0 exactly */
        o = v3_make(-n.y, n.x, 0.0f);
    else if (kind == 1) /* past the clamp: n.o > 1 */
        o = v3_scale(n, 1.0f + urand(rng, 0.0f, 1e-3f));
    else if (kind == 2) /* below the clamp: n.z < 1e-4 */
        z = v3_dot(n, z) > 0.0f ? v3_neg(z) : z;
    b->nx[k] = n.x; b->ny[k] = n.y; b->nz[k] = n.z;
    b->ox[k] = o.x; b->oy[k] = o.y; b->oz[k] = o.z;
    b->Zx[k] = z.x; b->Zy[k] = z.y; b->Zz[k] = z.z;
    double u = vt_uniform(rng);
    b->alpha[k] = u < 0.1 ? 0.0f : u < 0.2 ? -urand(rng, 0.0f, 1.0f) : u < 0.25 ? -0.0f : urand(rng, 0.0f, 1.0f);
    if (vt_uniform(rng) < 0.02) /* a NaN normal takes the clamp in both forms */
        b->nx[k] = NAN;
}

VT_TEST(shade_shadow_lanes_equal_shadow_lane_bit_for_bit)
{
    static vsgl_kernel_block blk, ref;
    vt_rng rng = {4321};
    size_t lanes = 0, differ = 0;
    for (int round = 0; round < 400; ++round) {
        size_t n = (size_t)round % (VSGL__KERNEL_BLOCK + 1); /* every length, 0 to a full block */
        int two = round & 1;
        memset(&blk, 0, sizeof blk);
        for (size_t k = 0; k < VSGL__KERNEL_BLOCK; ++k)
            lane_fields(&blk, k, &rng);
        ref = blk;
        vsgl__shadow_lanes(&blk, n, two);
        for (size_t k = 0; k < n; ++k) {
            vsgl__kernel_set_smooth(&ref, k, vsgl__shadow_lane(fabsf(ref.alpha[k]),
                                                               ref.nx[k] * ref.ox[k] + ref.ny[k] * ref.oy[k] +
                                                                   ref.nz[k] * ref.oz[k],
                                                               ref.nx[k] * ref.Zx[k] + ref.ny[k] * ref.Zy[k] +
                                                                   ref.nz[k] * ref.Zz[k],
                                                               two));
            const float got[5] = {blk.ga2[k], blk.gso[k], blk.gco[k], blk.gia[k], blk.gw[k]};
            const float want[5] = {ref.ga2[k], ref.gso[k], ref.gco[k], ref.gia[k], ref.gw[k]};
            differ += memcmp(got, want, sizeof got) != 0;
            ++lanes;
        }
        /* lanes past n keep what they had */
        for (size_t k = n; k < VSGL__KERNEL_BLOCK; ++k)
            differ += blk.gia[k] != 0.0f || blk.gso[k] != 0.0f;
    }
    VT_CHECK(lanes > 10000, "lanes compared: %zu", lanes);
    VT_CHECK(differ == 0, "%zu of %zu lanes differ from vsgl__shadow_lane", differ, lanes);
}
