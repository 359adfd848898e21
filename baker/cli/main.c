/*
 * lmbake: command-line entry point. Dispatches to a subcommand; every subcommand has
 * --help. Exit codes: 0 ok, 1 usage, 2 bad input, 3 internal error.
 */
#define _DEFAULT_SOURCE /* readlink, setenv */
#include "commands.h"

#include <lmbake/lmbake.h>

#include <stdio.h>
#include <string.h>
#ifdef __GLIBC__
#include <malloc.h>
#include <stdlib.h>
#include <unistd.h>
#endif

static const char usage[] =
    "usage: lmbake <command> [options]\n"
    "\n"
    "Bakes static lighting (lightmaps) into glTF 2.0 levels.\n"
    "\n"
    "commands:\n"
    "  bake SCENE [-c CONFIG] [-o OUTDIR]   bake lightmaps for a .gltf/.glb level\n"
    "  farm parallel|slurm SCENE --farm DIR -o OUTDIR --shards N\n"
    "                                       bake on many cores or machines through GNU\n"
    "                                       parallel or Slurm (docs/farm.md); the stages:\n"
    "  plan SCENE [-c CONFIG] --farm DIR    layout to DIR/plan.lmbp (or -o PLAN)\n"
    "  step SCENE --farm DIR --step S --shard K/N   one shard of one step\n"
    "  merge SCENE --farm DIR --step S --shards N   a step's parts into its state\n"
    "  finish SCENE --farm DIR -o OUTDIR    the outputs, byte for byte as 'bake' writes them\n"
    "  worker SCENE --farm DIR --shards N --worker W/J [-o OUTDIR]   a worker for every step\n"
    "  inspect SCENE [-c CONFIG] [--json]   list meshes, instances, materials, lights and\n"
    "                                       what will be lightmapped (and why not)\n"
    "  unwrap SCENE [-c CONFIG] [--png DIR] lightmap UV layout and its quality report\n"
    "  preview OUT.gltf [--port N]          look at a bake in a browser (127.0.0.1 only)\n"
    "\n"
    "options:\n"
    "  -h, --help      this help; 'lmbake <command> --help' for a command's options\n"
    "  --version       print the version\n"
    "\n"
    "exit codes: 0 ok, 1 usage error, 2 bad input (scene, config), 3 internal error\n";

#ifdef __GLIBC__
/* Large buffers on transparent huge pages: each is mapped on its own (below), and a first touch
 * of a fresh 4 KB page is a page fault, a fifth of the CPU time of a bake that reads its light
 * groups back and writes its files (docs/threads.md, "Huge pages"). glibc's malloc advises
 * huge pages for its mappings when its tunable glibc.malloc.hugetlb is 1, and reads tunables
 * only as a process starts: so lmbake starts itself again once with it set, unless
 * GLIBC_TUNABLES already names it (glibc.malloc.hugetlb=0 keeps 4 KB pages) or the running
 * file is not lmbake itself (a loader running it). Nothing a bake computes depends on it. */
static void on_huge_pages(char **argv)
{
    const char *tunables = getenv("GLIBC_TUNABLES");
    if (tunables && strstr(tunables, "glibc.malloc.hugetlb"))
        return;
    char exe[4096];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return;
    exe[n] = 0;
    const char *base = strrchr(exe, '/');
    if (strncmp(base ? base + 1 : exe, "lmbake", 6))
        return;
    char value[8192];
    snprintf(value, sizeof value, "%s%sglibc.malloc.hugetlb=1", tunables ? tunables : "",
             tunables && *tunables ? ":" : "");
    if (setenv("GLIBC_TUNABLES", value, 1) == 0)
        execv(exe, argv); /* returns only when it failed: go on with 4 KB pages */
}
#endif

int main(int argc, char **argv)
{
#ifdef __GLIBC__
    on_huge_pages(argv);
    /* Buffers of 128 KB and more are mapped and unmapped on their own. Left to itself, glibc
     * raises this threshold after the first large free, so later large transients (a band, a
     * chunk of a step, a filter's rows) come from the heap, where freeing them does not give
     * the memory back: about 30 MB more at the peak of a 2M-texel bake. */
    mallopt(M_MMAP_THRESHOLD, 128 * 1024);
#endif
    if (argc < 2) {
        fputs(usage, stderr);
        return LMB_ERR_USAGE;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "-h") || !strcmp(cmd, "--help") || !strcmp(cmd, "help")) {
        fputs(usage, stdout);
        return LMB_OK;
    }
    if (!strcmp(cmd, "--version") || !strcmp(cmd, "version")) {
        printf("lmbake %s\n", LMB_VERSION_STRING);
        return LMB_OK;
    }
    if (!strcmp(cmd, "inspect"))
        return cmd_inspect(argc - 1, argv + 1);
    if (!strcmp(cmd, "unwrap"))
        return cmd_unwrap(argc - 1, argv + 1);
    if (!strcmp(cmd, "preview"))
        return cmd_preview(argc - 1, argv + 1);
    if (!strcmp(cmd, "bake"))
        return cmd_bake(argc - 1, argv + 1);
    if (!strcmp(cmd, "plan"))
        return cmd_plan(argc - 1, argv + 1);
    if (!strcmp(cmd, "step"))
        return cmd_step(argc - 1, argv + 1);
    if (!strcmp(cmd, "merge"))
        return cmd_merge(argc - 1, argv + 1);
    if (!strcmp(cmd, "worker"))
        return cmd_worker(argc - 1, argv + 1);
    if (!strcmp(cmd, "finish"))
        return cmd_finish(argc - 1, argv + 1);
    if (!strcmp(cmd, "farm"))
        return cmd_farm(argc - 1, argv + 1);
    fprintf(stderr, "lmbake: unknown command '%s'\n\n%s", cmd, usage);
    return LMB_ERR_USAGE;
}
