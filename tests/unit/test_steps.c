/*
 * The farm's step runner (baker/steps/runner.h) on a synthetic step of 1,000 items whose cost
 * grows with the index (item i costs i + 1): each of 4 shards computes LMB_STEP_CHUNKS_PER_SHARD (32) chunks spread over
 * the step (chunk c to shard c mod 4), the shards' chunks tile [0, 1000) exactly once, and each
 * shard's cost is within 1.5% of a quarter of the total (chunks cut by cost, not by count); the merged
 * state reads back (finish mode) as the items in order with the counters summed, and is refused,
 * naming the part, when a part it lists was written again with other results or is gone; a shard run
 * twice writes the same bytes; a step under min_rays runs in every process and is no farm step;
 * a merge over a missing part or a part of another config is refused, naming it; a worker
 * whose step 0 is another step than the farm folder's refuses, naming both. Streamed
 * (lmb_steps_run_streamed): a local step is computed 64 items at a time and taken in order,
 * the same bytes and counters as whole; in finish mode it is read and taken at once; the float
 * sink fills arrays of 4, 0 and 6 floats across chunk borders and refuses a float too many.
 * usage: test_steps WORKDIR
 */
#define _GNU_SOURCE
#include "check.h"
#include "steps/runner.h"
#include "steps/step_parts.h"

#include <lmbake/lmbake.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define ITEMS 1000
#define SHARDS 4

typedef struct fake {
    uint64_t first, last, calls, items;
    double cost;
    const double *costs;
    int *hits; /* per item: how many times computed */
    uint32_t offset; /* item i's bytes are i + offset (another run's results) */
} fake;

/* Item i's bytes: its index (u32); counter 0 counts items, counter 1 sums the indices. */
static lmb_status compute(void *user, uint64_t first, uint64_t last, lmb_buf *out, uint64_t counters[LMB_STEP_COUNTERS],
                          lmb_error *err)
{
    fake *f = user;
    f->first = first;
    f->last = last;
    f->calls++;
    f->items += last - first;
    for (uint64_t i = first; f->costs && i < last; i++) {
        f->cost += f->costs[i];
        f->hits[i]++;
    }
    for (uint64_t i = first; i < last; i++) {
        uint32_t v = (uint32_t)i + f->offset;
        lmb_status st = lmb_buf_append(out, &v, 4, err);
        if (st != LMB_OK)
            return st;
        counters[0]++;
        counters[1] += i;
    }
    return LMB_OK;
}

/* A take function: appends what it is given to a buffer and counts its calls. */
typedef struct collected {
    lmb_buf all;
    uint32_t calls;
} collected;

static lmb_status collect(void *user, lmb_buf *bytes, lmb_error *err)
{
    collected *c = user;
    c->calls++;
    lmb_status st = lmb_buf_append(&c->all, bytes->data + bytes->read, bytes->size - bytes->read, err);
    bytes->read = bytes->size;
    return st;
}

/* Local streaming and the float sink. */
static void test_streamed(void)
{
    lmb_error err;
    lmb_steps *s;
    CHECK_INT(lmb_steps_create(LMB_STEPS_LOCAL, NULL, NULL, 0, 0, 1, 100.0, NULL, &s, &err), LMB_OK);
    fake f = {0, 0, 0, 0, 0, NULL, NULL, 0};
    lmb_step_desc d = {"streamed", ITEMS, NULL, 1e9, compute, &f};
    collected c = {{0}, 0};
    uint64_t counters[LMB_STEP_COUNTERS];
    CHECK_INT(lmb_steps_run_streamed(s, &d, 64, collect, &c, counters, &err), LMB_OK);
    CHECK_INT(c.calls, (ITEMS + 63) / 64);
    CHECK_INT(f.calls, (ITEMS + 63) / 64);
    CHECK_INT(lmb_steps_count(s), 1);
    CHECK_INT(c.all.size, 4 * ITEMS);
    int in_order = 1;
    for (uint32_t i = 0; i < ITEMS && c.all.size == 4 * ITEMS; i++) {
        uint32_t v;
        memcpy(&v, c.all.data + 4 * i, 4);
        in_order &= v == i;
    }
    CHECK(in_order);
    CHECK_INT(counters[0], ITEMS);
    CHECK_INT(counters[1], ITEMS * (ITEMS - 1) / 2);
    lmb_buf_free(&c.all);

    /* floats: items 0..9 as floats into arrays of 4, 0 and 6, three items a chunk */
    float a[4], b[1], e[6];
    float *dst[3] = {a, b, e};
    uint64_t floats[3] = {4, 0, 6};
    lmb_float_sink sink = {3, dst, floats, 0, 0};
    lmb_buf chunk = {0};
    int filled = 1;
    for (uint32_t i = 0; i < 10; i += 3) {
        chunk.size = chunk.read = 0;
        for (uint32_t k = i; k < i + 3 && k < 10; k++) {
            float v = (float)k;
            lmb_buf_append(&chunk, &v, 4, &err);
        }
        CHECK_INT(lmb_take_floats(&sink, &chunk, &err), LMB_OK);
        CHECK_INT(chunk.read, chunk.size);
    }
    CHECK(lmb_float_sink_full(&sink));
    for (int k = 0; k < 4; k++)
        filled &= a[k] == (float)k;
    for (int k = 0; k < 6; k++)
        filled &= e[k] == (float)(4 + k);
    CHECK(filled);
    chunk.size = chunk.read = 0;
    float extra = 1;
    lmb_buf_append(&chunk, &extra, 4, &err);
    CHECK_INT(lmb_take_floats(&sink, &chunk, &err), LMB_ERR_INPUT);
    CHECK(strstr(err.message, "more than the texels hold") != NULL);
    lmb_float_sink short_sink = {3, dst, floats, 0, 0};
    chunk.size = chunk.read = 0;
    lmb_buf_append(&chunk, &extra, 4, &err);
    CHECK_INT(lmb_take_floats(&short_sink, &chunk, &err), LMB_OK);
    CHECK(!lmb_float_sink_full(&short_sink));
    lmb_buf_free(&chunk);
    lmb_steps_free(s);
}

static lmb_part_identity identity(const char *config_text)
{
    lmb_part_identity id;
    memset(&id, 0, sizeof id);
    snprintf(id.version, sizeof id.version, "%s", LMB_VERSION_STRING);
    id.config_text = strdup(config_text);
    lmb_sha256(config_text, strlen(config_text), id.config);
    return id;
}

static char *read_all(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    *n = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    char *d = malloc(*n + 1);
    if (d && fread(d, 1, *n, f) != *n) {
        free(d);
        d = NULL;
    }
    fclose(f);
    return d;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_steps WORKDIR\n");
        return 2;
    }
    const char *dir = argv[1];
    lmb_error err;
    char farm[4096], other[4096], path[4400], path2[4400];
    snprintf(farm, sizeof farm, "%s/farm", dir);
    snprintf(other, sizeof other, "%s/other", dir);
    mkdir(dir, 0777);
    CHECK_INT(lmb_steps_make_dirs(farm, &err), LMB_OK);
    CHECK_INT(lmb_steps_make_dirs(other, &err), LMB_OK);
    double cost[ITEMS], total = 0;
    for (int i = 0; i < ITEMS; i++) {
        cost[i] = i + 1;
        total += cost[i];
    }
    lmb_part_identity id = identity("samples.gather: 64\n"), id_other = identity("samples.gather: 128\n");
    lmb_step_desc small = {"small", 10, NULL, 10.0, compute, NULL};
    static int hits[ITEMS];
    for (int k = 0; k < SHARDS; k++) {
        lmb_steps *s;
        CHECK_INT(lmb_steps_create(LMB_STEPS_SHARD, farm, &id, 0, (uint32_t)k, SHARDS, 100.0, NULL, &s, &err), LMB_OK);
        fake f = {0, 0, 0, 0, 0, cost, hits, 0}, fs = {0, 0, 0, 0, 0, NULL, NULL, 0};
        lmb_buf out = {0};
        uint64_t counters[LMB_STEP_COUNTERS];
        /* under min_rays: computed here, whole, and not counted as a step */
        small.user = &fs;
        CHECK_INT(lmb_steps_run(s, &small, &out, counters, &err), LMB_OK);
        CHECK_INT(fs.calls, 1);
        CHECK_INT(fs.last - fs.first, 10);
        CHECK_INT(lmb_steps_count(s), 0);
        lmb_step_desc d = {"skewed", ITEMS, cost, 1e9, compute, &f};
        CHECK_INT(lmb_steps_run(s, &d, &out, counters, &err), LMB_STEP_STOPPED);
        printf("shard %d: %llu items in %llu chunks, cost %.0f of %.0f (quarter %.0f)\n", k + 1,
               (unsigned long long)f.items, (unsigned long long)f.calls, f.cost, total, total / SHARDS);
        CHECK_INT(f.calls, LMB_STEP_CHUNKS_PER_SHARD);
        CHECK(fabs(f.cost - total / SHARDS) <= 0.015 * total / SHARDS);
        lmb_buf_free(&out);
        lmb_steps_free(s);
    }
    for (int i = 0; i < ITEMS; i++)
        CHECK_INT(hits[i], 1);

    /* shard 2 again: the same bytes */
    snprintf(path, sizeof path, "%s/parts/0000.2-of-4.part", farm);
    size_t n1 = 0, n2 = 0;
    char *first = read_all(path, &n1);
    {
        lmb_steps *s;
        CHECK_INT(lmb_steps_create(LMB_STEPS_SHARD, farm, &id, 0, 1, SHARDS, 100.0, NULL, &s, &err), LMB_OK);
        fake f = {0, 0, 0, 0, 0, NULL, NULL, 0};
        lmb_buf out = {0};
        uint64_t counters[LMB_STEP_COUNTERS];
        lmb_step_desc d = {"skewed", ITEMS, cost, 1e9, compute, &f};
        CHECK_INT(lmb_steps_run(s, &d, &out, counters, &err), LMB_STEP_STOPPED);
        lmb_buf_free(&out);
        lmb_steps_free(s);
    }
    char *second = read_all(path, &n2);
    CHECK(first && second && n1 == n2 && memcmp(first, second, n1) == 0);
    free(first);
    free(second);

    /* a part of another config in the farm: refused, naming the part and the key */
    {
        lmb_steps *s;
        CHECK_INT(lmb_steps_create(LMB_STEPS_SHARD, other, &id_other, 0, 2, SHARDS, 100.0, NULL, &s, &err), LMB_OK);
        fake f = {0, 0, 0, 0, 0, NULL, NULL, 0};
        lmb_buf out = {0};
        uint64_t counters[LMB_STEP_COUNTERS];
        lmb_step_desc d = {"skewed", ITEMS, cost, 1e9, compute, &f};
        CHECK_INT(lmb_steps_run(s, &d, &out, counters, &err), LMB_STEP_STOPPED);
        lmb_buf_free(&out);
        lmb_steps_free(s);
        snprintf(path, sizeof path, "%s/parts/0000.3-of-4.part", farm);
        snprintf(path2, sizeof path2, "%s/parts/0000.3-of-4.part", other);
        size_t n = 0;
        char *mine = read_all(path, &n), *theirs = read_all(path2, &n2);
        FILE *f3 = fopen(path, "wb");
        fwrite(theirs, 1, n2, f3);
        fclose(f3);
        lmb_merge_report r;
        CHECK_INT(lmb_steps_merge(farm, &id, 0, SHARDS, &r, &err), LMB_ERR_INPUT);
        printf("refused: %s\n", err.message);
        CHECK(strstr(err.message, "0000.3-of-4.part") && strstr(err.message, "samples.gather"));
        f3 = fopen(path, "wb"); /* back */
        fwrite(mine, 1, n, f3);
        fclose(f3);
        free(mine);
        free(theirs);
    }

    /* a missing part: the shard to rerun named */
    snprintf(path, sizeof path, "%s/parts/0000.4-of-4.part", farm);
    snprintf(path2, sizeof path2, "%s/parts/saved", farm);
    CHECK(rename(path, path2) == 0);
    lmb_merge_report r;
    CHECK_INT(lmb_steps_merge(farm, &id, 0, SHARDS, &r, &err), LMB_ERR_INPUT);
    printf("refused: %s\n", err.message);
    CHECK(strstr(err.message, "--shard 4/4") != NULL);
    CHECK(rename(path2, path) == 0);

    /* the merge, read back in finish mode: the items in order, counters summed */
    CHECK_INT(lmb_steps_merge(farm, &id, 0, SHARDS, &r, &err), LMB_OK);
    CHECK_INT(r.items, ITEMS);
    CHECK(!r.end);
    {
        lmb_steps *s;
        CHECK_INT(lmb_steps_create(LMB_STEPS_FINISH, farm, &id, 0, 0, 1, 100.0, NULL, &s, &err), LMB_OK);
        fake f = {0, 0, 0, 0, 0, NULL, NULL, 0};
        lmb_buf out = {0};
        uint64_t counters[LMB_STEP_COUNTERS];
        lmb_step_desc d = {"skewed", ITEMS, cost, 1e9, compute, &f};
        CHECK_INT(lmb_steps_run(s, &d, &out, counters, &err), LMB_OK);
        CHECK_INT(f.calls, 0); /* read, not computed */
        CHECK_INT(out.size, 4 * ITEMS);
        int in_order = 1;
        for (uint32_t i = 0; i < ITEMS && out.size == 4 * ITEMS; i++) {
            uint32_t v;
            memcpy(&v, out.data + 4 * i, 4);
            in_order &= v == i;
        }
        CHECK(in_order);
        CHECK_INT(counters[0], ITEMS);
        CHECK_INT(counters[1], ITEMS * (ITEMS - 1) / 2);
        lmb_steps_free(s);
        /* streamed in finish mode: read, and taken at once */
        CHECK_INT(lmb_steps_create(LMB_STEPS_FINISH, farm, &id, 0, 0, 1, 100.0, NULL, &s, &err), LMB_OK);
        collected c = {{0}, 0};
        CHECK_INT(lmb_steps_run_streamed(s, &d, 64, collect, &c, counters, &err), LMB_OK);
        CHECK_INT(f.calls, 0);
        CHECK_INT(c.calls, 1);
        CHECK(c.all.size == out.size && memcmp(c.all.data, out.data, out.size) == 0);
        lmb_buf_free(&c.all);
        /* the state lists its parts by their SHA-256: part 2 written again with other results
         * after the merge, or part 3 gone, and the step is refused, the part named */
        lmb_steps *shard2;
        CHECK_INT(lmb_steps_create(LMB_STEPS_SHARD, farm, &id, 0, 1, SHARDS, 100.0, NULL, &shard2, &err), LMB_OK);
        fake other = {0, 0, 0, 0, 0, NULL, NULL, 7};
        lmb_step_desc d_other = {"skewed", ITEMS, cost, 1e9, compute, &other};
        lmb_buf scratch = {0};
        CHECK_INT(lmb_steps_run(shard2, &d_other, &scratch, counters, &err), LMB_STEP_STOPPED);
        lmb_steps_free(shard2);
        lmb_steps *again;
        CHECK_INT(lmb_steps_create(LMB_STEPS_FINISH, farm, &id, 0, 0, 1, 100.0, NULL, &again, &err), LMB_OK);
        CHECK_INT(lmb_steps_run(again, &d, &scratch, counters, &err), LMB_ERR_INPUT);
        printf("refused: %s\n", err.message);
        CHECK(strstr(err.message, "0000.2-of-4.part") && strstr(err.message, "state lists"));
        lmb_steps_free(again);
        CHECK_INT(lmb_steps_create(LMB_STEPS_SHARD, farm, &id, 0, 1, SHARDS, 100.0, NULL, &shard2, &err), LMB_OK);
        fake same = {0, 0, 0, 0, 0, NULL, NULL, 0};
        lmb_step_desc d_same = {"skewed", ITEMS, cost, 1e9, compute, &same};
        CHECK_INT(lmb_steps_run(shard2, &d_same, &scratch, counters, &err), LMB_STEP_STOPPED); /* the same bytes */
        lmb_steps_free(shard2);
        snprintf(path, sizeof path, "%s/parts/0000.3-of-4.part", farm);
        snprintf(path2, sizeof path2, "%s/parts/saved", farm);
        CHECK(rename(path, path2) == 0);
        CHECK_INT(lmb_steps_create(LMB_STEPS_FINISH, farm, &id, 0, 0, 1, 100.0, NULL, &again, &err), LMB_OK);
        CHECK_INT(lmb_steps_run(again, &d, &scratch, counters, &err), LMB_ERR_INPUT);
        printf("refused: %s\n", err.message);
        CHECK(strstr(err.message, "--shard 3/4") != NULL);
        lmb_steps_free(again);
        CHECK(rename(path2, path) == 0);
        CHECK_INT(lmb_steps_create(LMB_STEPS_FINISH, farm, &id, 0, 0, 1, 100.0, NULL, &again, &err), LMB_OK);
        CHECK_INT(lmb_steps_run(again, &d, &scratch, counters, &err), LMB_OK);
        CHECK(scratch.size == out.size && memcmp(scratch.data, out.data, out.size) == 0);
        lmb_steps_free(again);
        lmb_buf_free(&scratch);
        /* the next step is not merged: refused, named */
        lmb_step_desc d2 = {"next", 5, NULL, 1e9, compute, &f};
        CHECK_INT(lmb_steps_run(s, &d2, &out, counters, &err), LMB_ERR_INPUT);
        CHECK(strstr(err.message, "has not been merged") != NULL);
        lmb_buf_free(&out);
        lmb_steps_free(s);
        /* a farm folder whose step 0 is another step (an older lmbake's step list): a worker
         * refuses, naming both steps, and computes and merges nothing */
        lmb_steps_worker w = {SHARDS, 0, 2, 0};
        CHECK_INT(lmb_steps_create_worker(farm, &id, &w, 100.0, NULL, &s, &err), LMB_OK);
        lmb_step_desc d3 = {"texels served", ITEMS, NULL, 1e9, compute, &f};
        CHECK_INT(lmb_steps_run(s, &d3, &out, counters, &err), LMB_ERR_INPUT);
        printf("refused: %s\n", err.message);
        CHECK(strstr(err.message, "'skewed'") && strstr(err.message, "'texels served'"));
        CHECK_INT(f.calls, 0);
        lmb_buf_free(&out);
        lmb_steps_free(s);
    }
    lmb_part_identity_free(&id);
    lmb_part_identity_free(&id_other);
    test_streamed();
    printf("%s\n", check_failed_count ? "FAILED" : "ok");
    return check_failed_count != 0;
}
