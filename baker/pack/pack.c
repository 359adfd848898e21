/*
 * Chart packing, first version: each chart is turned to its minimal-area bounding box
 * (rotating calipers over the convex hull of its UVs), given a border of padding + 1
 * texels (conservative footprint, bilinear reach, padding) and placed by a skyline packer
 * (lowest position first, then leftmost), tallest charts first. Charts sit on whole-texel
 * offsets, so the texel a triangle touches in chart space is the texel it touches in the
 * atlas. Boxes never overlap, so no texel is reachable from two charts. Deterministic.
 */
#include "pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct item {
    uint32_t chart;
    double m[4];      /* rotation (and optional 90-degree turn) chart uv -> box */
    double lo[2];     /* rotated bounds */
    uint32_t w, h;    /* box size in texels, border included */
} item;

typedef struct pt {
    double x, y;
} pt;

static int cmp_pt(const void *a, const void *b)
{
    const pt *p = a, *q = b;
    if (p->x != q->x)
        return p->x < q->x ? -1 : 1;
    return (p->y > q->y) - (p->y < q->y);
}

static double cross(pt o, pt a, pt b)
{
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

/* Andrew's monotone chain; returns the hull size, hull in out (capacity n + 1). */
static uint32_t hull(pt *p, uint32_t n, pt *out)
{
    qsort(p, n, sizeof *p, cmp_pt);
    uint32_t k = 0;
    for (uint32_t i = 0; i < n; i++) {
        while (k >= 2 && cross(out[k - 2], out[k - 1], p[i]) <= 0)
            k--;
        out[k++] = p[i];
    }
    for (uint32_t i = n - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross(out[k - 2], out[k - 1], p[i]) <= 0)
            k--;
        out[k++] = p[i];
    }
    return k > 1 ? k - 1 : k;
}

/* Rotation aligning the hull edge that gives the smallest bounding box with the x axis. */
static void min_box(const pt *h, uint32_t n, double m[4], double lo[2], double hi[2])
{
    double best = INFINITY;
    m[0] = 1; m[1] = 0; m[2] = 0; m[3] = 1;
    for (uint32_t e = 0; e < (n > 1 ? n : 1); e++) {
        double c = 1, s = 0;
        if (n > 1) {
            double dx = h[(e + 1) % n].x - h[e].x, dy = h[(e + 1) % n].y - h[e].y, l = sqrt(dx * dx + dy * dy);
            if (!(l > 0))
                continue;
            c = dx / l;
            s = dy / l;
        }
        double a[2] = {INFINITY, INFINITY}, b[2] = {-INFINITY, -INFINITY};
        for (uint32_t i = 0; i < n; i++) {
            double x = c * h[i].x + s * h[i].y, y = -s * h[i].x + c * h[i].y;
            a[0] = fmin(a[0], x); b[0] = fmax(b[0], x);
            a[1] = fmin(a[1], y); b[1] = fmax(b[1], y);
        }
        double area = (b[0] - a[0]) * (b[1] - a[1]);
        if (area < best - 1e-12) {
            best = area;
            m[0] = c; m[1] = s; m[2] = -s; m[3] = c;
            memcpy(lo, a, sizeof a);
            memcpy(hi, b, sizeof b);
        }
    }
    /* lying down: the long side horizontal */
    if (hi[1] - lo[1] > hi[0] - lo[0]) {
        double r[4] = {-m[2], -m[3], m[0], m[1]}; /* (x, y) -> (-y, x) */
        double nlo[2] = {-hi[1], lo[0]}, nhi[2] = {-lo[1], hi[0]};
        memcpy(m, r, sizeof r);
        memcpy(lo, nlo, sizeof nlo);
        memcpy(hi, nhi, sizeof nhi);
    }
}

static int prepare(const lmb_pack_chart *c, uint32_t index, uint32_t border, item *it)
{
    uint32_t n = 3 * c->triangle_count;
    pt *p = malloc(((size_t)n + 1) * sizeof *p), *h = malloc(((size_t)n + 2) * sizeof *h);
    if (!p || !h) {
        free(p);
        free(h);
        return 0;
    }
    for (uint32_t i = 0; i < n; i++) {
        p[i].x = c->uv[2 * i];
        p[i].y = c->uv[2 * i + 1];
    }
    double lo[2] = {0, 0}, hi[2] = {0, 0};
    uint32_t k = n ? hull(p, n, h) : 0;
    min_box(h, k, it->m, lo, hi);
    it->chart = index;
    it->lo[0] = lo[0];
    it->lo[1] = lo[1];
    /* lo is placed on a whole texel, so the texels touched are floor(hi - lo) + 1 wide */
    it->w = (uint32_t)(floor(hi[0] - lo[0]) + 1) + 2 * border;
    it->h = (uint32_t)(floor(hi[1] - lo[1]) + 1) + 2 * border;
    free(p);
    free(h);
    return 1;
}

static int taller_first(const void *a, const void *b)
{
    const item *x = a, *y = b;
    if (x->h != y->h)
        return x->h > y->h ? -1 : 1;
    if (x->w != y->w)
        return x->w > y->w ? -1 : 1;
    return (x->chart > y->chart) - (x->chart < y->chart);
}

/* Skyline: height of every column of the atlas. */
typedef struct atlas {
    uint32_t *sky;
    uint32_t used_w, used_h;
} atlas;

/* Lowest y where a box of width w fits at some x (leftmost among the lowest). */
static int place(const atlas *a, uint32_t size, uint32_t w, uint32_t h, uint32_t *ox, uint32_t *oy)
{
    uint32_t best_y = UINT32_MAX, best_x = 0;
    if (w > size || h > size)
        return 0;
    for (uint32_t x = 0; x + w <= size; x++) {
        uint32_t y = 0;
        for (uint32_t k = 0; k < w; k++)
            y = a->sky[x + k] > y ? a->sky[x + k] : y;
        if (y + h <= size && y < best_y) {
            best_y = y;
            best_x = x;
        }
    }
    if (best_y == UINT32_MAX)
        return 0;
    *ox = best_x;
    *oy = best_y;
    return 1;
}

void lmb_pack_result_free(lmb_pack_result *r)
{
    free(r->width);
    free(r->height);
    free(r->placements);
    memset(r, 0, sizeof *r);
}

lmb_status lmb_pack_charts(const lmb_pack_chart *charts, uint32_t count, const lmb_pack_options *opt,
                           lmb_pack_result *out, lmb_error *err)
{
    memset(out, 0, sizeof *out);
    uint32_t size = opt->max_size, border = opt->padding + 1;
    item *items = malloc(((size_t)count + 1) * sizeof *items);
    atlas *atlases = NULL;
    uint32_t na = 0;
    out->placements = calloc((size_t)count + 1, sizeof *out->placements);
    lmb_status st = (items && out->placements) ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
    for (uint32_t i = 0; st == LMB_OK && i < count; i++) {
        if (!prepare(&charts[i], i, border, &items[i]))
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
        else if (items[i].w > size || items[i].h > size)
            st = lmb_error_set(err, LMB_ERR_INPUT,
                               "chart %u is %u x %u texels with padding, larger than the maximum atlas size %u: lower "
                               "texel_density",
                               i, items[i].w, items[i].h, size);
    }
    if (st == LMB_OK)
        qsort(items, count, sizeof *items, taller_first);
    for (uint32_t i = 0; st == LMB_OK && i < count; i++) {
        item *it = &items[i];
        uint32_t x = 0, y = 0, a = 0;
        while (a < na && !place(&atlases[a], size, it->w, it->h, &x, &y))
            a++;
        if (a == na) {
            atlas *g = realloc(atlases, (na + 1) * sizeof *g);
            if (!g || !(g[na].sky = calloc(size, sizeof *g[na].sky))) {
                if (g)
                    atlases = g;
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
                break;
            }
            atlases = g;
            atlases[na].used_w = atlases[na].used_h = 0;
            na++;
            place(&atlases[a], size, it->w, it->h, &x, &y);
        }
        atlas *g = &atlases[a];
        for (uint32_t k = 0; k < it->w; k++)
            g->sky[x + k] = y + it->h;
        g->used_w = x + it->w > g->used_w ? x + it->w : g->used_w;
        g->used_h = y + it->h > g->used_h ? y + it->h : g->used_h;
        /* uv -> rotated -> shifted so lo lands exactly `border` texels into the box */
        lmb_pack_placement *p = &out->placements[it->chart];
        p->atlas = a;
        p->m[0] = it->m[0];
        p->m[1] = it->m[1];
        p->m[2] = (double)x + border - it->lo[0];
        p->m[3] = it->m[2];
        p->m[4] = it->m[3];
        p->m[5] = (double)y + border - it->lo[1];
    }
    if (st == LMB_OK) {
        out->atlas_count = na;
        out->width = malloc(((size_t)na + 1) * sizeof *out->width);
        out->height = malloc(((size_t)na + 1) * sizeof *out->height);
        if (!out->width || !out->height)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
        for (uint32_t a = 0; st == LMB_OK && a < na; a++) {
            out->width[a] = (atlases[a].used_w + 3) / 4 * 4;
            out->height[a] = (atlases[a].used_h + 3) / 4 * 4;
            out->width[a] = out->width[a] > size ? size : out->width[a];
            out->height[a] = out->height[a] > size ? size : out->height[a];
        }
    }
    for (uint32_t a = 0; a < na; a++)
        free(atlases[a].sky);
    free(atlases);
    free(items);
    if (st != LMB_OK)
        lmb_pack_result_free(out);
    return st;
}
