/*
 * What the lighting passes share (lighting.c drives them; lighting_bounces.c runs the bounce
 * passes before the final gather): each atlas's per-texel arrays and the passes' environment.
 */
#ifndef LMBAKE_LIGHTING_INTERNAL_H
#define LMBAKE_LIGHTING_INTERNAL_H

#include "lighting.h"
#include "gather/gather.h"
#include "irradiance_cache/ic_pass.h"

typedef struct atlas_work {
    lmb_texels t;
    float *direct;   /* 3 per listed texel */
    float *result;   /* 3 per listed texel: the pass being computed */
    float *direct_dir; /* output.directional: 3 per listed texel, direct light's direction sum, then
                          (light_directions) the light's mean direction */
    float *deferred; /* mixed lighting: 3 per listed texel, the `indirect` lights' part of direct; else NULL */
    float *shadowmask; /* output.shadowmask: 4 per listed texel; else NULL */
    float *variance; /* per listed texel: variance of a round of its sampled direct light (direct_refine.h) */
    uint64_t direct_rays; /* what the direct step traced for this atlas */
    double gather_noise;  /* the last cached gather's records: median relative standard error (ic_pass.h) */
} atlas_work;

/* What the passes share. */
typedef struct pass_env {
    const lmb_config *cfg;
    const lmb_log *log;
    const lmb_lighting_hooks *hooks;
    lmb_gather_job *job;
    atlas_work *w;
    lmb_cache *cache;
    lmb_bake_stats *stats;
    lmb_ic_points *points; /* set during the final gather only: where its records go */
    lmb_ic_records *shared; /* irradiance_cache.records: shared: the records passed on; else NULL */
    lmb_ic_own_texels *own; /* the texels every cached pass gathers on their own, marked by the first */
} pass_env;

/* The cache := every atlas's result (dilated). */
lmb_status lmb_lighting_store(atlas_work *w, lmb_cache *cache, lmb_error *err);

/* Hands stage `stage`'s light (field: offsetof(atlas_work, direct or result)) to the driver's
 * stage hook, every atlas then LMB_STAGE_WHOLE; LMB_OK when there is no hook. */
lmb_status lmb_lighting_stage(const lmb_lighting_hooks *hooks, const char *stage, atlas_work *w, lmb_cache *cache,
                              size_t field, lmb_error *err);

/* One gather pass over every atlas: result = gather(cache) (+ direct with add_direct: the
 * final gather, then filtered and refined), then (store) the cache := result. */
lmb_status lmb_lighting_gather(const pass_env *env, lmb_gather_stats *gs, int add_direct, int store, lmb_error *err);

/* The bounce passes before the final gather (lighting_bounces.c); *passes: how many ran. */
lmb_status lmb_lighting_bounces(const pass_env *env, uint32_t *passes, lmb_error *err);

#endif
