/* Rectangles on shelves (see rects.h). */
#include "rects.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void lmb_rect_result_free(lmb_rect_result *r)
{
    free(r->width);
    free(r->height);
    free(r->atlas);
    free(r->x);
    free(r->y);
    memset(r, 0, sizeof *r);
}

typedef struct shelf_state {
    uint32_t cx, cy, shelf, used_w; /* cursor, current shelf's height, widest row so far */
} shelf_state;

/* x rounded up to a multiple of block */
static uint32_t on_grid(uint32_t x, uint32_t block)
{
    return (x + block - 1) / block * block;
}

/* Places items order[from..to) (one group) from state s in an atlas W wide and max_size high;
 * 0 if one does not fit (s is then unspecified). */
static int place_group(const lmb_rect_item *items, const uint32_t *order, uint32_t from, uint32_t to, uint32_t W,
                       uint32_t max_size, uint32_t padding, uint32_t block, shelf_state *s, uint32_t *x, uint32_t *y)
{
    for (uint32_t j = from; j < to; j++) {
        const lmb_rect_item *it = &items[order[j]];
        if (it->w > W || it->h > max_size)
            return 0;
        if (s->cx > 0 && s->cx + it->w > W) { /* next shelf */
            s->cy = on_grid(s->cy + s->shelf + padding, block);
            s->cx = s->shelf = 0;
        }
        if (s->cy + it->h > max_size)
            return 0;
        x[order[j]] = s->cx;
        y[order[j]] = s->cy;
        s->used_w = s->cx + it->w > s->used_w ? s->cx + it->w : s->used_w;
        s->cx = on_grid(s->cx + it->w + padding, block);
        s->shelf = it->h > s->shelf ? it->h : s->shelf;
    }
    return 1;
}

lmb_status lmb_place_rects(const lmb_rect_item *items, uint32_t n, uint32_t padding, uint32_t block,
                           uint32_t max_size, lmb_rect_result *out, lmb_error *err)
{
    block = block > 1 ? block : 1;
    memset(out, 0, sizeof *out);
    out->failed_group = UINT32_MAX;
    uint32_t *order = malloc(((size_t)n + 1) * sizeof *order);
    out->width = malloc(((size_t)n + 1) * sizeof *out->width);
    out->height = malloc(((size_t)n + 1) * sizeof *out->height);
    out->atlas = malloc(((size_t)n + 1) * sizeof *out->atlas);
    out->x = malloc(((size_t)n + 1) * sizeof *out->x);
    out->y = malloc(((size_t)n + 1) * sizeof *out->y);
    if (!order || !out->width || !out->height || !out->atlas || !out->x || !out->y) {
        free(order);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "rectangles: out of memory");
    }
    double area = 0;
    uint32_t widest = 0;
    for (uint32_t k = 0; k < n; k++) {
        order[k] = k;
        area += ((double)items[k].w + padding) * ((double)items[k].h + padding);
        widest = items[k].w > widest ? items[k].w : widest;
    }
    /* within each group's run, tallest first (insertion sort: stable, deterministic) */
    for (uint32_t k = 1; k < n; k++)
        for (uint32_t j = k; j > 0 && items[order[j - 1]].group == items[order[j]].group &&
                             items[order[j - 1]].h < items[order[j]].h; j--) {
            uint32_t t = order[j];
            order[j] = order[j - 1];
            order[j - 1] = t;
        }
    double w = ceil(sqrt(area) / 4) * 4;
    uint32_t W = w > max_size ? max_size : w < widest ? widest : (uint32_t)w;
    shelf_state s = {0, 0, 0, 0};
    uint32_t a = 0;
    lmb_status st = LMB_OK;
    for (uint32_t from = 0; from < n && st == LMB_OK;) {
        uint32_t to = from + 1;
        while (to < n && items[order[to]].group == items[order[from]].group)
            to++;
        shelf_state saved = s;
        if (!place_group(items, order, from, to, W, max_size, padding, block, &s, out->x, out->y)) {
            int empty = saved.cx == 0 && saved.cy == 0;
            s = (shelf_state){0, 0, 0, 0};
            if (!empty) { /* close the atlas, retry in a new one */
                out->width[a] = saved.used_w;
                out->height[a] = saved.cy + saved.shelf;
                a++;
            }
            if (!place_group(items, order, from, to, W, max_size, padding, block, &s, out->x, out->y)) {
                out->failed_group = items[order[from]].group;
                st = lmb_error_set(err, LMB_ERR_INPUT, "rectangles of group %u do not fit one %ux%u atlas",
                                   out->failed_group, max_size, max_size);
                break;
            }
        }
        for (uint32_t j = from; j < to; j++)
            out->atlas[order[j]] = a;
        from = to;
    }
    if (st == LMB_OK && n) {
        out->width[a] = s.used_w;
        out->height[a] = s.cy + s.shelf;
        out->atlas_count = a + 1;
    }
    for (uint32_t k = 0; k < out->atlas_count; k++) { /* multiples of 4, as packed atlases */
        out->width[k] = (out->width[k] + 3) / 4 * 4;
        out->height[k] = (out->height[k] + 3) / 4 * 4;
    }
    free(order);
    return st;
}
