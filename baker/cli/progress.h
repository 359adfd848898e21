/*
 * Progress display for long stages: on a TTY one self-rewriting line with stage, percent,
 * rate and ETA; otherwise (logs, CI) a plain line at start, every 10% and at the end.
 * It implements lmb_progress_fn; the state lives in the caller's struct.
 */
#ifndef LMBAKE_PROGRESS_H
#define LMBAKE_PROGRESS_H

#include <stdint.h>
#include <stdio.h>

typedef struct cli_progress {
    FILE *out;
    int tty;            /* rewrite one line with \r */
    int quiet;          /* print nothing */
    char stage[64];     /* current stage */
    double stage_start; /* seconds, monotonic */
    double last_print;
    int last_decile;    /* plain mode: last 10% step printed */
    const char *unit;   /* what `done` counts, e.g. "texels" */
} cli_progress;

void cli_progress_init(cli_progress *p, FILE *out, int quiet);

/* lmb_progress_fn: user is a cli_progress. */
void cli_progress_update(void *user, const char *stage, uint64_t done, uint64_t total);

double cli_now(void);

#endif
