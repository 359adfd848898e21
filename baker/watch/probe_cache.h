/*
 * The light probes' placement kept beside its layout in the layout cache (`lmbake bake
 * --layout-cache DIR`, what `lmbake preview --watch` runs): where the probes go (the grid, the
 * probes moved out of geometry, the probes added along walls) and their tetrahedra depend on the
 * geometry, the lightmapped choice and the probes.* keys, all of which the layout's key holds,
 * and on no light. A bake that reads its layout back reads the placement the bake before it left
 * instead of tracing its rays and running qhull again (0.3-0.4 s of level-single-10's 5,220
 * probes). The file is DIR/layout-KEY-probes.lmbq: a header, the SHA-256 of the body, the body. A
 * file that is missing, damaged or of another format is not used (the probes are placed again)
 * and never stops a bake. Levels with MASK cut-outs (decided by materials and textures, which the
 * layout's key does not hold) place their probes every time, as they test their gather points.
 */
#ifndef LMBAKE_WATCH_PROBE_CACHE_H
#define LMBAKE_WATCH_PROBE_CACHE_H

#include "probes/probes.h"

#include <lmbake/lmbake.h>

/* Fills set (zeroed) from dir's file for scene and cfg, its probes' light arrays allocated and
 * zero; 1 when it was read, 0 when not (set is then empty, and a damaged file was warned of). */
int lmb_probe_cache_read(const lmb_scene *scene, const lmb_config *cfg, const char *dir, lmb_probe_set *set,
                         const lmb_log *log);

/* Writes set's placement and tetrahedra (made: set->tets_made) to dir's file for scene and cfg,
 * whole or not at all (a temporary file renamed); a failure is a warning. */
void lmb_probe_cache_write(const lmb_scene *scene, const lmb_config *cfg, const char *dir, const lmb_probe_set *set,
                           const lmb_log *log);

#endif
