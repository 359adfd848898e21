/*
 * A learned directional distribution for guided gathering: a share of the cosine lobe around
 * the surface normal (the diffuse part: light from everywhere) and K cosine-power lobes
 * (util/sampling.h, eq. 1), g(w) = c p_cos(w) + (1 - c) sum_k pi_k p(w; n^_k, a_k), sum pi_k = 1.
 * A gather point learns one (lmb_mixture_fit) from its weighted samples; its neighbours sample
 * from it (spatial reuse, estimator.h), each lobe re-aimed at the place its light came from
 * (lmb_mixture_reaim: parallax).
 * Fitting is weighted maximum likelihood by EM (Dempster et al. 1977) with the AMIS paper's
 * updates per lobe: the E-step gives each sample i a responsibility r_ik per component, the
 * M-step applies eq. 4 (axis = normalised sum of s_i r_ik w_i) and eq. 2 (exponent
 * a_k = -1 - sum s_i r_ik / sum s_i r_ik ln(w_i . n^_k)) per lobe; the shares are the
 * components' parts of the weights s_i (the integrand over the pdf it was drawn from). The
 * cosine component keeps its shape, only its share is learned. K is chosen per point by the
 * Bayesian information criterion over the effective sample size (sum s)^2 / sum s^2: a second
 * lobe must pay for its 4 parameters.
 */
#ifndef LMBAKE_MIXTURE_H
#define LMBAKE_MIXTURE_H

#include "util/sampling.h"

#include <stdint.h>

#define LMB_MIXTURE_MAX_LOBES 3

typedef struct lmb_mixture {
    uint32_t count;                           /* K; 0 = nothing learned */
    double diffuse;                           /* c: the cosine lobe's share */
    lmb_lobe lobe[LMB_MIXTURE_MAX_LOBES];
    double weight[LMB_MIXTURE_MAX_LOBES];     /* pi_k, summing to 1 */
    double tangent[LMB_MIXTURE_MAX_LOBES][3]; /* each lobe's frame (lmb_frame), for sampling */
    double bitangent[LMB_MIXTURE_MAX_LOBES][3];
    /* where each lobe's light comes from, relative to the point it was fitted at: the weighted
     * centroid of its samples' hit points; aimed[k] = 0 when most of its weight escaped (sky) */
    double target[LMB_MIXTURE_MAX_LOBES][3];
    int aimed[LMB_MIXTURE_MAX_LOBES];
} lmb_mixture;

/* Whether the mixture holds anything learned (all-diffuse counts: it says "sample the cosine lobe"). */
static inline int lmb_mixture_learned(const lmb_mixture *m)
{
    return m->count > 0 || m->diffuse > 0;
}

/* A mixture as kept between its fit and its re-aiming: without the frames, which
 * lmb_mixture_reaim sets again, and in single precision (108 bytes instead of 368: the
 * irradiance cache keeps one per record, a quarter of a million on a level of 1,900 props; a
 * sampling distribution needs no more digits than a float's). */
typedef struct lmb_mixture_kept {
    uint32_t count;
    uint8_t aimed[LMB_MIXTURE_MAX_LOBES];
    float diffuse;
    float axis[LMB_MIXTURE_MAX_LOBES][3];
    float exponent[LMB_MIXTURE_MAX_LOBES];
    float weight[LMB_MIXTURE_MAX_LOBES];
    float target[LMB_MIXTURE_MAX_LOBES][3];
} lmb_mixture_kept;

void lmb_mixture_keep(const lmb_mixture *m, lmb_mixture_kept *out);

/* The mixture fitted at `from` as seen from `to`: every aimed lobe turned towards its target
 * (parallax), exponents and shares kept; frames set. */
void lmb_mixture_reaim(const lmb_mixture *m, const double from[3], const double to[3], lmb_mixture *out);
void lmb_mixture_reaim_kept(const lmb_mixture_kept *m, const double from[3], const double to[3], lmb_mixture *out);

/* Per-thread memory of the fit. */
typedef struct lmb_mixture_scratch {
    uint32_t cap;
    float *w, *s, *r, *r2; /* directions (3 per sample), weights, responsibilities (K + 1 per sample, two models) */
    float *d;         /* hit distances */
} lmb_mixture_scratch;

void lmb_mixture_scratch_free(lmb_mixture_scratch *s);

/* Fits the cosine share around `normal` and up to max_lobes lobes to n weighted directions
 * (w: 3 doubles each, unit; s >= 0) whose samples hit at distances dist (NULL: unknown, no lobe
 * is aimed). Uses at most LMB_MIXTURE_FIT_SAMPLES of them (every k-th: the cost stays bounded).
 * Returns 0 (out->count = 0) when nothing carries weight or memory runs out. */
#define LMB_MIXTURE_FIT_SAMPLES 256
int lmb_mixture_fit(const double *w, const double *s, const double *dist, uint32_t n, const double normal[3],
                    uint32_t max_lobes, lmb_mixture_scratch *scratch, lmb_mixture *out);

/* A point's own adaptation between AMIS iterations: the cosine share and one lobe by a few EM
 * steps over its samples so far, from `start` (its previous update; NULL or not one lobe: from
 * scratch). Cheaper than lmb_mixture_fit: no choice of K, no targets. Returns 0 when nothing
 * carries weight. */
int lmb_mixture_update(const double *w, const double *s, uint32_t n, const double normal[3], const lmb_mixture *start,
                       lmb_mixture_scratch *scratch, lmb_mixture *out);

#endif
