/*
 * Rims at contact lines. A texel that geometry partly covers (some of its points lie inside
 * geometry: a light fixture flush under a ceiling, a wall standing on a floor) is lit from
 * its uncovered points only, and those may sit in a gap narrower than the texel, seeing
 * light no full texel around them sees (a double-sided emitter's back 1 mm under a ceiling:
 * up to 30x the ceiling around it). Bilinear filtering smears that sliver over two texels:
 * a bright outline. The lightmap cannot hold sub-texel detail, so a texel with a point
 * inside geometry or seeing a back face is limited to the brightest of its clean, valid
 * 8-neighbours (luminance; the colour is kept). The light removed is counted and reported.
 */
#ifndef LMBAKE_RIM_H
#define LMBAKE_RIM_H

#include <lmbake/lmbake.h>

#include "texels/texels.h"

typedef struct lmb_rim_stats {
    uint64_t limited;   /* texels lowered */
    double removed;     /* luminance removed, summed over texels */
    double total;       /* luminance of every valid texel before, summed */
} lmb_rim_stats;

/* rgb: 3 floats per listed texel of t (an atlas of t->width x t->height), lowered in place.
 * Adds to *stats. */
lmb_status lmb_rim_limit(const lmb_texels *t, float *rgb, lmb_rim_stats *stats, lmb_error *err);

#endif
