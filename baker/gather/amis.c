/*
 * lmbake's AMIS (estimator.h, `gather.amis_weights: unbiased`) and guided gathering (issue 12).
 * Unbiased AMIS: iteration t samples a proposal fixed before its samples (the cosine lobe at
 * t = 0, then d p_cos + (1 - d) F_t with F_t the mixture fitted to the earlier samples,
 * mixture.h), its samples weighted by that proposal alone, the iterations combined with
 * shares a_t set from earlier iterations only: each term is unbiased, and so is the sum.
 * Guided gathering: every sample from d p_cos + (1 - d) G, G learned at a neighbour (guide.h,
 * the irradiance cache's earlier records): one importance-sampling estimate with a fixed pdf.
 */
#include "gather/estimator_parts.h"

#include "util/fast_pow.h"

#include <stdlib.h>
#include <string.h>

#define PROPOSAL_MAX_LOBES (LMB_AMIS_MAX_ITERATIONS + 2 * LMB_MIXTURE_MAX_LOBES)

/* The pdf one iteration samples: q(w) = c p_cos(w) + sum_j b_j p(w; lobe j), c + sum b_j = 1. */
typedef struct proposal {
    double cosine;
    double cos_t[3], cos_b[3]; /* the cosine lobe's frame */
    uint32_t count;
    double share[PROPOSAL_MAX_LOBES];
    lmb_lobe lobe[PROPOSAL_MAX_LOBES];
    double t[PROPOSAL_MAX_LOBES][3], b[PROPOSAL_MAX_LOBES][3];
    /* per lobe for draw_four, in single precision: the axis, a, 1 / (a + 1) and
     * share (a + 1) / (2 pi) (its pdf's factor) */
    float axis_f[PROPOSAL_MAX_LOBES][3], a_f[PROPOSAL_MAX_LOBES], inv_a1[PROPOSAL_MAX_LOBES], scale[PROPOSAL_MAX_LOBES];
} proposal;

static void proposal_init(proposal *p, const lmb_lobe *cosine, double share)
{
    p->cosine = share;
    p->count = 0;
    lmb_frame(cosine->axis, p->cos_t, p->cos_b);
}

static void proposal_add(proposal *p, const lmb_mixture *m, double share)
{
    p->cosine += share * m->diffuse;
    for (uint32_t k = 0; k < m->count && p->count < PROPOSAL_MAX_LOBES; k++, p->count++) {
        p->share[p->count] = share * (1.0 - m->diffuse) * m->weight[k];
        p->lobe[p->count] = m->lobe[k];
        memcpy(p->t[p->count], m->tangent[k], sizeof p->t[0]);
        memcpy(p->b[p->count], m->bitangent[k], sizeof p->b[0]);
        for (int c = 0; c < 3; c++)
            p->axis_f[p->count][c] = (float)m->lobe[k].axis[c];
        p->a_f[p->count] = (float)m->lobe[k].a;
        p->inv_a1[p->count] = (float)(1.0 / (m->lobe[k].a + 1.0));
        p->scale[p->count] = (float)(p->share[p->count] * (m->lobe[k].a + 1.0) * (0.5 * LMB_INV_PI));
    }
}

/* Iteration t's proposal. With a defensive share d: d p_cos + (1 - d) F_t (F_t: the mixture
 * fitted to iterations < t); without one: the mixture of p_cos and F_1..F_t by their sample
 * counts (every direction stays covered). t = 0 is p_cos alone (T = 1 is classic, bit for bit). */
static void make_proposal(proposal *p, const lmb_lobe *cosine, uint32_t t, double d, const lmb_mixture *fits,
                          const double *nk)
{
    proposal_init(p, cosine, 1.0);
    if (t > 0 && d > 0) {
        if (lmb_mixture_learned(&fits[t])) {
            p->cosine = d;
            proposal_add(p, &fits[t], 1 - d);
        }
    } else if (t > 0) {
        double s_t = 0;
        for (uint32_t k = 0; k <= t; k++)
            s_t += nk[k];
        p->cosine = nk[0] / s_t;
        for (uint32_t k = 1; k <= t; k++)
            if (lmb_mixture_learned(&fits[k]))
                proposal_add(p, &fits[k], nk[k] / s_t);
            else
                p->cosine += nk[k] / s_t; /* nothing learned: that iteration sampled the cosine lobe */
    }
}

/* The share a_t of iteration t, from data of iterations < t only (so E[a_t E_t] = E[a_t] E and
 * the sum of a_t is 1 by construction: unbiased). The remaining weight R_t is split between
 * iteration t and the later ones in proportion to N_s / v_s, v_s their predicted per-sample
 * variance: the prior shape v_s ~ 1 / (s + 1) (later iterations adapted more) until two
 * iterations were measured, then v_s = v_{t-1} rho^(s - t + 1), rho the last
 * measured ratio v_{t-1} / v_{t-2} clamped to [0.1, 1]. (Inverse-variance weights are the
 * optimal combination of independent unbiased estimates; Owen, "Monte Carlo theory", ch. 10.5
 * on combining adaptive importance sampling stages.) */
static double iteration_share(uint32_t t, uint32_t T, const double *nk, const double *var, double remaining)
{
    double num = 0, den = 0;
    int measured = t >= 2 && var[t - 1] > 0 && var[t - 2] > 0;
    double rho = measured ? var[t - 1] / var[t - 2] : 1;
    rho = rho < 0.5 ? 0.5 : rho > 1 ? 1 : rho;
    for (uint32_t s = t; s < T; s++) {
        double v = measured ? pow(rho, (double)(s - t + 1)) : 1.0 / (double)(s + 1);
        double x = nk[s] / v;
        if (s == t)
            num = x;
        den += x;
    }
    return t + 1 == T ? remaining : remaining * num / den;
}

/* Directions of samples j0..j0+3 from the proposal and their pdfs q, four at a time: the
 * cos(theta) powers of the lobe draws and each lobe's power at the four directions are one
 * vector call each (util/fast_pow.h) instead of a chain of libm calls per sample. */
static void draw_four(const proposal *p, const lmb_lobe *cosine, lmb_rng rng, uint32_t j0, double w[4][3],
                      double q[4])
{
    double u[4][3], cum[PROPOSAL_MAX_LOBES]; /* cosine + share_0 + ... + share_j: where lobe j's picks end */
    int lobe[4];
    lmb_f4 base = {1, 1, 1, 1}, expo = {0, 0, 0, 0};
    double acc = p->cosine;
    for (uint32_t i = 0; i < p->count; i++)
        cum[i] = acc += p->share[i];
    for (int b = 0; b < 4; b++) {
        sample_uniforms(rng, j0 + (uint32_t)b, u[b]);
        /* the component: -1 (the cosine lobe) or the lobe whose interval of [0, 1) holds u2,
         * counted without branches (the picks are random: a branch would mispredict) */
        int k = 0;
        for (uint32_t i = 0; i + 1 < p->count; i++)
            k += u[b][2] >= cum[i];
        int cosine_pick = u[b][2] < p->cosine || p->count == 0;
        lobe[b] = cosine_pick ? -1 : k;
        base[b] = cosine_pick ? 1.0f : (float)(1.0 - u[b][0]);
        expo[b] = cosine_pick ? 0.0f : p->inv_a1[k];
    }
    lmb_f4 ct = lmb_pow_f4(base, expo), wx, wy, wz; /* cos(theta) = (1 - u1)^(1 / (a + 1)), util/sampling.h */
    for (int b = 0; b < 4; b++) {
        const double *axis = lobe[b] < 0 ? cosine->axis : p->lobe[lobe[b]].axis;
        const double *t = lobe[b] < 0 ? p->cos_t : p->t[lobe[b]], *bt = lobe[b] < 0 ? p->cos_b : p->b[lobe[b]];
        double c = lobe[b] < 0 ? sqrt(1.0 - u[b][0]) : (double)ct[b];
        double s2 = 1.0 - c * c, st = sqrt(s2 > 0 ? s2 : 0.0);
        float phi = (float)(2.0 * LMB_PI * u[b][1]);
        double x = st * (double)cosf(phi), y = st * (double)sinf(phi);
        for (int k = 0; k < 3; k++)
            w[b][k] = x * t[k] + y * bt[k] + c * axis[k];
        wx[b] = (float)w[b][0];
        wy[b] = (float)w[b][1];
        wz[b] = (float)w[b][2];
        q[b] = p->cosine * lmb_lobe_pdf(cosine, w[b]);
    }
    lmb_f4 sum = {0, 0, 0, 0};
    for (uint32_t k = 0; k < p->count; k++) {
        const float *a = p->axis_f[k];
        lmb_f4 c = wx * a[0] + wy * a[1] + wz * a[2], e = {0, 0, 0, 0};
        e += p->a_f[k];
        sum += lmb_pow_f4(c, e) * p->scale[k];
    }
    for (int b = 0; b < 4; b++)
        q[b] += (double)sum[b];
}

/* The weights every fit of the kept samples uses (mixture.h): s_i = lum(f_i) / q_{t_i}(w_i),
 * each sample over the pdf it was drawn from. */
static void set_fit_weights(lmb_estimator_scratch *s)
{
    for (uint32_t q = 0; q < s->count; q++)
        s->si[q] = s->lum[q] / s->own[q];
}

lmb_status lmb_amis_unbiased(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3],
                                lmb_rng rng, lmb_radiance_fn radiance, void *user, lmb_estimator_scratch *s,
                                lmb_estimate *out)
{
    uint32_t T = iteration_count(opt);
    double d = opt->method == LMB_GATHER_AMIS_DEFENSIVE ? opt->defensive : 0.0;
    static const lmb_mixture none;
    lmb_mixture fits[LMB_AMIS_MAX_ITERATIONS]; /* fits[t]: learned from iterations < t */
    double nk[LMB_AMIS_MAX_ITERATIONS], var[LMB_AMIS_MAX_ITERATIONS];
    if (!lmb_estimator_scratch_reserve(s, opt->rays))
        return LMB_ERR_INTERNAL;
    s->count = 0;
    for (uint32_t t = 0; t < T; t++)
        nk[t] = (double)(opt->rays / T + (t < opt->rays % T));
    fits[0] = none;
    proposal prop;
    uint32_t j = 0;
    double remaining = 1.0;
    for (uint32_t t = 0; t < T; t++) {
        out->share[t] = iteration_share(t, T, nk, var, remaining);
        remaining -= out->share[t];
        make_proposal(&prop, cosine, t, d, fits, nk);
        double sum = 0, sum2 = 0; /* of lum(f) / q: this iteration's per-sample variance */
        double four[4][3], q4[4];
        for (uint32_t i = 0; i < (uint32_t)nk[t]; i++, j++) {
            if (i % 4 == 0) /* this iteration's next four samples */
                draw_four(&prop, cosine, rng, j, four, q4);
            double w[3], l[3];
            memcpy(w, four[i % 4], sizeof w);
            double c = lmb_dot3(w, cosine->axis);
            if (c <= 0 || lmb_dot3(w, ng) <= 0)
                continue;
            double dist = radiance(user, w, j, l);
            out->traced++;
            int64_t q = keep_sample(s, w, l, c);
            if (q < 0)
                continue;
            s->own[q] = q4[i % 4];
            s->iteration[q] = t;
            s->dist[q] = dist;
            double y = s->lum[q] / s->own[q];
            sum += y;
            sum2 += y * y;
        }
        var[t] = nk[t] > 1 ? fmax(0.0, (sum2 - sum * sum / nk[t]) / (nk[t] - 1)) : 0;
        if (t + 1 < T) {
            fits[t + 1] = fits[t];
            lmb_mixture next;
            set_fit_weights(s);
            if (lmb_mixture_update(s->w, s->si, s->count, cosine->axis, t > 0 ? &fits[t] : NULL, &s->fit, &next)) {
                fits[t + 1] = next;
                out->adapted++;
            }
        }
    }
    out->var = 0;
    for (uint32_t t = 0; t < T; t++)
        out->var += nk[t] > 0 ? out->share[t] * out->share[t] * var[t] / nk[t] : 0;
    for (uint32_t q = 0; q < s->count; q++) {
        uint32_t t = s->iteration[q];
        double denom = nk[t] * s->own[q], x[3];
        for (int k = 0; k < 3; k++)
            out->e[k] += x[k] = s->f[3 * q + k] / denom * out->share[t];
        if (opt->gradient)
            add_rotation(out, cosine->axis, s->w + 3 * q, lmb_dot3(s->w + 3 * q, cosine->axis), x);
    }
    if (fits[T - 1].count)
        out->last = fits[T - 1].lobe[0];
    if (opt->learn_lobes && s->count) {
        set_fit_weights(s);
        lmb_mixture_fit(s->w, s->si, s->dist, s->count, cosine->axis, opt->learn_lobes, &s->fit, &out->learned);
    }
    return LMB_OK;
}

/* Guided gathering: every sample from the fixed pdf q = d p_cos + (1 - d) G, G learned at a
 * neighbour before this point's samples, so E = 1/N sum f / q is unbiased. (A texel's own
 * adaptation on top, G refined by EM over its first samples, lowered the noise by 6-8% and cost
 * 12-25% more time: docs/lighting.md.) */
void lmb_amis_guided(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3], lmb_rng rng,
                   lmb_radiance_fn radiance, void *user, lmb_estimate *out)
{
    if (opt->guide->count == 0) { /* all diffuse: the proposal is the cosine lobe, classic gathering */
        lmb_estimate_classic(opt, cosine, ng, rng, radiance, user, out);
        return;
    }
    proposal prop;
    proposal_init(&prop, cosine, opt->defensive);
    proposal_add(&prop, opt->guide, 1.0 - opt->defensive);
    double w[4][3], q[4], inv_n = 1.0 / (double)opt->rays, sum = 0, sum2 = 0;
    for (uint32_t j = 0; j < opt->rays; j++) {
        if (j % 4 == 0)
            draw_four(&prop, cosine, rng, j, w, q);
        const double *wj = w[j % 4];
        double l[3], c = lmb_dot3(wj, cosine->axis);
        if (c <= 0 || lmb_dot3(wj, ng) <= 0)
            continue;
        double dist = radiance(user, wj, j, l);
        out->traced++;
        double inv_q = 1.0 / q[j % 4], scale = c * inv_q * inv_n, x[3];
        for (int k = 0; k < 3; k++)
            out->e[k] += x[k] = l[k] * scale;
        double y = lmb_luminance(x) * opt->rays;
        sum += y;
        sum2 += y * y;
        if (opt->gradient) { /* a record: its rotation gradient and its harmonic mean distance */
            add_rotation(out, cosine->axis, wj, c, x);
            double wc = c * LMB_INV_PI * inv_q; /* p_cos / q */
            out->cos_weight += wc;
            out->cos_inverse_distance += dist > 0 && isfinite(dist) ? wc / dist : 0;
        }
    }
    if (prop.count)
        out->last = prop.lobe[0];
    out->var = lmb_sample_variance_of_mean(sum, sum2, opt->rays);
}

