/*
 * Final-gather estimators (see estimator.h): the scratch, classic gathering, and the dispatch
 * to the AMIS variants (amis_paper.c, amis.c).
 */
#include "estimator.h"

#include "gather/estimator_parts.h"

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
    free(s->iteration);
    free(s->dist);
    lmb_mixture_scratch_free(&s->fit);
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

int lmb_estimator_scratch_reserve(lmb_estimator_scratch *s, uint32_t n)
{
    if (n <= s->cap)
        return 1;
    int ok = grow(&s->w, 3 * (size_t)n) & grow(&s->f, 3 * (size_t)n) & grow(&s->lum, n) & grow(&s->denom, n) &
             grow(&s->own, n) & grow(&s->si, n) & grow(&s->dist, n);
    uint32_t *it = realloc(s->iteration, (size_t)n * sizeof *it);
    if (it)
        s->iteration = it;
    ok &= it != NULL;
    if (ok)
        s->cap = n;
    return ok;
}

/* Classic final gathering: E = 1/N sum f(w_j) / p_cos(w_j). */
void lmb_estimate_classic(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3], lmb_rng rng,
                          lmb_radiance_fn radiance, void *user, lmb_estimate *out)
{
    double frame[2][3]; /* the cosine lobe's, once per point */
    lmb_frame(cosine->axis, frame[0], frame[1]);
    double sum = 0, sum2 = 0; /* of lum(f) / p_cos, for the variance */
    for (uint32_t j = 0; j < opt->rays; j++) {
        double u[3], w[3], l[3], c, dist;
        sample_uniforms(rng, j, u);
        if (!draw_and_trace(cosine, frame, cosine, ng, u, j, radiance, user, w, l, &c, &dist, out))
            continue;
        double denom = (double)opt->rays * lmb_lobe_pdf(cosine, w), x[3];
        for (int k = 0; k < 3; k++)
            out->e[k] += x[k] = l[k] * c / denom;
        double y = lmb_luminance(x) * opt->rays;
        sum += y;
        sum2 += y * y;
        if (opt->gradient) {
            add_rotation(out, cosine->axis, w, c, x);
            out->cos_weight += 1; /* p_cos / q = 1 */
            out->cos_inverse_distance += dist > 0 && isfinite(dist) ? 1 / dist : 0;
        }
    }
    out->var = lmb_sample_variance_of_mean(sum, sum2, opt->rays);
}

int lmb_estimator_can_guide(const lmb_estimator_options *opt)
{
    return opt->method == LMB_GATHER_AMIS_DEFENSIVE && opt->unbiased && opt->defensive > 0 && opt->iterations >= 2;
}

int lmb_estimator_guided(const lmb_estimator_options *opt)
{
    return lmb_estimator_can_guide(opt) && opt->guide && lmb_mixture_learned(opt->guide);
}

uint32_t lmb_estimator_cosine_samples(const lmb_estimator_options *opt)
{
    if (lmb_estimator_guided(opt))
        return 0;
    uint32_t T = opt->method == LMB_GATHER_COSINE ? 1 : iteration_count(opt);
    return opt->rays / T + (opt->rays % T != 0); /* N_0, as amis() splits the rays */
}

lmb_status lmb_estimate_irradiance(const lmb_estimator_options *opt, const double n[3], const double ng[3],
                                   lmb_rng rng, lmb_radiance_fn radiance, void *user, lmb_estimator_scratch *scratch,
                                   lmb_estimate *out)
{
    memset(out, 0, sizeof *out);
    lmb_lobe cosine = {{n[0], n[1], n[2]}, 1.0};
    out->last = cosine;
    if (opt->method == LMB_GATHER_COSINE) {
        lmb_estimate_classic(opt, &cosine, ng, rng, radiance, user, out);
        return LMB_OK;
    }
    if (lmb_estimator_guided(opt)) {
        lmb_amis_guided(opt, &cosine, ng, rng, radiance, user, out);
        return LMB_OK;
    }
    if (opt->unbiased)
        return lmb_amis_unbiased(opt, &cosine, ng, rng, radiance, user, scratch, out);
    return lmb_amis_balance(opt, &cosine, ng, rng, radiance, user, scratch, out);
}
