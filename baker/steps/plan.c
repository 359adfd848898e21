/* The plan stage: layout to file and back (plan.h, lmbake.h). */
#include "plan.h"

#include "steps/part_file.h"
#include "steps/plan_codec.h"
#include "steps/runner.h"

#include <stdio.h>

#include <stdlib.h>
#include <string.h>

lmb_status lmb_plan_write(const lmb_scene *scene, const lmb_config *cfg, const char *plan_path,
                          lmb_progress_fn progress, void *progress_user, const lmb_log *log, lmb_error *err)
{
    lmb_layout l;
    lmb_part_identity id;
    memset(&id, 0, sizeof id);
    uint8_t *body = NULL;
    size_t size = 0;
    lmb_status st = lmb_layout_build(scene, cfg, progress, progress_user, log, &l, err);
    if (st == LMB_OK)
        st = lmb_plan_encode(&l, &body, &size, err);
    if (st == LMB_OK)
        st = lmb_part_identity_make(scene, cfg, &id, err);
    lmb_part_place place = {LMB_PART_PLAN, 0, 0, 1};
    if (st == LMB_OK)
        st = lmb_part_write(plan_path, &id, &place, body, size, err);
    if (st == LMB_OK)
        lmb_info(log, "plan: %s: %u atlas(es), %u charts, %zu bytes", plan_path, l.atlas_count, l.chart_total, size);
    free(body);
    lmb_part_identity_free(&id);
    lmb_layout_free(&l);
    return st;
}

lmb_status lmb_plan_read(const char *plan_path, const lmb_scene *scene, const lmb_config *cfg, lmb_layout *l,
                         lmb_part_identity *part_id, lmb_error *err)
{
    memset(l, 0, sizeof *l);
    if (part_id)
        memset(part_id, 0, sizeof *part_id);
    lmb_part_identity id;
    lmb_status st = lmb_part_identity_make(scene, cfg, &id, err);
    lmb_part_place want = {LMB_PART_PLAN, 0, 0, 1}, got;
    void *body = NULL;
    size_t size = 0;
    if (st == LMB_OK)
        st = lmb_part_read(plan_path, &id, &want, &got, &body, &size, err);
    if (st == LMB_OK)
        st = lmb_plan_decode(plan_path, body, size, scene, l, err);
    if (st == LMB_OK && part_id) { /* parts and states name this plan by its body's hash */
        lmb_sha256(body, size, id.plan);
        *part_id = id;
        id.config_text = NULL;
    }
    free(body);
    lmb_part_identity_free(&id);
    return st;
}

lmb_status lmb_farm_merge(const lmb_scene *scene, const lmb_config *cfg, const char *plan_path, const char *farm_dir,
                          uint32_t step, uint32_t shards, lmb_farm_merge_report *report, lmb_error *err)
{
    memset(report, 0, sizeof *report);
    lmb_layout l;
    lmb_part_identity id;
    lmb_status st = lmb_plan_read(plan_path, scene, cfg, &l, &id, err);
    lmb_merge_report r;
    if (st == LMB_OK)
        st = lmb_steps_merge(farm_dir, &id, step, shards, &r, err);
    if (st == LMB_OK) {
        report->end = r.end;
        report->noop = r.noop;
        report->items = r.items;
        snprintf(report->name, sizeof report->name, "%s", r.name);
    }
    lmb_layout_free(&l);
    lmb_part_identity_free(&id);
    return st;
}

uint32_t lmb_farm_end_step(const char *farm_dir)
{
    return lmb_steps_end_step(farm_dir);
}

lmb_status lmb_farm_make_dirs(const char *farm_dir, lmb_error *err)
{
    return lmb_steps_make_dirs(farm_dir, err);
}
