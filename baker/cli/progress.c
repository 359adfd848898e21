/* Stage progress with rate and ETA (see progress.h). */
#define _POSIX_C_SOURCE 200809L
#include "progress.h"

#include <string.h>
#include <time.h>
#include <unistd.h>

double cli_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void cli_progress_init(cli_progress *p, FILE *out, int quiet)
{
    memset(p, 0, sizeof *p);
    p->out = out;
    p->quiet = quiet;
    p->tty = isatty(fileno(out));
    p->last_decile = -1;
}

static void format_seconds(double s, char *buf, size_t size)
{
    if (s < 0 || s > 1e7)
        snprintf(buf, size, "--");
    else if (s < 60)
        snprintf(buf, size, "%.0fs", s);
    else if (s < 3600)
        snprintf(buf, size, "%dm%02ds", (int)s / 60, (int)s % 60);
    else
        snprintf(buf, size, "%dh%02dm", (int)s / 3600, ((int)s % 3600) / 60);
}

void cli_progress_update(void *user, const char *stage, uint64_t done, uint64_t total)
{
    cli_progress *p = user;
    if (p->quiet)
        return;
    double now = cli_now();
    if (strncmp(p->stage, stage, sizeof p->stage - 1) != 0) {
        if (p->tty && p->stage[0])
            fputc('\n', p->out);
        snprintf(p->stage, sizeof p->stage, "%s", stage);
        p->stage_start = now;
        p->last_print = 0;
        p->last_decile = -1;
    }
    double elapsed = now - p->stage_start;
    double frac = total ? (double)done / (double)total : 1.0;
    double rate = elapsed > 0 ? (double)done / elapsed : 0.0;
    char eta[32], took[32];
    format_seconds(frac > 0 ? elapsed * (1.0 - frac) / frac : -1, eta, sizeof eta);
    format_seconds(elapsed, took, sizeof took);
    if (p->tty) {
        if (done < total && now - p->last_print < 0.1)
            return;
        p->last_print = now;
        fprintf(p->out, "\r%-12s %5.1f%%  %llu/%llu  %.3g/s  ETA %s   ", stage, 100.0 * frac,
                (unsigned long long)done, (unsigned long long)total, rate, eta);
        if (done >= total)
            fprintf(p->out, "\r%-12s done in %s (%llu, %.3g/s)%20s\n", stage, took,
                    (unsigned long long)total, rate, "");
        fflush(p->out);
        if (done >= total)
            p->stage[0] = '\0';
        return;
    }
    int decile = (int)(frac * 10.0);
    if (decile == p->last_decile && done < total)
        return;
    p->last_decile = decile;
    if (done >= total) {
        fprintf(p->out, "%s: done in %s (%llu, %.3g/s)\n", stage, took, (unsigned long long)total, rate);
        p->stage[0] = '\0';
    } else {
        fprintf(p->out, "%s: %3.0f%% (%llu/%llu, %.3g/s, ETA %s)\n", stage, 100.0 * frac,
                (unsigned long long)done, (unsigned long long)total, rate, eta);
    }
    fflush(p->out);
}
