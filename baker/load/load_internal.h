/*
 * Pieces of the load stage shared between its files: building triangle lists from glTF
 * primitives (primitives.c) and walking the node graph into instances and lights (nodes.c).
 */
#ifndef LMBAKE_LOAD_INTERNAL_H
#define LMBAKE_LOAD_INTERNAL_H

#include "accessor.h"

/* Converts glTF primitive `gp` of mesh `mesh_index` into out (zeroed by the caller).
 * Returns LMB_OK with *skipped = 1 for points and lines (triangle_count 0) and for
 * primitives without POSITION (triangle_count: what its indices would have made). */
lmb_status lmb_load_primitive(const lmb_accessor_ctx *ctx, uint32_t mesh_index, uint32_t prim_index,
                              const char *mesh_name, uint32_t material_count, lmb_primitive *out,
                              int *skipped, const lmb_log *log, lmb_error *err);

void lmb_primitive_release(lmb_primitive *p);

/* Checks the node graph (indices, one parent, no cycles) and fills scene->instances and
 * scene->lights from the baked scene's roots. */
lmb_status lmb_load_nodes(const lmb_accessor_ctx *ctx, lmb_scene *scene, const lmb_log *log,
                          lmb_error *err);

/* Fills scene->materials from the glTF's materials (materials.c). */
lmb_status lmb_load_materials(const char *path, const lmb_gltf_view *v, lmb_scene *scene, lmb_error *err);

/* materials.default and materials.override applied to the loaded scene (material_config.c);
 * LMB_ERR_INTERNAL only when out of memory. */
lmb_status lmb_apply_material_config(lmb_scene *s, const lmb_config *cfg, const lmb_log *log);

/* "name" or "<kind> N" when the glTF object has no name; buf must hold 160 bytes. */
const char *lmb_object_label(char *buf, const char *kind, uint32_t index, const char *name);

char *lmb_strdup(const char *s);

#endif
