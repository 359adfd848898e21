/* Partly covered texels limited to their neighbours (see rim.h). */
#include "rim.h"

#include <stdlib.h>

static double luminance(const float *c)
{
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

lmb_status lmb_rim_limit(const lmb_texels *t, float *rgb, lmb_rim_stats *stats, lmb_error *err)
{
    size_t n = (size_t)t->width * t->height;
    int64_t *listed = malloc((n + 1) * sizeof *listed); /* atlas texel -> listed index, or -1 */
    if (!listed)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "rim: out of memory for a %ux%u atlas", t->width, t->height);
    for (size_t k = 0; k < n; k++)
        listed[k] = -1;
    for (uint32_t i = 0; i < t->count; i++) {
        listed[t->texel[i]] = i;
        if (t->valid[i])
            stats->total += luminance(rgb + 3 * (size_t)i);
    }
    /* limits come from uncovered texels only, which this loop never changes: the result does
     * not depend on the order */
    for (uint32_t i = 0; i < t->count; i++) {
        if (!t->valid[i] || !(t->edge[i] & LMB_EDGE_COVERED))
            continue;
        long x = (long)(t->texel[i] % t->width), y = (long)(t->texel[i] / t->width);
        double limit = -1;
        for (long dy = -1; dy <= 1; dy++)
            for (long dx = -1; dx <= 1; dx++) {
                long xx = x + dx, yy = y + dy;
                if ((!dx && !dy) || xx < 0 || yy < 0 || xx >= (long)t->width || yy >= (long)t->height)
                    continue;
                int64_t j = listed[(size_t)yy * t->width + (size_t)xx];
                if (j < 0 || !t->valid[j] || (t->edge[j] & LMB_EDGE_COVERED))
                    continue;
                double l = luminance(rgb + 3 * (size_t)j);
                limit = l > limit ? l : limit;
            }
        float *c = rgb + 3 * (size_t)i;
        double l = luminance(c);
        if (limit < 0 || l <= limit) /* no uncovered neighbour to compare with, or not brighter */
            continue;
        float f = (float)(limit / l);
        for (int k = 0; k < 3; k++)
            c[k] *= f;
        stats->limited++;
        stats->removed += l - luminance(c);
    }
    free(listed);
    return LMB_OK;
}
