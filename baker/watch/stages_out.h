/*
 * The light at each stage of a bake, written while the bake goes on (`lmbake bake --stages-out
 * DIR`, what `lmbake preview --watch` runs; docs/watch.md): per atlas the light the lightmap takes
 * (every light's but the `indirect` ones', mixed lighting), dilated, in the output's units, with
 * the lightmap's own name, DIR/STAGE/NAME-lightmap-N.hdr:
 *   direct:  the direct stage's light, as soon as that stage is done;
 *   bounces: all the light the bounce passes reached (the direct light, their bounces and the
 *            extrapolated tail: what the final gather then reads), once they are done; only
 *            when bounce passes ran.
 * The log line `stages: STAGE written to DIR/STAGE` says when a stage's files are whole. The
 * watch refines its quick picture with the difference of two bakes' stages at the final's
 * resolution while the final bake still runs.
 */
#ifndef LMBAKE_WATCH_STAGES_OUT_H
#define LMBAKE_WATCH_STAGES_OUT_H

#include "cache/bounce_cache.h"
#include "texels/texels.h"

#include <lmbake/lmbake.h>

/* Atlas a's light (light, minus deferred when not NULL: 3 floats per texel of t) as stage `stage`
 * under cfg->stages_out, through cache's image of atlas a (left holding it: the caller stores the
 * cache's next contents after). */
lmb_status lmb_stages_out_write(const lmb_config *cfg, const char *stage, lmb_cache *cache, uint32_t a,
                                const lmb_texels *t, const float *light, const float *deferred, lmb_error *err);

/* The log line that says stage `stage` is written whole. */
void lmb_stages_out_done(const lmb_config *cfg, const char *stage, const lmb_log *log);

/* The lighting's stage hook (pipeline/lighting.h lmb_stage_light_fn) that writes each stage under
 * cfg->stages_out: user is an lmb_stages_out. */
typedef struct lmb_stages_out {
    const lmb_config *cfg;
    const lmb_log *log;
} lmb_stages_out;
lmb_status lmb_stages_out_stage(void *user, const char *stage, uint32_t atlas, lmb_cache *cache, const lmb_texels *t,
                                const float *light, const float *deferred, lmb_error *err);

#endif
