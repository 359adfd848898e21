/*
 * The unwrap driver: topology -> segmentation -> flattening, then a validity check per
 * chart and splitting until every chart is valid. A chart is valid when every triangle
 * keeps its orientation in UV (no flips) and its boundary does not cross itself; with both,
 * the flattening of a chart is injective, so no two of its triangles share a texel. An
 * invalid chart, or one with a hole (a ring), is cut in two across its longest axis and
 * each half segmented again; a chart that cannot be cut becomes one chart per triangle
 * (a single triangle is always valid).
 */
#include "unwrap_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void lmb_unwrap_options_default(lmb_unwrap_options *o)
{
    o->max_chart_angle = 30.0 * 3.14159265358979323846 / 180.0;
    o->glue_below = 0;
    o->name = NULL;
}

void lmb_charts_free(lmb_charts *c)
{
    free(c->chart_of);
    free(c->uv);
    free(c->first);
    free(c->order);
    memset(c, 0, sizeof *c);
}

typedef struct bedge {
    const double *a, *b;
    uint32_t wa, wb; /* end points' vertex ids: mesh ids (chart_valid), welded ids (has_hole) */
} bedge;

/* Whether the edge of corner k of triangle f is inside its chart: the triangle across it
 * (or across its coplanar link, which planar charts grow over) is in the same chart. */
static int edge_inside(const lmb_topology *t, uint32_t f, int k, const uint32_t *chart_of)
{
    uint32_t id = chart_of[f], g = t->neighbor[3 * f + k], l = t->link[3 * f + k];
    return (g != LMB_NONE && chart_of[g] == id) || (l != LMB_NONE && chart_of[l] == id);
}

/* Boundary self-intersection over a uniform grid of the chart's UV bounding box. */
static int boundary_crosses(const bedge *e, uint32_t ne)
{
    if (ne < 4)
        return 0;
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (uint32_t i = 0; i < ne; i++)
        for (int d = 0; d < 2; d++) {
            lo[d] = fmin(lo[d], fmin(e[i].a[d], e[i].b[d]));
            hi[d] = fmax(hi[d], fmax(e[i].a[d], e[i].b[d]));
        }
    uint32_t g = (uint32_t)ceil(sqrt((double)ne));
    double cw = (hi[0] - lo[0]) / g + 1e-300, ch = (hi[1] - lo[1]) / g + 1e-300;
    /* cell lists: count, offsets, fill */
    uint32_t cells = g * g, *count = calloc((size_t)cells + 1, sizeof *count), total = 0;
    if (!count)
        return 1;
    uint32_t (*box)[4] = malloc((size_t)ne * sizeof *box);
    if (!box) {
        free(count);
        return 1;
    }
    for (uint32_t i = 0; i < ne; i++) {
        double x0 = fmin(e[i].a[0], e[i].b[0]), x1 = fmax(e[i].a[0], e[i].b[0]);
        double y0 = fmin(e[i].a[1], e[i].b[1]), y1 = fmax(e[i].a[1], e[i].b[1]);
        box[i][0] = (uint32_t)fmin(g - 1, (x0 - lo[0]) / cw);
        box[i][1] = (uint32_t)fmin(g - 1, (x1 - lo[0]) / cw);
        box[i][2] = (uint32_t)fmin(g - 1, (y0 - lo[1]) / ch);
        box[i][3] = (uint32_t)fmin(g - 1, (y1 - lo[1]) / ch);
        for (uint32_t y = box[i][2]; y <= box[i][3]; y++)
            for (uint32_t x = box[i][0]; x <= box[i][1]; x++) {
                count[y * g + x]++;
                total++;
            }
    }
    uint32_t *start = malloc(((size_t)cells + 1) * sizeof *start), *list = malloc(((size_t)total + 1) * sizeof *list);
    int hit = !start || !list;
    if (!hit) {
        uint32_t acc = 0;
        for (uint32_t c = 0; c < cells; c++) {
            start[c] = acc;
            acc += count[c];
            count[c] = 0;
        }
        start[cells] = acc;
        for (uint32_t i = 0; i < ne; i++)
            for (uint32_t y = box[i][2]; y <= box[i][3]; y++)
                for (uint32_t x = box[i][0]; x <= box[i][1]; x++)
                    list[start[y * g + x] + count[y * g + x]++] = i;
        for (uint32_t c = 0; c < cells && !hit; c++)
            for (uint32_t i = start[c]; i < start[c + 1] && !hit; i++)
                for (uint32_t j = i + 1; j < start[c + 1] && !hit; j++) {
                    const bedge *p = &e[list[i]], *q = &e[list[j]];
                    if (p->wa == q->wa || p->wa == q->wb || p->wb == q->wa || p->wb == q->wb)
                        continue;
                    hit = lmb_uv_crosses(p->a, p->b, q->a, q->b);
                }
    }
    free(count);
    free(box);
    free(start);
    free(list);
    return hit;
}

/* Valid: no flipped or collapsed triangle, boundary does not cross itself. */
static int chart_valid(const lmb_topology *t, const uint32_t *tris, uint32_t n,
                       const uint32_t *chart_of, const double *uv, bedge *scratch)
{
    uint32_t ne = 0;
    for (uint32_t i = 0; i < n; i++) {
        const double *p = uv + 6 * tris[i];
        if (!(lmb_uv_orient(p, p + 2, p + 4) > 0))
            return 0;
        for (int k = 0; k < 3; k++) {
            if (edge_inside(t, tris[i], k, chart_of))
                continue;
            bedge *b = &scratch[ne++];
            b->a = p + 2 * k;
            b->b = p + 2 * ((k + 1) % 3);
            b->wa = t->corner[3 * tris[i] + k];
            b->wb = t->corner[3 * tris[i] + (k + 1) % 3];
        }
    }
    return !boundary_crosses(scratch, ne);
}

/* A chart whose boundary falls into more than one connected piece has a hole (a ring,
 * such as the flat top of a torus): valid, but its hole wastes atlas space, so it is cut.
 * Boundary end points are merged with union-find over the chart's welded vertex ids. */
static int has_hole(const lmb_topology *t, const uint32_t *tris, uint32_t n,
                    const uint32_t *chart_of, bedge *scratch)
{
    uint32_t ne = 0;
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            if (edge_inside(t, tris[i], k, chart_of))
                continue;
            scratch[ne].wa = t->weld[3 * tris[i] + k];
            scratch[ne].wb = t->weld[3 * tris[i] + (k + 1) % 3];
            ne++;
        }
    if (ne < 6)
        return 0;
    /* local ids: sort the end points, then union-find over positions in the sorted list */
    uint32_t *ids = malloc(2 * (size_t)ne * sizeof *ids), *parent = malloc(2 * (size_t)ne * sizeof *parent);
    if (!ids || !parent) {
        free(ids);
        free(parent);
        return 0;
    }
    for (uint32_t e = 0; e < ne; e++) {
        ids[2 * e] = scratch[e].wa;
        ids[2 * e + 1] = scratch[e].wb;
    }
    qsort(ids, 2 * (size_t)ne, sizeof *ids, lmb_cmp_u32);
    uint32_t m = 0;
    for (uint32_t i = 0; i < 2 * ne; i++)
        if (i == 0 || ids[i] != ids[m - 1])
            ids[m++] = ids[i];
    for (uint32_t i = 0; i < m; i++)
        parent[i] = i;
    uint32_t pieces = m;
    for (uint32_t e = 0; e < ne; e++) {
        uint32_t a = lmb_lower_bound(ids, m, scratch[e].wa), b = lmb_lower_bound(ids, m, scratch[e].wb);
        while (parent[a] != a)
            a = parent[a] = parent[parent[a]];
        while (parent[b] != b)
            b = parent[b] = parent[parent[b]];
        if (a != b) {
            parent[a < b ? b : a] = a < b ? a : b;
            pieces--;
        }
    }
    free(ids);
    free(parent);
    return pieces > 1;
}

/* Reorders tris so the triangles on the negative side of the plane through the chart's
 * area-weighted centroid, normal to its principal axis (power iteration on the centroid
 * covariance), come first; returns their count. */
static uint32_t split_in_two(const lmb_topology *t, uint32_t *tris, uint32_t n)
{
    double c[3] = {0, 0, 0}, a = 0, cov[9] = {0}, v[3] = {1, 0.7, 0.4};
    for (uint32_t i = 0; i < n; i++) {
        double w = t->area[tris[i]];
        for (int d = 0; d < 3; d++)
            c[d] += w * t->centroid[3 * tris[i] + d];
        a += w;
    }
    if (!(a > 0))
        return 0;
    for (int d = 0; d < 3; d++)
        c[d] /= a;
    for (uint32_t i = 0; i < n; i++) {
        double w = t->area[tris[i]], q[3];
        for (int d = 0; d < 3; d++)
            q[d] = t->centroid[3 * tris[i] + d] - c[d];
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 3; k++)
                cov[3 * r + k] += w * q[r] * q[k];
    }
    for (int it = 0; it < 32; it++) {
        double nv[3] = {0, 0, 0}, l = 0;
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 3; k++)
                nv[r] += cov[3 * r + k] * v[k];
        for (int r = 0; r < 3; r++)
            l += nv[r] * nv[r];
        if (!(l > 0))
            break;
        for (int r = 0; r < 3; r++)
            v[r] = nv[r] / sqrt(l);
    }
    uint32_t lo = 0;
    for (uint32_t i = 0; i < n; i++) {
        const double *q = t->centroid + 3 * tris[i];
        if ((q[0] - c[0]) * v[0] + (q[1] - c[1]) * v[1] + (q[2] - c[2]) * v[2] < 0) {
            uint32_t x = tris[i];
            tris[i] = tris[lo];
            tris[lo++] = x;
        }
    }
    return lo;
}

/* Chart membership lists kept in one growing pool: chart c owns pool[at[c] .. at[c]+len[c]). */
typedef struct pool {
    uint32_t *tris, used, cap;
    uint32_t *at, *len, nc, ccap;
    double *angle;
} pool;

static int pool_reserve(pool *p, uint32_t tris, uint32_t charts)
{
    if (p->used + tris > p->cap) {
        uint32_t cap = p->cap ? p->cap : 1024;
        while (cap < p->used + tris)
            cap *= 2;
        uint32_t *q = realloc(p->tris, (size_t)cap * sizeof *q);
        if (!q)
            return 0;
        p->tris = q;
        p->cap = cap;
    }
    if (charts > p->ccap) {
        uint32_t cap = p->ccap ? p->ccap : 64;
        while (cap < charts)
            cap *= 2;
        uint32_t *a = realloc(p->at, (size_t)cap * sizeof *a);
        if (a) p->at = a;
        uint32_t *l = realloc(p->len, (size_t)cap * sizeof *l);
        if (l) p->len = l;
        double *g = realloc(p->angle, (size_t)cap * sizeof *g);
        if (g) p->angle = g;
        if (!a || !l || !g)
            return 0;
        p->ccap = cap;
    }
    return 1;
}

/* Appends charts first..last-1 (fresh from lmb_segment over tris[0..n)) to the pool. */
static int pool_add(pool *p, const uint32_t *tris, uint32_t n, const uint32_t *chart_of, uint32_t first,
                    uint32_t last, double angle)
{
    if (!pool_reserve(p, n, last))
        return 0;
    for (uint32_t c = first; c < last; c++) {
        p->len[c] = 0;
        p->angle[c] = angle;
    }
    for (uint32_t i = 0; i < n; i++)
        p->len[chart_of[tris[i]]]++;
    uint32_t acc = p->used;
    for (uint32_t c = first; c < last; c++) {
        p->at[c] = acc;
        acc += p->len[c];
        p->len[c] = 0;
    }
    for (uint32_t i = 0; i < n; i++) {
        uint32_t c = chart_of[tris[i]];
        p->tris[p->at[c] + p->len[c]++] = tris[i];
    }
    p->used = acc;
    p->nc = last;
    return 1;
}

/* Renumbers live charts 0..k-1 in order of id and fills out's lists. */
static lmb_status finish(lmb_charts *out, const pool *p, uint32_t nt, lmb_error *err)
{
    uint32_t live = 0;
    for (uint32_t c = 0; c < p->nc; c++)
        live += p->len[c] > 0;
    out->first = malloc(((size_t)live + 1) * sizeof *out->first);
    out->order = malloc(((size_t)nt + 1) * sizeof *out->order);
    if (!out->first || !out->order)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: out of memory");
    uint32_t k = 0, at = 0;
    for (uint32_t c = 0; c < p->nc; c++) {
        if (!p->len[c])
            continue;
        out->first[k] = at;
        for (uint32_t i = 0; i < p->len[c]; i++) {
            uint32_t f = p->tris[p->at[c] + i];
            out->chart_of[f] = k;
            out->order[at++] = f;
        }
        k++;
    }
    out->first[k] = at;
    out->chart_count = live;
    return LMB_OK;
}

/* "unwrap: X" from a stage that does not know the mesh -> "unwrap: mesh 'NAME': X". */
static void name_mesh(lmb_error *err, const char *name)
{
    const char *prefix = "unwrap: ";
    size_t n = strlen(prefix);
    if (!err || strncmp(err->message, prefix, n) != 0 || strncmp(err->message + n, "mesh '", 6) == 0)
        return;
    char rest[sizeof err->message];
    memcpy(rest, err->message + n, sizeof rest - n);
    rest[sizeof rest - n - 1] = 0;
    snprintf(err->message, sizeof err->message, "unwrap: mesh '%.200s': %.800s", name, rest);
}

lmb_status lmb_unwrap_mesh(const lmb_unwrap_input *in, const lmb_unwrap_options *opt, lmb_charts *out,
                           lmb_error *err)
{
    memset(out, 0, sizeof *out);
    lmb_topology t;
    const char *name = opt->name ? opt->name : "mesh";
    lmb_status st = lmb_topology_build(in, name, &t, err);
    if (st != LMB_OK)
        return st;
    out->topology = t.counts;
    uint32_t nt = in->triangle_count, n = 0, next = 0;
    pool p;
    memset(&p, 0, sizeof p);
    out->triangle_count = nt;
    out->chart_of = malloc(((size_t)nt + 1) * sizeof *out->chart_of);
    out->uv = calloc((size_t)nt * 6 + 1, sizeof *out->uv);
    uint32_t *tris = malloc(((size_t)nt + 1) * sizeof *tris);
    bedge *scratch = malloc(((size_t)nt * 3 + 1) * sizeof *scratch);
    if (!out->chart_of || !out->uv || !tris || !scratch)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: out of memory for %u triangles", nt);
    for (uint32_t f = 0; st == LMB_OK && f < nt; f++) {
        out->chart_of[f] = LMB_NONE;
        if (!((in->skip && in->skip[f]) || !(t.area[f] > 0)))
            tris[n++] = f;
    }
    if (st == LMB_OK)
        st = lmb_segment(in, &t, tris, n, opt->max_chart_angle, out->chart_of, &next, err);
    if (st == LMB_OK && !pool_add(&p, tris, n, out->chart_of, 0, next, opt->max_chart_angle))
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: out of memory");
    for (uint32_t c = 0; st == LMB_OK && c < p.nc; c++) {
        uint32_t len = p.len[c];
        const uint32_t *members = p.tris + p.at[c];
        int planar = 0;
        st = lmb_flatten(in, &t, members, len, out->uv, &planar, err);
        if (st != LMB_OK || len == 1 ||
            (chart_valid(&t, members, len, out->chart_of, out->uv, scratch) &&
             !has_hole(&t, members, len, out->chart_of, scratch))) {
            out->planar_charts += planar;
            continue;
        }
        /* split in two across the chart's longest axis, then grow charts in each half */
        memcpy(tris, members, len * sizeof *tris);
        uint32_t before = next, na = split_in_two(&t, tris, len);
        double angle = p.angle[c];
        for (uint32_t i = 0; i < len; i++)
            out->chart_of[tris[i]] = i < na ? LMB_NONE : LMB_NONE - 1; /* second half held back */
        if (na == 0 || na == len) { /* cannot cut: every triangle alone */
            for (uint32_t i = 0; i < len; i++)
                out->chart_of[tris[i]] = next++;
        } else {
            st = lmb_segment(in, &t, tris, na, angle, out->chart_of, &next, err);
            for (uint32_t i = na; i < len; i++)
                out->chart_of[tris[i]] = LMB_NONE;
            if (st == LMB_OK)
                st = lmb_segment(in, &t, tris + na, len - na, angle, out->chart_of, &next, err);
        }
        p.len[c] = 0;
        out->splits++;
        if (st == LMB_OK && !pool_add(&p, tris, len, out->chart_of, before, next, angle))
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: out of memory");
    }
    if (st == LMB_OK && opt->glue_below > 0) {
        int ok;
        out->glued = lmb_glue_narrow_charts(in, &t, out->chart_of, out->uv, p.nc, opt->glue_below, &ok);
        p.used = 0; /* the pool again, from the glued labels (tris was the splits' scratch) */
        p.nc = 0;
        n = 0;
        for (uint32_t f = 0; f < nt; f++)
            if (out->chart_of[f] != LMB_NONE)
                tris[n++] = f;
        if (!ok || !pool_add(&p, tris, n, out->chart_of, 0, next, opt->max_chart_angle))
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: out of memory");
    }
    if (st == LMB_OK)
        st = finish(out, &p, nt, err);
    if (st == LMB_OK && out->glued) { /* a chart glued across a crease is no longer a projection */
        out->planar_charts = 0;
        for (uint32_t c = 0; c < out->chart_count; c++) {
            const double *n0 = t.normal + 3 * out->order[out->first[c]];
            int planar = 1;
            for (uint32_t i = out->first[c] + 1; i < out->first[c + 1] && planar; i++) {
                const double *n1 = t.normal + 3 * out->order[i];
                planar = n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2] >= LMB_PLANAR_DOT;
            }
            out->planar_charts += planar;
        }
    }
    /* triangles left out keep UV 0 and chart LMB_NONE */
    free(tris);
    free(scratch);
    free(p.tris);
    free(p.at);
    free(p.len);
    free(p.angle);
    lmb_topology_free(&t);
    if (st != LMB_OK) {
        lmb_charts_free(out);
        name_mesh(err, name);
    }
    return st;
}
