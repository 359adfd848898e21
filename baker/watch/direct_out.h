/*
 * The direct light as the direct stage leaves it, written while the bake goes on (`lmbake bake
 * --direct-out DIR`, what `lmbake preview --watch` runs; docs/watch.md): per atlas the light the
 * lightmap takes from the lights directly (every light's but the `indirect` ones', mixed
 * lighting), dilated, in the output's units, as DIR/STEM-lightmap-N.hdr, the lightmap's own name.
 * The watch refines its quick picture with the difference of two bakes' direct light at the
 * final's resolution as soon as the final bake's direct stage is done, and reads the files once
 * the log line `direct light: written to DIR` says they are whole.
 */
#ifndef LMBAKE_WATCH_DIRECT_OUT_H
#define LMBAKE_WATCH_DIRECT_OUT_H

#include "cache/bounce_cache.h"
#include "texels/texels.h"

#include <lmbake/lmbake.h>

/* Atlas a's direct light (direct, minus deferred when not NULL: 3 floats per texel of t) to
 * cfg->direct_out, through cache's image of atlas a (left holding it: the caller stores the
 * cache's next contents after). */
lmb_status lmb_direct_out_write(const lmb_config *cfg, lmb_cache *cache, uint32_t a, const lmb_texels *t,
                                const float *direct, const float *deferred, lmb_error *err);

#endif
