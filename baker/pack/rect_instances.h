/*
 * Instances placed whole as rectangles of shared atlases (rects.h), their TEXCOORD_1 layout
 * fixed before placement (see rect_instances.c): meshes that keep their own TEXCOORD_1
 * (atlas.keep_uv1), and the copies of an EXT_mesh_gpu_instancing node, which share one mesh
 * and so one layout: each copy gets its own texels through a scale and offset.
 */
#ifndef LMBAKE_RECT_INSTANCES_H
#define LMBAKE_RECT_INSTANCES_H

#include "layout.h"

/* Lays out instances list[0..n) (kept TEXCOORD_1 or GPU copies; their texel densities chosen)
 * as rectangles in new atlases after l's: adds their shared layouts to l->blocks and sets each
 * one's atlas, block, rect and scale_offset. */
lmb_status lmb_layout_rect_instances(const lmb_scene *scene, const lmb_config *cfg, lmb_layout *l, const uint32_t *list,
                                     uint32_t n, const lmb_log *log, lmb_error *err);

/* Instance i's charts scaled to its texel density, chart-local, into uv (6 per mesh triangle;
 * layout.c); returns its texel area. */
double lmb_layout_scale_instance(const lmb_scene *scene, const lmb_layout *l, uint32_t i, double *uv);

#endif
