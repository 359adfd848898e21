/*
 * The options of `lmbake bake` and of the farm stages that share its run (plan, step, merge,
 * finish, worker): parsed into bake_args, then checked against the stage.
 */
#ifndef LMBAKE_CLI_BAKE_ARGS_H
#define LMBAKE_CLI_BAKE_ARGS_H

#include <lmbake/lmbake.h>

typedef enum stage_kind { STAGE_BAKE, STAGE_PLAN, STAGE_STEP, STAGE_MERGE, STAGE_FINISH, STAGE_WORKER } stage_kind;

typedef struct bake_args {
    const char *scene, *config, *outdir, *plan, *farm;
    const char *layout_cache; /* --layout-cache DIR */
    const char *stages_out;   /* --stages-out DIR */
    const char *timings_csv; /* --timings=CSV */
    int timings;
    long long threads, seed, rays, method; /* -1: from the config */
    int quiet, reference, preview, print_config, quick;
    int relight_only; /* --relight-only */
    const char *direct_of[LMB_MAX_DIRECT_OF + 1]; /* --direct-of LIGHT, repeatable */
    uint32_t direct_of_count;
    long long step;               /* -1: not given */
    unsigned long long shard, shards; /* --shard K/N (K 1-based), --shards N */
    unsigned long long worker, workers, wait_timeout; /* --worker W/J (W 1-based), --wait-timeout S */
    unsigned long long tail_threads; /* --tail-threads T: the output worker's threads after the last step */
    int tail_threads_given;
    int outdir_given;
} bake_args;

/* argv into a; help is printed for --help. 0: go on; -1: --help printed; > 0: a usage error's
 * exit code (the message printed). */
int bake_args_parse(int argc, char **argv, bake_args *a, const char *help);

/* The stage's checks of its options (and the plan's path into plan_path); 0 when fine, else a
 * usage error's exit code (the message printed). */
int bake_args_check_stage(stage_kind stage, bake_args *a, char *plan_path, size_t size);

#endif
