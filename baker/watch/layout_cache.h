/*
 * Layouts kept between bakes (docs/watch.md#what-is-redone): `lmbake bake --layout-cache DIR`,
 * which `lmbake preview --watch` passes to every bake it runs. A layout (unwrap, texel density,
 * pack) depends only on the scene's geometry and placement and on the config's layout keys; a
 * bake whose layout key names a file in DIR reads the layout back from it instead of building it
 * (a change of lights, materials, sky, sampling or output keys), and otherwise builds it and
 * leaves it there for the next bake. The layout read back is the one built (the plan stage's
 * codec, steps/plan_codec.h): the bake's files are the same, byte for byte.
 */
#ifndef LMBAKE_WATCH_LAYOUT_CACHE_H
#define LMBAKE_WATCH_LAYOUT_CACHE_H

#include "pack/layout.h"

#include <lmbake/lmbake.h>

/* The layout key: SHA-256 of lmbake's version, of what the layout reads of the scene (every
 * primitive's geometry and attributes, meshes, instances with their transforms and lightmapped
 * choice, probe volumes; not lights or materials) and of the config's text with its lighting-only
 * sections left out (samples but samples.texel, bounces, bounces_auto, gather, denoise,
 * irradiance_cache, farm, seed, threads, output, lights, sky, materials, seams). Any other key,
 * including one added later, counts as a layout key. *config_text (owned, free()) receives that
 * text. */
lmb_status lmb_layout_key(const lmb_scene *scene, const lmb_config *cfg, uint8_t scene_hash[32], char **config_text,
                          lmb_error *err);

/* *l := the layout of scene with cfg, read from dir when a bake with the same key left it there
 * (*reused = 1), else built by lmb_layout_build and written there (*reused = 0; a file that cannot
 * be written or read back is reported with a warning and the layout built: the bake goes on).
 * Free with lmb_layout_free. */
lmb_status lmb_layout_cached(const lmb_scene *scene, const lmb_config *cfg, const char *dir, lmb_progress_fn progress,
                             void *user, const lmb_log *log, lmb_layout *l, int *reused, lmb_error *err);

/* The file in dir that holds the layout of scene with cfg (whether or not it is there yet):
 * DIR/layout-KEY.lmbp. Other files kept with that layout take its name as their stem. */
lmb_status lmb_layout_cache_path(const lmb_scene *scene, const lmb_config *cfg, const char *dir, char *path, size_t size,
                                 lmb_error *err);

#endif
