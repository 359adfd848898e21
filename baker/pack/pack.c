/*
 * Chart packing on texel masks. Each chart is turned to its minimal-area bounding box
 * (rotating calipers over the convex hull of its UVs) and placed on a whole-texel offset;
 * its footprint is every texel a triangle touches (triangle/square overlap, separating
 * axes). The atlas records footprints dilated by 1 texel (what bilinear filtering reads);
 * a new chart's footprint dilated by padding + 1 must not meet them (Chebyshev distances),
 * so between what two charts can read lie at least `padding` untouched texels, and no
 * texel is reachable from two charts.
 * Placement is bottom-left first fit on 64-bit occupancy rows, largest charts first, in
 * both orientations (0 and 90 degrees), inside a width chosen from the total footprint
 * area so the atlas grows roughly square; an atlas widens to max_size before a new one is
 * opened. Charts fill the holes and hollows other charts leave. Deterministic.
 */
#include "pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct pt {
    double x, y;
} pt;

/* A chart's footprint in one orientation: w x h texels, bit rows of `words` words. */
typedef struct mask {
    uint32_t w, h, words;
    uint64_t *bits;
    uint32_t *first; /* per row: first set column, or w if none */
} mask;

typedef struct item {
    uint32_t chart;
    double m[4];  /* rotation chart uv -> box frame */
    double lo[2]; /* rotated bounds: lo placed at (border, border) */
    mask shape[4]; /* footprint dilated by padding + 1, tested against the atlas; k: turned k x 90 degrees */
    mask occ[4];   /* footprint dilated by 1 (the bilinear reach), what the atlas records */
    uint64_t area;
} item;

typedef struct atlas {
    uint32_t size, words, width; /* width: the part in use for placement */
    uint64_t *rows;
    uint32_t *free_from; /* per row: every column before it is occupied */
    uint32_t used_w, used_h;
    uint32_t open_row;   /* rows below it are full up to `width` (a chart's first row has texels) */
} atlas;

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

/* Andrew's monotone chain; out needs n + 1 entries. */
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
    lo[0] = lo[1] = hi[0] = hi[1] = 0;
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
            memcpy(lo, a, 2 * sizeof *a);
            memcpy(hi, b, 2 * sizeof *b);
        }
    }
}

/* Does triangle t (3 points) overlap the open square (x, y)-(x+1, y+1)? Separating axes:
 * the square's axes (bounding boxes) and the triangle's three edge normals. */
static int overlaps_square(const pt *t, double x, double y)
{
    double mnx = fmin(t[0].x, fmin(t[1].x, t[2].x)), mxx = fmax(t[0].x, fmax(t[1].x, t[2].x));
    double mny = fmin(t[0].y, fmin(t[1].y, t[2].y)), mxy = fmax(t[0].y, fmax(t[1].y, t[2].y));
    if (mxx <= x || mnx >= x + 1 || mxy <= y || mny >= y + 1)
        return 0;
    const pt sq[4] = {{x, y}, {x + 1, y}, {x + 1, y + 1}, {x, y + 1}};
    for (int e = 0; e < 3; e++) {
        pt a = t[e], b = t[(e + 1) % 3], o = t[(e + 2) % 3];
        double nx = -(b.y - a.y), ny = b.x - a.x;
        double side = nx * (o.x - a.x) + ny * (o.y - a.y); /* the triangle's side of the edge */
        int all_out = 1;
        for (int k = 0; k < 4 && all_out; k++) {
            double d = nx * (sq[k].x - a.x) + ny * (sq[k].y - a.y);
            all_out = side > 0 ? d <= 0 : d >= 0;
        }
        if (all_out && side != 0)
            return 0;
    }
    return 1;
}

static void mask_free(mask *m)
{
    free(m->bits);
    free(m->first);
    memset(m, 0, sizeof *m);
}

static int mask_alloc(mask *m, uint32_t w, uint32_t h)
{
    m->w = w;
    m->h = h;
    m->words = (w + 63) / 64;
    m->bits = calloc((size_t)m->words * h + 1, sizeof *m->bits);
    m->first = malloc(((size_t)h + 1) * sizeof *m->first);
    return m->bits && m->first;
}

static void mask_set(mask *m, uint32_t x, uint32_t y)
{
    m->bits[(size_t)y * m->words + x / 64] |= 1ull << (x % 64);
}

static int mask_get(const mask *m, uint32_t x, uint32_t y)
{
    return (int)(m->bits[(size_t)y * m->words + x / 64] >> (x % 64) & 1);
}

static void mask_first(mask *m)
{
    for (uint32_t y = 0; y < m->h; y++) {
        m->first[y] = m->w;
        for (uint32_t x = 0; x < m->w; x++)
            if (mask_get(m, x, y)) {
                m->first[y] = x;
                break;
            }
    }
}

/* Texels a chart (rotated and shifted; 3 points per triangle) touches, as bytes. */
static uint8_t *touched(const pt *tri, uint32_t n, uint32_t w, uint32_t h)
{
    uint8_t *touch = calloc((size_t)w * h + 1, 1);
    if (!touch)
        return NULL;
    for (uint32_t f = 0; f < n; f++) {
        const pt *t = tri + 3 * f;
        long x0 = (long)floor(fmin(t[0].x, fmin(t[1].x, t[2].x))), x1 = (long)floor(fmax(t[0].x, fmax(t[1].x, t[2].x)));
        long y0 = (long)floor(fmin(t[0].y, fmin(t[1].y, t[2].y))), y1 = (long)floor(fmax(t[0].y, fmax(t[1].y, t[2].y)));
        for (long y = y0 < 0 ? 0 : y0; y <= y1 && y < (long)h; y++)
            for (long x = x0 < 0 ? 0 : x0; x <= x1 && x < (long)w; x++)
                if (!touch[(size_t)y * w + (size_t)x] && overlaps_square(t, (double)x, (double)y))
                    touch[(size_t)y * w + (size_t)x] = 1;
    }
    return touch;
}

/* The touched texels dilated by `border` (Chebyshev: rows, then columns) as a bit mask. */
static int build_mask(const uint8_t *touch, uint32_t w, uint32_t h, uint32_t border, mask *m)
{
    uint8_t *tmp = calloc((size_t)w * h + 1, 1);
    if (!tmp || !mask_alloc(m, w, h)) {
        free(tmp);
        return 0;
    }
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++)
            if (touch[(size_t)y * w + x])
                for (long d = -(long)border; d <= (long)border; d++)
                    if ((long)x + d >= 0 && (long)x + d < (long)w)
                        tmp[(size_t)y * w + (size_t)((long)x + d)] = 1;
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++)
            if (tmp[(size_t)y * w + x])
                for (long d = -(long)border; d <= (long)border; d++)
                    if ((long)y + d >= 0 && (long)y + d < (long)h)
                        mask_set(m, x, (uint32_t)((long)y + d));
    mask_first(m);
    free(tmp);
    return 1;
}

/* The same mask turned 90 degrees: (x, y) -> (h - 1 - y, x). */
static int turn_mask(const mask *a, mask *b)
{
    if (!mask_alloc(b, a->h, a->w))
        return 0;
    for (uint32_t y = 0; y < a->h; y++)
        for (uint32_t x = 0; x < a->w; x++)
            if (mask_get(a, x, y))
                mask_set(b, a->h - 1 - y, x);
    mask_first(b);
    return 1;
}

/* Returns 1 when ready, 0 when out of memory, 2 when the chart's box (*bw x *bh) exceeds
 * max_size: checked before any mask is allocated. */
static int prepare(const lmb_pack_chart *c, uint32_t index, uint32_t border, uint32_t max_size, item *it,
                   double *bw, double *bh)
{
    uint32_t n = 3 * c->triangle_count;
    pt *p = malloc(((size_t)n + 1) * sizeof *p), *h = malloc(((size_t)n + 2) * sizeof *h);
    int ok = p && h;
    double hi[2];
    memset(it, 0, sizeof *it);
    it->chart = index;
    if (ok) {
        for (uint32_t i = 0; i < n; i++) {
            p[i].x = c->uv[2 * i];
            p[i].y = c->uv[2 * i + 1];
        }
        min_box(h, n ? hull(p, n, h) : 0, it->m, it->lo, hi);
        *bw = floor(hi[0] - it->lo[0]) + 1 + 2.0 * border;
        *bh = floor(hi[1] - it->lo[1]) + 1 + 2.0 * border;
        if (!(*bw <= max_size && *bh <= max_size)) {
            free(p);
            free(h);
            return 2;
        }
        uint32_t w = (uint32_t)*bw, hh = (uint32_t)*bh;
        for (uint32_t i = 0; i < n; i++) { /* the chart in its box frame, lo at (border, border) */
            double u = c->uv[2 * i], v = c->uv[2 * i + 1];
            p[i].x = it->m[0] * u + it->m[1] * v - it->lo[0] + border;
            p[i].y = it->m[2] * u + it->m[3] * v - it->lo[1] + border;
        }
        uint8_t *touch = touched(p, c->triangle_count, w, hh);
        ok = touch && build_mask(touch, w, hh, border, &it->shape[0]) && build_mask(touch, w, hh, 1, &it->occ[0]);
        for (int k = 1; ok && k < 4; k++)
            ok = turn_mask(&it->shape[k - 1], &it->shape[k]) && turn_mask(&it->occ[k - 1], &it->occ[k]);
        free(touch);
        for (uint32_t y = 0; ok && y < hh; y++)
            for (uint32_t x = 0; x < w; x++)
                it->area += (uint64_t)mask_get(&it->shape[0], x, y);
    }
    free(p);
    free(h);
    return ok;
}

static uint32_t longest_side(const item *x)
{
    return x->shape[0].w > x->shape[0].h ? x->shape[0].w : x->shape[0].h;
}

/* Second order tried for small inputs: longest side first (rectangles stack better). */
static int longer_first(const void *a, const void *b)
{
    const item *x = a, *y = b;
    uint32_t lx = longest_side(x), ly = longest_side(y);
    if (lx != ly)
        return lx > ly ? -1 : 1;
    if (x->area != y->area)
        return x->area > y->area ? -1 : 1;
    return (x->chart > y->chart) - (x->chart < y->chart);
}

static int larger_first(const void *a, const void *b)
{
    const item *x = a, *y = b;
    if (x->area != y->area)
        return x->area > y->area ? -1 : 1;
    return (x->chart > y->chart) - (x->chart < y->chart);
}

/* 64 atlas bits of row y starting at column x. */
static uint64_t window(const atlas *a, uint32_t y, uint32_t x)
{
    const uint64_t *row = a->rows + (size_t)y * a->words;
    uint32_t w = x / 64, s = x % 64;
    uint64_t lo = row[w], hi = w + 1 < a->words ? row[w + 1] : 0;
    return s ? (lo >> s) | (hi << (64 - s)) : lo;
}

static int fits(const atlas *a, const mask *m, uint32_t x, uint32_t y)
{
    for (uint32_t r = 0; r < m->h; r++) {
        const uint64_t *mr = m->bits + (size_t)r * m->words;
        for (uint32_t k = 0; k < m->words; k++)
            if (mr[k] && (window(a, y + r, x + 64 * k) & mr[k]))
                return 0;
    }
    return 1;
}

/* Bottom-left first fit inside a->width; returns 1 with (x, y). */
/* (from_y, from_x): no position before it in (y, x) order can fit (the first fit of an
 * identical mask found earlier: occupancy only grows). */
static int find(atlas *a, const mask *m, uint32_t from_y, uint32_t from_x, uint32_t *ox, uint32_t *oy)
{
    if (m->w > a->width || m->h > a->size)
        return 0;
    while (a->open_row < a->size && a->free_from[a->open_row] >= a->width)
        a->open_row++;
    if (from_y < a->open_row) {
        from_y = a->open_row;
        from_x = 0;
    }
    for (uint32_t y = from_y; y + m->h <= a->size; y++) {
        uint32_t start = y == from_y ? from_x : 0;
        for (uint32_t r = 0; r < m->h; r++) /* columns before free_from are taken in that row */
            if (m->first[r] < m->w && a->free_from[y + r] > m->first[r] && a->free_from[y + r] - m->first[r] > start)
                start = a->free_from[y + r] - m->first[r];
        for (uint32_t x = start; x + m->w <= a->width; x++)
            if (fits(a, m, x, y)) {
                *ox = x;
                *oy = y;
                return 1;
            }
    }
    return 0;
}

static void occupy(atlas *a, const mask *m, uint32_t x, uint32_t y)
{
    for (uint32_t r = 0; r < m->h; r++) {
        uint64_t *row = a->rows + (size_t)(y + r) * a->words;
        for (uint32_t c = 0; c < m->w; c++)
            if (mask_get(m, c, r))
                row[(x + c) / 64] |= 1ull << ((x + c) % 64);
        uint32_t f = a->free_from[y + r];
        while (f < a->size && (row[f / 64] >> (f % 64) & 1))
            f++;
        a->free_from[y + r] = f;
    }
    a->used_w = x + m->w > a->used_w ? x + m->w : a->used_w;
    a->used_h = y + m->h > a->used_h ? y + m->h : a->used_h;
}

static int atlas_open(atlas *a, uint32_t size, uint32_t width)
{
    memset(a, 0, sizeof *a);
    a->size = size;
    a->words = (size + 63) / 64 + 1;
    a->width = width;
    a->rows = calloc((size_t)a->words * size + 1, sizeof *a->rows);
    a->free_from = calloc((size_t)size + 1, sizeof *a->free_from);
    return a->rows && a->free_from;
}

void lmb_pack_result_free(lmb_pack_result *r)
{
    free(r->width);
    free(r->height);
    free(r->placements);
    memset(r, 0, sizeof *r);
}

/* Where each orientation of the previous chart first fitted in an atlas: a lower bound for
 * the next chart when its masks are the same (many identical cube faces, say). */
typedef struct hint {
    const item *prev;
    uint32_t atlas;
    uint32_t y[4], x[4];
    int valid[4];
} hint;

static int same_masks(const item *a, const item *b)
{
    for (int o = 0; o < 4; o++) {
        const mask *p = &a->shape[o], *q = &b->shape[o];
        if (p->w != q->w || p->h != q->h || memcmp(p->bits, q->bits, (size_t)p->words * p->h * sizeof *p->bits))
            return 0;
    }
    return 1;
}

/* Tries the four orientations in atlas a; picks the one that keeps the used area smaller. */
static int try_place(atlas *a, uint32_t ai, const item *it, hint *h, int *turn, uint32_t *x, uint32_t *y)
{
    uint32_t bx = 0, by = 0, best = UINT32_MAX;
    int use = h->prev && h->atlas == ai && same_masks(h->prev, it);
    for (int o = 0; o < 4; o++) {
        uint32_t px, py, fy = use && h->valid[o] ? h->y[o] : 0, fx = use && h->valid[o] ? h->x[o] : 0;
        if (use && !h->valid[o])
            continue; /* it did not fit before: it does not fit now */
        h->valid[o] = find(a, &it->shape[o], fy, fx, &px, &py);
        if (!h->valid[o])
            continue;
        h->y[o] = py;
        h->x[o] = px;
        uint32_t w = px + it->shape[o].w > a->used_w ? px + it->shape[o].w : a->used_w;
        uint32_t hh = py + it->shape[o].h > a->used_h ? py + it->shape[o].h : a->used_h;
        uint32_t score = w > hh ? w : hh;
        if (score < best) {
            best = score;
            *turn = o;
            bx = px;
            by = py;
        }
    }
    h->prev = it;
    h->atlas = ai;
    *x = bx;
    *y = by;
    return best != UINT32_MAX;
}

static void placement(const item *it, int turn, uint32_t x, uint32_t y, uint32_t border, uint32_t a,
                      lmb_pack_placement *p)
{
    /* box frame: bx = m0 u + m1 v - lo0 + border, by = m2 u + m3 v - lo1 + border; each quarter
     * turn maps (bx, by) -> (H - by, bx), H the height before it, as turn_mask maps texels
     * (cx, cy) -> (H - 1 - cy, cx), so texel squares land on texel squares */
    double r0[3] = {it->m[0], it->m[1], border - it->lo[0]}, r1[3] = {it->m[2], it->m[3], border - it->lo[1]};
    for (int t = 0; t < turn; t++) {
        double h = it->shape[t].h, n0[3] = {-r1[0], -r1[1], h - r1[2]};
        memcpy(r1, r0, sizeof r0);
        memcpy(r0, n0, sizeof n0);
    }
    p->atlas = a;
    for (int k = 0; k < 3; k++) {
        p->m[k] = r0[k];
        p->m[3 + k] = r1[k];
    }
    p->m[2] += x;
    p->m[5] += y;
}

/* Places the sorted items into atlases whose placement width starts at `width`; fills
 * out (placements must be allocated). */
static lmb_status place_all(const item *items, uint32_t count, uint32_t size, uint32_t border, uint32_t width,
                            lmb_pack_result *out, lmb_error *err)
{
    atlas *atlases = NULL;
    uint32_t na = 0;
    lmb_status st = LMB_OK;
    hint h;
    memset(&h, 0, sizeof h);
    for (uint32_t i = 0; st == LMB_OK && i < count; i++) {
        const item *it = &items[i];
        uint32_t x = 0, y = 0, a = 0;
        int turn = 0, placed = 0;
        for (a = 0; a < na && !placed; a++) {
            placed = try_place(&atlases[a], a, it, &h, &turn, &x, &y);
            if (!placed && atlases[a].width < size) { /* widen before giving up on it */
                atlases[a].width = size;
                atlases[a].open_row = 0;
                h.prev = NULL;
                placed = try_place(&atlases[a], a, it, &h, &turn, &x, &y);
            }
            if (placed)
                break;
        }
        if (!placed) {
            atlas *g = realloc(atlases, (na + 1) * sizeof *g);
            if (!g || !atlas_open(&g[na], size, width)) {
                if (g) {
                    atlases = g;
                    na++;
                }
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
                break;
            }
            atlases = g;
            a = na++;
            h.prev = NULL;
            if (!try_place(&atlases[a], a, it, &h, &turn, &x, &y)) {
                atlases[a].width = size;
                atlases[a].open_row = 0;
                h.prev = NULL;
                try_place(&atlases[a], a, it, &h, &turn, &x, &y);
            }
        }
        occupy(&atlases[a], &it->occ[turn], x, y);
        placement(it, turn, x, y, border, a, &out->placements[it->chart]);
    }
    if (st == LMB_OK) {
        out->atlas_count = na;
        out->width = malloc(((size_t)na + 1) * sizeof *out->width);
        out->height = malloc(((size_t)na + 1) * sizeof *out->height);
        if (!out->width || !out->height)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
        for (uint32_t a = 0; st == LMB_OK && a < na; a++) {
            uint32_t w = (atlases[a].used_w + 3) / 4 * 4, h = (atlases[a].used_h + 3) / 4 * 4;
            out->width[a] = w > size ? size : w;
            out->height[a] = h > size ? size : h;
        }
    }
    for (uint32_t a = 0; a < na; a++) {
        free(atlases[a].rows);
        free(atlases[a].free_from);
    }
    free(atlases);
    return st;
}

/* Total texels of a result's atlases, the last one counted at its cropped size. */
static uint64_t result_area(const lmb_pack_result *r)
{
    uint64_t a = 0;
    for (uint32_t i = 0; i < r->atlas_count; i++)
        a += (uint64_t)r->width[i] * r->height[i];
    return a;
}

lmb_status lmb_pack_charts(const lmb_pack_chart *charts, uint32_t count, const lmb_pack_options *opt,
                           lmb_pack_result *out, lmb_error *err)
{
    memset(out, 0, sizeof *out);
    uint32_t size = opt->max_size, border = opt->padding + 1, prepared = 0;
    item *items = calloc((size_t)count + 1, sizeof *items);
    out->placements = calloc((size_t)count + 1, sizeof *out->placements);
    lmb_status st = (items && out->placements) ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
    uint64_t total = 0;
    for (uint32_t i = 0; st == LMB_OK && i < count; i++, prepared++) {
        double bw = 0, bh = 0;
        int r = prepare(&charts[i], i, border, size, &items[i], &bw, &bh);
        if (r == 0)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
        else if (r == 2)
            st = lmb_error_set(err, LMB_ERR_INPUT,
                               "chart %u is %.0f x %.0f texels with padding, larger than the maximum atlas size %u: "
                               "lower texel_density",
                               i, bw, bh, size);
        total += items[i].area;
    }
    /* orders and placement widths to try: squares holding the footprints with some slack (a
     * few for small inputs, where packing is cheap and the choice matters most), at least the
     * widest chart; the result with fewest atlases, then least area, wins */
    static const double slack[] = {1.0, 1.16, 1.4, 1.08, 1.25, 1.6};
    static int (*const orders[])(const void *, const void *) = {larger_first, longer_first};
    uint32_t widest = 0, tries = count <= 50 ? 6 : count <= 300 ? 3 : 1, norders = count <= 300 ? 2 : 1;
    for (uint32_t i = 0; i < count; i++)
        widest = items[i].shape[0].w > widest ? items[i].shape[0].w : widest;
    lmb_pack_result best;
    memset(&best, 0, sizeof best);
    for (uint32_t k = 0; st == LMB_OK && k < tries * norders; k++) {
        if (k % tries == 0)
            qsort(items, count, sizeof *items, orders[k / tries]);
        uint32_t width = (uint32_t)ceil(sqrt((double)total * 1.05) * slack[k % tries]);
        width = width < widest ? widest : width;
        width = width > size ? size : width;
        lmb_pack_result r;
        memset(&r, 0, sizeof r);
        r.placements = calloc((size_t)count + 1, sizeof *r.placements);
        st = r.placements ? place_all(items, count, size, border, width, &r, err)
                          : lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
        if (st == LMB_OK && (k == 0 || r.atlas_count < best.atlas_count ||
                             (r.atlas_count == best.atlas_count && result_area(&r) < result_area(&best)))) {
            lmb_pack_result_free(&best);
            best = r;
        } else {
            lmb_pack_result_free(&r);
        }
    }
    if (st == LMB_OK) {
        free(out->placements);
        *out = best;
    } else {
        lmb_pack_result_free(&best);
    }
    for (uint32_t i = 0; i < prepared; i++) {
        for (int o = 0; o < 4; o++) {
            mask_free(&items[i].shape[o]);
            mask_free(&items[i].occ[o]);
        }
    }
    free(items);
    if (st != LMB_OK)
        lmb_pack_result_free(out);
    return st;
}
