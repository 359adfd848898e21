/*
 * Probes that line walls (docs/leaks.md#probes): after placement, every edge of the probes'
 * Delaunay tetrahedra (tetrahedra.c) is traced; where geometry blocks one, a probe is added on
 * each side of it, LMB_WALL_PROBE_OFFSET of a cell in front of the faces the edge meets from its
 * two ends (an end already within 2 x offset of its face adds none there: it lines the wall
 * itself). The tetrahedralization made again with them connects the wall's two sides only
 * between probes hugging it, so a point more than that from the wall is interpolated from
 * probes on its own side, as Unity's and Godot's tetrahedra are read, with nothing more for an
 * engine to read. Up to LMB_WALL_PROBE_ROUNDS rounds (each new probe's edges are traced in the
 * next); a new probe inside geometry, or within half the offset of a probe already there, is
 * not added. Deterministic: edges in tetrahedra order, rays traced in parallel into their slots,
 * new probes appended in that order.
 */
#include "probes.h"

#include <omp.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LMB_WALL_PROBE_ROUNDS 3

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

/* The point `offset` in front of the face ray o -> target meets first (0: nothing in between). */
static int in_front_of_wall(const lmb_rt *rt, const double o[3], const double target[3], double offset, double q[3])
{
    double d[3] = {target[0] - o[0], target[1] - o[1], target[2] - o[2]};
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0))
        return 0;
    for (int k = 0; k < 3; k++)
        d[k] /= len;
    lmb_rt_hit h;
    if (!lmb_rt_intersect(rt, o, d, rt->eps, len, &h) || h.t < 2 * offset)
        return 0;
    double side = h.backface ? -1.0 : 1.0; /* toward where the ray came from */
    for (int k = 0; k < 3; k++)
        q[k] = h.p[k] + side * offset * h.ng[k];
    return 1;
}

/* Whether q lies within `near` of any probe (a linear scan over the probes in the same coarse
 * cell is not needed at these counts: the candidates are few and the set is at most a few
 * thousand near any wall; a full scan keeps it simple and exact). */
static int crowded(const double *pos, uint32_t count, const double q[3], double near)
{
    for (uint32_t i = 0; i < count; i++) {
        double dx = pos[3 * (size_t)i] - q[0], dy = pos[3 * (size_t)i + 1] - q[1], dz = pos[3 * (size_t)i + 2] - q[2];
        if (dx * dx + dy * dy + dz * dz < near * near)
            return 1;
    }
    return 0;
}

lmb_status lmb_probes_line_walls(lmb_probe_set *set, const lmb_rt *rt, double offset, uint32_t limit, int threads,
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
                got[2 * k] = (uint8_t)(in_front_of_wall(rt, a, b, offset, cand + 6 * k) && !inside(rt, cand + 6 * k));
                got[2 * k + 1] = (uint8_t)(in_front_of_wall(rt, b, a, offset, cand + 6 * k + 3) &&
                                           !inside(rt, cand + 6 * k + 3));
            }
        }
        free(e);
        uint32_t before = set->count, added = 0;
        for (size_t k = 0; k < 2 * m && set->count < limit; k++) {
            const double *q = cand + 3 * k;
            if (!got[k] || crowded(set->position, set->count, q, 0.5 * offset))
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
            set->count++;
            added++;
        }
        free(cand);
        free(got);
        set->wall_probes += added;
        if (!added || set->count == before)
            break;
    }
    return LMB_OK;
}
