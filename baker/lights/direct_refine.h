/*
 * Adaptive direct light (samples.noise): once the lightmap's light is known (after the final
 * gather, or after the direct step when no gather runs), every texel whose direct light is
 * noisier than samples.noise times its light is computed again with as many rounds of the
 * sampled lights as its measured variance asks, up to samples.max_rays samples. The noise an
 * artist sees is relative to the whole light: a penumbra under bright bounced light needs few
 * samples; where direct light is all there is, it needs its own. A step of the bake (bands of
 * rows, as the direct step): byte-identical under any split, since a texel computed again
 * repeats its first rounds exactly and continues them (texel_direct.c).
 */
#ifndef LMBAKE_DIRECT_REFINE_H
#define LMBAKE_DIRECT_REFINE_H

#include "lights/direct_step.h"

typedef struct lmb_direct_noise {
    uint64_t texels;      /* valid texels with sampled light */
    uint64_t refined;     /* of those, computed again with more samples */
    uint64_t capped;      /* of those, stopped by samples.max_rays short of samples.noise */
    uint64_t samples;     /* samples the refinement added */
    int budget_limited;   /* some atlas asked for more than the budget (REFINE_BUDGET x the direct step's rays) */
    double loosened;      /* the largest k: the target reached was k x samples.noise (1: the target) */
    double median, p95;   /* estimated relative standard error per texel, of the light shown */
} lmb_direct_noise;

/* Refines atlas a's direct light in place (da: its texels, direct, direction, deferred and
 * variance arrays). shown: per listed texel the luminance of the lightmap's light (indirect +
 * direct - deferred) before refining. With samples.adaptive off nothing is refined, only measured.
 * Adds to *rays and to noise (median and p95 are set by lmb_direct_noise_finish). Afterwards
 * da->variance holds each texel's estimate's variance (a round's over its rounds), not a round's. */
lmb_status lmb_direct_refine_step(lmb_steps *steps, const lmb_direct *direct,
                                  const lmb_scene *scene, const lmb_layout *layout, uint32_t a, const double *shown,
                                  lmb_progress_fn progress, void *progress_user, lmb_direct_atlas *da, uint64_t *rays, lmb_direct_noise *noise, float **estimates,
                                  uint64_t *estimate_count, lmb_error *err);

/* noise->median and p95 from the estimates collected over every atlas (frees them). */
void lmb_direct_noise_finish(lmb_direct_noise *noise, float *estimates, uint64_t count);

/* stats and the log: what the bake reached (nothing when no texel has sampled light). */
void lmb_direct_noise_report(const lmb_direct_noise *noise, const lmb_direct_options *opt, lmb_bake_stats *stats,
                             const lmb_log *log);

#endif
