/* The edge-aware a-trous filter of an atlas's baked light (see denoise.h). */
#include "denoise.h"

#include "util/lmb_math.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* What the filter reads of a valid listed texel: where it is and how it faces (its size and
 * instance it reads from the texels). */
typedef struct texel_guide {
    float p[3], n[3];
} texel_guide;

/* The instance texel i lies on (its gather point's, lmb_texels_point's point 0). */
static uint32_t instance_of(const lmb_texels *t, uint32_t i)
{
    size_t at = (size_t)i * t->samples;
    return t->refs ? t->refs[at].instance : t->points[at].instance;
}

#define NOT_LISTED UINT32_MAX
#define LIGHT_CUT 16.0f /* the light term's cut-off, in its scale (exp(-16) = 1e-7) */

static const float B3[5] = {1.0f / 16, 4.0f / 16, 6.0f / 16, 4.0f / 16, 1.0f / 16};

/* The surface part of w(p, q) (denoise.h) for texels `atlas_distance` texels apart (g: the
 * guides of listed texels from g0 on); 0 when q is on another surface. */
static float surface_weight(const lmb_texels *t, uint32_t p, uint32_t q, const texel_guide *g, uint32_t g0,
                            float atlas_distance, float step)
{
    if (instance_of(t, p) != instance_of(t, q))
        return 0;
    const texel_guide *gp = &g[p - g0], *gq = &g[q - g0];
    float size = t->texel_size[p];
    float d[3] = {gq->p[0] - gp->p[0], gq->p[1] - gp->p[1], gq->p[2] - gp->p[2]};
    float far = 2.0f * (atlas_distance + 1.0f) * size;
    if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > far * far)
        return 0;
    float plane = fabsf(d[0] * gp->n[0] + d[1] * gp->n[1] + d[2] * gp->n[2]) / (size * step);
    float cosine = gp->n[0] * gq->n[0] + gp->n[1] * gq->n[1] + gp->n[2] * gq->n[2];
    if (cosine <= 0)
        return 0;
    return expf(-plane * plane) * powf(cosine, (float)LMB_DENOISE_NORMAL_POWER);
}

/*
 * The light at the centre tap from a plane fitted to the weighted taps (weighted least squares
 * of E = a + b u + c v; out = a, kept within the taps' range): a weighted mean is biased
 * wherever the taps are one-sided and the light has a slope (a chart's border at a corner, the
 * floor beside a block), a plane is not. Taps that cannot fix a plane (a line of texels) give
 * their weighted mean.
 */
static void plane_fit(const double m[6], double r[3][3], const float lo[3], const float hi[3], float *out)
{
    /* the inverse's first row of [[m0 m1 m2] [m1 m3 m4] [m2 m4 m5]], by cofactors */
    double c0 = m[3] * m[5] - m[4] * m[4], c1 = m[2] * m[4] - m[1] * m[5], c2 = m[1] * m[4] - m[2] * m[3];
    double det = m[0] * c0 + m[1] * c1 + m[2] * c2;
    int plane = det > 1e-6 * m[0] * m[0] * m[0];
    for (int c = 0; c < 3; c++) {
        double a = plane ? (c0 * r[c][0] + c1 * r[c][1] + c2 * r[c][2]) / det : r[c][0] / m[0];
        out[c] = (float)(a < lo[c] ? lo[c] : a > hi[c] ? hi[c] : a);
    }
}

/* One a-trous pass with taps `step` texels apart over listed texels [first, last): out (3
 * floats per texel of the range) from in (every listed texel's). */
static void atrous_pass(const lmb_texels *t, const uint32_t *listed, const texel_guide *g, uint32_t g0, const float *in,
                        float *out, uint32_t first, uint32_t last, uint32_t step, double light_scale,
                        const float *variance, int threads)
{
#pragma omp parallel for num_threads(threads) schedule(dynamic, 256)
    for (uint32_t i = first; i < last; i++) {
        const float *cp = in + 3 * (size_t)i;
        float *o = out + 3 * (size_t)(i - first);
        if (!t->valid[i]) {
            memcpy(o, cp, 3 * sizeof *o);
            continue;
        }
        long x = (long)(t->texel[i] % t->width), y = (long)(t->texel[i] / t->width);
        float lp = (float)lmb_luminance_f(cp);
        /* weighted moments for the local plane fit: m[0..5] = sum w (1, u, v, uu, uv, vv),
         * r[c] = sum w E_c (1, u, v), u and v the tap's offset in taps */
        double m[6] = {0, 0, 0, 0, 0, 0}, r[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
        float lo[3] = {cp[0], cp[1], cp[2]}, hi[3] = {cp[0], cp[1], cp[2]};
        for (int ky = 0; ky < 5; ky++) {
            long yy = y + (long)(ky - 2) * step;
            if (yy < 0 || yy >= (long)t->height)
                continue;
            for (int kx = 0; kx < 5; kx++) {
                long xx = x + (long)(kx - 2) * step;
                if (xx < 0 || xx >= (long)t->width)
                    continue;
                uint32_t j = listed[(size_t)yy * t->width + (size_t)xx];
                if (j == NOT_LISTED || !t->valid[j])
                    continue;
                const float *cq = in + 3 * (size_t)j;
                float w = B3[kx] * B3[ky];
                if (j != i) {
                    float dx = (float)(kx - 2) * step, dy = (float)(ky - 2) * step;
                    w *= surface_weight(t, i, j, g, g0, sqrtf(dx * dx + dy * dy), (float)step);
                    float lq = (float)lmb_luminance_f(cq);
                    float scale = variance ? (float)light_scale * sqrtf(variance[i] + variance[j])
                                           : (float)(light_scale * 0.5 * (lp + lq));
                    if (w > 0 && lp != lq) { /* past LIGHT_CUT the weight is 0, not 1e-7: dark stays dark */
                        float z = scale > 0 ? fabsf(lp - lq) / scale : LIGHT_CUT;
                        w *= z < LIGHT_CUT ? expf(-z) : 0.0f;
                    }
                }
                if (w <= 0)
                    continue;
                double u = kx - 2, v = ky - 2;
                m[0] += w, m[1] += w * u, m[2] += w * v, m[3] += w * u * u, m[4] += w * u * v, m[5] += w * v * v;
                for (int c = 0; c < 3; c++) {
                    r[c][0] += (double)w * cq[c], r[c][1] += (double)w * cq[c] * u, r[c][2] += (double)w * cq[c] * v;
                    lo[c] = cq[c] < lo[c] ? cq[c] : lo[c];
                    hi[c] = cq[c] > hi[c] ? cq[c] : hi[c];
                }
            }
        }
        plane_fit(m, r, lo, hi, o);
    }
}

/* Each valid texel's variance averaged over the valid texels of its 3 x 3 neighbourhood on
 * the same instance (SVGF's prefilter, Schied et al. 2017 sec. 4.3): a variance estimated
 * from a texel's two rounds alone is itself noisy, and 0 by chance would pin the texel. */
static void smooth_variance(const lmb_texels *t, const uint32_t *listed, const float *variance, float *out,
                            int threads)
{
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1024)
    for (uint32_t i = 0; i < t->count; i++) {
        out[i] = variance[i];
        if (!t->valid[i])
            continue;
        long x = (long)(t->texel[i] % t->width), y = (long)(t->texel[i] / t->width);
        double sum = 0;
        int n = 0;
        for (long yy = y - 1; yy <= y + 1; yy++)
            for (long xx = x - 1; xx <= x + 1; xx++) {
                if (xx < 0 || yy < 0 || xx >= (long)t->width || yy >= (long)t->height)
                    continue;
                uint32_t j = listed[(size_t)yy * t->width + (size_t)xx];
                if (j != NOT_LISTED && t->valid[j] && instance_of(t, j) == instance_of(t, i)) {
                    sum += variance[j];
                    n++;
                }
            }
        out[i] = (float)(sum / n);
    }
}

struct lmb_denoiser {
    const lmb_texels *t;
    uint32_t *listed;   /* atlas texel -> listed index, or NOT_LISTED */
    float *variance;    /* smoothed, or NULL */
    double light_scale;
    uint32_t levels;
    int rows_sorted;    /* listed texels in atlas order: a range's guides are its rows' and its taps' */
};

void lmb_denoiser_free(lmb_denoiser *d)
{
    if (!d)
        return;
    free(d->listed);
    free(d->variance);
    free(d);
}

lmb_status lmb_denoiser_create(const lmb_texels *t, const lmb_denoise_options *opt, lmb_denoiser **out, lmb_error *err)
{
    *out = NULL;
    if (opt->levels < 1 || opt->levels > 8 || !(opt->variance || opt->noise > 0) || !(opt->sigma_light > 0))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "denoise: levels %u, noise %g, sigma %g out of range", opt->levels,
                             opt->noise, opt->sigma_light);
    size_t n = (size_t)t->width * t->height;
    lmb_denoiser *d = calloc(1, sizeof *d);
    if (d) {
        d->t = t;
        d->levels = opt->levels;
        d->light_scale = opt->variance ? opt->sigma_light : opt->sigma_light * opt->noise;
        d->listed = malloc((n + 1) * sizeof *d->listed);
        d->variance = opt->variance ? malloc(((size_t)t->count + 1) * sizeof *d->variance) : NULL;
    }
    if (!d || !d->listed || (opt->variance && !d->variance)) {
        lmb_denoiser_free(d);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "denoise: out of memory for a %ux%u atlas", t->width, t->height);
    }
    for (size_t k = 0; k < n; k++)
        d->listed[k] = NOT_LISTED;
    d->rows_sorted = 1;
    for (uint32_t i = 0; i < t->count; i++) {
        d->listed[t->texel[i]] = i;
        d->rows_sorted &= i == 0 || t->texel[i] > t->texel[i - 1];
    }
    int threads = opt->threads > 0 ? opt->threads : omp_get_max_threads();
    if (d->variance)
        smooth_variance(t, d->listed, opt->variance, d->variance, threads);
    *out = d;
    return LMB_OK;
}

int lmb_denoiser_in_order(const lmb_denoiser *d)
{
    return d->rows_sorted;
}

/* The first listed texel at or after atlas texel `texel` (t->texel ascending). */
static uint32_t listed_from(const lmb_texels *t, uint64_t texel)
{
    uint32_t lo = 0, hi = t->count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (t->texel[mid] < texel)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

lmb_status lmb_denoiser_level(const lmb_denoiser *d, uint32_t level, const float *in, uint32_t first, uint32_t last,
                              float *out, int threads, lmb_error *err)
{
    const lmb_texels *t = d->t;
    if (first >= last)
        return LMB_OK;
    threads = threads > 0 ? threads : omp_get_max_threads();
    /* the guides of the range's rows and of every row its taps reach (2 x 2^level rows each way):
     * built for the pass and dropped, so no pass holds an atlas's guides whole */
    uint32_t g0 = 0, g1 = t->count;
    if (d->rows_sorted) {
        uint64_t reach = lmb_denoiser_reach(level), y0 = t->texel[first] / t->width, y1 = t->texel[last - 1] / t->width + 1;
        g0 = listed_from(t, (y0 > reach ? y0 - reach : 0) * t->width);
        g1 = listed_from(t, (y1 + reach) * (uint64_t)t->width);
    }
    texel_guide *g = malloc(((size_t)(g1 - g0) + 1) * sizeof *g);
    if (!g)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "denoise: out of memory for the guides of %u texels", g1 - g0);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1024)
    for (uint32_t i = g0; i < g1; i++) {
        texel_guide *gi = &g[i - g0];
        memset(gi, 0, sizeof *gi);
        if (!t->valid[i])
            continue;
        lmb_gather_point gp;
        lmb_texels_point(t, i, 0, &gp);
        for (int k = 0; k < 3; k++) {
            gi->p[k] = (float)gp.p[k];
            gi->n[k] = gp.n[k];
        }
    }
    atrous_pass(t, d->listed, g, g0, in, out, first, last, 1u << level, d->light_scale, d->variance, threads);
    free(g);
    return LMB_OK;
}

void lmb_denoise_measure(const lmb_texels *t, const float *rgb, double *sum, uint64_t *texels)
{
    for (uint32_t i = 0; i < t->count; i++)
        if (t->valid[i]) {
            *sum += lmb_luminance_f(rgb + 3 * (size_t)i);
            if (texels)
                (*texels)++;
        }
}

lmb_status lmb_denoise_atlas(const lmb_texels *t, float *rgb, const lmb_denoise_options *opt,
                             lmb_denoise_stats *stats, lmb_error *err)
{
    lmb_denoiser *d;
    lmb_status st = lmb_denoiser_create(t, opt, &d, err);
    if (st != LMB_OK)
        return st;
    size_t m = 3 * (size_t)t->count;
    float *work = malloc((m + 1) * sizeof *work);
    if (!work) {
        lmb_denoiser_free(d);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "denoise: out of memory for a %ux%u atlas", t->width, t->height);
    }
    lmb_denoise_measure(t, rgb, &stats->before, &stats->texels);
    /* passes alternate between rgb and work; an odd count ends in work and is copied back */
    float *from = rgb, *to = work;
    for (uint32_t level = 0; level < opt->levels; level++) {
        lmb_status st = lmb_denoiser_level(d, level, from, 0, t->count, to, opt->threads, err);
        if (st != LMB_OK) {
            free(work);
            lmb_denoiser_free(d);
            return st;
        }
        float *swap = from;
        from = to;
        to = swap;
    }
    if (from != rgb)
        memcpy(rgb, from, m * sizeof *rgb);
    lmb_denoise_measure(t, rgb, &stats->after, NULL);
    free(work);
    lmb_denoiser_free(d);
    return LMB_OK;
}
