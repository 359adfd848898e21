/*
 * The denoiser: an edge-aware a-trous filter of one atlas's light, in lightmap space: the final
 * gather's light, then all of it with the direct light's own variances (lighting.c, through
 * denoise_steps.h).
 *
 * The final gather's noise sits in the irradiance cache's records: each record's error is
 * copied to every texel it serves, so it is correlated over a record's reach (4 to 8 texels)
 * and neither more texel samples nor a wider interpolation remove it at a fair cost
 * (docs/noise.md). The filter averages a texel with the texels around it that lie on the same
 * surface and hold the same light up to the noise:
 *
 *   E'(p) = sum_q h(q - p) w(p, q) E(q) / sum_q h(q - p) w(p, q),
 *
 * over `levels` passes of the 5 x 5 B3-spline kernel h = (1, 4, 6, 4, 1) / 16 with holes, its
 * taps 2^k texels apart at pass k (Dammertz et al. 2010, "Edge-avoiding A-trous wavelet
 * transform for fast global illumination filtering", eq. 1-3; SVGF's luminance term, Schied et
 * al. 2017, eq. 3-5). The edge-stopping weight w is the product of
 *   - the surface: q on the same instance, its world distance at most 2 x (atlas distance + 1)
 *     texel sizes (a chart border in the atlas is a jump in the world), its distance from p's
 *     tangent plane under a texel size per tap step, and its shading normal
 *     max(0, n_p . n_q)^LMB_DENOISE_NORMAL_POWER;
 *   - the light: exp(-|l_p - l_q| / (sigma_l x noise x (l_p + l_q) / 2)), l the luminance and
 *     noise the relative standard error of the records' gathers (ic_pass.h), or, where every
 *     texel's own variance is known (the direct light's samples, direct_refine.h),
 *     exp(-|l_p - l_q| / (sigma_l sqrt(var_p + var_q))): a difference the noise cannot explain
 *     is an edge of the light, kept. The term is 0 past 16 of its scales (exp(-16) = 1e-7), so
 *     dark stays exactly dark beside light the noise cannot explain.
 * Each pass fits a plane to its weighted taps and keeps the plane's value at the centre
 * (weighted least squares): a weighted mean would be biased wherever the taps are one-sided on
 * a slope of light (a chart's border at a room's corner, a penumbra), a plane is not.
 * Texels that are not valid neither give nor take. Each pass reads the previous one's result
 * only, so the output does not depend on the thread count.
 */
#ifndef LMBAKE_DENOISE_H
#define LMBAKE_DENOISE_H

#include <lmbake/lmbake.h>

#include "texels/texels.h"

#define LMB_DENOISE_NORMAL_POWER 64.0
/* a texel's noise in the interpolated light, as a share of its records' median estimate */
#define LMB_DENOISE_TEXEL_SHARE 0.25
/* passes for the direct light's noise, which is white (a texel's own samples): 5 x 5 at 1 */
#ifndef LMB_DENOISE_DIRECT_LEVELS
#define LMB_DENOISE_DIRECT_LEVELS 2
#endif

/* A pass's estimated cost per texel in rays (the step runner's unit): about 0.9 us per texel and
 * pass on one core here, against 0.3 us per ray */
#define LMB_DENOISE_RAYS_PER_TEXEL 3.0

typedef struct lmb_denoise_options {
    uint32_t levels;     /* a-trous passes (taps 1, 2, ..., 2^(levels-1) texels apart), 1..8 */
    double noise;        /* relative standard error of the light before filtering (> 0) */
    const float *variance; /* NULL, or per listed texel the variance of its luminance as an estimate:
                              then the light term is exp(-|l_p - l_q| / (sigma_l sqrt(var_p + var_q)))
                              and noise is unused (a texel of variance 0 keeps its light) */
    double sigma_light;  /* how many times the noise a luminance difference may be and still count */
    int threads;         /* 0: OpenMP's default */
} lmb_denoise_options;

typedef struct lmb_denoise_stats {
    uint64_t texels;     /* valid texels filtered */
    double before, after; /* their luminance, summed, before and after */
} lmb_denoise_stats;

/* One atlas's filter state (the atlas-to-texel map, the smoothed variances; where each texel is
 * and how it faces is built per range): made once, then each pass can run over any range of texels,
 * so the passes can be steps of the bake (denoise_steps.h). Owned: lmb_denoiser_free. t and
 * opt->variance must outlive it. */
typedef struct lmb_denoiser lmb_denoiser;

lmb_status lmb_denoiser_create(const lmb_texels *t, const lmb_denoise_options *opt, lmb_denoiser **out,
                               lmb_error *err);
void lmb_denoiser_free(lmb_denoiser *d);

/* Pass `level` (taps 2^level texels apart) over listed texels [first, last): out gets 3 floats
 * per texel of the range, from in (3 floats per listed texel: the previous pass's result).
 * Reads in only within lmb_denoiser_reach(level) atlas rows of the range's rows, so a caller
 * going through the texels in order may write a texel's result back into in once the ranges
 * still to come start more than that many rows past it. */
lmb_status lmb_denoiser_level(const lmb_denoiser *d, uint32_t level, const float *in, uint32_t first, uint32_t last,
                              float *out, int threads, lmb_error *err);

/* Whether the listed texels are in atlas order (as the lights stage lists them); when not,
 * results may be written back only once a pass is done. */
int lmb_denoiser_in_order(const lmb_denoiser *d);

/* How many atlas rows pass `level`'s taps reach either way. */
static inline uint32_t lmb_denoiser_reach(uint32_t level)
{
    return 2u << level;
}

/* Adds the valid texels' luminance to *sum (and their count to *texels unless NULL). */
void lmb_denoise_measure(const lmb_texels *t, const float *rgb, double *sum, uint64_t *texels);

/* rgb: 3 floats per listed texel of t, filtered in place. Adds to *stats. */
lmb_status lmb_denoise_atlas(const lmb_texels *t, float *rgb, const lmb_denoise_options *opt,
                             lmb_denoise_stats *stats, lmb_error *err);

#endif
