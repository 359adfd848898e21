/*
 * `lmbake farm parallel|slurm SCENE [-c CONFIG] --farm DIR -o OUTDIR --shards N`: drivers for
 * schedulers a studio already has (docs/farm.md). Each writes a bash script into the farm
 * folder that runs the staged bake through that scheduler; lmbake schedules nothing itself.
 * The bake runs as J workers (lmbake worker) that live for the whole bake: the plan, then all
 * J at once, each running its shards of every step and merging each step from the parts in
 * DIR; worker 1 writes OUTDIR after the last step.
 *   parallel: DIR/parallel.sh, run at once (unless --script-only): the plan, then GNU parallel
 *             runs the J workers on local cores or on ssh hosts (--sshloginfile); one that
 *             fails stops the others, and rerunning the script resumes from the merged steps.
 *   slurm:    DIR/slurm.sh, submitted at once (unless --script-only): a plan job, then one job
 *             of J tasks (--ntasks, srun: Slurm starts them together) after it; DIR/finished or
 *             DIR/failed says how it ended. Submitting the script again resumes.
 * J workers must run at the same time (each waits for the others' parts): --workers J is
 * at most N, and on ssh hosts or Slurm they need J slots at once.
 * Every path in the scripts is absolute: on a farm DIR must be a folder every node sees at the
 * same path, and so must SCENE, CONFIG and the lmbake binary.
 */
#define _GNU_SOURCE
#include "cli_common.h"
#include "commands.h"

#include <lmbake/lmbake.h>

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

static const char help[] =
    "usage: lmbake farm parallel SCENE [-c CONFIG] --farm DIR -o OUTDIR --shards N [options]\n"
    "       lmbake farm slurm    SCENE [-c CONFIG] --farm DIR -o OUTDIR --shards N [options]\n"
    "\n"
    "Bakes SCENE in N shards per step through an existing scheduler, into the same files\n"
    "'lmbake bake' writes, byte for byte. J workers ('lmbake worker') run at once for the\n"
    "whole bake, each computing its shards of every step; DIR is the shared folder (plan,\n"
    "parts, merged steps, logs); every machine must see it, SCENE, CONFIG and lmbake at the\n"
    "same paths.\n"
    "\n"
    "  parallel   writes DIR/parallel.sh and runs it: the plan, then GNU parallel runs the\n"
    "             workers on this machine's cores or on ssh hosts; rerun it to resume\n"
    "  slurm      writes DIR/slurm.sh and submits it: a plan job, then one job of J tasks\n"
    "             (srun); DIR/finished (or DIR/failed) appears when OUTDIR is done\n"
    "\n"
    "  -c, --config FILE     bake config, as for 'lmbake bake'\n"
    "      --farm DIR        the shared folder (created)\n"
    "  -o, --output DIR      where worker 1 writes the bake after the last step\n"
    "      --shards N        shards per step\n"
    "      --threads T       threads per worker (default 0: all cores of its machine)\n"
    "      --workers J       workers, all running at once (default N; at most N); --jobs J\n"
    "                        is the same\n"
    "      --sshloginfile F  parallel: run the workers on the ssh hosts listed in F (GNU parallel's\n"
    "                        option; the hosts need J slots between them)\n"
    "      --partition P     slurm: the partition to submit to\n"
    "      --script-only     write the script, do not run or submit it\n"
    "  -q, --quiet           no progress\n"
    "  -h, --help            this help\n"
    "\n"
    "exit codes: 0 ok, 1 usage error, 2 bad input, 3 internal error (or the script's)\n";

typedef struct farm_args {
    const char *driver, *scene, *config, *farm, *outdir, *sshloginfile, *partition;
    unsigned long long shards, jobs, threads;
    int script_only, quiet;
} farm_args;

static int parse(int argc, char **argv, farm_args *a)
{
    memset(a, 0, sizeof *a);
    for (int i = 1; i < argc; i++) {
        const char *v;
        int r;
        if (cli_is_flag(argv[i], "--help", "-h")) {
            fputs(help, stdout);
            return -1;
        } else if ((r = cli_opt_value(argc, argv, &i, "--config", "-c", &v)) != 0) {
            if (r < 0)
                return cli_usage_error("farm", "%s needs a file", argv[i]);
            a->config = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--farm", NULL, &v)) != 0) {
            if (r < 0)
                return cli_usage_error("farm", "%s needs a folder", argv[i]);
            a->farm = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--output", "-o", &v)) != 0) {
            if (r < 0)
                return cli_usage_error("farm", "%s needs a folder", argv[i]);
            a->outdir = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--shards", NULL, &v)) != 0) {
            if (r < 0 || !cli_parse_uint(v, 100000, &a->shards) || !a->shards)
                return cli_usage_error("farm", "--shards needs a number 1..100000");
        } else if ((r = cli_opt_value(argc, argv, &i, "--jobs", NULL, &v)) != 0 ||
                   (r = cli_opt_value(argc, argv, &i, "--workers", NULL, &v)) != 0) {
            if (r < 0 || !cli_parse_uint(v, 100000, &a->jobs) || !a->jobs)
                return cli_usage_error("farm", "--workers needs a number 1..100000");
        } else if ((r = cli_opt_value(argc, argv, &i, "--threads", NULL, &v)) != 0) {
            if (r < 0 || !cli_parse_uint(v, 1024, &a->threads))
                return cli_usage_error("farm", "--threads needs a number 0..1024");
        } else if ((r = cli_opt_value(argc, argv, &i, "--sshloginfile", NULL, &v)) != 0) {
            if (r < 0)
                return cli_usage_error("farm", "%s needs a file", argv[i]);
            a->sshloginfile = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--partition", NULL, &v)) != 0) {
            if (r < 0)
                return cli_usage_error("farm", "%s needs a name", argv[i]);
            a->partition = v;
        } else if (cli_is_flag(argv[i], "--script-only", NULL)) {
            a->script_only = 1;
        } else if (cli_is_flag(argv[i], "--quiet", "-q")) {
            a->quiet = 1;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            return cli_usage_error("farm", "unknown option '%s'", argv[i]);
        } else if (!a->driver) {
            a->driver = argv[i];
        } else if (!a->scene) {
            a->scene = argv[i];
        } else {
            return cli_usage_error("farm", "one scene at a time ('%s' and '%s')", a->scene, argv[i]);
        }
    }
    if (!a->driver || (strcmp(a->driver, "parallel") && strcmp(a->driver, "slurm")))
        return cli_usage_error("farm", "the driver is 'parallel' or 'slurm'");
    if (!a->scene || !a->farm || !a->outdir || !a->shards)
        return cli_usage_error("farm", "SCENE, --farm DIR, -o OUTDIR and --shards N are needed");
    if (a->sshloginfile && strcmp(a->driver, "parallel"))
        return cli_usage_error("farm", "--sshloginfile is for 'farm parallel'");
    if (a->partition && strcmp(a->driver, "slurm"))
        return cli_usage_error("farm", "--partition is for 'farm slurm'");
    return 0;
}

/* An absolute path for p (existing: resolved; otherwise joined to the working folder). */
static int absolute(const char *p, char *out, size_t n)
{
    char cwd[PATH_MAX];
    if (realpath(p, out))
        return 1;
    if (p[0] == '/')
        return snprintf(out, n, "%s", p) < (int)n;
    return getcwd(cwd, sizeof cwd) && snprintf(out, n, "%s/%s", cwd, p) < (int)n;
}

/* Writes s single-quoted for bash. */
static void shq(FILE *f, const char *s)
{
    fputc('\'', f);
    for (; *s; s++)
        if (*s == '\'')
            fputs("'\\''", f);
        else
            fputc(*s, f);
    fputc('\'', f);
}

static void var(FILE *f, const char *name, const char *value)
{
    fprintf(f, "%s=", name);
    shq(f, value);
    fputc('\n', f);
}

/* The variables both scripts start with. */
static void script_head(FILE *f, const farm_args *a, const char *exe, const char *scene, const char *config,
                        const char *farm, const char *out)
{
    var(f, "LMBAKE", exe);
    var(f, "SCENE", scene);
    var(f, "FARM", farm);
    var(f, "OUT", out);
    fprintf(f, "SHARDS=%llu\n", a->shards);
    fprintf(f, "CONFIG=(");
    if (config) {
        fprintf(f, "-c ");
        shq(f, config);
    }
    fprintf(f, ")\nTHREADS=(--threads %llu)\n", a->threads);
    fprintf(f, "QUIET=(%s)\n", a->quiet ? "-q" : "");
}

static const char parallel_body[] =
    "command -v parallel >/dev/null || { echo \"lmbake farm parallel: GNU parallel is not installed (Debian: apt-get install parallel)\" >&2; exit 3; }\n"
    "mkdir -p \"$FARM/logs\"\n"
    "# workers that share a machine's cores: OpenMP threads sleep at once instead of spinning (docs/threads.md)\n"
    "[ \"$WORKERS\" -gt 1 ] && export OMP_WAIT_POLICY=\"${OMP_WAIT_POLICY:-passive}\"\n"
    "stamp() { printf '%s\\t%s\\n' \"$1\" \"$(date +%s.%N)\" >>\"$FARM/logs/times.tsv\"; }  # what each stage took\n"
    "stamp start\n"
    "# the plan runs alone: every core of this machine (the same plan at any thread count)\n"
    "[ -f \"$FARM/plan.lmbp\" ] || \"$LMBAKE\" plan \"$SCENE\" \"${CONFIG[@]}\" --farm \"$FARM\" \"${QUIET[@]}\"\n"
    "stamp plan\n"
    "# the workers, all at once, for the whole bake: worker W runs shards W, W+J, ... of every step,\n"
    "# merges each step from the parts in the farm folder; worker 1 writes OUT after the last step.\n"
    "# One that fails stops the others; running this script again resumes from the merged steps.\n"
    "parallel --will-cite --halt now,fail=1 -j \"$WORKERS\" \"${HOSTS[@]}\" --joblog \"$FARM/logs/workers.joblog\" -q \\\n"
    "  \"$LMBAKE\" worker \"$SCENE\" \"${CONFIG[@]}\" \"${THREADS[@]}\" --farm \"$FARM\" --shards \"$SHARDS\" \\\n"
    "  --worker \"{}/$WORKERS\" -o \"$OUT\" \"${QUIET[@]}\" ::: $(seq 1 \"$WORKERS\")\n"
    "stamp workers\n";

static const char slurm_body[] =
    "SELF=\"$FARM/slurm.sh\"\n"
    "case \"${1:-submit}\" in\n"
    "  submit)  # the plan job, then one job of WORKERS tasks (srun) after it\n"
    "    command -v sbatch >/dev/null || { echo \"lmbake farm slurm: sbatch not found (Debian: slurm-client)\" >&2; exit 3; }\n"
    "    mkdir -p \"$FARM/logs\"\n"
    "    rm -f \"$FARM/finished\" \"$FARM/failed\"\n"
    "    plan=$(\"${SBATCH[@]}\" --job-name=lmbake-plan --cpus-per-task=\"$CPUS\" --output=\"$FARM/logs/plan.out\" \"$SELF\" plan)\n"
    "    work=$(\"${SBATCH[@]}\" --job-name=lmbake-workers --dependency=\"afterok:${plan%%;*}\" --ntasks=\"$WORKERS\" \\\n"
    "      --cpus-per-task=\"$CPUS\" --output=\"$FARM/logs/workers.out\" \"$SELF\" workers)\n"
    "    \"${SBATCH[@]}\" --job-name=lmbake-failed --dependency=\"afternotok:${plan%%;*}\" --output=/dev/null \\\n"
    "      --wrap=\"touch '$FARM/failed'\" >/dev/null\n"
    "    echo \"submitted: plan job ${plan%%;*}, workers job ${work%%;*} ($WORKERS tasks)\";;\n"
    "  plan)\n"
    "    [ -f \"$FARM/plan.lmbp\" ] || exec \"$LMBAKE\" plan \"$SCENE\" \"${CONFIG[@]}\" \"${THREADS[@]}\" --farm \"$FARM\" -q;;\n"
    "  workers)  # all tasks start together; one that fails ends the job step (--kill-on-bad-exit)\n"
    "    if srun --kill-on-bad-exit=1 --output=\"$FARM/logs/worker-%t.out\" bash \"$SELF\" worker; then\n"
    "      touch \"$FARM/finished\"\n"
    "    else\n"
    "      touch \"$FARM/failed\"; exit 1\n"
    "    fi;;\n"
    "  worker)\n"
    "    exec \"$LMBAKE\" worker \"$SCENE\" \"${CONFIG[@]}\" \"${THREADS[@]}\" --farm \"$FARM\" --shards \"$SHARDS\" \\\n"
    "      --worker \"$((SLURM_PROCID + 1))/$WORKERS\" -o \"$OUT\";;\n"
    "  *) echo \"usage: bash $SELF [submit]\" >&2; exit 1;;\n"
    "esac\n";

int cmd_farm(int argc, char **argv)
{
    farm_args a;
    int r = parse(argc, argv, &a);
    if (r)
        return r < 0 ? LMB_OK : r;
    lmb_error err = {LMB_OK, ""};
    char exe[PATH_MAX], scene[PATH_MAX], config[PATH_MAX], farm[PATH_MAX], out[PATH_MAX], hosts[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return cli_fail(&(lmb_error){LMB_ERR_INTERNAL, "cannot find the lmbake binary (/proc/self/exe)"});
    exe[n] = 0;
    if (!realpath(a.scene, scene)) {
        lmb_error_set(&err, LMB_ERR_INPUT, "cannot open glTF '%s': %s", a.scene, strerror(errno));
        return cli_fail(&err);
    }
    if (a.config && !realpath(a.config, config)) {
        lmb_error_set(&err, LMB_ERR_INPUT, "cannot open config '%s': %s", a.config, strerror(errno));
        return cli_fail(&err);
    }
    if (a.sshloginfile && !realpath(a.sshloginfile, hosts)) {
        lmb_error_set(&err, LMB_ERR_INPUT, "cannot open --sshloginfile '%s': %s", a.sshloginfile, strerror(errno));
        return cli_fail(&err);
    }
    if (lmb_farm_make_dirs(a.farm, &err) != LMB_OK)
        return cli_fail(&err);
    if (!absolute(a.farm, farm, sizeof farm) || !absolute(a.outdir, out, sizeof out))
        return cli_fail(&(lmb_error){LMB_ERR_INPUT, "path too long"});
    int slurm = !strcmp(a.driver, "slurm");
    unsigned long long workers = a.jobs && a.jobs < a.shards ? a.jobs : a.shards;
    char path[PATH_MAX + 32];
    snprintf(path, sizeof path, "%s/%s.sh", farm, slurm ? "slurm" : "parallel");
    FILE *f = fopen(path, "w");
    if (!f) {
        lmb_error_set(&err, LMB_ERR_INPUT, "cannot write %s: %s", path, strerror(errno));
        return cli_fail(&err);
    }
    fprintf(f, "#!/usr/bin/env bash\n# Written by 'lmbake farm %s' (lmbake %s): the staged bake of the scene below in "
            "%llu shards per step.\n# docs/farm.md; 'lmbake farm --help'.\nset -euo pipefail\n", a.driver,
            LMB_VERSION_STRING, a.shards);
    script_head(f, &a, exe, scene, a.config ? config : NULL, farm, out);
    if (slurm) {
        /* --kill-on-invalid-dep: a failed shard cancels the jobs that wait on it (none hang) */
    fprintf(f, "CPUS=%llu\nSBATCH=(sbatch --parsable --kill-on-invalid-dep=yes", a.threads ? a.threads : 1);
        if (a.partition) {
            fprintf(f, " --partition=");
            shq(f, a.partition);
        }
        fprintf(f, ")\nWORKERS=%llu\n%s", workers, slurm_body);
    } else {
        fprintf(f, "WORKERS=%llu\nHOSTS=(", workers);
        if (a.sshloginfile) {
            fprintf(f, "--sshloginfile ");
            shq(f, hosts);
        }
        fprintf(f, ")\n%s", parallel_body);
    }
    if (fclose(f) != 0) {
        lmb_error_set(&err, LMB_ERR_INTERNAL, "cannot write %s: %s", path, strerror(errno));
        return cli_fail(&err);
    }
    if (!a.quiet)
        printf("farm %s: %s\n", a.driver, path);
    if (a.script_only)
        return LMB_OK;
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        execlp("bash", "bash", path, (char *)NULL);
        _exit(127);
    }
    int status = 0;
    if (pid < 0 || waitpid(pid, &status, 0) < 0)
        return cli_fail(&(lmb_error){LMB_ERR_INTERNAL, "cannot run bash"});
    int code = WIFEXITED(status) ? WEXITSTATUS(status) : LMB_ERR_INTERNAL;
    if (code != 0)
        fprintf(stderr, "lmbake farm %s: %s exited with %d (rerun it to resume)\n", a.driver, path, code);
    return code;
}
