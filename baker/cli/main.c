/*
 * lmbake: command-line entry point. Dispatches to a subcommand; every subcommand has
 * --help. Exit codes: 0 ok, 1 usage, 2 bad input, 3 internal error.
 */
#include "commands.h"

#include <lmbake/lmbake.h>

#include <stdio.h>
#include <string.h>

static const char usage[] =
    "usage: lmbake <command> [options]\n"
    "\n"
    "Bakes static lighting (lightmaps) into glTF 2.0 levels.\n"
    "\n"
    "commands:\n"
    "  bake SCENE [-c CONFIG] [-o OUTDIR]   bake lightmaps for a .gltf/.glb level\n"
    "  plan SCENE [-c CONFIG] -o PLAN       the staged bake's plan stage: layout to a file\n"
    "                                       ('bake --plan PLAN' starts from it; docs/farm.md)\n"
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

int main(int argc, char **argv)
{
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
    fprintf(stderr, "lmbake: unknown command '%s'\n\n%s", cmd, usage);
    return LMB_ERR_USAGE;
}
