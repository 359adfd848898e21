/* The denoiser's levels as steps of the bake, written back as they come (denoise_steps.h). */
#include "denoise_steps.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct denoise_job {
    const lmb_denoise_part *atlases;
    uint32_t count;
    lmb_denoiser **dn;  /* per atlas; NULL: not filtered */
    uint64_t *first;    /* per atlas (+1): its first item */
    uint32_t level;
    int threads;
    lmb_buf pending;    /* results of items [written, taken) not written back yet */
    uint64_t written, taken;
} denoise_job;

static lmb_status denoise_range(void *user, uint64_t first, uint64_t last, lmb_buf *out,
                                uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    (void)counters;
    const denoise_job *j = user;
    lmb_status st = LMB_OK;
    for (uint32_t a = 0; a < j->count && st == LMB_OK; a++) {
        uint64_t lo = first > j->first[a] ? first : j->first[a], hi = last < j->first[a + 1] ? last : j->first[a + 1];
        if (!j->dn[a] || lo >= hi)
            continue;
        size_t n = 3 * (size_t)(hi - lo);
        float *o = lmb_buf_extend(out, n * sizeof *o, err); /* filtered straight into the step's bytes */
        if (!o)
            return LMB_ERR_INTERNAL;
        st = lmb_denoiser_level(j->dn[a], j->level, j->atlases[a].light, (uint32_t)(lo - j->first[a]),
                                (uint32_t)(hi - j->first[a]), o, j->threads, err);
    }
    return st;
}

/* Item k's atlas (an atlas with no items is skipped: j->first is ascending). */
static uint32_t item_atlas(const denoise_job *j, uint64_t k)
{
    uint32_t a = 0;
    while (a + 1 < j->count && j->first[a + 1] <= k)
        a++;
    return a;
}

/* Whether item k's result may be written back while items from `next` on are still to be
 * filtered: another atlas's, or rows beyond the taps' reach. */
static int may_write_back(const denoise_job *j, uint64_t k, uint64_t next)
{
    if (next >= j->first[j->count])
        return 1;
    uint32_t a = item_atlas(j, k), b = item_atlas(j, next);
    if (a != b)
        return 1;
    const lmb_texels *t = j->atlases[a].t;
    if (!lmb_denoiser_in_order(j->dn[a]))
        return 0;
    uint32_t row = t->texel[k - j->first[a]] / t->width, next_row = t->texel[next - j->first[a]] / t->width;
    return (uint64_t)row + lmb_denoiser_reach(j->level) < next_row;
}

/* The level's results as they come (lmb_steps_run_streamed): kept, and written back as far as
 * may_write_back allows. */
static lmb_status denoise_take(void *user, lmb_buf *bytes, lmb_error *err)
{
    denoise_job *j = user;
    size_t n = bytes->size - bytes->read;
    if (n % (3 * sizeof(float)))
        return lmb_error_set(err, LMB_ERR_INPUT, "denoise: %zu bytes are not whole texels", n);
    lmb_status st = lmb_buf_append(&j->pending, bytes->data + bytes->read, n, err);
    bytes->read = bytes->size;
    j->taken += n / (3 * sizeof(float));
    if (j->taken > j->first[j->count])
        return lmb_error_set(err, LMB_ERR_INPUT, "denoise: the step gave more texels than it has");
    uint64_t done = j->written;
    while (st == LMB_OK && done < j->taken && may_write_back(j, done, j->taken))
        done++;
    for (uint64_t k = j->written; k < done;) { /* atlas by atlas */
        uint32_t a = item_atlas(j, k);
        uint64_t end = done < j->first[a + 1] ? done : j->first[a + 1];
        memcpy(j->atlases[a].light + 3 * (k - j->first[a]), j->pending.data + 3 * sizeof(float) * (k - j->written),
               3 * sizeof(float) * (end - k));
        k = end;
    }
    size_t used = 3 * sizeof(float) * (done - j->written);
    memmove(j->pending.data, j->pending.data + used, j->pending.size - used);
    j->pending.size -= used;
    j->written = done;
    return st;
}

lmb_status lmb_denoise_steps(lmb_steps *steps, const lmb_denoise_part *atlases, uint32_t atlas_count,
                             const lmb_denoise_run *run, lmb_denoise_stats *stats, lmb_error *err)
{
    denoise_job j = {atlases, atlas_count, calloc((size_t)atlas_count + 1, sizeof(lmb_denoiser *)),
                     calloc((size_t)atlas_count + 2, sizeof(uint64_t)), 0, run->threads, {0}, 0, 0};
    lmb_status st = j.dn && j.first ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "denoise: out of memory");
    for (uint32_t a = 0; a < atlas_count && st == LMB_OK; a++) {
        const lmb_denoise_part *x = &atlases[a];
        j.first[a + 1] = j.first[a];
        if (!x->variance && !(x->noise > 0))
            continue;
        lmb_denoise_options opt = {run->levels, x->noise, x->variance, run->strength, run->threads};
        st = lmb_denoiser_create(x->t, &opt, &j.dn[a], err);
        j.first[a + 1] += x->t->count;
        if (st == LMB_OK)
            lmb_denoise_measure(x->t, x->light, &stats->before, &stats->texels);
    }
    for (uint32_t level = 0; level < run->levels && st == LMB_OK && j.first[atlas_count] > 0; level++) {
        char name[96];
        snprintf(name, sizeof name, "denoise %s, level %u", run->what, level + 1);
        j.level = level;
        j.written = j.taken = 0;
        lmb_step_desc d = {name, j.first[atlas_count], NULL, LMB_DENOISE_RAYS_PER_TEXEL * (double)j.first[atlas_count],
                           denoise_range, &j};
        uint64_t counters[LMB_STEP_COUNTERS];
        st = lmb_steps_run_streamed(steps, &d, LMB_STEP_STREAM_ITEMS, denoise_take, &j, counters, err);
        if (st == LMB_OK && j.written != j.first[atlas_count])
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "denoise: step '%s' gave %llu of %llu texels", name,
                               (unsigned long long)j.taken, (unsigned long long)j.first[atlas_count]);
    }
    lmb_buf_free(&j.pending);
    for (uint32_t a = 0; a < atlas_count && st == LMB_OK; a++)
        if (j.dn[a])
            lmb_denoise_measure(atlases[a].t, atlases[a].light, &stats->after, NULL);
    for (uint32_t a = 0; j.dn && a < atlas_count; a++)
        lmb_denoiser_free(j.dn[a]);
    free(j.dn);
    free(j.first);
    return st;
}
