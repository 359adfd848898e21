/*
 * The paper's AMIS (estimator.h, `gather.amis_weights: balance`). Notation of DESIGN.md section 4: lobe
 * theta_t = (n^_t, a_t), N_t samples at iteration t, mixture pdf of iteration t
 * q_t = d p_cos + (1 - d) p(.; theta_t) (d = 0 for plain AMIS, and q_0 = p_cos always).
 * Each kept sample i carries denom_i = sum_{k<=t} N_k q_k(w_i), updated by one lobe
 * evaluation per sample per iteration, so re-weighting costs O(N T) pdf evaluations and no rays;
 * s_i = lum(f_i) / denom_i (eq. 3 with the balance heuristic) drives eqs. 4 and 2, and the
 * estimate is sum_i f_i / denom_i (per channel). Samples with f = 0 add nothing to either and
 * are not kept.
 */
#include "gather/estimator_parts.h"

#include <stdlib.h>
#include <string.h>

/* q_t(w): the pdf iteration t sampled from. */
static double mixture_pdf(const lmb_lobe *cosine, const lmb_lobe *lobe, double d, const double w[3])
{
    double p = lmb_lobe_pdf(lobe, w);
    return d > 0 ? d * lmb_lobe_pdf(cosine, w) + (1.0 - d) * p : p;
}

/* Eqs. 4 and 2 over the kept samples: the next lobe, or 0 when nothing was seen. */
static int next_lobe(const lmb_estimator_scratch *s, lmb_lobe *next)
{
    double sum = 0, v[3] = {0, 0, 0};
    for (uint32_t i = 0; i < s->count; i++) {
        double si = s->lum[i] / s->denom[i];
        s->si[i] = si;
        sum += si;
        for (int k = 0; k < 3; k++)
            v[k] += si * s->w[3 * i + k];
    }
    double len = sqrt(lmb_dot3(v, v));
    if (!(sum > 0) || !(len > 0))
        return 0;
    double axis[3] = {v[0] / len, v[1] / len, v[2] / len}, lsum = 0;
    for (uint32_t i = 0; i < s->count; i++) {
        double c = fabs(lmb_dot3(s->w + 3 * i, axis));
        lsum += s->si[i] * (double)logf((float)(c > 1e-6 ? c : 1e-6));
    }
    double a = lsum < 0 ? -1.0 - sum / lsum : LMB_AMIS_MAX_EXPONENT;
    if (!(a >= 0))
        a = 0;
    if (a > LMB_AMIS_MAX_EXPONENT)
        a = LMB_AMIS_MAX_EXPONENT;
    memcpy(next->axis, axis, sizeof axis);
    next->a = a;
    return 1;
}

/* The paper's AMIS (balance weights over all lobes, eq. 3): consistent, not unbiased. */
lmb_status lmb_amis_balance(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3], lmb_rng rng,
                       lmb_radiance_fn radiance, void *user, lmb_estimator_scratch *s, lmb_estimate *out)
{
    uint32_t T = iteration_count(opt);
    double d = opt->method == LMB_GATHER_AMIS_DEFENSIVE ? opt->defensive : 0.0;
    lmb_lobe lobes[LMB_AMIS_MAX_ITERATIONS];
    double nk[LMB_AMIS_MAX_ITERATIONS];
    if (!lmb_estimator_scratch_reserve(s, opt->rays))
        return LMB_ERR_INTERNAL;
    s->count = 0;
    lobes[0] = *cosine;
    uint32_t j = 0;
    for (uint32_t t = 0; t < T; t++) {
        uint32_t n_t = opt->rays / T + (t < opt->rays % T), first_new = s->count;
        nk[t] = (double)n_t;
        for (uint32_t i = 0; i < n_t; i++, j++) {
            double u[3], w[3], l[3];
            sample_uniforms(rng, j, u);
            const lmb_lobe *lobe = &lobes[t];
            if (d > 0 && u[2] < d)
                lobe = cosine;
            double c, dist;
            if (!draw_and_trace(lobe, NULL, cosine, ng, u, j, radiance, user, w, l, &c, &dist, out))
                continue;
            int64_t q = keep_sample(s, w, l, c);
            if (q < 0)
                continue;
            (void)dist;
            s->denom[q] = 0;
            for (uint32_t k = 0; k < t; k++) /* a new sample sees every earlier lobe once */
                s->denom[q] += nk[k] * mixture_pdf(cosine, &lobes[k], d, w);
            s->denom[q] += nk[t] * mixture_pdf(cosine, &lobes[t], d, w); /* N_t q_t(w) */
        }
        for (uint32_t q = 0; q < first_new; q++) /* ... and every earlier sample the lobe of iteration t */
            s->denom[q] += nk[t] * mixture_pdf(cosine, &lobes[t], d, s->w + 3 * q);
        if (t + 1 < T) {
            lobes[t + 1] = lobes[t];
            if (next_lobe(s, &lobes[t + 1]))
                out->adapted++;
        }
    }
    for (uint32_t q = 0; q < s->count; q++) {
        double x[3];
        for (int k = 0; k < 3; k++)
            out->e[k] += x[k] = s->f[3 * q + k] / s->denom[q];
        if (opt->gradient)
            add_rotation(out, cosine->axis, s->w + 3 * q, lmb_dot3(s->w + 3 * q, cosine->axis), x);
    }
    out->last = lobes[T - 1];
    return LMB_OK;
}

