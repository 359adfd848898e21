/*
 * The unwrap stage: one mesh (object space) -> charts with flattened, chart-local UVs in
 * world-ish units (each chart's UV area equals its 3D area), ready for the pack stage to
 * scale to a texel density and place. Pipeline, each in its own file:
 *   topology.c  weld by position into a half-edge mesh (OpenMesh, through halfedge_adapter.cpp);
 *               triangle adjacency across manifold, consistently wound edges
 *   segment.c   greedy chart growth from seeds under a normal-cone and roundness cost
 *   flatten.c   planar projection where exact, else LSCM (Levy et al. 2002) solved with CHOLMOD
 *   unwrap.c    validity (no flips, no boundary self-intersection) and splitting until valid
 *   glue.c      narrow charts glued onto a neighbour, unfolded across the crease
 */
#ifndef LMBAKE_UNWRAP_H
#define LMBAKE_UNWRAP_H

#include <lmbake/lmbake.h>

typedef struct lmb_unwrap_input {
    uint32_t vertex_count;
    const float *positions; /* 3 per vertex */
    uint32_t triangle_count;
    const uint32_t *indices; /* 3 per triangle */
    const uint8_t *skip;     /* per triangle, 1 = not charted (zero area); may be NULL */
} lmb_unwrap_input;

typedef struct lmb_unwrap_options {
    double max_chart_angle; /* radians: a chart's normals stay within this cone of its mean */
    double glue_below;      /* object units: charts narrower than this are glued onto a neighbour
                               (glue.c); 0 = none. The layout sets it from atlas.min_chart_texels
                               and the density the mesh is expected to get. */
    const char *name;       /* the mesh, named in error messages; NULL: "mesh" */
} lmb_unwrap_options;

/* What welding into the half-edge mesh found. Every triangle is kept whatever it found:
 * a refused triangle is added again on duplicated vertices and its edges become seams. */
typedef struct lmb_topology_counts {
    uint32_t complex_edge_faces;  /* refused: an edge of theirs already had two triangles */
    uint32_t flipped_faces;       /* refused: a neighbour runs the shared edge the same way */
    uint32_t vertex_faces;        /* refused at a vertex: a closed fan, or fans OpenMesh could not relink */
    uint32_t duplicated_vertices; /* vertices added at an existing position to re-add refused triangles */
    uint32_t nonmanifold_edges;   /* edges that 3+ triangles share: seams for all of them */
    uint32_t bowtie_vertices;     /* vertices where 2+ fans meet (accepted and kept as they are) */
    /* OpenMesh's own ::omerr() warnings, captured and counted by message (not printed) */
    uint32_t om_complex_vertex, om_complex_edge, om_relink_failed, om_other;
} lmb_topology_counts;

void lmb_unwrap_options_default(lmb_unwrap_options *o);

typedef struct lmb_charts {
    uint32_t chart_count;
    uint32_t triangle_count;
    uint32_t *chart_of;   /* per triangle, UINT32_MAX if skipped (zero area) */
    double *uv;           /* 6 per triangle: chart-local, isometric scale; skipped: all 0 */
    uint32_t *first;      /* chart_count + 1 offsets into `order` */
    uint32_t *order;      /* triangles sorted by chart */
    uint32_t planar_charts;   /* flattened by projection */
    uint32_t splits;          /* charts split because their flattening was invalid */
    uint32_t glued;           /* narrow charts glued onto a neighbour (glue_below) */
    lmb_topology_counts topology;
} lmb_charts;

/* Charts one mesh. The result is deterministic. Free with lmb_charts_free. */
lmb_status lmb_unwrap_mesh(const lmb_unwrap_input *in, const lmb_unwrap_options *opt, lmb_charts *out,
                           lmb_error *err);

void lmb_charts_free(lmb_charts *c);

#endif
