/* The texels a lookup must check the side of (see texel_sides.h). */
#include "texel_sides.h"

#include "raytrace/rt_sight.h"

#include <stdlib.h>
#include <string.h>

static int by_texel(const void *a, const void *b)
{
    uint32_t x = ((const lmb_texel_anchor *)a)->texel, y = ((const lmb_texel_anchor *)b)->texel;
    return x < y ? -1 : x > y;
}

lmb_status lmb_texel_sides_build(lmb_texel_sides *s, const lmb_texels *t, uint32_t w, uint32_t h, lmb_error *err)
{
    memset(s, 0, sizeof *s);
    uint32_t n = 0;
    for (uint32_t i = 0; i < t->count; i++)
        n += t->valid[i] && (t->edge[i] & LMB_EDGE_NEAR);
    s->near = calloc((size_t)w * h + 1, 1);
    s->anchors = malloc(((size_t)n + 1) * sizeof *s->anchors);
    if (!s->near || !s->anchors) {
        lmb_texel_sides_free(s);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "bounce cache: out of memory for %u texels beside walls", n);
    }
    for (uint32_t i = 0; i < t->count; i++) {
        if (!t->valid[i] || !(t->edge[i] & LMB_EDGE_NEAR))
            continue;
        lmb_gather_point g;
        lmb_texels_point(t, i, t->gather_at[i], &g);
        lmb_texel_anchor *a = &s->anchors[s->count++];
        a->texel = t->texel[i];
        a->lift = (float)(LMB_SIGHT_LIFT * t->texel_size[i]);
        for (int k = 0; k < 3; k++) {
            a->p[k] = g.p[k];
            a->ng[k] = g.ng[k];
        }
        s->near[t->texel[i]] = 1;
    }
    int sorted = 1;
    for (uint32_t k = 1; k < s->count; k++)
        sorted &= s->anchors[k].texel > s->anchors[k - 1].texel;
    if (!sorted)
        qsort(s->anchors, s->count, sizeof *s->anchors, by_texel);
    return LMB_OK;
}

void lmb_texel_sides_free(lmb_texel_sides *s)
{
    free(s->near);
    free(s->anchors);
    memset(s, 0, sizeof *s);
}

int lmb_texel_sides_in_sight(const lmb_texel_sides *s, const lmb_rt *rt, uint32_t texel, const double p[3],
                             const float ng[3])
{
    if (!s->near || !s->near[texel])
        return 1;
    uint32_t lo = 0, hi = s->count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (s->anchors[mid].texel < texel)
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo >= s->count || s->anchors[lo].texel != texel)
        return 1;
    const lmb_texel_anchor *a = &s->anchors[lo];
    double n[3] = {ng[0], ng[1], ng[2]};
    return lmb_rt_in_sight(rt, p, n, a->p, a->ng, a->lift);
}
