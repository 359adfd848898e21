/*
 * The unwrap stage: one mesh (object space) -> charts with flattened, chart-local UVs in
 * world-ish units (each chart's UV area equals its 3D area), ready for the pack stage to
 * scale to a texel density and place. Pipeline, each in its own file:
 *   topology.c  weld by position, triangle adjacency across manifold, consistently wound edges
 *   segment.c   greedy chart growth from seeds under a normal-cone and roundness cost
 *   flatten.c   planar projection where exact, else LSCM (Levy et al. 2002) solved with CHOLMOD
 *   unwrap.c    validity (no flips, no boundary self-intersection) and splitting until valid
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
} lmb_unwrap_options;

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
} lmb_charts;

/* Charts one mesh. The result is deterministic. Free with lmb_charts_free. */
lmb_status lmb_unwrap_mesh(const lmb_unwrap_input *in, const lmb_unwrap_options *opt, lmb_charts *out,
                           lmb_error *err);

void lmb_charts_free(lmb_charts *c);

#endif
