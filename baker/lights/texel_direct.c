/*
 * Direct light texel by texel (see direct.h, lmb_direct_compute): each of a texel's points is
 * tested for lying inside geometry, the others get direct light (lmb_direct_eval), and the
 * texel keeps their mean, the point indirect light is gathered at, whether geometry covers it
 * in part (post/rim.c) and, for directional lightmaps, the light's direction sum; with mixed
 * lighting also the `indirect` lights' part and the shadowmask lights' visibility.
 */
#include "direct.h"

#include <omp.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../raytrace/rt_sight.h"
#include "../util/frame.h"
#include "../util/lmb_math.h"
#include "../util/rng.h"

/* A point's light in progress: its exact part once, its sampled part summed over rounds (with
 * the luminance of each round's estimate, for the variance). */
typedef struct point_sum {
    lmb_shading_point sp;
    uint32_t k;                                  /* the point's index in its texel */
    lmb_rng rng;
    uint64_t sequence;
    double e[3], dir[3], deferred[3];            /* exact part */
    double se[3], sdir[3], sdeferred[3];         /* sampled part, summed over rounds */
    double lum, lum2;                            /* sum over rounds of the sampled luminance, and of its square */
} point_sum;

/* The variance of one round's estimate of the texel's mean luminance: per point, the variance
 * of its rounds' estimates (their spread at one place: what another seed changes), pooled over
 * the points. The texel's standard error after R rounds is sqrt(variance / R). Scrambled Sobol
 * rounds of one sequence are negatively correlated, so this overstates the error a little. */
static double round_variance(const point_sum *ps, uint32_t used, uint32_t rounds)
{
    double var = 0;
    for (uint32_t k = 0; k < used && rounds > 1; k++) {
        double m = ps[k].lum / rounds, v = (ps[k].lum2 - rounds * m * m) / (rounds - 1);
        var += v > 0 ? v : 0;
    }
    return used ? var / ((double)used * used) : 0;
}

uint32_t lmb_direct_round_samples(const lmb_direct_options *opt)
{
    return opt->samples > 1 ? (opt->samples + 1) / 2 : 1;
}

/*
 * The points of a texel near geometry that lie on its own side of it: a texel split by a wall's
 * foot takes light from one room only. The first usable point is the anchor; the points not in
 * its sight along the surface (raytrace/rt_sight.h) are across a wall. When those are the
 * majority, the first of them becomes the anchor instead (the texel belongs where most of it
 * lies; a tie keeps the first). Keeps the anchor's side in ps[0..kept), the anchor first and the
 * rest in point order, and returns how many. Adds the rays traced to *rays.
 */
static uint32_t keep_own_side(const lmb_direct *d, point_sum *ps, uint32_t used, double texel_size, uint32_t *rays)
{
    const lmb_rt *rt = lmb_direct_rt(d);
    double lift = LMB_SIGHT_LIFT * texel_size;
    uint8_t seen[256];
    uint32_t anchor = 0, count = 0;
    for (int attempt = 0; attempt < 2; attempt++) {
        count = 0;
        for (uint32_t j = 0; j < used; j++) {
            seen[j] = j == anchor || lmb_rt_in_sight(rt, ps[anchor].sp.p, ps[anchor].sp.ng, ps[j].sp.p, ps[j].sp.ng, lift);
            *rays += j != anchor;
            count += seen[j];
        }
        if (2 * count >= used)
            break;
        for (uint32_t j = 0; j < used; j++)
            if (!seen[j]) {
                anchor = j;
                break;
            }
    }
    if (count == used)
        return used;
    uint32_t kept = 0, at = 0;
    for (uint32_t j = 0; j < used; j++)
        if (seen[j]) {
            at = j == anchor ? kept : at;
            ps[kept++] = ps[j]; /* kept <= j: in place */
        }
    point_sum a = ps[at];
    memmove(ps + 1, ps, at * sizeof *ps);
    ps[0] = a;
    return kept;
}

/*
 * Whether a thin wall stands within LMB_BESIDE_TEXELS texels of point sp along its surface: 8 rays
 * in its tangent plane, lifted as a sight test lifts (raytrace/rt_sight.h), 1.0824 x that long
 * (the nearest of 8 rays to a straight wall meets it within 1 / cos(22.5 degrees) of its
 * distance), and for a ray that meets a face, the same ray on from there: the wall is thin when it
 * ends within LMB_THIN_TEXELS texels (the ray meets its far side). Only across such a wall can a
 * bilinear lookup on the other side read this texel (cache/texel_sides.h); a crate or a step
 * wider than that keeps every lookup on its own side.
 */
static int thin_wall_beside(const lmb_direct *d, const lmb_shading_point *sp, double texel_size, uint32_t *rays)
{
    const lmb_rt *rt = lmb_direct_rt(d);
    double t1[3], t2[3], o[3], reach = 1.0824 * LMB_BESIDE_TEXELS * texel_size;
    lmb_frame(sp->ng, t1, t2);
    for (int k = 0; k < 3; k++)
        o[k] = sp->p[k] + LMB_SIGHT_LIFT * texel_size * sp->ng[k];
    for (int j = 0; j < 8; j++) {
        double w[3];
        lmb_rt_tangent_direction(t1, t2, j, w);
        lmb_rt_hit h, far;
        ++*rays;
        if (!lmb_rt_intersect(rt, o, w, 0.0, reach, &h))
            continue;
        ++*rays;
        if (lmb_rt_intersect(rt, h.p, w, rt->eps, LMB_THIN_TEXELS * texel_size, &far))
            return 1;
    }
    return 0;
}

/*
 * Direct light of listed texel i with `rounds` (>= 2) rounds of the sampled lights. Each usable
 * point evaluates its exact lights once and its sampled lights (area lights, sun discs, many
 * lights, the sky) in rounds of half samples.direct (and half sky.samples) along one scrambled
 * Sobol sequence per point: the direct step's two rounds (first = 0) are samples.direct's
 * samples. A refinement (first = 2) takes the rounds after them and its own random stream, and
 * its estimate is those rounds alone: the rounds that decided how many it needs are left out,
 * so a texel that drew low or high there is not kept low or high (the bias of adaptive
 * sampling that reuses its pilot). Every draw is keyed by texel, point and sample index: no
 * state is stored between the steps. job->variance gets round_variance. Adds the sampled
 * lights' samples to *samples.
 */
static void texel_direct(const lmb_direct_job *job, lmb_texels *t, uint32_t i, uint32_t first, uint32_t rounds,
                         float *out, uint64_t *rays, point_sum *ps, uint64_t *samples)
{
    const lmb_direct_options *opt = lmb_direct_opts(job->direct);
    double mask_sum[LMB_SHADOWMASK_CHANNELS] = {0};
    uint32_t used = 0, r = 0;
    int near_back = 0, near = 0;
    uint64_t key = ((uint64_t)job->atlas << 32) | t->texel[i];
    for (uint32_t k = 0; k < t->points_in[i]; k++) {
        point_sum *p = &ps[used];
        memset(p, 0, sizeof *p);
        p->k = k;
        lmb_texel_shading_point(job->direct, t, i, k, &p->sp);
        p->rng = lmb_rng_make(opt->seed, key, k);
        if (lmb_texel_point_cut(job->direct, t, i, k))
            continue;
        lmb_point_sight sight = {LMB_NEAR_TEXELS * t->texel_size[i], 0, 0};
        int inside = lmb_point_inside_geometry(job->direct, &p->sp, job->atlas, t->texel[i], k, &p->rng, &r, &sight);
        near |= sight.near;
        if (inside)
            continue;
        near_back |= sight.sees_back;
        used++;
    }
    uint32_t own_side = used;
    if (near && used > 1)
        used = keep_own_side(job->direct, ps, used, t->texel_size[i], &r);
    int beside = used && (used < own_side || (near && thin_wall_beside(job->direct, &ps[0].sp, t->texel_size[i], &r)));
    t->gather_at[i] = used ? (uint8_t)ps[0].k : 0;
    for (uint32_t j = 0; j < used; j++) {
        point_sum *p = &ps[j];
        p->sequence = lmb_mix64(p->rng.key ^ 0x51u);
        lmb_direct_draw exact = {LMB_DIRECT_EXACT, 0, 0, p->sequence, 0};
        r += lmb_direct_eval(job->direct, &p->sp, &exact, &p->rng, p->e, p->dir, p->deferred);
        if (first) /* the refinement's own stream for the sky and many lights (drawn by power past 256) */
            p->rng = lmb_rng_make(opt->seed, key, 0x6000u + p->k);
        if (job->shadowmask) { /* a stream of its own: the lightmap does not change with output.shadowmask */
            lmb_rng mask_rng = lmb_rng_make(opt->seed, key, 0x5000u + p->k);
            double vis[LMB_SHADOWMASK_CHANNELS];
            r += lmb_shadowmask_at(job->direct, &p->sp, &mask_rng, vis);
            for (int c = 0; c < LMB_SHADOWMASK_CHANNELS; c++)
                mask_sum[c] += vis[c];
        }
    }
    uint32_t per_round = lmb_direct_round_samples(opt);
    uint32_t sky_round = opt->sky_samples > 1 ? (opt->sky_samples + 1) / 2 : 1;
    if (!used || !lmb_direct_has_sampled(job->direct))
        rounds = 0;
    for (uint32_t round = 0; round < rounds; round++)
        for (uint32_t k = 0; k < used; k++) {
            point_sum *p = &ps[k];
            lmb_direct_draw draw = {LMB_DIRECT_SAMPLED, per_round, sky_round, p->sequence, (first + round) * per_round};
            double e[3], dir[3], deferred[3];
            r += lmb_direct_eval(job->direct, &p->sp, &draw, &p->rng, e, dir, deferred);
            double l = lmb_luminance(e);
            p->lum += l;
            p->lum2 += l * l;
            for (int d = 0; d < 3; d++) {
                p->se[d] += e[d];
                p->sdir[d] += dir[d];
                p->sdeferred[d] += deferred[d];
            }
            *samples += per_round;
        }
    if (job->variance)
        job->variance[i] = (float)round_variance(ps, used, rounds);
    double sum[3] = {0, 0, 0}, dir_sum[3] = {0, 0, 0}, deferred_sum[3] = {0, 0, 0};
    for (uint32_t k = 0; k < used; k++)
        for (int d = 0; d < 3; d++) {
            sum[d] += ps[k].e[d] + (rounds ? ps[k].se[d] / rounds : 0);
            dir_sum[d] += ps[k].dir[d] + (rounds ? ps[k].sdir[d] / rounds : 0);
            deferred_sum[d] += ps[k].deferred[d] + (rounds ? ps[k].sdeferred[d] / rounds : 0);
        }
    t->valid[i] = used > 0;
    t->edge[i] = (uint8_t)((used > 0 && (used < t->points_in[i] || near_back) ? LMB_EDGE_COVERED : 0) |
                           (beside ? LMB_EDGE_NEAR : 0));
    for (int d = 0; d < 3; d++) {
        out[3 * i + d] = used ? (float)(sum[d] / used) : 0.0f;
        if (job->direction)
            job->direction[3 * (size_t)i + d] = used ? (float)(dir_sum[d] / used) : 0.0f;
        if (job->deferred)
            job->deferred[3 * (size_t)i + d] = used ? (float)(deferred_sum[d] / used) : 0.0f;
    }
    for (int c = 0; job->shadowmask && c < LMB_SHADOWMASK_CHANNELS; c++)
        job->shadowmask[LMB_SHADOWMASK_CHANNELS * (size_t)i + c] = used ? (float)(mask_sum[c] / used) : 0.0f;
    *rays += r;
}

/* Refinement items first by their rounds, most first (longest-processing-time order: the
 * texels with thousands of rays start early and do not end the loop alone), then in list order. */
static int by_rounds(const void *a, const void *b)
{
    const uint64_t *x = a, *y = b;
    uint32_t rx = (uint32_t)(x[1] >> 32), ry = (uint32_t)(y[1] >> 32);
    if (rx != ry)
        return rx < ry ? 1 : -1;
    return x[0] < y[0] ? -1 : x[0] > y[0];
}

lmb_status lmb_direct_compute_bands(const lmb_direct_job *jobs, lmb_texels *t, float *const *irradiance, uint32_t bands,
                                    uint64_t *rays, uint64_t *samples, lmb_error *err)
{
    if (!bands)
        return LMB_OK;
    const lmb_direct_options *opt = lmb_direct_opts(jobs[0].direct);
    int threads = opt->threads ? (int)opt->threads : omp_get_max_threads();
    int refine = jobs[0].rounds != NULL;
    /* the work: (band << 32 | texel), with the refinement's rounds beside it for the order */
    uint64_t n = 0;
    uint32_t most_samples = 1;
    for (uint32_t b = 0; b < bands; b++) {
        most_samples = t[b].samples > most_samples ? t[b].samples : most_samples;
        for (uint32_t i = 0; i < t[b].count; i++)
            n += !refine || jobs[b].rounds[i];
    }
    uint64_t *items = malloc((2 * n + 1) * sizeof *items);
    if (!items)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "direct: out of memory for %llu texels", (unsigned long long)n);
    n = 0;
    for (uint32_t b = 0; b < bands; b++)
        for (uint32_t i = 0; i < t[b].count; i++)
            if (!refine || jobs[b].rounds[i]) {
                items[2 * n] = (uint64_t)b << 32 | i;
                items[2 * n + 1] = (uint64_t)(refine ? jobs[b].rounds[i] : 0) << 32;
                n++;
            }
    if (refine)
        qsort(items, n, 2 * sizeof *items, by_rounds);
    uint64_t total_rays = 0, total_samples = 0;
    int failed = 0;
#pragma omp parallel num_threads(threads) reduction(+ : total_rays, total_samples, failed)
    {
        lmb_rt_thread_init();
        point_sum *ps = malloc(((size_t)most_samples + 1) * sizeof *ps);
        failed += !ps;
        /* the direct step's texels cost alike and neighbours share cache lines: chunks of 16
         * in atlas order; the refinement's differ a thousandfold: one at a time, longest first */
#pragma omp for schedule(dynamic, 16)
        for (uint64_t k = 0; k < (refine ? 0 : n); k++) {
            uint32_t b = (uint32_t)(items[2 * k] >> 32), i = (uint32_t)items[2 * k];
            if (ps)
                texel_direct(&jobs[b], &t[b], i, 0, 2, irradiance[b], &total_rays, ps, &total_samples);
        }
#pragma omp for schedule(dynamic, 1)
        for (uint64_t k = 0; k < (refine ? n : 0); k++) {
            uint32_t b = (uint32_t)(items[2 * k] >> 32), i = (uint32_t)items[2 * k];
            if (ps)
                texel_direct(&jobs[b], &t[b], i, 2, jobs[b].rounds[i], irradiance[b], &total_rays, ps, &total_samples);
        }
        free(ps);
    }
    free(items);
    *rays += total_rays;
    *samples += total_samples;
    if (failed)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "direct: out of memory for %u points per texel", most_samples);
    return LMB_OK;
}
