/* The light at each stage of a bake written for the watch (see stages_out.h). */
#include "stages_out.h"

#include "write/atlas_images.h"
#include "write/output_dir.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

lmb_status lmb_stages_out_write(const lmb_config *cfg, const char *stage, lmb_cache *cache, uint32_t a,
                                const lmb_texels *t, const float *light, const float *deferred, lmb_error *err)
{
    char dir[sizeof cfg->stages_out + 32];
    snprintf(dir, sizeof dir, "%s/%s", cfg->stages_out, stage);
    if (mkdir(dir, 0777) != 0 && errno != EEXIST)
        return lmb_error_set(err, LMB_ERR_INPUT, "--stages-out: cannot make the folder '%s' (%s)", dir, strerror(errno));
    size_t n = 3 * (size_t)t->count;
    float *shown = malloc((n + 1) * sizeof *shown);
    if (!shown)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "--stages-out: out of memory for atlas %u", a);
    for (size_t k = 0; k < n; k++) { /* what the lightmap holds of it (lighting.c does the same) */
        float v = light[k] - (deferred ? deferred[k] : 0.0f);
        shown[k] = v > 0 ? v : 0.0f;
    }
    lmb_status st = lmb_cache_store(cache, a, t, shown, err);
    free(shown);
    char stem[256];
    lmb_output_stem(cache->scene->path, stem, sizeof stem);
    if (st == LMB_OK)
        st = lmb_write_hdr_image(cfg, dir, stem, a, cache->irradiance[a], cache->layout->width[a],
                                 cache->layout->height[a], err);
    return st;
}

void lmb_stages_out_done(const lmb_config *cfg, const char *stage, const lmb_log *log)
{
    lmb_info(log, "stages: %s written to %s/%s", stage, cfg->stages_out, stage);
}

lmb_status lmb_stages_out_stage(void *user, const char *stage, uint32_t atlas, lmb_cache *cache, const lmb_texels *t,
                                const float *light, const float *deferred, lmb_error *err)
{
    const lmb_stages_out *so = user;
    if (atlas == UINT32_MAX) { /* LMB_STAGE_WHOLE */
        lmb_stages_out_done(so->cfg, stage, so->log);
        return LMB_OK;
    }
    return lmb_stages_out_write(so->cfg, stage, cache, atlas, t, light, deferred, err);
}
