/* The direct stage's light written for the watch (see direct_out.h). */
#include "direct_out.h"

#include "write/atlas_images.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

lmb_status lmb_direct_out_write(const lmb_config *cfg, lmb_cache *cache, uint32_t a, const lmb_texels *t,
                                const float *direct, const float *deferred, lmb_error *err)
{
    size_t n = 3 * (size_t)t->count;
    float *shown = malloc((n + 1) * sizeof *shown);
    if (!shown)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "--direct-out: out of memory for atlas %u", a);
    for (size_t k = 0; k < n; k++) { /* what the lightmap holds of it (lighting.c does the same) */
        float v = direct[k] - (deferred ? deferred[k] : 0.0f);
        shown[k] = v > 0 ? v : 0.0f;
    }
    lmb_status st = lmb_cache_store(cache, a, t, shown, err);
    free(shown);
    const char *path = cache->scene->path, *base = strrchr(path, '/');
    char stem[256];
    snprintf(stem, sizeof stem, "%s", base ? base + 1 : path);
    char *dot = strrchr(stem, '.');
    if (dot && dot != stem)
        *dot = '\0';
    if (st == LMB_OK)
        st = lmb_write_hdr_image(cfg, cfg->direct_out, stem, a, cache->irradiance[a], cache->layout->width[a],
                                 cache->layout->height[a], err);
    return st;
}
