/* The gather stage (see gather.h): cache passes, the path-traced reference, threads. */
#include "gather.h"

#include "cache/back_light.h"
#include "gather/guide.h"
#include "util/lmb_math.h"

#include <omp.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* One gather point's context for the estimator's radiance callback. */
typedef struct point_rays {
    const lmb_gather_job *job;
    lmb_shading_point sp;
    double o[3];
    uint64_t key;
    uint64_t rays;
    uint32_t cosine_samples;   /* samples below this index are cosine-distributed */
    uint32_t distances;        /* of those, how many were traced */
    double inverse_distances;  /* and the sum of 1 / hit distance (0 for a miss) */
} point_rays;

/* A hit as a shading point (its geometric normal, front side) for direct light there. */
static void hit_point(const lmb_rt *rt, const double o[3], const double w[3], const lmb_rt_hit *h, lmb_shading_point *y)
{
    for (int k = 0; k < 3; k++) {
        y->p[k] = o[k] + h->t * w[k];
        y->n[k] = y->ng[k] = h->ng[k];
    }
    y->eps = 4 * rt->eps;
}

/* B leaving hit h toward the gather point: from the cache or (no lightmap) direct light there; 0
 * from a back face. */
static inline void hit_radiance(point_rays *pr, const double w[3], const lmb_rt_hit *h, uint32_t sample, double out[3])
{
    const lmb_gather_job *job = pr->job;
    double albedo[3], e[3];
    out[0] = out[1] = out[2] = 0;
    lmb_hit_kind kind = lmb_cache_lookup(job->cache, h, albedo, e);
    if (kind == LMB_HIT_DARK || (kind == LMB_HIT_UNMAPPED && job->unmapped_dark))
        return;
    double through[3];
    if (kind == LMB_HIT_BACK) { /* a back that reflects: its light estimated where the ray met it */
        double front[3] = {e[0], e[1], e[2]};
        lmb_rng rng = lmb_rng_make(job->seed, pr->key, ((uint64_t)job->pass << 32) | sample);
        pr->rays += lmb_cache_back_irradiance(job->cache, job->direct, h, pr->o, w, job->direct_at_hits, &rng, e);
        for (int k = 0; k < 3; k++)
            out[k] = albedo[k] * e[k];
        if (job->cache->diffuse_through && lmb_cache_diffuse_through(job->cache, h, through) > 0)
            for (int k = 0; k < 3; k++) /* and the front's light it lets through */
                out[k] += through[k] * front[k];
        return;
    }
    if (kind == LMB_HIT_UNMAPPED || job->direct_at_hits) {
        lmb_shading_point y;
        double d[3];
        hit_point(job->rt, pr->o, w, h, &y);
        lmb_rng rng = lmb_rng_make(job->seed, pr->key, ((uint64_t)job->pass << 32) | sample);
        pr->rays += lmb_direct_at(job->direct, &y, 1, &rng, d, NULL);
        for (int k = 0; k < 3; k++) /* unmapped: direct light only (one bounce) */
            e[k] = kind == LMB_HIT_UNMAPPED ? d[k] : e[k] + d[k];
    }
    for (int k = 0; k < 3; k++)
        out[k] = albedo[k] * e[k];
    if (kind == LMB_HIT_CACHED && job->cache->diffuse_through && lmb_cache_diffuse_through(job->cache, h, through) > 0) {
        double back[3]; /* the back's light it lets through to the front, estimated there */
        lmb_rng rng = lmb_rng_make(job->seed, pr->key ^ 0x444946465553ull, ((uint64_t)job->pass << 32) | sample);
        pr->rays += lmb_cache_back_irradiance(job->cache, job->direct, h, pr->o, w, job->direct_at_hits, &rng, back);
        for (int k = 0; k < 3; k++)
            out[k] += through[k] * back[k];
    }
}

/* Radiance arriving from w: B at the first opaque hit, seen through the surfaces light partly
 * passes before it, each adding what its covered share reflects (rt_surface.h). Returns the
 * distance to the nearest surface met (INFINITY: none). */
static double cached_radiance(void *user, const double w[3], uint32_t sample, double out[3])
{
    point_rays *pr = user;
    const lmb_gather_job *job = pr->job;
    lmb_rt_hit h;
    lmb_rt_layer layers[LMB_RT_MAX_LAYERS];
    uint32_t nl;
    out[0] = out[1] = out[2] = 0;
    pr->rays++;
    if (!job->rt->partial_geoms) { /* nothing light passes in part: the closest hit alone */
        int hit = lmb_rt_intersect(job->rt, pr->o, w, pr->sp.eps, 1e300, &h);
        if (sample < pr->cosine_samples) {
            pr->distances++;
            pr->inverse_distances += hit && h.t > 0 ? 1.0 / h.t : 0.0;
        }
        if (!hit)
            return INFINITY;
        hit_radiance(pr, w, &h, sample, out);
        return h.t;
    }
    int hit = lmb_rt_intersect_layers(job->rt, pr->o, w, pr->sp.eps, 1e300, &h, layers, &nl);
    double first = nl ? layers[0].hit.t : hit ? h.t : INFINITY;
    if (sample < pr->cosine_samples) {
        pr->distances++;
        pr->inverse_distances += isfinite(first) && first > 0 ? 1.0 / first : 0.0;
    }
    if (!nl) {
        if (hit)
            hit_radiance(pr, w, &h, sample, out);
        return first;
    }
    double through[3] = {1, 1, 1}, b[3];
    for (uint32_t j = 0; j < nl; j++) {
        hit_radiance(pr, w, &layers[j].hit, sample, b);
        for (int k = 0; k < 3; k++) {
            out[k] += through[k] * layers[j].cover * b[k];
            through[k] *= layers[j].pass[k];
        }
    }
    if (hit) {
        hit_radiance(pr, w, &h, sample, b);
        for (int k = 0; k < 3; k++)
            out[k] += through[k] * b[k];
    }
    return first;
}

/* The reference path's next surface along w: the opaque hit, or a surface light partly passes
 * chosen to reflect with probability cover / (cover + mean pass) (else the path goes through it,
 * beta times pass over the probability of passing), so the reference stays unbiased. */
static int reference_hit(const lmb_gather_job *job, const double o[3], const double w[3], double eps, lmb_rng *rng,
                         double beta[3], lmb_rt_hit *h, double *cover)
{
    lmb_rt_layer layers[LMB_RT_MAX_LAYERS];
    uint32_t nl;
    int hit = lmb_rt_intersect_layers(job->rt, o, w, eps, 1e300, h, layers, &nl);
    *cover = 1.0;
    for (uint32_t j = 0; j < nl; j++) {
        double mean = (layers[j].pass[0] + layers[j].pass[1] + layers[j].pass[2]) / 3.0;
        double q = layers[j].cover / (layers[j].cover + mean);
        if (lmb_rng_next(rng) < q) {
            *h = layers[j].hit;
            *cover = layers[j].cover / q;
            return 1;
        }
        for (int k = 0; k < 3; k++)
            beta[k] *= layers[j].pass[k] / (1.0 - q);
    }
    return hit;
}

/* Path-traced indirect irradiance at sp: paths x depth cosine bounces, direct light at each hit. */
static void reference(point_rays *pr, double out[3])
{
    const lmb_gather_job *job = pr->job;
    uint32_t paths = job->estimator.rays;
    double sum[3] = {0, 0, 0};
    for (uint32_t j = 0; j < paths; j++) {
        lmb_rng rng = lmb_rng_make(job->seed, pr->key, ((uint64_t)job->pass << 32) | j);
        lmb_shading_point x = pr->sp;
        double o[3] = {pr->o[0], pr->o[1], pr->o[2]}, beta[3] = {1, 1, 1};
        for (uint32_t d = 0; d < job->depth; d++) {
            lmb_lobe cosine = {{x.n[0], x.n[1], x.n[2]}, 1.0};
            double w[3], u1 = lmb_rng_next(&rng), u2 = lmb_rng_next(&rng);
            lmb_lobe_sample(&cosine, u1, u2, w);
            if (lmb_dot3(w, x.ng) <= 0)
                break;
            lmb_rt_hit h;
            double cover;
            pr->rays++;
            if (!reference_hit(job, o, w, x.eps, &rng, beta, &h, &cover))
                break;
            double albedo[3], unused[3];
            lmb_hit_kind kind = lmb_cache_lookup(job->cache, &h, albedo, unused);
            if (kind == LMB_HIT_DARK)
                break;
            for (int k = 0; k < 3; k++)
                albedo[k] *= cover;
            lmb_shading_point y;
            hit_point(job->rt, o, w, &h, &y);
            int back = kind == LMB_HIT_BACK; /* a back that reflects: the path goes on from it */
            double through[3];
            if (job->cache->diffuse_through && lmb_cache_diffuse_through(job->cache, &h, through) > 0) {
                /* reflect or go through, by their weights (each then divided by its probability) */
                double lr = lmb_luminance(albedo), lt = lmb_luminance(through), q = lr / (lr + lt);
                if (!(lr + lt > 0))
                    break;
                int reflect = lmb_rng_next(&rng) < q;
                for (int k = 0; k < 3; k++)
                    albedo[k] = reflect ? albedo[k] / q : cover * through[k] / (1 - q);
                back ^= !reflect;
            }
            for (int k = 0; back && k < 3; k++)
                y.n[k] = y.ng[k] = -y.ng[k];
            double e[3];
            pr->rays += lmb_direct_at(job->direct, &y, 1, &rng, e, NULL);
            /* cosine sampling: f / p = pi B = pi albedo/pi E, so the path weight gains rho = pi albedo/pi */
            for (int k = 0; k < 3; k++) {
                beta[k] *= LMB_PI * albedo[k];
                sum[k] += beta[k] * e[k];
            }
            if (!(beta[0] + beta[1] + beta[2] > 0))
                break;
            x = y;
            for (int k = 0; k < 3; k++)
                o[k] = y.p[k] + y.ng[k] * y.eps;
        }
    }
    for (int k = 0; k < 3; k++)
        out[k] = sum[k] / paths;
}

/* The texel's gather point, the origin of its rays and its random-stream key. */
static void point_setup(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, uint32_t i, point_rays *pr)
{
    memset(pr, 0, sizeof *pr);
    pr->job = job;
    pr->key = ((uint64_t)atlas << 32) | t->texel[i];
    lmb_texel_shading_point(job->direct, t, i, t->gather_at[i], &pr->sp);
    for (int k = 0; k < 3; k++)
        pr->o[k] = pr->sp.p[k] + pr->sp.ng[k] * pr->sp.eps;
}

/* The estimator at the point (the same stream whether a texel or a record asks); `more` picks
 * the stream of a record's second gather (lmb_gather_record). */
static lmb_status estimate_at(const lmb_gather_job *job, point_rays *pr, lmb_estimator_scratch *scratch,
                              const lmb_estimator_options *opt, lmb_estimate *est, int more)
{
    /* stream b = pass << 32 | 0xFFFFFFFF (0xFFFFFFFE: more): apart from the per-sample streams of hits */
    lmb_rng rng = lmb_rng_make(job->seed, pr->key, ((uint64_t)job->pass << 32) | (0xFFFFFFFFu - (more != 0)));
    return lmb_estimate_irradiance(opt, pr->sp.n, pr->sp.ng, rng, cached_radiance, pr, scratch, est);
}

/* Guided gathering's part in a per-texel pass: pilots first, then the texels they guide. */
typedef struct guide_phase {
    lmb_guide *guide; /* NULL: every texel gathers alone */
    int pilots;       /* 1: this sweep gathers the pilots; 0: the other texels */
    uint32_t lobes;   /* lobes a pilot learns */
} guide_phase;

static lmb_status gather_texel(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, uint32_t i,
                               const guide_phase *gp, lmb_estimator_scratch *scratch, float *out,
                               lmb_gather_stats *st)
{
    uint32_t pilot = gp->guide ? gp->guide->pilot_of[i] : UINT32_MAX;
    if (gp->guide && gp->pilots != (pilot != UINT32_MAX))
        return LMB_OK; /* the other sweep's texel */
    out[3 * (size_t)i] = out[3 * (size_t)i + 1] = out[3 * (size_t)i + 2] = 0;
    if (!t->valid[i])
        return LMB_OK;
    point_rays pr;
    point_setup(job, atlas, t, i, &pr);
    double e[3];
    if (job->reference) {
        reference(&pr, e);
    } else {
        lmb_estimator_options opt = job->estimator;
        lmb_mixture guide;
        if (pilot != UINT32_MAX)
            opt.learn_lobes = gp->lobes;
        else if (gp->guide && lmb_guide_find(gp->guide, t, i, pr.sp.p, pr.sp.n, &guide))
            opt.guide = &guide;
        lmb_estimate est;
        if (estimate_at(job, &pr, scratch, &opt, &est, 0) != LMB_OK)
            return LMB_ERR_INTERNAL;
        memcpy(e, est.e, sizeof e);
        st->adapted += est.adapted;
        if (pilot != UINT32_MAX) {
            lmb_guide_pilot *pl = &gp->guide->pilots[pilot];
            memcpy(pl->p, pr.sp.p, sizeof pl->p);
            memcpy(pl->n, pr.sp.n, sizeof pl->n);
            pl->reach = 2.0f * (float)gp->guide->stride * t->texel_size[i];
            pl->mixture = est.learned;
        }
    }
    for (int k = 0; k < 3; k++)
        out[3 * (size_t)i + k] = (float)e[k];
    st->rays += pr.rays;
    st->texels++;
    return LMB_OK;
}

/*
 * A record's rays by its own noise (samples.noise, final gather): its error is copied to every
 * texel it serves, so when its estimated standard error sqrt(est->var) is above noise_target x
 * the light there (the last pass's, from the cache), it gathers again with the rays that bring
 * the error to the target, est->var / target^2 x N in all (at most max_rays), from a stream of
 * its own and guided by what it was guided by or learned; out->e and out->rot become the
 * ray-weighted mean of both gathers (each unbiased).
 */
static lmb_status more_rays(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, uint32_t i,
                            const lmb_estimator_options *opt, double max_rays, const lmb_estimate *est, int guided,
                            point_rays *pr, lmb_estimator_scratch *scratch, lmb_gather_point_result *out,
                            lmb_gather_stats *st)
{
    if (!(job->noise_target > 0) || !(est->var > 0) || !job->cache || job->reference)
        return LMB_OK;
    double shown = lmb_luminance_f(job->cache->irradiance[atlas] + 3 * (size_t)t->texel[i]);
    double target = job->noise_target * shown;
    if (!(target > 0) || est->var <= target * target)
        return LMB_OK;
    double want = ceil(opt->rays * est->var / (target * target));
    st->extended++;
    if (want > max_rays) {
        want = max_rays;
        st->capped++;
    }
    if (want <= opt->rays)
        return LMB_OK;
    lmb_estimator_options again = *opt;
    again.rays = (uint32_t)(want - opt->rays);
    again.learn_lobes = 0;
    if (!guided && est->learned.count)
        again.guide = &est->learned;
    lmb_estimate second;
    if (estimate_at(job, pr, scratch, &again, &second, 1) != LMB_OK)
        return LMB_ERR_INTERNAL;
    double a = (double)opt->rays / want, b = 1 - a;
    out->var = a * a * est->var + b * b * (second.var > 0 ? second.var : 0);
    for (int k = 0; k < 3; k++) {
        out->e[k] = a * est->e[k] + b * second.e[k];
        for (int c = 0; c < 3; c++)
            out->rot[k][c] = a * est->rot[k][c] + b * second.rot[k][c];
    }
    return LMB_OK;
}

lmb_status lmb_gather_record(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, uint32_t i,
                            const lmb_mixture *guide, uint32_t learn_lobes, double ray_share,
                            lmb_estimator_scratch *scratch, lmb_gather_point_result *out, lmb_gather_stats *st)
{
    point_rays pr;
    point_setup(job, atlas, t, i, &pr);
    lmb_estimator_options opt = job->estimator;
    double max_rays = job->max_rays;
    if (ray_share < 1) {
        double rays = floor(opt.rays * ray_share + 0.5);
        opt.rays = rays < 1 ? 1 : (uint32_t)rays;
        max_rays = floor(max_rays * ray_share + 0.5);
    }
    opt.gradient = 1;
    opt.guide = guide;
    int guided = lmb_estimator_guided(&opt);
    opt.learn_lobes = guided ? 0 : learn_lobes;
    pr.cosine_samples = lmb_estimator_cosine_samples(&opt);
    lmb_estimate est;
    if (estimate_at(job, &pr, scratch, &opt, &est, 0) != LMB_OK)
        return LMB_ERR_INTERNAL;
    memcpy(out->p, pr.sp.p, sizeof out->p);
    memcpy(out->n, pr.sp.n, sizeof out->n);
    memcpy(out->e, est.e, sizeof out->e);
    memcpy(out->rot, est.rot, sizeof out->rot);
    out->var = est.var > 0 ? est.var : 0;
    if (guided)
        out->harmonic = est.cos_inverse_distance > 0 ? est.cos_weight / est.cos_inverse_distance : HUGE_VAL;
    else
        out->harmonic = pr.inverse_distances > 0 ? pr.distances / pr.inverse_distances : HUGE_VAL;
    out->learned = est.learned;
    if (more_rays(job, atlas, t, i, &opt, max_rays, &est, guided, &pr, scratch, out, st) != LMB_OK)
        return LMB_ERR_INTERNAL;
    st->rays += pr.rays;
    st->texels++;
    st->adapted += est.adapted;
    return LMB_OK;
}

/*
 * The indirect part of a texel's light direction (directional lightmaps): `rays` stratified
 * cosine-distributed rays read the finished cache; with p(w) = cos / pi,
 *   v = integral L(w) w cos dw  ~  pi / N sum lum(L(w_i)) w_i,
 * the irradiance-weighted direction sum in the units of lmb_direct_at's dir (lux).
 */
static void texel_direction(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, uint32_t i, uint32_t rays,
                            float *out, uint64_t *traced)
{
    double v[3] = {0, 0, 0};
    out[3 * (size_t)i] = out[3 * (size_t)i + 1] = out[3 * (size_t)i + 2] = 0;
    if (!t->valid[i])
        return;
    point_rays pr;
    point_setup(job, atlas, t, i, &pr);
    uint32_t sx = (uint32_t)ceil(sqrt((double)rays)), sy = (rays + sx - 1) / sx;
    lmb_lobe cosine = {{pr.sp.n[0], pr.sp.n[1], pr.sp.n[2]}, 1.0};
    for (uint32_t s = 0; s < rays; s++) {
        /* pass + 1: apart from the streams of light samples at unmapped hits (pass, s) */
        lmb_rng rng = lmb_rng_make(job->seed, pr.key, ((uint64_t)(job->pass + 1) << 32) | s);
        double u1 = ((s % sx) + lmb_rng_next(&rng)) / sx, u2 = (((s / sx) % sy) + lmb_rng_next(&rng)) / sy, w[3], l[3];
        lmb_lobe_sample(&cosine, u1, u2, w);
        if (lmb_dot3(w, pr.sp.ng) <= 0)
            continue;
        cached_radiance(&pr, w, s, l);
        double lum = lmb_luminance(l);
        for (int k = 0; k < 3; k++)
            v[k] += lum * w[k];
    }
    for (int k = 0; k < 3; k++)
        out[3 * (size_t)i + k] = (float)(LMB_PI * v[k] / rays);
    *traced += pr.rays;
}

lmb_status lmb_gather_directions(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, uint32_t first,
                                 uint32_t last, uint32_t rays, float *out, lmb_gather_stats *stats)
{
    int threads = job->threads ? (int)job->threads : omp_get_max_threads();
    uint64_t traced = 0;
#pragma omp parallel num_threads(threads) reduction(+ : traced)
    {
        lmb_rt_thread_init();
#pragma omp for schedule(dynamic, 64)
        for (uint32_t i = first; i < last; i++)
            texel_direction(job, atlas, t, i, rays, out, &traced);
    }
    stats->rays += traced;
    stats->texels += last - first;
    return LMB_OK;
}

/* One sweep over the atlas's texels in blocks (progress after each block when `report`). */
static int sweep(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, uint32_t first, uint32_t last,
                 const guide_phase *gp, int report, float *out, lmb_gather_stats *stats)
{
    const uint32_t block = 256;
    int threads = job->threads ? (int)job->threads : omp_get_max_threads(), failed = 0;
    for (uint32_t start = first; start < last && !failed; start += block) {
        uint32_t end = start + block < last ? start + block : last;
        uint64_t rays = 0, texels = 0, adapted = 0;
#pragma omp parallel num_threads(threads) reduction(+ : rays, texels, adapted, failed)
        {
            lmb_rt_thread_init();
            lmb_estimator_scratch scratch = {0};
            lmb_gather_stats st = {0};
#pragma omp for schedule(dynamic, 4)
            for (uint32_t i = start; i < end; i++)
                if (gather_texel(job, atlas, t, i, gp, &scratch, out, &st) != LMB_OK)
                    failed = 1;
            lmb_estimator_scratch_free(&scratch);
            rays += st.rays;
            texels += st.texels;
            adapted += st.adapted;
        }
        stats->rays += rays;
        stats->texels += texels;
        stats->adapted += adapted;
        if (report && job->progress)
            job->progress(job->progress_user, job->stage, job->progress_done + end, job->progress_total);
    }
    return !failed;
}

int lmb_gather_is_guided(const lmb_gather_job *job)
{
    return !job->reference && job->guide_stride > 0 && lmb_estimator_can_guide(&job->estimator);
}

lmb_status lmb_gather_atlas(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, float *out,
                            lmb_gather_stats *stats, lmb_error *err)
{
    return lmb_gather_texels(job, atlas, t, 0, t->count, out, stats, err);
}

lmb_status lmb_gather_texels(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, uint32_t first,
                             uint32_t last, float *out, lmb_gather_stats *stats, lmb_error *err)
{
    lmb_guide guide;
    guide_phase gp = {NULL, 0, job->guide_lobes};
    if (lmb_gather_is_guided(job) && (first != 0 || last != t->count))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: a guided gather runs over whole atlases", job->stage);
    if (lmb_gather_is_guided(job)) {
        if (!lmb_guide_init(&guide, t, job->guide_stride))
            return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory for the guide of atlas %u", job->stage,
                                 atlas);
        gp.guide = &guide;
        gp.pilots = 1;
    }
    int ok = 1;
    if (gp.guide) { /* the pilots first: every guided texel reads a finished mixture */
        ok = sweep(job, atlas, t, first, last, &gp, 0, out, stats);
        gp.pilots = 0;
    }
    ok = ok && sweep(job, atlas, t, first, last, &gp, 1, out, stats);
    if (gp.guide)
        lmb_guide_free(&guide);
    if (!ok)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory for %u gather samples", job->stage,
                             job->estimator.rays);
    return LMB_OK;
}
