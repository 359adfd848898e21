/*
 * Chart placement on texel masks (footprints: footprint.c). Bottom-left first fit on
 * 64-bit occupancy rows, largest charts first, in four quarter turns, inside a width chosen
 * from the total footprint area so the atlas grows roughly square; an atlas widens to
 * max_size before a new one is opened. Charts fill the holes and hollows others leave.
 *
 * Speed at level scale (issue 10): the search skips what cannot fit instead of testing it.
 *   - within an atlas: free runs per row and per mask row (atlas_space.c);
 *   - identical masks: a table of first fits per distinct mask and atlas (below);
 *   - atlases: one whose free area is smaller than the footprint is not searched;
 *   - groups (instances): with options.grouped all charts of a group share an atlas. A
 *     group whose footprints exceed an atlas is refused before anything is placed; one
 *     that stops fitting in its atlas is moved whole to the next (its texels are cleared:
 *     footprints never share a texel, so clearing is exact), and refused at once if it
 *     does not fit an empty one. No retry of the whole packing.
 * Deterministic: the same input gives the same output.
 */
#include "pack_internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#define NONE UINT32_MAX

static uint32_t longest_side(const lmb_pack_item *x)
{
    return x->shape[0].w > x->shape[0].h ? x->shape[0].w : x->shape[0].h;
}

/* Second order tried for small inputs: longest side first (rectangles stack better). */
static int longer_first(const void *a, const void *b)
{
    const lmb_pack_item *x = a, *y = b;
    uint32_t lx = longest_side(x), ly = longest_side(y);
    if (lx != ly)
        return lx > ly ? -1 : 1;
    if (x->area != y->area)
        return x->area > y->area ? -1 : 1;
    return (x->chart > y->chart) - (x->chart < y->chart);
}

static int larger_first(const void *a, const void *b)
{
    const lmb_pack_item *x = a, *y = b;
    if (x->area != y->area)
        return x->area > y->area ? -1 : 1;
    return (x->chart > y->chart) - (x->chart < y->chart);
}

void lmb_pack_result_free(lmb_pack_result *r)
{
    free(r->width);
    free(r->height);
    free(r->placements);
    memset(r, 0, sizeof *r);
}

/* Where each orientation of a mask first fitted in an atlas, for every distinct mask seen:
 * a lower bound in (y, x) order for a later identical mask (many identical box faces in a
 * modular level), valid while the atlas's occupancy only grows: void once a group leaves it
 * or it widens (its generation). Open addressing on (mask hash, atlas); identical masks are compared bit for bit. */
typedef struct hint {
    const lmb_pack_item *item; /* NULL: empty slot */
    uint32_t atlas, generation;
    uint32_t y[4], x[4];
    int valid[4];
} hint;

typedef struct hints {
    hint *slot;
    uint32_t cap, count; /* cap: a power of two */
} hints;

static int same_masks(const lmb_pack_item *a, const lmb_pack_item *b)
{
    const lmb_mask *p = &a->shape[0], *q = &b->shape[0]; /* the other turns follow from it */
    return a->shape_hash == b->shape_hash && p->w == q->w && p->h == q->h &&
           !memcmp(p->bits, q->bits, (size_t)p->words * p->h * sizeof *p->bits);
}

static uint32_t hint_index(const hints *h, uint64_t hash, uint32_t atlas)
{
    uint64_t k = hash ^ (atlas * 0x9E3779B97F4A7C15ull);
    k ^= k >> 29;
    return (uint32_t)(k & (h->cap - 1));
}

/* The entry for (it's mask, atlas): an existing one of the atlas's generation, or a new
 * empty one (NULL without memory). */
static hint *hint_for(hints *h, const lmb_pack_item *it, uint32_t atlas, uint32_t generation, int *found)
{
    if (2 * (h->count + 1) > h->cap) {
        uint32_t cap = h->cap ? 2 * h->cap : 1024;
        hint *slot = calloc(cap, sizeof *slot), *old = h->slot;
        if (!slot)
            return NULL;
        uint32_t old_cap = h->cap;
        h->slot = slot;
        h->cap = cap;
        for (uint32_t i = 0; i < old_cap; i++)
            if (old[i].item) {
                uint32_t j = hint_index(h, old[i].item->shape_hash, old[i].atlas);
                while (h->slot[j].item)
                    j = (j + 1) & (cap - 1);
                h->slot[j] = old[i];
            }
        free(old);
    }
    uint32_t j = hint_index(h, it->shape_hash, atlas);
    while (h->slot[j].item) {
        if (h->slot[j].atlas == atlas && same_masks(h->slot[j].item, it)) {
            *found = h->slot[j].generation == generation;
            h->slot[j].generation = generation;
            return &h->slot[j];
        }
        j = (j + 1) & (h->cap - 1);
    }
    *found = 0;
    h->count++;
    h->slot[j].item = it;
    h->slot[j].atlas = atlas;
    h->slot[j].generation = generation;
    return &h->slot[j];
}

/* Tries the four orientations in atlas a; picks the one that keeps the used area smaller. */
static int try_orientations(lmb_atlas *a, uint32_t ai, const lmb_pack_item *it, hints *hs, int *turn, uint32_t *x,
                            uint32_t *y)
{
    uint32_t bx = 0, by = 0, best = UINT32_MAX;
    if (it->occ_area > a->free_area)
        return 0;
    int use;
    hint none, *h = hint_for(hs, it, ai, a->generation, &use);
    if (!h) { /* no memory for the table: search from the start */
        memset(&none, 0, sizeof none);
        h = &none;
        use = 0;
    }
    for (int o = 0; o < 4; o++) {
        uint32_t px, py, fy = use && h->valid[o] ? h->y[o] : 0, fx = use && h->valid[o] ? h->x[o] : 0;
        if (use && !h->valid[o])
            continue; /* it did not fit before: it does not fit now */
        h->valid[o] = lmb_atlas_find(a, &it->shape[o], fy, fx, &px, &py);
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
    *x = bx;
    *y = by;
    return best != UINT32_MAX;
}

/* In atlas a, widening it to max_size before giving up. */
static int try_place(lmb_atlas *a, uint32_t ai, const lmb_pack_item *it, hints *h, int *turn, uint32_t *x, uint32_t *y)
{
    if (try_orientations(a, ai, it, h, turn, x, y))
        return 1;
    if (a->width >= a->size)
        return 0;
    lmb_atlas_widen(a);
    return try_orientations(a, ai, it, h, turn, x, y);
}

static void placement(const lmb_pack_item *it, int turn, uint32_t x, uint32_t y, uint32_t a, lmb_pack_placement *p)
{
    /* box frame: bx = m0 u + m1 v - lo0 + off0, by = m2 u + m3 v - lo1 + off1; each quarter
     * turn maps (bx, by) -> (H - by, bx), H the height before it in texels, as the footprint's
     * quarter turns map cells (cx, cy) -> (H - 1 - cy, cx), so texel squares land on texel
     * squares (and blocks on blocks: the frame is whole blocks); (x, y) is in cells */
    double r0[3] = {it->m[0], it->m[1], it->off[0] - it->lo[0]}, r1[3] = {it->m[2], it->m[3], it->off[1] - it->lo[1]};
    for (int t = 0; t < turn; t++) {
        double h = (double)it->shape[t].h * it->block, n0[3] = {-r1[0], -r1[1], h - r1[2]};
        memcpy(r1, r0, sizeof r0);
        memcpy(r0, n0, sizeof n0);
    }
    p->atlas = a;
    for (int k = 0; k < 3; k++) {
        p->m[k] = r0[k];
        p->m[3 + k] = r1[k];
    }
    p->m[2] += (double)x * it->block;
    p->m[5] += (double)y * it->block;
}

/* The state of one placement run over the sorted items. */
typedef struct placer {
    const lmb_pack_item *items;
    uint32_t count, size, width; /* in cells (texels, or blocks) */
    uint32_t block;               /* texels per cell side */
    int grouped;
    lmb_atlas *atlases;
    uint32_t atlas_count;
    uint32_t *where, *px, *py; /* per item: atlas (NONE: not placed), position */
    int *turn;
    uint32_t *group_atlas;     /* per group: its atlas or NONE */
    uint32_t *group_first, *group_items; /* items of group g: group_items[group_first[g] .. group_first[g+1]) */
    hints h;
} placer;

static int open_atlas(placer *p)
{
    lmb_atlas *g = realloc(p->atlases, (p->atlas_count + 1) * sizeof *g);
    if (!g)
        return 0;
    p->atlases = g;
    if (!lmb_atlas_open(&g[p->atlas_count], p->size, p->width)) {
        lmb_atlas_free(&g[p->atlas_count]);
        return 0;
    }
    p->atlas_count++;
    return 1;
}

static int place_in(placer *p, uint32_t i, uint32_t a)
{
    const lmb_pack_item *it = &p->items[i];
    if (!try_place(&p->atlases[a], a, it, &p->h, &p->turn[i], &p->px[i], &p->py[i]))
        return 0;
    lmb_atlas_occupy(&p->atlases[a], &it->occ[p->turn[i]], p->px[i], p->py[i], it->occ_area);
    p->where[i] = a;
    return 1;
}

static void unplace(placer *p, uint32_t i)
{
    const lmb_pack_item *it = &p->items[i];
    lmb_atlas_vacate(&p->atlases[p->where[i]], &it->occ[p->turn[i]], p->px[i], p->py[i], it->occ_area);
    p->where[i] = NONE;
}

/* Group g whole into atlas a, or nothing of it (returns 0 and leaves a as it was). */
static int place_group_in(placer *p, uint32_t g, uint32_t a)
{
    for (uint32_t k = p->group_first[g]; k < p->group_first[g + 1]; k++)
        if (!place_in(p, p->group_items[k], a)) {
            while (k-- > p->group_first[g])
                unplace(p, p->group_items[k]);
            return 0;
        }
    p->group_atlas[g] = a;
    return 1;
}

/* Moves group g (some of it placed in its atlas) whole to another atlas. LMB_ERR_INPUT if it
 * does not fit even an empty one. */
static lmb_status move_group(placer *p, uint32_t g, lmb_error *err)
{
    uint32_t from = p->group_atlas[g];
    for (uint32_t k = p->group_first[g]; k < p->group_first[g + 1]; k++)
        if (p->where[p->group_items[k]] != NONE)
            unplace(p, p->group_items[k]);
    for (uint32_t a = 0; a < p->atlas_count; a++)
        if (a != from && place_group_in(p, g, a))
            return LMB_OK;
    if (!open_atlas(p))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
    lmb_atlas_widen(&p->atlases[p->atlas_count - 1]);
    if (place_group_in(p, g, p->atlas_count - 1))
        return LMB_OK;
    return lmb_error_set(err, LMB_ERR_INPUT, "group %u does not fit in one %ux%u atlas", g, p->size * p->block,
                         p->size * p->block);
}

static lmb_status place_one(placer *p, uint32_t i, lmb_error *err)
{
    uint32_t g = p->items[i].group;
    if (p->grouped && p->group_atlas[g] != NONE)
        return place_in(p, i, p->group_atlas[g]) ? LMB_OK : move_group(p, g, err);
    for (uint32_t a = 0; a < p->atlas_count; a++)
        if (place_in(p, i, a)) {
            if (p->grouped)
                p->group_atlas[g] = a;
            return LMB_OK;
        }
    if (!open_atlas(p))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
    if (!place_in(p, i, p->atlas_count - 1)) /* prepare checked that every chart fits max_size */
        return lmb_error_set(err, LMB_ERR_INTERNAL, "pack: chart %u does not fit an empty atlas", p->items[i].chart);
    if (p->grouped)
        p->group_atlas[g] = p->atlas_count - 1;
    return LMB_OK;
}

/* Items of each group in sorted order (a counting sort, stable). */
static int index_groups(placer *p, uint32_t groups)
{
    p->group_first = calloc((size_t)groups + 2, sizeof *p->group_first);
    p->group_items = malloc(((size_t)p->count + 1) * sizeof *p->group_items);
    p->group_atlas = malloc(((size_t)groups + 1) * sizeof *p->group_atlas);
    if (!p->group_first || !p->group_items || !p->group_atlas)
        return 0;
    for (uint32_t i = 0; i < p->count; i++)
        p->group_first[p->items[i].group + 1]++;
    for (uint32_t g = 0; g < groups; g++)
        p->group_first[g + 1] += p->group_first[g];
    uint32_t *fill = malloc(((size_t)groups + 1) * sizeof *fill);
    if (!fill)
        return 0;
    memcpy(fill, p->group_first, (size_t)groups * sizeof *fill);
    for (uint32_t i = 0; i < p->count; i++)
        p->group_items[fill[p->items[i].group]++] = i;
    free(fill);
    for (uint32_t g = 0; g < groups; g++)
        p->group_atlas[g] = NONE;
    return 1;
}

/* Places the sorted items into atlases whose placement width starts at `width`; fills out
 * (placements must be allocated). On LMB_ERR_INPUT out->failed_group names the group. */
static lmb_status place_all(const lmb_pack_item *items, uint32_t count, uint32_t groups, const lmb_pack_options *opt,
                            uint32_t width, lmb_pack_result *out, lmb_error *err)
{
    placer p;
    memset(&p, 0, sizeof p);
    p.items = items;
    p.count = count;
    p.block = opt->block > 1 ? opt->block : 1;
    p.size = opt->max_size / p.block;
    p.width = width;
    p.grouped = opt->grouped;
    p.where = malloc(((size_t)count + 1) * sizeof *p.where);
    p.px = malloc(((size_t)count + 1) * sizeof *p.px);
    p.py = malloc(((size_t)count + 1) * sizeof *p.py);
    p.turn = calloc((size_t)count + 1, sizeof *p.turn);
    lmb_status st = (p.where && p.px && p.py && p.turn && (!p.grouped || index_groups(&p, groups)))
                        ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
    for (uint32_t i = 0; st == LMB_OK && i < count; i++)
        p.where[i] = NONE;
    for (uint32_t i = 0; st == LMB_OK && i < count; i++) {
        if (p.where[i] != NONE)
            continue; /* placed with its group when the group moved */
        st = place_one(&p, i, err);
        if (st == LMB_ERR_INPUT)
            out->failed_group = items[i].group;
    }
    if (st == LMB_OK) {
        uint32_t na = p.atlas_count;
        out->atlas_count = na;
        out->width = calloc((size_t)na + 1, sizeof *out->width);
        out->height = calloc((size_t)na + 1, sizeof *out->height);
        if (!out->width || !out->height)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
        for (uint32_t i = 0; st == LMB_OK && i < count; i++) { /* the extent in use: moved groups left space */
            const lmb_mask *m = &items[i].occ[p.turn[i]];
            uint32_t a = p.where[i];
            out->width[a] = p.px[i] + m->w > out->width[a] ? p.px[i] + m->w : out->width[a];
            out->height[a] = p.py[i] + m->h > out->height[a] ? p.py[i] + m->h : out->height[a];
            placement(&items[i], p.turn[i], p.px[i], p.py[i], a, &out->placements[items[i].chart]);
        }
        for (uint32_t a = 0; st == LMB_OK && a < na; a++) {
            uint32_t w = (out->width[a] * p.block + 3) / 4 * 4, h = (out->height[a] * p.block + 3) / 4 * 4;
            out->width[a] = w > opt->max_size ? opt->max_size : w;
            out->height[a] = h > opt->max_size ? opt->max_size : h;
        }
    }
    for (uint32_t a = 0; a < p.atlas_count; a++)
        lmb_atlas_free(&p.atlases[a]);
    free(p.atlases);
    free(p.where);
    free(p.px);
    free(p.py);
    free(p.turn);
    free(p.group_atlas);
    free(p.group_first);
    free(p.group_items);
    free(p.h.slot);
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

/* Before placing anything: a group whose footprints hold more texels than an atlas cannot
 * fit one (footprints never share a texel). Returns the group or NONE. */
static uint32_t oversized_group(const lmb_pack_item *items, uint32_t count, uint32_t groups, uint32_t size)
{
    uint64_t *area = calloc((size_t)groups + 1, sizeof *area);
    uint32_t bad = NONE;
    if (!area)
        return NONE;
    for (uint32_t i = 0; i < count; i++)
        area[items[i].group] += items[i].occ_area;
    for (uint32_t g = 0; g < groups && bad == NONE; g++)
        if (area[g] > (uint64_t)size * size)
            bad = g;
    free(area);
    return bad;
}

static lmb_status pack_texels(const lmb_pack_chart *charts, uint32_t count, const lmb_pack_options *opt,
                              lmb_pack_result *out, lmb_error *err)
{
    memset(out, 0, sizeof *out);
    out->failed_group = out->failed_chart = NONE;
    uint32_t block = opt->block > 1 ? opt->block : 1, size = opt->max_size, border = opt->padding + 1;
    uint32_t cells = size / block, prepared = 0, groups = 0; /* cells: the atlas side in mask cells */
    lmb_pack_item *items = calloc((size_t)count + 1, sizeof *items);
    out->placements = calloc((size_t)count + 1, sizeof *out->placements);
    lmb_status st = (items && out->placements) ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
    uint64_t total = 0;
    /* every chart's footprint masks at once (the work, and independent); then, in chart order,
     * the first chart that failed and the totals, as one thread would find them */
    int *ready = st == LMB_OK ? malloc(((size_t)count + 1) * sizeof *ready) : NULL;
    double *box = st == LMB_OK ? malloc((2 * (size_t)count + 1) * sizeof *box) : NULL;
    if (st == LMB_OK && (!ready || !box))
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
    int threads = opt->threads ? (int)opt->threads : omp_get_max_threads();
    uint32_t to_prepare = st == LMB_OK ? count : 0;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16)
    for (uint32_t i = 0; i < to_prepare; i++) {
        box[2 * i] = box[2 * i + 1] = 0;
        ready[i] = lmb_pack_prepare(&charts[i], i, border, block, size, &items[i], &box[2 * i], &box[2 * i + 1]);
    }
    if (st == LMB_OK) /* all are prepared: all are freed at the end */
        prepared = count;
    for (uint32_t i = 0; st == LMB_OK && i < count; i++) {
        double bw = box[2 * i], bh = box[2 * i + 1];
        int r = ready[i];
        if (opt->grouped)
            groups = charts[i].group + 1 > groups ? charts[i].group + 1 : groups;
        else
            items[i].group = 0;
        if (r == 0)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
        else if (r == 2) {
            out->failed_chart = i;
            out->failed_group = charts[i].group;
            st = lmb_error_set(err, LMB_ERR_INPUT,
                               "chart %u is %.0f x %.0f texels with padding, larger than the maximum atlas size %u: "
                               "lower texel_density",
                               i, bw, bh, size);
        }
        total += items[i].area;
    }
    free(ready);
    free(box);
    uint32_t bad = st == LMB_OK && opt->grouped ? oversized_group(items, count, groups, cells) : NONE;
    if (bad != NONE) {
        out->failed_group = bad;
        st = lmb_error_set(err, LMB_ERR_INPUT, "group %u does not fit in one %ux%u atlas (its footprints alone "
                           "cover more texels)", bad, size, size);
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
        width = width > cells ? cells : width;
        lmb_pack_result r;
        memset(&r, 0, sizeof r);
        r.placements = calloc((size_t)count + 1, sizeof *r.placements);
        st = r.placements ? place_all(items, count, groups, opt, width, &r, err)
                          : lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
        if (st == LMB_ERR_INPUT)
            out->failed_group = r.failed_group;
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
        out->failed_group = out->failed_chart = NONE;
    } else {
        lmb_pack_result_free(&best);
    }
    for (uint32_t i = 0; i < prepared; i++) {
        for (int o = 0; o < 4; o++) {
            lmb_mask_free(&items[i].shape[o]);
            lmb_mask_free(&items[i].occ[o]);
        }
    }
    free(items);
    if (st != LMB_OK) {
        uint32_t g = out->failed_group, c = out->failed_chart;
        lmb_pack_result_free(out);
        out->failed_group = g;
        out->failed_chart = c;
    }
    return st;
}

/* With opt->block > 1 the masks' cells are blocks (footprint.c): charts land on the block grid
 * and no block holds texels of two charts' records, which stay `padding` texels apart. */
lmb_status lmb_pack_charts(const lmb_pack_chart *charts, uint32_t count, const lmb_pack_options *opt,
                           lmb_pack_result *out, lmb_error *err)
{
    return pack_texels(charts, count, opt, out, err);
}

uint32_t lmb_pack_block_for(const lmb_config *cfg)
{
    int blocks = cfg->ktx2_format == LMB_KTX2_BC6H || cfg->ktx2_format == LMB_KTX2_ASTC_HDR;
    return (cfg->output_formats & LMB_OUTPUT_KTX2) && blocks ? 4 : 1;
}
