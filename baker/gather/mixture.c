/* Learned directional mixtures: the weighted EM fit and re-aiming (see mixture.h). */
#include "mixture.h"

#include "gather/estimator.h"
#include "util/fast_pow.h"

#include <stdlib.h>
#include <stddef.h>
#include <string.h>

#define EM_STEPS 8      /* a mixture learned for the neighbours */
#define EM_STEPS_COLD 6 /* a point's own first adaptation (lmb_mixture_update) */
#define EM_STEPS_WARM 2 /* its later ones, from the previous */
#define MIN_COS 1e-4f

void lmb_mixture_scratch_free(lmb_mixture_scratch *s)
{
    free(s->w);
    free(s->s);
    free(s->r);
    free(s->r2);
    free(s->d);
    memset(s, 0, sizeof *s);
}

static int reserve(lmb_mixture_scratch *s, uint32_t n)
{
    if (n <= s->cap)
        return 1;
    float *w = realloc(s->w, 3 * (size_t)n * sizeof *w);
    if (w)
        s->w = w;
    float *x = realloc(s->s, (size_t)n * sizeof *x);
    if (x)
        s->s = x;
    float *r = realloc(s->r, (LMB_MIXTURE_MAX_LOBES + 1) * (size_t)n * sizeof *r);
    if (r)
        s->r = r;
    float *r2 = realloc(s->r2, (LMB_MIXTURE_MAX_LOBES + 1) * (size_t)n * sizeof *r2);
    if (r2)
        s->r2 = r2;
    float *d = realloc(s->d, (size_t)n * sizeof *d);
    if (d)
        s->d = d;
    if (!w || !x || !r || !r2 || !d)
        return 0;
    s->cap = n;
    return 1;
}

static float dot3f(const float *a, const double b[3])
{
    return a[0] * (float)b[0] + a[1] * (float)b[1] + a[2] * (float)b[2];
}

/* The fit in progress: component 0 is the cosine lobe around the normal, 1..K the lobes. */
typedef struct model {
    uint32_t K;
    lmb_lobe lobe[LMB_MIXTURE_MAX_LOBES + 1];
    double share[LMB_MIXTURE_MAX_LOBES + 1]; /* summing to 1 over all K + 1 components */
} model;

/* E-step: r (K + 1 per sample); a sample outside every component goes to the cosine lobe's
 * responsibility (it cannot be outside that one: samples lie above the surface). Returns the
 * weighted log-likelihood of the samples under 0.9 g + 0.1 / (4 pi) (the floor keeps a
 * sample outside every lobe finite). */
static double responsibilities(const model *m, const float *w, const float *s, uint32_t n, float *r)
{
    uint32_t C = m->K + 1;
    double ll = 0;
    lmb_f4 floor = {0, 0, 0, 0};
    floor += (float)(0.25 * LMB_INV_PI * 0.1);
    for (uint32_t i0 = 0; i0 < n; i0 += 4) { /* four samples at a time: one vector power per component */
        lmb_f4 wx = {0, 0, 0, 0}, wy = wx, wz = wx, sum = wx, p[LMB_MIXTURE_MAX_LOBES + 1];
        uint32_t lanes = n - i0 < 4 ? n - i0 : 4;
        for (uint32_t b = 0; b < lanes; b++) {
            wx[b] = w[3 * (i0 + b)];
            wy[b] = w[3 * (i0 + b) + 1];
            wz[b] = w[3 * (i0 + b) + 2];
        }
        for (uint32_t k = 0; k < C; k++) {
            const lmb_lobe *l = &m->lobe[k];
            lmb_f4 c = wx * (float)l->axis[0] + wy * (float)l->axis[1] + wz * (float)l->axis[2];
            float scale = (float)(m->share[k] * (l->a + 1.0) * (0.5 * LMB_INV_PI));
            if (l->a == 1.0) {
                lmb_f4 zero = {0, 0, 0, 0};
                p[k] = lmb_select_f4(c > 0.0f, c, zero) * scale;
            } else {
                lmb_f4 a = {0, 0, 0, 0};
                a += (float)l->a;
                p[k] = lmb_pow_f4(c, a) * scale;
            }
            sum += p[k];
        }
        lmb_f4 logs = lmb_log2_f4(0.9f * sum + floor) * 0.6931471805599453f;
        for (uint32_t b = 0; b < lanes; b++) {
            float *ri = r + (size_t)(i0 + b) * C;
            for (uint32_t k = 0; k < C; k++)
                ri[k] = sum[b] > 0 ? p[k][b] / sum[b] : (float)(k == 0);
            ll += (double)s[i0 + b] * (double)logs[b];
        }
    }
    return ll;
}

/* Component k's weight sum_i s_i r_ik; for k > 0 also eq. 4 (axis) and eq. 2 (exponent). */
static double m_step(const float *w, const float *s, const float *r, uint32_t n, uint32_t C, uint32_t k,
                     lmb_lobe *lobe)
{
    double sum = 0, v[3] = {0, 0, 0};
    for (uint32_t i = 0; i < n; i++) {
        double x = (double)s[i] * r[(size_t)i * C + k];
        sum += x;
        for (int c = 0; c < 3; c++)
            v[c] += x * w[3 * i + c];
    }
    double len = sqrt(lmb_dot3(v, v));
    if (k == 0 || !(sum > 0) || !(len > 0))
        return sum;
    for (int c = 0; c < 3; c++)
        lobe->axis[c] = v[c] / len;
    double lsum = 0;
    for (uint32_t i0 = 0; i0 < n; i0 += 4) { /* eq. 2's logarithms four at a time */
        lmb_f4 c = {1, 1, 1, 1};
        uint32_t lanes = n - i0 < 4 ? n - i0 : 4;
        for (uint32_t b = 0; b < lanes; b++) {
            float x = fabsf(dot3f(w + 3 * (i0 + b), lobe->axis));
            c[b] = x > MIN_COS ? x : MIN_COS;
        }
        lmb_f4 ln = lmb_log2_f4(c) * 0.6931471805599453f;
        for (uint32_t b = 0; b < lanes; b++)
            lsum += (double)s[i0 + b] * r[(size_t)(i0 + b) * C + k] * (double)ln[b];
    }
    double a = lsum < 0 ? -1.0 - sum / lsum : LMB_AMIS_MAX_EXPONENT;
    lobe->a = a >= 0 ? (a > LMB_AMIS_MAX_EXPONENT ? LMB_AMIS_MAX_EXPONENT : a) : 0;
    return sum;
}

/* `steps` EM steps from model m, then one E-step that scores it and leaves r for set_targets.
 * Returns the weighted log-likelihood (-HUGE_VAL when nothing carries weight). */
static double em(const float *w, const float *s, float *r, uint32_t n, uint32_t steps, model *m)
{
    for (uint32_t step = 0; step < steps; step++) {
        responsibilities(m, w, s, n, r);
        double total = 0;
        for (uint32_t k = 0; k <= m->K; k++)
            total += m->share[k] = m_step(w, s, r, n, m->K + 1, k, &m->lobe[k]);
        if (!(total > 0))
            return -HUGE_VAL;
        for (uint32_t k = 0; k <= m->K; k++)
            m->share[k] /= total;
    }
    return responsibilities(m, w, s, n, r);
}

/* EM for the cosine share and K lobes, started at the K heaviest mutually distant samples. */
static double fit_k(const float *w, const float *s, float *r, uint32_t n, uint32_t K, const double normal[3],
                    uint32_t steps, model *m)
{
    m->K = K;
    m->lobe[0] = (lmb_lobe){{normal[0], normal[1], normal[2]}, 1.0};
    m->share[0] = 0.5;
    for (uint32_t k = 1; k <= K; k++) {
        double best = -1;
        uint32_t pick = 0;
        for (uint32_t i = 0; i < n; i++) {
            double far = 1;
            for (uint32_t j = 1; j < k; j++) {
                double c = 0.5 * (1.0 - dot3f(w + 3 * i, m->lobe[j].axis));
                far = c < far ? c : far;
            }
            double score = (double)s[i] * far;
            if (score > best) {
                best = score;
                pick = i;
            }
        }
        for (int c = 0; c < 3; c++)
            m->lobe[k].axis[c] = w[3 * pick + c];
        m->lobe[k].a = 20;
        m->share[k] = 0.5 / K;
    }
    return em(w, s, r, n, steps, m);
}

/* Each lobe's target: the centroid of its samples' hit points weighted by s_i r_ik, when hits
 * (not escapes) carry at least half of its weight (r from the final E-step). */
static void set_targets(lmb_mixture *out, const uint32_t *index, const float *w, const float *s, const float *d,
                        const float *r, uint32_t n, uint32_t C)
{
    for (uint32_t k = 0; k < out->count; k++) {
        double sum = 0, hit = 0, c[3] = {0, 0, 0};
        for (uint32_t i = 0; i < n; i++) {
            double x = (double)s[i] * r[(size_t)i * C + index[k]];
            sum += x;
            if (!isfinite(d[i]))
                continue;
            hit += x;
            for (int j = 0; j < 3; j++)
                c[j] += x * (double)d[i] * w[3 * i + j];
        }
        out->aimed[k] = hit > 0.5 * sum && hit > 0;
        for (int j = 0; j < 3; j++)
            out->target[k][j] = out->aimed[k] ? c[j] / hit : 0;
    }
}

void lmb_mixture_keep(const lmb_mixture *m, lmb_mixture_kept *out)
{
    memset(out, 0, sizeof *out);
    out->count = m->count;
    out->diffuse = (float)m->diffuse;
    for (uint32_t k = 0; k < m->count && k < LMB_MIXTURE_MAX_LOBES; k++) {
        out->aimed[k] = (uint8_t)(m->aimed[k] != 0);
        out->exponent[k] = (float)m->lobe[k].a;
        out->weight[k] = (float)m->weight[k];
        for (int j = 0; j < 3; j++) {
            out->axis[k][j] = (float)m->lobe[k].axis[j];
            out->target[k][j] = (float)m->target[k][j];
        }
    }
}

/* Turns every aimed lobe of out (fitted at `from`) towards its target as seen from `to` and
 * sets every lobe's frame. */
static void reaim_in_place(lmb_mixture *out, const double from[3], const double to[3])
{
    for (uint32_t k = 0; k < out->count; k++) {
        if (out->aimed[k]) {
            double v[3];
            for (int j = 0; j < 3; j++)
                v[j] = from[j] + out->target[k][j] - to[j];
            double len = sqrt(lmb_dot3(v, v));
            if (len > 0) {
                for (int j = 0; j < 3; j++) {
                    out->lobe[k].axis[j] = v[j] / len;
                    out->target[k][j] = v[j];
                }
            }
        }
        lmb_frame(out->lobe[k].axis, out->tangent[k], out->bitangent[k]);
    }
}

void lmb_mixture_reaim(const lmb_mixture *m, const double from[3], const double to[3], lmb_mixture *out)
{
    memset(out, 0, sizeof *out);
    out->count = m->count;
    out->diffuse = m->diffuse;
    for (uint32_t k = 0; k < m->count && k < LMB_MIXTURE_MAX_LOBES; k++) {
        out->lobe[k] = m->lobe[k];
        out->weight[k] = m->weight[k];
        out->aimed[k] = m->aimed[k];
        memcpy(out->target[k], m->target[k], sizeof out->target[k]);
    }
    reaim_in_place(out, from, to);
}

void lmb_mixture_reaim_kept(const lmb_mixture_kept *m, const double from[3], const double to[3], lmb_mixture *out)
{
    memset(out, 0, sizeof *out);
    out->count = m->count;
    out->diffuse = m->diffuse;
    for (uint32_t k = 0; k < m->count && k < LMB_MIXTURE_MAX_LOBES; k++) {
        double len = 0;
        for (int j = 0; j < 3; j++) {
            out->lobe[k].axis[j] = m->axis[k][j];
            out->target[k][j] = m->target[k][j];
            len += out->lobe[k].axis[j] * out->lobe[k].axis[j];
        }
        len = sqrt(len); /* a unit axis rounded to floats: unit again */
        for (int j = 0; len > 0 && j < 3; j++)
            out->lobe[k].axis[j] /= len;
        out->lobe[k].a = m->exponent[k];
        out->weight[k] = m->weight[k];
        out->aimed[k] = m->aimed[k];
    }
    reaim_in_place(out, from, to);
}

/* Copies the samples to fit into the scratch (see lmb_mixture_fit): every step-th, standing for
 * step samples each, and every heavy one (weight above 1/LMB_MIXTURE_FIT_SAMPLES of the total:
 * at most that many) as itself, so that the rare samples that found a small bright spot are
 * never dropped. Weights normalised to sum 1. Returns the count, 0 when too few carry weight. */
static uint32_t select_samples(const double *w, const double *s, const double *dist, uint32_t n,
                               lmb_mixture_scratch *scratch, double *n_eff)
{
    if (n == 0 || !reserve(scratch, 2 * LMB_MIXTURE_FIT_SAMPLES + 1))
        return 0;
    double all = 0;
    for (uint32_t i = 0; i < n; i++)
        all += s[i] > 0 ? s[i] : 0;
    if (!(all > 0))
        return 0;
    uint32_t step = n > LMB_MIXTURE_FIT_SAMPLES ? (n + LMB_MIXTURE_FIT_SAMPLES - 1) / LMB_MIXTURE_FIT_SAMPLES : 1;
    double heavy = all / LMB_MIXTURE_FIT_SAMPLES, total = 0, total2 = 0;
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; i++) {
        if (!(s[i] > 0) || (s[i] < heavy && i % step))
            continue;
        double x = s[i] >= heavy ? s[i] : s[i] * step;
        for (int c = 0; c < 3; c++)
            scratch->w[3 * m + c] = (float)w[3 * i + c];
        scratch->d[m] = dist ? (float)dist[i] : INFINITY;
        scratch->s[m++] = (float)x;
        total += x;
    }
    if (!(total > 0) || m < 8)
        return 0;
    for (uint32_t i = 0; i < m; i++) {
        scratch->s[i] = (float)(scratch->s[i] / total);
        total2 += (double)scratch->s[i] * scratch->s[i];
    }
    *n_eff = 1.0 / total2;
    return m;
}

/* The model as a mixture: lobes with a negligible share dropped (their share goes to the
 * cosine lobe), weights renormalised; frames set; targets when the caller sets them. */
static void to_mixture(const model *md, lmb_mixture *out, uint32_t *index)
{
    memset(out, 0, sizeof *out);
    double lobes = 1.0 - md->share[0], sum = 0;
    for (uint32_t k = 1; k <= md->K; k++)
        if (lobes > 0 && md->share[k] > 1e-3 * lobes) {
            index[out->count] = k;
            out->lobe[out->count] = md->lobe[k];
            sum += out->weight[out->count++] = md->share[k];
        }
    for (uint32_t k = 0; k < out->count; k++) {
        out->weight[k] /= sum;
        lmb_frame(out->lobe[k].axis, out->tangent[k], out->bitangent[k]);
    }
    out->diffuse = out->count ? 1.0 - sum : 1.0;
}

int lmb_mixture_fit(const double *w, const double *s, const double *dist, uint32_t n, const double normal[3],
                    uint32_t max_lobes, lmb_mixture_scratch *scratch, lmb_mixture *out)
{
    memset(out, 0, sizeof *out);
    if (max_lobes > LMB_MIXTURE_MAX_LOBES)
        max_lobes = LMB_MIXTURE_MAX_LOBES;
    double n_eff;
    uint32_t m = select_samples(w, s, dist, n, scratch, &n_eff);
    if (!m)
        return 0;
    /* K = 0 is the cosine lobe alone: where light comes from everywhere alike (the furnace),
     * the fit says so and guided gathering samples exactly as classic gathering does */
    model best = {0}, cand;
    best.lobe[0] = (lmb_lobe){{normal[0], normal[1], normal[2]}, 1.0};
    best.share[0] = 1;
    float *r_best = scratch->r, *r_cand = scratch->r2; /* the responsibilities of each model */
    double best_score = n_eff * responsibilities(&best, scratch->w, scratch->s, m, r_best);
    for (uint32_t K = 1; K <= max_lobes && m >= 8 * K; K++) {
        double ll = fit_k(scratch->w, scratch->s, r_cand, m, K, normal, EM_STEPS, &cand);
        /* BIC: n_eff x mean log-likelihood - (parameters / 2) ln n_eff, 4 K parameters */
        double score = n_eff * ll - 2.0 * K * log(n_eff);
        if (!(score > best_score))
            break;
        best = cand;
        best_score = score;
        float *swap = r_best;
        r_best = r_cand;
        r_cand = swap;
    }
    uint32_t index[LMB_MIXTURE_MAX_LOBES];
    to_mixture(&best, out, index);
    if (best.K == 0 || out->count == 0)
        return 1;
    set_targets(out, index, scratch->w, scratch->s, scratch->d, r_best, m, best.K + 1);
    return 1;
}

int lmb_mixture_update(const double *w, const double *s, uint32_t n, const double normal[3], const lmb_mixture *start,
                       lmb_mixture_scratch *scratch, lmb_mixture *out)
{
    double n_eff;
    uint32_t m = select_samples(w, s, NULL, n, scratch, &n_eff);
    if (!m)
        return 0;
    model md, diffuse = {0};
    diffuse.lobe[0] = (lmb_lobe){{normal[0], normal[1], normal[2]}, 1.0};
    diffuse.share[0] = 1;
    double ll;
    if (start && start->count == 1) {
        md.K = 1;
        md.lobe[0] = diffuse.lobe[0];
        md.share[0] = start->diffuse;
        md.lobe[1] = start->lobe[0];
        md.share[1] = 1.0 - start->diffuse;
        ll = em(scratch->w, scratch->s, scratch->r, m, EM_STEPS_WARM, &md);
    } else {
        ll = fit_k(scratch->w, scratch->s, scratch->r, m, 1, normal, EM_STEPS_COLD, &md);
    }
    if (!(ll > -HUGE_VAL))
        return 0;
    /* the cosine lobe alone unless the lobe pays for its 4 parameters (BIC, as lmb_mixture_fit):
     * where light comes from everywhere alike the next iteration samples as classic gathering */
    double ll0 = responsibilities(&diffuse, scratch->w, scratch->s, m, scratch->r2);
    if (n_eff * ll0 >= n_eff * ll - 2.0 * log(n_eff))
        md = diffuse;
    uint32_t index[1];
    to_mixture(&md, out, index);
    return 1;
}
