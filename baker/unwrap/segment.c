/*
 * Chart segmentation by greedy growth (in the spirit of xatlas / Levy et al. 2002's
 * "feature-based" charts, much simplified): seeds are taken largest triangle first; a
 * chart grows across manifold edges, cheapest candidate first, where
 *   cost = (1 - n_f . N)  +  0.5 * |centroid_f - C| / sqrt(A)
 * (N, C, A: the chart's area-weighted mean normal, centroid and area), so coplanar
 * regions fill before curved ones and charts grow round rather than in strands. A face
 * joins only if its normal is within max_angle of N at the moment it is taken.
 *
 * A chart whose faces all share its seed's plane also grows across the topology's coplanar
 * links (seams between coplanar triangles of a soup, topology.c); once it has, it takes only
 * faces of that plane, so it stays a projection (flatten.c) and never needs LSCM, which
 * could not join the two sides of a seam.
 */
#include "unwrap_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct entry {
    double cost;
    uint32_t face, via_link; /* via_link: reached only across a coplanar link */
} entry;

typedef struct heap {
    entry *e;
    uint32_t n, cap;
} heap;

static int before(const entry *a, const entry *b)
{
    return a->cost < b->cost || (a->cost == b->cost && a->face < b->face);
}

static int heap_push(heap *h, entry x)
{
    if (h->n == h->cap) {
        uint32_t cap = h->cap ? 2 * h->cap : 256;
        entry *e = realloc(h->e, cap * sizeof *e);
        if (!e)
            return 0;
        h->e = e;
        h->cap = cap;
    }
    uint32_t i = h->n++;
    while (i > 0 && before(&x, &h->e[(i - 1) / 2])) {
        h->e[i] = h->e[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    h->e[i] = x;
    return 1;
}

static entry heap_pop(heap *h)
{
    entry top = h->e[0], last = h->e[--h->n];
    uint32_t i = 0;
    for (;;) {
        uint32_t c = 2 * i + 1;
        if (c >= h->n)
            break;
        if (c + 1 < h->n && before(&h->e[c + 1], &h->e[c]))
            c++;
        if (!before(&h->e[c], &last))
            break;
        h->e[i] = h->e[c];
        i = c;
    }
    if (h->n)
        h->e[i] = last;
    return top;
}

typedef struct chart_state {
    double nsum[3], csum[3], area;
    const double *seed_normal;
    int planar; /* every face so far in the seed's plane (SEED_PLANE_DOT) */
    int linked; /* grown across a link: only faces of the seed's plane may join */
} chart_state;

static double dot_mean_normal(const struct chart_state *s, const double *n);

/* Within half of flatten.c's planar tolerance of the seed, so every face is within it of
 * the chart's mean normal. */
#define SEED_PLANE_DOT (1.0 - 2.5e-8)

static int in_seed_plane(const chart_state *s, const double *n)
{
    const double *m = s->seed_normal;
    return n[0] * m[0] + n[1] * m[1] + n[2] * m[2] >= SEED_PLANE_DOT;
}

/* Whether face f (normal n) may join the chart now, reached through a neighbour or a link. */
static int may_join(const chart_state *s, const double *n, uint32_t via_link, double cos_max)
{
    if (via_link || s->linked)
        return s->planar && in_seed_plane(s, n);
    return dot_mean_normal(s, n) >= cos_max;
}

static double dot_mean_normal(const struct chart_state *s, const double *n)
{
    double len = sqrt(s->nsum[0] * s->nsum[0] + s->nsum[1] * s->nsum[1] + s->nsum[2] * s->nsum[2]);
    return len > 0 ? (n[0] * s->nsum[0] + n[1] * s->nsum[1] + n[2] * s->nsum[2]) / len : 1.0;
}

static double cost_of(const lmb_topology *t, const chart_state *s, uint32_t f)
{
    const double *c = t->centroid + 3 * f;
    double d2 = 0;
    for (int i = 0; i < 3; i++) {
        double d = c[i] - s->csum[i] / s->area;
        d2 += d * d;
    }
    return (1.0 - dot_mean_normal(s, t->normal + 3 * f)) + 0.5 * sqrt(d2 / s->area);
}

static void add_face(const lmb_topology *t, chart_state *s, uint32_t f, uint32_t via_link)
{
    double a = t->area[f];
    s->planar = s->planar && in_seed_plane(s, t->normal + 3 * f);
    s->linked |= via_link != 0;
    for (int i = 0; i < 3; i++) {
        s->nsum[i] += a * t->normal[3 * f + i];
        s->csum[i] += a * t->centroid[3 * f + i];
    }
    s->area += a;
}


typedef struct seed {
    double area;
    uint32_t face;
} seed;

static int by_area_desc(const void *a, const void *b)
{
    const seed *x = a, *y = b;
    if (x->area != y->area)
        return x->area > y->area ? -1 : 1;
    return (x->face > y->face) - (x->face < y->face);
}

lmb_status lmb_segment(const lmb_unwrap_input *in, const lmb_topology *t, const uint32_t *tris, uint32_t n,
                       double max_angle, uint32_t *chart_of, uint32_t *next_chart, lmb_error *err)
{
    (void)in;
    double cos_max = cos(max_angle);
    seed *seeds = malloc(((size_t)n + 1) * sizeof *seeds);
    heap h = {NULL, 0, 0};
    if (!seeds)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: out of memory");
    for (uint32_t i = 0; i < n; i++) {
        seeds[i].area = t->area[tris[i]];
        seeds[i].face = tris[i];
    }
    qsort(seeds, n, sizeof *seeds, by_area_desc);
    for (uint32_t i = 0; i < n; i++) {
        uint32_t s0 = seeds[i].face;
        if (chart_of[s0] != LMB_NONE)
            continue;
        uint32_t id = (*next_chart)++;
        chart_state st;
        memset(&st, 0, sizeof st);
        st.seed_normal = t->normal + 3 * s0;
        st.planar = 1;
        chart_of[s0] = id;
        add_face(t, &st, s0, 0);
        h.n = 0;
        uint32_t f = s0, via = 0;
        for (;;) {
            for (int k = 0; k < 6; k++) { /* the three neighbours, then the three links */
                uint32_t g = k < 3 ? t->neighbor[3 * f + k] : t->link[3 * f + k - 3];
                if (g != LMB_NONE && chart_of[g] == LMB_NONE && (k < 3 || st.planar)) {
                    entry e = {cost_of(t, &st, g), g, k >= 3};
                    if (!heap_push(&h, e)) {
                        free(h.e);
                        free(seeds);
                        return lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: out of memory");
                    }
                }
            }
            f = LMB_NONE;
            while (h.n && f == LMB_NONE) {
                entry e = heap_pop(&h);
                if (chart_of[e.face] == LMB_NONE && may_join(&st, t->normal + 3 * e.face, e.via_link, cos_max)) {
                    f = e.face;
                    via = e.via_link;
                }
            }
            if (f == LMB_NONE)
                break;
            chart_of[f] = id;
            add_face(t, &st, f, via);
        }
    }
    free(h.e);
    free(seeds);
    return LMB_OK;
}
