/*
 * Final-gather estimators (see estimator.h). Notation of DESIGN.md section 4: lobe
 * theta_t = (n^_t, a_t), N_t samples at iteration t, mixture pdf of iteration t
 * q_t = d p_cos + (1 - d) p(.; theta_t) (d = 0 for plain AMIS, and q_0 = p_cos always).
 * Each kept sample i carries denom_i = sum_{k<=t} N_k q_k(w_i), updated by one lobe
 * evaluation per sample per iteration, so re-weighting costs O(N T) pdf evaluations and no rays;
 * s_i = lum(f_i) / denom_i (eq. 3 with the balance heuristic) drives eqs. 4 and 2, and the
 * estimate is sum_i f_i / denom_i (per channel). Samples with f = 0 add nothing to either and
 * are not kept.
 */
#include "estimator.h"

#include <stdlib.h>
#include <string.h>

void lmb_estimator_scratch_free(lmb_estimator_scratch *s)
{
    free(s->w);
    free(s->f);
    free(s->lum);
    free(s->denom);
    free(s->own);
    free(s->si);
    memset(s, 0, sizeof *s);
}

static int grow(double **p, size_t n)
{
    double *q = realloc(*p, n * sizeof *q);
    if (!q)
        return 0;
    *p = q;
    return 1;
}

static int scratch_reserve(lmb_estimator_scratch *s, uint32_t n)
{
    if (n <= s->cap)
        return 1;
    int ok = grow(&s->w, 3 * (size_t)n) & grow(&s->f, 3 * (size_t)n) & grow(&s->lum, n) & grow(&s->denom, n) &
             grow(&s->own, n) & grow(&s->si, n);
    if (ok)
        s->cap = n;
    return ok;
}

static double luminance(const double c[3])
{
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

/* The numbers of sample j: counter-based, whatever the method. */
static void sample_uniforms(lmb_rng rng, uint32_t j, double u[3])
{
    rng.counter = 4 * (uint64_t)j;
    u[0] = lmb_rng_next(&rng);
    u[1] = lmb_rng_next(&rng);
    u[2] = lmb_rng_next(&rng);
}

/* Sample j's direction from `lobe` into w; when it lies above the surface (shading and
 * geometric normals) traces it: l = radiance, *c = w.n, returns 1. Shared by both methods so
 * that the same stream gives the same rays. */
static int draw_and_trace(const lmb_lobe *lobe, const lmb_lobe *cosine, const double ng[3], const double u[3],
                          uint32_t j, lmb_radiance_fn radiance, void *user, double w[3], double l[3], double *c,
                          lmb_estimate *out)
{
    lmb_lobe_sample(lobe, u[0], u[1], w);
    *c = lmb_dot3(w, cosine->axis);
    if (*c <= 0 || lmb_dot3(w, ng) <= 0)
        return 0;
    radiance(user, w, j, l);
    out->traced++;
    return 1;
}

/* The rotation gradient's term of a sample of weight x = f / (N q) per channel (estimator.h). */
static void add_rotation(lmb_estimate *out, const double n[3], const double w[3], double c, const double x[3])
{
    double nxw[3];
    lmb_cross3(n, w, nxw);
    for (int ch = 0; ch < 3; ch++)
        for (int k = 0; k < 3; k++)
            out->rot[ch][k] += x[ch] / c * nxw[k];
}

/* Classic final gathering: E = 1/N sum f(w_j) / p_cos(w_j). */
static void classic(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3], lmb_rng rng,
                    lmb_radiance_fn radiance, void *user, lmb_estimate *out)
{
    for (uint32_t j = 0; j < opt->rays; j++) {
        double u[3], w[3], l[3], c;
        sample_uniforms(rng, j, u);
        if (!draw_and_trace(cosine, cosine, ng, u, j, radiance, user, w, l, &c, out))
            continue;
        double denom = (double)opt->rays * lmb_lobe_pdf(cosine, w), x[3];
        for (int k = 0; k < 3; k++)
            out->e[k] += x[k] = l[k] * c / denom;
        if (opt->gradient)
            add_rotation(out, cosine->axis, w, c, x);
    }
}

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

/* T as the options give it, within 1..LMB_AMIS_MAX_ITERATIONS. */
static uint32_t iteration_count(const lmb_estimator_options *opt)
{
    return opt->iterations < 1 ? 1 : opt->iterations > LMB_AMIS_MAX_ITERATIONS ? LMB_AMIS_MAX_ITERATIONS : opt->iterations;
}

uint32_t lmb_estimator_cosine_samples(const lmb_estimator_options *opt)
{
    uint32_t T = opt->method == LMB_GATHER_COSINE ? 1 : iteration_count(opt);
    return opt->rays / T + (opt->rays % T != 0); /* N_0, as amis() splits the rays */
}

static lmb_status amis(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3], lmb_rng rng,
                       lmb_radiance_fn radiance, void *user, lmb_estimator_scratch *s, lmb_estimate *out)
{
    uint32_t T = iteration_count(opt);
    double d = opt->method == LMB_GATHER_AMIS_DEFENSIVE ? opt->defensive : 0.0;
    lmb_lobe lobes[LMB_AMIS_MAX_ITERATIONS];
    double nk[LMB_AMIS_MAX_ITERATIONS];
    if (!scratch_reserve(s, opt->rays))
        return LMB_ERR_INTERNAL;
    s->count = 0;
    lobes[0] = *cosine;
    uint32_t j = 0;
    double share_sum = 0;
    for (uint32_t t = 0; t < T; t++)
        share_sum += (double)(opt->rays / T + (t < opt->rays % T)) * (t + 1);
    double s_t = 0; /* S_t = N_0 + ... + N_t */
    for (uint32_t t = 0; t < T; t++) {
        uint32_t n_t = opt->rays / T + (t < opt->rays % T), first_new = s->count;
        nk[t] = (double)n_t;
        s_t += nk[t];
        /* the unbiased estimate without a defensive share samples the mixture of lobes 0..t */
        int past_mixture = opt->unbiased && !(d > 0);
        for (uint32_t i = 0; i < n_t; i++, j++) {
            double u[3], w[3], l[3];
            sample_uniforms(rng, j, u);
            const lmb_lobe *lobe = &lobes[t];
            if (past_mixture) {
                double pick = u[2] * s_t, acc = 0;
                uint32_t k = 0;
                while (k < t && pick >= (acc += nk[k]))
                    k++;
                lobe = &lobes[k];
            } else if (d > 0 && u[2] < d) {
                lobe = cosine;
            }
            double c;
            if (!draw_and_trace(lobe, cosine, ng, u, j, radiance, user, w, l, &c, out))
                continue;
            double f[3] = {l[0] * c, l[1] * c, l[2] * c}, lum = luminance(f);
            if (!(lum > 0))
                continue;
            uint32_t q = s->count++;
            memcpy(s->w + 3 * q, w, sizeof w);
            memcpy(s->f + 3 * q, f, sizeof f);
            s->lum[q] = lum;
            s->denom[q] = 0;
            for (uint32_t k = 0; k < t; k++) /* a new sample sees every earlier lobe once */
                s->denom[q] += nk[k] * mixture_pdf(cosine, &lobes[k], d, w);
            double own = nk[t] * mixture_pdf(cosine, &lobes[t], d, w); /* N_t q_t(w) */
            s->denom[q] += own;
            if (past_mixture) /* N_t x the mixture's pdf D_t(w) / S_t */
                own = s->denom[q] * (nk[t] / s_t);
            /* divided by the share a_t, as a ratio so that T = 1 gives classic's N p exactly */
            s->own[q] = own * (share_sum / (nk[t] * (t + 1)));
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
            out->e[k] += x[k] = s->f[3 * q + k] / (opt->unbiased ? s->own[q] : s->denom[q]);
        if (opt->gradient)
            add_rotation(out, cosine->axis, s->w + 3 * q, lmb_dot3(s->w + 3 * q, cosine->axis), x);
    }
    out->last = lobes[T - 1];
    return LMB_OK;
}

lmb_status lmb_estimate_irradiance(const lmb_estimator_options *opt, const double n[3], const double ng[3],
                                   lmb_rng rng, lmb_radiance_fn radiance, void *user, lmb_estimator_scratch *scratch,
                                   lmb_estimate *out)
{
    memset(out, 0, sizeof *out);
    lmb_lobe cosine = {{n[0], n[1], n[2]}, 1.0};
    out->last = cosine;
    if (opt->method == LMB_GATHER_COSINE) {
        classic(opt, &cosine, ng, rng, radiance, user, out);
        return LMB_OK;
    }
    return amis(opt, &cosine, ng, rng, radiance, user, scratch, out);
}
