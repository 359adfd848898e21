/*
 * Gluing charts too narrow for the lightmap onto a neighbour (the last step of the unwrap).
 *
 * At a level's texel density a soup's trims, the ends and tops of thin walls, stair risers and
 * small crates are charts one or two texels wide: each costs a footprint of padding several
 * times its own area, and a chart narrower than a texel covers no texel centre at all, so it is
 * lit only by dilation. A chart whose width (its extent across its principal axis in UV) is
 * below opt->glue_below is glued to the neighbouring chart it shares the most edge length with:
 * its own flattening is kept and moved rigidly in UV (a rotation and translation, the scale
 * within 10% of 1) so that one shared edge lands on the neighbour's copy of it. It unfolds
 * across the crease, as a folded strip of paper lies flat, so its stretch does not change.
 *
 * Neighbours are found across the half-edge mesh's edges, its coplanar links and, across a
 * seam, every triangle on the same welded edge (the inner faces of touching crates, a beam's
 * face on the wall under it). Any crease angle is allowed: a chart this narrow has a texel or
 * two, which blend with the neighbour's across the crease, where before they had none of their
 * own or were lit by dilation. The move is kept only where nothing overlaps: the shared edge
 * must be run the other way by the neighbour (so the glued chart lies across it), no edge of the
 * glued chart may cross an edge of the neighbour, and neither may hold the other's triangle
 * centroids. Narrowest charts are glued first; a chart that grew by gluing is measured
 * again when its turn comes. Deterministic: orders and ties are by chart id.
 */
#include "unwrap_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


typedef struct chart_list {
    uint32_t *head, *tail, *next, *count; /* members as linked lists (next per triangle) */
} chart_list;

/* Seam edges by welded end points (sorted), so a chart can be glued across a seam the
 * half-edge mesh made (a non-manifold edge: the inner faces of touching crates). */
typedef struct seam_index {
    lmb_welded_edge *e;
    uint32_t n;
} seam_index;

static int seam_index_build(const lmb_topology *t, const uint32_t *chart_of, uint32_t nt, seam_index *si)
{
    si->n = 0;
    si->e = malloc(sizeof(lmb_welded_edge) * (3 * (size_t)nt + 1));
    if (!si->e)
        return 0;
    for (uint32_t f = 0; f < nt; f++)
        for (uint32_t k = 0; k < 3; k++) {
            uint32_t a = t->weld[3 * f + k], b = t->weld[3 * f + (k + 1) % 3];
            if (chart_of[f] != LMB_NONE && t->neighbor[3 * f + k] == LMB_NONE && a != b)
                si->e[si->n++] = (lmb_welded_edge){a < b ? a : b, a < b ? b : a, f, k};
        }
    qsort(si->e, si->n, sizeof *si->e, lmb_cmp_welded_edge);
    return 1;
}

/* The first entry of edge (a, b) in the index; si->n if none. */
static uint32_t seam_first(const seam_index *si, uint32_t a, uint32_t b)
{
    uint32_t lo_id = a < b ? a : b, hi_id = a < b ? b : a, lo = 0, hi = si->n;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        const lmb_welded_edge *m = &si->e[mid];
        if (m->lo < lo_id || (m->lo == lo_id && m->hi < hi_id))
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < si->n && si->e[lo].lo == lo_id && si->e[lo].hi == hi_id ? lo : si->n;
}

/* Iterates the triangles across edge k of f: its neighbour, or across a seam every other
 * triangle on the same welded edge (the caller checks which way it runs). *it starts at 0;
 * returns LMB_NONE when done. */
static uint32_t across_next(const lmb_topology *t, const seam_index *si, uint32_t f, int k, uint32_t *it)
{
    if (t->neighbor[3 * f + k] != LMB_NONE)
        return (*it)++ == 0 ? t->neighbor[3 * f + k] : LMB_NONE;
    uint32_t a = t->weld[3 * f + k], b = t->weld[3 * f + (k + 1) % 3];
    if (*it == 0)
        *it = seam_first(si, a, b) + 1; /* stored one past, so 0 means "not started" */
    while (*it - 1 < si->n) {
        const lmb_welded_edge *e = &si->e[*it - 1];
        if (e->lo != (a < b ? a : b) || e->hi != (a < b ? b : a))
            break;
        (*it)++;
        if (e->face != f)
            return e->face;
    }
    *it = UINT32_MAX;
    return LMB_NONE;
}

typedef struct narrow {
    double width;
    uint32_t chart;
} narrow;

static int by_width(const void *a, const void *b)
{
    const narrow *x = a, *y = b;
    if (x->width != y->width)
        return x->width < y->width ? -1 : 1;
    return (x->chart > y->chart) - (x->chart < y->chart);
}

/* Extent of chart c's UV points across their principal axis (2x2 covariance). */
static double chart_width(const chart_list *cl, uint32_t c, const double *uv)
{
    double m[2] = {0, 0}, cxx = 0, cxy = 0, cyy = 0;
    uint32_t n = 0;
    for (uint32_t f = cl->head[c]; f != LMB_NONE; f = cl->next[f])
        for (int k = 0; k < 3; k++, n++) {
            m[0] += uv[6 * f + 2 * k];
            m[1] += uv[6 * f + 2 * k + 1];
        }
    if (n == 0)
        return INFINITY;
    m[0] /= n;
    m[1] /= n;
    for (uint32_t f = cl->head[c]; f != LMB_NONE; f = cl->next[f])
        for (int k = 0; k < 3; k++) {
            double x = uv[6 * f + 2 * k] - m[0], y = uv[6 * f + 2 * k + 1] - m[1];
            cxx += x * x;
            cxy += x * y;
            cyy += y * y;
        }
    /* the principal axis' angle, then the extent across it */
    double a = 0.5 * atan2(2 * cxy, cxx - cyy), ax = cos(a), ay = sin(a), lo = INFINITY, hi = -INFINITY;
    for (uint32_t f = cl->head[c]; f != LMB_NONE; f = cl->next[f])
        for (int k = 0; k < 3; k++) {
            double d = -ay * uv[6 * f + 2 * k] + ax * uv[6 * f + 2 * k + 1];
            lo = fmin(lo, d);
            hi = fmax(hi, d);
        }
    return hi - lo;
}

/* Point p strictly inside triangle t (counter-clockwise UV). */
static int inside(const double *t, const double *p)
{
    return lmb_uv_orient(t, t + 2, p) > 0 && lmb_uv_orient(t + 2, t + 4, p) > 0 && lmb_uv_orient(t + 4, t, p) > 0;
}

/* Point p inside triangle t by more than a sliver: each edge function above eps x the edge's
 * length (a vertex the move put on the host's edge or corner, up to rounding, is not inside). */
static int inside_by(const double *t, const double *p, double eps)
{
    for (int k = 0; k < 3; k++) {
        const double *a = t + 2 * k, *b = t + 2 * ((k + 1) % 3);
        if (!(lmb_uv_orient(a, b, p) > eps * hypot(b[0] - a[0], b[1] - a[1])))
            return 0;
    }
    return 1;
}

static void tri_box(const double *t, double box[4])
{
    box[0] = fmin(t[0], fmin(t[2], t[4]));
    box[1] = fmin(t[1], fmin(t[3], t[5]));
    box[2] = fmax(t[0], fmax(t[2], t[4]));
    box[3] = fmax(t[1], fmax(t[3], t[5]));
}

/* Whether the moved triangles of c (moved, 6 per member in list order) overlap host h. */
static int overlaps(const chart_list *cl, uint32_t c, uint32_t h, const double *uv, const double *moved)
{
    double cb[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    uint32_t n = cl->count[c];
    for (uint32_t i = 0; i < n; i++) {
        double b[4];
        tri_box(moved + 6 * i, b);
        cb[0] = fmin(cb[0], b[0]);
        cb[1] = fmin(cb[1], b[1]);
        cb[2] = fmax(cb[2], b[2]);
        cb[3] = fmax(cb[3], b[3]);
    }
    for (uint32_t g = cl->head[h]; g != LMB_NONE; g = cl->next[g]) {
        const double *q = uv + 6 * g;
        double gb[4];
        tri_box(q, gb);
        if (gb[2] < cb[0] || gb[0] > cb[2] || gb[3] < cb[1] || gb[1] > cb[3])
            continue;
        double qc[2] = {(q[0] + q[2] + q[4]) / 3, (q[1] + q[3] + q[5]) / 3};
        for (uint32_t i = 0; i < n; i++) {
            const double *p = moved + 6 * i;
            double pb[4];
            tri_box(p, pb);
            if (gb[2] < pb[0] || gb[0] > pb[2] || gb[3] < pb[1] || gb[1] > pb[3])
                continue;
            double pc[2] = {(p[0] + p[2] + p[4]) / 3, (p[1] + p[3] + p[5]) / 3};
            if (inside(q, pc) || inside(p, qc))
                return 1;
            /* a corner inside the other triangle: the glued chart keeps its own edge lengths (within
             * 10%), so beside the anchor its triangle can fold over the host's in a thin wedge that
             * no edge crosses properly and no centroid lies in */
            double eps = 1e-9 * fmax(cb[2] - cb[0], cb[3] - cb[1]);
            for (int a = 0; a < 3; a++)
                if (inside_by(q, p + 2 * a, eps) || inside_by(p, q + 2 * a, eps))
                    return 1;
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++)
                    if (lmb_uv_crosses(p + 2 * a, p + 2 * ((a + 1) % 3), q + 2 * b, q + 2 * ((b + 1) % 3)))
                        return 1;
        }
    }
    return 0;
}

/* The corner of triangle g whose welded vertex is w, or -1. */
static int corner_of(const lmb_topology *t, uint32_t g, uint32_t w)
{
    for (int k = 0; k < 3; k++)
        if (t->weld[3 * g + k] == w)
            return k;
    return -1;
}

/* Scratch for one chart's candidate hosts. */
typedef struct candidates {
    uint32_t n, host[64];
    double shared[64]; /* 3D edge length shared with each host */
} candidates;

/* The charts across c's edges, with the edge length each shares with c. */
static void find_hosts(const lmb_topology *t, const seam_index *si, const lmb_unwrap_input *in,
                       const chart_list *cl, const uint32_t *chart_of, uint32_t c, candidates *h)
{
    h->n = 0;
    for (uint32_t f = cl->head[c]; f != LMB_NONE; f = cl->next[f])
        for (int k = 0; k < 3; k++)
            for (uint32_t it = 0, g; (g = across_next(t, si, f, k, &it)) != LMB_NONE;) {
                if (chart_of[g] == c || chart_of[g] == LMB_NONE)
                    continue;
                const float *a = in->positions + 3 * in->indices[3 * f + k],
                            *b = in->positions + 3 * in->indices[3 * f + (k + 1) % 3];
                double d[3] = {(double)a[0] - b[0], (double)a[1] - b[1], (double)a[2] - b[2]};
                uint32_t j = 0;
                while (j < h->n && h->host[j] != chart_of[g])
                    j++;
                if (j == h->n) {
                    if (h->n == 64)
                        continue; /* enough candidates */
                    h->host[h->n] = chart_of[g];
                    h->shared[h->n++] = 0;
                }
                h->shared[j] += sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            }
}

/* The first edge of c (in member order) that host h's triangle g runs the other way, with
 * copies of equal length (within 10%): its corners in f (k0 -> k1) and g (g0, g1). */
static int find_anchor(const lmb_topology *t, const seam_index *si, const chart_list *cl, const uint32_t *chart_of,
                       const double *uv, uint32_t c, uint32_t h, uint32_t *f_out, uint32_t *g_out, int corners[4])
{
    for (uint32_t f = cl->head[c]; f != LMB_NONE; f = cl->next[f])
        for (int k0 = 0; k0 < 3; k0++)
            for (uint32_t it = 0, g; (g = across_next(t, si, f, k0, &it)) != LMB_NONE;) {
                int k1 = (k0 + 1) % 3;
                int g0 = chart_of[g] == h ? corner_of(t, g, t->weld[3 * f + k0]) : -1,
                    g1 = chart_of[g] == h ? corner_of(t, g, t->weld[3 * f + k1]) : -1;
                if (g0 < 0 || g1 < 0 || (g1 + 1) % 3 != g0) /* g must run it from f's k1 to f's k0 */
                    continue;
                const double *p0 = uv + 6 * f + 2 * k0, *p1 = uv + 6 * f + 2 * k1;
                const double *q0 = uv + 6 * g + 2 * g0, *q1 = uv + 6 * g + 2 * g1;
                double lp = (p1[0] - p0[0]) * (p1[0] - p0[0]) + (p1[1] - p0[1]) * (p1[1] - p0[1]),
                       lq = (q1[0] - q0[0]) * (q1[0] - q0[0]) + (q1[1] - q0[1]) * (q1[1] - q0[1]);
                if (!(lp > 0) || !(lq > 0) || lq < 0.81 * lp || lq > 1.21 * lp)
                    continue;
                *f_out = f;
                *g_out = g;
                corners[0] = k0, corners[1] = k1, corners[2] = g0, corners[3] = g1;
                return 1;
            }
    return 0;
}

/* c's UVs moved rigidly so that edge (p0, p1) of triangle f lands on (q1, q0) of g: a
 * rotation taking p0 -> p1 to q0 -> q1, and the edges' mid-points made to meet (both
 * flattenings are isometric: no scale). moved: 6 per member, in list order. */
static void move_chart(const chart_list *cl, uint32_t c, const double *uv, uint32_t f, uint32_t g,
                       const int corners[4], double *moved)
{
    const double *p0 = uv + 6 * f + 2 * corners[0], *p1 = uv + 6 * f + 2 * corners[1];
    const double *q0 = uv + 6 * g + 2 * corners[2], *q1 = uv + 6 * g + 2 * corners[3];
    double dp[2] = {p1[0] - p0[0], p1[1] - p0[1]}, dq[2] = {q1[0] - q0[0], q1[1] - q0[1]};
    double s = sqrt((dp[0] * dp[0] + dp[1] * dp[1]) * (dq[0] * dq[0] + dq[1] * dq[1]));
    double cs = (dp[0] * dq[0] + dp[1] * dq[1]) / s, sn = (dp[0] * dq[1] - dp[1] * dq[0]) / s;
    double mp[2] = {0.5 * (p0[0] + p1[0]), 0.5 * (p0[1] + p1[1])}, mq[2] = {0.5 * (q0[0] + q1[0]), 0.5 * (q0[1] + q1[1])};
    uint32_t i = 0;
    for (uint32_t m = cl->head[c]; m != LMB_NONE; m = cl->next[m], i++)
        for (int v = 0; v < 3; v++) {
            double x = uv[6 * m + 2 * v] - mp[0], y = uv[6 * m + 2 * v + 1] - mp[1];
            moved[6 * i + 2 * v] = mq[0] + cs * x - sn * y;
            moved[6 * i + 2 * v + 1] = mq[1] + sn * x + cs * y;
        }
}

/* The moved chart's copies of the anchor edge's two vertices put exactly on the host's: the two
 * flattenings give the edge lengths up to 10% apart, and a glued edge left longer than the
 * host's would reach past its ends, on the line of the host's edge, where the atlas's
 * rounding makes slivers that two triangles cover (texels shared across the seam). Only copies
 * that the move put near the host's (within a tenth of the edge) are welded; returns 0 when that
 * would flip or collapse a triangle of the chart (its area more than halved): no glue there. */
static int weld_anchor(const lmb_topology *t, const chart_list *cl, uint32_t c, const double *uv, uint32_t g,
                       const int corners[4], double *moved)
{
    uint32_t w0 = t->weld[3 * g + corners[2]], w1 = t->weld[3 * g + corners[3]], i = 0;
    const double *q0 = uv + 6 * g + 2 * corners[2], *q1 = uv + 6 * g + 2 * corners[3];
    double tol = 0.1 * hypot(q1[0] - q0[0], q1[1] - q0[1]);
    for (uint32_t m = cl->head[c]; m != LMB_NONE; m = cl->next[m], i++) {
        double *p = moved + 6 * i, before = lmb_uv_orient(p, p + 2, p + 4);
        for (int v = 0; v < 3; v++) {
            uint32_t w = t->weld[3 * m + v];
            const double *q = w == w0 ? q0 : w == w1 ? q1 : NULL;
            if (q && hypot(p[2 * v] - q[0], p[2 * v + 1] - q[1]) <= tol)
                memcpy(p + 2 * v, q, 2 * sizeof *p);
        }
        double after = lmb_uv_orient(p, p + 2, p + 4);
        if (!(before > 0 ? after > 0.5 * before : after < 0.5 * before))
            return 0;
    }
    return 1;
}

/* c becomes part of h: its moved UVs, h's id, its members appended to h's list. */
static void attach(chart_list *cl, uint32_t *chart_of, double *uv, uint32_t c, uint32_t h, const double *moved)
{
    uint32_t i = 0;
    for (uint32_t m = cl->head[c]; m != LMB_NONE; m = cl->next[m], i++) {
        memcpy(uv + 6 * m, moved + 6 * i, 6 * sizeof *uv);
        chart_of[m] = h;
    }
    cl->next[cl->tail[h]] = cl->head[c];
    cl->tail[h] = cl->tail[c];
    cl->count[h] += cl->count[c];
    cl->head[c] = cl->tail[c] = LMB_NONE;
    cl->count[c] = 0;
}

/* Tries to glue chart c onto a neighbour, the one sharing the most edge length first (ties:
 * lower id); the anchor edge fixes the move, so a host where it overlaps is passed over.
 * Returns the host, or LMB_NONE. */
static uint32_t glue_one(const lmb_topology *t, const seam_index *si, const lmb_unwrap_input *in, chart_list *cl,
                         uint32_t *chart_of, double *uv, uint32_t c, double *moved, candidates *hosts)
{
    find_hosts(t, si, in, cl, chart_of, c, hosts);
    while (hosts->n > 0) {
        uint32_t best = 0;
        for (uint32_t j = 1; j < hosts->n; j++)
            if (hosts->shared[j] > hosts->shared[best] ||
                (hosts->shared[j] == hosts->shared[best] && hosts->host[j] < hosts->host[best]))
                best = j;
        uint32_t h = hosts->host[best], f, g;
        hosts->n--;
        hosts->host[best] = hosts->host[hosts->n];
        hosts->shared[best] = hosts->shared[hosts->n];
        int corners[4];
        if (!find_anchor(t, si, cl, chart_of, uv, c, h, &f, &g, corners))
            continue;
        move_chart(cl, c, uv, f, g, corners, moved);
        if (!weld_anchor(t, cl, c, uv, g, corners, moved) || overlaps(cl, c, h, uv, moved))
            continue;
        attach(cl, chart_of, uv, c, h, moved);
        return h;
    }
    return LMB_NONE;
}

uint32_t lmb_glue_narrow_charts(const lmb_unwrap_input *in, const lmb_topology *t, uint32_t *chart_of, double *uv,
                                uint32_t chart_count, double glue_below, int *ok)
{
    *ok = 1;
    uint32_t nt = in->triangle_count, glued = 0;
    if (!(glue_below > 0) || chart_count < 2)
        return 0;
    chart_list cl = {malloc(sizeof(uint32_t) * chart_count), malloc(sizeof(uint32_t) * chart_count),
                     malloc(sizeof(uint32_t) * ((size_t)nt + 1)), calloc(chart_count, sizeof(uint32_t))};
    narrow *order = malloc(sizeof(narrow) * chart_count);
    candidates *hosts = malloc(sizeof *hosts);
    double *moved = NULL;
    seam_index si = {NULL, 0};
    if (!seam_index_build(t, chart_of, nt, &si) || !cl.head || !cl.tail || !cl.next || !cl.count || !order || !hosts) {
        *ok = 0;
        goto done;
    }
    for (uint32_t c = 0; c < chart_count; c++)
        cl.head[c] = cl.tail[c] = LMB_NONE;
    for (uint32_t f = 0; f < nt; f++) {
        uint32_t c = chart_of[f];
        cl.next[f] = LMB_NONE;
        if (c == LMB_NONE || c >= chart_count)
            continue;
        if (cl.head[c] == LMB_NONE)
            cl.head[c] = f;
        else
            cl.next[cl.tail[c]] = f;
        cl.tail[c] = f;
        cl.count[c]++;
    }
    uint32_t nn = 0;
    for (uint32_t c = 0; c < chart_count; c++) {
        double w = cl.count[c] ? chart_width(&cl, c, uv) : INFINITY;
        if (w < glue_below)
            order[nn++] = (narrow){w, c};
    }
    qsort(order, nn, sizeof *order, by_width);
    moved = malloc(sizeof(double) * 6 * ((size_t)nt + 1));
    if (!moved) {
        *ok = 0;
        goto done;
    }
    for (uint32_t j = 0; j < nn; j++) {
        uint32_t c = order[j].chart;
        if (cl.count[c] == 0)
            continue; /* glued into another already */
        if (chart_width(&cl, c, uv) >= glue_below)
            continue; /* charts glued onto it made it wide enough */
        glued += glue_one(t, &si, in, &cl, chart_of, uv, c, moved, hosts) != LMB_NONE;
    }
done:
    free(si.e);
    free(cl.head);
    free(cl.tail);
    free(cl.next);
    free(cl.count);
    free(order);
    free(hosts);
    free(moved);
    return glued;
}
