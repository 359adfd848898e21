/*
 * The final-gather estimators of irradiance at one gather point, independent of ray tracing:
 * E = integral over the hemisphere of f(w) = L(w) max(0, w.n) dw, where L(w) is the radiance
 * arriving from direction w (a callback: one traced ray per call).
 *   classic:        cosine-weighted samples, E ~ 1/N sum f / p_cos.
 *   AMIS:           the paper's adaptive multiple importance sampling (DESIGN.md section 4):
 *                   T iterations of N_t samples from cosine-power lobes, every sample weighted by
 *                   the balance heuristic over all lobes so far (deterministic mixture, eq. 3),
 *                   the next lobe's axis by eq. 4 and exponent by the weighted MLE of eq. 2.
 *   AMIS defensive: every iteration samples the mixture q_t = d p_cos + (1 - d) p_t, so every
 *                   weight is bounded by f / (d N p_cos): at most 1/d times classic's variance
 *                   (Hesterberg's defensive importance sampling); d = 0 is the paper exactly.
 *                   The default, guided below.
 * AMIS as the paper gives it is consistent, not unbiased: a sample is re-weighted by lobes that
 * were fitted to it, which lowers the weight of exactly the samples that found a bright spot
 * (measured: -10% at 1024 rays on some Cornell box texels, -15% for two caps in
 * tests/unit/test_estimator.c). With `unbiased` (amis.c) iteration t samples a pdf q_t fixed
 * before its samples: the cosine lobe at t = 0, then d p_cos + (1 - d) F_t, F_t the cosine
 * share and lobe fitted by a few EM steps (mixture.h: eqs. 2 and 4 per lobe) to the earlier
 * samples weighted lum(f)/q; without a defensive share, the mixture of p_cos and F_1..F_t by
 * their sample counts. E = sum_t a_t (1/N_t) sum_i f / q_t: each term is unbiased, and the
 * shares a_t depend on earlier iterations only (their measured variances; Owen, "Monte Carlo
 * theory", ch. 10.5) and sum to 1, so E is unbiased.
 *   Guided (options.guide, unbiased defensive AMIS with T >= 2): a mixture G learned at a
 * neighbouring point before this point's samples (spatial reuse, guide.h); every sample is
 * drawn from d p_cos + (1 - d) G and E = 1/N sum f / q: one importance-sampling estimate with
 * a fixed pdf, unbiased. options.learn_lobes fits the mixture a point passes on (out->learned).
 * A sample whose direction lies below the geometric normal has f = 0 and traces no ray.
 * Rotation gradient (options.gradient): turning the normal by the small rotation vector v
 * changes w.n by v.(n x w), so dE/dv = integral of L(w) (n x w) dw (Ward and Heckbert 1992's
 * rotation gradient, written for any pdf): every sample adds its weight f/q times
 * (n x w) / (w.n), with the same weights as E, so it is unbiased whenever E is.
 * Random numbers: sample j of the point uses counter 4j.. of the caller's stream, so the
 * same stream gives the same directions to every method (AMIS with T = 1 is classic
 * gathering, bit for bit).
 */
#ifndef LMBAKE_ESTIMATOR_H
#define LMBAKE_ESTIMATOR_H

#include <lmbake/lmbake.h>

#include "util/sampling.h"
#include "gather/mixture.h"
#include "util/rng.h"

#define LMB_AMIS_MAX_ITERATIONS 64
#define LMB_AMIS_MAX_EXPONENT 1000.0 /* a lobe narrower than ~4 degrees (half width) is not learned */

/* Radiance (RGB) arriving from unit direction w; `sample` is the sample's index at the point.
 * Returns the distance to what it came from (INFINITY: the ray escaped), which lets a learned
 * mixture aim its lobes at the same places from a neighbouring point (mixture.h). */
typedef double (*lmb_radiance_fn)(void *user, const double w[3], uint32_t sample, double out[3]);

typedef struct lmb_estimator_options {
    lmb_gather_method method;
    uint32_t rays;       /* samples N (all iterations together) */
    uint32_t iterations; /* T, AMIS only; 1..LMB_AMIS_MAX_ITERATIONS */
    double defensive;    /* d, AMIS defensive only, in [0, 1) */
    int unbiased;        /* AMIS: weight each iteration's samples by its own pdf (see above) */
    int gradient;        /* also estimate the rotation gradient (irradiance cache records) */
    /* guided gathering (unbiased AMIS with a defensive share, T >= 2): a mixture learned at a
     * neighbouring point before this point's samples (spatial reuse); NULL or empty: none */
    const lmb_mixture *guide;
    uint32_t learn_lobes; /* > 0: fit a mixture of up to this many lobes to all samples (out->learned) */
} lmb_estimator_options;

/* Per-thread memory for the AMIS samples (grows as needed; free with lmb_estimator_scratch_free). */
typedef struct lmb_estimator_scratch {
    uint32_t cap, count;
    double *w, *f;        /* 3 each per kept sample: direction, integrand f (RGB) */
    double *lum, *denom;  /* luminance of f; sum over lobes so far of N_k q_k(w) */
    double *own;          /* unbiased AMIS: q_t(w), the pdf the sample was drawn from */
    uint32_t *iteration;  /* unbiased AMIS: the sample's iteration t */
    double *dist;         /* unbiased AMIS: the sample's hit distance */
    double *si;           /* eq. 3's s_i of the current lobe update */
    lmb_mixture_scratch fit;
} lmb_estimator_scratch;

typedef struct lmb_estimate {
    double e[3];       /* irradiance estimate */
    uint32_t traced;   /* rays traced (samples above the surface) */
    lmb_lobe last;     /* the last lobe used (AMIS), or the cosine lobe */
    uint32_t adapted;  /* iterations that changed the lobe */
    double rot[3][3];  /* with options.gradient: per channel, dE/d(rotation vector of the normal) */
    lmb_mixture learned; /* with options.learn_lobes: the mixture fitted to all samples (count 0: none) */
    /* classic and guided gathering with options.gradient: the cosine-weighted harmonic mean hit distance, as importance weights
     * p_cos / q over its traced samples: sum of p_cos/q and of p_cos/q / t (t = inf adds 0) */
    double cos_weight, cos_inverse_distance;
    double share[LMB_AMIS_MAX_ITERATIONS]; /* unbiased AMIS: the weight a_t given to iteration t */
    double var; /* the estimated variance of lum(e), from the samples themselves: classic and guided,
                   var(lum f / q) / N; unbiased AMIS, sum_t a_t^2 var_t / N_t; 0 for balance weights */
} lmb_estimate;

void lmb_estimator_scratch_free(lmb_estimator_scratch *s);

/* Whether these options can gather guided (unbiased defensive AMIS, T >= 2): a pass with them
 * gathers pilots first and guides the rest (gather/guide.h, the irradiance cache's records). */
int lmb_estimator_can_guide(const lmb_estimator_options *opt);

/* Whether these options gather guided (a learned guide given to unbiased defensive AMIS, T >= 2). */
int lmb_estimator_guided(const lmb_estimator_options *opt);

/* How many leading samples (indices 0..) are drawn from the cosine lobe: all of classic's,
 * AMIS's first iteration. */
uint32_t lmb_estimator_cosine_samples(const lmb_estimator_options *opt);

/* Estimates E at a point with shading normal n and geometric normal ng (both unit). Returns
 * LMB_ERR_INTERNAL only when the scratch cannot grow (out of memory). */
lmb_status lmb_estimate_irradiance(const lmb_estimator_options *opt, const double n[3], const double ng[3],
                                   lmb_rng rng, lmb_radiance_fn radiance, void *user, lmb_estimator_scratch *scratch,
                                   lmb_estimate *out);

#endif
