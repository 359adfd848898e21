/*
 * Quality of a lightmap UV layout, with the definitions docs/unwrap.md states:
 *   coverage  = texels whose centre lies inside some triangle / (width x height)
 *   overlap   = texel centres covered by two or more triangles
 *   L2 stretch = Sander et al. 2001, area-weighted, normalized so 1.0 is ideal
 *   density   = (UV area / 3D area) per triangle / the layout's mean, area-weighted p1/p50/p99
 * Input is a triangle soup: world positions and texel-space UVs per corner, one atlas.
 */
#ifndef LMBAKE_UNWRAP_METRICS_H
#define LMBAKE_UNWRAP_METRICS_H

#include <lmbake/lmbake.h>

typedef struct lmb_uv_layout {
    uint32_t triangle_count;
    const double *pos; /* 9 per triangle: world-space corners */
    const double *uv;  /* 6 per triangle: corners in texel units, (0,0) = atlas corner */
    uint32_t width, height; /* atlas size in texels */
} lmb_uv_layout;

typedef struct lmb_uv_metrics {
    uint64_t covered_texels;     /* centres inside at least one triangle */
    uint64_t overlapping_texels; /* centres inside two or more */
    double coverage;             /* covered / (width x height) */
    double l2_stretch;           /* 1.0 = isometric up to one global scale */
    double density_p1, density_p50, density_p99;
    uint32_t degenerate_uv;      /* triangles with zero UV area (not rasterized) */
} lmb_uv_metrics;

/* Computes m for layout l. Uses width*height bytes of scratch memory. */
lmb_status lmb_uv_metrics_compute(const lmb_uv_layout *l, lmb_uv_metrics *m, lmb_error *err);

/* Calls visit(user, x, y) for every texel whose centre (x+0.5, y+0.5) lies inside the
 * triangle uv[6] (texel units), clipped to width x height. Centres on an edge belong to
 * exactly one of the two triangles sharing it (top-left rule), so a mesh's texels are
 * counted once. Returns the number of texels visited. */
uint64_t lmb_raster_triangle_centres(const double uv[6], uint32_t width, uint32_t height,
                                     void (*visit)(void *user, uint32_t x, uint32_t y), void *user);

#endif
