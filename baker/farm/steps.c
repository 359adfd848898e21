/* The step runner: local, shard and finish modes; parts and their merge (steps.h). */
#define _GNU_SOURCE
#include "steps.h"

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
    int finishes;
    uint32_t tail_threads;
    double wait_timeout;
};

/* The body of a part or a state:
 *   u32 end, u32 name_length, u64 items, first, last, counters[LMB_STEP_COUNTERS], u64 bytes,
 *   name, bytes                                  (little-endian hosts only, as part_file.h) */
#define BODY_HEADER (2 * 4 + (4 + LMB_STEP_COUNTERS) * 8)

typedef struct step_body {
    uint32_t end;
    uint64_t items, first, last, counters[LMB_STEP_COUNTERS];
    char name[96];
    const uint8_t *bytes;
    uint64_t size;
} step_body;

lmb_status lmb_buf_append(lmb_buf *b, const void *p, size_t n, lmb_error *err)
{
    if (b->size + n > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->size + n)
            cap *= 2;
        uint8_t *d = realloc(b->data, cap);
        if (!d)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory for %zu bytes of step results", cap);
        b->data = d;
        b->cap = cap;
    }
    if (n)
        memcpy(b->data + b->size, p, n);
    b->size += n;
    return LMB_OK;
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

lmb_status lmb_steps_make_dirs(const char *dir, lmb_error *err)
{
    char path[4200];
    const char *sub[] = {"", "/parts", "/steps"};
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s%s", dir, sub[k]);
        if (mkdir(path, 0777) != 0 && errno != EEXIST)
            return lmb_error_set(err, LMB_ERR_INPUT, "farm folder %s: %s", path, strerror(errno));
    }
    return LMB_OK;
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
        (*out)->finishes = w->finishes;
        (*out)->tail_threads = w->tail_threads;
        (*out)->wait_timeout = w->wait_timeout;
    }
    return st;
}

int lmb_steps_light_unused(const lmb_steps *s)
{
    return s && (s->mode == LMB_STEPS_SHARD || (s->mode == LMB_STEPS_WORKER && !s->finishes));
}

uint32_t lmb_steps_tail_threads(const lmb_steps *s, uint32_t threads)
{
    return s && s->mode == LMB_STEPS_WORKER && s->finishes && s->tail_threads ? s->tail_threads : threads;
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

static void put(uint8_t **p, const void *v, size_t n)
{
    memcpy(*p, v, n);
    *p += n;
}

/* The body for b (bytes from b->bytes), malloc'd. */
static uint8_t *encode_body(const step_body *b, size_t *size)
{
    uint32_t name_length = (uint32_t)strlen(b->name);
    *size = BODY_HEADER + name_length + b->size;
    uint8_t *body = malloc(*size + 1), *p = body;
    if (!body)
        return NULL;
    put(&p, &b->end, 4);
    put(&p, &name_length, 4);
    put(&p, &b->items, 8);
    put(&p, &b->first, 8);
    put(&p, &b->last, 8);
    put(&p, b->counters, 8 * LMB_STEP_COUNTERS);
    put(&p, &b->size, 8);
    put(&p, b->name, name_length);
    if (b->size)
        put(&p, b->bytes, b->size);
    return body;
}

static lmb_status decode_body(const char *path, const uint8_t *body, size_t size, step_body *b, lmb_error *err)
{
    memset(b, 0, sizeof *b);
    uint32_t name_length;
    if (size < BODY_HEADER)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: step body too short (%zu bytes)", path, size);
    const uint8_t *p = body;
    memcpy(&b->end, p, 4);
    memcpy(&name_length, p + 4, 4);
    memcpy(&b->items, p + 8, 8);
    memcpy(&b->first, p + 16, 8);
    memcpy(&b->last, p + 24, 8);
    memcpy(b->counters, p + 32, 8 * LMB_STEP_COUNTERS);
    memcpy(&b->size, p + 32 + 8 * LMB_STEP_COUNTERS, 8);
    if (name_length >= sizeof b->name || b->size > size - BODY_HEADER - name_length ||
        BODY_HEADER + name_length + b->size != size || b->first > b->last || b->last > b->items || b->end > 1)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: inconsistent step body", path);
    memcpy(b->name, p + BODY_HEADER, name_length);
    b->bytes = p + BODY_HEADER + name_length;
    return LMB_OK;
}

static void part_path(const char *dir, uint32_t step, uint32_t shard, uint32_t shards, char *out, size_t n)
{
    snprintf(out, n, "%s/parts/%04u.%u-of-%u.part", dir, step, shard + 1, shards);
}

static void state_path(const char *dir, uint32_t step, char *out, size_t n)
{
    snprintf(out, n, "%s/steps/%04u.state", dir, step);
}

/* Shard k of n's range of items: the first item whose cost prefix reaches k/n of the total
 * (doubles summed in item order: the same cut on every machine). */
static uint64_t cut(const lmb_step_desc *d, uint32_t k, uint32_t n)
{
    if (k == 0)
        return 0;
    if (k >= n)
        return d->items;
    if (!d->cost)
        return d->items * k / n;
    double total = 0, sum = 0;
    for (uint64_t i = 0; i < d->items; i++)
        total += d->cost[i];
    double target = total * k / n;
    for (uint64_t i = 0; i < d->items; i++) {
        if (sum >= target)
            return i;
        sum += d->cost[i];
    }
    return d->items;
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

/* Computes shard `shard`'s range of step `step` into out and writes it as its part. */
static lmb_status run_shard(lmb_steps *s, const lmb_step_desc *d, uint32_t step, uint32_t shard, lmb_buf *out,
                            uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    char path[4400];
    out->size = out->read = 0;
    memset(counters, 0, LMB_STEP_COUNTERS * sizeof *counters);
    uint64_t first = cut(d, shard, s->shards), last = cut(d, shard + 1, s->shards);
    lmb_info(s->log, "step %u (%s): shard %u of %u, items %llu-%llu of %llu", step, d->name, shard + 1, s->shards,
             (unsigned long long)first, (unsigned long long)last, (unsigned long long)d->items);
    double t0 = seconds_now();
    lmb_status st = first < last ? d->fn(d->user, first, last, out, counters, err) : LMB_OK;
    if (st != LMB_OK)
        return st;
    double took = seconds_now() - t0;
    step_body b = {0, d->items, first, last, {0}, {0}, out->data, out->size};
    memcpy(b.counters, counters, sizeof b.counters);
    snprintf(b.name, sizeof b.name, "%s", d->name);
    size_t size;
    uint8_t *body = encode_body(&b, &size);
    if (!body)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory for step %u's part", step);
    part_path(s->dir, step, shard, s->shards, path, sizeof path);
    lmb_part_place place = {LMB_PART_SHARD, step, shard, s->shards};
    st = lmb_part_write(path, &s->id, &place, body, size, err);
    free(body);
    if (st == LMB_OK) /* the farm benchmark reads this line's time */
        lmb_info(s->log, "step %u: shard %u of %u computed in %.4f s, wrote %s", step, shard + 1, s->shards, took, path);
    return st;
}

/* Step `step`'s merged state into out and counters, checked against d. */
static lmb_status read_state(lmb_steps *s, const lmb_step_desc *d, uint32_t step, lmb_buf *out,
                             uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    char path[4400];
    out->size = out->read = 0;
    memset(counters, 0, LMB_STEP_COUNTERS * sizeof *counters);
    state_path(s->dir, step, path, sizeof path);
    struct stat sb;
    if (stat(path, &sb) != 0)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: step %u (%s) has not been merged: run its shards and "
                             "'lmbake merge' first", path, step, d->name);
    lmb_part_place want = {LMB_PART_STATE, step, 0, 1}, got;
    void *raw = NULL;
    size_t size = 0;
    lmb_status st = lmb_part_read(path, &s->id, &want, &got, &raw, &size, err);
    step_body b;
    if (st == LMB_OK)
        st = decode_body(path, raw, size, &b, err);
    if (st == LMB_OK && (b.end || b.items != d->items || strcmp(b.name, d->name) != 0))
        st = lmb_error_set(err, LMB_ERR_INPUT, "%s: holds '%s' (%llu items%s), but this bake's step %u is '%s' "
                           "(%llu items)", path, b.name, (unsigned long long)b.items, b.end ? ", the end" : "", step,
                           d->name, (unsigned long long)d->items);
    if (st == LMB_OK) {
        memcpy(counters, b.counters, sizeof b.counters);
        st = lmb_buf_append(out, b.bytes, b.size, err);
    }
    free(raw);
    return st;
}

/* Worker mode: unless step `step` is merged already (a worker restarted, or another worker got
 * there first), computes this worker's shards of it (those whose part is not in place), waits
 * until every shard's part is in the farm folder, and merges them into the step's state. */
static lmb_status work_step(lmb_steps *s, const lmb_step_desc *d, uint32_t step, lmb_buf *out,
                            uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    char path[4400];
    state_path(s->dir, step, path, sizeof path);
    if (exists(path))
        return LMB_OK;
    lmb_status st = LMB_OK;
    for (uint32_t k = s->worker; k < s->shards && st == LMB_OK; k += s->workers) {
        part_path(s->dir, step, k, s->shards, path, sizeof path);
        if (!exists(path)) /* one in place was written before a restart: the merge checks it */
            st = run_shard(s, d, step, k, out, counters, err);
    }
    double start = seconds_now(), said = start;
    useconds_t nap = 500;
    for (uint32_t k = 0; k < s->shards && st == LMB_OK;) {
        part_path(s->dir, step, k, s->shards, path, sizeof path);
        if (exists(path)) {
            k++;
            continue;
        }
        state_path(s->dir, step, path, sizeof path);
        if (exists(path)) /* merged by another worker */
            return LMB_OK;
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
        nap = nap < 50000 ? 2 * nap : 100000;
    }
    if (st != LMB_OK)
        return st;
    state_path(s->dir, step, path, sizeof path);
    if (exists(path))
        return LMB_OK;
    lmb_merge_report report;
    return lmb_steps_merge(s->dir, &s->id, step, s->shards, &report, err);
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
        lmb_status st = work_step(s, d, step, out, counters, err);
        if (st != LMB_OK)
            return st;
    }
    /* an earlier step (shard mode), any step (finish), or a step the workers have merged */
    return read_state(s, d, step, out, counters, err);
}

lmb_status lmb_steps_write_end(lmb_steps *s, lmb_error *err)
{
    char path[4400];
    step_body b;
    memset(&b, 0, sizeof b);
    b.end = 1;
    snprintf(b.name, sizeof b.name, "end");
    size_t size;
    uint8_t *body = encode_body(&b, &size);
    if (!body)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory");
    part_path(s->dir, s->step, s->shard, s->shards, path, sizeof path);
    lmb_part_place place = {LMB_PART_SHARD, s->step, s->shard, s->shards};
    lmb_status st = lmb_part_write(path, &s->id, &place, body, size, err);
    free(body);
    if (st == LMB_OK)
        lmb_info(s->log, "step %u: the bake has %u steps: nothing to do (wrote %s)", s->step, s->next, path);
    return st;
}

uint32_t lmb_steps_end_step(const char *dir)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/end", dir);
    FILE *f = fopen(path, "r");
    unsigned v = UINT32_MAX;
    if (!f)
        return UINT32_MAX;
    if (fscanf(f, "%u", &v) != 1)
        v = UINT32_MAX;
    fclose(f);
    return v;
}

/* DIR/end := "step\n" (atomically). */
static lmb_status write_end_marker(const char *dir, uint32_t step, lmb_error *err)
{
    char path[4200], tmp[4500];
    snprintf(path, sizeof path, "%s/end", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    int ok = f && fprintf(f, "%u\n", step) > 0;
    ok = (f && fclose(f) == 0) && ok;
    if (!ok || rename(tmp, path) != 0) {
        remove(tmp);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot write: %s", path, strerror(errno));
    }
    return LMB_OK;
}

lmb_status lmb_steps_worker_end(lmb_steps *s, lmb_error *err)
{
    if (s->mode != LMB_STEPS_WORKER || lmb_steps_end_step(s->dir) == s->next)
        return LMB_OK;
    return write_end_marker(s->dir, s->next, err);
}

lmb_status lmb_steps_merge(const char *dir, const lmb_part_identity *id, uint32_t step, uint32_t shards,
                           lmb_merge_report *report, lmb_error *err)
{
    memset(report, 0, sizeof *report);
    uint32_t end = lmb_steps_end_step(dir);
    if (end != UINT32_MAX && step > end) {
        report->noop = 1;
        return LMB_OK;
    }
    char path[4400];
    void **raw = calloc((size_t)shards + 1, sizeof *raw);
    step_body *b = calloc((size_t)shards + 1, sizeof *b);
    lmb_status st = raw && b ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory");
    uint64_t total = 0, next = 0;
    for (uint32_t k = 0; k < shards && st == LMB_OK; k++) {
        part_path(dir, step, k, shards, path, sizeof path);
        struct stat sb;
        if (stat(path, &sb) != 0) {
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: missing: shard %u of %u of step %u has not finished (rerun "
                               "it: 'lmbake step ... --step %u --shard %u/%u')", path, k + 1, shards, step, step, k + 1,
                               shards);
            break;
        }
        lmb_part_place want = {LMB_PART_SHARD, step, k, shards}, got;
        size_t size = 0;
        st = lmb_part_read(path, id, &want, &got, &raw[k], &size, err);
        if (st == LMB_OK)
            st = decode_body(path, raw[k], size, &b[k], err);
        if (st != LMB_OK)
            break;
        if (b[k].end != b[0].end || (!b[k].end && (b[k].items != b[0].items || strcmp(b[k].name, b[0].name) ||
                                                   b[k].first != next)))
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: does not fit the other parts of step %u ('%s', items %llu-%llu "
                               "of %llu; expected '%s' from item %llu)", path, step, b[k].name,
                               (unsigned long long)b[k].first, (unsigned long long)b[k].last,
                               (unsigned long long)b[k].items, b[0].name, (unsigned long long)next);
        next = b[k].last;
        total += b[k].size;
    }
    if (st == LMB_OK && !b[0].end && next != b[0].items)
        st = lmb_error_set(err, LMB_ERR_INPUT, "step %u: the parts cover items 0-%llu of %llu", step,
                           (unsigned long long)next, (unsigned long long)b[0].items);
    step_body m;
    memset(&m, 0, sizeof m);
    uint8_t *bytes = st == LMB_OK ? malloc(total + 1) : NULL;
    if (st == LMB_OK && !bytes)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory for step %u (%llu bytes)", step,
                           (unsigned long long)total);
    if (st == LMB_OK) {
        m.end = b[0].end;
        m.items = b[0].items;
        m.first = 0;
        m.last = b[0].items;
        snprintf(m.name, sizeof m.name, "%s", b[0].name);
        for (uint32_t k = 0; k < shards; k++) {
            for (int c = 0; c < LMB_STEP_COUNTERS; c++)
                m.counters[c] += b[k].counters[c];
            if (b[k].size)
                memcpy(bytes + m.size, b[k].bytes, b[k].size);
            m.size += b[k].size;
        }
        m.bytes = bytes;
        size_t size;
        uint8_t *body = encode_body(&m, &size);
        if (!body)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory");
        state_path(dir, step, path, sizeof path);
        lmb_part_place place = {LMB_PART_STATE, step, 0, 1};
        if (st == LMB_OK)
            st = lmb_part_write(path, id, &place, body, size, err);
        free(body);
    }
    if (st == LMB_OK && m.end) /* the marker steps past the end look at */
        st = write_end_marker(dir, step, err);
    if (st == LMB_OK) {
        report->end = m.end;
        report->items = m.items;
        snprintf(report->name, sizeof report->name, "%s", m.name);
    }
    free(bytes);
    for (uint32_t k = 0; raw && k < shards; k++)
        free(raw[k]);
    free(raw);
    free(b);
    return st;
}
