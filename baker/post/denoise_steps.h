/*
 * The denoiser (denoise.h) over every atlas of a bake, each of its levels a step of the bake
 * (steps/runner.h): the items are the listed texels of the atlases it filters, in atlas order,
 * and each level reads the previous level's light of every texel. In a local bake a level's
 * results are written back into the light as soon as no texel still to be filtered reads them
 * (lmb_denoiser_reach rows on), so the bake holds a few rows of them, not a second copy of the
 * light; the output is the same bytes as writing them back at the level's end, or as a farm's.
 */
#ifndef LMBAKE_DENOISE_STEPS_H
#define LMBAKE_DENOISE_STEPS_H

#include "post/denoise.h"
#include "steps/runner.h"

/* One atlas's part. */
typedef struct lmb_denoise_part {
    const lmb_texels *t;
    float *light;          /* 3 floats per listed texel: filtered in place */
    const float *variance; /* per listed texel, the light's own variance (denoise.h), or NULL */
    double noise;          /* with no variance: the relative noise; <= 0: the atlas is left alone */
} lmb_denoise_part;

typedef struct lmb_denoise_run {
    uint32_t levels;       /* 1..8 */
    double strength;       /* sigma_light */
    int threads;           /* 0: all */
    const char *what;      /* the light, in the steps' names ("denoise WHAT, level K") */
} lmb_denoise_run;

/* Filters the atlases' light; stats add up the valid texels filtered and their luminance. */
lmb_status lmb_denoise_steps(lmb_steps *steps, const lmb_denoise_part *atlases, uint32_t atlas_count,
                             const lmb_denoise_run *run, lmb_denoise_stats *stats, lmb_error *err);

#endif
