/*
 * Chart footprints for the packer. Each chart is turned to its minimal-area bounding box
 * (rotating calipers over the convex hull of its UVs) and placed on a whole-texel offset;
 * its footprint is every texel a triangle touches (triangle/square overlap, separating
 * axes), kept as bit masks in four quarter turns: dilated by 1 texel (what bilinear
 * filtering reads: what the atlas records) and by padding + 1 (what must not meet another
 * chart's record), so between what two charts can read lie at least `padding` texels.
 * For block-compressed atlases both masks are then taken to blocks (a block is set when any of
 * its texels is), at the sub-block offset that sets the fewest: charts placed on blocks whose
 * records never share a block keep the texel padding and never meet in a block.
 */
#include "pack_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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

void lmb_mask_free(lmb_mask *m)
{
    free(m->bits);
    free(m->first);
    free(m->last);
    free(m->run);
    free(m->solid);
    memset(m, 0, sizeof *m);
}

static int mask_alloc(lmb_mask *m, uint32_t w, uint32_t h)
{
    m->w = w;
    m->h = h;
    m->words = (w + 63) / 64;
    m->bits = calloc((size_t)m->words * h + 1, sizeof *m->bits);
    m->first = malloc(((size_t)h + 1) * sizeof *m->first);
    m->last = malloc(((size_t)h + 1) * sizeof *m->last);
    m->run = malloc(((size_t)h + 1) * sizeof *m->run);
    m->solid = malloc((size_t)h + 1);
    return m->bits && m->first && m->last && m->run && m->solid;
}

static void mask_set(lmb_mask *m, uint32_t x, uint32_t y)
{
    m->bits[(size_t)y * m->words + x / 64] |= 1ull << (x % 64);
}


/* Per row: first and last set column, the longest run of set bits and whether the set
 * bits are one run; and the row with the longest run (what the placement tests first). */
static void mask_rows(lmb_mask *m)
{
    m->widest_row = 0;
    for (uint32_t y = 0; y < m->h; y++) {
        uint32_t first = m->w, last = 0, run = 0, best = 0, runs = 0;
        for (uint32_t x = 0; x < m->w; x++)
            if (lmb_mask_bit(m, x, y)) {
                if (first == m->w)
                    first = x;
                last = x;
                runs += run == 0;
                best = ++run > best ? run : best;
            } else {
                run = 0;
            }
        m->first[y] = first;
        m->last[y] = last;
        m->run[y] = best;
        m->solid[y] = runs == 1;
        if (best > m->run[m->widest_row])
            m->widest_row = y;
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

/* The touched texels dilated by `border` (Chebyshev: rows, then columns) as a bit lmb_mask. */
static int build_mask(const uint8_t *touch, uint32_t w, uint32_t h, uint32_t border, lmb_mask *m)
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
    mask_rows(m);
    free(tmp);
    return 1;
}

/* The same lmb_mask turned 90 degrees: (x, y) -> (h - 1 - y, x). */
static int turn_mask(const lmb_mask *a, lmb_mask *b)
{
    if (!mask_alloc(b, a->h, a->w))
        return 0;
    for (uint32_t y = 0; y < a->h; y++)
        for (uint32_t x = 0; x < a->w; x++)
            if (lmb_mask_bit(a, x, y))
                mask_set(b, a->h - 1 - y, x);
    mask_rows(b);
    return 1;
}

/* Blocks of b x b texels that texel mask t, shifted by (sx, sy) texels, touches: counted
 * (out NULL) or set in out. */
static uint64_t blocks_of(const lmb_mask *t, uint32_t b, uint32_t sx, uint32_t sy, lmb_mask *out)
{
    uint32_t bw = (t->w + sx + b - 1) / b, bh = (t->h + sy + b - 1) / b;
    uint8_t *seen = calloc((size_t)bw * bh + 1, 1);
    uint64_t n = 0;
    if (!seen)
        return UINT64_MAX;
    for (uint32_t y = 0; y < t->h; y++)
        for (uint32_t x = t->first[y]; x < t->w && x <= t->last[y]; x++)
            if (lmb_mask_bit(t, x, y)) {
                size_t k = (size_t)((y + sy) / b) * bw + (x + sx) / b;
                n += !seen[k];
                seen[k] = 1;
            }
    if (out) {
        for (uint32_t y = 0; y < bh; y++)
            for (uint32_t x = 0; x < bw; x++)
                if (seen[(size_t)y * bw + x])
                    mask_set(out, x, y);
        mask_rows(out);
    }
    free(seen);
    return n;
}

/* The texel masks of item it taken to b x b blocks at the sub-block shift that touches the
 * fewest blocks (ties: the fewest recorded blocks, then the smallest shift); it->off moves by
 * that shift. 0 when out of memory. */
static int to_blocks(lmb_pack_item *it, uint32_t b)
{
    uint32_t best_x = 0, best_y = 0;
    uint64_t best_shape = UINT64_MAX, best_occ = UINT64_MAX;
    for (uint32_t sy = 0; sy < b; sy++)
        for (uint32_t sx = 0; sx < b; sx++) {
            uint64_t ns = blocks_of(&it->shape[0], b, sx, sy, NULL);
            if (ns > best_shape)
                continue;
            uint64_t no = blocks_of(&it->occ[0], b, sx, sy, NULL);
            if (ns == UINT64_MAX || no == UINT64_MAX)
                return 0;
            if (ns < best_shape || no < best_occ) {
                best_shape = ns;
                best_occ = no;
                best_x = sx;
                best_y = sy;
            }
        }
    const lmb_mask *t = &it->shape[0];
    lmb_mask shape, occ;
    memset(&shape, 0, sizeof shape);
    memset(&occ, 0, sizeof occ);
    uint32_t bw = (t->w + best_x + b - 1) / b, bh = (t->h + best_y + b - 1) / b;
    int ok = mask_alloc(&shape, bw, bh) && mask_alloc(&occ, bw, bh) &&
             blocks_of(&it->shape[0], b, best_x, best_y, &shape) != UINT64_MAX &&
             blocks_of(&it->occ[0], b, best_x, best_y, &occ) != UINT64_MAX;
    lmb_mask_free(&it->shape[0]);
    lmb_mask_free(&it->occ[0]);
    it->shape[0] = shape;
    it->occ[0] = occ;
    it->off[0] += best_x;
    it->off[1] += best_y;
    it->block = b;
    return ok;
}

/* Returns 1 when ready, 0 when out of memory, 2 when the chart's box (*bw x *bh) exceeds
 * max_size: checked before any lmb_mask is allocated. */
int lmb_pack_prepare(const lmb_pack_chart *c, uint32_t index, uint32_t border, uint32_t block, uint32_t max_size,
                     lmb_pack_item *it, double *bw, double *bh)
{
    uint32_t n = 3 * c->triangle_count;
    pt *p = malloc(((size_t)n + 1) * sizeof *p), *h = malloc(((size_t)n + 2) * sizeof *h);
    int ok = p && h;
    double hi[2];
    memset(it, 0, sizeof *it);
    it->chart = index;
    it->group = c->group;
    it->off[0] = it->off[1] = border;
    it->block = 1;
    if (ok) {
        for (uint32_t i = 0; i < n; i++) {
            p[i].x = c->uv[2 * i];
            p[i].y = c->uv[2 * i + 1];
        }
        min_box(h, n ? hull(p, n, h) : 0, it->m, it->lo, hi);
        *bw = floor(hi[0] - it->lo[0]) + 1 + 2.0 * border;
        *bh = floor(hi[1] - it->lo[1]) + 1 + 2.0 * border;
        /* with blocks, a sub-block shift may add up to block - 1 texels to either side */
        double limit = block > 1 ? (double)(max_size / block * block) - (block - 1) : (double)max_size;
        if (!(*bw <= limit && *bh <= limit)) {
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
        if (ok && block > 1)
            ok = to_blocks(it, block);
        for (int k = 1; ok && k < 4; k++)
            ok = turn_mask(&it->shape[k - 1], &it->shape[k]) && turn_mask(&it->occ[k - 1], &it->occ[k]);
        free(touch);
        for (uint32_t y = 0; ok && y < it->shape[0].h; y++)
            for (uint32_t x = 0; x < it->shape[0].w; x++)
                it->area += (uint64_t)lmb_mask_bit(&it->shape[0], x, y), it->occ_area += (uint64_t)lmb_mask_bit(&it->occ[0], x, y);
        if (ok) { /* FNV-1a over the size and the bit rows */
            const lmb_mask *m = &it->shape[0];
            uint64_t hsh = 1469598103934665603ull ^ ((uint64_t)m->w << 32 | m->h);
            for (size_t k = 0; k < (size_t)m->words * m->h; k++)
                hsh = (hsh ^ m->bits[k]) * 1099511628211ull;
            it->shape_hash = hsh;
        }
    }
    free(p);
    free(h);
    return ok;
}


void lmb_pack_chart_box(const lmb_pack_chart *c, double *w, double *h)
{
    uint32_t n = 3 * c->triangle_count;
    pt *p = malloc(((size_t)n + 1) * sizeof *p), *hl = malloc(((size_t)n + 2) * sizeof *hl);
    double m[4], lo[2], hi[2];
    *w = *h = 0;
    if (!p || !hl) {
        free(p);
        free(hl);
        return;
    }
    for (uint32_t i = 0; i < n; i++) {
        p[i].x = c->uv[2 * i];
        p[i].y = c->uv[2 * i + 1];
    }
    min_box(hl, n ? hull(p, n, hl) : 0, m, lo, hi);
    *w = hi[0] - lo[0];
    *h = hi[1] - lo[1];
    free(p);
    free(hl);
}
