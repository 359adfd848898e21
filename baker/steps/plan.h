/*
 * The plan stage (docs/farm.md): a bake's layout in a file other stages (and other machines)
 * start from. lmb_plan_write (lmbake.h) writes it; lmb_plan_read gives the layout back after
 * checking the file against the scene and config the reader was given.
 */
#ifndef LMBAKE_FARM_PLAN_H
#define LMBAKE_FARM_PLAN_H

#include "steps/part_file.h"
#include "pack/layout.h"

#include <lmbake/lmbake.h>

/* *l := the layout in plan_path, made for this scene (its file and buffers) and this config
 * (threads aside); otherwise LMB_ERR_INPUT naming what differs. Free with lmb_layout_free.
 * part_id (may be NULL) receives the identity the farm's parts carry: this plan's, with the
 * SHA-256 of its body as `plan` (free with lmb_part_identity_free). */
lmb_status lmb_plan_read(const char *plan_path, const lmb_scene *scene, const lmb_config *cfg, lmb_layout *l,
                         lmb_part_identity *part_id, lmb_error *err);

#endif
