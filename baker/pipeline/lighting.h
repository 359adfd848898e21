/*
 * The lighting half of the pipeline, over every atlas of a layout (DESIGN.md section 2,
 * steps 4-7): gather points per texel -> direct light -> bounce passes -> final gather (or
 * the path-traced reference). Bounces need every atlas's direct light before any gather,
 * so all atlases' texels stay in memory through the passes.
 *   bounces = 0: E = E_direct.
 *   bounces = k: the cache starts as E_direct; k - 1 cheap passes (classic gathering,
 *                samples.bounce rays) each set the cache to E_direct + gather(previous cache);
 *                the final gather (gather.method, samples.gather rays) gives
 *                E = E_direct + gather(cache): k bounces of indirect light in all.
 *   irradiance_cache.error > 0: every pass gathers at records only and interpolates the
 *                rest (irradiance_cache/ic_pass.h), each pass with its own records.
 *   --reference: E = E_direct + path-traced indirect light of depth k, no cache.
 * The result is left in the cache (its images, dilated), which the writer saves; `records`
 * (may be NULL) receives the final gather's irradiance-cache records (none without the cache).
 * Every expensive loop runs as a step of `steps` (steps/runner.h): in this process, or as a
 * farm shard (which stops the bake with LMB_STEP_STOPPED once its part is written), or read
 * from the farm's merged states.
 */
#ifndef LMBAKE_LIGHTING_H
#define LMBAKE_LIGHTING_H

#include <lmbake/lmbake.h>

#include "cache/bounce_cache.h"
#include "steps/runner.h"
#include "irradiance_cache/ic_pass.h"
#include "lights/direct.h"
#include "texels/texels.h"

/* A lighting stage's light, handed out as soon as it is whole (what `bake --stages-out` writes for
 * the watch: watch/stages_out.h). Called per atlas with the stage ("direct": the direct stage's
 * light; "bounces": all the light the bounce passes reached, before the final gather reads it),
 * the atlas's texels, its light (3 floats per texel) and `deferred` (mixed lighting: the part of
 * it the engine adds itself; else NULL), and the cache, whose image of atlas `atlas` it may use as
 * scratch (the passes store the cache's next contents after); then once with atlas =
 * LMB_STAGE_WHOLE (t, light, deferred NULL) when every atlas was given. Not LMB_OK stops the bake. */
#define LMB_STAGE_WHOLE UINT32_MAX
typedef lmb_status (*lmb_stage_light_fn)(void *user, const char *stage, uint32_t atlas, lmb_cache *cache,
                                         const lmb_texels *t, const float *light, const float *deferred,
                                         lmb_error *err);

/* What the driver watches of the lighting: progress (may cancel) and the stages' light (NULL: not). */
typedef struct lmb_lighting_hooks {
    lmb_progress_fn progress;
    void *progress_user;
    lmb_stage_light_fn stage_light;
    void *stage_user;
} lmb_lighting_hooks;

lmb_status lmb_light_atlases(const lmb_config *cfg, const lmb_direct *direct, lmb_cache *cache, lmb_steps *steps,
                             const lmb_lighting_hooks *hooks, lmb_bake_stats *stats, lmb_ic_points *records,
                             const lmb_log *log, lmb_error *err);

#endif
