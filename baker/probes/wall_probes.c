/*
 * Probes that line walls (docs/leaks.md#probes): after placement, every edge of the probes'
 * Delaunay tetrahedra (tetrahedra.c) is traced; where geometry blocks one, a probe is added on
 * each side of it, LMB_WALL_PROBE_OFFSET of a cell in front of the faces the edge meets from its
 * two ends (an end already within 2 x offset of its face adds none there: it lines the wall
 * itself). The tetrahedralization made again with them connects the wall's two sides only
 * between probes hugging it, so a point more than that from the wall is interpolated from
 * probes on its own side, as Unity's and Godot's tetrahedra are read, with nothing more for an
 * engine to read. Up to LMB_WALL_PROBE_ROUNDS rounds (each new probe's edges are traced in the
 * next); a new probe inside geometry, or within `spacing` of a probe already there (a wall is
 * lined at the probes' own spacing near surfaces, not once per edge: a level of many rooms would
 * otherwise get thirty times its probes), is not added. Deterministic: edges in tetrahedra order, rays traced in parallel into their slots,
 * new probes appended in that order.
 */
#include "probes.h"

#include <omp.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define LMB_WALL_PROBE_ROUNDS 2

typedef struct edge {
    uint32_t a, b;
} edge;

static int by_edge(const void *x, const void *y)
{
    const edge *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    return p->b < q->b ? -1 : p->b > q->b;
}

/* The point `offset` in front of the face ray o -> target meets first (0: nothing in between, or
 * what it meets is not a wall: a prop the probes light, which moves or is small). */
static int in_front_of_wall(const lmb_rt *rt, const lmb_layout *layout, const double o[3], const double target[3],
                            double offset, double q[3])
{
    double d[3] = {target[0] - o[0], target[1] - o[1], target[2] - o[2]};
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0))
        return 0;
    for (int k = 0; k < 3; k++)
        d[k] /= len;
    lmb_rt_hit h;
    if (!lmb_rt_intersect(rt, o, d, rt->eps, len, &h) || h.t < 2 * offset ||
        !layout->instances[rt->geoms[h.geom].instance].lightmapped)
        return 0;
    double side = h.backface ? -1.0 : 1.0; /* toward where the ray came from */
    for (int k = 0; k < 3; k++)
        q[k] = h.p[k] + side * offset * h.ng[k];
    return 1;
}

/* Probes hashed by the cell of a grid of `size` they lie in: whether a point has a probe within
 * `size` is a look at 27 cells (open addressing on the cell's coordinates; next[] chains the
 * probes of one cell). */
typedef struct probe_hash {
    double size;
    uint32_t cap;        /* slots, a power of two */
    int64_t (*key)[3];   /* per slot: the cell (INT64_MIN: empty) */
    uint32_t *head;      /* per slot: its first probe + 1 */
    uint32_t *next;      /* per probe: the next probe of its cell + 1 */
} probe_hash;

static uint32_t slot_of(const probe_hash *h, const int64_t c[3])
{
    uint64_t x = (uint64_t)c[0] * 0x9E3779B97F4A7C15ull ^ (uint64_t)c[1] * 0xC2B2AE3D27D4EB4Full ^
                 (uint64_t)c[2] * 0x165667B19E3779F9ull;
    uint32_t i = (uint32_t)(x >> 32) & (h->cap - 1);
    while (h->key[i][0] != INT64_MIN && (h->key[i][0] != c[0] || h->key[i][1] != c[1] || h->key[i][2] != c[2]))
        i = (i + 1) & (h->cap - 1);
    return i;
}

static void cell_of(const probe_hash *h, const double q[3], int64_t c[3])
{
    for (int k = 0; k < 3; k++)
        c[k] = (int64_t)floor(q[k] / h->size);
}

static void hash_add(probe_hash *h, const double *pos, uint32_t i)
{
    int64_t c[3];
    cell_of(h, pos + 3 * (size_t)i, c);
    uint32_t s = slot_of(h, c);
    memcpy(h->key[s], c, sizeof c);
    h->next[i] = h->head[s];
    h->head[s] = i + 1;
}

static int crowded(const probe_hash *h, const double *pos, const double q[3])
{
    int64_t c[3];
    cell_of(h, q, c);
    for (int dz = -1; dz <= 1; dz++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                int64_t n[3] = {c[0] + dx, c[1] + dy, c[2] + dz};
                uint32_t s = slot_of(h, n);
                for (uint32_t j = h->head[s]; j && h->key[s][0] != INT64_MIN; j = h->next[j - 1]) {
                    const double *p = pos + 3 * (size_t)(j - 1);
                    double d2 = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
                    if (d2 < h->size * h->size)
                        return 1;
                }
            }
    return 0;
}

lmb_status lmb_probes_line_walls(lmb_probe_set *set, const lmb_layout *layout, const lmb_rt *rt,
                                 double offset, double spacing, uint32_t limit, int threads,
                                 int (*inside)(const lmb_rt *rt, const double p[3]), lmb_error *err)
{
    for (int round = 0; round < LMB_WALL_PROBE_ROUNDS && set->count >= 4; round++) {
        lmb_probe_tetrahedra_out tets;
        lmb_status st = lmb_probe_tetrahedra(set, &tets, err);
        if (st != LMB_OK)
            return st;
        size_t ne = 6 * (size_t)tets.count;
        edge *e = malloc((ne + 1) * sizeof *e);
        if (!e) {
            lmb_probe_tetrahedra_free(&tets);
            return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for %zu tetrahedra edges", ne);
        }
        static const int pair[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
        for (uint32_t t = 0; t < tets.count; t++)
            for (int j = 0; j < 6; j++) {
                uint32_t a = tets.tetrahedra[4 * (size_t)t + pair[j][0]], b = tets.tetrahedra[4 * (size_t)t + pair[j][1]];
                e[6 * (size_t)t + j] = (edge){a < b ? a : b, a < b ? b : a};
            }
        lmb_probe_tetrahedra_free(&tets);
        qsort(e, ne, sizeof *e, by_edge);
        size_t m = 0;
        for (size_t k = 0; k < ne; k++)
            if (!m || by_edge(&e[k], &e[m - 1]))
                e[m++] = e[k];
        double *cand = malloc((6 * m + 1) * sizeof *cand);
        uint8_t *got = calloc(2 * m + 1, 1);
        if (!cand || !got) {
            free(e);
            free(cand);
            free(got);
            return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for %zu tetrahedra edges", m);
        }
        const double *pos = set->position;
#pragma omp parallel num_threads(threads)
        {
            lmb_rt_thread_init();
#pragma omp for schedule(dynamic, 256)
            for (int64_t k = 0; k < (int64_t)m; k++) {
                const double *a = pos + 3 * (size_t)e[k].a, *b = pos + 3 * (size_t)e[k].b;
                got[2 * k] = (uint8_t)(in_front_of_wall(rt, layout, a, b, offset, cand + 6 * k) && !inside(rt, cand + 6 * k));
                got[2 * k + 1] = (uint8_t)(in_front_of_wall(rt, layout, b, a, offset, cand + 6 * k + 3) &&
                                           !inside(rt, cand + 6 * k + 3));
            }
        }
        free(e);
        uint32_t before = set->count, added = 0, most = before + (uint32_t)(2 * m < limit ? 2 * m : limit);
        most = most < limit ? most : limit;
        probe_hash h = {spacing, 1, NULL, NULL, NULL};
        while (h.cap < 2 * (uint64_t)most + 16)
            h.cap *= 2;
        h.key = malloc((size_t)h.cap * sizeof *h.key);
        h.head = calloc(h.cap, sizeof *h.head);
        h.next = calloc((size_t)most + 1, sizeof *h.next);
        if (!h.key || !h.head || !h.next) {
            free(h.key);
            free(h.head);
            free(h.next);
            free(cand);
            free(got);
            return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for %u probes", most);
        }
        for (uint32_t s2 = 0; s2 < h.cap; s2++)
            h.key[s2][0] = INT64_MIN;
        for (uint32_t i = 0; i < before; i++)
            hash_add(&h, set->position, i);
        for (size_t k = 0; k < 2 * m && set->count < most; k++) {
            const double *q = cand + 3 * k;
            if (!got[k] || crowded(&h, set->position, q))
                continue;
            double *p = realloc(set->position, 3 * ((size_t)set->count + 1) * sizeof *p);
            uint32_t *c = realloc(set->cell, ((size_t)set->count + 1) * sizeof *c);
            if (p)
                set->position = p;
            if (c)
                set->cell = c;
            if (!p || !c) {
                free(cand);
                free(got);
                return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for %u probes", set->count + 1);
            }
            memcpy(set->position + 3 * (size_t)set->count, q, 3 * sizeof *q);
            set->cell[set->count] = lmb_probe_voxel_of(set, q);
            hash_add(&h, set->position, set->count);
            set->count++;
            added++;
        }
        free(h.key);
        free(h.head);
        free(h.next);
        free(cand);
        free(got);
        set->wall_probes += added;
        if (!added || set->count == before)
            break;
    }
    return LMB_OK;
}
