/* The per-light budget (budget.h): VSGLs and RSM texels follow the light
 * each light reflects into the scene. */
#include "render/budget.h"
#include "vsgl/render.h"

#include <math.h>

static int contributes(const vsgl_light_share *l)
{
    return l->weight > 0.0 && l->weight < INFINITY;
}

uint32_t vsgl__budget_rsm_max(uint32_t rsm)
{
    double r = ceil(VSGL__BUDGET_RSM_CAP * (double)rsm);
    return r > VSGL_RSM_RESOLUTION_MAX ? VSGL_RSM_RESOLUTION_MAX : (uint32_t)r;
}

uint32_t vsgl__budget_vsgl_max(uint32_t n_vsgl)
{
    double n = ceil(VSGL__BUDGET_VSGL_CAP * (double)n_vsgl);
    return n > VSGL_VSGL_COUNT_MAX ? VSGL_VSGL_COUNT_MAX : (uint32_t)n;
}

/* A light's footprint as the texel split uses it: (0, 1], 1 when unknown. */
static double footprint_of(const vsgl_light_share *l)
{
    return l->footprint > 0.0 && l->footprint <= 1.0 ? l->footprint : 1.0;
}

static uint32_t clamp_side(double side, uint32_t lo, uint32_t hi)
{
    if (!(side >= (double)lo))
        return lo;
    if (side >= (double)hi)
        return hi;
    return (uint32_t)lround(side);
}

void vsgl__light_budget(vsgl_light_share *lights, uint32_t count, uint32_t n_vsgl, uint32_t rsm)
{
    const double n = (double)n_vsgl, floor_n = VSGL__BUDGET_FLOOR * n;
    const double cap = (double)vsgl__budget_vsgl_max(n_vsgl);
    uint32_t k = 0;
    double sum = 0.0;
    for (uint32_t i = 0; i < count; ++i) {
        lights[i].fraction = contributes(&lights[i]) ? pow(lights[i].weight, VSGL__BUDGET_POWER) : 0.0;
        lights[i].vsgls = 0.0;
        if (lights[i].fraction > 0.0 && lights[i].fraction < INFINITY) {
            sum += lights[i].fraction;
            ++k;
        } else {
            lights[i].fraction = 0.0;
        }
    }
    for (uint32_t i = 0; i < count; ++i)
        lights[i].fraction = sum > 0.0 && sum < INFINITY ? lights[i].fraction / sum : 0.0;

    uint32_t lo = rsm / 4 > VSGL_RSM_RESOLUTION_MIN ? rsm / 4 : VSGL_RSM_RESOLUTION_MIN;
    uint32_t hi = vsgl__budget_rsm_max(rsm);
    if (k <= 1 || !(sum > 0.0 && sum < INFINITY)) { /* nothing to share: the settings as they are */
        for (uint32_t i = 0; i < count; ++i) {
            int one = k == 1 && lights[i].fraction > 0.0;
            lights[i].vsgls = one ? n : floor_n;
            lights[i].vsgl_count = one ? n_vsgl : (uint32_t)ceil(floor_n);
            lights[i].rsm_resolution = one ? rsm : (rsm / 2 > lo ? rsm / 2 : lo);
            if (lights[i].vsgl_count < 1)
                lights[i].vsgl_count = 1;
        }
        return;
    }

    /* The floor for each, the rest by share; what a cap cuts goes to the
     * uncapped lights by their shares (at most k rounds). */
    double spend = (n - floor_n) * (double)k;
    for (uint32_t round = 0; round < k && spend > 1e-9 * n; ++round) {
        double open = 0.0;
        for (uint32_t i = 0; i < count; ++i)
            if (lights[i].fraction > 0.0 && floor_n + lights[i].vsgls < cap)
                open += lights[i].fraction;
        if (!(open > 0.0))
            break;
        double left = 0.0;
        for (uint32_t i = 0; i < count; ++i) {
            if (!(lights[i].fraction > 0.0) || !(floor_n + lights[i].vsgls < cap))
                continue;
            double v = lights[i].vsgls + spend * lights[i].fraction / open;
            if (floor_n + v > cap) {
                left += floor_n + v - cap;
                v = cap - floor_n;
            }
            lights[i].vsgls = v;
        }
        spend = left;
    }
    double texels = 0.0, weighted = 0.0;
    for (uint32_t i = 0; i < count; ++i) {
        if (!(lights[i].fraction > 0.0))
            continue;
        lights[i].vsgls += floor_n;
        texels += (double)lights[i].faces * (double)rsm * (double)rsm;
        weighted += (double)lights[i].faces * lights[i].vsgls / footprint_of(&lights[i]);
    }

    /* Integer counts by largest remainder, so that they sum as the reals;
     * ties go to the lower index. */
    uint32_t total = 0, target = 0;
    double real_total = 0.0;
    for (uint32_t i = 0; i < count; ++i)
        if (lights[i].fraction > 0.0) {
            lights[i].vsgl_count = (uint32_t)floor(lights[i].vsgls);
            total += lights[i].vsgl_count;
            real_total += lights[i].vsgls;
        }
    target = (uint32_t)lround(real_total);
    while (total < target) {
        uint32_t best = count;
        double best_rem = -1.0;
        for (uint32_t i = 0; i < count; ++i) {
            if (!(lights[i].fraction > 0.0))
                continue;
            double rem = lights[i].vsgls - (double)lights[i].vsgl_count;
            if (rem > best_rem) {
                best_rem = rem;
                best = i;
            }
        }
        if (best == count)
            break;
        ++lights[best].vsgl_count;
        ++total;
    }
    double per = weighted > 0.0 ? texels / weighted : 0.0; /* texels per VSGL on a footprint */
    for (uint32_t i = 0; i < count; ++i) {
        if (lights[i].fraction > 0.0) {
            if (lights[i].vsgl_count < 1)
                lights[i].vsgl_count = 1;
            lights[i].rsm_resolution = clamp_side(sqrt(per * lights[i].vsgls / footprint_of(&lights[i])), lo, hi);
        } else { /* the probe saw nothing */
            lights[i].vsgls = floor_n;
            lights[i].vsgl_count = floor_n >= 1.0 ? (uint32_t)ceil(floor_n) : 1u;
            lights[i].rsm_resolution = rsm / 2 > lo ? rsm / 2 : lo;
        }
    }
}

void vsgl__footprint_rsm(vsgl_light_share *lights, uint32_t count, double texels_per_vsgl, uint32_t rsm,
                         uint32_t hi)
{
    uint32_t lo = rsm / 4 > VSGL_RSM_RESOLUTION_MIN ? rsm / 4 : VSGL_RSM_RESOLUTION_MIN;
    if (hi < lo)
        hi = lo;
    for (uint32_t i = 0; i < count; ++i) {
        double f = lights[i].footprint, v = lights[i].vsgls;
        if (!contributes(&lights[i]) || !(f > 0.0 && f <= 1.0) || !(v > 0.0 && v < INFINITY) ||
            !(texels_per_vsgl > 0.0 && texels_per_vsgl < INFINITY))
            continue;
        lights[i].rsm_resolution = clamp_side(sqrt(texels_per_vsgl * v / f), lo, hi);
    }
}
