/* Pilot texels and their lookup for guided per-texel gathering (see guide.h). */
#include "guide.h"

#include <stdlib.h>
#include <string.h>


void lmb_guide_free(lmb_guide *g)
{
    free(g->cell);
    free(g->pilot_of);
    free(g->pilots);
    memset(g, 0, sizeof *g);
}

int lmb_guide_init(lmb_guide *g, const lmb_texels *t, uint32_t stride)
{
    memset(g, 0, sizeof *g);
    g->stride = stride;
    g->cols = t->width / stride + 1;
    g->rows = t->height / stride + 1;
    g->cell = malloc((size_t)g->cols * g->rows * sizeof *g->cell);
    g->pilot_of = malloc(((size_t)t->count + 1) * sizeof *g->pilot_of);
    if (!g->cell || !g->pilot_of) {
        lmb_guide_free(g);
        return 0;
    }
    for (size_t c = 0; c < (size_t)g->cols * g->rows; c++)
        g->cell[c] = -1;
    for (uint32_t i = 0; i < t->count; i++) {
        uint32_t x = t->texel[i] % t->width, y = t->texel[i] / t->width;
        g->pilot_of[i] = UINT32_MAX;
        if (t->valid[i] && x % stride == 0 && y % stride == 0) {
            g->cell[(size_t)(y / stride) * g->cols + x / stride] = (int32_t)i;
            g->pilot_of[i] = g->pilot_count++;
        }
    }
    g->pilots = calloc(g->pilot_count + 1, sizeof *g->pilots);
    if (!g->pilots) {
        lmb_guide_free(g);
        return 0;
    }
    return 1;
}

int lmb_guide_find(const lmb_guide *g, const lmb_texels *t, uint32_t i, const double p[3], const double n[3],
                   lmb_mixture *out)
{
    uint32_t x = t->texel[i] % t->width, y = t->texel[i] / t->width;
    uint32_t cx = x / g->stride, cy = y / g->stride;
    const lmb_guide_pilot *best = NULL;
    double best_d2 = 0;
    for (uint32_t k = 0; k < 4; k++) {
        uint32_t gx = cx + (k & 1), gy = cy + (k >> 1);
        if (gx >= g->cols || gy >= g->rows)
            continue;
        int32_t c = g->cell[(size_t)gy * g->cols + gx];
        if (c < 0)
            continue;
        const lmb_guide_pilot *pl = &g->pilots[g->pilot_of[c]];
        if (!lmb_mixture_learned(&pl->mixture) || lmb_dot3(pl->n, n) < LMB_GUIDE_SAME_SURFACE_COS)
            continue;
        double d[3] = {pl->p[0] - p[0], pl->p[1] - p[1], pl->p[2] - p[2]}, d2 = lmb_dot3(d, d);
        if (d2 > (double)pl->reach * pl->reach || (best && d2 >= best_d2))
            continue;
        best = pl;
        best_d2 = d2;
    }
    if (!best)
        return 0;
    lmb_mixture_reaim(&best->mixture, best->p, p, out);
    return 1;
}
