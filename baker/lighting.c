/* The lighting passes over all atlases (see lighting.h). */
#include "lighting.h"

#include "gather/gather.h"
#include "util/clock.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct atlas_work {
    lmb_texels t;
    float *direct;   /* 3 per listed texel */
    float *result;   /* 3 per listed texel: the pass being computed */
} atlas_work;

static void work_free(atlas_work *w, uint32_t n)
{
    for (uint32_t a = 0; w && a < n; a++) {
        lmb_texels_free(&w[a].t);
        free(w[a].direct);
        free(w[a].result);
    }
    free(w);
}

/* One gather pass over every atlas: result = direct + gather(cache), then the cache := result. */
static lmb_status gather_pass(lmb_gather_job *job, atlas_work *w, lmb_cache *cache, lmb_bake_stats *stats,
                              lmb_gather_stats *gs, lmb_error *err)
{
    lmb_status st = LMB_OK;
    job->progress_done = 0;
    for (uint32_t a = 0; a < cache->atlas_count && st == LMB_OK; a++) {
        st = lmb_gather_atlas(job, a, &w[a].t, w[a].result, gs, err);
        for (size_t k = 0; st == LMB_OK && k < 3 * (size_t)w[a].t.count; k++)
            w[a].result[k] += w[a].direct[k];
        job->progress_done += w[a].t.count;
    }
    for (uint32_t a = 0; a < cache->atlas_count && st == LMB_OK; a++)
        st = lmb_cache_store(cache, a, &w[a].t, w[a].result, err);
    stats->rays += gs->rays;
    return st;
}

lmb_status lmb_light_atlases(const lmb_config *cfg, const lmb_direct *direct, lmb_cache *cache,
                             lmb_progress_fn progress, void *user, lmb_bake_stats *stats, lmb_error *err)
{
    uint32_t n = cache->atlas_count;
    atlas_work *w = calloc((size_t)n + 1, sizeof *w);
    if (!w)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory");
    lmb_status st = LMB_OK;
    uint64_t total = 0;
    /* gather points and direct light, atlas by atlas */
    for (uint32_t a = 0; a < n && st == LMB_OK; a++) {
        st = lmb_texels_build(cache->scene, cache->layout, a, cfg->texel_samples, &w[a].t, err);
        if (st != LMB_OK)
            break;
        w[a].direct = calloc(3 * (size_t)w[a].t.count + 1, sizeof *w[a].direct);
        w[a].result = calloc(3 * (size_t)w[a].t.count + 1, sizeof *w[a].result);
        if (!w[a].direct || !w[a].result) {
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", a);
            break;
        }
        lmb_direct_job job = {direct, a, progress, user};
        st = lmb_direct_compute(&job, &w[a].t, w[a].direct, &stats->rays, err);
        for (uint32_t i = 0; i < w[a].t.count; i++) {
            stats->texels++;
            stats->valid_texels += w[a].t.valid[i];
        }
        total += w[a].t.count;
        if (st == LMB_OK)
            st = lmb_cache_store(cache, a, &w[a].t, w[a].direct, err);
    }
    lmb_gather_job job;
    memset(&job, 0, sizeof job);
    job.direct = direct;
    job.cache = cache;
    job.rt = cache->rt;
    job.seed = cfg->seed;
    job.threads = cfg->threads;
    job.progress = progress;
    job.progress_user = user;
    job.progress_total = total;
    /* bounce passes: classic gathering with few rays */
    char stage[64];
    for (uint32_t b = 1; b < cfg->bounces && !cfg->reference && st == LMB_OK; b++) {
        lmb_gather_stats gs = {0, 0, 0};
        lmb_estimator_options e = {LMB_GATHER_COSINE, cfg->bounce_rays, 1, 0, 0};
        job.estimator = e;
        job.pass = b;
        snprintf(stage, sizeof stage, "bounce %u/%u", b, cfg->bounces);
        job.stage = stage;
        st = gather_pass(&job, w, cache, stats, &gs, err);
    }
    /* the final gather, or the reference */
    if (cfg->bounces > 0 && st == LMB_OK) {
        lmb_gather_stats gs = {0, 0, 0};
        lmb_estimator_options e = {cfg->gather_method, cfg->gather_rays, cfg->amis_iterations, cfg->defensive_fraction,
                                   cfg->amis_weights == LMB_AMIS_UNBIASED};
        job.estimator = e;
        job.pass = 1000;
        job.reference = cfg->reference;
        job.depth = cfg->bounces;
        job.stage = cfg->reference ? "reference" : "final gather";
        double t0 = lmb_seconds();
        st = gather_pass(&job, w, cache, stats, &gs, err);
        stats->gather_seconds = lmb_seconds() - t0;
        stats->gather_rays = gs.rays;
        stats->amis_adapted = gs.adapted;
    }
    work_free(w, n);
    return st;
}
