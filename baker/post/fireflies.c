/* Fireflies spread to their neighbours (see fireflies.h). */
#include "fireflies.h"

#include "texels/dilate.h"

#include <omp.h>

#include <stdlib.h>
#include <string.h>

static float luminance(const float *c)
{
    return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
}

/* The median luminance of the valid texels of the 5 x 5 window around (x, y), itself left out;
 * -1 when fewer than 8 are valid (too little to call anything an outlier), or when even the
 * window's least value is over lum / LMB_FIREFLY_FACTOR (the median is at least the least:
 * no spike, and no sort). */
static float window_median(const float *lum, const uint8_t *state, uint32_t w, uint32_t h, long x, long y)
{
    float v[24], least = 0, spike = lum[(size_t)y * w + (size_t)x];
    int n = 0;
    for (long dy = -2; dy <= 2; dy++)
        for (long dx = -2; dx <= 2; dx++) {
            long xx = x + dx, yy = y + dy;
            if ((!dx && !dy) || xx < 0 || yy < 0 || xx >= (long)w || yy >= (long)h)
                continue;
            size_t j = (size_t)yy * w + (size_t)xx;
            if (state[j] == LMB_TEXEL_VALID) {
                least = n == 0 || lum[j] < least ? lum[j] : least;
                v[n++] = lum[j];
            }
        }
    if (n < 8 || spike <= LMB_FIREFLY_FACTOR * least)
        return -1;
    for (int a = 1; a < n; a++) { /* insertion sort: at most 24 values, once per texel (qsort's calls cost more) */
        float t = v[a];
        int b = a;
        for (; b > 0 && v[b - 1] > t; b--)
            v[b] = v[b - 1];
        v[b] = t;
    }
    return n % 2 ? v[n / 2] : 0.5f * (v[n / 2 - 1] + v[n / 2]);
}

/* The part of texel i's light it keeps when it is a lone spike (0 < keep < 1), with its m valid
 * neighbours in nb; 1 when it is no spike. Reads only lum and state: any texel, any order. */
static float spike_keep(const float *lum, const uint8_t *state, uint32_t w, uint32_t h, size_t i, size_t nb[8], int *m)
{
    *m = 0;
    if (state[i] != LMB_TEXEL_VALID || !(lum[i] > 0))
        return 1.0f;
    long x = (long)(i % w), y = (long)(i / w);
    float median = window_median(lum, state, w, h, x, y);
    if (median < 0 || lum[i] <= LMB_FIREFLY_FACTOR * median)
        return 1.0f;
    float brightest = 0;
    for (long dy = -1; dy <= 1; dy++)
        for (long dx = -1; dx <= 1; dx++) {
            long xx = x + dx, yy = y + dy;
            if ((dx || dy) && xx >= 0 && yy >= 0 && xx < (long)w && yy < (long)h &&
                state[(size_t)yy * w + (size_t)xx] == LMB_TEXEL_VALID) {
                nb[*m] = (size_t)yy * w + (size_t)xx;
                brightest = lum[nb[*m]] > brightest ? lum[nb[*m]] : brightest;
                (*m)++;
            }
        }
    /* a lone spike: a line of light one texel wide (light through a slit) has neighbours as
     * bright along it, a lit area beside a shadow has lit neighbours: neither is touched */
    if (!*m || lum[i] <= LMB_FIREFLY_LONE * brightest)
        return 1.0f;
    return (float)(LMB_FIREFLY_FACTOR * median / lum[i]);
}

lmb_status lmb_fireflies_spread(float *rgb, const uint8_t *state, uint32_t w, uint32_t h, int threads,
                                lmb_firefly_stats *stats, lmb_error *err)
{
    size_t n = (size_t)w * h;
    float *lum = malloc((n + 1) * sizeof *lum), *before = malloc((3 * n + 1) * sizeof *before);
    uint8_t *spike = malloc(n + 1);
    if (!lum || !before || !spike) {
        free(lum);
        free(before);
        free(spike);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "fireflies: out of memory for a %ux%u atlas", w, h);
    }
    threads = threads > 0 ? threads : omp_get_max_threads();
    memcpy(before, rgb, 3 * n * sizeof *rgb);
#pragma omp parallel for num_threads(threads) schedule(static)
    for (size_t i = 0; i < n; i++)
        lum[i] = luminance(before + 3 * i);
    for (size_t i = 0; i < n; i++) /* in texel order: the same sum at any thread count */
        if (state[i] == LMB_TEXEL_VALID)
            stats->total += lum[i];
    /* finding the spikes (a 5 x 5 median per texel) is the work: in parallel */
#pragma omp parallel for num_threads(threads) schedule(dynamic, 4096)
    for (size_t i = 0; i < n; i++) {
        size_t nb[8];
        int m;
        spike[i] = spike_keep(lum, state, w, h, i, nb, &m) < 1.0f;
    }
    /* moving their light adds into shared neighbours: in texel order, as one thread would */
    for (size_t i = 0; i < n; i++) {
        if (!spike[i])
            continue;
        size_t nb[8];
        int m;
        float keep = spike_keep(lum, state, w, h, i, nb, &m);
        for (int c = 0; c < 3; c++) {
            float moved = before[3 * i + c] * (1.0f - keep);
            rgb[3 * i + c] -= moved;
            for (int k = 0; k < m; k++)
                rgb[3 * nb[k] + c] += moved / (float)m;
        }
        stats->texels++;
        stats->moved += lum[i] * (1.0 - keep);
    }
    free(lum);
    free(before);
    free(spike);
    return LMB_OK;
}
