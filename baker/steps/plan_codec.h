/*
 * The plan's body (docs/farm.md): the layout of a bake (lmb_layout: the meshes' triangle
 * soups and charts, each instance's lightmap UVs and atlas, the atlases' sizes, the density
 * report) as bytes and back, so a pass on another machine lights exactly the texels the plan
 * stage laid out without unwrapping again. Numbers are stored as the machine holds them
 * (little-endian x86-64 / arm64: every machine of a farm); arrays as a count and their bytes,
 * an absent array as count UINT64_MAX. Timings are not kept (they are not part of the result).
 */
#ifndef LMBAKE_FARM_PLAN_CODEC_H
#define LMBAKE_FARM_PLAN_CODEC_H

#include "pack/layout.h"

#include <stddef.h>
#include <stdint.h>

/* *out (owned, free()) := the layout's bytes. */
lmb_status lmb_plan_encode(const lmb_layout *l, uint8_t **out, size_t *size, lmb_error *err);

/* *l := the layout in bytes, for `scene` (free with lmb_layout_free, also after an error). Every
 * count is checked against the bytes left before anything is allocated, and against the scene
 * (meshes, instances, each instance's UVs); `name` is used in messages. */
lmb_status lmb_plan_decode(const char *name, const uint8_t *bytes, size_t size, const lmb_scene *scene,
                           lmb_layout *l, lmb_error *err);

#endif
