/* Broad receiver lobes: the tables' lookup (math/broad_lobe.h). */
#include "math/broad_lobe.h"
#include "math/sg_internal.h"
#include "math/warp_lanes.h"
#include "vsgl/lobes.h"

/* bilinear in (row y, column x) of one table */
static void lookup(const vsgl_broad_table *t, int j, int k, float fy, float fx, float *scale, float *amplitude)
{
    const float *a = t->amplitude[j], *b = t->amplitude[j + 1];
    *scale = t->scale[j] + fy * (t->scale[j + 1] - t->scale[j]);
    *amplitude = (1.0f - fy) * ((1.0f - fx) * a[k] + fx * a[k + 1]) + fy * ((1.0f - fx) * b[k] + fx * b[k + 1]);
}

void vsgl__broad_lobe(float alpha, float f0, float cos_o, int two, float *scale, float *amplitude)
{
    float r = sqrtf(alpha > 0.0f ? alpha : 0.0f);
    if (!(r > VSGL__BROAD_R0)) { /* also a NaN */
        *scale = *amplitude = 1.0f;
        return;
    }
    float y = (r - VSGL__BROAD_R0) / (1.0f - VSGL__BROAD_R0) * (VSGL__BROAD_ROWS - 1);
    y = y < (float)(VSGL__BROAD_ROWS - 1) ? y : (float)(VSGL__BROAD_ROWS - 1);
    float u0 = sqrtf(VSGL__BROAD_C0), c = cos_o < VSGL__BROAD_C0 ? VSGL__BROAD_C0 : (cos_o < 1.0f ? cos_o : 1.0f);
    float x = (sqrtf(c) - u0) / (1.0f - u0) * (VSGL__BROAD_COLS - 1);
    int j = (int)y, k = (int)x;
    j = j < VSGL__BROAD_ROWS - 2 ? j : VSGL__BROAD_ROWS - 2;
    k = k < VSGL__BROAD_COLS - 2 ? k : VSGL__BROAD_COLS - 2;
    float fy = y - (float)j, fx = x - (float)k;
    float d = (1.0f - f0) / (1.0f - VSGL__BROAD_DIELECTRIC_F0);
    d = d > 0.0f ? (d < 1.0f ? d : 1.0f) : 0.0f; /* also a NaN f0 */
    float sc, sd, ac, ad;
    const vsgl_broad_table *t = vsgl__broad_tables[two ? 0 : 1];
    lookup(&t[0], j, k, fy, fx, &sc, &ac);
    lookup(&t[1], j, k, fy, fx, &sd, &ad);
    *scale = sc + d * (sd - sc);
    *amplitude = ac + d * (ad - ac);
}

void vsgl__receiver_asg_finish(v3 n, v3 o, float scale, float amplitude, vsgl_asg *a)
{
    if (scale != 1.0f) {
        a->lambda *= scale;
        a->mu *= scale;
    }
    vsgl__asg_cut_at_horizon(a, &n, &o);
    if (amplitude != 1.0f) /* no logf for the sharp lobes, most receivers */
        a->log_amplitude += logf(amplitude);
}

void vsgl__receiver_asg(v3 n, v3 t, v3 o, float alpha_x, float alpha_y, float scale, float amplitude,
                        vsgl_asg *out)
{
    vsgl_warp_lanes w;
    vsgl__warp_lane_set(&w, 0, n, t, o, alpha_x, alpha_y);
    vsgl__warp_lanes(&w, 1);
    vsgl__warp_lane_get(&w, 0, out);
    vsgl__receiver_asg_finish(n, o, scale, amplitude, out);
}
