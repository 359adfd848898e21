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
 * normal equations are sparse and positive definite: one CHOLMOD factorisation, three
 * right-hand sides (RGB).
 *
 * A seam edge: the same world-space edge (endpoints equal to 1/1000 of a texel) in two
 * triangles of lightmapped instances, one instance or two, whose shading normals agree at
 * both endpoints (a smooth surface: a crease between flat-shaded faces is a real edge of
 * the light and is left alone) and whose lightmap UVs differ.
 */
#ifndef LMBAKE_SEAMS_H
#define LMBAKE_SEAMS_H

#include <lmbake/lmbake.h>

#include "pack/layout.h"

#define LMB_SEAM_WEIGHT 100.0 /* W: a seam sample's weight against one texel's data term */
#define LMB_SEAM_FREE 0.01    /* d_i of a texel without a value of its own (padding, dilated) */

typedef struct lmb_seam_report {
    uint64_t edges;          /* seam edges found */
    uint64_t samples;        /* points along them */
    uint64_t texels;         /* texels solved for */
    double jump_before;      /* largest |lum A - lum B| / mean over the points, before */
    double jump_after;       /* ... and after */
    double seconds;
} lmb_seam_report;

/* Stitches the atlases in place. rgb[a]: 3 floats per texel of atlas a (dilated: padding
 * holds values); state[a]: LMB_TEXEL_* per texel. */
lmb_status lmb_seams_stitch(const lmb_scene *scene, const lmb_layout *l, float *const *rgb, const uint8_t *const *state,
                            lmb_seam_report *report, lmb_error *err);

#endif
