/* The stitching solve in independent blocks (see seam_solve.h). */
#include "seam_solve.h"

#include "texels/dilate.h"

#include "util/lmb_math.h"
#include "util/spd_solve.h"

#include <omp.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The texels the rows read, numbered in order of first use (rows in order, taps in order). */
typedef struct unknowns {
    int32_t **of_texel;  /* per atlas, per texel: its unknown or -1 */
    uint32_t *atlas_of;  /* per unknown */
    uint32_t *texel_of;  /* per unknown */
    uint32_t count, cap;
} unknowns;

/* What one block's solve reports (reduced over the blocks in block order). */
typedef struct block_result {
    int failed;     /* the factorisation failed (CHOLMOD status in `status`) or memory ran out */
    int status;
    uint64_t samples, over_before, over_after;
    double jump_before, jump_after;
} block_result;

/* Unknown index of a texel, made on first use. -1: out of memory. */
static int64_t unknown_of(unknowns *u, uint32_t atlas, uint32_t texel)
{
    int32_t *k = &u->of_texel[atlas][texel];
    if (*k >= 0)
        return *k;
    if (u->count == u->cap) {
        uint32_t cap = u->cap ? 2 * u->cap : 1024;
        uint32_t *a = realloc(u->atlas_of, (size_t)cap * sizeof *a);
        if (a)
            u->atlas_of = a;
        uint32_t *t = realloc(u->texel_of, (size_t)cap * sizeof *t);
        if (t)
            u->texel_of = t;
        if (!a || !t)
            return -1;
        u->cap = cap;
    }
    u->atlas_of[u->count] = atlas;
    u->texel_of[u->count] = texel;
    *k = (int32_t)u->count;
    return u->count++;
}

static int32_t unknown_at(const unknowns *u, const seam_row *r, int j)
{
    return u->of_texel[lmb_seam_tap_atlas(r, j)][r->texel[j]];
}

/* |lum A - lum B| / their mean at a seam point, from the atlases as they are. */
static double jump_at(float *const *rgb, const seam_row *r)
{
    double side[2][3] = {{0, 0, 0}, {0, 0, 0}};
    for (int j = 0; j < 8; j++) {
        const float *p = rgb[lmb_seam_tap_atlas(r, j)] + 3 * (size_t)r->texel[j];
        for (int c = 0; c < 3; c++)
            side[j / 4][c] += fabs(r->w[j]) * p[c];
    }
    double a = lmb_luminance(side[0]), b = lmb_luminance(side[1]), m = 0.5 * (a + b);
    return m > 0 ? fabs(a - b) / m : 0;
}

static uint32_t find_root(uint32_t *parent, uint32_t u)
{
    while (parent[u] != u) {
        parent[u] = parent[parent[u]];
        u = parent[u];
    }
    return u;
}

/* The normal equations (upper triangle) of one block over its active rows, solved into x (3
 * columns of n: R, G, B). unk: the block's unknowns (global, ascending), local: global ->
 * index in unk. 0 on failure (*status: CHOLMOD's, or 1 for memory). */
static int solve_system(const unknowns *u, float *const *rgb, const uint8_t *const *state, const seam_row *rows,
                        const size_t *row_list, const uint8_t *active, size_t nr, const uint32_t *unk, size_t n,
                        const uint32_t *local, double *x, int *status)
{
    size_t entries = n;
    for (size_t r = 0; r < nr; r++)
        for (int p = 0; active[r] && p < 8; p++)
            for (int q = 0; q < 8; q++)
                entries += local[unknown_at(u, &rows[row_list[r]], p)] <= local[unknown_at(u, &rows[row_list[r]], q)];
    lmb_spd sys;
    int ok = lmb_spd_begin(&sys, n, entries, 3);
    *status = ok ? 0 : 1;
    if (ok) {
        cholmod_triplet *T = sys.a;
        int *ti = T->i, *tj = T->j;
        double *tx = T->x, *bx = sys.b->x;
        for (size_t k = 0; k < n; k++) {
            uint32_t a = u->atlas_of[unk[k]], t = u->texel_of[unk[k]];
            double d = state[a][t] == LMB_TEXEL_VALID ? 1.0 : LMB_SEAM_FREE;
            ti[T->nnz] = tj[T->nnz] = (int)k;
            tx[T->nnz++] = d;
            for (int c = 0; c < 3; c++)
                bx[k + c * n] = d * rgb[a][3 * (size_t)t + c];
        }
        for (size_t r = 0; r < nr; r++) {
            const seam_row *row = &rows[row_list[r]];
            for (int p = 0; active[r] && p < 8; p++)
                for (int q = 0; q < 8; q++) {
                    uint32_t up = local[unknown_at(u, row, p)], uq = local[unknown_at(u, row, q)];
                    if (up > uq)
                        continue;
                    ti[T->nnz] = (int)up;
                    tj[T->nnz] = (int)uq;
                    tx[T->nnz++] = LMB_SEAM_WEIGHT * row->w[p] * row->w[q];
                }
        }
        ok = lmb_spd_solve(&sys, x);
        *status = ok ? 0 : sys.cm.status;
    }
    lmb_spd_end(&sys);
    return ok;
}

/*
 * One block: solves, then drops the points whose texels the solution would make negative
 * (light that two sides cannot share: where the sides meet other geometry, the match would
 * have to overshoot) and solves again, at most LMB_SEAM_ROUNDS times; writes the result back
 * and reports the largest jump over the points kept, before and after. The rows read only the
 * block's texels, so blocks run side by side.
 */
static void solve_block(const unknowns *u, float *const *rgb, const uint8_t *const *state, const seam_row *rows,
                        const size_t *row_list, size_t nr, const uint32_t *unk, size_t n, uint32_t *local,
                        block_result *res)
{
    memset(res, 0, sizeof *res);
    for (size_t k = 0; k < n; k++)
        local[unk[k]] = (uint32_t)k;
    uint8_t *active = malloc(nr + 1), *negative = calloc(n + 1, 1);
    double *x = malloc((3 * n + 1) * sizeof *x);
    res->failed = !active || !negative || !x;
    res->status = res->failed;
    if (!res->failed)
        memset(active, 1, nr);
    for (int round = 0; !res->failed && round < LMB_SEAM_ROUNDS; round++) {
        res->failed = !solve_system(u, rgb, state, rows, row_list, active, nr, unk, n, local, x, &res->status);
        size_t dropped = 0;
        for (size_t k = 0; !res->failed && k < n; k++)
            negative[k] = x[k] < 0 || x[k + n] < 0 || x[k + 2 * n] < 0;
        for (size_t r = 0; !res->failed && r < nr; r++)
            for (int j = 0; active[r] && j < 8; j++)
                if (negative[local[unknown_at(u, &rows[row_list[r]], j)]]) {
                    active[r] = 0;
                    dropped++;
                }
        if (!dropped)
            break;
    }
    for (size_t r = 0; !res->failed && r < nr; r++)
        if (active[r]) {
            double j = jump_at(rgb, &rows[row_list[r]]);
            res->jump_before = fmax(res->jump_before, j);
            res->over_before += j > 0.01;
            res->samples++;
        }
    for (size_t k = 0; !res->failed && k < n; k++)
        for (int c = 0; c < 3; c++) {
            double v = x[k + c * n];
            rgb[u->atlas_of[unk[k]]][3 * (size_t)u->texel_of[unk[k]] + c] = (float)(isfinite(v) && v > 0 ? v : 0);
        }
    for (size_t r = 0; !res->failed && r < nr; r++)
        if (active[r]) {
            double j = jump_at(rgb, &rows[row_list[r]]);
            res->jump_after = fmax(res->jump_after, j);
            res->over_after += j > 0.01;
        }
    free(active);
    free(negative);
    free(x);
}

/* Blocks: the connected sets of unknowns (joined by the rows' taps), numbered by their first
 * unknown and gathered in that order until a block would pass LMB_SEAM_BLOCK_UNKNOWNS.
 * block_of: per unknown. Returns the number of blocks; 0 when out of memory. */
static uint32_t make_blocks(const unknowns *u, const seam_row *rows, size_t nr, uint32_t *block_of)
{
    size_t n = u->count;
    uint32_t *parent = malloc((n + 1) * sizeof *parent), *set_size = calloc(n + 1, sizeof *set_size);
    if (!parent || !set_size) {
        free(parent);
        free(set_size);
        return 0;
    }
    for (size_t k = 0; k < n; k++)
        parent[k] = (uint32_t)k;
    for (size_t r = 0; r < nr; r++) {
        uint32_t a = find_root(parent, (uint32_t)unknown_at(u, &rows[r], 0));
        for (int j = 1; j < 8; j++) {
            uint32_t b = find_root(parent, (uint32_t)unknown_at(u, &rows[r], j));
            if (a != b)
                parent[a > b ? a : b] = a < b ? a : b; /* the smaller index stays the root */
            a = a < b ? a : b;
        }
    }
    for (size_t k = 0; k < n; k++)
        set_size[find_root(parent, (uint32_t)k)]++;
    /* a set's root is its smallest unknown, so sets are met in order of their first unknown */
    uint32_t blocks = 0, in_block = 0;
    for (size_t k = 0; k < n; k++) {
        if (parent[k] != k)
            continue;
        if (blocks == 0 || (in_block > 0 && (uint64_t)in_block + set_size[k] > LMB_SEAM_BLOCK_UNKNOWNS)) {
            blocks++;
            in_block = 0;
        }
        in_block += set_size[k];
        set_size[k] = blocks - 1; /* the root's slot now holds its block */
    }
    for (size_t k = 0; k < n; k++)
        block_of[k] = set_size[find_root(parent, (uint32_t)k)];
    free(parent);
    free(set_size);
    return blocks;
}

lmb_status lmb_seam_solve(const lmb_layout *l, float *const *rgb, const uint8_t *const *state, const seam_row *rows,
                          size_t nr, int threads, lmb_seam_report *report, lmb_error *err)
{
    unknowns u = {calloc((size_t)l->atlas_count + 1, sizeof *u.of_texel), NULL, NULL, 0, 0};
    lmb_status st = u.of_texel ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "seams: out of memory");
    for (uint32_t a = 0; st == LMB_OK && a < l->atlas_count; a++) {
        size_t texels = (size_t)l->width[a] * l->height[a];
        u.of_texel[a] = malloc((texels + 1) * sizeof *u.of_texel[a]);
        if (!u.of_texel[a])
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "seams: out of memory for atlas %u", a);
        else
            memset(u.of_texel[a], 0xff, texels * sizeof *u.of_texel[a]);
    }
    for (size_t r = 0; st == LMB_OK && r < nr; r++)
        for (int j = 0; j < 8; j++)
            if (unknown_of(&u, lmb_seam_tap_atlas(&rows[r], j), rows[r].texel[j]) < 0)
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "seams: out of memory for the unknowns");
    size_t n = u.count;
    uint32_t *block_of = malloc((n + 1) * sizeof *block_of), *local = malloc((n + 1) * sizeof *local);
    uint32_t blocks = st == LMB_OK && block_of && local ? make_blocks(&u, rows, nr, block_of) : 0;
    /* each block's unknowns (ascending) and rows (in order), by a counting sort */
    size_t *unk_start = calloc((size_t)blocks + 2, sizeof *unk_start), *row_start = calloc((size_t)blocks + 2, sizeof *row_start);
    uint32_t *unk = malloc((n + 1) * sizeof *unk);
    size_t *row_list = malloc((nr + 1) * sizeof *row_list);
    block_result *res = calloc((size_t)blocks + 1, sizeof *res);
    if (st == LMB_OK && (!blocks || !unk_start || !row_start || !unk || !row_list || !res))
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "seams: out of memory for %zu unknowns", n);
    if (st == LMB_OK) {
        for (size_t k = 0; k < n; k++)
            unk_start[block_of[k] + 2]++;
        for (size_t r = 0; r < nr; r++)
            row_start[block_of[unknown_at(&u, &rows[r], 0)] + 2]++;
        for (uint32_t b = 2; b < blocks + 2; b++) {
            unk_start[b] += unk_start[b - 1];
            row_start[b] += row_start[b - 1];
        }
        for (size_t k = 0; k < n; k++)
            unk[unk_start[block_of[k] + 1]++] = (uint32_t)k;
        for (size_t r = 0; r < nr; r++)
            row_list[row_start[block_of[unknown_at(&u, &rows[r], 0)] + 1]++] = r;
        /* now block b's unknowns are unk[unk_start[b] .. unk_start[b + 1]), rows likewise */
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
        for (uint32_t b = 0; b < blocks; b++)
            solve_block(&u, rgb, state, rows, row_list + row_start[b], row_start[b + 1] - row_start[b],
                        unk + unk_start[b], unk_start[b + 1] - unk_start[b], local, &res[b]);
        for (uint32_t b = 0; b < blocks; b++) {
            if (res[b].failed) {
                st = lmb_error_set(err, LMB_ERR_INTERNAL,
                                   "seams: the stitching solve failed (CHOLMOD status %d, %zu unknowns in block %u of %u)",
                                   res[b].status, unk_start[b + 1] - unk_start[b], b, blocks);
                break;
            }
            report->samples += res[b].samples;
            report->over_1pct_before += res[b].over_before;
            report->over_1pct += res[b].over_after;
            report->jump_before = fmax(report->jump_before, res[b].jump_before);
            report->jump_after = fmax(report->jump_after, res[b].jump_after);
        }
        report->dropped = nr - report->samples;
        report->texels = n;
    }
    for (uint32_t a = 0; u.of_texel && a < l->atlas_count; a++)
        free(u.of_texel[a]);
    free(u.of_texel);
    free(u.atlas_of);
    free(u.texel_of);
    free(block_of);
    free(local);
    free(unk_start);
    free(row_start);
    free(unk);
    free(row_list);
    free(res);
    return st;
}
