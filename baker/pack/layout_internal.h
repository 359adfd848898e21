/*
 * Shared by the layout's files: layout.c (unwrap, place, build) and budget.c (keeping the texel
 * budget: rounds of placement at lower densities, props to the light probes).
 */
#ifndef LMBAKE_LAYOUT_INTERNAL_H
#define LMBAKE_LAYOUT_INTERNAL_H

#include "density.h"
#include "layout.h"

/* One placement of the lightmapped instances list[0..n) (their charts unwrapped, measures
 * taken): densities for `budget` texels, then packing. log: the packer's messages, NULL to keep a
 * trial quiet. */
lmb_status lmb_layout_place(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, const uint32_t *list, uint32_t n,
                            const lmb_density_measures *measures, uint64_t budget, const lmb_log *log, lmb_error *err);

/* Undoes lmb_layout_place: the charts stay, every placement goes. */
void lmb_layout_unplace(lmb_layout *l);

/* texel_density: auto: places list[0..n) for the budget and again at lower densities while the
 * layout makes over 110% of it (budget.c). *over: no density can keep it; then with
 * retry_if_over the layout is left unplaced and quiet (the caller tries fewer charts or the
 * probes), else placed at the budget's density with a warning. */
lmb_status lmb_layout_place_within_budget(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l,
                                          const uint32_t *list, uint32_t n, const lmb_density_measures *measures,
                                          const lmb_log *log, int retry_if_over, int *over, lmb_error *err);

/* No density keeps the budget with every chart: failed == LMB_OK when the rounds found the charts'
 * floor over it (l->density.floor_texels), LMB_ERR_INPUT when a mesh's copies fit no atlas at any
 * density (l->unfit_mesh, err set). The props the probes light instead (probe_lit.h) leave list,
 * the rest is placed within the budget (measures become the kept list's); with nothing to move,
 * the layout for the whole budget and a warning, or the error as it was. */
lmb_status lmb_layout_light_by_probes(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, const uint32_t *list,
                                      uint32_t n, lmb_density_measures *measures, const lmb_log *log,
                                      lmb_status failed, lmb_error *err);

#endif
