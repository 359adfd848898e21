/* An irradiance-cache pass's record gathers as a step of the bake (ic_pass_internal.h): a
 * record's bytes, its mixture's, and the gathers over a range of texels. */
#include "ic_pass_internal.h"

#include "gather/guide.h"
#include "raytrace/rt_sight.h"

#include <omp.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Room for the mixtures of n records (new ones not yet had). */
static int reserve_mix(pass_ctx *c, uint32_t n)
{
    if (!c->guided || n <= c->mix_cap)
        return 1;
    uint32_t cap = c->mix_cap ? c->mix_cap : 1024;
    while (cap < n)
        cap = cap > UINT32_MAX / 2 ? n : cap * 2;
    lmb_mixture_kept *m = realloc(c->mix, (size_t)cap * sizeof *m);
    if (m)
        c->mix = m;
    uint8_t *h = realloc(c->has_mix, cap);
    if (h) {
        memset(h + c->mix_cap, 0, cap - c->mix_cap);
        c->has_mix = h;
    }
    if (!m || !h)
        return 0;
    c->mix_cap = cap;
    return 1;
}

/* The faces beside the record along its surface (lmb_ic_record.side, lmb_rt_sides): lifted as a
 * sight test lifts it, LMB_IC_CLEAR_REACH x its largest reach long. */
static void record_sides(const pass_ctx *c, texel_at x, lmb_ic_record *r)
{
    const lmb_texels *t = c->t[x.atlas];
    lmb_gather_point g;
    lmb_texels_point(t, x.index, t->gather_at[x.index], &g);
    double ng[3] = {g.ng[0], g.ng[1], g.ng[2]};
    r->lift = (float)(LMB_SIGHT_LIFT * t->texel_size[x.index]);
    lmb_rt_side side[2];
    uint32_t n = lmb_rt_sides(c->job->rt, r->p, ng, r->lift, LMB_IC_CLEAR_REACH * r->r_max, side, 2);
    for (uint32_t q = 0; q < n; q++) {
        for (int k = 0; k < 3; k++)
            r->side[q][k] = (float)side[q].m[k];
        r->side[q][3] = (float)side[q].d;
    }
}

/* Record from a gather at texel x: reach clamps from the texel's size, the rotation gradient
 * bounded like the translation one (at most E over the largest normal difference served). */
static void make_record(const pass_ctx *c, texel_at x, const lmb_gather_point_result *g, int again, lmb_ic_record *r)
{
    memset(r, 0, sizeof *r);
    memcpy(r->p, g->p, sizeof r->p);
    memcpy(r->n, g->n, sizeof r->n);
    for (int ch = 0; ch < 3; ch++)
        r->e[ch] = (float)g->e[ch];
    double size = c->t[x.atlas]->texel_size[x.index];
    r->r_min = (float)(c->opt->min_spacing * size);
    r->r_max = (float)(c->opt->max_spacing * size);
    r->harmonic = (float)g->harmonic;
    r->var = (float)g->var;
    r->r = (float)lmb_ic_reach(&c->records, r);
    double turn = sqrt(2.0) * c->records.normal_limit; /* |n_i x n| at the largest difference */
    for (int ch = 0; ch < 3; ch++) {
        double mag = sqrt(lmb_dot3(g->rot[ch], g->rot[ch])) * turn;
        double scale = mag > r->e[ch] ? r->e[ch] / mag : 1;
        for (int k = 0; k < 3; k++)
            r->grad_r[ch][k] = (float)(scale * g->rot[ch][k]);
    }
    r->atlas = x.atlas;
    r->texel = x.index;
    if (!c->own_level && !again) /* a texel gathered on its own serves no other; a record gathered
                                    again keeps its sides (only its light is taken) */
        record_sides(c, x, r);
}

/* A record's bytes in a step (steps/runner.h): p and n (6 doubles), then its floats e .. lift (35,
 * contiguous), atlas, texel. */
#define RECORD_FLOATS 35
_Static_assert(offsetof(lmb_ic_record, lift) - offsetof(lmb_ic_record, e) == (RECORD_FLOATS - 1) * sizeof(float),
               "lmb_ic_record: e .. lift are contiguous floats");

static lmb_status put_record(lmb_buf *out, const lmb_ic_record *r, lmb_error *err)
{
    lmb_status st = lmb_buf_append(out, r->p, sizeof r->p, err);
    if (st == LMB_OK)
        st = lmb_buf_append(out, r->n, sizeof r->n, err);
    if (st == LMB_OK)
        st = lmb_buf_append(out, r->e, RECORD_FLOATS * sizeof(float), err);
    if (st == LMB_OK)
        st = lmb_buf_append(out, &r->atlas, 4, err);
    if (st == LMB_OK)
        st = lmb_buf_append(out, &r->texel, 4, err);
    return st;
}

static int take_record(lmb_buf *in, lmb_ic_record *r)
{
    memset(r, 0, sizeof *r);
    return lmb_buf_take(in, r->p, sizeof r->p) && lmb_buf_take(in, r->n, sizeof r->n) &&
           lmb_buf_take(in, r->e, RECORD_FLOATS * sizeof(float)) && lmb_buf_take(in, &r->atlas, 4) &&
           lmb_buf_take(in, &r->texel, 4);
}

/* A mixture's bytes: count, diffuse, then per lobe its 14 doubles and `aimed` (unused lobes
 * are not written: a part's bytes do not depend on memory left over). */
static lmb_status put_mixture(lmb_buf *out, const lmb_mixture *m, lmb_error *err)
{
    lmb_status st = lmb_buf_append(out, &m->count, 4, err);
    if (st == LMB_OK)
        st = lmb_buf_append(out, &m->diffuse, 8, err);
    for (uint32_t k = 0; k < m->count && k < LMB_MIXTURE_MAX_LOBES && st == LMB_OK; k++) {
        double v[14];
        memcpy(v, m->lobe[k].axis, 24);
        v[3] = m->lobe[k].a;
        v[4] = m->weight[k];
        memcpy(v + 5, m->tangent[k], 24);
        memcpy(v + 8, m->bitangent[k], 24);
        memcpy(v + 11, m->target[k], 24);
        int32_t aimed = m->aimed[k];
        st = lmb_buf_append(out, v, sizeof v, err);
        if (st == LMB_OK)
            st = lmb_buf_append(out, &aimed, 4, err);
    }
    return st;
}

static int take_mixture(lmb_buf *in, lmb_mixture *m)
{
    memset(m, 0, sizeof *m);
    if (!lmb_buf_take(in, &m->count, 4) || !lmb_buf_take(in, &m->diffuse, 8) || m->count > LMB_MIXTURE_MAX_LOBES)
        return 0;
    for (uint32_t k = 0; k < m->count; k++) {
        double v[14];
        int32_t aimed;
        if (!lmb_buf_take(in, v, sizeof v) || !lmb_buf_take(in, &aimed, 4))
            return 0;
        memcpy(m->lobe[k].axis, v, 24);
        m->lobe[k].a = v[3];
        m->weight[k] = v[4];
        memcpy(m->tangent[k], v + 5, 24);
        memcpy(m->bitangent[k], v + 8, 24);
        memcpy(m->target[k], v + 11, 24);
        m->aimed[k] = aimed;
    }
    return 1;
}

/* The share of the record rays (ray_scale x a texel's) a record gathers with: placed on a grid of
 * spacing s, it stands for at most s x s texels, so min(s^2, ray_scale) texels' rays; gathered
 * again, the texels it serves (ic_pass.c, count_served). Never more than a record costs without
 * the cache at the texels it stands for. */
static double ray_share(const pass_ctx *c, const uint32_t *slots, uint64_t k)
{
    double scale = c->opt->ray_scale;
    if (slots)
        return c->records.serves ? c->records.serves[slots[k]] / scale : 1;
    double cell = (double)c->spacing * c->spacing;
    return cell < scale ? cell / scale : 1;
}

/* A gather_records call as a step: its items are the texels at[]. */
typedef struct records_step {
    pass_ctx *c;
    const uint32_t *at;           /* texel ids */
    const uint32_t *slots;
    int candidates;              /* at[] are a level's candidates: each is first tested for coverage
                                    by the records so far, and gathered only when uncovered */
    uint64_t done_before, total; /* progress */
} records_step;

/* Gathers at items [first, last) in parallel blocks: per item its record (and, guided, the
 * mixture it gathered by or learned). Reads earlier groups' records and mixtures only. */
static lmb_status gather_records_range(void *user, uint64_t first, uint64_t last, lmb_buf *out,
                                       uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    const records_step *rs = user;
    pass_ctx *c = rs->c;
    const uint64_t block = 64;
    int failed = 0;
    lmb_status st = LMB_OK;
    lmb_ic_record *rec = malloc(block * sizeof *rec);
    lmb_mixture *mix = c->guided ? malloc(block * sizeof *mix) : NULL;
    uint8_t covered[64] = {0};
    if (!rec || (c->guided && !mix))
        failed = 1;
    for (uint64_t start = first; start < last && !failed && st == LMB_OK; start += block) {
        uint64_t end = start + block < last ? start + block : last, rays = 0, texels = 0, adapted = 0, extended = 0,
                 capped = 0;
#pragma omp parallel num_threads(c->threads) reduction(+ : rays, texels, adapted, extended, capped, failed)
        {
            lmb_rt_thread_init();
            lmb_estimator_scratch scratch = {0};
            lmb_gather_stats gs = {0};
#pragma omp for schedule(dynamic, 1)
            for (uint64_t k = start; k < end; k++) {
                lmb_mixture guide;
                const lmb_mixture *by = NULL;
                const texel_at x = lmb_ic_texel_at(c, rs->at[k]);
                if (rs->candidates) {
                    double p[3], nn[3];
                    lmb_ic_texel_point(c, x, p, nn);
                    covered[k - start] = lmb_ic_interpolate(&c->records, p, nn, NULL) >= LMB_IC_COVERED;
                    if (covered[k - start])
                        continue;
                }
                if (c->guided && !c->own_level) {
                    double p[3], n[3];
                    lmb_ic_texel_point(c, x, p, n);
                    int64_t j = lmb_ic_records_nearest(&c->records, p, n, LMB_GUIDE_SAME_SURFACE_COS, c->has_mix);
                    if (j >= 0) {
                        lmb_mixture_reaim_kept(&c->mix[j], c->records.rec[j].p, p, &guide);
                        by = &guide;
                    }
                }
                lmb_gather_point_result g;
                if (lmb_gather_record(c->own_level ? c->own_job : c->job, x.atlas, c->t[x.atlas], x.index, by,
                                      c->own_level ? 0 : c->lobes, ray_share(c, rs->slots, k),
                                      &scratch, &g, &gs) !=
                    LMB_OK) {
                    failed = 1;
                    continue;
                }
                if (c->guided)
                    mix[k - start] = by ? guide : g.learned;
                make_record(c, x, &g, rs->slots != NULL, &rec[k - start]);
            }
            lmb_estimator_scratch_free(&scratch);
            rays += gs.rays;
            texels += gs.texels;
            adapted += gs.adapted;
            extended += gs.extended;
            capped += gs.capped;
        }
        counters[0] += rays;
        counters[1] += texels;
        counters[2] += adapted;
        counters[3] += extended;
        counters[4] += capped;
        for (uint64_t k = start; k < end && !failed && st == LMB_OK; k++) {
            if (rs->candidates) { /* a flag byte: covered (nothing follows) or a record */
                uint8_t flag = !covered[k - start];
                st = lmb_buf_append(out, &flag, 1, err);
                if (!flag || st != LMB_OK)
                    continue;
            }
            st = put_record(out, &rec[k - start], err);
            if (st == LMB_OK && c->guided)
                st = put_mixture(out, &mix[k - start], err);
        }
        lmb_ic_report(c, rs->done_before + end, rs->total);
    }
    free(rec);
    free(mix);
    if (failed)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory for %u gather samples", c->job->stage,
                             c->job->estimator.rays);
    return st;
}

/* Where a step's records go as they come (lmb_steps_run_streamed): each item's flag (when
 * candidates), record and mixture, into rec (new records) or over the records at slots. */
typedef struct records_taken {
    pass_ctx *c;
    const uint32_t *slots;
    int candidates;
    lmb_ic_record *rec;
    uint64_t items, made; /* items read, records made */
} records_taken;

static lmb_status take_records(void *user, lmb_buf *bytes, lmb_error *err)
{
    records_taken *rt = user;
    pass_ctx *c = rt->c;
    for (; bytes->read < bytes->size; rt->items++) {
        uint8_t flag = 1;
        if (rt->candidates && !lmb_buf_take(bytes, &flag, 1))
            flag = 2;
        if (!flag)
            continue;
        uint32_t slot = rt->slots ? rt->slots[rt->items] : c->records.count + (uint32_t)rt->made;
        lmb_ic_record fresh;
        lmb_mixture mix;
        if (flag == 2 || !take_record(bytes, &fresh) || (c->guided && !take_mixture(bytes, &mix)))
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: a truncated record in step results", c->job->stage);
        if (c->guided && !c->own_level)
            lmb_mixture_keep(&mix, &c->mix[slot]); /* not read before has_mix is set, when the whole group is in */
        if (rt->slots) {
            memcpy(c->records.rec[slot].e, fresh.e, sizeof fresh.e);
            memcpy(c->records.rec[slot].grad_r, fresh.grad_r, sizeof fresh.grad_r);
        } else {
            rt->rec[rt->made] = fresh;
        }
        rt->made++;
    }
    return LMB_OK;
}

/* Items per chunk of a records step in a local bake: a chunk's records and mixtures are at most
 * 4096 x 640 bytes. */
#define RECORD_CHUNK 4096

lmb_status lmb_ic_gather_records(pass_ctx *c, const uint32_t *at, uint64_t m, const uint32_t *slots, int candidates,
                                 lmb_ic_record *rec, uint64_t *made, uint64_t done_before, uint64_t total,
                                 lmb_gather_stats *stats, lmb_error *err)
{
    if (!c->own_level && !reserve_mix(c, slots ? c->records.count : c->records.count + (uint32_t)m))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for guides");
    records_step rs = {c, at, slots, candidates, done_before, total};
    char name[160];
    snprintf(name, sizeof name, "%s: %s %u", c->stage,
             c->own_level ? "texels gathered on their own, part"
             : slots      ? "records gathered again, group"
                          : "records placed, level",
             c->own_level ? c->own_part : slots ? c->regather_group : c->group);
    double rays = 0;
    for (uint64_t k = 0; k < m; k++)
        rays += ray_share(c, slots, k);
    lmb_step_desc d = {name, m, NULL, rays * c->job->estimator.rays, gather_records_range, &rs};
    uint64_t counters[LMB_STEP_COUNTERS];
    records_taken rt = {c, slots, candidates, rec, 0, 0};
    /* taken as they come, records gathered again too: a take writes the irradiance, rotation
     * gradient and mixture of records of the group being gathered, which no gather of the
     * group reads (they read positions, reaches and earlier groups' mixtures only) */
    lmb_status st = lmb_steps_run_streamed(c->job->steps, &d, RECORD_CHUNK, take_records, &rt, counters, err);
    stats->rays += counters[0];
    stats->texels += counters[1];
    stats->adapted += counters[2];
    stats->extended += counters[3];
    stats->capped += counters[4];
    if (st == LMB_OK && rt.items != m)
        st = lmb_error_set(err, LMB_ERR_INPUT, "%s: step '%s' holds %llu of %llu records", c->job->stage, name,
                           (unsigned long long)rt.items, (unsigned long long)m);
    if (made)
        *made = rt.made;
    if (st != LMB_OK)
        return st;
    for (uint64_t k = 0; c->guided && !c->own_level && k < rt.made; k++) /* the group is in: later groups may be guided by it */
        c->has_mix[slots ? slots[k] : c->records.count + (uint32_t)k] = 1;
    return LMB_OK;
}
