/* The step runner's files: the part and state body format, chunk cuts, the merge (step_parts.h). */
#define _GNU_SOURCE
#include "step_parts.h"

#include "util/big_buffer.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

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


static void put(uint8_t **p, const void *v, size_t n)
{
    memcpy(*p, v, n);
    *p += n;
}

static size_t head_size(const step_body *b)
{
    return BODY_HEADER + strlen(b->name) + 24 * b->chunk_count;
}

/* Everything of b's body before its result bytes, into p (head_size(b) bytes). */
static void put_head(const step_body *b, uint8_t *p)
{
    uint32_t name_length = (uint32_t)strlen(b->name);
    put(&p, &b->end, 4);
    put(&p, &name_length, 4);
    put(&p, &b->items, 8);
    put(&p, &b->chunk_count, 8);
    put(&p, b->counters, 8 * LMB_STEP_COUNTERS);
    put(&p, &b->size, 8);
    put(&p, b->name, name_length);
    for (uint64_t c = 0; c < b->chunk_count; c++) {
        put(&p, &b->chunks[c].first, 8);
        put(&p, &b->chunks[c].last, 8);
        put(&p, &b->chunks[c].size, 8);
    }
}

lmb_status lmb_step_body_write(const char *path, const lmb_part_identity *id, const lmb_part_place *place,
                               const step_body *b, lmb_error *err)
{
    size_t size = head_size(b);
    uint8_t *head = malloc(size + 1);
    if (!head)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory for '%s'", path);
    put_head(b, head);
    lmb_part_piece pieces[2] = {{head, size}, {b->bytes, b->size}};
    lmb_status st = lmb_part_write_pieces(path, id, place, pieces, 2, err);
    free(head);
    return st;
}

lmb_status lmb_step_body_decode(const char *path, const uint8_t *body, size_t size, step_body *b, lmb_error *err)
{
    memset(b, 0, sizeof *b);
    uint32_t name_length;
    if (size < BODY_HEADER)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: step body too short (%zu bytes)", path, size);
    const uint8_t *p = body;
    memcpy(&b->end, p, 4);
    memcpy(&name_length, p + 4, 4);
    memcpy(&b->items, p + 8, 8);
    memcpy(&b->chunk_count, p + 16, 8);
    memcpy(b->counters, p + 24, 8 * LMB_STEP_COUNTERS);
    memcpy(&b->size, p + 24 + 8 * LMB_STEP_COUNTERS, 8);
    size_t rest = size - BODY_HEADER;
    if (name_length >= sizeof b->name || name_length > rest || b->chunk_count > (rest - name_length) / 24 ||
        b->size != rest - name_length - 24 * b->chunk_count || b->end > 1)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: inconsistent step body", path);
    memcpy(b->name, p + BODY_HEADER, name_length);
    const uint8_t *table = p + BODY_HEADER + name_length;
    b->chunks = malloc((b->chunk_count + 1) * sizeof *b->chunks);
    if (!b->chunks)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
    uint64_t bytes = 0, next = 0;
    for (uint64_t c = 0; c < b->chunk_count; c++) {
        memcpy(&b->chunks[c].first, table + 24 * c, 8);
        memcpy(&b->chunks[c].last, table + 24 * c + 8, 8);
        memcpy(&b->chunks[c].size, table + 24 * c + 16, 8);
        const step_chunk *k = &b->chunks[c];
        if (k->first < next || k->first >= k->last || k->last > b->items || k->size > b->size - bytes) {
            free(b->chunks);
            b->chunks = NULL;
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: inconsistent step body (chunk %llu)", path,
                                 (unsigned long long)c);
        }
        next = k->last;
        bytes += k->size;
    }
    if (bytes != b->size) {
        free(b->chunks);
        b->chunks = NULL;
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: inconsistent step body (chunk sizes)", path);
    }
    b->bytes = table + 24 * b->chunk_count;
    return LMB_OK;
}

void lmb_step_part_path(const char *dir, uint32_t step, uint32_t shard, uint32_t shards, char *out, size_t n)
{
    snprintf(out, n, "%s/parts/%04u.%u-of-%u.part", dir, step, shard + 1, shards);
}

void lmb_step_state_path(const char *dir, uint32_t step, char *out, size_t n)
{
    snprintf(out, n, "%s/steps/%04u.state", dir, step);
}

/* The step's chunks: cuts[c] .. cuts[c + 1] for c < *count, cut at the item boundary nearest
 * to where the cost prefix reaches c / count of the total (doubles summed in item order: the same cuts on every machine).
 * cuts: malloc'd, count + 1 entries. */
uint64_t *lmb_step_chunk_cuts(const lmb_step_desc *d, uint32_t shards, uint64_t *count)
{
    uint64_t m = (uint64_t)shards * LMB_STEP_CHUNKS_PER_SHARD;
    m = m < d->items ? m : d->items;
    uint64_t *cuts = malloc((m + 1) * sizeof *cuts);
    if (!cuts)
        return NULL;
    *count = m;
    double total = 0, sum = 0;
    for (uint64_t i = 0; d->cost && i < d->items; i++)
        total += d->cost[i];
    uint64_t i = 0;
    cuts[0] = 0;
    for (uint64_t c = 1; c < m; c++) {
        if (!d->cost) {
            cuts[c] = d->items * c / m;
            continue;
        }
        double target = total * (double)c / (double)m;
        while (i < d->items && sum < target)
            sum += d->cost[i++];
        if (i > cuts[c - 1] + 1 && sum - target > target - (sum - d->cost[i - 1])) /* the nearer boundary */
            sum -= d->cost[--i];
        cuts[c] = i;
    }
    cuts[m] = d->items;
    return cuts;
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
lmb_status lmb_step_write_end_marker(const char *dir, uint32_t step, lmb_error *err)
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

/* Step `step`'s state: which parts were merged, by the SHA-256 that ends each part file
 * (u32 shards, u32 0, shards x 32 bytes). The parts hold the items; a state that copied them
 * would cost the merging worker a second write and hash of every step's bytes (0.6 s of
 * level-single-10's 16-shard critical path). */
static lmb_status write_state_file(const char *dir, const lmb_part_identity *id, uint32_t step, uint32_t shards,
                                   const lmb_part_view *views, lmb_error *err)
{
    size_t size = 8 + 32 * (size_t)shards;
    uint8_t *body = malloc(size);
    if (!body)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory for step %u's state", step);
    uint32_t head[2] = {shards, 0};
    memcpy(body, head, 8);
    for (uint32_t k = 0; k < shards; k++)
        memcpy(body + 8 + 32 * (size_t)k, views[k].sum, 32);
    char path[4400];
    lmb_step_state_path(dir, step, path, sizeof path);
    lmb_part_place place = {LMB_PART_STATE, step, 0, 1};
    lmb_status st = lmb_part_write(path, id, &place, body, size, err);
    free(body);
    return st;
}

lmb_status lmb_step_state_read(const char *dir, const lmb_part_identity *id, uint32_t step, uint32_t *shards,
                               uint8_t **sums, lmb_error *err)
{
    *shards = 0;
    *sums = NULL;
    char path[4400];
    lmb_step_state_path(dir, step, path, sizeof path);
    lmb_part_place want = {LMB_PART_STATE, step, 0, 1}, got;
    void *body = NULL;
    size_t size = 0;
    lmb_status st = lmb_part_read(path, id, &want, &got, &body, &size, err);
    if (st != LMB_OK)
        return st;
    uint32_t head[2] = {0, 0};
    if (size >= 8)
        memcpy(head, body, 8);
    if (size < 8 || head[0] == 0 || head[1] != 0 || size != 8 + 32 * (size_t)head[0]) {
        free(body);
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: inconsistent state (%zu bytes)", path, size);
    }
    *shards = head[0];
    memmove(body, (uint8_t *)body + 8, size - 8);
    *sums = body;
    return LMB_OK;
}

/* Merges the parts of step `step`: writes its state (write_state) and/or gives its bytes and
 * counters (out, counters; may be NULL). sums (shards x 32 bytes, or NULL): the parts must be
 * those a state lists. */
lmb_status lmb_step_merge_parts(const char *dir, const lmb_part_identity *id, uint32_t step, uint32_t shards,
                              int write_state, const uint8_t *sums, lmb_buf *out, uint64_t *counters,
                              lmb_merge_report *report, lmb_error *err)
{
    memset(report, 0, sizeof *report);
    uint32_t end = lmb_steps_end_step(dir);
    if (end != UINT32_MAX && step > end) {
        report->noop = 1;
        return LMB_OK;
    }
    char path[4400];
    lmb_part_view *views = calloc((size_t)shards + 1, sizeof *views);
    step_body *b = calloc((size_t)shards + 1, sizeof *b);
    lmb_status st = views && b ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory");
    uint64_t total = 0, chunk_total = 0;
    for (uint32_t k = 0; k < shards && st == LMB_OK; k++) {
        lmb_step_part_path(dir, step, k, shards, path, sizeof path);
        struct stat sb;
        if (stat(path, &sb) != 0) {
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: missing: shard %u of %u of step %u has not finished (rerun "
                               "it: 'lmbake step ... --step %u --shard %u/%u')", path, k + 1, shards, step, step, k + 1,
                               shards);
            break;
        }
        lmb_part_place want = {LMB_PART_SHARD, step, k, shards}, got;
        st = lmb_part_map(path, id, &want, &got, &views[k], err);
        if (st == LMB_OK && sums && memcmp(views[k].sum, sums + 32 * (size_t)k, 32))
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: not the part that step %u's state lists (another SHA-256): "
                               "written again since the merge? (merge the step again: 'lmbake merge ... --step %u')",
                               path, step, step);
        if (st == LMB_OK)
            st = lmb_step_body_decode(path, views[k].body, views[k].body_length, &b[k], err);
        if (st != LMB_OK)
            break;
        if (b[k].end != b[0].end || (!b[k].end && (b[k].items != b[0].items || strcmp(b[k].name, b[0].name))))
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: does not fit the other parts of step %u ('%s' of %llu items%s; "
                               "expected '%s' of %llu items)", path, step, b[k].name, (unsigned long long)b[k].items,
                               b[k].end ? ", the end" : "", b[0].name, (unsigned long long)b[0].items);
        total += b[k].size;
        chunk_total += b[k].chunk_count;
    }
    /* every shard's chunks in item order: they must tile the items exactly once */
    typedef struct placed {
        uint64_t first, last, size;
        const uint8_t *bytes;
        uint32_t shard;
    } placed;
    placed *all = st == LMB_OK ? malloc((chunk_total + 1) * sizeof *all) : NULL;
    if (st == LMB_OK && !all)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory for step %u's chunks", step);
    uint64_t count = 0;
    for (uint32_t k = 0; k < shards && st == LMB_OK; k++) {
        const uint8_t *p = b[k].bytes;
        for (uint64_t c = 0; c < b[k].chunk_count; c++) {
            uint64_t at = count++;
            while (at > 0 && all[at - 1].first > b[k].chunks[c].first) { /* insertion: parts come sorted */
                all[at] = all[at - 1];
                at--;
            }
            all[at] = (placed){b[k].chunks[c].first, b[k].chunks[c].last, b[k].chunks[c].size, p, k};
            p += b[k].chunks[c].size;
        }
    }
    uint64_t next = 0;
    for (uint64_t c = 0; c < count && st == LMB_OK; c++) {
        if (all[c].first != next) {
            lmb_step_part_path(dir, step, all[c].shard, shards, path, sizeof path);
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: does not fit the other parts of step %u (its items %llu-%llu; "
                               "expected the chunk from item %llu)", path, step, (unsigned long long)all[c].first,
                               (unsigned long long)all[c].last, (unsigned long long)next);
        }
        next = all[c].last;
    }
    if (st == LMB_OK && !b[0].end && next != b[0].items)
        st = lmb_error_set(err, LMB_ERR_INPUT, "step %u: the parts cover items 0-%llu of %llu", step,
                           (unsigned long long)next, (unsigned long long)b[0].items);
    step_body m;
    memset(&m, 0, sizeof m);
    uint8_t *bytes = st == LMB_OK ? lmb_big_alloc(total + 1) : NULL;
    if (st == LMB_OK && !bytes)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory for step %u (%llu bytes)", step,
                           (unsigned long long)total);
    step_chunk whole = {0, b ? b[0].items : 0, total};
    if (st == LMB_OK) {
        m.end = b[0].end;
        m.items = b[0].items;
        m.chunk_count = m.end || !m.items ? 0 : 1;
        m.chunks = &whole;
        snprintf(m.name, sizeof m.name, "%s", b[0].name);
        for (uint32_t k = 0; k < shards; k++)
            for (int c = 0; c < LMB_STEP_COUNTERS; c++)
                m.counters[c] += b[k].counters[c];
        for (uint64_t c = 0; c < count; c++) {
            if (all[c].size)
                memcpy(bytes + m.size, all[c].bytes, all[c].size);
            m.size += all[c].size;
        }
        m.bytes = bytes;
        if (write_state)
            st = write_state_file(dir, id, step, shards, views, err);
        if (st == LMB_OK && out) { /* the merged bytes become out's (no copy) */
            free(out->data);
            out->data = bytes;
            out->size = m.size;
            out->cap = total + 1;
            out->read = 0;
            bytes = NULL;
            memcpy(counters, m.counters, sizeof m.counters);
        }
    }
    free(all);
    if (st == LMB_OK && m.end) /* the marker steps past the end look at */
        st = lmb_step_write_end_marker(dir, step, err);
    if (st == LMB_OK) {
        report->end = m.end;
        report->items = m.items;
        snprintf(report->name, sizeof report->name, "%s", m.name);
    }
    free(bytes);
    for (uint32_t k = 0; views && b && k < shards; k++) {
        lmb_part_unmap(&views[k]);
        free(b[k].chunks);
    }
    free(views);
    free(b);
    return st;
}

lmb_status lmb_steps_merge(const char *dir, const lmb_part_identity *id, uint32_t step, uint32_t shards,
                           lmb_merge_report *report, lmb_error *err)
{
    return lmb_step_merge_parts(dir, id, step, shards, 1, NULL, NULL, NULL, report, err);
}

