/*
 * The seams stage: least-squares seam stitching (Sloan, "Stitching UV seams", 2017, as
 * Bakery ships it). Where one smooth surface is cut into two charts, the two sides of the
 * cut are filtered from different texels, and a continuous wall shows a line. For every
 * such seam edge, points along it are looked up bilinearly on both sides; the texels those
 * lookups read are solved for so that the two sides agree, while every texel moves as little
 * as possible from its baked value:
 *
 *   min_x  sum_i d_i (x_i - x0_i)^2 + W sum_s (b_A(s) . x - b_B(s) . x)^2
 *
 * (d_i = 1 at valid texels, LMB_SEAM_FREE at padding and filled texels, which may move
 * freely; W = LMB_SEAM_WEIGHT; b_A, b_B the bilinear weights of point s on each side). The
 * normal equations are sparse and positive definite: one CHOLMOD factorisation per
 * independent block of texels (seam_solve.h), three
 * right-hand sides (RGB).
 *
 * A seam edge: the same world-space edge (endpoints equal to 1/1000 of a texel) in two
 * triangles of lightmapped instances, one instance or two, whose shading normals agree at
 * both endpoints (a smooth surface: a crease between flat-shaded faces is a real edge of
 * the light and is left alone) and whose lightmap UVs differ. A point along it is matched
 * only where both sides read a valid texel and nothing stands on the edge (a wall on a
 * floor's seam, two rooms apart: from a quarter texel above the edge, both sides must be in
 * sight).
 */
#ifndef LMBAKE_SEAMS_H
#define LMBAKE_SEAMS_H

#include <lmbake/lmbake.h>

#include "pack/layout.h"
#include "raytrace/rt_scene.h"

#define LMB_SEAM_WEIGHT 100.0 /* W: a seam sample's weight against one texel's data term */
#define LMB_SEAM_FREE 0.01    /* d_i of a texel without a value of its own (padding, dilated) */
#define LMB_SEAM_ROUNDS 4     /* solves at most: points whose match goes negative are dropped */

typedef struct lmb_seam_report {
    uint64_t edges;          /* seam edges found */
    uint64_t samples;        /* points along them that were matched */
    uint64_t dropped;        /* points left unmatched: the match would need negative light */
    uint64_t texels;         /* texels solved for */
    double jump_before;      /* largest |lum A - lum B| / mean over the points, before */
    double jump_after;       /* ... and after */
    uint64_t over_1pct_before;
    uint64_t over_1pct;      /* points whose jump is over 1% after (over_1pct_before: before) */
    int equal;               /* both sides of every point read the same light (black, or equal in
                                every channel): nothing was solved, the atlases are as they were */
    double seconds;
} lmb_seam_report;

/* Stitches the atlases in place. rgb[a]: 3 floats per texel of atlas a (dilated: padding
 * holds values); state[a]: LMB_TEXEL_* per texel. The edges are found and their points placed
 * on `threads` threads (0: all cores); the result does not depend on it. */
lmb_status lmb_seams_stitch(const lmb_scene *scene, const lmb_layout *l, const lmb_rt *rt, float *const *rgb,
                            const uint8_t *const *state, int threads, lmb_seam_report *report, lmb_error *err);

#endif
