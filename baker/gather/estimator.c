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

#include "util/fast_pow.h"

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

static int scratch_reserve(lmb_estimator_scratch *s, uint32_t n)
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
static int draw_and_trace(const lmb_lobe *lobe, double frame[2][3], const lmb_lobe *cosine, const double ng[3],
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
    double frame[2][3]; /* the cosine lobe's, once per point */
    lmb_frame(cosine->axis, frame[0], frame[1]);
    for (uint32_t j = 0; j < opt->rays; j++) {
        double u[3], w[3], l[3], c, dist;
        sample_uniforms(rng, j, u);
        if (!draw_and_trace(cosine, frame, cosine, ng, u, j, radiance, user, w, l, &c, &dist, out))
            continue;
        double denom = (double)opt->rays * lmb_lobe_pdf(cosine, w), x[3];
        for (int k = 0; k < 3; k++)
            out->e[k] += x[k] = l[k] * c / denom;
        if (opt->gradient) {
            add_rotation(out, cosine->axis, w, c, x);
            out->cos_weight += 1; /* p_cos / q = 1 */
            out->cos_inverse_distance += dist > 0 && isfinite(dist) ? 1 / dist : 0;
        }
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

int lmb_estimator_guided(const lmb_estimator_options *opt)
{
    return opt->method == LMB_GATHER_AMIS_DEFENSIVE && opt->unbiased && opt->defensive > 0 && opt->iterations >= 2 &&
           opt->guide && lmb_mixture_learned(opt->guide);
}

uint32_t lmb_estimator_cosine_samples(const lmb_estimator_options *opt)
{
    if (lmb_estimator_guided(opt))
        return 0;
    uint32_t T = opt->method == LMB_GATHER_COSINE ? 1 : iteration_count(opt);
    return opt->rays / T + (opt->rays % T != 0); /* N_0, as amis() splits the rays */
}

/* The paper's AMIS (balance weights over all lobes, eq. 3): consistent, not unbiased. */
static lmb_status amis_balance(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3], lmb_rng rng,
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

/* ---- unbiased AMIS: guided, several lobes, variance-aware shares ---------------------------- */

#define PROPOSAL_MAX_LOBES (LMB_AMIS_MAX_ITERATIONS + 2 * LMB_MIXTURE_MAX_LOBES)

/* The pdf one iteration samples: q(w) = c p_cos(w) + sum_j b_j p(w; lobe j), c + sum b_j = 1. */
typedef struct proposal {
    double cosine;
    double cos_t[3], cos_b[3]; /* the cosine lobe's frame */
    uint32_t count;
    double share[PROPOSAL_MAX_LOBES];
    lmb_lobe lobe[PROPOSAL_MAX_LOBES];
    double t[PROPOSAL_MAX_LOBES][3], b[PROPOSAL_MAX_LOBES][3];
    /* the lobes four at a time for proposal_pdf: axes, exponents a_j, and
     * scale_j = share_j (a_j + 1) / (2 pi) (the pdf is scale_j (w.n^_j)^a_j); unused lanes 0 */
    lmb_f4 ax[PROPOSAL_MAX_LOBES / 4 + 1], ay[PROPOSAL_MAX_LOBES / 4 + 1], az[PROPOSAL_MAX_LOBES / 4 + 1];
    lmb_f4 exponent[PROPOSAL_MAX_LOBES / 4 + 1], scale[PROPOSAL_MAX_LOBES / 4 + 1];
} proposal;

static void proposal_init(proposal *p, const lmb_lobe *cosine, double share)
{
    p->cosine = share;
    p->count = 0;
    lmb_frame(cosine->axis, p->cos_t, p->cos_b);
    memset(p->ax, 0, sizeof p->ax);
    memset(p->ay, 0, sizeof p->ay);
    memset(p->az, 0, sizeof p->az);
    memset(p->exponent, 0, sizeof p->exponent);
    memset(p->scale, 0, sizeof p->scale);
}

static void proposal_add(proposal *p, const lmb_mixture *m, double share)
{
    p->cosine += share * m->diffuse;
    for (uint32_t k = 0; k < m->count && p->count < PROPOSAL_MAX_LOBES; k++, p->count++) {
        p->share[p->count] = share * (1.0 - m->diffuse) * m->weight[k];
        uint32_t v = p->count / 4, l = p->count % 4;
        p->ax[v][l] = (float)m->lobe[k].axis[0];
        p->ay[v][l] = (float)m->lobe[k].axis[1];
        p->az[v][l] = (float)m->lobe[k].axis[2];
        p->exponent[v][l] = (float)m->lobe[k].a;
        p->scale[v][l] = (float)(p->share[p->count] * (m->lobe[k].a + 1.0) * (0.5 * LMB_INV_PI));
        p->lobe[p->count] = m->lobe[k];
        memcpy(p->t[p->count], m->tangent[k], sizeof p->t[0]);
        memcpy(p->b[p->count], m->bitangent[k], sizeof p->b[0]);
    }
}

/* q(w): the lobes' powers four at a time (util/fast_pow.h). */
static double proposal_pdf(const proposal *p, const lmb_lobe *cosine, const double w[3])
{
    double q = p->cosine * lmb_lobe_pdf(cosine, w);
    float wx = (float)w[0], wy = (float)w[1], wz = (float)w[2];
    for (uint32_t v = 0; v * 4 < p->count; v++) {
        lmb_f4 c = wx * p->ax[v] + wy * p->ay[v] + wz * p->az[v];
        lmb_f4 x = lmb_pow_f4(c, p->exponent[v]) * p->scale[v];
        q += (double)(x[0] + x[1]) + (double)(x[2] + x[3]);
    }
    return q;
}

/* u picks the component (cosine first), u1 and u2 the direction. */
static void proposal_sample(const proposal *p, const lmb_lobe *cosine, double u1, double u2, double u, double w[3])
{
    if (u < p->cosine || p->count == 0) {
        lmb_lobe_sample_in_frame(cosine, p->cos_t, p->cos_b, u1, u2, w);
        return;
    }
    double acc = p->cosine;
    uint32_t j = 0;
    while (j + 1 < p->count && u >= (acc += p->share[j]))
        j++;
    lmb_lobe_sample_in_frame(&p->lobe[j], p->t[j], p->b[j], u1, u2, w);
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

/* Eqs. 2 and 4 (or the EM fit for several lobes) over the kept samples, weighted by
 * s_i = lum(f_i) / q_{t_i}(w_i): each sample over the pdf it was drawn from. */
static int fit_samples(lmb_estimator_scratch *s, const double normal[3], uint32_t lobes, lmb_mixture *out)
{
    for (uint32_t q = 0; q < s->count; q++)
        s->si[q] = s->lum[q] / s->own[q];
    return lmb_mixture_fit(s->w, s->si, s->dist, s->count, normal, lobes, &s->fit, out);
}

static lmb_status amis_unbiased(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3],
                                lmb_rng rng, lmb_radiance_fn radiance, void *user, lmb_estimator_scratch *s,
                                lmb_estimate *out)
{
    uint32_t T = iteration_count(opt);
    double d = opt->method == LMB_GATHER_AMIS_DEFENSIVE ? opt->defensive : 0.0;
    static const lmb_mixture none;
    lmb_mixture fits[LMB_AMIS_MAX_ITERATIONS]; /* fits[t]: learned from iterations < t */
    double nk[LMB_AMIS_MAX_ITERATIONS], var[LMB_AMIS_MAX_ITERATIONS];
    if (!scratch_reserve(s, opt->rays))
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
        for (uint32_t i = 0; i < (uint32_t)nk[t]; i++, j++) {
            double u[3], w[3], l[3];
            sample_uniforms(rng, j, u);
            proposal_sample(&prop, cosine, u[0], u[1], u[2], w);
            double c = lmb_dot3(w, cosine->axis);
            if (c <= 0 || lmb_dot3(w, ng) <= 0)
                continue;
            double dist = radiance(user, w, j, l);
            out->traced++;
            double f[3] = {l[0] * c, l[1] * c, l[2] * c}, lum = luminance(f);
            if (!(lum > 0))
                continue;
            uint32_t q = s->count++;
            memcpy(s->w + 3 * q, w, sizeof w);
            memcpy(s->f + 3 * q, f, sizeof f);
            s->lum[q] = lum;
            s->own[q] = proposal_pdf(&prop, cosine, w);
            s->iteration[q] = t;
            s->dist[q] = dist;
            double y = lum / s->own[q];
            sum += y;
            sum2 += y * y;
        }
        var[t] = nk[t] > 1 ? fmax(0.0, (sum2 - sum * sum / nk[t]) / (nk[t] - 1)) : 0;
        if (t + 1 < T) {
            fits[t + 1] = fits[t];
            lmb_mixture next;
            for (uint32_t q = 0; q < s->count; q++)
                s->si[q] = s->lum[q] / s->own[q];
            if (lmb_mixture_update(s->w, s->si, s->count, cosine->axis, t > 0 ? &fits[t] : NULL, &s->fit, &next)) {
                fits[t + 1] = next;
                out->adapted++;
            }
        }
    }
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
    if (opt->learn_lobes && s->count)
        fit_samples(s, cosine->axis, opt->learn_lobes, &out->learned);
    return LMB_OK;
}

/* Guided gathering: every sample from the fixed pdf q = d p_cos + (1 - d) G, G learned at a
 * neighbour before this point's samples, so E = 1/N sum f / q is unbiased. (A texel's own
 * adaptation on top, G refined by EM over its first samples, lowered the noise by 6-8% and cost
 * 12-25% more time: README, "Guided gathering".) */
/* Directions of samples j0..j0+3 from the proposal and their pdfs q, four at a time: the
 * cos(theta) powers of the lobe draws and each lobe's power at the four directions are one
 * vector call each (util/fast_pow.h) instead of a chain of libm calls per sample. */
static void draw_four(const proposal *p, const lmb_lobe *cosine, lmb_rng rng, uint32_t j0, double w[4][3],
                      double q[4])
{
    double u[4][3];
    int lobe[4];
    lmb_f4 base = {1, 1, 1, 1}, expo = {0, 0, 0, 0};
    for (int b = 0; b < 4; b++) {
        sample_uniforms(rng, j0 + (uint32_t)b, u[b]);
        lobe[b] = -1; /* the cosine lobe */
        if (u[b][2] >= p->cosine && p->count) {
            double acc = p->cosine;
            int k = 0;
            while (k + 1 < (int)p->count && u[b][2] >= (acc += p->share[k]))
                k++;
            lobe[b] = k;
            base[b] = (float)(1.0 - u[b][0]);
            expo[b] = (float)(1.0 / (p->lobe[k].a + 1.0));
        }
    }
    lmb_f4 ct = lmb_pow_f4(base, expo), wx, wy, wz; /* cos(theta) = (1 - u1)^(1 / (a + 1)), lobe.h */
    for (int b = 0; b < 4; b++) {
        const double *axis = lobe[b] < 0 ? cosine->axis : p->lobe[lobe[b]].axis;
        const double *t = lobe[b] < 0 ? p->cos_t : p->t[lobe[b]], *bt = lobe[b] < 0 ? p->cos_b : p->b[lobe[b]];
        double c = lobe[b] < 0 ? sqrt(1.0 - u[b][0]) : (double)ct[b];
        double st = sqrt(fmax(0.0, 1.0 - c * c));
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
        const double *a = p->lobe[k].axis;
        lmb_f4 c = wx * (float)a[0] + wy * (float)a[1] + wz * (float)a[2];
        lmb_f4 e = {(float)p->lobe[k].a, (float)p->lobe[k].a, (float)p->lobe[k].a, (float)p->lobe[k].a};
        sum += lmb_pow_f4(c, e) * (float)(p->share[k] * (p->lobe[k].a + 1.0) * (0.5 * LMB_INV_PI));
    }
    for (int b = 0; b < 4; b++)
        q[b] += (double)sum[b];
}

/* Guided gathering: every sample from the fixed pdf q = d p_cos + (1 - d) G, G learned at a
 * neighbour before this point's samples, so E = 1/N sum f / q is unbiased. (A texel's own
 * adaptation on top, G refined by EM over its first samples, lowered the noise by 6-8% and cost
 * 12-25% more time: README, "Guided gathering".) */
static void guided(const lmb_estimator_options *opt, const lmb_lobe *cosine, const double ng[3], lmb_rng rng,
                   lmb_radiance_fn radiance, void *user, lmb_estimate *out)
{
    if (opt->guide->count == 0) { /* all diffuse: the proposal is the cosine lobe, classic gathering */
        classic(opt, cosine, ng, rng, radiance, user, out);
        return;
    }
    proposal prop;
    proposal_init(&prop, cosine, opt->defensive);
    proposal_add(&prop, opt->guide, 1.0 - opt->defensive);
    double w[4][3], q[4], inv_n = 1.0 / (double)opt->rays;
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
        if (opt->gradient) { /* a record: its rotation gradient and its harmonic mean distance */
            add_rotation(out, cosine->axis, wj, c, x);
            double wc = c * LMB_INV_PI * inv_q; /* p_cos / q */
            out->cos_weight += wc;
            out->cos_inverse_distance += dist > 0 && isfinite(dist) ? wc / dist : 0;
        }
    }
    if (prop.count)
        out->last = prop.lobe[0];
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
    if (lmb_estimator_guided(opt)) {
        guided(opt, &cosine, ng, rng, radiance, user, out);
        return LMB_OK;
    }
    if (opt->unbiased)
        return amis_unbiased(opt, &cosine, ng, rng, radiance, user, scratch, out);
    return amis_balance(opt, &cosine, ng, rng, radiance, user, scratch, out);
}
