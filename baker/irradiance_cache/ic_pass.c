/* A gather pass through the irradiance cache: placement, gradients, interpolation (ic_pass.h). */
#include "ic_pass.h"
#include "ic_pass_internal.h"

#include "steps/runner.h"
#include "gather/guide.h"
#include "irradiance_cache/records.h"
#include "util/frame.h"

#include <math.h>
#include <omp.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Rounds of placement at most; see lmb_ic_gather_pass. */
#define LMB_IC_ROUNDS 4




texel_at lmb_ic_texel_at(const pass_ctx *c, uint32_t id)
{
    uint32_t lo = 0, hi = c->atlas_count; /* the last atlas whose first id is <= id */
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (c->first_id[mid] <= id)
            lo = mid;
        else
            hi = mid;
    }
    return (texel_at){lo, id - c->first_id[lo]};
}

void lmb_ic_texel_point(const pass_ctx *c, texel_at x, double p[3], double n[3])
{
    lmb_shading_point sp;
    const lmb_texels *t = c->t[x.atlas];
    lmb_texel_shading_point(c->job->direct, t, x.index, t->gather_at[x.index], &sp);
    memcpy(p, sp.p, 3 * sizeof *p);
    memcpy(n, sp.n, 3 * sizeof *n);
}

void lmb_ic_report(pass_ctx *c, uint64_t done_in_level, uint64_t level_total)
{
    const lmb_gather_job *job = c->job;
    if (!job->progress)
        return;
    uint64_t total = c->valid_total * (c->levels + 1);
    uint64_t done = c->valid_total * c->level + (level_total ? done_in_level * c->valid_total / level_total : 0);
    done = done < total ? done : total - (total > 0);
    if (done < c->reported)
        done = c->reported;
    c->reported = done;
    job->progress(job->progress_user, c->stage, done, total);
}

/* Valid texels on this level's grid that are not records yet, in (atlas, texel) order. One pass
 * into room for every texel, shrunk after (the grid's spacing is a power of 2: a mask, not a
 * division): it runs twice per level in every process of a farm, 0.07 -> 0.02 s a call on
 * level-single-10's 625k texels. */
static lmb_status level_candidates(const pass_ctx *c, uint32_t spacing, uint32_t **out, uint64_t *count, lmb_error *err)
{
    uint64_t total = 0, n = 0;
    for (uint32_t a = 0; a < c->atlas_count; a++)
        total += c->t[a]->count;
    uint32_t *cand = malloc((size_t)(total + 1) * sizeof *cand);
    if (!cand)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %llu candidates",
                             (unsigned long long)total);
    const uint32_t mask = spacing - 1; /* spacing: 1, 2, 4, ... */
    for (uint32_t a = 0; a < c->atlas_count; a++) {
        const lmb_texels *t = c->t[a];
        const uint8_t *record = c->is_record[a], *own = c->own ? c->own[a] : NULL;
        for (uint32_t i = 0; i < t->count; i++) {
            if (!t->valid[i] || record[i] || (own && own[i]))
                continue;
            uint32_t x = t->texel[i] % t->width, y = t->texel[i] / t->width;
            if ((x | y) & mask)
                continue;
            cand[n++] = c->first_id[a] + i;
        }
    }
    uint32_t *shrunk = realloc(cand, (size_t)(n + 1) * sizeof *cand);
    *out = shrunk ? shrunk : cand;
    *count = n;
    return LMB_OK;
}

/* The items of a per-texel step (texels served, interpolation): every atlas's listed texels in
 * order; first[a] is atlas a's first item (atlas_count + 1 entries, malloc'd). */
typedef struct texel_items {
    const pass_ctx *c;
    uint64_t *first;
} texel_items;

static lmb_status texel_items_make(const pass_ctx *c, texel_items *ti, lmb_error *err)
{
    ti->c = c;
    ti->first = calloc((size_t)c->atlas_count + 2, sizeof *ti->first);
    if (!ti->first)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory");
    for (uint32_t a = 0; a < c->atlas_count; a++)
        ti->first[a + 1] = ti->first[a] + c->t[a]->count;
    return LMB_OK;
}

/* Atlas a's texels [*i0, *i1) among items [first, last); 0 when it holds none of them. */
static int texel_items_span(const texel_items *ti, uint32_t a, uint64_t first, uint64_t last, uint32_t *i0,
                            uint32_t *i1)
{
    uint64_t a0 = ti->first[a], a1 = ti->first[a + 1];
    if (a1 <= first || a0 >= last)
        return 0;
    *i0 = (uint32_t)((first > a0 ? first : a0) - a0);
    *i1 = (uint32_t)((last < a1 ? last : a1) - a0);
    return 1;
}

/* records.serves: how many texels each record serves, from its shares of every valid texel's
 * interpolation (lmb_ic_add_shares), rounded up and kept within [1, ray_scale]. A record that
 * gathers ray_scale x a texel's rays for fewer texels than that costs more than gathering at
 * those texels would: records crowd where charts are small or normals turn (instanced props
 * of a few hundred texels each), and there a record serves one or two texels. Positions and
 * reaches fixed, the shares are too: counted by the first pass that gathers again and kept
 * with the records. A step (two lookups per texel: 1.7 s of a 95 s bake of level-single-10
 * at one thread, too much for every farm process to repeat): items are every atlas's listed
 * texels in order; a call's bytes are the shares it added, u32 n then n x (u32 record, u64
 * share), records ascending. The shares are integers: their sum is the same however the
 * texels are split, at any thread count. */
static lmb_status served_range(void *user, uint64_t first, uint64_t last, lmb_buf *out,
                               uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    const texel_items *ti = user;
    const pass_ctx *c = ti->c;
    (void)counters;
    uint32_t m = c->records.count;
    uint64_t *share = calloc((size_t)m + 1, sizeof *share);
    if (!share)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %u records", m);
    for (uint32_t a = 0; a < c->atlas_count; a++) {
        const lmb_texels *t = c->t[a];
        uint32_t i0, i1;
        if (!texel_items_span(ti, a, first, last, &i0, &i1))
            continue;
#pragma omp parallel for num_threads(c->threads) schedule(dynamic, 1024)
        for (uint32_t i = i0; i < i1; i++) {
            double p[3], n[3];
            if (!t->valid[i] || lmb_ic_is_own(c, a, i))
                continue;
            lmb_ic_texel_point(c, (texel_at){a, i}, p, n);
            lmb_ic_add_shares(&c->records, p, n, share);
        }
    }
    uint32_t n = 0;
    for (uint32_t k = 0; k < m; k++)
        n += share[k] != 0;
    uint8_t *p = lmb_buf_extend(out, 4 + 12 * (size_t)n, err);
    if (p) {
        memcpy(p, &n, 4), p += 4;
        for (uint32_t k = 0; k < m; k++)
            if (share[k]) {
                memcpy(p, &k, 4);
                memcpy(p + 4, &share[k], 8);
                p += 12;
            }
    }
    free(share);
    return p ? LMB_OK : LMB_ERR_INTERNAL;
}

typedef struct served_sum {
    uint64_t *share;
    uint32_t records;
} served_sum;

static lmb_status take_served(void *user, lmb_buf *bytes, lmb_error *err)
{
    served_sum *sum = user;
    uint32_t n, k;
    uint64_t v;
    while (bytes->read < bytes->size) {
        if (!lmb_buf_take(bytes, &n, 4))
            return lmb_error_set(err, LMB_ERR_INPUT, "texels served: a truncated block");
        for (uint32_t j = 0; j < n; j++) {
            if (!lmb_buf_take(bytes, &k, 4) || !lmb_buf_take(bytes, &v, 8) || k >= sum->records)
                return lmb_error_set(err, LMB_ERR_INPUT, "texels served: a truncated block or a record out of range");
            sum->share[k] += v;
        }
    }
    return LMB_OK;
}

static lmb_status count_served(pass_ctx *c, lmb_error *err)
{
    uint32_t m = c->records.count, scale = c->opt->ray_scale;
    if (scale <= 1 || !m || c->records.serves)
        return LMB_OK;
    texel_items ti;
    lmb_status st = texel_items_make(c, &ti, err);
    if (st != LMB_OK)
        return st;
    served_sum sum = {calloc(m, sizeof(uint64_t)), m};
    uint32_t *serves = malloc((size_t)m * sizeof *serves);
    if (!sum.share || !serves) {
        free(ti.first);
        free(sum.share);
        free(serves);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %u records", m);
    }
    char name[160];
    snprintf(name, sizeof name, "%s: texels served", c->stage);
    /* rays: an interpolation and a second walk per texel; counted as 16 rays per texel */
    lmb_step_desc d = {name, ti.first[c->atlas_count], NULL, 16.0 * (double)ti.first[c->atlas_count], served_range,
                       &ti};
    uint64_t counters[LMB_STEP_COUNTERS];
    st = lmb_steps_run_streamed(c->job->steps, &d, LMB_STEP_STREAM_ITEMS, take_served, &sum, counters, err);
    for (uint32_t k = 0; k < m && st == LMB_OK; k++) {
        uint64_t texels = (sum.share[k] + LMB_IC_SHARE_ONE - 1) / LMB_IC_SHARE_ONE;
        serves[k] = texels < 1 ? 1 : texels > scale ? scale : (uint32_t)texels;
    }
    free(ti.first);
    free(sum.share);
    if (st != LMB_OK) {
        free(serves);
        return st;
    }
    c->records.serves = serves;
    return LMB_OK;
}

/* The records of an earlier pass, gathered again with this pass's light, group by group in
 * placement order (guided gathering reads earlier groups' mixtures); a record that serves
 * fewer texels than ray_scale gathers that many texels' rays (count_served). */
static lmb_status regather(pass_ctx *c, lmb_gather_stats *stats, lmb_error *err)
{
    uint32_t m = c->records.count, groups = 0;
    uint32_t *at = malloc(((size_t)m + 1) * sizeof *at);
    uint32_t *slots = malloc(((size_t)m + 1) * sizeof *slots);
    if (!at || !slots) {
        free(at);
        free(slots);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %u records", m);
    }
    for (uint32_t k = 0; k < m; k++) {
        c->is_record[c->records.rec[k].atlas][c->records.rec[k].texel] = 1;
        groups = c->records.rec[k].group + 1 > groups ? c->records.rec[k].group + 1 : groups;
    }
    c->level = c->levels - 1;
    lmb_status st = count_served(c, err);
    uint64_t done = 0;
    /* unguided, a record's gather reads no other record: all groups in one step */
    uint32_t step_groups = c->guided ? groups : 1;
    for (uint32_t g = 0; g < step_groups && st == LMB_OK; g++) {
        uint32_t n = 0;
        for (uint32_t k = 0; k < m; k++)
            if (!c->guided || c->records.rec[k].group == g) {
                slots[n] = k;
                at[n++] = lmb_ic_texel_id(c, (texel_at){c->records.rec[k].atlas, c->records.rec[k].texel});
            }
        c->regather_group = g;
        if (n)
            st = lmb_ic_gather_records(c, at, n, slots, 0, NULL, NULL, done, m, stats, err);
        done += n;
    }
    free(at);
    free(slots);
    return st;
}

/*
 * A later round's candidates at one level: keeps, in order, those the records leave uncovered
 * now. Records are only added and reaches only shrink (neighbour clamping lowers harmonic
 * distances, and a record's weight falls with its reach), so a candidate found covered when
 * the level was last tested is covered still unless a record that weighed at it then has
 * shrunk since. Only candidates where some shrunk record had a positive weight with its reach
 * of then (those records, as they were, form a small set of their own) are tested again: a
 * few thousand of a million on level-single-10, so the test runs here, in every process of a
 * farm, and the level's step holds only the gathers.
 */
static lmb_status uncovered_again(pass_ctx *c, uint32_t slot, uint32_t *cand, uint64_t *n, lmb_error *err)
{
    const double *then = c->tested_reach[slot];
    lmb_ic_records shrunk;
    lmb_ic_records_init(&shrunk, c->records.error);
    shrunk.rt = c->records.rt;
    lmb_status st = LMB_OK;
    for (uint32_t i = 0; i < c->tested_count[slot] && st == LMB_OK; i++)
        if (c->records.rec[i].r < then[i]) {
            lmb_ic_record as_then = c->records.rec[i];
            as_then.r = then[i];
            st = lmb_ic_records_append(&shrunk, &as_then, 1, err);
        }
    uint8_t *keep = NULL;
    if (st == LMB_OK && shrunk.count) {
        st = lmb_ic_records_index(&shrunk, c->threads, err);
        keep = malloc(*n + 1);
        if (st == LMB_OK && !keep)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %llu candidates",
                               (unsigned long long)*n);
    }
    if (st == LMB_OK && keep) {
        const uint64_t count = *n;
#pragma omp parallel for num_threads(c->threads) schedule(dynamic, 4096)
        for (uint64_t k = 0; k < count; k++) {
            double p[3], nn[3];
            lmb_ic_texel_point(c, lmb_ic_texel_at(c, cand[k]), p, nn);
            keep[k] = lmb_ic_interpolate(&shrunk, p, nn, NULL) > 0 &&
                      lmb_ic_interpolate(&c->records, p, nn, NULL) < LMB_IC_COVERED;
        }
    }
    uint64_t m = 0;
    for (uint64_t k = 0; st == LMB_OK && keep && k < *n; k++)
        if (keep[k])
            cand[m++] = cand[k];
    if (st == LMB_OK)
        *n = m;
    free(keep);
    lmb_ic_records_free(&shrunk);
    return st;
}

/* The reaches of the records so far, as level `slot`'s candidates are tested against them. */
static lmb_status note_tested(pass_ctx *c, uint32_t slot, lmb_error *err)
{
    double *r = realloc(c->tested_reach[slot], ((size_t)c->records.count + 1) * sizeof *r);
    if (!r)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %u records",
                             c->records.count);
    for (uint32_t i = 0; i < c->records.count; i++)
        r[i] = c->records.rec[i].r;
    c->tested_reach[slot] = r;
    c->tested_count[slot] = c->records.count;
    return LMB_OK;
}

/* Gathers at the uncovered candidates of one level (slot: its place from the coarsest) and
 * appends them as records. The first round tests coverage inside the step (a million
 * lookups, worth sharing out); later rounds before it (uncovered_again). */
static lmb_status place_level(pass_ctx *c, uint32_t spacing, uint32_t slot, uint32_t round, int clamp,
                              uint64_t *placed, lmb_gather_stats *stats, lmb_error *err)
{
    uint32_t *cand = NULL;
    uint64_t n = 0;
    lmb_status st = level_candidates(c, spacing, &cand, &n, err);
    if (st == LMB_OK && round > 0)
        st = uncovered_again(c, slot, cand, &n, err);
    if (st == LMB_OK)
        st = note_tested(c, slot, err);
    if (st != LMB_OK) {
        free(cand);
        return st;
    }
    lmb_ic_record *fresh = malloc((size_t)(n + 1) * sizeof *fresh);
    if (!fresh) {
        free(cand);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %llu records",
                             (unsigned long long)n);
    }
    uint64_t m = 0;
    c->spacing = spacing;
    st = lmb_ic_gather_records(c, cand, n, NULL, round == 0, fresh, &m, 0, n, stats, err);
    for (uint64_t k = 0; st == LMB_OK && k < m; k++) {
        c->is_record[fresh[k].atlas][fresh[k].texel] = 1;
        fresh[k].group = c->group;
    }
    c->group++;
    if (st == LMB_OK)
        st = lmb_ic_records_append(&c->records, fresh, (uint32_t)m, err);
    free(fresh);
    free(cand);
    if (st == LMB_OK && m) /* no new record: the index stands */
        st = lmb_ic_records_index(&c->records, c->threads, err);
    *placed = m;
    if (st == LMB_OK && m && clamp)
        st = lmb_ic_records_clamp(&c->records, (uint32_t)c->threads, err);
    return st;
}

/* The translation-gradient fit as a step: items are records, 9 floats each (as records keep
 * them: a farm's gradients are rounded where a single process's are). */
static lmb_status fit_range(void *user, uint64_t first, uint64_t last, lmb_buf *out,
                            uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    const pass_ctx *c = user;
    (void)counters;
    double (*g)[3][3] = malloc(((size_t)(last - first) + 1) * sizeof *g);
    if (!g)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for gradients");
    lmb_ic_records_fit_range(&c->records, (uint32_t)first, (uint32_t)last, (uint32_t)c->threads, g);
    lmb_status st = LMB_OK;
    for (uint64_t i = 0; i < last - first && st == LMB_OK; i++) {
        float gf[9];
        for (int k = 0; k < 9; k++)
            gf[k] = (float)g[i][k / 3][k % 3];
        st = lmb_buf_append(out, gf, sizeof gf, err);
    }
    free(g);
    return st;
}

static lmb_status fit_gradients(pass_ctx *c, lmb_error *err)
{
    char name[160];
    snprintf(name, sizeof name, "%s: gradients", c->stage);
    /* rays: a fit visits the records within twice its reach; counted as 64 rays per record */
    lmb_step_desc d = {name, c->records.count, NULL, 64.0 * c->records.count, fit_range, c};
    lmb_buf bytes = {0};
    uint64_t counters[LMB_STEP_COUNTERS];
    lmb_status st = lmb_steps_run(c->job->steps, &d, &bytes, counters, err);
    for (uint32_t i = 0; i < c->records.count && st == LMB_OK; i++)
        if (!lmb_buf_take(&bytes, c->records.rec[i].grad_t, sizeof c->records.rec[i].grad_t))
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: step holds too few records", name);
    lmb_buf_free(&bytes);
    return st;
}

/* Interpolation as a step (steps/runner.h): items are every atlas's listed texels in order. */
static lmb_status interpolate_range(void *user, uint64_t first, uint64_t last, lmb_buf *out,
                                    uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    const texel_items *ti = user;
    const pass_ctx *c = ti->c;
    (void)counters;
    for (uint32_t a = 0; a < c->atlas_count; a++) {
        const lmb_texels *t = c->t[a];
        uint32_t i0, i1;
        if (!texel_items_span(ti, a, first, last, &i0, &i1))
            continue;
        float *o = malloc(3 * sizeof *o * ((size_t)(i1 - i0) + 1));
        if (!o)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for atlas %u", a);
#pragma omp parallel for num_threads(c->threads) schedule(dynamic, 1024)
        for (uint32_t i = i0; i < i1; i++) {
            double e[3] = {0, 0, 0}, p[3], n[3];
            if (lmb_ic_is_own(c, a, i)) {
                for (int k = 0; k < 3; k++)
                    e[k] = c->own_e[a][3 * (size_t)i + k];
            } else if (t->valid[i]) {
                lmb_ic_texel_point(c, (texel_at){a, i}, p, n);
                lmb_ic_interpolate(&c->records, p, n, e);
            }
            for (int k = 0; k < 3; k++)
                o[3 * (size_t)(i - i0) + k] = (float)e[k];
        }
        lmb_status st = lmb_buf_append(out, o, 3 * sizeof *o * (i1 - i0), err);
        free(o);
        if (st != LMB_OK)
            return st;
    }
    return LMB_OK;
}

/* Every valid texel := the interpolation at its gather point (invalid: 0). A step: the
 * lookups cost about as much as a few gather rays per texel, too much to repeat in every
 * farm process that replays this pass. */
static lmb_status interpolate_all(const pass_ctx *c, float *const *out, lmb_error *err)
{
    texel_items is;
    lmb_status st = texel_items_make(c, &is, err);
    if (st != LMB_OK)
        return st;
    char name[160];
    snprintf(name, sizeof name, "%s: interpolation", c->stage);
    /* rays: a lookup visits tens of records; counted as 8 rays per texel for farm.min_step_rays */
    lmb_step_desc d = {name, is.first[c->atlas_count], NULL, 8.0 * (double)is.first[c->atlas_count],
                       interpolate_range, &is};
    uint64_t counters[LMB_STEP_COUNTERS], *floats = calloc((size_t)c->atlas_count + 1, sizeof *floats);
    if (!floats) {
        free(is.first);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory");
    }
    for (uint32_t a = 0; a < c->atlas_count; a++)
        floats[a] = 3 * (uint64_t)c->t[a]->count;
    lmb_float_sink sink = {c->atlas_count, out, floats, 0, 0};
    st = lmb_steps_run_streamed(c->job->steps, &d, LMB_STEP_STREAM_ITEMS, lmb_take_floats, &sink, counters, err);
    if (st == LMB_OK && !lmb_float_sink_full(&sink))
        st = lmb_error_set(err, LMB_ERR_INPUT, "%s: step holds too few texels", name);
    free(floats);
    free(is.first);
    return st;
}

static lmb_status export_points(const lmb_ic_records *s, lmb_ic_points *out, lmb_error *err)
{
    float *p = malloc(4 * ((size_t)s->count + 1) * sizeof *p);
    if (!p)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %u record points", s->count);
    for (uint32_t i = 0; i < s->count; i++) {
        for (int k = 0; k < 3; k++)
            p[4 * (size_t)i + k] = (float)s->rec[i].p[k];
        p[4 * (size_t)i + 3] = (float)s->rec[i].r;
    }
    free(out->xyzr);
    out->xyzr = p;
    out->count = s->count;
    return LMB_OK;
}

/* A record's relative noise and its light, for the weighted median. */
typedef struct noise_item {
    double rel, lum;
} noise_item;

static int compare_noise(const void *a, const void *b)
{
    double x = ((const noise_item *)a)->rel, y = ((const noise_item *)b)->rel;
    return (x > y) - (x < y);
}

/* Per atlas, the median of sqrt(var) / lum(e) over its records with light and an estimated
 * variance (0 when it has none), each record weighted by its light lum(e): how noisy the
 * interpolated light is, for the denoiser. Weighted by light, because a record's noise shows
 * in proportion to its light: a sunlit yard's records far from anything that bounces light
 * hold a thousandth of the light under a roof beside them, and their rare hits make them
 * noisy out of all proportion to what they show; counted alike, they set the whole atlas's
 * level (a card's shadow under it was filtered at 16.6% and lost 14% of its light). */
static lmb_status records_noise(const pass_ctx *c, double *noise, lmb_error *err)
{
    const lmb_ic_records *s = &c->records;
    size_t most = 0;
    for (uint32_t a = 0; a < c->atlas_count; a++)
        most = c->own_e[a] && c->t[a]->count > most ? c->t[a]->count : most;
    noise_item *rel = malloc(((size_t)s->count + most + 1) * sizeof *rel);
    if (!rel)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %u records", s->count);
    for (uint32_t a = 0; a < c->atlas_count; a++) {
        uint32_t n = 0;
        double total = 0;
        for (uint32_t k = 0; k < s->count; k++) {
            const lmb_ic_record *r = &s->rec[k];
            double lum = lmb_luminance_f(r->e);
            if (r->atlas == a && lum > 0 && r->var > 0) {
                rel[n++] = (noise_item){sqrt(r->var) / lum, lum};
                total += lum;
            }
        }
        for (uint32_t i = 0; c->own_e[a] && i < c->t[a]->count; i++) { /* own texels: as records of one texel */
            double lum = lmb_luminance_f(c->own_e[a] + 3 * (size_t)i);
            if (c->own[a][i] && lum > 0 && c->own_var[a][i] > 0) {
                rel[n++] = (noise_item){sqrt(c->own_var[a][i]) / lum, lum};
                total += lum;
            }
        }
        qsort(rel, n, sizeof *rel, compare_noise);
        double half = 0.5 * total, run = 0;
        noise[a] = 0;
        for (uint32_t k = 0; k < n; k++) {
            run += rel[k].lum;
            if (run >= half) {
                noise[a] = rel[k].rel;
                break;
            }
        }
    }
    free(rel);
    return LMB_OK;
}

/* Frees what only the record gathers read: the records' guide mixtures and the levels' tested
 * reaches (idempotent). */
static void free_gather_state(pass_ctx *c)
{
    free(c->mix);
    free(c->has_mix);
    c->mix = NULL;
    c->has_mix = NULL;
    c->mix_cap = 0;
    for (uint32_t l = 0; c->tested_reach && l < c->levels; l++)
        free(c->tested_reach[l]);
    free(c->tested_reach);
    free(c->tested_count);
    c->tested_reach = NULL;
    c->tested_count = NULL;
}

lmb_status lmb_ic_gather_pass(const lmb_gather_job *job, const lmb_ic_options *opt, uint32_t atlas_count,
                              const lmb_texels *const *t, float *const *out, lmb_ic_pass_stats *pass,
                              lmb_ic_records *shared, lmb_ic_own_texels *own, lmb_gather_stats *stats,
                              lmb_error *err)
{
    lmb_gather_job record_job = *job;
    uint64_t rays = (uint64_t)job->estimator.rays * opt->ray_scale;
    record_job.estimator.rays = rays > 1048576 * 64 ? 1048576 * 64 : (uint32_t)rays;
    lmb_gather_job own_job = record_job;
    own_job.noise_target = 0;
    pass_ctx c;
    memset(&c, 0, sizeof c);
    c.job = &record_job;
    c.own_job = &own_job;
    c.opt = opt;
    c.atlas_count = atlas_count;
    c.t = t;
    c.threads = job->threads ? (int)job->threads : omp_get_max_threads();
    snprintf(c.stage, sizeof c.stage, "%s (cache)", job->stage);
    c.guided = job->guide_stride > 0 && lmb_estimator_can_guide(&job->estimator);
    c.lobes = job->guide_lobes;
    lmb_ic_records_init(&c.records, opt->error);
    int reuse = shared && shared->count;
    if (reuse) { /* take the earlier pass's records */
        c.records = *shared;
        lmb_ic_records_init(shared, opt->error);
    }
    c.records.rt = job->rt; /* records serve no point across geometry (records.c, across_geometry) */
    lmb_status st = LMB_OK;
    c.is_record = calloc((size_t)atlas_count + 1, sizeof *c.is_record);
    c.first_id = calloc((size_t)atlas_count + 1, sizeof *c.first_id);
    if (!c.is_record || !c.first_id)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory");
    for (uint32_t a = 0; a < atlas_count && st == LMB_OK; a++) {
        if ((uint64_t)c.first_id[a] + t[a]->count > UINT32_MAX - 1)
            st = lmb_error_set(err, LMB_ERR_INPUT, "irradiance cache: more than 4 billion texels in all atlases");
        else
            c.first_id[a + 1] = c.first_id[a] + t[a]->count;
        c.is_record[a] = calloc((size_t)t[a]->count + 1, 1);
        if (!c.is_record[a])
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for atlas %u", a);
        for (uint32_t i = 0; i < t[a]->count; i++)
            c.valid_total += t[a]->valid[i];
    }
    uint32_t top = 1;
    while ((double)top * 2 <= opt->max_spacing)
        top *= 2;
    for (uint32_t s = top; s >= 1; s /= 2)
        c.levels++;
    c.tested_reach = calloc(c.levels + 1, sizeof *c.tested_reach);
    c.tested_count = calloc(c.levels + 1, sizeof *c.tested_count);
    if (st == LMB_OK && (!c.tested_reach || !c.tested_count))
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory");
    if (st == LMB_OK)
        st = lmb_ic_records_index(&c.records, c.threads, err);
    if (st == LMB_OK)
        st = lmb_ic_gather_own_texels(&c, own, stats, err);
    if (st == LMB_OK && reuse)
        st = regather(&c, stats, err);
    /* Rounds of the whole coarse-to-fine sequence until one places nothing: clamping after a
     * level can shrink reaches and uncover texels found covered before, and such a patch is
     * refilled coarse to fine too (a round of spacing 1 alone would fill it texel by texel).
     * The last allowed round does not clamp, so no valid texel is left uncovered. A later
     * round tests again only the candidates near records that shrank (uncovered_again). */
    for (uint32_t round = 0; round < LMB_IC_ROUNDS && st == LMB_OK && !reuse; round++) {
        int last_round = round + 1 == LMB_IC_ROUNDS;
        uint64_t placed_in_round = 0;
        uint32_t slot = 0;
        for (uint32_t s = top; s >= 1 && st == LMB_OK; s /= 2, slot++, c.level += round == 0) {
            uint64_t placed = 0;
            st = place_level(&c, s, slot, round, !last_round, &placed, stats, err);
            placed_in_round += placed;
        }
        if (!placed_in_round)
            break;
    }
    if (st == LMB_OK)
        st = fit_gradients(&c, err);
    free_gather_state(&c); /* the interpolation reads records only: their guides and tests go first */
    if (st == LMB_OK)
        st = interpolate_all(&c, out, err);
    if (st == LMB_OK) {
        if (job->progress) /* done (report() stops short of the total until here) */
            job->progress(job->progress_user, c.stage, c.valid_total * (c.levels + 1), c.valid_total * (c.levels + 1));
    }
    for (uint32_t a = 0; st == LMB_OK && pass && a < atlas_count; a++) {
        pass->records[a] = pass->valid[a] = 0;
        if (pass->own)
            pass->own[a] = 0;
        for (uint32_t i = 0; i < t[a]->count; i++) {
            pass->records[a] += c.is_record[a][i];
            pass->valid[a] += t[a]->valid[i];
        }
        for (uint32_t i = 0; pass->own && c.own && i < t[a]->count; i++)
            pass->own[a] += lmb_ic_is_own(&c, a, i);
    }
    if (st == LMB_OK && pass && pass->points)
        st = export_points(&c.records, pass->points, err);
    if (st == LMB_OK && pass && pass->noise)
        st = records_noise(&c, pass->noise, err);
    for (uint32_t a = 0; c.is_record && a < atlas_count; a++)
        free(c.is_record[a]);
    free(c.is_record);
    free(c.first_id);
    free_gather_state(&c);
    lmb_ic_free_own_texels(&c);
    if (shared && st == LMB_OK) { /* handed to the next pass */
        lmb_ic_records_free(shared);
        *shared = c.records;
    } else {
        lmb_ic_records_free(&c.records);
    }
    return st;
}
