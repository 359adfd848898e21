/*
 * The output glTF of a bake: the input's document with TEXCOORD_1 on every lightmapped
 * primitive (new vertices where charts split it), the lightmap images as textures linked by
 * MOZ_lightmap (and the directional and shadowmask maps), instanced copies' rectangles, the
 * lights' bake modes and the final gather's records file; written into the staging folder.
 */
#ifndef LMBAKE_WRITE_LIGHTMAPPED_GLTF_H
#define LMBAKE_WRITE_LIGHTMAPPED_GLTF_H

#include <lmbake/lmbake.h>

#include "lights/light_groups.h"
#include "pack/layout.h"
#include "write/atlas_images.h"
#include "write/gltf_write.h"
#include "write/output_dir.h"
#include "write/records_file.h"

/* Texture files the input references by relative path, copied to the output (warned, not
 * failed, when one cannot be). Call before lmb_write_lightmapped_gltf adds the lightmaps. */
void lmb_copy_input_textures(lmb_scene *s, lmb_output_dir *od, const lmb_log *log);

/* DIR/STEM.gltf (+ STEM-lightmap.bin) and, when records->count, the records file. outputs: per
 * atlas what its images hold (RGBM range). probes: NULL or the light probes. groups: NULL or the
 * light groups, whose files (lmb_write_group_images) each lightmap texture names. */
lmb_status lmb_write_lightmapped_gltf(lmb_scene *s, const lmb_config *cfg, const lmb_layout *l, const char *dir,
                                      const char *stem, const lmb_atlas_output *outputs, const lmb_ic_points *records,
                                      int directional, int shadowmask, const lmb_gltf_probes *probes,
                                      const lmb_light_groups *groups, lmb_error *err);

#endif
