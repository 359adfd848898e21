/* Per-stage wall time, CPU time and serial share of a bake (see timings.h). */
#define _GNU_SOURCE
#include "timings.h"

#include <dirent.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

/* 10 ms: fine enough for stages of tenths of seconds and up, and at most a few tenths of a
 * percent of one core (a sample reads each thread's clock once) */
#define SAMPLE_MS 10
#define MAX_STAGES 64
#define MAX_THREADS 4096

typedef struct stage_times {
    char name[48];
    double wall;    /* seconds the driving thread spent in it */
    double sampled; /* seconds of sampler intervals attributed to it */
    double cpu;     /* CPU seconds over all threads (but the sampler) */
    double serial;  /* seconds of intervals with at most one thread running */
} stage_times;

typedef struct thread_clock {
    pid_t tid;
    int64_t last_ns;
    unsigned seen; /* the sample that last saw it */
} thread_clock;

struct cli_timings {
    pthread_t sampler;
    pthread_mutex_t lock; /* guards stages[], count, current */
    atomic_int stop;
    pid_t sampler_tid;
    stage_times stages[MAX_STAGES];
    int count, current;
    double entered; /* when the driving thread entered `current` */
    thread_clock threads[MAX_THREADS];
    int thread_count;
    unsigned generation;
    double started;
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The CPU-time clock of thread `tid` of this process: Linux's MAKE_THREAD_CPUCLOCK(tid,
 * CPUCLOCK_SCHED), the id glibc's pthread_getcpuclockid builds (kernel ABI: ~tid << 3 | 6).
 * OpenMP's threads have no pthread_t the caller can see, so they are found by their tid. */
static int64_t thread_cpu_ns(pid_t tid)
{
    clockid_t id = (clockid_t)((~(unsigned)tid << 3) | 6u);
    struct timespec ts;
    if (clock_gettime(id, &ts) != 0)
        return -1;
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static thread_clock *find_thread(cli_timings *t, pid_t tid)
{
    for (int k = 0; k < t->thread_count; k++)
        if (t->threads[k].tid == tid)
            return &t->threads[k];
    if (t->thread_count == MAX_THREADS) { /* reuse a slot of an ended thread */
        for (int k = 0; k < t->thread_count; k++)
            if (t->threads[k].seen != t->generation - 1 && t->threads[k].seen != t->generation) {
                t->threads[k] = (thread_clock){tid, 0, t->generation};
                return &t->threads[k];
            }
        return NULL;
    }
    t->threads[t->thread_count] = (thread_clock){tid, 0, t->generation};
    return &t->threads[t->thread_count++];
}

/* One sample: the CPU each thread used since the last one; returns the CPU seconds and sets
 * *busy to the threads that ran more than half of dt. */
static double sample_threads(cli_timings *t, double dt, int *busy)
{
    DIR *d = opendir("/proc/self/task");
    double cpu = 0;
    *busy = 0;
    if (!d)
        return 0;
    t->generation++;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        pid_t tid = (pid_t)atoi(e->d_name);
        if (tid <= 0 || tid == t->sampler_tid)
            continue;
        int known = 0;
        for (int k = 0; k < t->thread_count && !known; k++)
            known = t->threads[k].tid == tid;
        thread_clock *c = find_thread(t, tid);
        int64_t ns = thread_cpu_ns(tid);
        if (!c || ns < 0)
            continue;
        /* a thread that appeared since the last sample ran all its CPU time inside this interval */
        int64_t delta = ns - (known ? c->last_ns : 0);
        c->last_ns = ns;
        c->seen = t->generation;
        if (delta > 0) {
            cpu += 1e-9 * (double)delta;
            *busy += 1e-9 * (double)delta > 0.5 * dt;
        }
    }
    closedir(d);
    return cpu;
}

static void *sampler_main(void *arg)
{
    cli_timings *t = arg;
    t->sampler_tid = (pid_t)syscall(SYS_gettid);
    int busy;
    double last = now_s();
    sample_threads(t, 1, &busy); /* the baseline: CPU before the first interval is not the stage's */
    struct timespec pause = {0, SAMPLE_MS * 1000000L};
    while (!atomic_load(&t->stop)) {
        nanosleep(&pause, NULL);
        double now = now_s(), dt = now - last;
        last = now;
        double cpu = sample_threads(t, dt, &busy);
        pthread_mutex_lock(&t->lock);
        stage_times *s = &t->stages[t->current];
        s->sampled += dt;
        s->cpu += cpu;
        if (busy <= 1)
            s->serial += dt;
        pthread_mutex_unlock(&t->lock);
    }
    return NULL;
}

/* "bounce pass 2 (auto), atlas 0" -> "bounce pass 2"; "direct, atlas 1: more samples" -> "direct". */
static void stage_key(const char *stage, char *key, size_t size)
{
    size_t n = 0;
    int depth = 0;
    for (const char *p = stage; *p && n + 1 < size; p++) {
        if (*p == '(')
            depth++;
        else if (*p == ')' && depth)
            depth--;
        else if (!depth && (*p == ',' || *p == ':'))
            break;
        else if (!depth)
            key[n++] = *p;
    }
    while (n && key[n - 1] == ' ')
        n--;
    key[n] = 0;
}

cli_timings *cli_timings_start(const char *first_stage)
{
    cli_timings *t = calloc(1, sizeof *t);
    if (!t)
        return NULL;
    pthread_mutex_init(&t->lock, NULL);
    t->started = t->entered = now_s();
    snprintf(t->stages[0].name, sizeof t->stages[0].name, "%s", first_stage);
    t->count = 1;
    if (pthread_create(&t->sampler, NULL, sampler_main, t) != 0) {
        pthread_mutex_destroy(&t->lock);
        free(t);
        return NULL;
    }
    return t;
}

void cli_timings_stage(cli_timings *t, const char *stage)
{
    if (!t)
        return;
    char key[48];
    stage_key(stage, key, sizeof key);
    pthread_mutex_lock(&t->lock);
    if (strcmp(t->stages[t->current].name, key) != 0) {
        double now = now_s();
        t->stages[t->current].wall += now - t->entered;
        t->entered = now;
        int k = 0;
        while (k < t->count && strcmp(t->stages[k].name, key) != 0)
            k++;
        if (k == t->count && t->count < MAX_STAGES)
            snprintf(t->stages[t->count++].name, sizeof t->stages[0].name, "%s", key);
        t->current = k < t->count ? k : t->count - 1;
    }
    pthread_mutex_unlock(&t->lock);
}

void cli_timings_finish(cli_timings *t, FILE *out, const char *csv_path)
{
    if (!t)
        return;
    atomic_store(&t->stop, 1);
    pthread_join(t->sampler, NULL);
    double now = now_s();
    t->stages[t->current].wall += now - t->entered;
    stage_times all = {"whole bake", now - t->started, 0, 0, 0};
    for (int k = 0; k < t->count; k++) {
        all.sampled += t->stages[k].sampled;
        all.cpu += t->stages[k].cpu;
        all.serial += t->stages[k].serial;
    }
    if (!out) { /* the bake failed: nothing to report */
        pthread_mutex_destroy(&t->lock);
        free(t);
        return;
    }
    FILE *csv = csv_path ? fopen(csv_path, "w") : NULL;
    if (csv)
        fprintf(csv, "stage,wall_s,cpu_s,serial_s\n");
    fprintf(out, "timings: %-28s %9s %9s %8s %8s\n", "stage", "wall s", "CPU s", "CPU/wall", "serial");
    for (int k = 0; k <= t->count; k++) {
        const stage_times *s = k < t->count ? &t->stages[k] : &all;
        /* the serial share is measured on the sampled intervals; scaled to the stage's wall time */
        double share = s->sampled > 0 ? s->serial / s->sampled : 1.0;
        fprintf(out, "timings: %-28s %9.3f %9.3f %8.2f %7.1f%%\n", s->name, s->wall, s->cpu,
                s->wall > 0 ? s->cpu / s->wall : 0.0, 100.0 * share);
        if (csv)
            fprintf(csv, "%s,%.4f,%.4f,%.4f\n", s->name, s->wall, s->cpu, share * s->wall);
    }
    if (csv && fclose(csv) != 0)
        fprintf(out, "timings: could not write %s\n", csv_path);
    else if (csv_path && !csv)
        fprintf(out, "timings: could not open %s\n", csv_path);
    pthread_mutex_destroy(&t->lock);
    free(t);
}
