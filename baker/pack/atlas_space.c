/*
 * Atlas occupancy for the packer (see pack_internal.h): 64-bit occupancy rows, bottom-left
 * first fit of a footprint mask, and what makes the search fast at level scale (issue 10):
 *   - rows: each atlas row keeps its longest free run; a position whose rows lack the runs
 *     the mask's rows need is skipped without looking at bits;
 *   - columns: per mask row that is one run, the next free run long enough is found a word
 *     at a time, and the rows' constraints move x right until they agree; a collision with
 *     such a row moves x past the occupied texel at once.
 * Footprints never share a texel, so clearing one (vacate) is exact.
 */
#include "pack_internal.h"

#include <stdlib.h>
#include <string.h>

/* 64 atlas bits of row y starting at column x. */
static uint64_t window(const lmb_atlas *a, uint32_t y, uint32_t x)
{
    const uint64_t *row = a->rows + (size_t)y * a->words;
    uint32_t w = x / 64, s = x % 64;
    uint64_t lo = row[w], hi = w + 1 < a->words ? row[w + 1] : 0;
    return s ? (lo >> s) | (hi << (64 - s)) : lo;
}

/* Longest run of free texels in row y before a->width. */
static uint32_t row_max_run(const lmb_atlas *a, uint32_t y)
{
    const uint64_t *row = a->rows + (size_t)y * a->words;
    uint32_t best = 0, cur = 0;
    for (uint32_t w = 0; 64 * w < a->width; w++) {
        uint32_t nb = a->width - 64 * w < 64 ? a->width - 64 * w : 64;
        uint64_t bits = row[w] | (nb < 64 ? ~0ull << nb : 0);
        if (bits == 0) {
            cur += 64;
            continue;
        }
        for (uint32_t b = 0; b < 64; b++) {
            if (bits >> b & 1) {
                best = cur > best ? cur : best;
                cur = 0;
            } else {
                cur++;
            }
        }
    }
    return cur > best ? cur : best;
}

/* 0 when m fits at (x, y); else the next column worth trying (> x). */
static uint32_t collides(const lmb_atlas *a, const lmb_mask *m, uint32_t x, uint32_t y)
{
    for (uint32_t r = 0; r < m->h; r++) {
        const uint64_t *mr = m->bits + (size_t)r * m->words;
        for (uint32_t k = 0; k < m->words; k++) {
            uint64_t hit = mr[k] ? window(a, y + r, x + 64 * k) & mr[k] : 0;
            if (!hit)
                continue;
            if (!m->solid[r])
                return x + 1;
            /* the rightmost occupied texel under this run: every shift that keeps it under the run collides */
            uint32_t c = x + 64 * k + 63 - (uint32_t)__builtin_clzll(hit);
            return c - m->first[r] + 1;
        }
    }
    return 0;
}

/* The first column p >= from where row y has `len` free texels [p, p + len) before `limit`,
 * or UINT32_MAX: alternately skips occupied and free runs a word at a time. */
static uint32_t next_free_run(const lmb_atlas *a, uint32_t y, uint32_t from, uint32_t len, uint32_t limit)
{
    const uint64_t *row = a->rows + (size_t)y * a->words;
    uint32_t p = from;
    while (p + len <= limit) {
        /* skip occupied texels: the first zero bit at or after p */
        uint64_t inv = ~row[p / 64] >> (p % 64);
        while (!inv) {
            p = (p / 64 + 1) * 64;
            if (p + len > limit)
                return UINT32_MAX;
            inv = ~row[p / 64];
        }
        p += (uint32_t)__builtin_ctzll(inv);
        if (p + len > limit)
            return UINT32_MAX;
        /* the free run from p: up to the next set bit */
        uint32_t e = p;
        uint64_t bits = row[e / 64] >> (e % 64);
        while (!bits) {
            e = (e / 64 + 1) * 64;
            if (e >= p + len)
                return p;
            bits = row[e / 64];
        }
        e += (uint32_t)__builtin_ctzll(bits);
        if (e >= p + len)
            return p;
        p = e;
    }
    return UINT32_MAX;
}

/* Moves *x right to the first column where every solid row of m lies on a free run of its
 * atlas row (each row's constraint only pushes x right, so alternating them converges).
 * Returns 0 when some row has no such run before the width. */
static int align_runs(const lmb_atlas *a, const lmb_mask *m, uint32_t y, uint32_t *x)
{
    for (int moved = 1; moved;) {
        moved = 0;
        for (uint32_t k = 0; k < m->h; k++) {
            uint32_t r = k == 0 ? m->widest_row : k == m->widest_row ? 0 : k;
            if (!m->solid[r])
                continue;
            uint32_t len = m->last[r] - m->first[r] + 1;
            uint32_t limit = a->width - (m->w - 1 - m->last[r]);
            uint32_t p = next_free_run(a, y + r, *x + m->first[r], len, limit);
            if (p == UINT32_MAX)
                return 0;
            if (p - m->first[r] > *x) {
                *x = p - m->first[r];
                moved = 1;
            }
        }
    }
    return 1;
}

/* Rows y..y+h-1 have the free runs the mask's rows need (a necessary condition). */
static int rows_can_hold(const lmb_atlas *a, const lmb_mask *m, uint32_t y)
{
    if (a->max_run[y + m->widest_row] < m->run[m->widest_row])
        return 0;
    for (uint32_t r = 0; r < m->h; r++)
        if (a->max_run[y + r] < m->run[r])
            return 0;
    return 1;
}

/* Bottom-left first fit inside a->width; returns 1 with (x, y). (from_y, from_x): no
 * position before it in (y, x) order can fit (an identical mask's earlier first fit). */
int lmb_atlas_find(lmb_atlas *a, const lmb_mask *m, uint32_t from_y, uint32_t from_x, uint32_t *ox, uint32_t *oy)
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
        if (!rows_can_hold(a, m, y))
            continue;
        uint32_t x = y == from_y ? from_x : 0;
        for (uint32_t r = 0; r < m->h; r++) /* columns before free_from are taken in that row */
            if (m->first[r] < m->w && a->free_from[y + r] > m->first[r] && a->free_from[y + r] - m->first[r] > x)
                x = a->free_from[y + r] - m->first[r];
        while (x + m->w <= a->width) {
            if (!align_runs(a, m, y, &x))
                break; /* some row has no free run long enough to the right: next y */
            uint32_t next = collides(a, m, x, y);
            if (!next) {
                *ox = x;
                *oy = y;
                return 1;
            }
            x = next;
        }
    }
    return 0;
}

static void refresh_rows(lmb_atlas *a, uint32_t y0, uint32_t h)
{
    for (uint32_t y = y0; y < y0 + h; y++) {
        const uint64_t *row = a->rows + (size_t)y * a->words;
        uint32_t f = 0;
        while (f < a->size && (row[f / 64] >> (f % 64) & 1))
            f++;
        a->free_from[y] = f;
        a->max_run[y] = row_max_run(a, y);
    }
}

void lmb_atlas_occupy(lmb_atlas *a, const lmb_mask *m, uint32_t x, uint32_t y, uint64_t area)
{
    for (uint32_t r = 0; r < m->h; r++) {
        uint64_t *row = a->rows + (size_t)(y + r) * a->words;
        for (uint32_t c = m->first[r]; c < m->w && c <= m->last[r]; c++)
            if (lmb_mask_bit(m, c, r))
                row[(x + c) / 64] |= 1ull << ((x + c) % 64);
    }
    refresh_rows(a, y, m->h);
    a->used_w = x + m->w > a->used_w ? x + m->w : a->used_w;
    a->used_h = y + m->h > a->used_h ? y + m->h : a->used_h;
    a->free_area -= area;
}

/* Clears what occupy recorded (footprints never share a texel, so this is exact). */
void lmb_atlas_vacate(lmb_atlas *a, const lmb_mask *m, uint32_t x, uint32_t y, uint64_t area)
{
    for (uint32_t r = 0; r < m->h; r++) {
        uint64_t *row = a->rows + (size_t)(y + r) * a->words;
        for (uint32_t c = m->first[r]; c < m->w && c <= m->last[r]; c++)
            if (lmb_mask_bit(m, c, r))
                row[(x + c) / 64] &= ~(1ull << ((x + c) % 64));
    }
    refresh_rows(a, y, m->h);
    a->open_row = y < a->open_row ? y : a->open_row;
    a->free_area += area;
    a->generation++;
}

int lmb_atlas_open(lmb_atlas *a, uint32_t size, uint32_t width)
{
    memset(a, 0, sizeof *a);
    a->size = size;
    a->words = (size + 63) / 64 + 1;
    a->width = width;
    a->free_area = (uint64_t)size * size;
    a->rows = calloc((size_t)a->words * size + 1, sizeof *a->rows);
    a->free_from = calloc((size_t)size + 1, sizeof *a->free_from);
    a->max_run = malloc(((size_t)size + 1) * sizeof *a->max_run);
    if (!a->rows || !a->free_from || !a->max_run)
        return 0;
    for (uint32_t y = 0; y < size; y++)
        a->max_run[y] = width;
    return 1;
}

void lmb_atlas_widen(lmb_atlas *a)
{
    a->generation++;
    a->width = a->size;
    a->open_row = 0;
    refresh_rows(a, 0, a->size);
}

void lmb_atlas_free(lmb_atlas *a)
{
    free(a->rows);
    free(a->free_from);
    free(a->max_run);
}

