/*
 * `lmbake bake --timings`: where a bake's wall time goes and how much of it ran on one thread.
 * Per stage (the progress stages: a stage runs from its first progress call to the next
 * stage's first call, as tools/bench_threads.sh and ../shared/tools/portable/scaling.sh cut
 * a log): its wall time, the CPU time summed over the process's threads, and the serial
 * share: the part of its wall time during which at most one thread ran.
 *
 * How: a sampling thread reads every thread's CPU clock every 10 ms (Linux's per-thread
 * CPU-time clocks, found from /proc/self/task). An interval in which one thread or none used
 * more than half of it counts as serial. The sampler's own thread is left out. Threads that
 * a busy machine preempts look idle, so the serial share is an upper bound on a loaded machine.
 */
#ifndef LMBAKE_CLI_TIMINGS_H
#define LMBAKE_CLI_TIMINGS_H

#include <stdint.h>
#include <stdio.h>

typedef struct cli_timings cli_timings;

/* Starts the sampler; the first stage is `first_stage` (e.g. "load"). NULL when the sampler
 * cannot start (the caller goes on without timings). */
cli_timings *cli_timings_start(const char *first_stage);

/* The driving thread enters `stage` (progress stage names; "(...)" and ", atlas N" are dropped
 * so that "bounce pass 2 (auto), atlas 0" and "bounce pass 2 (auto) (cache)" are one stage).
 * A stage seen before is continued, not restarted. */
void cli_timings_stage(cli_timings *t, const char *stage);

/* Stops the sampler and prints the table (stage, wall s, CPU s, CPU/wall, serial share) and
 * the whole bake's line to `out`; with csv_path, also writes it as CSV. out NULL: prints
 * nothing (a failed bake). Frees t; NULL is a no-op. */
void cli_timings_finish(cli_timings *t, FILE *out, const char *csv_path);

#endif
