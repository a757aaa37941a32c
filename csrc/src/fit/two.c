/* Two VSGLs per light (Tokuyoshi 2015 poster): one diffuse and one specular
 * VSGL from all texels of the light's RSM. */
#include "fit/vsgl_set.h"
#include "core/context.h"
#include "core/parallel.h"

#include <stdlib.h>
#include <string.h>

typedef struct sum_job {
    const vsgl_scene *scene;
    const vsgl_rsm *rsm;
    v3 origin;
    int32_t estimator;
    vsgl_moments *partial; /* 2 per chunk */
} sum_job;

static int32_t sum_chunk(void *user, size_t chunk, size_t b, size_t e)
{
    sum_job *j = user;
    vsgl_moments acc[2], m[2];
    memset(acc, 0, sizeof acc);
    for (size_t t = b; t < e; ++t)
        if (vsgl__vpl_moments(j->scene, j->rsm, t, j->origin, j->estimator, m)) {
            vsgl__moments_add(&acc[0], &m[0], 1.0);
            vsgl__moments_add(&acc[1], &m[1], 1.0);
        }
    j->partial[2 * chunk] = acc[0];
    j->partial[2 * chunk + 1] = acc[1];
    return 0;
}

vsgl_result vsgl__fit_two(vsgl_context *ctx, const vsgl_scene *scene, const vsgl_rsm *rsm,
                          const vsgl_render_settings *s, vsgl_vsgl_set *out)
{
    enum { CHUNK = 4096 };
    size_t chunks = vsgl__chunk_count(rsm->count, CHUNK);
    sum_job j = {scene, rsm, vsgl__rsm_origin(rsm), s->sharpness_estimator, NULL};
    j.partial = calloc(chunks * 2 + 2, sizeof *j.partial);
    if (!j.partial)
        return vsgl__fail(ctx, VSGL_ERROR_OUT_OF_MEMORY, "fit: out of memory for %zu chunks", chunks);
    vsgl__parallel_for(vsgl_context_thread_count(ctx), rsm->count, CHUNK, sum_chunk, &j);
    vsgl_moments total[2];
    memset(total, 0, sizeof total);
    for (size_t c = 0; c < chunks; ++c) {  /* fixed order: deterministic */
        vsgl__moments_add(&total[0], &j.partial[2 * c], 1.0);
        vsgl__moments_add(&total[1], &j.partial[2 * c + 1], 1.0);
    }
    free(j.partial);
    vsgl_result r = VSGL_OK;
    for (uint32_t lobe = 0; lobe < 2 && r == VSGL_OK; ++lobe) {
        vsgl_vsgl v;
        if (vsgl__moments_to_vsgl(&total[lobe], j.origin, s->sharpness_estimator, rsm->light, lobe, &v))
            r = vsgl__vsgl_set_push(out, &v);
    }
    if (r != VSGL_OK)
        return vsgl__fail(ctx, r, "fit: out of memory");
    return VSGL_OK;
}
