/* The step runner: local, shard, finish and worker modes; parts and their merge (runner.h). */
#define _GNU_SOURCE
#include "runner.h"
#include "step_parts.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

struct lmb_steps {
    lmb_steps_mode mode;
    char *dir;
    lmb_part_identity id;
    uint32_t step, shard, shards;
    uint32_t next;        /* the step lmb_steps_run meets next */
    double min_rays;
    const lmb_log *log;
    /* worker mode (lmb_steps_create_worker) */
    uint32_t worker, workers;
    double wait_timeout;
    double computed_s, waited_s, merged_s; /* worker mode: where its steps' time went */
};

/* Room for n more bytes: the capacity doubles, or grows to exactly what is asked when that is
 * more (a step that appends a whole atlas at once gets no slack). */
static lmb_status buf_reserve(lmb_buf *b, size_t n, lmb_error *err)
{
    if (b->size + n <= b->cap)
        return LMB_OK;
    size_t cap = b->cap ? 2 * b->cap : 4096;
    if (cap < b->size + n)
        cap = b->size + n;
    uint8_t *d = realloc(b->data, cap);
    if (!d)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory for %zu bytes of step results", cap);
    b->data = d;
    b->cap = cap;
    return LMB_OK;
}

lmb_status lmb_buf_append(lmb_buf *b, const void *p, size_t n, lmb_error *err)
{
    lmb_status st = buf_reserve(b, n, err);
    if (st != LMB_OK)
        return st;
    if (n)
        memcpy(b->data + b->size, p, n);
    b->size += n;
    return LMB_OK;
}

void *lmb_buf_extend(lmb_buf *b, size_t n, lmb_error *err)
{
    if (buf_reserve(b, n, err) != LMB_OK)
        return NULL;
    b->size += n;
    return b->data + b->size - n;
}

int lmb_buf_take(lmb_buf *b, void *p, size_t n)
{
    if (b->read + n > b->size)
        return 0;
    memcpy(p, b->data + b->read, n);
    b->read += n;
    return 1;
}

void lmb_buf_free(lmb_buf *b)
{
    free(b->data);
    memset(b, 0, sizeof *b);
}

lmb_status lmb_steps_create(lmb_steps_mode mode, const char *dir, const lmb_part_identity *id, uint32_t step,
                            uint32_t shard, uint32_t shards, double min_rays, const lmb_log *log, lmb_steps **out,
                            lmb_error *err)
{
    *out = NULL;
    lmb_steps *s = calloc(1, sizeof *s);
    if (!s)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory");
    s->mode = mode;
    s->step = step;
    s->shard = shard;
    s->shards = shards ? shards : 1;
    s->log = log;
    s->min_rays = min_rays;
    if (mode != LMB_STEPS_LOCAL) {
        s->dir = strdup(dir);
        s->id = *id;
        s->id.config_text = id->config_text ? strdup(id->config_text) : NULL;
        if (!s->dir || (id->config_text && !s->id.config_text)) {
            lmb_steps_free(s);
            return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory");
        }
    }
    *out = s;
    return LMB_OK;
}

lmb_status lmb_steps_create_worker(const char *dir, const lmb_part_identity *id, const lmb_steps_worker *w,
                                   double min_rays, const lmb_log *log, lmb_steps **out, lmb_error *err)
{
    if (!w->shards || !w->workers || w->worker >= w->workers || w->workers > w->shards)
        return lmb_error_set(err, LMB_ERR_USAGE, "worker %u of %u with %u shards: out of range", w->worker + 1,
                             w->workers, w->shards);
    lmb_status st = lmb_steps_create(LMB_STEPS_WORKER, dir, id, 0, 0, w->shards, min_rays, log, out, err);
    if (st == LMB_OK) {
        (*out)->worker = w->worker;
        (*out)->workers = w->workers;
        (*out)->wait_timeout = w->wait_timeout;
    }
    return st;
}

void lmb_steps_free(lmb_steps *s)
{
    if (!s)
        return;
    free(s->dir);
    lmb_part_identity_free(&s->id);
    free(s);
}

uint32_t lmb_steps_count(const lmb_steps *s)
{
    return s ? s->next : 0;
}

static int exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

static double seconds_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Computes shard `shard`'s chunks of step `step` into out and writes them as its part. */
static lmb_status run_shard(lmb_steps *s, const lmb_step_desc *d, uint32_t step, uint32_t shard, lmb_buf *out,
                            uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    char path[4400];
    out->size = out->read = 0;
    memset(counters, 0, LMB_STEP_COUNTERS * sizeof *counters);
    uint64_t count = 0, mine = 0, items = 0;
    uint64_t *cuts = lmb_step_chunk_cuts(d, s->shards, &count);
    step_chunk *chunks = malloc((count / s->shards + 2) * sizeof *chunks);
    if (!cuts || !chunks) {
        free(cuts);
        free(chunks);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory for step %u's chunks", step);
    }
    double t0 = seconds_now();
    lmb_status st = LMB_OK;
    for (uint64_t c = shard; c < count && st == LMB_OK; c += s->shards) {
        if (cuts[c] >= cuts[c + 1])
            continue;
        size_t before = out->size;
        st = d->fn(d->user, cuts[c], cuts[c + 1], out, counters, err);
        chunks[mine++] = (step_chunk){cuts[c], cuts[c + 1], out->size - before};
        items += cuts[c + 1] - cuts[c];
    }
    free(cuts);
    double took = seconds_now() - t0;
    s->computed_s += took;
    step_body b = {0, d->items, {0}, {0}, mine, chunks, out->data, out->size};
    memcpy(b.counters, counters, sizeof b.counters);
    snprintf(b.name, sizeof b.name, "%s", d->name);
    lmb_step_part_path(s->dir, step, shard, s->shards, path, sizeof path);
    lmb_part_place place = {LMB_PART_SHARD, step, shard, s->shards};
    double t1 = seconds_now();
    if (st == LMB_OK)
        st = lmb_step_body_write(path, &s->id, &place, &b, err);
    double wrote = seconds_now() - t1;
    free(chunks);
    if (st == LMB_OK) /* the farm benchmark reads this line's times */
        lmb_info(s->log, "step %u (%s): shard %u of %u computed in %.4f s (%llu of %llu items in %llu chunks), wrote %s "
                 "in %.4f s", step, d->name, shard + 1, s->shards, took, (unsigned long long)items,
                 (unsigned long long)d->items, (unsigned long long)mine, path, wrote);
    return st;
}

/* Step `step`'s merged state into out and counters, checked against d: the parts its state
 * lists, merged again. */
static lmb_status read_state(lmb_steps *s, const lmb_step_desc *d, uint32_t step, lmb_buf *out,
                             uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    char path[4400];
    out->size = out->read = 0;
    memset(counters, 0, LMB_STEP_COUNTERS * sizeof *counters);
    lmb_step_state_path(s->dir, step, path, sizeof path);
    struct stat sb;
    if (stat(path, &sb) != 0)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: step %u (%s) has not been merged: run its shards and "
                             "'lmbake merge' first", path, step, d->name);
    uint32_t shards = 0;
    uint8_t *sums = NULL;
    lmb_merge_report report;
    lmb_status st = lmb_step_state_read(s->dir, &s->id, step, &shards, &sums, err);
    if (st == LMB_OK)
        st = lmb_step_merge_parts(s->dir, &s->id, step, shards, 0, sums, out, counters, &report, err);
    free(sums);
    if (st == LMB_OK && (report.end || report.noop || report.items != d->items || strcmp(report.name, d->name)))
        st = lmb_error_set(err, LMB_ERR_INPUT, "%s: holds '%s' (%llu items%s), but this bake's step %u is '%s' "
                           "(%llu items)", path, report.name, (unsigned long long)report.items,
                           report.end || report.noop ? ", the end" : "", step, d->name, (unsigned long long)d->items);
    return st;
}

/* Worker mode: unless step `step` is merged already (a worker restarted), computes this
 * worker's shards of it (those whose part is not in place), waits until every shard's part is
 * in the farm folder, and merges them in memory into out (*merged := 1); worker 1 also writes
 * the step's state, which a restarted worker and 'lmbake finish' read. Polls every 20 ms at
 * most: a part is seen within 20 ms of its rename, at two stat() calls per poll. */
static lmb_status work_step(lmb_steps *s, const lmb_step_desc *d, uint32_t step, lmb_buf *out,
                            uint64_t counters[LMB_STEP_COUNTERS], int *merged, lmb_error *err)
{
    char path[4400];
    *merged = 0;
    lmb_step_state_path(s->dir, step, path, sizeof path);
    if (exists(path))
        return LMB_OK;
    lmb_status st = LMB_OK;
    for (uint32_t k = s->worker; k < s->shards && st == LMB_OK; k += s->workers) {
        lmb_step_part_path(s->dir, step, k, s->shards, path, sizeof path);
        if (!exists(path)) /* one in place was written before a restart: the merge checks it */
            st = run_shard(s, d, step, k, out, counters, err);
    }
    double start = seconds_now(), said = start;
    useconds_t nap = 500;
    lmb_merge_report report;
    for (uint32_t k = 0; k < s->shards && st == LMB_OK;) {
        lmb_step_part_path(s->dir, step, k, s->shards, path, sizeof path);
        if (exists(path)) {
            k++;
            continue;
        }
        lmb_step_state_path(s->dir, step, path, sizeof path);
        if (exists(path)) { /* merged already (by a worker started before this one) */
            s->waited_s += seconds_now() - start;
            return LMB_OK;
        }
        double t = seconds_now();
        if (s->wait_timeout > 0 && t - start > s->wait_timeout)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "step %u (%s): waited %.0f s for parts/%04u.%u-of-%u.part: "
                                 "is worker %u of %u running? (restart it: 'lmbake worker ... --worker %u/%u')", step,
                                 d->name, t - start, step, k + 1, s->shards, k % s->workers + 1, s->workers,
                                 k % s->workers + 1, s->workers);
        if (t - said >= 60) {
            lmb_info(s->log, "step %u (%s): waiting %.0f s for parts/%04u.%u-of-%u.part (worker %u of %u)", step,
                     d->name, t - start, step, k + 1, s->shards, k % s->workers + 1, s->workers);
            said = t;
        }
        usleep(nap);
        nap = nap < 10000 ? 2 * nap : 20000;
    }
    double waited = seconds_now();
    s->waited_s += waited - start;
    if (st == LMB_OK)
        st = lmb_step_merge_parts(s->dir, &s->id, step, s->shards, s->worker == 0, NULL, out, counters, &report, err);
    if (st == LMB_OK && (report.end || report.noop || report.items != d->items || strcmp(report.name, d->name)))
        st = lmb_error_set(err, LMB_ERR_INPUT, "%s/parts: step %u's parts hold '%s' (%llu items%s), but this bake's "
                           "step %u is '%s' (%llu items): a farm folder with parts of another run?", s->dir, step,
                           report.name, (unsigned long long)report.items, report.end || report.noop ? ", the end" : "",
                           step, d->name, (unsigned long long)d->items);
    *merged = st == LMB_OK;
    s->merged_s += seconds_now() - waited;
    return st;
}

lmb_status lmb_steps_run(lmb_steps *s, const lmb_step_desc *d, lmb_buf *out, uint64_t counters[LMB_STEP_COUNTERS],
                         lmb_error *err)
{
    out->size = out->read = 0;
    memset(counters, 0, LMB_STEP_COUNTERS * sizeof *counters);
    if (!d->items) /* nothing to do: no step (every process sees the same count) */
        return LMB_OK;
    if (d->rays < s->min_rays) /* cheaper here than a farm step: every process computes it */
        return d->fn(d->user, 0, d->items, out, counters, err);
    uint32_t step = s->next++;
    if (s->mode == LMB_STEPS_LOCAL || (s->mode == LMB_STEPS_SHARD && step > s->step))
        return d->fn(d->user, 0, d->items, out, counters, err);
    if (s->mode == LMB_STEPS_SHARD && step == s->step) {
        lmb_status st = run_shard(s, d, step, s->shard, out, counters, err);
        return st == LMB_OK ? LMB_STEP_STOPPED : st;
    }
    if (s->mode == LMB_STEPS_WORKER) {
        int merged;
        lmb_status st = work_step(s, d, step, out, counters, &merged, err);
        double t0 = seconds_now();
        if (st == LMB_OK && !merged)
            st = read_state(s, d, step, out, counters, err);
        s->merged_s += seconds_now() - t0;
        return st;
    }
    /* an earlier step (shard mode), any step (finish), or a step the workers have merged */
    return read_state(s, d, step, out, counters, err);
}

lmb_status lmb_steps_run_streamed(lmb_steps *s, const lmb_step_desc *d, uint64_t chunk, lmb_step_take_fn take,
                                  void *take_user, uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    lmb_buf bytes = {0};
    lmb_status st = LMB_OK;
    int below = d->rays < s->min_rays;
    int here = below || s->mode == LMB_STEPS_LOCAL || (s->mode == LMB_STEPS_SHARD && s->next > s->step);
    if (!d->items || !here) { /* read (or, at a shard's own step, computed and written): all at once */
        st = lmb_steps_run(s, d, &bytes, counters, err);
        if (st == LMB_OK && d->items)
            st = take(take_user, &bytes, err);
        lmb_buf_free(&bytes);
        return st;
    }
    memset(counters, 0, LMB_STEP_COUNTERS * sizeof *counters);
    if (!below)
        s->next++; /* numbered as lmb_steps_run numbers it */
    chunk = chunk ? chunk : d->items;
    for (uint64_t first = 0; first < d->items && st == LMB_OK; first += chunk) {
        uint64_t last = d->items - first > chunk ? first + chunk : d->items;
        bytes.size = bytes.read = 0;
        st = d->fn(d->user, first, last, &bytes, counters, err);
        if (st == LMB_OK)
            st = take(take_user, &bytes, err);
        if (st == LMB_OK && bytes.read != bytes.size)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "step '%s': %zu bytes of items %llu..%llu left unread", d->name,
                               bytes.size - bytes.read, (unsigned long long)first, (unsigned long long)last);
    }
    lmb_buf_free(&bytes);
    return st;
}

/* Moves past arrays that are full (or hold nothing). */
static void sink_skip_full(lmb_float_sink *k)
{
    while (k->at < k->arrays && k->filled == k->floats[k->at]) {
        k->at++;
        k->filled = 0;
    }
}

lmb_status lmb_take_floats(void *sink, lmb_buf *bytes, lmb_error *err)
{
    lmb_float_sink *k = sink;
    if ((bytes->size - bytes->read) % sizeof(float))
        return lmb_error_set(err, LMB_ERR_INPUT, "step results: %zu bytes are not whole floats", bytes->size - bytes->read);
    for (sink_skip_full(k); bytes->read < bytes->size; sink_skip_full(k)) {
        if (k->at == k->arrays)
            return lmb_error_set(err, LMB_ERR_INPUT, "step results: %zu bytes more than the texels hold",
                                 bytes->size - bytes->read);
        uint64_t have = (bytes->size - bytes->read) / sizeof(float), need = k->floats[k->at] - k->filled;
        uint64_t n = have < need ? have : need;
        lmb_buf_take(bytes, k->dst[k->at] + k->filled, n * sizeof(float));
        k->filled += n;
    }
    return LMB_OK;
}

int lmb_float_sink_full(lmb_float_sink *k)
{
    sink_skip_full(k);
    return k->at == k->arrays;
}

lmb_status lmb_steps_write_end(lmb_steps *s, lmb_error *err)
{
    char path[4400];
    step_body b;
    memset(&b, 0, sizeof b);
    b.end = 1;
    snprintf(b.name, sizeof b.name, "end");
    lmb_step_part_path(s->dir, s->step, s->shard, s->shards, path, sizeof path);
    lmb_part_place place = {LMB_PART_SHARD, s->step, s->shard, s->shards};
    lmb_status st = lmb_step_body_write(path, &s->id, &place, &b, err);
    if (st == LMB_OK)
        lmb_info(s->log, "step %u: the bake has %u steps: nothing to do (wrote %s)", s->step, s->next, path);
    return st;
}

lmb_status lmb_steps_worker_end(lmb_steps *s, lmb_error *err)
{
    if (s->mode != LMB_STEPS_WORKER)
        return LMB_OK;
    lmb_info(s->log, "worker %u of %u: %u steps: its shards took %.2f s, waiting for the other workers' parts %.2f s, "
             "merging and reading the steps %.2f s", s->worker + 1, s->workers, s->next, s->computed_s, s->waited_s,
             s->merged_s);
    if (lmb_steps_end_step(s->dir) == s->next)
        return LMB_OK;
    return lmb_step_write_end_marker(s->dir, s->next, err);
}

