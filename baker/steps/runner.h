/*
 * The bake's expensive loops as steps (docs/farm.md). A step is a list of independent work
 * items (texels, bands of texels, irradiance-cache records) whose results depend only on what
 * earlier steps gave; its function computes any range of them into bytes, in item order.
 * The lighting stage runs every such loop through lmb_steps_run, and the runner decides where
 * the bytes come from:
 *   local  (lmbake bake): the function runs over all items, in this process;
 *   shard  (lmbake step --step S --shard k/N): steps before S are read from the merged
 *          states in the farm folder, step S runs over shard k's chunks of items (cut by
 *          estimated cost) and is written as a part; then the bake stops (LMB_STEP_STOPPED);
 *   finish (lmbake finish): every step is read from the merged states;
 *   worker (lmbake worker --worker W/J): a process for the whole bake. At each step it runs its
 *          shards (W, W + J, ... of N), waits for the other workers' parts in the farm folder,
 *          merges them into the step's state itself and goes on, so a step costs it its own
 *          items, a wait and a read, not a process start and a replay. A step already merged
 *          is read (a restarted worker catches up by replaying the merged states).
 * The code between steps (rim limits, record placement, k-d trees, interpolation, dilation)
 * runs in every process on the same bytes, so a shard and a one-machine bake see the same
 * state before each step, and the finish stage writes exactly what lmbake bake writes.
 *
 * Files (all part_file.h containers with the plan's identity):
 *   DIR/parts/SSSS.K-of-N.part   shard K (1-based) of N of step S: items [first, last)
 *   DIR/steps/SSSS.state         step S merged: all its items (lmb_steps_merge)
 *   DIR/end                      the step the bake ended at ("S\n"): steps from S on are no-ops
 * A shard whose bake ends before step S writes an "end" part; their merge writes DIR/end.
 */
#ifndef LMBAKE_STEPS_RUNNER_H
#define LMBAKE_STEPS_RUNNER_H

#include "steps/part_file.h"

#include <lmbake/lmbake.h>

#include <stddef.h>
#include <stdint.h>

/* Returned through the pipeline once a shard has written its part: not an error. */
#define LMB_STEP_STOPPED ((lmb_status)100)

/* Counters a step adds up over its items (rays, texels, ...; meaning is the caller's). */
#define LMB_STEP_COUNTERS 6

/* A growable byte buffer (owned: lmb_buf_free). */
typedef struct lmb_buf {
    uint8_t *data;
    size_t size, cap, read; /* read: where lmb_buf_take continues */
} lmb_buf;

lmb_status lmb_buf_append(lmb_buf *b, const void *p, size_t n, lmb_error *err);
/* Appends n bytes left for the caller to write (no copy through a buffer of its own); NULL
 * when out of memory (err set). The pointer is valid until the next append. */
void *lmb_buf_extend(lmb_buf *b, size_t n, lmb_error *err);
/* Copies the next n bytes into p; 0 when fewer are left. */
int lmb_buf_take(lmb_buf *b, void *p, size_t n);
void lmb_buf_free(lmb_buf *b);

/* Computes items [first, last) into out (appended in item order) and adds to counters. */
typedef lmb_status (*lmb_step_fn)(void *user, uint64_t first, uint64_t last, lmb_buf *out,
                                  uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err);

typedef struct lmb_step_desc {
    const char *name;     /* what the step is, for messages ("direct, atlas 0") */
    uint64_t items;
    const double *cost;   /* estimated cost per item (NULL: equal): shards get equal sums */
    double rays;          /* estimated rays of the whole step: under the runner's minimum, the step
                             runs in every process (local) and is no step of the farm */
    lmb_step_fn fn;
    void *user;
} lmb_step_desc;

typedef enum lmb_steps_mode { LMB_STEPS_LOCAL, LMB_STEPS_SHARD, LMB_STEPS_FINISH, LMB_STEPS_WORKER } lmb_steps_mode;

typedef struct lmb_steps lmb_steps;

/* min_rays: steps estimated under it run locally in every mode (farm.min_step_rays).
 * Local: dir, id may be NULL. Shard: run step `step`, shard `shard` (0-based) of `shards`.
 * id: the plan's identity (lmb_plan_read), copied. */
lmb_status lmb_steps_create(lmb_steps_mode mode, const char *dir, const lmb_part_identity *id, uint32_t step,
                            uint32_t shard, uint32_t shards, double min_rays, const lmb_log *log, lmb_steps **out,
                            lmb_error *err);
void lmb_steps_free(lmb_steps *s);

/* A worker's place in the farm (0-based worker of workers; its shards: worker, worker + workers, ...). */
typedef struct lmb_steps_worker {
    uint32_t shards, worker, workers;
    double wait_timeout;    /* seconds to wait for another worker's part before failing (0: for ever) */
} lmb_steps_worker;

lmb_status lmb_steps_create_worker(const char *dir, const lmb_part_identity *id, const lmb_steps_worker *w,
                                   double min_rays, const lmb_log *log, lmb_steps **out, lmb_error *err);

/* Worker mode, the lighting done: writes DIR/end (the number of steps) unless it is there. */
lmb_status lmb_steps_worker_end(lmb_steps *s, lmb_error *err);

/* Runs (or reads) the next step: *out := all its items' bytes (reset first), counters := their
 * sums. Shard mode, at its own step: writes the part and returns LMB_STEP_STOPPED. */
lmb_status lmb_steps_run(lmb_steps *s, const lmb_step_desc *d, lmb_buf *out, uint64_t counters[LMB_STEP_COUNTERS],
                         lmb_error *err);

/* Takes a step's bytes as they come; must read all it is given (bytes->read == bytes->size). */
typedef lmb_status (*lmb_step_take_fn)(void *user, lmb_buf *bytes, lmb_error *err);

/* Items per chunk for a streamed step of texels: its bytes in a local bake are this many texels'. */
#define LMB_STEP_STREAM_ITEMS 65536

/* lmb_steps_run, with the bytes handed to take in item order: where the step runs in this
 * process over all its items (a local bake, or a step under the runner's minimum), `chunk`
 * items at a time, so the whole step's bytes never exist at once (the texel arrays they fill
 * are all the step costs); elsewhere (a farm's merged state) all at once. The bytes are the
 * same either way: items are independent. */
lmb_status lmb_steps_run_streamed(lmb_steps *s, const lmb_step_desc *d, uint64_t chunk, lmb_step_take_fn take,
                                  void *take_user, uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err);

/* The take function of the common step whose bytes are floats filling arrays one after the
 * other (an atlas's texels, then the next atlas's): dst[k] receives floats[k] floats. */
typedef struct lmb_float_sink {
    uint32_t arrays;
    float *const *dst;
    const uint64_t *floats;
    uint32_t at;     /* the array being filled, and how much of it is */
    uint64_t filled;
} lmb_float_sink;

lmb_status lmb_take_floats(void *sink, lmb_buf *bytes, lmb_error *err);
/* Whether every array is full (the step gave all it should). */
int lmb_float_sink_full(lmb_float_sink *sink);

/* Steps run or read so far. */
uint32_t lmb_steps_count(const lmb_steps *s);

/* Shard mode, the bake having ended before the shard's step: writes an "end" part. */
lmb_status lmb_steps_write_end(lmb_steps *s, lmb_error *err);

/* What a merge did. */
typedef struct lmb_merge_report {
    int end;              /* the bake ends before this step (DIR/end written) */
    int noop;             /* the step is past the end already: nothing merged */
    uint64_t items;
    char name[96];
} lmb_merge_report;

/* Merges the `shards` parts of step `step` into its state, after checking each against id
 * (naming the part and what differs) and that their chunks cover the items exactly once. */
lmb_status lmb_steps_merge(const char *dir, const lmb_part_identity *id, uint32_t step, uint32_t shards,
                           lmb_merge_report *report, lmb_error *err);

/* The step the bake ended at (DIR/end), or UINT32_MAX when not known yet. */
uint32_t lmb_steps_end_step(const char *dir);

/* Creates DIR, DIR/parts and DIR/steps (existing ones are fine). */
lmb_status lmb_steps_make_dirs(const char *dir, lmb_error *err);

#endif
