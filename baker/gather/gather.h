/*
 * The gather stage: indirect irradiance at every valid texel of an atlas, at the texel's first
 * point outside geometry (indirect light varies slowly; direct light keeps all the texel's
 * points). Two kinds of pass:
 *   - a cache pass (bounce passes and the final gather): one estimator per texel (classic,
 *     AMIS or defensive AMIS, estimator.h) whose rays read the bounce cache (bounce_cache.h);
 *   - the reference (`lmbake bake --reference`): brute-force path tracing with no cache. Each
 *     path samples the cosine lobe at every vertex and adds next-event estimates of direct
 *     light (lmb_direct_at) at each hit, depth = bounces: E_ind = sum_k (rho_1 ... rho_k) E_d(y_k),
 *     the estimator pi L(y_1) under cosine sampling unrolled (path vertices use their geometric
 *     normal).
 * Random numbers are keyed by (seed, atlas and texel, pass, sample): results do not depend on
 * the thread count.
 */
#ifndef LMBAKE_GATHER_H
#define LMBAKE_GATHER_H

#include <lmbake/lmbake.h>

#include "cache/bounce_cache.h"
#include "gather/estimator.h"
#include "lights/direct.h"

typedef struct lmb_gather_job {
    const lmb_direct *direct;   /* lights, for hits on surfaces without a lightmap and the reference */
    const lmb_cache *cache;     /* the previous pass (unused by the reference) */
    const lmb_rt *rt;
    uint64_t seed;
    uint32_t threads;           /* 0: all cores */
    lmb_estimator_options estimator;
    int reference;              /* path tracing, estimator.rays paths per texel */
    uint32_t depth;             /* reference: bounces */
    uint32_t pass;              /* keys the random streams */
    uint32_t guide_stride;      /* guided gathering: pilot texels every this many texels (0: off; guide.h) */
    uint32_t guide_lobes;       /* lobes a pilot learns (gather.lobes) */
    int direct_at_hits;         /* the cache holds indirect light only; direct light is computed
                                   at each hit with shadow rays (gather.direct_at_hits) */
    int unmapped_dark;          /* hits on surfaces without a lightmap bring nothing: a bounce pass after the
                                   first gathers what the last pass added (D_b = K D_{b-1}), and such a
                                   surface's only light, its direct light, was the first pass's */
    const char *stage;          /* progress stage name */
    lmb_progress_fn progress;
    void *progress_user;
    uint64_t progress_done, progress_total; /* texels before this atlas, texels of the whole pass */
    struct lmb_steps *steps;    /* where the pass's gathers run (steps/runner.h) */
    double noise_target;        /* > 0 (the final gather with samples.adaptive): a record whose estimated
                                   standard error is above this share of the light there (the last pass's,
                                   in the cache) gathers more rays, up to max_rays in all */
    uint32_t max_rays;
} lmb_gather_job;

typedef struct lmb_gather_stats {
    uint64_t rays;      /* rays traced (gather rays, and shadow rays at hits) */
    uint64_t texels;    /* texels gathered */
    uint64_t adapted;   /* AMIS: lobe updates that changed the lobe */
    uint64_t records;   /* irradiance cache: records placed (texels counts their gathers too) */
    uint64_t extended;  /* records that gathered more rays for noise_target */
    uint64_t capped;    /* of those, stopped at max_rays short of it */
} lmb_gather_stats;

/* One gather at listed texel i's gather point, as an irradiance-cache record needs it. */
typedef struct lmb_gather_point_result {
    double p[3], n[3];  /* the gather point and its shading normal */
    double e[3];        /* irradiance (the same value lmb_gather_atlas gives the texel) */
    double rot[3][3];   /* rotation gradient per channel (estimator.h) */
    double var;         /* the variance of lum(e) as an estimate (0: not estimated), for the denoiser */
    double harmonic;    /* harmonic mean hit distance of its cosine-distributed rays (HUGE_VAL: none hit;
                           guided: of all its rays, weighted p_cos / q) */
    lmb_mixture learned; /* with learn_lobes: what it learned for its neighbours (guide.h) */
} lmb_gather_point_result;

/* guide: a mixture to gather by (lmb_estimator_guided; NULL: none); learn_lobes > 0: fit one
 * (out->learned) when not guided. ray_share in (0, 1]: this share of the job's rays and of its
 * max_rays (1: the job's). */
lmb_status lmb_gather_record(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, uint32_t i,
                            const lmb_mixture *guide, uint32_t learn_lobes, double ray_share,
                            lmb_estimator_scratch *scratch, lmb_gather_point_result *out, lmb_gather_stats *st);

/* The indirect part of every listed texel's light direction (directional lightmaps): the
 * irradiance-weighted sum of incoming directions, sum lum(L) w cos over the hemisphere (lux),
 * from `rays` cosine rays that read the finished cache (job->direct_at_hits must be off: the
 * cache then holds all the light). Listed texels [first, last): 3 floats per texel into out
 * (indexed by texel); 0 for invalid texels. */
lmb_status lmb_gather_directions(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, uint32_t first,
                                 uint32_t last, uint32_t rays, float *out, lmb_gather_stats *stats);

/* Indirect irradiance of every listed texel of t (atlas `atlas`) into out (3 floats per texel;
 * 0 for invalid texels). */
lmb_status lmb_gather_atlas(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, float *out,
                            lmb_gather_stats *stats, lmb_error *err);

/* The same for listed texels [first, last) only (out indexed by texel). A guided gather
 * (lmb_gather_is_guided: pilots first, then the texels they guide) takes whole atlases only. */
lmb_status lmb_gather_texels(const lmb_gather_job *job, uint32_t atlas, const lmb_texels *t, uint32_t first,
                             uint32_t last, float *out, lmb_gather_stats *stats, lmb_error *err);
int lmb_gather_is_guided(const lmb_gather_job *job);

#endif
