/* Adaptive direct light: more rounds where the light shown is noisier than samples.noise
 * (direct_refine.h). */
#include "direct_refine.h"

#include "util/lmb_math.h"
#include "util/select.h"

#include <omp.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The refinement's rays are at most this many times the direct step's over the atlas: on a level
 * where most texels are in penumbra under little other light (an outdoor level under a sky),
 * samples.max_rays alone would let the bake take many times as long. Past it, every refined
 * texel's extra rounds shrink in proportion. */
#define REFINE_BUDGET 1.0

typedef struct refine_ctx {
    const lmb_direct_options *opt;
    const lmb_direct *direct;
    const lmb_scene *scene;
    const lmb_layout *layout;
    uint32_t atlas, width, height, rows;
    const lmb_direct_atlas *da;
    const uint32_t *rounds;  /* per listed texel: 0 (kept) or its rounds */
    uint32_t *first;         /* per band (+1): its first listed texel */
    lmb_instance_rows instance_rows; /* which instances a band visits */
    lmb_progress_fn progress;
    void *progress_user;
    uint64_t bands;          /* the atlas's: progress is told over all of them, so a farm shard's
                                chunks do not each report a stage done */
} refine_ctx;

/* The rounds texel i needs: its standard error after R rounds is sqrt(variance / R); R is the
 * least with that under k x samples.noise x the light shown, at most samples.max_rays samples
 * (counting every point of the texel). 0: two rounds (the direct step's) are enough. */
static uint32_t rounds_needed(const lmb_direct_options *opt, double k, double variance, double shown, int *capped)
{
    *capped = 0;
    double target = k * opt->noise_target * shown;
    if (!(variance > 0) || !(target > 0) || variance <= 2 * target * target)
        return 0;
    double want = ceil(variance / (target * target));
    double most = floor((double)opt->max_rays / ((double)opt->texel_samples * lmb_direct_round_samples(opt)));
    if (want > most) {
        want = most;
        *capped = 1;
    }
    return want > 2 ? (uint32_t)want : 0;
}

/* Per listed texel, the means over the valid texels within NEIGHBOURS texels of it in the atlas
 * (itself included) of the round variance and of the luminance shown: what decides its rounds.
 * A texel's own draws weigh 1/25 there, so a texel that drew low is not refined for being low
 * (its relative error looks large) nor one that drew high left high: deciding from its own
 * estimate alone biased a sun map's mean 1% high. Returns 0 when out of memory. */
#define NEIGHBOURS 2
static int neighbourhood_means(const lmb_direct_atlas *da, const double *shown, uint32_t width, uint32_t height,
                               int threads, float *mean_var, float *mean_lum)
{
    int32_t *at = malloc(((size_t)width * height + 1) * sizeof *at);
    if (!at)
        return 0;
    for (size_t p = 0; p < (size_t)width * height; p++)
        at[p] = -1;
    for (uint32_t i = 0; i < da->t.count; i++)
        if (da->t.valid[i])
            at[da->t.texel[i]] = (int32_t)i;
#pragma omp parallel for num_threads(threads) schedule(static)
    for (uint32_t i = 0; i < da->t.count; i++) {
        int64_t x = da->t.texel[i] % width, y = da->t.texel[i] / width;
        double v = 0, l = 0;
        uint32_t n = 0;
        for (int64_t yy = y - NEIGHBOURS; yy <= y + NEIGHBOURS; yy++)
            for (int64_t xx = x - NEIGHBOURS; xx <= x + NEIGHBOURS; xx++) {
                if (xx < 0 || yy < 0 || xx >= width || yy >= height || at[yy * width + xx] < 0)
                    continue;
                int32_t j = at[yy * width + xx];
                v += da->variance[j];
                l += shown[j];
                n++;
            }
        mean_var[i] = n ? (float)(v / n) : 0.0f;
        mean_lum[i] = n ? (float)(l / n) : 0.0f;
    }
    free(at);
    return 1;
}

/* rounds[i] := the rounds every texel needs at k x samples.noise, from its neighbourhood's
 * variance and light (rim texels keep the limit post/rim.c set); returns their sum; with noise,
 * counts the refined and capped texels. In parallel: the sums are of integers, exact in any order. */
static double plan_rounds(const lmb_direct_options *opt, const lmb_direct_atlas *da, const float *mean_var,
                          const float *mean_lum, double k, int threads, uint32_t *rounds, lmb_direct_noise *noise)
{
    uint64_t sum = 0, refined = 0, capped = 0;
#pragma omp parallel for num_threads(threads) schedule(static) reduction(+ : sum, refined, capped)
    for (uint32_t i = 0; i < da->t.count; i++) {
        rounds[i] = 0;
        if (!da->t.valid[i] || !(da->variance[i] > 0) || (da->t.edge[i] & LMB_EDGE_COVERED))
            continue;
        int was_capped;
        rounds[i] = rounds_needed(opt, k, mean_var[i], mean_lum[i], &was_capped);
        sum += rounds[i];
        refined += rounds[i] > 0;
        capped += rounds[i] > 0 && was_capped;
    }
    if (noise) {
        noise->refined += refined;
        noise->capped += capped;
    }
    return (double)sum;
}

/* Valid texels of the atlas with sampled direct light. */
static uint64_t noise_texels_here(const lmb_direct_atlas *da)
{
    uint64_t n = 0;
    for (uint32_t i = 0; i < da->t.count; i++)
        n += da->t.valid[i] && da->variance[i] > 0;
    return n;
}

/* The refined texels of one band and their new light. */
typedef struct band_refined {
    uint32_t i0, i1, refined; /* its listed texels [i0, i1), how many of them are refined */
    lmb_texels texels;
    float *e, *var, *dir, *deferred;
} band_refined;

static void band_refined_free(band_refined *r)
{
    lmb_texels_free(&r->texels);
    free(r->e);
    free(r->var);
    free(r->dir);
    free(r->deferred);
    memset(r, 0, sizeof *r);
}

/* Band b's bytes: u32 refined; per refined texel u32 listed index, f32 variance, 3 f32 direct,
 * then 3 f32 direction sum when directional and 3 f32 deferred light with mixed lighting. */
static lmb_status put_refined(const refine_ctx *c, const band_refined *r, lmb_buf *out, lmb_error *err)
{
    lmb_status st = lmb_buf_append(out, &r->refined, 4, err);
    for (uint32_t j = 0; st == LMB_OK && r->refined && j < r->i1 - r->i0; j++) {
        if (!c->rounds[r->i0 + j])
            continue;
        uint32_t listed = r->i0 + j;
        st = lmb_buf_append(out, &listed, 4, err);
        if (st == LMB_OK)
            st = lmb_buf_append(out, &r->var[j], 4, err);
        if (st == LMB_OK)
            st = lmb_buf_append(out, &r->e[3 * j], 12, err);
        if (st == LMB_OK && r->dir)
            st = lmb_buf_append(out, &r->dir[3 * j], 12, err);
        if (st == LMB_OK && r->deferred)
            st = lmb_buf_append(out, &r->deferred[3 * j], 12, err);
    }
    return st;
}

/* Builds and refines the bands of group[0..n) (their texels at once, a band per thread; then
 * every refined texel of them in one loop, longest first: lmb_direct_compute_bands). */
static lmb_status refine_group(const refine_ctx *c, uint64_t b0, uint64_t b1, const uint8_t *skip, band_refined *r,
                               lmb_direct_job *jobs, lmb_texels *texels, float **e,
                               uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    uint32_t n = (uint32_t)(b1 - b0), used = 0;
    lmb_status st = lmb_direct_build_bands(c->opt, c->scene, c->layout, c->atlas, c->rows, b0, b1, &c->instance_rows,
                                           skip, texels, err);
    for (uint32_t k = 0; k < n && st == LMB_OK; k++) { /* r owns the texels from here */
        r[k].i0 = c->first[b0 + k];
        r[k].i1 = c->first[b0 + k + 1];
        r[k].texels = texels[k];
        memset(&texels[k], 0, sizeof texels[k]);
    }
    for (uint32_t k = 0; k < n && st == LMB_OK; k++) {
        band_refined *br = &r[k];
        if (skip[k])
            continue;
        for (uint32_t i = br->i0; i < br->i1; i++)
            br->refined += c->rounds[i] > 0;
        size_t count = br->texels.count;
        uint32_t y0 = (uint32_t)(b0 + k) * c->rows;
        if (count != br->i1 - br->i0) {
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "direct light of atlas %u: rows from %u list %zu texels, not %u",
                               c->atlas, y0, count, br->i1 - br->i0);
            break;
        }
        for (uint32_t j = 0; st == LMB_OK && j < count; j++)
            if (br->texels.texel[j] != c->da->t.texel[br->i0 + j])
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "direct light of atlas %u: texel lists disagree", c->atlas);
        br->e = calloc(3 * count + 1, sizeof *br->e);
        br->var = calloc(count + 1, sizeof *br->var);
        br->dir = c->da->direction ? calloc(3 * count + 1, sizeof *br->dir) : NULL;
        br->deferred = c->da->deferred ? calloc(3 * count + 1, sizeof *br->deferred) : NULL;
        if (st == LMB_OK && (!br->e || !br->var || (c->da->direction && !br->dir) || (c->da->deferred && !br->deferred)))
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "direct light: out of memory refining atlas %u", c->atlas);
        jobs[used] = (lmb_direct_job){c->direct, c->atlas, br->dir, br->deferred, NULL, br->var, c->rounds + br->i0};
        texels[used] = br->texels; /* a shallow copy: the texels stay br's */
        e[used++] = br->e;
    }
    if (st == LMB_OK)
        st = lmb_direct_compute_bands(jobs, texels, e, used, &counters[0], &counters[1], err);
    /* lmb_direct_compute_bands wrote valid and gather_at into the copies: the same arrays as br's */
    memset(texels, 0, (size_t)n * sizeof *texels);
    return st;
}

/* Bands [first, last): those with refined texels in groups of lmb_direct_group_bands (empty
 * bands cost nothing and do not count), each group refined at once (refine_group). */
static lmb_status refine_bands(void *user, uint64_t first, uint64_t last, lmb_buf *out,
                               uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    const refine_ctx *c = user;
    uint32_t group = lmb_direct_group_bands(c->opt);
    uint64_t most = last - first;
    band_refined *r = calloc(most + 1, sizeof *r);
    uint8_t *skip = calloc(most + 1, 1);
    lmb_direct_job *jobs = calloc(most + 1, sizeof *jobs);
    lmb_texels *texels = calloc(most + 1, sizeof *texels);
    float **e = calloc(most + 1, sizeof *e);
    lmb_status st = LMB_OK;
    if (!r || !skip || !jobs || !texels || !e)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "direct light: out of memory refining atlas %u", c->atlas);
    for (uint64_t b0 = first; b0 < last && st == LMB_OK;) {
        uint64_t b1 = b0;
        for (uint32_t nonempty = 0; b1 < last && nonempty < group; b1++) {
            int any = 0;
            for (uint32_t i = c->first[b1]; i < c->first[b1 + 1] && !any; i++)
                any = c->rounds[i] > 0;
            skip[b1 - b0] = (uint8_t)!any;
            nonempty += (uint32_t)any;
        }
        st = refine_group(c, b0, b1, skip, r, jobs, texels, e, counters, err);
        for (uint64_t b = b0; b < b1; b++) {
            if (st == LMB_OK)
                st = put_refined(c, &r[b - b0], out, err);
            band_refined_free(&r[b - b0]);
        }
        if (st == LMB_OK && c->progress)
            c->progress(c->progress_user, "direct refinement", b1, c->bands);
        b0 = b1;
    }
    free(r);
    free(skip);
    free(jobs);
    free(texels);
    free(e);
    return st;
}

/* Applies the step's bytes to da. */
static lmb_status take_refined(lmb_buf *in, uint64_t bands, lmb_direct_atlas *da, uint32_t atlas, lmb_error *err)
{
    for (uint64_t b = 0; b < bands; b++) {
        uint32_t refined;
        if (!lmb_buf_take(in, &refined, 4))
            return lmb_error_set(err, LMB_ERR_INPUT, "refined direct light of atlas %u: truncated band", atlas);
        for (uint32_t k = 0; k < refined; k++) {
            uint32_t i;
            if (!lmb_buf_take(in, &i, 4) || i >= da->t.count || !lmb_buf_take(in, &da->variance[i], 4) ||
                !lmb_buf_take(in, &da->direct[3 * (size_t)i], 12) ||
                (da->direction && !lmb_buf_take(in, &da->direction[3 * (size_t)i], 12)) ||
                (da->deferred && !lmb_buf_take(in, &da->deferred[3 * (size_t)i], 12)))
                return lmb_error_set(err, LMB_ERR_INPUT, "refined direct light of atlas %u: truncated band", atlas);
        }
    }
    return LMB_OK;
}

lmb_status lmb_direct_refine_step(lmb_steps *steps, const lmb_direct *direct,
                                  const lmb_scene *scene, const lmb_layout *layout, uint32_t a, const double *shown,
                                  lmb_progress_fn progress, void *progress_user, lmb_direct_atlas *da, uint64_t *rays, lmb_direct_noise *noise, float **estimates,
                                  uint64_t *estimate_count, lmb_error *err)
{
    const lmb_direct_options *opt = lmb_direct_opts(direct);
    uint32_t count = da->t.count, width = layout->width[a], height = layout->height[a];
    uint32_t rows = width ? (LMB_DIRECT_BAND_TEXELS + width - 1) / width : 1;
    rows = rows ? rows : 1;
    uint64_t bands = height ? (height + (uint64_t)rows - 1) / rows : 0;
    uint32_t *rounds = calloc((size_t)count + 1, sizeof *rounds);
    uint32_t *first = calloc(bands + 2, sizeof *first);
    double *cost = calloc(bands + 1, sizeof *cost);
    float *more = realloc(*estimates, (*estimate_count + count + 1) * sizeof *more);
    if (more)
        *estimates = more;
    if (!rounds || !first || !cost || !more) {
        free(rounds);
        free(first);
        free(cost);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "direct light: out of memory refining atlas %u", a);
    }
    double per_texel = (double)opt->texel_samples * lmb_direct_round_samples(opt), step_rays = 0;
    uint64_t b = 0;
    for (uint32_t i = 0; i < count; i++) {
        while (b < bands && da->t.texel[i] >= (uint64_t)(b + 1) * rows * width)
            first[++b] = i;
    }
    while (b < bands)
        first[++b] = count;
    /* The budget in rays: a texel's round costs about half the rays the direct step spent on an
     * average texel with sampled light (validity and exact lights included: an overestimate).
     * Over budget, the target is loosened for every texel alike (the least k with the plan at
     * k x samples.noise within it, by bisection): the bake reaches the most even noise it can
     * afford, rather than some texels the target and the rest nothing. */
    uint64_t sampled = noise_texels_here(da);
    double round_rays = sampled ? (double)da->rays / (2.0 * (double)sampled) : 0;
    double budget = REFINE_BUDGET * (double)da->rays, k = 1;
    int threads = opt->threads ? (int)opt->threads : omp_get_max_threads();
    float *mean_var = malloc(((size_t)count + 1) * sizeof *mean_var), *mean_lum = malloc(((size_t)count + 1) * sizeof *mean_lum);
    if (!mean_var || !mean_lum || !neighbourhood_means(da, shown, width, height, threads, mean_var, mean_lum)) {
        free(mean_var);
        free(mean_lum);
        free(rounds);
        free(first);
        free(cost);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "direct light: out of memory refining atlas %u", a);
    }
    if (opt->adaptive && plan_rounds(opt, da, mean_var, mean_lum, 1, threads, rounds, NULL) * round_rays > budget) {
        double lo = 1, hi = 2;
        while (hi < 1e6 && plan_rounds(opt, da, mean_var, mean_lum, hi, threads, rounds, NULL) * round_rays > budget)
            hi *= 2;
        for (int it = 0; it < 40 && hi < 1e6; it++) {
            double mid = 0.5 * (lo + hi);
            if (plan_rounds(opt, da, mean_var, mean_lum, mid, threads, rounds, NULL) * round_rays > budget)
                lo = mid;
            else
                hi = mid;
        }
        k = hi;
        noise->budget_limited = 1;
    }
    if (k > noise->loosened)
        noise->loosened = k;
    if (opt->adaptive)
        plan_rounds(opt, da, mean_var, mean_lum, k < 1e6 ? k : 1e300, threads, rounds, noise);
    free(mean_var);
    free(mean_lum);
    for (uint32_t i = 0, bb = 0; i < count; i++) {
        while (bb + 1 < bands && i >= first[bb + 1])
            bb++;
        noise->texels += da->t.valid[i] && da->variance[i] > 0;
        cost[bb] += rounds[i] * per_texel;
        step_rays += 2 * rounds[i] * per_texel;
    }
    lmb_status st = LMB_OK;
    if (noise->refined) {
        refine_ctx c = {opt, direct, scene, layout, a, width, height, rows, da, rounds, first, {0},
                        progress, progress_user, bands};
        st = lmb_instance_rows_make(scene, layout, a, rows, &c.instance_rows, err);
        char name[64];
        snprintf(name, sizeof name, "direct, atlas %u: more samples", a);
        lmb_step_desc d = {name, bands, cost, step_rays, refine_bands, &c};
        lmb_buf bytes = {0};
        uint64_t counters[LMB_STEP_COUNTERS];
        if (st == LMB_OK)
            st = lmb_steps_run(steps, &d, &bytes, counters, err);
        if (st == LMB_OK) {
            *rays += counters[0];
            noise->samples += counters[1];
            st = take_refined(&bytes, bands, da, a, err);
        }
        lmb_buf_free(&bytes);
        lmb_instance_rows_free(&c.instance_rows);
    }
    /* what the texels reached, measured again where they were refined */
    for (uint32_t i = 0; st == LMB_OK && i < count; i++) {
        double v = da->variance[i], lum = shown[i];
        if (da->t.valid[i] && v > 0)
            (*estimates)[(*estimate_count)++] = lum > 0 ? (float)(sqrt(v / (rounds[i] ? rounds[i] : 2)) / lum) : 0.0f;
        da->variance[i] = (float)(v / (rounds[i] ? rounds[i] : 2)); /* now the estimate's own (denoise.h) */
    }
    free(rounds);
    free(first);
    free(cost);
    return st;
}

void lmb_direct_noise_finish(lmb_direct_noise *noise, float *estimates, uint64_t count)
{
    if (count) {
        noise->median = lmb_select_kth(estimates, count, count / 2);
        noise->p95 = lmb_select_kth(estimates, count, (uint64_t)(0.95 * (double)(count - 1)));
    }
    free(estimates);
}

void lmb_direct_noise_report(const lmb_direct_noise *noise, const lmb_direct_options *opt, lmb_bake_stats *stats,
                             const lmb_log *log)
{
    if (!noise->texels)
        return;
    stats->direct_noise_median = noise->median;
    stats->direct_noise_p95 = noise->p95;
    stats->direct_refined = noise->refined;
    stats->direct_capped = noise->capped;
    lmb_info(log,
             "direct light: estimated noise per texel median %.2f%%, p95 %.2f%% of the light (samples.noise %g%%%s); "
             "%llu of %llu texels (%.1f%%) took more samples (%.1f per texel on average), %llu of them stopped at "
             "samples.max_rays %u",
             100.0 * noise->median, 100.0 * noise->p95, 100.0 * opt->noise_target, opt->adaptive ? "" : ", not adaptive",
             (unsigned long long)noise->refined, (unsigned long long)noise->texels,
             100.0 * (double)noise->refined / (double)noise->texels,
             noise->refined ? (double)noise->samples / (double)noise->refined : 0.0, (unsigned long long)noise->capped,
             opt->max_rays);
    if (noise->budget_limited)
        lmb_info(log, "direct light: samples.noise asked for more rays than the direct step's; the texels were refined "
                 "to %.2f%% instead (raise samples.direct for more)", 100.0 * noise->loosened * opt->noise_target);
}
