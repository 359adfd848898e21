/* Ring-by-ring dilation (see dilate.h). Each ring reads only texels filled in earlier rings,
 * so the result does not depend on visiting order. */
#include "dilate.h"

#include <omp.h>

#include <stdlib.h>
#include <string.h>

/* May texel i be filled in ring `ring` (1 = next to a valid texel)? */
static int fillable(const uint8_t *kind, size_t i, uint32_t ring)
{
    return kind[i] == LMB_TEXEL_EMPTY || ring <= LMB_DILATE_INSIDE_RINGS;
}

/* Is some neighbour of texel i (8-connected) filled? */
static int near_filled(const uint8_t *state, uint32_t w, uint32_t h, size_t i)
{
    uint32_t x = (uint32_t)(i % w), y = (uint32_t)(i / w);
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            long xx = (long)x + dx, yy = (long)y + dy;
            if (xx >= 0 && yy >= 0 && xx < (long)w && yy < (long)h && state[(size_t)yy * w + (size_t)xx] == 1)
                return 1;
        }
    return 0;
}

lmb_status lmb_dilate(float *rgb, const uint8_t *kind, uint32_t w, uint32_t h, int threads, lmb_error *err)
{
    size_t n = (size_t)w * h;
    threads = threads > 0 ? threads : omp_get_max_threads();
    uint32_t *ring = malloc((n + 1) * sizeof *ring), *next = malloc((n + 1) * sizeof *next);
    uint8_t *state = malloc(n + 1); /* 0 empty, 1 filled, 2 queued for this ring */
    uint8_t *first = malloc(n + 1);
    if (!ring || !next || !state || !first) {
        free(ring);
        free(next);
        free(state);
        free(first);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "dilate: out of memory for %ux%u", w, h);
    }
    size_t nr = 0;
#pragma omp parallel for num_threads(threads) schedule(static)
    for (size_t i = 0; i < n; i++)
        state[i] = kind[i] == LMB_TEXEL_VALID ? 1 : 0;
    /* first ring: empty texels next to a filled one (found in parallel, listed in texel order) */
#pragma omp parallel for num_threads(threads) schedule(static)
    for (size_t i = 0; i < n; i++)
        first[i] = !state[i] && fillable(kind, i, 1) && near_filled(state, w, h, i);
    for (size_t i = 0; i < n; i++)
        if (first[i]) {
            ring[nr++] = (uint32_t)i;
            state[i] = 2;
        }
    free(first);
    for (uint32_t ring_no = 1; nr; ring_no++) {
        /* average filled neighbours into each ring texel: each reads filled texels only and
         * writes itself, so the ring's texels go in parallel in any order */
#pragma omp parallel for num_threads(threads) schedule(static) if (nr > 4096)
        for (size_t r = 0; r < nr; r++) {
            uint32_t i = ring[r], x = i % w, y = i / w, cnt = 0;
            int darkest = kind[i] == LMB_TEXEL_INSIDE;
            float s[3] = {0, 0, 0}, least = 0;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    long xx = (long)x + dx, yy = (long)y + dy;
                    if (xx < 0 || yy < 0 || xx >= (long)w || yy >= (long)h)
                        continue;
                    size_t j = (size_t)yy * w + (size_t)xx;
                    if (state[j] != 1)
                        continue;
                    const float *v = rgb + 3 * j;
                    float lum = 0.2126f * v[0] + 0.7152f * v[1] + 0.0722f * v[2];
                    if (darkest) { /* the first of the darkest, in scan order */
                        if (!cnt || lum < least)
                            for (int c = 0; c < 3; c++)
                                s[c] = v[c];
                        least = !cnt || lum < least ? lum : least;
                        cnt = 1;
                        continue;
                    }
                    for (int c = 0; c < 3; c++)
                        s[c] += v[c];
                    cnt++;
                }
            for (int c = 0; c < 3; c++)
                rgb[3 * (size_t)i + c] = cnt ? s[c] / (float)cnt : 0.0f;
        }
        /* mark the ring filled, then collect the next one (the list's order does not change
         * the result: a ring's texels read only earlier rings) */
        for (size_t r = 0; r < nr; r++)
            state[ring[r]] = 1;
        size_t nn = 0;
        for (size_t r = 0; r < nr; r++) {
            uint32_t i = ring[r], x = i % w, y = i / w;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    long xx = (long)x + dx, yy = (long)y + dy;
                    if (xx < 0 || yy < 0 || xx >= (long)w || yy >= (long)h)
                        continue;
                    size_t j = (size_t)yy * w + (size_t)xx;
                    if (state[j] == 0 && fillable(kind, j, ring_no + 1)) {
                        state[j] = 2;
                        next[nn++] = (uint32_t)j;
                    }
                }
        }
        uint32_t *t = ring;
        ring = next;
        next = t;
        nr = nn;
    }
    free(ring);
    free(next);
    free(state);
    return LMB_OK;
}
