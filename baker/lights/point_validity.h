/*
 * Gather points' validity kept between bakes (docs/watch.md#what-is-redone). Whether a gather
 * point lies inside geometry (lmb_point_inside_geometry: 16 hemisphere rays looking for back
 * faces) depends only on the geometry, the layout, the gather points per texel and the seed, not
 * on any light; it is most of the direct stage's rays. A memo holds the answer of every point of
 * every atlas (a byte each), filled the first time a point is tested and read after that: the
 * watch's bakes that keep their layout (lights, materials, sky or sampling changed) read the
 * memo the bake before them left in the layout cache (watch/validity_cache.h) instead of
 * tracing the rays again. A point read from the memo takes the same random numbers as one
 * tested (its stream moves past the test's draws), so the lightmaps are the same, byte for byte.
 */
#ifndef LMBAKE_LIGHTS_POINT_VALIDITY_H
#define LMBAKE_LIGHTS_POINT_VALIDITY_H

#include <stdint.h>

#include "pack/layout.h"

#include <lmbake/lmbake.h>

/* A point's entry: its state (the low two bits: not yet tested, usable (no hemisphere ray hit a
 * back face), usable but near the inside of geometry (some did), inside geometry), and NEAR when
 * some hemisphere ray hit within LMB_NEAR_TEXELS texels (lmb_point_sight.near). */
enum { LMB_VALIDITY_UNKNOWN = 0, LMB_VALIDITY_CLEAR = 1, LMB_VALIDITY_NEAR_BACK = 2, LMB_VALIDITY_INSIDE = 3 };
enum { LMB_VALIDITY_STATE = 3, LMB_VALIDITY_NEAR = 4 };

typedef struct lmb_point_validity {
    uint32_t atlas_count;
    uint32_t samples;   /* gather points per texel (samples.texel) */
    uint64_t *size;     /* per atlas: width x height x samples entries */
    uint8_t **entry;    /* per atlas: entry[(y * width + x) * samples + k] */
} lmb_point_validity;

/* An empty memo (every entry unknown) for layout's atlases and `samples` points per texel. */
lmb_status lmb_point_validity_init(lmb_point_validity *v, const lmb_layout *layout, uint32_t samples, lmb_error *err);
void lmb_point_validity_free(lmb_point_validity *v);

/* Entries that are not unknown, over every atlas. */
uint64_t lmb_point_validity_known(const lmb_point_validity *v);

#endif
