/*
 * Direct light texel by texel (see direct.h, lmb_direct_compute): each of a texel's points is
 * tested for lying inside geometry, the others get direct light (lmb_direct_at), and the
 * texel keeps their mean, the point indirect light is gathered at, whether geometry covers it
 * in part (post/rim.c) and, for directional lightmaps, the light's direction sum; with mixed
 * lighting also the `indirect` lights' part and the shadowmask lights' visibility.
 */
#include "direct.h"

#include <omp.h>

#include <stdlib.h>

static void texel_direct(const lmb_direct_job *job, lmb_texels *t, uint32_t i, float *out, uint64_t *rays)
{
    double sum[3] = {0, 0, 0}, dir_sum[3] = {0, 0, 0}, deferred_sum[3] = {0, 0, 0}, mask_sum[LMB_SHADOWMASK_CHANNELS] = {0};
    uint32_t used = 0, r = 0;
    int near_back = 0;
    uint64_t key = ((uint64_t)job->atlas << 32) | t->texel[i];
    t->gather_at[i] = 0;
    for (uint32_t k = 0; k < t->points_in[i]; k++) {
        lmb_shading_point sp;
        lmb_texel_shading_point(job->direct, t, i, k, &sp);
        lmb_rng rng = lmb_rng_make(lmb_direct_config(job->direct)->seed, key, k);
        int sees_back;
        if (lmb_point_inside_geometry(job->direct, &sp, &rng, &r, &sees_back))
            continue;
        near_back |= sees_back;
        if (!used)
            t->gather_at[i] = (uint8_t)k;
        double e[3], dir[3], deferred[3];
        r += lmb_direct_at_split(job->direct, &sp, 0, &rng, e, dir, deferred);
        for (int d = 0; d < 3; d++) {
            sum[d] += e[d];
            dir_sum[d] += dir[d];
            deferred_sum[d] += deferred[d];
        }
        if (job->shadowmask) { /* a stream of its own: the lightmap does not change with output.shadowmask */
            lmb_rng mask_rng = lmb_rng_make(lmb_direct_config(job->direct)->seed, key, 0x5000u + k);
            double vis[LMB_SHADOWMASK_CHANNELS];
            r += lmb_shadowmask_at(job->direct, &sp, &mask_rng, vis);
            for (int c = 0; c < LMB_SHADOWMASK_CHANNELS; c++)
                mask_sum[c] += vis[c];
        }
        used++;
    }
    t->valid[i] = used > 0;
    t->partly_covered[i] = used > 0 && (used < t->points_in[i] || near_back);
    for (int d = 0; d < 3; d++) {
        out[3 * i + d] = used ? (float)(sum[d] / used) : 0.0f;
        if (job->direction)
            job->direction[3 * (size_t)i + d] = used ? (float)(dir_sum[d] / used) : 0.0f;
        if (job->deferred)
            job->deferred[3 * (size_t)i + d] = used ? (float)(deferred_sum[d] / used) : 0.0f;
    }
    for (int c = 0; job->shadowmask && c < LMB_SHADOWMASK_CHANNELS; c++)
        job->shadowmask[LMB_SHADOWMASK_CHANNELS * (size_t)i + c] = used ? (float)(mask_sum[c] / used) : 0.0f;
    *rays += r;
}

lmb_status lmb_direct_compute(const lmb_direct_job *job, lmb_texels *t, float *irradiance, uint64_t *rays, lmb_error *err)
{
    const uint32_t block = 1024;
    uint64_t total = 0;
    int threads = lmb_direct_config(job->direct)->threads ? (int)lmb_direct_config(job->direct)->threads : omp_get_max_threads();
    for (uint32_t start = 0; start < t->count; start += block) {
        uint32_t end = start + block < t->count ? start + block : t->count;
        uint64_t block_rays = 0;
#pragma omp parallel num_threads(threads) reduction(+ : block_rays)
        {
            lmb_rt_thread_init();
#pragma omp for schedule(dynamic, 16)
            for (uint32_t i = start; i < end; i++)
                texel_direct(job, t, i, irradiance, &block_rays);
        }
        total += block_rays;
        if (job->progress)
            job->progress(job->progress_user, "direct", end, t->count);
    }
    *rays += total;
    (void)err;
    return LMB_OK;
}
