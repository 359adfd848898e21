/* The plan stage: layout to file and back (plan.h, lmbake.h). */
#include "plan.h"

#include "farm/part_file.h"
#include "farm/plan_codec.h"

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
                         lmb_error *err)
{
    memset(l, 0, sizeof *l);
    lmb_part_identity id;
    lmb_status st = lmb_part_identity_make(scene, cfg, &id, err);
    lmb_part_place want = {LMB_PART_PLAN, 0, 0, 1}, got;
    void *body = NULL;
    size_t size = 0;
    if (st == LMB_OK)
        st = lmb_part_read(plan_path, &id, &want, &got, &body, &size, err);
    if (st == LMB_OK)
        st = lmb_plan_decode(plan_path, body, size, scene, l, err);
    free(body);
    lmb_part_identity_free(&id);
    return st;
}
