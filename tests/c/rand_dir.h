/* Test helpers: uniform floats and uniformly distributed unit vectors
 * (rejection sampling in the unit ball) from the harness's generator. */
#ifndef VSGL_TEST_RAND_DIR_H
#define VSGL_TEST_RAND_DIR_H

#include "harness.h"
#include "math/vec.h"

static inline float urand(vt_rng *r, float lo, float hi)
{
    return lo + (hi - lo) * (float)vt_uniform(r);
}

static inline v3 rand_dir(vt_rng *r)
{
    for (;;) {
        v3 d = v3_make(urand(r, -1, 1), urand(r, -1, 1), urand(r, -1, 1));
        float l = v3_length(d);
        if (l > 0.1f && l <= 1.0f)
            return v3_scale(d, 1.0f / l);
    }
}

#endif
