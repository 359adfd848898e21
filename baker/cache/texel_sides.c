/* The texels a lookup must check the side of (see texel_sides.h). */
#include "texel_sides.h"

#include "raytrace/rt_sight.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* The planes of the nearest faces beside texel i's gather point (lmb_rt_sides: lifted as a sight
 * test lifts, 1.0824 x LMB_BESIDE_TEXELS texels long, as texel_direct.c looked). */
static void texel_planes(const lmb_texels *t, uint32_t i, const lmb_rt *rt, lmb_texel_anchor *a)
{
    lmb_gather_point g;
    lmb_texels_point(t, i, t->gather_at[i], &g);
    double ng[3] = {g.ng[0], g.ng[1], g.ng[2]}, size = t->texel_size[i];
    lmb_rt_side side[LMB_SIDE_PLANES];
    a->planes = lmb_rt_sides(rt, g.p, ng, LMB_SIGHT_LIFT * size, 1.0824 * LMB_BESIDE_TEXELS * size, side, LMB_SIDE_PLANES);
    for (uint32_t q = 0; q < a->planes; q++) {
        for (int k = 0; k < 3; k++)
            a->plane[q].m[k] = (float)side[q].m[k];
        a->plane[q].d = (float)side[q].d;
    }
}

static int by_texel(const void *a, const void *b)
{
    uint32_t x = ((const lmb_texel_anchor *)a)->texel, y = ((const lmb_texel_anchor *)b)->texel;
    return x < y ? -1 : x > y;
}

lmb_status lmb_texel_sides_build(lmb_texel_sides *s, const lmb_texels *t, const lmb_rt *rt, uint32_t w, uint32_t h,
                                 int threads, lmb_error *err)
{
    memset(s, 0, sizeof *s);
    uint32_t n = 0;
    for (uint32_t i = 0; i < t->count; i++)
        n += t->valid[i] && (t->edge[i] & LMB_EDGE_NEAR);
    s->near = calloc(((size_t)w * h + 63) / 64 + 1, sizeof *s->near);
    s->anchors = malloc(((size_t)n + 1) * sizeof *s->anchors);
    uint32_t *list = malloc(((size_t)n + 1) * sizeof *list);
    if (!s->near || !s->anchors || !list) {
        free(list);
        lmb_texel_sides_free(s);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "bounce cache: out of memory for %u texels beside walls", n);
    }
    for (uint32_t i = 0; i < t->count; i++)
        if (t->valid[i] && (t->edge[i] & LMB_EDGE_NEAR))
            list[s->count++] = i;
    int64_t count = s->count;
#pragma omp parallel num_threads(threads > 0 ? threads : omp_get_max_threads())
    {
        lmb_rt_thread_init();
#pragma omp for schedule(dynamic, 256)
        for (int64_t k = 0; k < count; k++) {
            s->anchors[k].texel = t->texel[list[k]];
            texel_planes(t, list[k], rt, &s->anchors[k]);
        }
    }
    free(list);
    int sorted = 1;
    for (uint32_t k = 1; k < s->count; k++)
        sorted &= s->anchors[k].texel > s->anchors[k - 1].texel;
    if (!sorted)
        qsort(s->anchors, s->count, sizeof *s->anchors, by_texel);
    /* only anchors with a plane are kept (a texel whose tangent rays met nothing now needs no test) */
    uint32_t kept = 0;
    for (uint32_t k = 0; k < s->count; k++)
        if (s->anchors[k].planes > 0) {
            s->anchors[kept++] = s->anchors[k];
            s->near[s->anchors[k].texel >> 6] |= 1ull << (s->anchors[k].texel & 63);
        }
    s->count = kept;
    size_t words = ((size_t)w * h + 63) / 64;
    s->rank = malloc((words + 1) * sizeof *s->rank);
    if (!s->rank) {
        lmb_texel_sides_free(s);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "bounce cache: out of memory for %u texels beside walls", n);
    }
    uint32_t before = 0;
    for (size_t k = 0; k < words; k++) {
        s->rank[k] = before;
        before += (uint32_t)__builtin_popcountll(s->near[k]);
    }
    return LMB_OK;
}

void lmb_texel_sides_free(lmb_texel_sides *s)
{
    free(s->near);
    free(s->rank);
    free(s->anchors);
    memset(s, 0, sizeof *s);
}

int lmb_texel_sides_in_sight(const lmb_texel_sides *s, uint32_t texel, const double p[3])
{
    if (!lmb_texel_sides_near(s, texel))
        return 1;
    uint64_t below = s->near[texel >> 6] & ((1ull << (texel & 63)) - 1);
    uint32_t lo = s->rank[texel >> 6] + (uint32_t)__builtin_popcountll(below);
    const lmb_texel_anchor *a = &s->anchors[lo];
    for (uint32_t q = 0; q < a->planes; q++) {
        const lmb_side_plane *pl = &a->plane[q];
        if (pl->m[0] * p[0] + pl->m[1] * p[1] + pl->m[2] * p[2] < pl->d)
            return 0;
    }
    return 1;
}
