/*
 * Direct light at gather points (the "direct" step of the pipeline): KHR_lights_punctual
 * point and spot lights (candela, inverse square, the spec's range window and smooth cone
 * falloff), directional lights (lux), and emissive triangles as area lights (nits), each
 * with Embree shadow rays. Output: irradiance E (lux) per texel, linear RGB, before albedo.
 * Also marks texels whose points lie inside geometry invalid (most rays from them hit back
 * faces), so light does not leak under walls and shadows do not leak out.
 */
#ifndef LMBAKE_DIRECT_H
#define LMBAKE_DIRECT_H

#include "rt_scene.h"
#include "load/textures.h"
#include "texels/texels.h"

typedef struct lmb_emitters lmb_emitters; /* opaque: emissive triangles and their power CDF */

/* Emissive triangles of every instance; `textures` (may be NULL) holds decoded emissive
 * textures, which multiply the material's emissive factor x strength. */
lmb_status lmb_emitters_build(const lmb_scene *scene, const lmb_config *cfg, const lmb_textures *textures,
                              lmb_emitters **out, lmb_error *err);
void lmb_emitters_free(lmb_emitters *e);
uint32_t lmb_emitters_count(const lmb_emitters *e);

typedef struct lmb_direct_job {
    const lmb_scene *scene;
    const lmb_config *cfg;
    const lmb_rt *rt;
    const lmb_emitters *emitters;
    uint32_t atlas;      /* keys the random streams */
    lmb_progress_fn progress;
    void *progress_user;
} lmb_direct_job;

/* Fills irradiance (3 floats per listed texel of t) and t->valid. Counts rays traced. */
lmb_status lmb_direct_compute(const lmb_direct_job *job, lmb_texels *t, float *irradiance, uint64_t *rays,
                              lmb_error *err);

#endif
