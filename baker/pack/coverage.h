/* How many texels a layout makes: the texels the texels stage will list (those with a gather
 * point, texels.h), counted from the layout alone, so that the texel budget can be checked
 * before any light is computed (layout.c keeps a bake within 110% of atlas.texels). */
#ifndef LMBAKE_COVERAGE_H
#define LMBAKE_COVERAGE_H

#include "layout.h"

/* Texels of every atlas of l that hold a point: a sub-sample (samples per texel, stratified as
 * lmb_texel_subsample places them) within one texel of a lightmapped triangle, exactly the
 * texels stage's rule. threads: 0 = all cores; the count does not depend on it. */
uint64_t lmb_layout_count_texels(const lmb_scene *scene, const lmb_layout *l, uint32_t samples, uint32_t threads,
                                 lmb_error *err, lmb_status *status);

/* Atlas a's texels that hold a point, as above: width x height bytes, 1 or 0 (caller frees), or
 * NULL when out of memory. */
uint8_t *lmb_layout_texel_map(const lmb_scene *scene, const lmb_layout *l, uint32_t atlas, uint32_t samples,
                              uint32_t threads);

#endif
