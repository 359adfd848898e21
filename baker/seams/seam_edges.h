/* Seam edges (seam_edges.c), shared by the stitcher (seams.c): every lightmapped triangle
 * edge that is not inside a chart, keyed by its snapped world endpoints. */
#ifndef LMBAKE_SEAM_EDGES_H
#define LMBAKE_SEAM_EDGES_H

#include "pack/layout.h"

/* One triangle edge, found by a hash of its endpoints (snapped to 1/1000 texel, in order). 16
 * bytes: a level of 1,900 props holds 1.4 million (and as many again while they are sorted). */
typedef struct edge_ref {
    uint64_t hash;
    uint32_t instance;
    uint32_t triangle : 29; /* < LMB_SEAM_MAX_TRIANGLES */
    uint32_t corner : 2;    /* the edge runs from corner `corner` to corner + 1 (mod 3) */
    uint32_t swapped : 1;   /* corner + 1 holds the smaller endpoint */
} edge_ref;

/* Triangles a mesh may have for its edges to be stitched (edge_ref.triangle's bits). */
#define LMB_SEAM_MAX_TRIANGLES (1u << 29)

/* The snapping grid: 1/1000 of the finest texel of any lightmapped instance. */
double lmb_seam_snap_size(const lmb_layout *l);

/* The snapped endpoints of instance's triangle f's edge from `corner`, smaller first; *swapped
 * as in edge_ref. */
void lmb_seam_edge_key(const lmb_scene *s, const lmb_layout *l, uint32_t instance, uint32_t f, int corner, double snap,
                       int64_t key[6], int *swapped);

/* Every lightmapped triangle's edges but those inside a chart (the same texels on both sides in
 * every instance), sorted by hash then instance, triangle, corner: the order does not depend on
 * `threads`. *out: owned by the caller. */
lmb_status lmb_seam_collect_edges(const lmb_scene *s, const lmb_layout *l, double snap, int threads, edge_ref **out,
                                  size_t *count, lmb_error *err);

#endif
