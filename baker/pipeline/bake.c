/*
 * The bake pipeline driver: layout (unwrap + pack) -> ray-tracing scene, textures, lights ->
 * lighting (lighting.h: texels, direct light, bounce passes, final gather, dilation) ->
 * images (write/atlas_images.h); then the final gather's irradiance-cache records
 * (write/records_file.h) and the glTF with TEXCOORD_1 and MOZ_lightmap. Output is written
 * into a staging folder beside outdir and swapped into place only when everything succeeded
 * (write/output_dir.h), so a failed or killed bake leaves nothing behind; outdir may
 * not be the input's own folder (the input and its .bin files are never written over).
 */
#include <lmbake/lmbake.h>

#include "util/clock.h"
#include "util/memory.h"
#include "steps/plan.h"
#include "steps/runner.h"
#include "watch/layout_cache.h"
#include "watch/stages_out.h"
#include "watch/probe_cache.h"
#include "watch/validity_cache.h"
#include "pipeline/group_cache.h"
#include "pipeline/group_lighting.h"
#include "pipeline/group_store.h"
#include "pipeline/lighting.h"
#include "pipeline/stage_options.h"
#include "lights/direct.h"
#include "lights/light_groups.h"
#include "load/gltf_adapter.h"
#include "load/textures.h"
#include "pack/coverage.h"
#include "pack/layout.h"
#include "texels/dilate.h"
#include "post/fireflies.h"
#include "probes/probes.h"
#include "seams/seams.h"
#include "texels/texels.h"
#include "write/atlas_images.h"
#include "write/ktx2.h"
#include "write/lightmapped_gltf.h"
#include "write/output_dir.h"
#include "write/records_file.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A bake of `texels` texels (0: not known yet) must fit the memory left: otherwise an error
 * naming the key, the estimate and what fits, before the work that would be killed. */
/* The block KTX2 format's name as the log says it (output.ktx2_format: bc6h or astc_hdr). */
static const char *block_format_name(const lmb_config *cfg)
{
    return cfg->ktx2_format == LMB_KTX2_BC6H ? "BC6H" : "ASTC HDR";
}

static lmb_status texels_fit_memory(const lmb_config *cfg, uint64_t texels, lmb_error *err)
{
    uint64_t avail = lmb_memory_available();
    double need = (double)LMB_BAKE_BASE_BYTES + 1.1 * (double)texels * (double)LMB_BAKE_BYTES_PER_TEXEL;
    if (!texels || !avail || need <= (double)avail)
        return LMB_OK;
    double fits = ((double)avail - (double)LMB_BAKE_BASE_BYTES) / (1.1 * (double)LMB_BAKE_BYTES_PER_TEXEL);
    const char *where = cfg->config_path[0] ? cfg->config_path : "the config";
    if (cfg->texel_density > 0)
        return lmb_error_set(err, LMB_ERR_INPUT,
                             "%s: texel_density %g makes %llu texels: a bake of them needs about %.1f GB (%llu bytes "
                             "per texel over a %llu MB base) and %.1f GB is available; lower texel_density (about %.0f "
                             "texels fit)",
                             where, cfg->texel_density, (unsigned long long)texels, need / 1e9,
                             LMB_BAKE_BYTES_PER_TEXEL, LMB_BAKE_BASE_BYTES >> 20, (double)avail / 1e9, fmax(fits, 0));
    return lmb_error_set(err, LMB_ERR_INPUT,
                         "%s: atlas.texels %llu: a bake of that many texels needs about %.1f GB (%llu bytes per texel "
                         "over a %llu MB base) and %.1f GB is available; lower atlas.texels (at most about %.0f fits)",
                         where, (unsigned long long)texels, need / 1e9, LMB_BAKE_BYTES_PER_TEXEL,
                         LMB_BAKE_BASE_BYTES >> 20, (double)avail / 1e9, fmax(fits, 0));
}

/* Nothing emits light: every lightmap is exactly black whatever the passes would compute, so
 * none runs (no gather points, no rays, no seams). Each atlas's texels are those the layout
 * lists (coverage.h), marked valid for the mask and the dilation; no texel is tested for lying
 * inside geometry. Directional maps, when asked for, point nowhere (D = 0). */
/* lmb_farm_run.relight_only: LMB_OK when the layout was read back and every light group is kept
 * in the layout cache (the bake only sums and writes), else LMB_NOT_KEPT saying what is not. */
static lmb_status relight_only(const lmb_scene *s, const lmb_config *cfg, const lmb_farm_run *run,
                               const lmb_light_groups *groups, lmb_error *err)
{
    if (!groups->count)
        return lmb_error_set(err, LMB_NOT_KEPT, "--relight-only: %s has no light groups (output.light_groups)", s->path);
    if (!run->layout_reused)
        return lmb_error_set(err, LMB_NOT_KEPT, "--relight-only: the layout is not kept in %s", run->layout_cache);
    uint8_t(*keys)[32] = malloc((size_t)groups->count * sizeof *keys);
    if (!keys)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: out of memory");
    lmb_status st = lmb_group_cache_keys(s, cfg, groups, keys, err);
    for (uint32_t g = 0; g < groups->count && st == LMB_OK; g++)
        if (!lmb_group_cache_has(run->layout_cache, keys[g]))
            st = lmb_error_set(err, LMB_NOT_KEPT, "--relight-only: light group '%s' is to be lit (its light is not "
                               "kept in %s)", groups->name[g], run->layout_cache);
    free(keys);
    return st;
}

static lmb_status dark_atlases(const lmb_scene *s, const lmb_config *cfg, const lmb_layout *l, lmb_cache *cache,
                               lmb_bake_stats *stats, lmb_error *err)
{
    stats->no_light = 1;
    if (cfg->directional && !cache->direction)
        cache->direction = calloc((size_t)l->atlas_count + 1, sizeof *cache->direction);
    if (cfg->directional && !cache->direction)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory");
    for (uint32_t a = 0; a < l->atlas_count; a++) {
        size_t n = (size_t)l->width[a] * l->height[a];
        uint8_t *map = lmb_layout_texel_map(s, l, a, cfg->texel_samples, cfg->threads);
        if (!map)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", a);
        for (size_t k = 0; k < n; k++) {
            cache->state[a][k] = map[k] ? LMB_TEXEL_VALID : LMB_TEXEL_EMPTY;
            stats->texels += map[k];
        }
        stats->valid_texels = stats->texels;
        free(map);
        if (cfg->directional && !(cache->direction[a] = calloc(3 * n + 1, sizeof **cache->direction)))
            return lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", a);
    }
    return LMB_OK;
}

/* The post stage on the final lightmaps (docs/artists.md): fireflies spread to their
 * neighbours, then seams stitched. */
static lmb_status post_process(const lmb_scene *s, const lmb_config *cfg, const lmb_layout *l, const lmb_rt *rt,
                               lmb_cache *cache, lmb_progress_fn progress, void *user, lmb_bake_stats *stats,
                               const lmb_log *log, lmb_error *err)
{
    lmb_status st = LMB_OK;
    if (st == LMB_OK && cfg->firefly_spread && !cfg->reference) {
        lmb_firefly_stats fs = {0, 0, 0};
        for (uint32_t a = 0; st == LMB_OK && a < l->atlas_count; a++) {
            if (progress)
                progress(user, "fireflies", a, l->atlas_count);
            uint64_t before = fs.texels, last = ~0ull;
            /* a spike shared with its neighbours may leave them above the bound: again, a few times */
            for (int pass = 0; pass < LMB_FIREFLY_PASSES && st == LMB_OK && fs.texels != last; pass++) {
                last = fs.texels;
                double total = fs.total;
                st = lmb_fireflies_spread(cache->irradiance[a], cache->state[a], l->width[a], l->height[a],
                                          (int)cfg->threads, &fs, err);
                if (pass)
                    fs.total = total; /* the atlas's light counts once */
            }
            if (st == LMB_OK && fs.texels > before) /* padding follows the texels it was dilated from */
                st = lmb_dilate(cache->irradiance[a], cache->state[a], l->width[a], l->height[a], (int)cfg->threads,
                                err);
        }
        if (progress && st == LMB_OK)
            progress(user, "fireflies", l->atlas_count, l->atlas_count);
        stats->firefly_texels = fs.texels;
        stats->firefly_moved = fs.total > 0 ? fs.moved / fs.total : 0;
        if (st == LMB_OK && fs.texels)
            lmb_info(log, "fireflies: %llu texels above %gx the median around them; %.4f%% of the light moved to their "
                     "neighbours (none removed)", (unsigned long long)fs.texels, LMB_FIREFLY_FACTOR,
                     100 * stats->firefly_moved);
    }
    if (st == LMB_OK && cfg->seam_stitch) {
        lmb_seam_report sr;
        if (progress)
            progress(user, "seams", 0, 1);
        st = lmb_seams_stitch(s, l, rt, cache->irradiance, (const uint8_t *const *)cache->state, (int)cfg->threads, &sr,
                              err);
        if (progress && st == LMB_OK)
            progress(user, "seams", 1, 1);
        stats->seam_edges = sr.edges;
        stats->seam_jump_before = sr.jump_before;
        stats->seam_jump_after = sr.jump_after;
        if (st == LMB_OK && sr.equal)
            lmb_info(log, "seams: %llu edges (%llu points): both sides read the same light everywhere, nothing to "
                     "stitch (%.2fs)", (unsigned long long)sr.edges, (unsigned long long)sr.samples, sr.seconds);
        else if (st == LMB_OK && sr.edges)
            lmb_info(log, "seams: %llu edges stitched (%llu points, %llu left unmatched, %llu texels) in %.2fs; largest "
                     "jump %.2f%% -> %.2f%%; points over 1%%: %llu -> %llu", (unsigned long long)sr.edges,
                     (unsigned long long)sr.samples, (unsigned long long)sr.dropped, (unsigned long long)sr.texels,
                     sr.seconds, 100 * sr.jump_before, 100 * sr.jump_after, (unsigned long long)sr.over_1pct_before,
                     (unsigned long long)sr.over_1pct);
    }
    return st;
}

lmb_status lmb_bake(lmb_scene *s, const lmb_config *cfg, const char *outdir, lmb_progress_fn progress, void *user,
                    lmb_bake_stats *stats, const lmb_log *log, lmb_error *err)
{
    return lmb_bake_planned(s, cfg, NULL, outdir, progress, user, stats, log, err);
}

lmb_status lmb_bake_planned(lmb_scene *s, const lmb_config *cfg, const char *plan_path, const char *outdir,
                            lmb_progress_fn progress, void *user, lmb_bake_stats *stats, const lmb_log *log,
                            lmb_error *err)
{
    lmb_farm_run run = {LMB_FARM_LOCAL, NULL, 0, 0, 1, 0, 0, 0, 1, 0, NULL, 0, 0, 0};
    return lmb_bake_farm(s, cfg, plan_path, &run, outdir, progress, user, stats, log, err);
}

lmb_status lmb_bake_farm(lmb_scene *s, const lmb_config *cfg, const char *plan_path, lmb_farm_run *run,
                         const char *outdir, lmb_progress_fn progress, void *user, lmb_bake_stats *stats,
                         const lmb_log *log, lmb_error *err)
{
    lmb_bake_stats unused;
    if (!stats)
        stats = &unused;
    int worker = run->mode == LMB_FARM_WORKER, finishes = worker && outdir && run->worker == 0;
    int shard = run->mode == LMB_FARM_STEP || (worker && !finishes), writes = !shard;
    if (run->mode != LMB_FARM_LOCAL && !plan_path)
        return lmb_error_set(err, LMB_ERR_USAGE, "a farm step, worker or finish needs the plan ('lmbake plan')");
    if (shard && (run->shards == 0 || run->shard >= run->shards))
        return lmb_error_set(err, LMB_ERR_USAGE, "shard %u of %u: out of range", run->shard + 1, run->shards);
    run->ended = 0;
    run->layout_reused = 0;
    double t0 = lmb_seconds();
    memset(stats, 0, sizeof *stats);
    lmb_scene_set_light_modes(s, cfg, shard ? NULL : log); /* mixed lighting: which lights the bake holds */
    lmb_output_dir od;
    memset(&od, 0, sizeof od);
    lmb_status st = writes ? lmb_output_dir_open(&od, outdir, s->path, log, err) : LMB_OK;
    if (st != LMB_OK)
        return st;
    lmb_part_identity id;
    memset(&id, 0, sizeof id);
    lmb_steps *steps = NULL;
    lmb_layout l;
    lmb_rt rt;
    lmb_emitters *em = NULL;
    lmb_direct *direct = NULL;
    lmb_sky *sky = NULL;
    lmb_sky *unit_sky = NULL; /* the sky of a unit light group: sky.intensity 1 (its weight, after) */
    lmb_emitters *unit_em = NULL; /* the emitters of a unit light group: emission 1 (its weight, after) */
    lmb_textures tx;
    lmb_cache cache;
    lmb_ic_points records = {NULL, 0};
    lmb_probe_set probes;
    memset(&probes, 0, sizeof probes);
    lmb_light_groups groups; /* output.light_groups: none unless the level has some */
    memset(&groups, 0, sizeof groups);
    lmb_group_light group_light;
    memset(&group_light, 0, sizeof group_light);
    /* the groups' light kept between bakes beside the layouts (a local bake with --layout-cache:
     * the watch's), or NULL */
    const char *groups_kept = run->layout_cache && run->mode == LMB_FARM_LOCAL && !plan_path ? run->layout_cache : NULL;
    lmb_point_validity validity; /* with a layout cache: the gather points' validity kept between bakes */
    memset(&validity, 0, sizeof validity);
    uint64_t validity_read = 0;
    memset(&l, 0, sizeof l);
    memset(&rt, 0, sizeof rt);
    memset(&tx, 0, sizeof tx);
    memset(&cache, 0, sizeof cache);
    lmb_sky_options sky_opt = lmb_sky_options_of(cfg);
    st = lmb_sky_create(&sky_opt, s, log, &sky, err); /* before the layout: a bad sky.image stops the bake at once */
    if (st == LMB_OK && !plan_path)
        st = texels_fit_memory(cfg, cfg->texel_density > 0 ? 0 : lmb_config_atlas_texels(cfg), err);
    if (st == LMB_OK && plan_path) /* the plan stage's layout (steps/plan.h), checked against this scene and config */
        st = lmb_plan_read(plan_path, s, cfg, &l, &id, err);
    else if (st == LMB_OK && run->layout_cache && run->mode == LMB_FARM_LOCAL)
        st = lmb_layout_cached(s, cfg, run->layout_cache, progress, user, log, &l, &run->layout_reused, err);
    else if (st == LMB_OK)
        st = lmb_layout_build(s, cfg, progress, user, log, &l, err);
    /* an explicit density: the texels it made (a layout read back passed this when it was built) */
    if (st == LMB_OK && !plan_path && !run->layout_reused && cfg->texel_density > 0) {
        uint64_t made = lmb_layout_count_texels(s, &l, cfg->texel_samples, cfg->threads, err, &st);
        if (st == LMB_OK)
            st = texels_fit_memory(cfg, made, err);
    }
    if (st == LMB_OK && progress)
        progress(user, "scene set-up", 0, 1); /* ray-tracing scene, textures, lights, bounce cache */
    if (st == LMB_OK) /* before the ray-tracing scene: alpha and transmission textures decide what rays pass */
        st = lmb_textures_load(s, &tx, log, err);
    if (st == LMB_OK)
        st = lmb_rt_build(s, &tx, &rt, err);
    if (st == LMB_OK && !shard)
        lmb_info(log, "ray tracing: %llu triangles placed, %llu stored (meshes used more than once are Embree "
                 "instances), built in %.2f s", (unsigned long long)rt.placed_triangles,
                 (unsigned long long)rt.stored_triangles, rt.build_seconds);
    uint32_t moving[4] = {0, 0, 0, 0};
    for (uint32_t i = 0; i < s->instance_count; i++)
        moving[s->instances[i].motion] += !s->instances[i].occludes;
    if (st == LMB_OK && !shard && (moving[LMB_SKINNED] || moving[LMB_MORPHING] || moving[LMB_LOWER_LOD]))
        lmb_info(log, "what moves: %u skinned, %u morphing and %u lower-LOD instance(s) are not lightmapped and cast no "
                 "baked shadow; the light probes light them (a node's extras.%s: true makes it static scenery)",
                 moving[LMB_SKINNED], moving[LMB_MORPHING], moving[LMB_LOWER_LOD], cfg->extras_key);
    if (st == LMB_OK && !shard && (rt.cut_triangles || rt.partial_triangles))
        lmb_info(log, "materials: %llu placed triangles have alpha cut-outs (alphaMode MASK), %llu let light through "
                 "in part (alphaMode BLEND, KHR_materials_transmission); every ray sees them as their material says",
                 (unsigned long long)rt.cut_triangles, (unsigned long long)rt.partial_triangles);
    lmb_emitter_options emitter_opt = lmb_emitter_options_of(cfg);
    if (st == LMB_OK)
        st = lmb_emitters_build(s, &emitter_opt, &tx, &em, err);
    lmb_direct_options direct_opt = lmb_direct_options_of(cfg);
    if (st == LMB_OK)
        st = lmb_direct_create(s, &direct_opt, &rt, em, sky, &direct, err);
    /* light groups (not for bake --direct-of: the watch's look at some lights' direct light) */
    if (st == LMB_OK && !cfg->direct_of_count)
        st = lmb_light_groups_resolve(s, cfg, sky != NULL, lmb_emitters_power(em), &groups, err);
    if (st == LMB_OK && groups.count && !shard)
        lmb_light_groups_report(&groups, s, log);
    if (st == LMB_OK && run->relight_only)
        st = relight_only(s, cfg, run, &groups, err);
    if (st == LMB_OK)
        st = lmb_cache_init(&cache, s, &l, &rt, &tx, err);
    cache.threads = cfg->threads;
    cache.backs_reflect = cfg->reflect_sides == LMB_EMIT_MATERIAL;
    cache.ray_spread = sqrt(LMB_PI / (cfg->gather_rays ? cfg->gather_rays : 1));
    if (st == LMB_OK && progress)
        progress(user, "scene set-up", 1, 1);
    lmb_steps_mode mode = run->mode == LMB_FARM_STEP ? LMB_STEPS_SHARD : run->mode == LMB_FARM_FINISH ? LMB_STEPS_FINISH
                                                                                                   : LMB_STEPS_LOCAL;
    lmb_steps_worker sw = {run->shards, run->worker, run->workers, run->wait_timeout};
    if (st == LMB_OK && worker)
        st = lmb_steps_create_worker(run->farm_dir, &id, &sw, (double)cfg->farm_min_step_rays, log, &steps, err);
    else if (st == LMB_OK)
        st = lmb_steps_create(mode, run->farm_dir, &id, run->step, run->shard, run->shards,
                              (double)cfg->farm_min_step_rays, log, &steps, err);
    double tl = lmb_seconds();
    int dark = st == LMB_OK && !lmb_direct_any_light(direct);
    if (dark && !shard)
        lmb_warn(log, "%s: nothing emits light (no KHR_lights_punctual light, no emissive material, no sky): the "
                 "lightmaps are black; no light is computed", s->path);
    /* the validity memo holds what the geometry decides; MASK cut-outs decide it too (from
     * materials and textures the layout cache does not key on): levels with them test again */
    if (st == LMB_OK && !dark && run->layout_cache && run->mode == LMB_FARM_LOCAL && !plan_path && !rt.cut_geoms) {
        st = lmb_point_validity_init(&validity, &l, cfg->texel_samples, err);
        if (st == LMB_OK && lmb_validity_cache_read(s, cfg, run->layout_cache, &validity, log))
            validity_read = lmb_point_validity_known(&validity);
        if (st == LMB_OK)
            lmb_direct_set_validity(direct, &validity);
    }
    /* the lighting's hooks: progress, and each stage's light to the watch's folder when asked */
    lmb_stages_out so = {cfg, log};
    lmb_lighting_hooks hooks = {progress, user, cfg->stages_out[0] ? lmb_stages_out_stage : NULL, &so};
    if (st == LMB_OK && dark)
        st = dark_atlases(s, cfg, &l, &cache, stats, err);
    else if (st == LMB_OK && !groups.count)
        st = lmb_light_atlases(cfg, direct, &cache, steps, &hooks, stats, &records, log, err);
    /* light probes: placed in every process alike, lit as a step from the finished cache (not
     * for bake --direct-of: the watch reads only its lightmaps) */
    /* with a layout cache, the placement (rays, qhull) is read back with the layout when a bake
     * left it (watch/probe_cache.h); MASK cut-outs decide it too, as they do the validity */
    int probes_kept = run->layout_cache && run->mode == LMB_FARM_LOCAL && !plan_path && !rt.cut_geoms, probes_read = 0;
    if (st == LMB_OK && !cfg->direct_of_count) {
        probes_read = probes_kept && lmb_probe_cache_read(s, cfg, run->layout_cache, &probes, log);
        if (!probes_read)
            st = lmb_probes_place(s, &l, cfg, &rt, shard ? NULL : log, &probes, err);
    }
    if (st == LMB_OK && groups.count && !dark && groups.sky >= 0 && groups.unit[groups.sky]) {
        lmb_sky_options unit_opt = lmb_sky_options_of(cfg);
        unit_opt.intensity = 1;
        for (int c = 0; c < 3 && groups.sky_color_weight; c++)
            unit_opt.color[c] = 1; /* sky.color is the group's weight too */
        st = lmb_sky_create(&unit_opt, s, NULL, &unit_sky, err);
    }
    if (st == LMB_OK && groups.count && !dark && groups.emissive >= 0 && groups.unit[groups.emissive]) {
        lmb_emitter_options unit_opt = emitter_opt;
        unit_opt.unit = 1;
        st = lmb_emitters_build(s, &unit_opt, &tx, &unit_em, err);
    }
    if (st == LMB_OK && groups.count && !dark) { /* each group's lighting and probes on its own */
        lmb_lighting_hooks group_hooks = {progress, user, NULL, NULL};
        lmb_group_env ge = {s, cfg, &direct_opt, &rt, unit_em ? unit_em : em, unit_sky ? unit_sky : sky, &cache, steps, &group_hooks,
                            validity.entry ? &validity : NULL, cfg->direct_of_count ? NULL : &probes, !shard,
                            groups_kept, shard ? NULL : log};
        st = lmb_group_lighting(&ge, &groups, stats, &records, &group_light, err);
    } else if (st == LMB_OK) {
        st = lmb_probes_light(&probes, cfg, direct, &cache, steps, dark, progress, user, shard ? NULL : log, err);
    }
    if (st == LMB_OK && validity.entry) {
        if (validity_read)
            lmb_info(log, "gather points: the validity of %llu read back with the layout (their rays not traced again)",
                     (unsigned long long)validity_read);
        if (lmb_point_validity_known(&validity) > validity_read)
            lmb_validity_cache_write(s, cfg, run->layout_cache, &validity, log);
    }
    if (direct)
        lmb_direct_set_validity(direct, NULL);
    lmb_point_validity_free(&validity);
    if (st == LMB_OK && worker)
        st = lmb_steps_worker_end(steps, err);
    if (worker && !finishes) {
        run->steps = lmb_steps_count(steps);
        goto done;
    }
    if (shard) { /* the shard's part is written (stopped), or the bake ended before its step */
        if (st == LMB_OK) {
            st = lmb_steps_write_end(steps, err);
            run->ended = 1;
        } else if (st == LMB_STEP_STOPPED) {
            st = LMB_OK;
        }
        run->steps = lmb_steps_count(steps);
        goto done;
    }
    run->steps = lmb_steps_count(steps);
    /* After the last step a worker writing the output runs alone: the cores the other workers
     * used are free, and the output is the same bytes at any thread count. */
    lmb_config tail_cfg = *cfg;
    if (finishes)
        tail_cfg.threads = run->tail_threads;
    cfg = &tail_cfg;
    if (st == LMB_OK && !dark && !groups.count)
        st = post_process(s, cfg, &l, &rt, &cache, progress, user, stats, log, err);
    /* light groups: each group's lightmap through the post stage (a group read back from the
     * cache had it), kept for the next bake, then their sum at the scales */
    for (uint32_t g = 0; st == LMB_OK && !dark && g < groups.count; g++) {
        if (group_light.cached[g])
            continue;
        st = lmb_group_light_bring_back(&group_light, g, err);
        if (st != LMB_OK)
            break;
        lmb_group_swap(&group_light, g, &cache);
        st = post_process(s, cfg, &l, &rt, &cache, progress, user, stats, log, err);
        lmb_group_swap(&group_light, g, &cache);
        if (st == LMB_OK && groups_kept)
            lmb_group_cache_write(groups_kept, group_light.key[g], g, &group_light, &cache, probes.count,
                                  stats->texels, stats->valid_texels, log);
        lmb_group_light_put_away(&group_light, g, log);
    }
    if (st == LMB_OK && !dark && groups.count)
        st = lmb_group_compose(&groups, &group_light, &cache, &probes, err);
    /* The light is done: what only lighting read goes before the images, where OpenImageIO's
     * libraries are loaded (the lights before the ray-tracing scene they point into). */
    lmb_direct_free(direct);
    direct = NULL;
    lmb_sky_free(sky);
    sky = NULL;
    lmb_sky_free(unit_sky);
    unit_sky = NULL;
    lmb_emitters_free(unit_em);
    unit_em = NULL;
    lmb_emitters_free(em);
    em = NULL;
    lmb_textures_free(&tx);
    lmb_rt_free(&rt);
    lmb_atlas_output *outputs = calloc((size_t)l.atlas_count + 1, sizeof *outputs);
    if (st == LMB_OK && !outputs)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "output: out of memory");
    uint64_t clamped = 0;
    for (uint32_t a = 0; st == LMB_OK && a < l.atlas_count; a++) {
        if (progress)
            progress(user, "images", a, l.atlas_count);
        st = lmb_write_atlas_images(cfg, od.staging, od.stem, a, cache.irradiance[a], cache.state[a], l.width[a],
                                    l.height[a], groups.count > 0 && !dark, &outputs[a], err);
        clamped += outputs[a].rgbm_clamped;
        if (st == LMB_OK && outputs[a].rgbm_clamped)
            lmb_warn(log, "atlas %u: %llu texels brighter than RGBM's range %g were clamped (output.rgbm_range; auto "
                     "fits the brightest texel)", a, (unsigned long long)outputs[a].rgbm_clamped, outputs[a].rgbm_range);
        if (st == LMB_OK && outputs[a].ktx2.encode_seconds > 0)
            lmb_info(log, "atlas %u: %s blocks of %ux%u texels encoded in %.2fs", a,
                     block_format_name(cfg), l.width[a], l.height[a],
                     outputs[a].ktx2.encode_seconds);
        if (st == LMB_OK && outputs[a].ktx2.clamped)
            lmb_warn(log, "atlas %u: %llu texels brighter than %s's range (65504) were clamped in the .ktx2 (output.scale: "
                     "radiance divides by pi)", a, (unsigned long long)outputs[a].ktx2.clamped,
                     block_format_name(cfg));
    }
    if (progress && st == LMB_OK)
        progress(user, "images", l.atlas_count, l.atlas_count);
    stats->rgbm_clamped = clamped;
    /* each group's own files: its light as lit (a group of one source at intensity 1; the glTF
     * names the intensity a game multiplies it by), the same bytes at any scale and intensity,
     * so a group read back from the cache copies the files it kept instead of encoding them */
    for (uint32_t g = 0; st == LMB_OK && !dark && g < groups.count; g++) {
        for (uint32_t a = 0; st == LMB_OK && a < l.atlas_count; a++) {
            char paths[LMB_GROUP_FILES][LMB_GROUP_IMAGE_PATH];
            const char *const names[LMB_GROUP_FILES] = {paths[0], paths[1], paths[2]};
            uint32_t files = lmb_group_image_paths(cfg, od.staging, od.stem, a, groups.name[g], paths);
            if (group_light.cached[g] && groups_kept &&
                lmb_group_cache_copy_files(groups_kept, group_light.key[g], a, names, files, log))
                continue;
            st = lmb_group_light_bring_back(&group_light, g, err); /* its images, for its files alone */
            if (st != LMB_OK)
                break;
            lmb_ktx2_report ktx2 = {0};
            st = lmb_write_group_images(cfg, od.staging, od.stem, a, groups.name[g],
                                        group_light.irradiance[(size_t)g * l.atlas_count + a], cache.state[a],
                                        l.width[a], l.height[a], &ktx2, err);
            if (st == LMB_OK && ktx2.clamped)
                lmb_warn(log, "atlas %u, light group '%s': %llu texels brighter than %s's range (65504) were clamped in "
                         "its .ktx2", a, groups.name[g], (unsigned long long)ktx2.clamped,
                         block_format_name(cfg));
            if (st == LMB_OK && groups_kept)
                lmb_group_cache_keep_files(groups_kept, group_light.key[g], a, names, files, log);
        }
        lmb_group_light_drop(&group_light, g); /* nothing reads its images after its files */
    }
    for (uint32_t a = 0; st == LMB_OK && cache.shadowmask && a < l.atlas_count; a++)
        st = lmb_write_shadowmask_image(od.staging, od.stem, a, cache.shadowmask[a], l.width[a], l.height[a], err);
    for (uint32_t a = 0; st == LMB_OK && cache.direction && a < l.atlas_count; a++)
        st = lmb_write_direction_images(cfg, od.staging, od.stem, a, cache.direction[a], l.width[a], l.height[a], err);
    stats->light_seconds = lmb_seconds() - tl;
    stats->atlases = l.atlas_count;
    stats->texel_density = l.density.scene_density;
    stats->density_auto = l.density.automatic;
    stats->density_capped = l.density.capped;
    stats->density_raised = l.density.raised;
    if (st == LMB_OK && progress)
        progress(user, "glTF", 0, 1);
    if (st == LMB_OK) {
        lmb_copy_input_textures(s, &od, log);
        lmb_gltf_probes out_probes;
        st = lmb_probes_output(&probes, cfg, od.staging, od.stem, log, &out_probes, err);
        for (uint32_t g = 0; st == LMB_OK && !dark && group_light.sh && g < groups.count; g++) /* as its files */
            st = lmb_probes_output_group(&out_probes, &probes, cfg, od.staging, od.stem, g, groups.name[g],
                                         groups.scale[g], groups.weight[g],
                                         group_light.sh[g], group_light.cube[g], err);
        if (st == LMB_OK)
            st = lmb_write_lightmapped_gltf(s, cfg, &l, od.staging, od.stem, outputs, &records, cache.direction != NULL,
                                            cache.shadowmask != NULL, &out_probes, dark ? NULL : &groups, err);
        lmb_probes_output_free(&out_probes);
    }
    free(outputs);
    if (st == LMB_OK)
        st = lmb_output_dir_commit(&od, err);
    else
        lmb_output_dir_abort(&od);
    if (st == LMB_OK && probes_kept && !probes_read)
        lmb_probe_cache_write(s, cfg, run->layout_cache, &probes, log);
    if (st == LMB_OK && progress)
        progress(user, "glTF", 1, 1);
    if (st == LMB_OK)
        snprintf(stats->gltf_path, sizeof stats->gltf_path, "%s/%s.gltf", outdir, od.stem);
done:
    lmb_group_light_free(&group_light);
    lmb_light_groups_free(&groups);
    lmb_point_validity_free(&validity);
    lmb_steps_free(steps);
    lmb_part_identity_free(&id);
    lmb_cache_free(&cache);
    free(records.xyzr);
    lmb_probe_set_free(&probes);
    lmb_direct_free(direct);
    lmb_sky_free(sky);
    lmb_sky_free(unit_sky);
    lmb_emitters_free(unit_em);
    lmb_emitters_free(em);
    lmb_textures_free(&tx);
    lmb_rt_free(&rt);
    lmb_layout_free(&l);
    stats->seconds = lmb_seconds() - t0;
    return st;
}
