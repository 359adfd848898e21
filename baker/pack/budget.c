/* How a layout keeps the texel budget (layout.c builds, this file checks): the rounds that lower
 * the density until the layout makes at most 110% of atlas.texels, the log's word on it, and the
 * props that go to the light probes when no density can keep it (probe_lit.h). */
#include "layout_internal.h"
#include "coverage.h"
#include "density.h"
#include "probe_lit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A bake may make at most this share of atlas.texels (padding, partly covered edge texels and
 * raised small props included); a layout over it is made again at a lower density. */
#define BUDGET_SLACK 1.10
#define BUDGET_AIM 0.97
#define BUDGET_ROUNDS 6

/* The log's word on how the layout kept the texel budget (l->density after placing): no density
 * keeps it (impossible), over it after the rounds, made again, and props short of their
 * atlas.min_chart_texels floor. first_made: the first round's texels. */
static void report_budget(const lmb_config *cfg, const lmb_layout *l, const lmb_log *log, int impossible,
                          uint64_t first_made)
{
    uint64_t budget = l->density.budget, made = l->density.texels;
    double share = 100.0 * (double)made / (double)budget;
    if (impossible)
        lmb_warn(log,
                 "texel budget: the layout makes %llu texels, %.0f%% of atlas.texels %llu, and no density keeps it: "
                 "its %u charts take about %.0f texels whatever the density (every chart touches a few texels and "
                 "is padded; instanced copies repeat their mesh's charts), so the density stays %.4g texels per unit. "
                 "Raise atlas.texels, or give small props fewer charts or no lightmap",
                 (unsigned long long)made, share, (unsigned long long)budget, l->chart_total, l->density.floor_texels,
                 l->density.scene_density);
    else if (made > BUDGET_SLACK * (double)budget)
        lmb_warn(log, "texel budget: %llu texels made, %.0f%% of atlas.texels %llu, after %u layouts",
                 (unsigned long long)made, share, (unsigned long long)budget, l->density.rounds);
    else if (l->density.rounds > 1)
        lmb_info(log,
                 "texel budget: the layout at the budget's density made %.0f%% of atlas.texels %llu (small charts' "
                 "edge texels and padding, raised props); made again at %.4g texels per unit: %llu texels (%.0f%%)",
                 100.0 * (double)first_made / (double)budget, (unsigned long long)budget, l->density.scene_density,
                 (unsigned long long)made, share);
    if (l->density.short_of_floor)
        lmb_warn(log,
                 "atlas.min_chart_texels: %u small instance(s) fall short of charts %u texels wide to keep the texel "
                 "budget: they get %.0f%% of that density at least (charts down to %.1f texels); raise atlas.texels "
                 "to give them more",
                 l->density.short_of_floor, cfg->min_chart_texels, 100 * l->density.floor_share_min,
                 cfg->min_chart_texels * l->density.floor_share_min);
}

/* texel_density: auto: places for the budget and counts the texels the layout makes
 * (coverage.h). The density's estimate counts surface only; small charts also touch texels at
 * their edges and are padded, so a level of many small charts makes more. While a layout makes
 * more than BUDGET_SLACK x the budget, the budget asked of the density is lowered and the layout
 * made again: first by the ratio, then along the line through the last two layouts (texels =
 * a x asked + m: m is what the charts take at any density, their edges and padding). When m
 * alone is over the budget, no density keeps it: lowering would only take texels from the
 * surfaces that can use them, so the first layout stays and a warning gives the numbers. A
 * level within the budget keeps its first layout, unchanged. */
lmb_status lmb_layout_place_within_budget(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, const uint32_t *list,
                                      uint32_t n, const lmb_density_measures *measures, const lmb_log *log,
                                      int retry_if_over, int *over, lmb_error *err)
{
    uint64_t budget = lmb_config_atlas_texels(cfg), made = 0, first_made = 0;
    double asked = (double)budget, prev_asked = 0, prev_made = 0, floor_texels = 0;
    uint32_t round = 0;
    int impossible = 0;
    lmb_status st = LMB_OK;
    for (;;) {
        round++;
        st = lmb_layout_place(s, cfg, l, list, n, measures, (uint64_t)asked, round == 1 ? log : NULL, err);
        if (st != LMB_OK || !l->density.automatic)
            break;
        made = lmb_layout_count_texels(s, l, cfg->texel_samples, cfg->threads, err, &st);
        first_made = round == 1 ? made : first_made;
        if (st != LMB_OK || made <= BUDGET_SLACK * (double)budget || round >= BUDGET_ROUNDS)
            break;
        double next = asked * BUDGET_AIM * (double)budget / (double)made;
        if (round >= 2) {
            double a = ((double)prev_made - (double)made) / (prev_asked - asked);
            floor_texels = (double)made - a * asked;
            impossible = !(a > 0) || floor_texels >= BUDGET_AIM * (double)budget;
            if (!impossible)
                next = (BUDGET_AIM * (double)budget - floor_texels) / a;
        }
        lmb_layout_unplace(l);
        if (impossible) { /* the first layout again (the density for the whole budget), unless the caller
                             tries fewer charts or the probes first: then it places */
            if (!retry_if_over)
                st = lmb_layout_place(s, cfg, l, list, n, measures, budget, NULL, err);
            made = first_made;
            break;
        }
        prev_asked = asked;
        prev_made = (double)made;
        asked = fmax(1.0, floor(next));
    }
    if (st != LMB_OK)
        return st;
    l->density.budget = budget;
    l->density.texels = made;
    l->density.rounds = round;
    l->density.floor_texels = impossible ? floor_texels : 0;
    *over = impossible;
    if (impossible && retry_if_over)
        return LMB_OK; /* unplaced: the caller tries fewer charts, then the probes, first */
    report_budget(cfg, l, log, impossible, first_made);
    return LMB_OK;
}

/* The moved meshes' names and copies, for the warning ("'Prop' (10000), ..."). */
static void moved_names(const lmb_scene *s, const uint8_t *moved, char *names, size_t size)
{
    names[0] = '\0';
    uint32_t *copies = calloc((size_t)s->mesh_count + 1, sizeof *copies);
    if (!copies)
        return; /* the warning goes out without names */
    for (uint32_t i = 0; i < s->instance_count; i++) /* one pass: copies per mesh */
        copies[s->instances[i].mesh] += moved[i];
    size_t used = 0;
    uint32_t named = 0;
    for (uint32_t m = 0; m < s->mesh_count && used + 1 < size && named <= 3; m++) { /* by mesh index */
        if (!copies[m])
            continue;
        int w = named < 3 ? snprintf(names + used, size - used, "%s'%.40s' (%u)", named ? ", " : "", s->meshes[m].name,
                                     copies[m])
                          : snprintf(names + used, size - used, ", ...");
        used += w > 0 ? (size_t)w : 0;
        named++;
    }
    free(copies);
}

/* No density keeps the budget with every chart: either the rounds found the charts' floor over it
 * (failed == LMB_OK, l->density.floor_texels known) or a mesh's copies fit no atlas at any
 * density (failed == LMB_ERR_INPUT, l->unfit_mesh; err holds that error). The meshes drawn many
 * times whose charts cost the most (and any that fit no atlas, found again on each try) are lit by
 * the probes instead (probe_lit.h) and the rest placed again within the budget; measures become
 * the kept list's. With nothing to move: the layout for the whole budget and its warning, or the
 * error as it was. */
lmb_status lmb_layout_light_by_probes(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, const uint32_t *list,
                                      uint32_t n, lmb_density_measures *measures, const lmb_log *log,
                                      lmb_status failed, lmb_error *err)
{
    uint32_t *keep = malloc(((size_t)n + 1) * sizeof *keep);
    uint8_t *moved = malloc((size_t)s->instance_count + 1), *forced = calloc((size_t)s->mesh_count + 1, 1);
    double *area = malloc(((size_t)n + 1) * sizeof *area);
    if (!keep || !moved || !forced || !area) {
        free(keep);
        free(moved);
        free(forced);
        free(area);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    }
    memcpy(area, measures->area, (size_t)n * sizeof *area); /* the whole list's: measures become the kept one's */
    double floor_texels = failed == LMB_OK ? l->density.floor_texels : 0;
    uint64_t budget = lmb_config_atlas_texels(cfg);
    int unfit = failed != LMB_OK;
    if (unfit)
        forced[l->unfit_mesh] = 1;
    lmb_probe_lit_choice choice = {0};
    lmb_status st = failed;
    for (uint32_t tries = 0; tries <= s->mesh_count; tries++) {
        if (lmb_probe_lit_choose(s, l, list, n, area, floor_texels, budget, forced, keep, moved, &choice) != 0) {
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
            break;
        }
        if (!choice.moved)
            break;
        lmb_layout_unplace(l);
        lmb_density_measures_free(measures);
        st = lmb_density_measure(s, cfg, l, keep, choice.kept, measures, err);
        int over = 0;
        if (st == LMB_OK)
            st = lmb_layout_place_within_budget(s, cfg, l, keep, choice.kept, measures, log, 0, &over, err);
        if (st != LMB_ERR_INPUT || l->unfit_mesh == UINT32_MAX || forced[l->unfit_mesh])
            break;
        forced[l->unfit_mesh] = 1; /* another mesh's copies fit no atlas: it goes too */
        unfit = 1;
    }
    if (!choice.moved && failed == LMB_OK && st == LMB_OK) { /* nothing can go: the whole budget's layout, over it */
        uint64_t made = l->density.texels;
        st = lmb_layout_place(s, cfg, l, list, n, measures, budget, NULL, err);
        l->density.texels = made;
        if (st == LMB_OK)
            report_budget(cfg, l, log, 1, 0);
    }
    if (st == LMB_OK && choice.moved) {
        for (uint32_t i = 0; i < s->instance_count; i++)
            l->instances[i].probe_lit = moved[i];
        l->density.probe_lit = choice.moved;
        l->density.probe_lit_meshes = choice.moved_meshes;
        char names[160];
        moved_names(s, moved, names, sizeof names);
        int probes_off = !cfg->probes_auto && cfg->probe_volume_count == 0 && s->probe_volume_count == 0;
        const char *shadows = probes_off
                                  ? "; the probes are off (probes.auto false, no volumes), so they get no baked light"
                                  : ", and the probe grid covers them";
        if (floor_texels > 0 && !unfit)
            lmb_warn(log,
                     "texel budget: %u instance(s) of %u mesh(es) drawn many times are lit by the light probes, not "
                     "the lightmap: %s. With them every chart together takes about %.0f texels whatever the density, "
                     "%.0f%% of atlas.texels %llu (each chart touches a few texels and is padded; every copy repeats "
                     "its mesh's charts). They still cast shadows and bounce light%s. To lightmap them, raise "
                     "atlas.texels above about %.0f or give those meshes fewer charts",
                     choice.moved, choice.moved_meshes, names, floor_texels, 100.0 * floor_texels / (double)budget,
                     (unsigned long long)budget, shadows, 2.0 * floor_texels);
        else
            lmb_warn(log,
                     "texel budget: %u instance(s) of %u mesh(es) drawn many times are lit by the light probes, not "
                     "the lightmap: %s. The copies of a node share one atlas, and theirs fit no %ux%u atlas at any "
                     "density (each chart is padded; every copy repeats its mesh's charts). They still cast shadows "
                     "and bounce light%s. To lightmap them, raise atlas.max_size or give those meshes fewer charts",
                     choice.moved, choice.moved_meshes, names, cfg->max_atlas_size, cfg->max_atlas_size, shadows);
    }
    free(keep);
    free(moved);
    free(forced);
    free(area);
    return st;
}
