/*
 * Gather points and direct light of one atlas as a step of the bake (steps/runner.h): its items
 * are bands of ~16k texels (rows), each built and lit on its own (memory, issue 10: a band's
 * sub-sampled points live only while its direct light is computed). A band's bytes are its
 * texels as the atlas keeps them (one gather point each) and their direct light; results do
 * not depend on the bands: random streams are keyed by (atlas, texel).
 */
#ifndef LMBAKE_DIRECT_STEP_H
#define LMBAKE_DIRECT_STEP_H

#include "steps/runner.h"
#include "lights/direct.h"
#include "texels/texels.h"

/* Texels per band of the direct step and of its refinement (rows of about this many texels):
 * small enough that a step of 16 shards still deals each several bands (docs/farm.md#balance);
 * a texel's light does not depend on its band. */
#define LMB_DIRECT_BAND_TEXELS 1024

typedef struct lmb_direct_atlas {
    lmb_texels t;        /* the atlas's listed texels, one gather point each */
    float *direct;       /* 3 per listed texel */
    float *direction;    /* output.directional: 3 per listed texel, direct light's direction sum; else NULL */
    float *deferred;     /* `indirect` lights (lmb_direct_has_deferred): 3 per listed texel, their part of
                            direct; else NULL */
    float *shadowmask;   /* output.shadowmask with channels in use: 4 per listed texel, visibilities; else NULL */
    float *variance;     /* per listed texel: variance of one round's estimate of its luminance
                            (lmb_direct_job; 0: no sampled light), for lmb_direct_refine_step */
    uint64_t rays;       /* rays the step traced for this atlas */
} lmb_direct_atlas;

/* Bands lit at once by the direct step and its refinement: 4 per thread, so that a band's
 * serial set-up (its texels) runs beside the others and the texels' loop has enough work. */
uint32_t lmb_direct_group_bands(const lmb_direct_options *opt);

/* out[k] := the texels of band first + k of atlas `atlas` (rows per band `rows`), for k in
 * [0, last - first), built in parallel (a band per thread); skip (NULL: none): per band, 1
 * leaves out[k] empty. On error nothing is left allocated and err is the first band's error. */
lmb_status lmb_direct_build_bands(const lmb_direct_options *opt, const lmb_scene *scene, const lmb_layout *layout,
                                  uint32_t atlas, uint32_t rows, uint64_t first, uint64_t last,
                                  const lmb_instance_rows *instance_rows, const uint8_t *skip, lmb_texels *out,
                                  lmb_error *err);

/* *out := atlas a's texels and direct light (owned: free its arrays and lmb_texels_free). */
lmb_status lmb_direct_atlas_step(lmb_steps *steps, const lmb_direct *direct,
                                 const lmb_scene *scene, const lmb_layout *layout, uint32_t a, lmb_progress_fn progress,
                                 void *progress_user, lmb_direct_atlas *out, uint64_t *rays, lmb_error *err);

#endif
