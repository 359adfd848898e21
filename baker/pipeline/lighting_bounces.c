/* The bounce passes before the final gather (lighting_internal.h). */
#include "lighting_internal.h"

#include "util/lmb_math.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Rays per texel of bounce pass b: higher orders carry less light and reach the texel through
 * more gathers (their noise averages out), so they may use fewer (samples.bounce_high). */
static uint32_t pass_rays(const lmb_config *cfg, uint32_t b)
{
    return b >= 3 && cfg->bounce_rays_high ? cfg->bounce_rays_high : cfg->bounce_rays;
}

/* Mean of each channel over the valid texels of every atlas (field: direct or result). */
static void mean_rgb(const atlas_work *w, uint32_t n, size_t field, double out[3])
{
    double sum[3] = {0, 0, 0};
    uint64_t count = 0;
    for (uint32_t a = 0; a < n; a++) {
        const float *e = *(float *const *)(const void *)((const char *)&w[a] + field);
        for (uint32_t i = 0; i < w[a].t.count; i++)
            if (w[a].t.valid[i]) {
                count++;
                for (int c = 0; c < 3; c++)
                    sum[c] += e[3 * (size_t)i + c];
            }
    }
    for (int c = 0; c < 3; c++)
        out[c] = count ? sum[c] / (double)count : 0;
}

/* The tail's uncertainty a stop may leave (bounces_auto's third rule), as a share of the
 * light: a tenth of the tail bounces_auto.tail lets the passes leave out (0.5% at its default),
 * so a bake that asks for a smaller tail gets a tighter bound too. */
#define TAIL_BOUND_SHARE 0.1

/* How far apart the geometric tails D r / (1 - r) of the ratios the last two passes allow can
 * be: r anywhere between the two ratios, widened by the settling test's tolerance (0.02 + 5%).
 * Where the later passes' ratios scatter (16 rays per texel gathering a few % of the light: an
 * open level's 0.19 0.45 0.28 0.43 0.34) they never settle, yet once what a pass adds is small
 * enough every ratio between them gives the same total within that bound; the passes after that
 * would only pin down a number that no longer matters. */
static double tail_range(double added, double r1, double r2)
{
    double lo = r1 < r2 ? r1 : r2, hi = r1 < r2 ? r2 : r1, tol = 0.02 + 0.05 * hi;
    lo = lo - tol < 0 ? 0 : lo - tol;
    hi = hi + tol > 0.98 ? 0.98 : hi + tol;
    return added * (hi / (1 - hi) - lo / (1 - lo));
}

/*
 * The bounce passes before the final gather (docs/lighting.md "Bounces"). Each pass gathers
 * the light the previous pass added, not all the light so far:
 *   D_0 = E_direct,  D_b = K D_{b-1},  E_b = D_0 + D_1 + ... + D_b,
 * with K one cosine gather (per texel or through the irradiance cache). The sum is the same
 * Neumann series as gathering E_{b-1} again (E_b = E_direct + K E_{b-1}), but each pass's noise
 * is now proportional to what that pass adds: gathering E_{b-1} again re-gathers the direct
 * light's hot spots in every pass, and their noise (a few % of the light with a point light
 * near a ceiling) swamped the later passes' small increments and the ratio that bounces: auto
 * reads from them.
 *
 * bounces: k runs k - 1 passes. bounces: auto runs passes until what they add settles into
 * a geometric series: the ratio r = D_b / D_{b-1} (per channel: the mean albedo seen, weighted
 * by where light goes) agrees with the previous pass's, and the tail the passes leave out,
 * T = D_b r / (1 - r) beyond E_b, is below bounces_auto.tail of the total; or the tail is known
 * to within a tenth of bounces_auto.tail of the light whatever ratio the last two passes allow (tail_range); or a
 * pass adds under 0.1% of the light; or bounces_auto.max. The tail is then added texel by texel,
 * T_x = D_b,x r / (1 - r), so the final gather reads converged light: a closed room of albedo
 * rho gets pi Le / (1 - rho), not the series cut after b + 1 terms. (At rho = 0.8 a 1% tail
 * takes ~20 passes; the ratio settles after 3-4 and the extrapolation is exact for a furnace.)
 * On return w[].result holds E_b (+ tail) and so does the cache.
 */
lmb_status lmb_lighting_bounces(const pass_env *env, uint32_t *passes, lmb_error *err)
{
    const lmb_config *cfg = env->cfg;
    lmb_gather_job *job = env->job;
    atlas_work *w = env->w;
    lmb_cache *cache = env->cache;
    lmb_bake_stats *stats = env->stats;
    uint32_t n = cache->atlas_count;
    int automatic = cfg->bounces == LMB_AUTO;
    uint32_t max_passes = automatic ? cfg->bounces_max - 1 : cfg->bounces - 1;
    double direct[3], total[3], added[3], last[3] = {0, 0, 0}, ratio[3] = {0, 0, 0}, prev_ratio = -1;
    float **sum = calloc((size_t)n + 1, sizeof *sum);
    lmb_status st = sum ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory");
    for (uint32_t a = 0; a < n && st == LMB_OK; a++) {
        sum[a] = malloc((3 * (size_t)w[a].t.count + 1) * sizeof **sum);
        if (!sum[a])
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", a);
        else
            memcpy(sum[a], w[a].direct, 3 * (size_t)w[a].t.count * sizeof **sum);
    }
    mean_rgb(w, n, offsetof(atlas_work, direct), direct);
    memcpy(total, direct, sizeof total);
    stats->bounce_energy[0] = lmb_luminance(direct);
    char stage[64];
    uint32_t done = 0;
    double tail_factor[3] = {0, 0, 0};
    for (uint32_t b = 1; b <= max_passes && st == LMB_OK; b++) {
        lmb_gather_stats gs = {0};
        lmb_estimator_options e = {.method = LMB_GATHER_COSINE, .rays = pass_rays(cfg, b), .iterations = 1};
        job->estimator = e;
        job->pass = b;
        job->unmapped_dark = b >= 2; /* surfaces without a lightmap: their direct light, in the first pass only */
        if (automatic)
            snprintf(stage, sizeof stage, "bounce pass %u (auto)", b);
        else
            snprintf(stage, sizeof stage, "bounce %u/%u", b, cfg->bounces);
        job->stage = stage;
        st = lmb_lighting_gather(env, &gs, 0, 0, err); /* result := D_b, gathered from D_{b-1} in the cache */
        if (st != LMB_OK)
            break;
        done = b;
        mean_rgb(w, n, offsetof(atlas_work, result), added);
        for (uint32_t a = 0; a < n; a++)
            for (size_t k = 0; k < 3 * (size_t)w[a].t.count; k++)
                sum[a][k] += w[a].result[k];
        for (int c = 0; c < 3; c++) {
            total[c] += added[c];
            ratio[c] = last[c] > 0 ? added[c] / last[c] : 0;
            ratio[c] = ratio[c] < 0 ? 0 : ratio[c] > 0.98 ? 0.98 : ratio[c];
            last[c] = added[c];
        }
        if (b < LMB_MAX_REPORTED_BOUNCES)
            stats->bounce_energy[b] = lmb_luminance(added);
        int last_pass = b == max_passes;
        if (automatic) {
            double r = lmb_luminance(ratio), tail[3];
            for (int c = 0; c < 3; c++)
                tail[c] = added[c] * ratio[c] / (1 - ratio[c]);
            double all = lmb_luminance(total) + lmb_luminance(tail);
            double tail_share = all > 0 ? lmb_luminance(tail) / all : 0;
            int settled = b >= 2 && prev_ratio >= 0 && fabs(r - prev_ratio) <= 0.02 + 0.05 * r;
            /* a pass that adds under 0.1% of the light leaves a tail below the passes' noise */
            int small = lmb_luminance(added) <= 1e-3 * lmb_luminance(total);
            int bounded = b >= 2 && prev_ratio >= 0 && tail_range(lmb_luminance(added), prev_ratio, r) <= TAIL_BOUND_SHARE * cfg->bounces_tail * all;
            int converged = small || (settled && tail_share < cfg->bounces_tail) || bounded;
            stats->bounce_stop = small                                           ? LMB_BOUNCES_SMALL_PASS
                                 : settled && tail_share < cfg->bounces_tail ? LMB_BOUNCES_TAIL
                                 : bounded                                   ? LMB_BOUNCES_TAIL_BOUNDED
                                                                             : LMB_BOUNCES_MAX;
            stats->tail_share = b >= 2 ? tail_share : 0;
            stats->bounce_ratio = b >= 2 ? r : 0;
            prev_ratio = b >= 2 ? r : -1;
            last_pass |= converged;
            if (last_pass && b >= 2 && lmb_luminance(added) > 0)
                for (int c = 0; c < 3; c++)
                    tail_factor[c] = ratio[c] / (1 - ratio[c]);
            else if (last_pass)
                stats->tail_share = 0; /* nothing left to extrapolate */
            stats->tail_added = tail_factor[0] > 0 || tail_factor[1] > 0 || tail_factor[2] > 0;
        }
        if (last_pass)
            break;
        st = lmb_lighting_store(w, cache, err); /* the cache := D_b, what the next pass gathers */
    }
    job->unmapped_dark = 0; /* the gathers after the passes read all the light */
    /* result := E_b + the tail D_b r / (1 - r); the cache := result */
    for (uint32_t a = 0; a < n && st == LMB_OK; a++)
        for (size_t k = 0; k < 3 * (size_t)w[a].t.count; k++) {
            double v = sum[a][k] + (done ? w[a].result[k] * tail_factor[k % 3] : 0);
            w[a].result[k] = (float)(v > 0 ? v : 0);
        }
    /* the driver's stage hook: all the light the passes reached, before the final gather reads it */
    if (st == LMB_OK && done)
        st = lmb_lighting_stage(env->hooks, "bounces", w, cache, offsetof(atlas_work, result), err);
    if (st == LMB_OK)
        st = lmb_lighting_store(w, cache, err);
    for (uint32_t a = 0; sum && a < n; a++)
        free(sum[a]);
    free(sum);
    *passes = done;
    return st;
}

