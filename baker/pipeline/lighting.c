/* The lighting passes over all atlases (see lighting.h). */
#include "lighting_internal.h"

#include "steps/runner.h"
#include "gather/gather.h"
#include "lights/direct_refine.h"
#include "lights/direct_step.h"
#include "irradiance_cache/ic_pass.h"
#include "post/denoise_steps.h"
#include "post/rim.h"
#include "util/clock.h"
#include "util/lmb_math.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void work_free(atlas_work *w, uint32_t n)
{
    for (uint32_t a = 0; w && a < n; a++) {
        lmb_texels_free(&w[a].t);
        free(w[a].direct);
        free(w[a].result);
        free(w[a].direct_dir);
        free(w[a].deferred);
        free(w[a].shadowmask);
        free(w[a].variance);
    }
    free(w);
}

lmb_status lmb_lighting_stage(const lmb_lighting_hooks *hooks, const char *stage, atlas_work *w, lmb_cache *cache,
                              size_t field, lmb_error *err)
{
    lmb_status st = LMB_OK;
    if (!hooks || !hooks->stage_light)
        return LMB_OK;
    for (uint32_t a = 0; a < cache->atlas_count && st == LMB_OK; a++)
        st = hooks->stage_light(hooks->stage_user, stage, a, cache, &w[a].t, *(float **)((char *)&w[a] + field),
                                w[a].deferred, err);
    if (st == LMB_OK)
        st = hooks->stage_light(hooks->stage_user, stage, LMB_STAGE_WHOLE, cache, NULL, NULL, NULL, err);
    return st;
}

/* The cache := every atlas's result (dilated). */
lmb_status lmb_lighting_store(atlas_work *w, lmb_cache *cache, lmb_error *err)
{
    lmb_status st = LMB_OK;
    for (uint32_t a = 0; a < cache->atlas_count && st == LMB_OK; a++)
        st = lmb_cache_store(cache, a, &w[a].t, w[a].result, err);
    return st;
}

/* The cache := indirect light only, the last pass stored (result; with no bounce pass before
 * the final gather, direct light alone) minus direct light, for gather.direct_at_hits. */
static lmb_status store_indirect(atlas_work *w, lmb_cache *cache, int passes_ran, lmb_error *err)
{
    lmb_status st = LMB_OK;
    for (uint32_t a = 0; a < cache->atlas_count && st == LMB_OK; a++) {
        size_t n = 3 * (size_t)w[a].t.count;
        float *ind = calloc(n + 1, sizeof *ind);
        if (!ind)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", a);
        for (size_t k = 0; passes_ran && k < n; k++)
            ind[k] = w[a].result[k] > w[a].direct[k] ? w[a].result[k] - w[a].direct[k] : 0.0f;
        st = lmb_cache_store(cache, a, &w[a].t, ind, err);
        free(ind);
    }
    return st;
}


/* The pass's gather through the irradiance cache, every atlas at once (records are shared
 * across atlases), with one report line per atlas. */
static lmb_status cached_gather(const pass_env *env, lmb_gather_stats *gs, lmb_error *err)
{
    uint32_t n = env->cache->atlas_count;
    const lmb_texels **t = calloc((size_t)n + 1, sizeof *t);
    float **out = calloc((size_t)n + 1, sizeof *out);
    uint64_t *records = calloc((size_t)n + 1, sizeof *records), *valid = calloc((size_t)n + 1, sizeof *valid),
             *own = calloc((size_t)n + 1, sizeof *own);
    double *noise = calloc((size_t)n + 1, sizeof *noise);
    lmb_status st = LMB_OK;
    if (!t || !out || !records || !valid || !own || !noise)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory");
    for (uint32_t a = 0; st == LMB_OK && a < n; a++) {
        t[a] = &env->w[a].t;
        out[a] = env->w[a].result;
    }
    lmb_ic_options opt = {env->cfg->ic_error, env->cfg->ic_min_spacing, env->cfg->ic_max_spacing,
                          env->cfg->ic_ray_scale};
    lmb_ic_pass_stats ps = {records, valid, own, env->points, noise};
    if (st == LMB_OK)
        st = lmb_ic_gather_pass(env->job, &opt, n, t, out, &ps, env->shared, env->own, gs, err);
    uint64_t all = 0;
    for (uint32_t a = 0; st == LMB_OK && a < n; a++) {
        all += records[a];
        env->w[a].gather_noise = noise[a];
        char own_note[128] = "";
        if (own[a])
            snprintf(own_note, sizeof own_note, ", %llu gathered on their own (curved at the texel's scale)",
                     (unsigned long long)own[a]);
        uint64_t interpolated = valid[a] - records[a] - own[a];
        lmb_info(env->log, "%s, atlas %u: %llu records%s, %.1f%% of %llu valid texels interpolated", env->job->stage, a,
                 (unsigned long long)records[a], own_note, valid[a] ? 100.0 * (double)interpolated / (double)valid[a] : 0.0,
                 (unsigned long long)valid[a]);
    }
    gs->records = all;
    free(t);
    free(out);
    free(records);
    free(valid);
    free(own);
    free(noise);
    return st;
}

/* Every atlas's `field` (3 floats per listed texel) through the edge-aware filter
 * (post/denoise_steps.h) at the relative noise `noise` (atlas by atlas when NULL: each atlas's
 * records' gather_noise) or, with own_variance, each texel's variance, with `levels` passes;
 * `what` names the light in the log line. */
static lmb_status denoise_light(const pass_env *env, size_t field, const double *noise, int own_variance,
                                uint32_t levels, const char *what, lmb_error *err)
{
    const lmb_config *cfg = env->cfg;
    uint32_t n = env->cache->atlas_count;
    lmb_denoise_stats ds = {0};
    double most = 0;
    lmb_denoise_part *atlases = calloc((size_t)n + 1, sizeof *atlases);
    if (!atlases)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "denoise: out of memory");
    for (uint32_t a = 0; a < n; a++) {
        atlas_work *w = &env->w[a];
        double level = noise ? *noise : LMB_DENOISE_TEXEL_SHARE * w->gather_noise;
        int filtered = level > 0 && (!own_variance || w->variance);
        atlases[a] = (lmb_denoise_part){&w->t, *(float **)(void *)((char *)w + field),
                                         filtered && own_variance ? w->variance : NULL, filtered ? level : 0};
        most = filtered && level > most ? level : most;
    }
    lmb_denoise_run run = {levels, cfg->denoise_strength, (int)cfg->threads, own_variance ? "all light" : "gathered light"};
    const char *stage = own_variance ? "denoise all light" : "denoise gathered light";
    if (env->job->progress)
        env->job->progress(env->job->progress_user, stage, 0, 1);
    lmb_status st = lmb_denoise_steps(env->job->steps, atlases, n, &run, &ds, err);
    if (env->job->progress && st == LMB_OK)
        env->job->progress(env->job->progress_user, stage, 1, 1);
    free(atlases);
    env->stats->denoised_texels += ds.texels;
    if (st == LMB_OK && ds.texels)
        lmb_info(env->log, "denoise: %s of %llu texels filtered at %.2f%% noise (%u levels, strength %g); its mean "
                 "moved %+.3f%%", what, (unsigned long long)ds.texels, 100 * most, levels, cfg->denoise_strength,
                 ds.before > 0 ? 100 * (ds.after / ds.before - 1) : 0.0);
    return st;
}

/* A pass over every atlas's listed texels as a step (steps/runner.h): items are the texels in
 * atlas order, or whole atlases when the gather is guided (pilots first, lmb_gather_texels). */
typedef struct texel_pass {
    const pass_env *env;
    uint32_t direction_rays;  /* > 0: light directions (lmb_gather_directions); 0: the gather */
    uint64_t *first;          /* per atlas (+1): its first item */
    int per_atlas;
} texel_pass;

static lmb_status texel_pass_range(void *user, uint64_t first, uint64_t last, lmb_buf *out,
                                   uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    const texel_pass *tp = user;
    lmb_gather_job *job = tp->env->job;
    lmb_status st = LMB_OK;
    for (uint32_t a = 0; a < tp->env->cache->atlas_count && st == LMB_OK; a++) {
        const lmb_texels *t = &tp->env->w[a].t;
        uint64_t a0 = tp->first[a], a1 = tp->first[a + 1];
        if (a1 <= first || a0 >= last || !t->count)
            continue;
        uint32_t i0 = tp->per_atlas ? 0 : (uint32_t)((first > a0 ? first : a0) - a0);
        uint32_t i1 = tp->per_atlas ? t->count : (uint32_t)((last < a1 ? last : a1) - a0);
        float *e = calloc(3 * (size_t)t->count + 1, sizeof *e);
        if (!e)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", a);
        lmb_gather_stats gs = {0};
        uint64_t before = 0;
        for (uint32_t b = 0; b < a; b++)
            before += tp->env->w[b].t.count;
        job->progress_done = before;
        if (tp->direction_rays)
            st = lmb_gather_directions(job, a, t, i0, i1, tp->direction_rays, e, &gs);
        else
            st = lmb_gather_texels(job, a, t, i0, i1, e, &gs, err);
        if (st == LMB_OK)
            st = lmb_buf_append(out, e + 3 * (size_t)i0, 3 * sizeof *e * (i1 - i0), err);
        counters[0] += gs.rays;
        counters[1] += gs.texels;
        counters[2] += gs.adapted;
        free(e);
    }
    return st;
}

/* Runs the pass as one step; its texels' 3 floats each go to take, in atlas order (a local
 * bake hands them over chunk by chunk, never holding the step's bytes whole). */
static lmb_status texel_step(const pass_env *env, const char *name, uint32_t direction_rays, lmb_step_take_fn take,
                             void *take_user, lmb_gather_stats *gs, lmb_error *err)
{
    uint32_t n = env->cache->atlas_count;
    texel_pass tp = {env, direction_rays, calloc((size_t)n + 2, sizeof(uint64_t)), 0};
    tp.per_atlas = !direction_rays && lmb_gather_is_guided(env->job);
    double *cost = tp.per_atlas ? calloc((size_t)n + 1, sizeof *cost) : NULL;
    if (!tp.first || (tp.per_atlas && !cost)) {
        free(tp.first);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory");
    }
    for (uint32_t a = 0; a < n; a++) {
        tp.first[a + 1] = tp.first[a] + (tp.per_atlas ? 1 : env->w[a].t.count);
        if (cost)
            cost[a] = env->w[a].t.count;
    }
    uint64_t texels = 0;
    for (uint32_t a = 0; a < n; a++)
        texels += env->w[a].t.count;
    double rays = (double)texels * (direction_rays ? direction_rays : env->job->estimator.rays);
    lmb_step_desc d = {name, tp.first[n], cost, rays, texel_pass_range, &tp};
    uint64_t counters[LMB_STEP_COUNTERS];
    lmb_status st = lmb_steps_run_streamed(env->job->steps, &d, tp.per_atlas ? 1 : LMB_STEP_STREAM_ITEMS, take,
                                           take_user, counters, err);
    if (st == LMB_OK) {
        gs->rays += counters[0];
        gs->texels += counters[1];
        gs->adapted += counters[2];
    }
    free(tp.first);
    free(cost);
    return st;
}

/* The gather at every texel as one step, into every atlas's result. */
static lmb_status gather_step(const pass_env *env, lmb_gather_stats *gs, lmb_error *err)
{
    uint32_t n = env->cache->atlas_count;
    uint64_t *floats = calloc((size_t)n + 1, sizeof *floats);
    float **dst = calloc((size_t)n + 1, sizeof *dst);
    lmb_status st = floats && dst ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory");
    for (uint32_t a = 0; a < n && st == LMB_OK; a++) {
        dst[a] = env->w[a].result;
        floats[a] = 3 * (uint64_t)env->w[a].t.count;
    }
    lmb_float_sink sink = {n, dst, floats, 0, 0};
    if (st == LMB_OK)
        st = texel_step(env, env->job->stage, 0, lmb_take_floats, &sink, gs, err);
    if (st == LMB_OK && !lmb_float_sink_full(&sink))
        st = lmb_error_set(err, LMB_ERR_INPUT, "%s: step holds too few texels", env->job->stage);
    free(floats);
    free(dst);
    return st;
}

/* Adaptive direct light (direct_refine.h): every atlas's direct light computed again where it is
 * noisier than samples.noise x the light shown, result (+ direct - deferred when with_direct
 * is 0: result holds the gathered light only) ; stats and the log get what the bake reached. */
static lmb_status refine_direct(const pass_env *env, int result_has_direct, lmb_error *err)
{
    lmb_direct_noise noise = {0};
    float *estimates = NULL;
    uint64_t estimate_count = 0;
    lmb_status st = LMB_OK;
    for (uint32_t a = 0; a < env->cache->atlas_count && st == LMB_OK; a++) {
        atlas_work *w = &env->w[a];
        double *shown = malloc(((size_t)w->t.count + 1) * sizeof *shown); /* its luminance: all that is read */
        if (!shown) {
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", a);
            break;
        }
        for (uint32_t i = 0; i < w->t.count; i++) {
            float rgb[3];
            for (int c = 0; c < 3; c++) {
                size_t k = 3 * (size_t)i + c;
                float v = result_has_direct ? w->result[k]
                                            : w->result[k] + w->direct[k] - (w->deferred ? w->deferred[k] : 0.0f);
                rgb[c] = v > 0 ? v : 0.0f;
            }
            shown[i] = lmb_luminance_f(rgb);
        }
        lmb_direct_atlas da = {w->t, w->direct, w->direct_dir, w->deferred, NULL, w->variance, w->direct_rays};
        st = lmb_direct_refine_step(env->job->steps, env->job->direct, env->cache->scene, env->cache->layout, a,
                                    shown, env->job->progress, env->job->progress_user, &da, &env->stats->rays, &noise,
                                    &estimates, &estimate_count, err);
        free(shown);
    }
    lmb_direct_noise_finish(&noise, estimates, estimate_count);
    if (st == LMB_OK)
        lmb_direct_noise_report(&noise, lmb_direct_opts(env->job->direct), env->stats, env->log);
    return st;
}

/* One gather pass over every atlas: result = gather(cache) (+ direct with add_direct), then
 * (store) the cache := result. The gather runs at every texel, or at irradiance-cache records
 * (irradiance_cache.error > 0). */
lmb_status lmb_lighting_gather(const pass_env *env, lmb_gather_stats *gs, int add_direct, int store, lmb_error *err)
{
    lmb_gather_job *job = env->job;
    atlas_work *w = env->w;
    lmb_cache *cache = env->cache;
    lmb_bake_stats *stats = env->stats;
    lmb_status st = LMB_OK;
    job->progress_done = 0;
    int through_cache = env->cfg->ic_error > 0 && !job->reference;
    if (through_cache)
        st = cached_gather(env, gs, err);
    else
        st = gather_step(env, gs, err);
    for (uint32_t a = 0; add_direct && through_cache && a < cache->atlas_count; a++)
        if (env->w[a].gather_noise > stats->indirect_noise)
            stats->indirect_noise = env->w[a].gather_noise;
    if (add_direct && env->shared) /* the final gather: no later pass reads the records */
        lmb_ic_records_free(env->shared);
    if (add_direct && store) /* nothing gathers until the store: the filter and refinement get its room */
        lmb_cache_release(cache);
    if (st == LMB_OK && add_direct && through_cache && env->cfg->denoise_indirect && !job->reference)
        st = denoise_light(env, offsetof(atlas_work, result), NULL, 0, env->cfg->denoise_levels,
                           "the final gather's light (a quarter of its records' median noise)", err);
    if (st == LMB_OK && add_direct && !job->reference) /* the final gather: the light shown is known */
        st = refine_direct(env, 0, err);
    /* the lightmap's direct light: every light's but the `indirect` ones' (mixed lighting);
     * nothing reads direct light after this */
    for (uint32_t a = 0; add_direct && a < cache->atlas_count && st == LMB_OK; a++) {
        for (size_t k = 0; k < 3 * (size_t)w[a].t.count; k++) {
            float v = w[a].result[k] + w[a].direct[k] - (w[a].deferred ? w[a].deferred[k] : 0.0f);
            w[a].result[k] = v > 0 ? v : 0.0f;
        }
        free(w[a].direct);
        w[a].direct = NULL;
    }
    if (st == LMB_OK && add_direct && !job->reference && env->cfg->denoise_direct && stats->direct_noise_median > 0)
        st = denoise_light(env, offsetof(atlas_work, result), &stats->direct_noise_median, 1, LMB_DENOISE_DIRECT_LEVELS,
                           "the light with its direct part (each texel's direct light's own variance)", err);
    for (uint32_t a = 0; add_direct && a < cache->atlas_count; a++) { /* read by the refinement and filter only */
        free(w[a].variance);
        w[a].variance = NULL;
    }
    if (st == LMB_OK && store)
        st = lmb_lighting_store(w, cache, err);
    stats->rays += gs->rays;
    return st;
}

/*
 * Directional lightmaps (output.directional; docs/artists.md): per texel the
 * mean direction the light arrives from, weighted by irradiance,
 *   D = (v_direct + v_indirect) / lum(E),   v = integral lum(L(w)) w cos dw,
 * v_direct from the lights stage (exact per light), v_indirect from samples.directional cosine
 * rays reading the finished cache (lmb_gather_directions). |D| <= 1: 1 when all light comes
 * from one direction, 2/3 under a uniform sky. Noise can push |D| past 1: it is clamped.
 * Here: texel i of atlas a, direct_dir := D from v_direct (direct_dir) and v_indirect (ind).
 */
static void finish_direction(const pass_env *env, uint32_t a, uint32_t i, const float ind[3])
{
    atlas_work *w = &env->w[a];
    const float *e = (env->stats->bounces ? w->result : w->direct) + 3 * (size_t)i;
    float *d = w->direct_dir + 3 * (size_t)i;
    double lum = 0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2], v[3], len = 0;
    for (int k = 0; k < 3; k++) {
        v[k] = (double)ind[k] + (double)d[k];
        v[k] = lum > 0 ? v[k] / lum : 0;
        len += v[k] * v[k];
    }
    len = sqrt(len);
    for (int k = 0; k < 3; k++)
        d[k] = (float)(len > 1 ? v[k] / len : v[k]);
}

/* The directions step's texels as they come (lmb_steps_run_streamed), each finished at once:
 * no array of the indirect parts is kept. */
typedef struct directions_taken {
    const pass_env *env;
    uint32_t atlas, texel; /* the next texel */
} directions_taken;

/* Moves past atlases whose texels are all finished; 0 when none is left. */
static int directions_next(directions_taken *k)
{
    while (k->atlas < k->env->cache->atlas_count && k->texel == k->env->w[k->atlas].t.count) {
        k->atlas++;
        k->texel = 0;
    }
    return k->atlas < k->env->cache->atlas_count;
}

static lmb_status directions_take(void *user, lmb_buf *bytes, lmb_error *err)
{
    directions_taken *k = user;
    if ((bytes->size - bytes->read) % (3 * sizeof(float)))
        return lmb_error_set(err, LMB_ERR_INPUT, "directions: %zu bytes are not whole texels", bytes->size - bytes->read);
    while (bytes->read < bytes->size) {
        if (!directions_next(k))
            return lmb_error_set(err, LMB_ERR_INPUT, "directions: the step holds more texels than the atlases");
        float ind[3];
        lmb_buf_take(bytes, ind, sizeof ind);
        finish_direction(k->env, k->atlas, k->texel++, ind);
    }
    return LMB_OK;
}

static lmb_status light_directions(const pass_env *env, lmb_error *err)
{
    const lmb_config *cfg = env->cfg;
    lmb_gather_job *job = env->job;
    atlas_work *w = env->w;
    lmb_cache *cache = env->cache;
    lmb_bake_stats *stats = env->stats;
    lmb_status st = LMB_OK;
    job->pass = 2000;
    job->direct_at_hits = 0; /* the cache holds all the light now */
    job->stage = "directions";
    lmb_gather_stats gs = {0};
    directions_taken taken = {env, 0, 0};
    if (!stats->no_light && stats->bounces > 0) { /* bounces: 0 has no indirect light to point to */
        st = texel_step(env, "directions", cfg->directional_rays, directions_take, &taken, &gs, err);
        if (st == LMB_OK && directions_next(&taken))
            st = lmb_error_set(err, LMB_ERR_INPUT, "directions: step holds too few texels");
    } else {
        const float none[3] = {0, 0, 0};
        for (uint32_t a = 0; a < cache->atlas_count; a++)
            for (uint32_t i = 0; i < w[a].t.count; i++)
                finish_direction(env, a, i, none);
    }
    stats->rays += gs.rays;
    for (uint32_t a = 0; a < cache->atlas_count && st == LMB_OK; a++)
        st = lmb_cache_store_direction(cache, a, &w[a].t, w[a].direct_dir, err);
    return st;
}

lmb_status lmb_light_atlases(const lmb_config *cfg, const lmb_direct *direct, lmb_cache *cache, lmb_steps *steps,
                             const lmb_lighting_hooks *hooks, lmb_bake_stats *stats, lmb_ic_points *records,
                             const lmb_log *log, lmb_error *err)
{
    lmb_progress_fn progress = hooks ? hooks->progress : NULL;
    void *user = hooks ? hooks->progress_user : NULL;
    uint32_t n = cache->atlas_count;
    atlas_work *w = calloc((size_t)n + 1, sizeof *w);
    if (!w)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory");
    lmb_status st = LMB_OK;
    uint64_t total = 0, beside = 0;
    lmb_rim_stats rim = {0, 0, 0};
    /* gather points and direct light, atlas by atlas */
    for (uint32_t a = 0; a < n && st == LMB_OK; a++) {
        lmb_direct_atlas da;
        st = lmb_direct_atlas_step(steps, direct, cache->scene, cache->layout, a, progress, user, &da, &stats->rays,
                                   err);
        w[a].t = da.t;
        w[a].direct = da.direct;
        w[a].direct_dir = da.direction;
        w[a].deferred = da.deferred;
        w[a].shadowmask = da.shadowmask;
        w[a].variance = da.variance;
        w[a].direct_rays = da.rays;
        if (st == LMB_OK)
            st = lmb_rim_limit(&w[a].t, w[a].direct, &rim, err);
        if (st != LMB_OK)
            break;
        w[a].result = calloc(3 * (size_t)w[a].t.count + 1, sizeof *w[a].result);
        if (!w[a].result) {
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "lighting: out of memory for atlas %u", a);
            break;
        }
        for (uint32_t i = 0; i < w[a].t.count; i++) {
            stats->texels++;
            stats->valid_texels += w[a].t.valid[i];
            beside += w[a].t.valid[i] && (w[a].t.edge[i] & LMB_EDGE_NEAR);
        }
        total += w[a].t.count;
    }
    if (st == LMB_OK)
        st = lmb_lighting_stage(hooks, "direct", w, cache, offsetof(atlas_work, direct), err);
    for (uint32_t a = 0; a < n && st == LMB_OK; a++)
        st = lmb_cache_store(cache, a, &w[a].t, w[a].direct, err);
    stats->rim_limited = rim.limited;
    stats->rim_energy = rim.total > 0 ? rim.removed / rim.total : 0;
    if (stats->texels > stats->valid_texels || beside)
        lmb_info(log, "texels: %llu inside geometry (every gather point in a solid: filled from valid neighbours, never "
                 "lit); %llu beside geometry (lit from their own side, read only from it: docs/leaks.md)",
                 (unsigned long long)(stats->texels - stats->valid_texels), (unsigned long long)beside);
    if (rim.limited)
        lmb_info(log, "rims: %llu partly covered texels limited to their neighbours (%.3f%% of the direct light)",
                 (unsigned long long)rim.limited, 100.0 * stats->rim_energy);
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
    job.steps = steps;
    lmb_ic_records shared;
    lmb_ic_records_init(&shared, cfg->ic_error > 0 ? cfg->ic_error : 1);
    lmb_ic_own_texels own = {0};
    pass_env env = {cfg, log, hooks, &job, w, cache, stats, NULL, cfg->ic_records == LMB_IC_RECORDS_SHARED ? &shared : NULL,
                    &own};
    /* nothing emits: every texel is exactly 0 whatever the gather would do, so it does not run */
    int dark = !lmb_direct_any_light(direct);
    stats->no_light = dark;
    /* bounce passes: classic gathering with few rays, a fixed number or until converged */
    uint32_t passes = 0;
    if (st == LMB_OK && !dark && !cfg->reference && (cfg->bounces == LMB_AUTO || cfg->bounces > 1))
        st = lmb_lighting_bounces(&env, &passes, err);
    uint32_t bounces = dark ? 0 : cfg->bounces == LMB_AUTO ? (cfg->reference ? cfg->bounces_max : passes + 1) : cfg->bounces;
    stats->bounces = bounces;
    /* the final gather, or the reference */
    if (bounces > 0 && st == LMB_OK) {
        lmb_gather_stats gs = {0};
        lmb_estimator_options e = {.method = cfg->gather_method,
                                   .rays = cfg->gather_rays,
                                   .iterations = cfg->amis_iterations,
                                   .defensive = cfg->defensive_fraction,
                                   .unbiased = cfg->amis_weights == LMB_AMIS_UNBIASED};
        job.estimator = e;
        job.direct_at_hits = cfg->direct_at_hits && !cfg->reference;
        if (job.direct_at_hits) /* the cache := the last pass minus direct light */
            st = store_indirect(w, cache, bounces > 1, err);
        job.guide_stride = cfg->guide_stride;
        job.guide_lobes = cfg->guide_lobes;
        job.pass = 1000;
        job.reference = cfg->reference;
        job.depth = bounces;
        job.stage = cfg->reference ? "reference" : "final gather";
        if (cfg->adaptive) { /* records gather more where their noise asks (gather.c, more_rays) */
            job.noise_target = cfg->noise_target;
            /* at most twice a record's base rays (and samples.max_rays): the gather at most doubles */
            uint64_t base = (uint64_t)cfg->gather_rays * cfg->ic_ray_scale, most = 2 * base;
            most = most < cfg->max_rays ? most : (cfg->max_rays > base ? cfg->max_rays : base);
            job.max_rays = (uint32_t)(most < UINT32_MAX ? most : UINT32_MAX);
        }
        double t0 = lmb_seconds();
        env.points = records;
        if (st == LMB_OK)
            st = lmb_lighting_gather(&env, &gs, 1, 1, err);
        env.points = NULL;
        stats->gather_records = gs.records;
        stats->gather_seconds = lmb_seconds() - t0;
        stats->gather_rays = gs.rays;
        stats->amis_adapted = gs.adapted;
        stats->records_extended = gs.extended;
        stats->records_capped = gs.capped;
        if (gs.extended)
            lmb_info(log, "final gather: %llu of %llu records (%.1f%%) gathered more rays for samples.noise %g%%, %llu of "
                     "them stopped at samples.max_rays %u",
                     (unsigned long long)gs.extended, (unsigned long long)gs.records,
                     gs.records ? 100.0 * (double)gs.extended / (double)gs.records : 0.0, 100.0 * cfg->noise_target,
                     (unsigned long long)gs.capped, job.max_rays);
    }
    /* no gather ran: the lightmap is the direct light without the `indirect` lights' */
    for (uint32_t a = 0; a < n && st == LMB_OK && bounces == 0; a++)
        memset(w[a].result, 0, 3 * sizeof *w[a].result * (size_t)w[a].t.count);
    if (st == LMB_OK && bounces == 0 && !dark)
        st = refine_direct(&env, 0, err);
    for (uint32_t a = 0; a < n && st == LMB_OK && bounces == 0 && (w[a].deferred || !dark); a++) {
        for (size_t k = 0; k < 3 * (size_t)w[a].t.count; k++) {
            float v = w[a].direct[k] - (w[a].deferred ? w[a].deferred[k] : 0.0f);
            w[a].direct[k] = v > 0 ? v : 0.0f;
        }
        st = lmb_cache_store(cache, a, &w[a].t, w[a].direct, err);
    }
    for (uint32_t a = 0; a < n && st == LMB_OK && w[a].shadowmask; a++)
        st = lmb_cache_store_shadowmask(cache, a, &w[a].t, w[a].shadowmask, err);
    if (st == LMB_OK && cfg->directional && progress)
        progress(user, "directions", 0, 1);
    if (st == LMB_OK && cfg->directional)
        st = light_directions(&env, err);
    if (st == LMB_OK && cfg->directional && progress)
        progress(user, "directions", 1, 1);
    lmb_ic_records_free(&shared);
    lmb_ic_own_texels_free(&own);
    work_free(w, n);
    return st;
}
