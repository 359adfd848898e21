/*
 * Sampling helpers shared by the lights and the gather:
 *   - the cosine-power lobe of the AMIS paper (eq. 1): p(w; n^, a) = (a + 1) / (2 pi) (w.n^)^a on
 *     the hemisphere around the unit axis n^, zero outside it. a = 1 is cosine sampling (the
 *     Lambertian pdf cos/pi), the starting lobe of every gather point. Sampling inverts the
 *     CDF of cos(theta): cos(theta) = u1^(1 / (a + 1)), phi = 2 pi u2, in the frame of
 *     util/frame.h;
 *   - picking a segment of a tabulated CDF (lights by power, emitters by power, the sky map's rows
 *     and columns) by binary search.
 */
#ifndef LMBAKE_SAMPLING_H
#define LMBAKE_SAMPLING_H

#include "util/frame.h"
#include "util/lmb_math.h"

#include <math.h>
#include <stdint.h>

/* The segment of cdf[0..count] (non-decreasing, cdf[count] > 0) that u in [0, 1) picks:
 * u x cdf[count] lies in [cdf[k], cdf[k + 1]); *prob = its share of the total. */
uint32_t lmb_cdf_pick(const double *cdf, uint32_t count, double u, double *prob);

/* The segment of cdf[0..n] (non-decreasing, cdf[n] > 0) holding x in [0, cdf[n]), never one of
 * zero weight (x rounded onto a boundary moves past it). */
uint32_t lmb_cdf_segment(const double *cdf, uint32_t n, double x);

typedef struct lmb_lobe {
    double axis[3]; /* unit */
    double a;       /* exponent, >= 0 */
} lmb_lobe;

/* pdf of direction w (unit) under the lobe, per steradian. */
static inline double lmb_lobe_pdf(const lmb_lobe *l, const double w[3])
{
    double c = lmb_dot3(w, l->axis);
    if (c <= 0)
        return 0;
    /* single precision for the power: ~1e-7 relative, 3x faster than pow, and AMIS evaluates
     * it N x T times per gather point (a weight does not need more) */
    return (l->a + 1.0) * (0.5 * LMB_INV_PI) * (l->a == 1.0 ? c : (double)expf((float)l->a * logf((float)c)));
}

/* Direction drawn from the lobe with uniforms u1, u2 in [0, 1), in the lobe's frame (t, b, axis)
 * from lmb_frame (a mixture computes its lobes' frames once). */
static inline void lmb_lobe_sample_in_frame(const lmb_lobe *l, const double t[3], const double b[3], double u1,
                                            double u2, double w[3])
{
    /* 1 - u1 is in (0, 1]: cos(theta) > 0, so the pdf of the sample is never 0 */
    double ct = l->a == 1.0 ? sqrt(1.0 - u1) : (double)expf(logf((float)(1.0 - u1)) / (float)(l->a + 1.0));
    double st = sqrt(fmax(0.0, 1.0 - ct * ct));
    float phi = (float)(2.0 * LMB_PI * u2); /* single precision: the direction needs no more */
    double x = st * (double)cosf(phi), y = st * (double)sinf(phi);
    for (int k = 0; k < 3; k++)
        w[k] = x * t[k] + y * b[k] + ct * l->axis[k];
}

/* Direction drawn from the lobe with uniforms u1, u2 in [0, 1). */
static inline void lmb_lobe_sample(const lmb_lobe *l, double u1, double u2, double w[3])
{
    double t[3], b[3];
    lmb_frame(l->axis, t, b);
    lmb_lobe_sample_in_frame(l, t, b, u1, u2, w);
}

#endif
