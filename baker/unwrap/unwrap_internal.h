/* Shared between the unwrap stage's files (see unwrap.h for the pipeline). */
#ifndef LMBAKE_UNWRAP_INTERNAL_H
#define LMBAKE_UNWRAP_INTERNAL_H

#include "unwrap.h"

#define LMB_NONE UINT32_MAX

/* qsort comparison of uint32_t, and the position of key in a sorted array (lower bound). */
static inline int lmb_cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static inline uint32_t lmb_lower_bound(const uint32_t *ids, uint32_t n, uint32_t key)
{
    uint32_t lo = 0, hi = n;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (ids[mid] < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Orientation of triangle abc in UV (twice its signed area), and whether segments pq and rs
 * cross properly (touching at an end point does not count). */
static inline double lmb_uv_orient(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
}

static inline int lmb_uv_crosses(const double *p, const double *q, const double *r, const double *s)
{
    double d1 = lmb_uv_orient(p, q, r), d2 = lmb_uv_orient(p, q, s), d3 = lmb_uv_orient(r, s, p),
           d4 = lmb_uv_orient(r, s, q);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

/* Corner k's edge of triangle `face` by its welded end points (lo < hi). Sorted with
 * lmb_cmp_welded_edge, the triangles on one welded edge are neighbours in the list
 * (topology.c's coplanar links, glue.c's seams). */
typedef struct lmb_welded_edge {
    uint32_t lo, hi, face, k;
} lmb_welded_edge;

static inline int lmb_cmp_welded_edge(const void *a, const void *b)
{
    const lmb_welded_edge *x = a, *y = b;
    if (x->lo != y->lo)
        return x->lo < y->lo ? -1 : 1;
    if (x->hi != y->hi)
        return x->hi < y->hi ? -1 : 1;
    return (x->face > y->face) - (x->face < y->face);
}

/* Welded topology of one mesh: vertices merged by exact position into a half-edge mesh
 * (OpenMesh; a triangle it refuses gets duplicated vertices), and for each triangle corner
 * k its mesh vertex and the triangle across edge (k, k+1), or LMB_NONE at a boundary, a
 * non-manifold edge (3+ triangles), a winding flip (both triangles run the edge the same
 * way) or a skipped triangle. */
typedef struct lmb_topology {
    uint32_t vertex_count; /* welded vertices and their duplicates */
    uint32_t *corner;      /* 3 per triangle: vertex id, shared by the corners of one chart vertex */
    uint32_t *weld;        /* 3 per triangle: welded vertex id (equal positions, before any duplicate) */
    uint32_t *neighbor;    /* 3 per triangle */
    uint32_t *link;        /* 3 per triangle: across a seam edge (neighbor LMB_NONE), the one other
                              triangle on the same welded edge that is coplanar and faces the same
                              way (PLANAR_DOT), else LMB_NONE: a planar chart may grow across it */
    double *normal;        /* 3 per triangle, unit (0 for skipped) */
    double *area;          /* per triangle */
    double *centroid;      /* 3 per triangle */
    lmb_topology_counts counts;
} lmb_topology;

/* Two unit normals this close are one plane for flattening (flatten.c's planar test). */
#define LMB_PLANAR_DOT (1.0 - 1e-7)

/* name: the mesh, for messages (NULL: "mesh"). */
lmb_status lmb_topology_build(const lmb_unwrap_input *in, const char *name, lmb_topology *t, lmb_error *err);
void lmb_topology_free(lmb_topology *t);

/* Grows charts over the triangles listed in tris[0..n) (all unassigned in chart_of, which
 * holds LMB_NONE for them); new charts get ids from *next_chart on. */
lmb_status lmb_segment(const lmb_unwrap_input *in, const lmb_topology *t, const uint32_t *tris, uint32_t n,
                       double max_angle, uint32_t *chart_of, uint32_t *next_chart, lmb_error *err);

/* Flattens the triangles tris[0..n) of one chart into uv (6 per triangle, indexed by
 * triangle). *planar is set when a projection was exact. */
lmb_status lmb_flatten(const lmb_unwrap_input *in, const lmb_topology *t, const uint32_t *tris, uint32_t n,
                       double *uv, int *planar, lmb_error *err);

/* Glues every chart narrower than glue_below (object units, across its principal axis in
 * UV) onto the neighbouring chart it shares the most edge length with, moved rigidly in UV,
 * where nothing overlaps (glue.c). Charts are ids below chart_count in chart_of; a glued
 * chart's triangles take its host's id and UVs in the host's frame. Returns the charts
 * glued; *ok = 0 when out of memory (nothing is glued then). */
uint32_t lmb_glue_narrow_charts(const lmb_unwrap_input *in, const lmb_topology *t, uint32_t *chart_of, double *uv,
                                uint32_t chart_count, double glue_below, int *ok);

#endif
