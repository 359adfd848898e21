/* The lmbake subcommands; each takes its own argv (argv[0] is the subcommand name) and
 * returns the process exit code (docs/cli.md). */
#ifndef LMBAKE_COMMANDS_H
#define LMBAKE_COMMANDS_H

int cmd_inspect(int argc, char **argv);
int cmd_bake(int argc, char **argv);
int cmd_plan(int argc, char **argv);   /* cmd_bake.c: the staged bake's stages (docs/farm.md) */
int cmd_step(int argc, char **argv);
int cmd_merge(int argc, char **argv);
int cmd_finish(int argc, char **argv);
int cmd_worker(int argc, char **argv);
int cmd_farm(int argc, char **argv);   /* cmd_farm.c: scripts for GNU parallel and Slurm */
int cmd_unwrap(int argc, char **argv);
int cmd_preview(int argc, char **argv);

#endif
