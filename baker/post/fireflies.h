/*
 * Fireflies: single texels far brighter than every texel around them, where a rare sample
 * found a bright, small source (light escaping a gap under a double-sided fixture, a hot spot
 * seen by one gather ray). Their light is real on average but lands on the wrong texel. A
 * valid texel brighter (luminance) than LMB_FIREFLY_FACTOR x the median of the valid texels of
 * its 5 x 5 neighbourhood and LMB_FIREFLY_LONE x its brightest valid 8-neighbour (a lone
 * spike, not a line or an edge of light) is lowered to the first bound, and what it loses is shared equally among
 * its valid 8-neighbours: the light is moved, never removed (the sum over the neighbourhood is
 * unchanged, so means are kept), and how much moved is reported. Decisions read the image as
 * the gather left it, so the result does not depend on the order texels are visited.
 */
#ifndef LMBAKE_FIREFLIES_H
#define LMBAKE_FIREFLIES_H

#include <lmbake/lmbake.h>

#define LMB_FIREFLY_FACTOR 4.0
#define LMB_FIREFLY_LONE 2.0   /* and above this many times its brightest valid 8-neighbour */
#define LMB_FIREFLY_PASSES 8 /* at most, per atlas: a spike's share can leave a neighbour over the bound */

typedef struct lmb_firefly_stats {
    uint64_t texels;  /* fireflies lowered */
    double moved;     /* luminance moved to their neighbours, summed */
    double total;     /* luminance of every valid texel, summed */
} lmb_firefly_stats;

/* rgb: width x height x 3 floats, changed in place; state: LMB_TEXEL_* per texel. Adds to *stats.
 * threads: 0 for all cores; the result does not depend on it (spikes are found in parallel, their
 * light moved in texel order). */
lmb_status lmb_fireflies_spread(float *rgb, const uint8_t *state, uint32_t width, uint32_t height, int threads,
                                lmb_firefly_stats *stats, lmb_error *err);

#endif
