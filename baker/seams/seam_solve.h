/* The stitching solve of seams.h, shared by the stitcher (seams.c): the seam points as rows of
 * the least squares, and the solve in independent blocks. */
#ifndef LMBAKE_SEAM_SOLVE_H
#define LMBAKE_SEAM_SOLVE_H

#include "seams.h"

/* One seam point: 8 taps (4 bilinear taps per side, in the side's atlas; side B's weights
 * negated). 72 bytes: a level of 1,900 props holds 660,000. */
typedef struct seam_row {
    uint32_t atlas[2], texel[8];
    float w[8];
} seam_row;

/* The atlas of tap j (0..7). */
static inline uint32_t lmb_seam_tap_atlas(const seam_row *r, int j)
{
    return r->atlas[j / 4];
}

/* Unknowns solved together at most (a connected set of texels larger than this is one block):
 * bounds the memory of one factorisation. */
#define LMB_SEAM_BLOCK_UNKNOWNS 8192

/* Solves the seams.h least squares over rows and writes the result into rgb (texels the rows
 * read only); fills report's samples, dropped, texels and jumps. The system falls apart into
 * connected sets of texels (one per group of charts that share seams: a copy's charts never
 * share a texel with another copy's); sets are grouped into blocks of at most
 * LMB_SEAM_BLOCK_UNKNOWNS in the order of their first texel and the blocks solved on `threads`
 * threads, each with its own CHOLMOD factorisation. The blocks are the same at any thread
 * count, and a level whose seams fit one block is solved as one system. */
lmb_status lmb_seam_solve(const lmb_layout *l, float *const *rgb, const uint8_t *const *state, const seam_row *rows,
                          size_t nr, int threads, lmb_seam_report *report, lmb_error *err);

#endif
