/* The options of `lmbake bake` and the farm stages (see bake_args.h). */
#include "bake_args.h"

#include "cli_common.h"

#include <stdio.h>
#include <string.h>

/* "K/N" with 1 <= K <= N <= 100000 into *k, *n; 0 on junk. */
static int parse_fraction(const char *v, unsigned long long *k, unsigned long long *n)
{
    char head[32];
    const char *slash = v ? strchr(v, '/') : NULL;
    if (!slash || (size_t)(slash - v) >= sizeof head)
        return 0;
    memcpy(head, v, (size_t)(slash - v));
    head[slash - v] = 0;
    return cli_parse_uint(head, 100000, k) && cli_parse_uint(slash + 1, 100000, n) && *k >= 1 && *k <= *n;
}

int bake_args_parse(int argc, char **argv, bake_args *a, const char *help)
{
    memset(a, 0, sizeof *a);
    a->outdir = "lmbake-out";
    a->threads = a->seed = a->rays = a->method = a->step = -1;
    for (int i = 1; i < argc; i++) {
        const char *v;
        int r;
        unsigned long long n;
        if (cli_is_flag(argv[i], "--help", "-h")) {
            fputs(help, stdout);
            return -1;
        } else if ((r = cli_opt_value(argc, argv, &i, "--config", "-c", &v)) != 0) {
            if (r < 0)
                return cli_usage_error("bake", "%s needs a file", argv[i]);
            a->config = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--output", "-o", &v)) != 0) {
            if (r < 0)
                return cli_usage_error("bake", "%s needs a folder", argv[i]);
            a->outdir = v;
            a->outdir_given = 1;
        } else if ((r = cli_opt_value(argc, argv, &i, "--threads", NULL, &v)) != 0) {
            if (r < 0 || !cli_parse_uint(v, 1024, &n))
                return cli_usage_error("bake", "--threads needs a number 0..1024");
            a->threads = (long long)n;
        } else if ((r = cli_opt_value(argc, argv, &i, "--seed", NULL, &v)) != 0) {
            if (r < 0 || !cli_parse_uint(v, (1ULL << 63) - 1, &n))
                return cli_usage_error("bake", "--seed needs a non-negative integer");
            a->seed = (long long)n;
        } else if ((r = cli_opt_value(argc, argv, &i, "--rays", NULL, &v)) != 0) {
            if (r < 0 || !cli_parse_uint(v, 1048576, &n) || n == 0)
                return cli_usage_error("bake", "--rays needs a number 1..1048576");
            a->rays = (long long)n;
        } else if ((r = cli_opt_value(argc, argv, &i, "--method", NULL, &v)) != 0) {
            static const char *const names[] = {"cosine", "amis", "amis_defensive"};
            a->method = -2;
            for (int k = 0; r > 0 && k < 3; k++)
                if (!strcmp(v, names[k]))
                    a->method = k;
            if (a->method < 0)
                return cli_usage_error("bake", "--method needs cosine, amis or amis_defensive");
        } else if (cli_is_flag(argv[i], "--preview", NULL)) {
            a->preview = 1;
        } else if (cli_is_flag(argv[i], "--quick", NULL)) {
            a->quick = 1;
        } else if (cli_is_flag(argv[i], "--relight-only", NULL)) {
            a->relight_only = 1;
        } else if ((r = cli_opt_value(argc, argv, &i, "--direct-of", NULL, &v)) != 0) {
            if (r < 0 || !*v)
                return cli_usage_error("bake", "--direct-of needs a light's name");
            if (a->direct_of_count == LMB_MAX_DIRECT_OF)
                return cli_usage_error("bake", "--direct-of: at most %d lights", LMB_MAX_DIRECT_OF);
            a->direct_of[a->direct_of_count++] = v;
        } else if (cli_is_flag(argv[i], "--reference", NULL)) {
            a->reference = 1;
        } else if ((r = cli_opt_value(argc, argv, &i, "--plan", NULL, &v)) != 0) {
            if (r < 0)
                return cli_usage_error("bake", "%s needs a file", argv[i]);
            a->plan = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--layout-cache", NULL, &v)) != 0) {
            if (r < 0)
                return cli_usage_error("bake", "%s needs a folder", argv[i]);
            a->layout_cache = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--stages-out", NULL, &v)) != 0) {
            if (r < 0 || !*v)
                return cli_usage_error("bake", "%s needs a folder", argv[i]);
            if (strlen(v) >= sizeof ((lmb_config *)0)->stages_out)
                return cli_usage_error("bake", "--stages-out: the folder's path is too long");
            a->stages_out = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--farm", NULL, &v)) != 0) {
            if (r < 0)
                return cli_usage_error("bake", "%s needs a folder", argv[i]);
            a->farm = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--step", NULL, &v)) != 0) {
            if (r < 0 || !cli_parse_uint(v, 1000000, &n))
                return cli_usage_error("bake", "--step needs a number 0..1000000");
            a->step = (long long)n;
        } else if ((r = cli_opt_value(argc, argv, &i, "--shard", NULL, &v)) != 0) {
            if (r < 0 || !parse_fraction(v, &a->shard, &a->shards))
                return cli_usage_error("bake", "--shard needs K/N with 1 <= K <= N <= 100000, e.g. 2/4");
        } else if ((r = cli_opt_value(argc, argv, &i, "--worker", NULL, &v)) != 0) {
            if (r < 0 || !parse_fraction(v, &a->worker, &a->workers))
                return cli_usage_error("worker", "--worker needs W/J with 1 <= W <= J <= 100000, e.g. 1/2");
        } else if ((r = cli_opt_value(argc, argv, &i, "--tail-threads", NULL, &v)) != 0) {
            if (r < 0 || !cli_parse_uint(v, 1024, &a->tail_threads))
                return cli_usage_error("worker", "--tail-threads needs a number 0..1024 (0: every core)");
            a->tail_threads_given = 1;
        } else if ((r = cli_opt_value(argc, argv, &i, "--wait-timeout", NULL, &v)) != 0) {
            if (r < 0 || !cli_parse_uint(v, 100000000, &a->wait_timeout))
                return cli_usage_error("worker", "--wait-timeout needs seconds 0..100000000 (0: wait for ever)");
        } else if ((r = cli_opt_value(argc, argv, &i, "--shards", NULL, &v)) != 0) {
            if (r < 0 || !cli_parse_uint(v, 100000, &a->shards) || a->shards < 1)
                return cli_usage_error("bake", "--shards needs a number 1..100000");
        } else if (cli_is_flag(argv[i], "--timings", NULL) || !strncmp(argv[i], "--timings=", 10)) {
            a->timings = 1;
            a->timings_csv = argv[i][9] == '=' ? argv[i] + 10 : NULL;
            if (a->timings_csv && !*a->timings_csv)
                return cli_usage_error("bake", "--timings= needs a CSV file name");
        } else if (cli_is_flag(argv[i], "--print-config", NULL)) {
            a->print_config = 1;
        } else if (cli_is_flag(argv[i], "--quiet", "-q")) {
            a->quiet = 1;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            return cli_usage_error("bake", "unknown option '%s'", argv[i]);
        } else if (a->scene) {
            return cli_usage_error("bake", "one scene at a time ('%s' and '%s')", a->scene, argv[i]);
        } else {
            a->scene = argv[i];
        }
    }
    if (!a->scene && !a->print_config)
        return cli_usage_error("bake", "no SCENE given");
    return 0;
}

/* The farm stages' checks of their options; returns 0 when fine. */
int bake_args_check_stage(stage_kind stage, bake_args *a, char *plan_path, size_t size)
{
    static const char *const names[] = {"bake", "plan", "step", "merge", "finish", "worker"};
    const char *name = names[stage];
    int farm_stage = stage == STAGE_STEP || stage == STAGE_MERGE || stage == STAGE_FINISH || stage == STAGE_WORKER;
    if (stage != STAGE_WORKER && (a->worker || a->wait_timeout || a->tail_threads_given))
        return cli_usage_error(name, "--worker, --wait-timeout and --tail-threads are options of 'lmbake worker'");
    if (stage == STAGE_WORKER && (a->step >= 0 || a->shard || !a->shards))
        return cli_usage_error(name, "a worker takes --shards N (and --worker W/J), not --step or --shard");
    if (stage == STAGE_WORKER && !a->worker)
        a->worker = a->workers = 1;
    if (stage == STAGE_WORKER && a->workers > a->shards)
        return cli_usage_error(name, "--worker %llu/%llu: at most as many workers as shards (%llu)", a->worker,
                               a->workers, a->shards);

    if (stage != STAGE_BAKE &&
        (a->plan || a->reference || a->print_config || a->quick || a->layout_cache || a->direct_of_count ||
         a->stages_out))
        return cli_usage_error(name, "--plan, --layout-cache, --quick, --direct-of, --stages-out, --reference and "
                               "--print-config are "
                               "'lmbake bake' options");
    if (a->plan && a->layout_cache)
        return cli_usage_error(name, "--plan and --layout-cache both give the layout: one or the other");
    if (a->relight_only && (!a->layout_cache || stage != STAGE_BAKE))
        return cli_usage_error(name, "--relight-only needs --layout-cache DIR (where the light groups are kept)");
    if (stage != STAGE_BAKE && stage != STAGE_FINISH && a->preview)
        return cli_usage_error(name, "--preview is an option of 'lmbake bake' and 'lmbake finish'");
    if (farm_stage && !a->farm)
        return cli_usage_error(name, "--farm DIR is needed (the folder 'lmbake plan --farm DIR' made)");
    if ((stage == STAGE_BAKE || stage == STAGE_PLAN) && (a->step >= 0 || a->shards))
        return cli_usage_error(name, "--step, --shard and --shards are options of 'lmbake step' and 'lmbake merge'");
    if ((stage == STAGE_STEP || stage == STAGE_MERGE) && (a->step < 0 || !a->shards))
        return cli_usage_error(name, "--step S and %s are needed", stage == STAGE_STEP ? "--shard K/N" : "--shards N");
    if (stage == STAGE_STEP && !a->shard)
        return cli_usage_error(name, "--shard K/N is needed");
    if (stage == STAGE_MERGE && a->shard)
        return cli_usage_error(name, "merge takes --shards N, not --shard");
    if (stage == STAGE_BAKE && a->farm)
        return cli_usage_error(name, "--farm is an option of the farm stages (lmbake plan, step, merge, finish)");
    if (a->farm)
        snprintf(plan_path, size, "%s/plan.lmbp", a->farm);
    if (stage == STAGE_PLAN && a->farm)
        a->outdir = plan_path;
    else if (stage == STAGE_PLAN && !strcmp(a->outdir, "lmbake-out"))
        a->outdir = "lmbake.plan";
    return 0;
}

