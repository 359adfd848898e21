/*
 * The gather points' validity memo (lights/point_validity.h) kept beside its layout in the
 * layout cache (`lmbake bake --layout-cache DIR`, what `lmbake preview --watch` runs): a bake
 * that reads its layout back reads the memo the bake before it left, and the direct stage traces
 * no validity rays for the points in it. The file is DIR/layout-KEY-seedN.lmbv (the memo depends
 * on the layout, the gather points per texel and the seed; nothing else): a header, then per
 * atlas its entries compressed with zstd. A file that is missing, damaged or of another shape is
 * not used (the points are tested again) and never stops a bake.
 */
#ifndef LMBAKE_WATCH_VALIDITY_CACHE_H
#define LMBAKE_WATCH_VALIDITY_CACHE_H

#include "lights/point_validity.h"

#include <lmbake/lmbake.h>

/* Fills v (made by lmb_point_validity_init for this layout) from dir's file for scene and cfg;
 * 1 when it was read, 0 when not (v is then all unknown). */
int lmb_validity_cache_read(const lmb_scene *scene, const lmb_config *cfg, const char *dir, lmb_point_validity *v,
                            const lmb_log *log);

/* Writes v to dir's file for scene and cfg (whole or not at all: a temporary file renamed);
 * a failure is a warning. */
void lmb_validity_cache_write(const lmb_scene *scene, const lmb_config *cfg, const char *dir,
                              const lmb_point_validity *v, const lmb_log *log);

#endif
