/*
 * `lmbake bake SCENE [-c CONFIG] [-o OUTDIR]`: the whole pipeline on one level.
 * Command-line values override the config file, which overrides the defaults.
 * Stages: load, select, then lmb_bake (unwrap, pack, texels, direct light, bounce passes,
 * final gather or the path-traced reference, dilation, write).
 */
#include "bake_args.h"
#include "cli_common.h"
#include "commands.h"
#include "node_tool.h"
#include "progress.h"
#include "timings.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char help[] =
    "usage: lmbake bake SCENE [options]\n"
    "\n"
    "Bakes lightmaps for SCENE (.gltf or .glb) into OUTDIR; the input is never modified.\n"
    "\n"
    "  -c, --config FILE   per-level bake config (YAML); see assets/example-config.yaml\n"
    "  -o, --output DIR    output folder (default: ./lmbake-out)\n"
    "      --threads N     worker threads, 0 = all cores (overrides the config)\n"
    "      --seed N        random seed (overrides the config)\n"
    "      --method M      final gather: cosine, amis or amis_defensive (overrides gather.method)\n"
    "      --rays N        final gather rays per texel (overrides samples.gather)\n"
    "      --preview       also render the views of `lmbake preview` (lit, lightmap, checker,\n"
    "                      invalid, atlases) headless to OUTDIR/preview-<view>.png\n"
    "      --reference     path-trace indirect light with no cache (ground truth for error\n"
    "                      measurement; --rays paths per texel: use many)\n"
    "      --quick         a quick look: half the texel density (its own atlases), a quarter\n"
    "                      of the rays, the irradiance cache sparser, at most two bounce\n"
    "                      passes, no seam stitching or probes, only the .hdr and .png\n"
    "                      (docs/watch.md)\n"
    "      --direct-of LIGHT\n"
    "                      bake only the direct light of LIGHT (a glob over light and light\n"
    "                      node names; repeatable, at most 16): no bounces, sky or emissive\n"
    "                      surfaces, only the .hdr and .png (one light's share of a bake,\n"
    "                      for scripts that relight a level light by light)\n"
    "      --stages-out DIR\n"
    "                      write the light of each stage as soon as it is known, per atlas as\n"
    "                      DIR/direct/<name>-lightmap-N.hdr (the direct light) and\n"
    "                      DIR/bounces/... (after the bounce passes), and say so in the log\n"
    "                      (what preview --watch refines its quick picture with, docs/watch.md)\n"
    "      --plan PLAN     start from a plan written by 'lmbake plan' (same input and config,\n"
    "                      threads aside; otherwise refused, naming what differs): no unwrap\n"
    "      --layout-cache DIR\n"
    "                      keep the layout (unwrap, pack) in DIR and read it back when only\n"
    "                      lights, materials, sky or sampling changed (what preview --watch\n"
    "                      does between bakes): the same files, byte for byte\n"
    "      --relight-only  with --layout-cache and light groups: bake only when the layout\n"
    "                      and every group's light are kept in DIR (an edit of scales or of\n"
    "                      a unit group's weight: the sum and the files); else exit 4 before\n"
    "                      any work, nothing written (preview --watch tries it first)\n"
    "      --print-config  print the effective config (every key, after -c and the options\n"
    "                      above) as YAML that -c reads back, and exit; SCENE may be left out\n"
    "      --timings[=CSV] at the end, per stage: wall time, CPU time over all threads and the\n"
    "                      share of the wall time when at most one thread ran (also as CSV)\n"
    "  -q, --quiet         no progress or warnings\n"
    "  -h, --help          this help\n"
    "\n"
    "With no config: texel_density auto (the lightmapped surface gets atlas.texels = 629,145\n"
    "texels, whatever the level's units; the density chosen is printed) and bounces auto\n"
    "(bounce passes until the light converges, then its geometric tail; the log says what each\n"
    "pass added). Set either to a number in the config to fix it.\n"
    "Outdoor levels: sky.intensity (nits) or sky.image (an HDR map) gives them a sky, and\n"
    "materials.default.albedo an albedo where the file has no material (docs/sky.md).\n"
    "\n"
    "exit codes: 0 ok, 1 usage error, 2 bad input, 3 internal error, 4 --relight-only and\n"
    "not every light group kept\n";

/* "bounces: auto, 7 passes + final gather; each pass added 31.2% 18.1% ... of the direct light;
 * ratio 0.79, estimated tail 9.8% of the total added" */
static void print_bounces(const lmb_config *cfg, const lmb_bake_stats *bs)
{
    if (cfg->bounces != LMB_AUTO || cfg->reference || bs->no_light)
        return;
    uint32_t passes = bs->bounces ? bs->bounces - 1 : 0;
    printf("bounces: auto, %u pass(es) + final gather", passes);
    if (passes && bs->bounce_energy[0] > 0) {
        printf("; each pass added (share of the direct light):");
        for (uint32_t b = 1; b <= passes && b < LMB_MAX_REPORTED_BOUNCES; b++)
            printf(" %.3g%%", 100.0 * bs->bounce_energy[b] / bs->bounce_energy[0]);
    }
    if (bs->bounce_stop == LMB_BOUNCES_SMALL_PASS)
        printf("; stopped: the last pass added under 0.1%% of the light");
    else if (bs->bounce_stop == LMB_BOUNCES_MAX)
        printf("; stopped at bounces_auto.max %u", cfg->bounces_max);
    else if (bs->bounce_stop == LMB_BOUNCES_TAIL)
        printf("; the bounce ratio settled");
    else if (bs->bounce_stop == LMB_BOUNCES_TAIL_BOUNDED)
        printf("; stopped: any ratio the last two passes allow gives the tail within %.2g%% of the light (a tenth of "
               "bounces_auto.tail)", 10.0 * cfg->bounces_tail);
    if (bs->tail_added)
        printf("; bounce ratio %.3f, geometric tail of %.2f%% of the total added", bs->bounce_ratio,
               100.0 * bs->tail_share);
    printf("\n");
}

static const char plan_help[] =
    "usage: lmbake plan SCENE [-c CONFIG] -o PLAN [options]\n"
    "\n"
    "The staged bake's first stage (docs/farm.md): loads SCENE, unwraps and packs it as\n"
    "'lmbake bake' would with CONFIG, and writes the layout to PLAN with the identity of the\n"
    "input, the config and lmbake (SHA-256, checked when the plan is read). Then\n"
    "'lmbake bake SCENE -c CONFIG --plan PLAN -o OUTDIR' bakes from it: the same files, byte for byte.\n"
    "\n"
    "options: -c, --config, --threads, --seed, --method, --rays, -q as for 'lmbake bake';\n"
    "  -o, --output PLAN   the plan file to write (default: ./lmbake.plan)\n"
    "\n"
    "exit codes: 0 ok, 1 usage error, 2 bad input, 3 internal error\n";

static const char step_help[] =
    "usage: lmbake step SCENE [-c CONFIG] --farm DIR --step S --shard K/N [options]\n"
    "\n"
    "Runs shard K of N of step S of the staged bake in DIR (made by 'lmbake plan --farm DIR'),\n"
    "reading steps 0..S-1 from their merged states, and writes DIR/parts/SSSS.K-of-N.part\n"
    "(atomically: a killed shard leaves nothing; rerunning one writes the same bytes). A step\n"
    "past the bake's last one does nothing. SCENE and CONFIG must be the plan's.\n"
    "\n"
    "options: --threads N, -q as for 'lmbake bake'\n"
    "\n"
    "exit codes: 0 ok, 1 usage error, 2 bad input, 3 internal error\n";

static const char merge_help[] =
    "usage: lmbake merge SCENE [-c CONFIG] --farm DIR --step S --shards N\n"
    "\n"
    "Checks and merges the N parts of step S in DIR and writes DIR/steps/SSSS.state, which\n"
    "lists them by SHA-256: later steps and 'lmbake finish' merge the parts it lists (keep the\n"
    "parts until the bake is done). Refuses a part made from another plan, input, config or lmbake\n"
    "version, naming the part and what differs, and a missing part, naming the shard to rerun.\n"
    "When the bake has no step S, writes DIR/end: the drivers stop there.\n"
    "\n"
    "exit codes: 0 ok, 1 usage error, 2 bad input, 3 internal error\n";

static const char finish_help[] =
    "usage: lmbake finish SCENE [-c CONFIG] --farm DIR -o OUTDIR [options]\n"
    "\n"
    "The staged bake's last stage: reads every step's merged state from DIR, post-processes\n"
    "(seams, fireflies, dilation) and writes OUTDIR exactly as 'lmbake bake' does, byte for\n"
    "byte, all-or-nothing. Refuses to start while a step is not merged.\n"
    "\n"
    "options: --threads N, --preview, -q as for 'lmbake bake'\n"
    "\n"
    "exit codes: 0 ok, 1 usage error, 2 bad input, 3 internal error\n";

static const char worker_help[] =
    "usage: lmbake worker SCENE [-c CONFIG] --farm DIR --shards N [--worker W/J] [-o OUTDIR] [options]\n"
    "\n"
    "A worker of the staged bake in DIR (made by 'lmbake plan --farm DIR') that lives for the\n"
    "whole bake: J workers run at once, one per machine (or per core group); at every step,\n"
    "worker W computes shards W, W+J, W+2J, ... of N and writes their parts, waits until every\n"
    "part of the step is in DIR, merges them and goes on. Worker 1 writes each step's merged\n"
    "state to DIR and, with -o, OUTDIR at the end, byte for byte as 'lmbake bake' does. A\n"
    "worker that dies can be started again: it reads the merged steps and carries on where\n"
    "the bake is.\n"
    "\n"
    "  --worker W/J         this worker of J (default 1/1); J <= N\n"
    "  -o, --output DIR     worker 1 writes the bake there after the last step (the other\n"
    "                       workers ignore it: one command line serves them all)\n"
    "  --tail-threads T     worker 1's threads after the last step, when the others have stopped\n"
    "                       (post-processing and writing; default 0: every core of its machine;\n"
    "                       --threads is a worker's share while all of them work)\n"
    "  --wait-timeout S     fail when another worker's part is S seconds late (default 0: wait;\n"
    "                       a worker says every minute which part it waits for)\n"
    "  --threads T, -q      as for 'lmbake bake'\n"
    "\n"
    "exit codes: 0 ok, 1 usage error, 2 bad input, 3 internal error\n";

static int run(int argc, char **argv, stage_kind stage);

/* The progress callback with --timings: each stage's first call starts its timing. */
typedef struct timed_progress {
    cli_progress *progress;
    cli_timings *timings;
} timed_progress;

static void timed_progress_update(void *user, const char *stage, uint64_t done, uint64_t total)
{
    timed_progress *tp = user;
    cli_timings_stage(tp->timings, stage);
    cli_progress_update(tp->progress, stage, done, total);
}

static int with_help(int argc, char **argv, const char *text, stage_kind stage)
{
    for (int i = 1; i < argc; i++)
        if (cli_is_flag(argv[i], "--help", "-h")) {
            fputs(text, stdout);
            return 0;
        }
    return run(argc, argv, stage);
}

int cmd_bake(int argc, char **argv)
{
    return run(argc, argv, STAGE_BAKE);
}

int cmd_plan(int argc, char **argv)
{
    return with_help(argc, argv, plan_help, STAGE_PLAN);
}

int cmd_step(int argc, char **argv)
{
    return with_help(argc, argv, step_help, STAGE_STEP);
}

int cmd_merge(int argc, char **argv)
{
    return with_help(argc, argv, merge_help, STAGE_MERGE);
}

int cmd_finish(int argc, char **argv)
{
    return with_help(argc, argv, finish_help, STAGE_FINISH);
}

int cmd_worker(int argc, char **argv)
{
    return with_help(argc, argv, worker_help, STAGE_WORKER);
}

static int run(int argc, char **argv, stage_kind stage)
{
    bake_args a;
    int r = bake_args_parse(argc, argv, &a, help);
    if (r)
        return r < 0 ? LMB_OK : r;
    char plan_path[PATH_MAX + 16] = "";
    if ((r = bake_args_check_stage(stage, &a, plan_path, sizeof plan_path)) != 0)
        return r;
    int plan_stage = stage == STAGE_PLAN;
    if ((stage == STAGE_STEP || stage == STAGE_MERGE) && lmb_farm_end_step(a.farm) < (uint64_t)a.step) {
        if (!a.quiet) /* the bake ended before this step: a no-op, before any loading */
            printf("step %lld: the bake ended at step %u: nothing to do\n", a.step, lmb_farm_end_step(a.farm));
        return LMB_OK;
    }
    lmb_config cfg;
    lmb_error err = {LMB_OK, ""};
    lmb_config_default(&cfg);
    if (a.config && lmb_config_load(a.config, &cfg, &err) != LMB_OK)
        return cli_fail(&err);
    if (a.threads >= 0)
        cfg.threads = (uint32_t)a.threads;
    if (a.seed >= 0)
        cfg.seed = (uint64_t)a.seed;
    if (a.rays > 0)
        cfg.gather_rays = (uint32_t)a.rays;
    if (a.method >= 0)
        cfg.gather_method = (lmb_gather_method)a.method;
    cfg.reference = a.reference;
    /* keys are linted as the user set them, not as --quick changes them */
    lmb_config user_cfg = cfg;
    if (a.quick)
        lmb_config_quick(&cfg);
    if (a.direct_of_count && lmb_config_direct_of(&cfg, a.direct_of, a.direct_of_count, &err) != LMB_OK)
        return cli_fail(&err);
    if (a.stages_out) {
        if (mkdir(a.stages_out, 0777) != 0 && errno != EEXIST) {
            lmb_error_set(&err, LMB_ERR_INPUT, "--stages-out: cannot make the folder '%s' (%s)", a.stages_out,
                          strerror(errno));
            return cli_fail(&err);
        }
        snprintf(cfg.stages_out, sizeof cfg.stages_out, "%s", a.stages_out);
    }
    if (a.print_config) {
        size_t n = lmb_config_write(&cfg, NULL, 0);
        char *text = malloc(n + 1);
        if (!text)
            return cli_fail(&(lmb_error){LMB_ERR_INTERNAL, "out of memory"});
        lmb_config_write(&cfg, text, n + 1);
        fputs(text, stdout);
        free(text);
        return 0;
    }
    cli_warnings warnings = {0, a.quiet};
    lmb_log log = cli_log(&warnings);
    /* once per bake: not in every farm shard */
    if ((stage == STAGE_BAKE || stage == STAGE_PLAN) && lmb_config_lint(&user_cfg, &log, &err) != LMB_OK)
        return cli_fail(&err);
    double t0 = cli_now();
    cli_timings *timings = a.timings ? cli_timings_start("load") : NULL;
    if (a.timings && !timings)
        fprintf(stderr, "lmbake: warning: --timings: the sampling thread did not start; no timings\n");
    lmb_scene *scene;
    if (lmb_scene_load(a.scene, &cfg, &scene, &log, &err) != LMB_OK) {
        cli_timings_finish(timings, NULL, NULL);
        return cli_fail(&err);
    }
    lmb_scene_select_lightmapped(scene, &cfg);
    lmb_scene_stats st;
    lmb_scene_stats_compute(scene, &st);
    if (!a.quiet)
        printf("load: %s in %.2fs: %u instances (%u lightmapped, %llu triangles), %u punctual lights, "
               "%llu emissive triangles\n",
               a.scene, cli_now() - t0, scene->instance_count, st.lightmapped_instances,
               (unsigned long long)st.lightmapped_triangles, scene->light_count,
               (unsigned long long)st.emissive_triangles);
    fflush(stdout); /* before the progress lines on stderr */
    if (!st.lightmapped_instances) {
        lmb_error_set(&err, LMB_ERR_INPUT, "%s: nothing to lightmap (see 'lmbake inspect' for each instance's reason)",
                      a.scene);
        lmb_scene_free(scene);
        cli_timings_finish(timings, NULL, NULL);
        return cli_fail(&err);
    }
    cli_progress progress;
    cli_progress_init(&progress, stderr, a.quiet);
    timed_progress timed = {&progress, timings};
    if (plan_stage) {
        lmb_status rc = a.farm ? lmb_farm_make_dirs(a.farm, &err) : LMB_OK;
        if (rc == LMB_OK)
            rc = lmb_plan_write(scene, &cfg, a.outdir, timings ? timed_progress_update : cli_progress_update,
                                timings ? (void *)&timed : (void *)&progress, &log, &err);
        lmb_scene_free(scene);
        cli_timings_finish(timings, rc == LMB_OK ? stdout : NULL, a.timings_csv);
        if (rc != LMB_OK)
            return cli_fail(&err);
        if (!a.quiet)
            printf("plan: %s\n", a.outdir);
        return LMB_OK;
    }
    if (stage == STAGE_MERGE) {
        lmb_farm_merge_report mr;
        lmb_status rc = lmb_farm_merge(scene, &cfg, plan_path, a.farm, (uint32_t)a.step, (uint32_t)a.shards, &mr, &err);
        lmb_scene_free(scene);
        cli_timings_finish(timings, rc == LMB_OK ? stdout : NULL, a.timings_csv);
        if (rc != LMB_OK)
            return cli_fail(&err);
        if (!a.quiet && mr.end)
            printf("merge: the bake has %lld steps: step %lld does not exist (%s/end written)\n", a.step, a.step, a.farm);
        else if (!a.quiet && !mr.noop)
            printf("merge: step %lld (%s): %llu parts, %llu items\n", a.step, mr.name, a.shards,
                   (unsigned long long)mr.items);
        return LMB_OK;
    }
    lmb_farm_run fr = {stage == STAGE_STEP     ? LMB_FARM_STEP
                       : stage == STAGE_FINISH ? LMB_FARM_FINISH
                       : stage == STAGE_WORKER ? LMB_FARM_WORKER
                                               : LMB_FARM_LOCAL,
                       a.farm, (uint32_t)(a.step > 0 ? a.step : 0), (uint32_t)(a.shard ? a.shard - 1 : 0),
                       (uint32_t)(a.shards ? a.shards : 1), 0, 0,
                       (uint32_t)(a.worker ? a.worker - 1 : 0), (uint32_t)(a.workers ? a.workers : 1),
                       (double)a.wait_timeout, a.layout_cache, 0, (uint32_t)a.tail_threads, a.relight_only};
    int writes_bake = stage != STAGE_STEP && (stage != STAGE_WORKER || (a.outdir_given && a.worker == 1));
    lmb_bake_stats bs;
    double ts = cli_now();
    lmb_status rc = lmb_bake_farm(scene, &cfg, a.farm ? plan_path : a.plan, &fr, writes_bake ? a.outdir : NULL,
                                  timings ? timed_progress_update : cli_progress_update,
                                  timings ? (void *)&timed : (void *)&progress, &bs, &log, &err);
    lmb_scene_free(scene);
    if (rc != LMB_OK) {
        cli_timings_finish(timings, NULL, NULL);
        return cli_fail(&err);
    }
    cli_timings_stage(timings, "report"); /* the bake's own time ends here */
    if (!writes_bake || stage == STAGE_STEP) /* no summary follows: the timings now */
        cli_timings_finish(timings, stdout, a.timings_csv);
    if (!writes_bake && stage == STAGE_WORKER) {
        if (!a.quiet)
            printf("worker %llu/%llu: %u steps, %.2f s\n", a.worker, a.workers, fr.steps, cli_now() - ts);
        return LMB_OK;
    }
    if (stage == STAGE_STEP) {
        if (!a.quiet && fr.ended)
            printf("step %lld: the bake has %u steps: nothing to do (an end part was written)\n", a.step, fr.steps);
        else if (!a.quiet)
            printf("step %lld, shard %llu/%llu: %.2f s\n", a.step, a.shard, a.shards, cli_now() - ts);
        return LMB_OK;
    }
    char script[PATH_MAX + 64];
    /* the preview script is looked up before the bake's summary, so a missing one is said first */
    if (a.preview && !node_tool_path("render.mjs", script, sizeof script))
        return LMB_ERR_INTERNAL;
    if (!a.quiet) {
        if (bs.density_auto)
            printf("texel density: auto, %.4g texels per unit (budget %llu texels%s)", bs.texel_density,
                   (unsigned long long)lmb_config_atlas_texels(&cfg), cfg.atlas_texels ? "" : ", atlas.texels: auto");
        else
            printf("texel density: %.4g texels per unit", bs.texel_density);
        if (bs.density_capped)
            printf("; %u instance(s) lowered to fit one atlas", bs.density_capped);
        if (bs.density_raised)
            printf("; %u small instance(s) raised (atlas.min_chart_texels)", bs.density_raised);
        printf("\n");
        print_bounces(&cfg, &bs);
    }
    if (!a.quiet && bs.bounces > 0)
    {
        printf("%s: %.3f s, %llu rays, %.4g rays/s, ", cfg.reference ? "reference" : "final gather", bs.gather_seconds,
               (unsigned long long)bs.gather_rays, bs.gather_seconds > 0 ? (double)bs.gather_rays / bs.gather_seconds : 0.0);
        if (bs.gather_records)
            printf("%llu records of at most %u rays (irradiance_cache.error %g)", (unsigned long long)bs.gather_records,
                   cfg.gather_rays * cfg.ic_ray_scale, cfg.ic_error);
        else
            printf("%u rays per texel", cfg.gather_rays);
        printf(", %u bounce(s)\n", bs.bounces);
    }
    if (!a.quiet)
        printf("bake: %.2f s (lighting %.2f s), %u atlas(es), %llu texels (%llu valid), %llu rays, %.3g rays/s\n"
               "output: %s (lightmaps beside it)\n",
               bs.seconds, bs.light_seconds, bs.atlases, (unsigned long long)bs.texels,
               (unsigned long long)bs.valid_texels, (unsigned long long)bs.rays,
               bs.light_seconds > 0 ? (double)bs.rays / bs.light_seconds : 0.0, bs.gltf_path);
    if (writes_bake && stage != STAGE_STEP)
        cli_timings_finish(timings, stdout, a.timings_csv);
    if (a.preview) {
        char *args[] = {bs.gltf_path, (char *)a.outdir, NULL};
        int code = node_tool_run(script, args);
        if (code != 0) {
            lmb_error_set(&err, LMB_ERR_INTERNAL, "the bake in %s is complete, but its preview images were not "
                          "rendered (tools/preview/render.mjs exit %d)", a.outdir, code);
            return cli_fail(&err);
        }
        if (!a.quiet)
            printf("preview: %s/preview-<view>.png\n", a.outdir);
    }
    return LMB_OK;
}
