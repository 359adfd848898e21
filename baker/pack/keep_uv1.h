/* atlas.keep_uv1: using a mesh's own TEXCOORD_1 instead of unwrapping it, each instance a square
 * of a shared atlas (see keep_uv1.c). */
#ifndef LMBAKE_KEEP_UV1_H
#define LMBAKE_KEEP_UV1_H

#include "layout.h"

/* 1 if every primitive of the mesh has TEXCOORD_1. */
int lmb_mesh_has_uv1(const lmb_scene *scene, uint32_t mesh);

/* One chart holding the mesh's TEXCOORD_1 as is (normalized [0,1]). */
lmb_status lmb_charts_from_uv1(const lmb_scene *scene, uint32_t mesh, const lmb_mesh_soup *soup, lmb_charts *out,
                               lmb_error *err);

/* Side of the square that gives `density` texels per world unit, clamped to 16..max. */
uint32_t lmb_uv1_atlas_size(double world_area, const lmb_charts *c, double density, uint32_t max_size);

/* Squares of sides side[0..n) placed on shelves (largest first, `padding` texels apart) in
 * atlases of at most max_size a side: square k lands in atlas atlas_of[k] at (x[k], y[k]).
 * *atlas_count atlases, their sizes in *width and *height (malloc'd, the caller frees).
 * Every side must be <= max_size. */
lmb_status lmb_place_squares(const uint32_t *side, uint32_t n, uint32_t padding, uint32_t max_size, uint32_t *atlas_of,
                             uint32_t *x, uint32_t *y, uint32_t *atlas_count, uint32_t **width, uint32_t **height,
                             lmb_error *err);

#endif
