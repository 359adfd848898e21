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

#endif
