/*
 * Texel density per instance (issue 10: defaults that bake any level). The density is
 * texels per world unit. An explicit `texel_density` or a `density_overrides` entry wins;
 * `texel_density: auto` (the default) picks one scene-wide density so that the lightmapped
 * surface fills the texel budget (`atlas.texels`):
 *     d = sqrt(budget / sum of world areas),
 * scale-free by construction (a level in millimetres and the same in metres get the same
 * texels). Every instance must sit whole in one atlas, so each also has a fit density (an
 * estimate from its charts' boxes and padding, below); an instance whose fit is lower than d
 * gets its fit (a warning names it) and the texels it leaves go to the others. An instance
 * whose charts would be smaller than atlas.min_chart_texels at d is raised to its floor
 * (lmb_density_floor) and the budget shrinks the rest.
 */
#ifndef LMBAKE_DENSITY_H
#define LMBAKE_DENSITY_H

#include "layout.h"

/* The largest density at which instance i is expected to fit one max_size atlas: its
 * largest chart's box plus padding within max_size, and its charts' boxes with padding
 * within 80% of the atlas area (what the packer reaches with many charts). Infinite for an
 * instance that keeps its TEXCOORD_1 (it gets its own atlas, clamped). */
double lmb_density_fit(const lmb_scene *s, const lmb_layout *l, const lmb_config *cfg, uint32_t instance);

/* atlas.min_chart_texels' floor for instance i: the density at which the charts that hold
 * at least half its world area (the area-weighted median of the charts' shorter box sides)
 * span min_chart_texels texels each way; 0 when the key is 0 or the instance keeps its
 * TEXCOORD_1. A few-centimetre prop in a 100 m level would otherwise get 1-3 texel charts. */
double lmb_density_floor(const lmb_scene *s, const lmb_layout *l, const lmb_config *cfg, uint32_t instance);

/* What the density choice needs of each instance list[k], whatever the budget: its fit, its
 * lightmapped world area and its atlas.min_chart_texels floor (0: none, or an override). */
typedef struct lmb_density_measures {
    double *fit, *area, *floor_d; /* per list entry */
} lmb_density_measures;

lmb_status lmb_density_measure(const lmb_scene *s, const lmb_config *cfg, const lmb_layout *l, const uint32_t *list,
                               uint32_t n, lmb_density_measures *out, lmb_error *err);
void lmb_density_measures_free(lmb_density_measures *m);

/* Sets l->instances[list[k]].texel_density for the lightmapped instances list[0..n), auto's
 * scene density filling `budget` texels (measures: lmb_density_measure of the same list).
 * Explicit densities far above what fits one atlas (their charts' boxes with padding over
 * 130% of it, or the longest chart longer than its side) are LMB_ERR_INPUT naming the instance
 * and the density estimated to fit, before anything is packed; nearer ones are left to the
 * packer, which names the instance if it cannot place it. */
lmb_status lmb_density_choose(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, const uint32_t *list,
                              uint32_t n, const lmb_density_measures *measures, uint64_t budget, const lmb_log *log,
                              lmb_density_report *report, lmb_error *err);

/* The first density_overrides entry matching instance i's node or mesh name, or 0. */
double lmb_density_override_for(const lmb_scene *s, const lmb_config *cfg, uint32_t instance);

/* Before charting: texels per object unit each mesh is expected to get, per_mesh[m] for
 * m < s->mesh_count (0 for meshes no instance lightmaps): the most over its lightmapped
 * instances of their density (an override, texel_density, or auto's sqrt(budget / world
 * area), before any fit cap or floor) times their linear scale (sqrt of world over object
 * area). Needs the soups. */
void lmb_density_expected(const lmb_scene *s, const lmb_config *cfg, const lmb_layout *l, double *per_mesh);

/* World area of instance i's lightmapped triangles. */
double lmb_instance_world_area(const lmb_scene *s, const lmb_layout *l, uint32_t instance);

#endif
