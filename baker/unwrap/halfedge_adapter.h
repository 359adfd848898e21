/*
 * The OpenMesh adapter of the unwrapper (C header over halfedge_adapter.cpp): builds a
 * triangle half-edge mesh from welded triangles and exports, once, what chart growth and
 * chart boundaries walk: per triangle corner its half-edge vertex and the triangle across
 * its edge. No C++ type and no exception crosses this header; OpenMesh's ::omerr()
 * messages are counted, not printed.
 */
#ifndef LMBAKE_HALFEDGE_ADAPTER_H
#define LMBAKE_HALFEDGE_ADAPTER_H

#include "unwrap.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lmb_halfedge_input {
    const char *name;        /* the mesh, for messages */
    uint32_t vertex_count;   /* welded vertices (one per distinct position) */
    const float *positions;  /* 3 per welded vertex */
    uint32_t face_count;
    const uint32_t *faces;   /* 3 welded ids per triangle, in the input's winding */
    const uint8_t *skip;     /* per triangle, 1 = not added (zero area, not charted); never NULL */
} lmb_halfedge_input;

/* Adds every triangle not skipped to an OpenMesh TriMesh, in input order. A triangle that
 * add_face refuses (an edge that already has two triangles, a winding flip, a closed or
 * unlinkable vertex fan) is added again on duplicated vertices (same positions): one
 * vertex where that clears every problem, else all three. Edges that 3 or more input
 * triangles share become seams for all of them. Fills, per corner 3 f + k (the edge from
 * corner k to k + 1 of triangle f):
 *   corner_vertex  the half-edge mesh's vertex (a welded id, or >= vertex_count for a
 *                  duplicate; skipped triangles keep their welded ids)
 *   neighbor       the triangle across the edge (face-halfedge circulator, then the
 *                  opposite halfedge's face), or UINT32_MAX: boundary, seam, skipped
 * and *mesh_vertices (welded + duplicated vertices) and *counts. Deterministic: the
 * same input gives the same output. Thread-safe (see halfedge_adapter.cpp on ::omerr()). */
lmb_status lmb_halfedge_build(const lmb_halfedge_input *in, uint32_t *corner_vertex, uint32_t *neighbor,
                              uint32_t *mesh_vertices, lmb_topology_counts *counts, lmb_error *err);

#ifdef __cplusplus
}
#endif

#endif
