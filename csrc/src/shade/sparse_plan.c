/* Shading plans (shade_job.h): allocation, release, whether one fits a
 * G-buffer and settings, whether a record filled it. */

#include "shade/sparse.h"

#include <stdlib.h>

void vsgl__shade_plan_free(vsgl_shade_plan *p)
{
    if (!p)
        return;
    free(p->row_ok);
    free(p->dlane_of);
    free(p->dlanes);
    free(p->anchor_sample);
    free(p->anchor_lane);
    free(p->w4);
    free(p->direct);
    free(p->cd);
    free(p->colour);
    free(p->cell_x);
    free(p->cell_y);
    free(p->cell_tx);
    free(p->cell_ty);
    free(p->d2_ok);
    free(p->geo);
    free(p->pack);
    free(p->interp);
    free(p->blend);
    free(p->direct_of);
    free(p->marks);
    free(p);
}

/* The anchor cell of slot k of column x (or row y): as sample_cell. */
static void cell_table(uint32_t n, size_t spp, uint32_t aa, uint32_t stride, uint32_t *cell, float *t, int rows)
{
    const float inv_aa = 1.0f / (float)aa;
    for (uint32_t x = 0; x < n; ++x)
        for (size_t k = 0; k < spp; ++k) {
            float ox, oy;
            sparse_slot_offset(k, aa, inv_aa, &ox, &oy);
            sparse_axis_cell(x, rows ? oy : ox, stride, n, &cell[(size_t)x * spp + k], &t[(size_t)x * spp + k]);
        }
}

vsgl_shade_plan *vsgl__shade_plan_new(const vsgl_gbuffer *g, const vsgl_render_settings *s, uint32_t aw, uint32_t ah)
{
    vsgl_shade_plan *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    size_t na = (size_t)aw * ah, pixels = (size_t)g->width * g->height;
    p->stride = s->shade_stride;
    p->glossy_mode = (uint32_t)s->glossy_mode;
    p->width = g->width;
    p->height = g->height;
    p->aw = aw;
    p->ah = ah;
    p->spp = g->spp;
    p->count = g->count;
    p->anchor_sample = malloc((na + 1) * sizeof *p->anchor_sample);
    p->anchor_lane = malloc((na + 1) * sizeof *p->anchor_lane);
    p->w4 = malloc((g->count + 1) * 4 * sizeof *p->w4);
    p->direct = malloc((g->count + 1) * sizeof *p->direct);
    p->cd = malloc((g->count + 1) * 4 * sizeof *p->cd);
    p->colour = malloc((pixels + 1) * 7 * sizeof *p->colour);
    p->row_ok = calloc((size_t)g->height + 2, 1);
    p->dlane_of = malloc((g->count + 1) * sizeof *p->dlane_of);
    p->cell_x = malloc(((size_t)g->width * g->spp + 1) * sizeof *p->cell_x);
    p->cell_tx = malloc(((size_t)g->width * g->spp + 1) * sizeof *p->cell_tx);
    p->cell_y = malloc(((size_t)g->height * g->spp + 1) * sizeof *p->cell_y);
    p->cell_ty = malloc(((size_t)g->height * g->spp + 1) * sizeof *p->cell_ty);
    p->d2_ok = calloc(na + 1, 1);
    p->pack = malloc((na + 1) * 12 * sizeof *p->pack);
    p->geo = malloc((na + 1) * 8 * sizeof *p->geo);
    if (!p->anchor_sample || !p->anchor_lane || !p->w4 || !p->direct || !p->cd || !p->colour || !p->row_ok ||
        !p->dlane_of || !p->cell_x || !p->cell_tx || !p->cell_y || !p->cell_ty || !p->d2_ok || !p->pack || !p->geo) {
        vsgl__shade_plan_free(p);
        return NULL;
    }
    cell_table(g->width, g->spp, g->aa, p->stride, p->cell_x, p->cell_tx, 0);
    cell_table(g->height, g->spp, g->aa, p->stride, p->cell_y, p->cell_ty, 1);
    return p;
}

int vsgl__shade_plan_matches(const vsgl_shade_plan *p, const vsgl_gbuffer *g, const vsgl_render_settings *s,
                             uint32_t aw, uint32_t ah)
{
    return p && p->stride == s->shade_stride && p->glossy_mode == (uint32_t)s->glossy_mode &&
           p->width == g->width && p->height == g->height && p->spp == g->spp && p->count == g->count &&
           p->aw == aw && p->ah == ah;
}

int vsgl__shade_plan_complete(const vsgl_shade_plan *p)
{
    for (size_t y = 0; y <= (size_t)p->height; ++y)
        if (!p->row_ok[y])
            return 0;
    return 1;
}
