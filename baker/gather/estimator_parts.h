/*
 * What the final-gather estimators share (internal to baker/gather): the sample streams, the
 * draw-and-trace step, the rotation gradient's term, and the estimators estimator.c dispatches
 * to: classic (estimator.c), the paper's AMIS (amis_paper.c), lmbake's unbiased AMIS and guided
 * gathering (amis.c).
 */
#ifndef LMBAKE_ESTIMATOR_PARTS_H
#define LMBAKE_ESTIMATOR_PARTS_H

#include "gather/estimator.h"
#include "util/lmb_math.h"

#include <string.h>

/* Grows the scratch to n samples; 0 when out of memory. */
int lmb_estimator_scratch_reserve(lmb_estimator_scratch *s, uint32_t n);

static inline double luminance(const double c[3])
{
    return lmb_luminance(c);
}

/* The variance of the mean of n samples y from their sum and sum of squares (0 when n < 2). */
static inline double lmb_sample_variance_of_mean(double sum, double sum2, uint32_t n)
{
    if (n < 2)
        return 0;
    double v = (sum2 - sum * sum / n) / ((double)n - 1);
    return v > 0 ? v / n : 0;
}

/* The numbers of sample j: counter-based, whatever the method. */
static inline void sample_uniforms(lmb_rng rng, uint32_t j, double u[3])
{
    rng.counter = 4 * (uint64_t)j;
    u[0] = lmb_rng_next(&rng);
    u[1] = lmb_rng_next(&rng);
    u[2] = lmb_rng_next(&rng);
}

/* Sample j's direction from `lobe` into w; when it lies above the surface (shading and
 * geometric normals) traces it: l = radiance, *c = w.n, returns 1. Shared by both methods so
 * that the same stream gives the same rays. */
static inline int draw_and_trace(const lmb_lobe *lobe, double frame[2][3], const lmb_lobe *cosine, const double ng[3],
                          const double u[3], uint32_t j, lmb_radiance_fn radiance, void *user, double w[3], double l[3],
                          double *c, double *dist, lmb_estimate *out)
{
    if (frame)
        lmb_lobe_sample_in_frame(lobe, frame[0], frame[1], u[0], u[1], w);
    else
        lmb_lobe_sample(lobe, u[0], u[1], w);
    *c = lmb_dot3(w, cosine->axis);
    if (*c <= 0 || lmb_dot3(w, ng) <= 0)
        return 0;
    *dist = radiance(user, w, j, l);
    out->traced++;
    return 1;
}

/* Keeps a traced sample for re-weighting and fitting: direction w, integrand f = l c and its
 * luminance. Returns its index, or -1 when f is 0 (it adds nothing to any estimate or fit). */
static inline int64_t keep_sample(lmb_estimator_scratch *s, const double w[3], const double l[3], double c)
{
    double f[3] = {l[0] * c, l[1] * c, l[2] * c}, lum = luminance(f);
    if (!(lum > 0))
        return -1;
    uint32_t q = s->count++;
    memcpy(s->w + 3 * q, w, 3 * sizeof *w);
    memcpy(s->f + 3 * q, f, sizeof f);
    s->lum[q] = lum;
    return q;
}

/* The rotation gradient's term of a sample of weight x = f / (N q) per channel (estimator.h). */
static inline void add_rotation(lmb_estimate *out, const double n[3], const double w[3], double c, const double x[3])
{
    double nxw[3];
    lmb_cross3(n, w, nxw);
    for (int ch = 0; ch < 3; ch++)
        for (int k = 0; k < 3; k++)
            out->rot[ch][k] += x[ch] / c * nxw[k];
}

/* T as the options give it, within 1..LMB_AMIS_MAX_ITERATIONS. */
static inline uint32_t iteration_count(const lmb_estimator_options *opt)
{
    return opt->iterations < 1 ? 1 : opt->iterations > LMB_AMIS_MAX_ITERATIONS ? LMB_AMIS_MAX_ITERATIONS : opt->iterations;
}

void lmb_estimate_classic(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3], lmb_rng rng,
                          lmb_radiance_fn radiance, void *user, lmb_estimate *out);
lmb_status lmb_amis_balance(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3], lmb_rng rng,
                            lmb_radiance_fn radiance, void *user, lmb_estimator_scratch *s, lmb_estimate *out);
lmb_status lmb_amis_unbiased(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3], lmb_rng rng,
                             lmb_radiance_fn radiance, void *user, lmb_estimator_scratch *s, lmb_estimate *out);
void lmb_amis_guided(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3], lmb_rng rng,
                     lmb_radiance_fn radiance, void *user, lmb_estimate *out);

#endif
