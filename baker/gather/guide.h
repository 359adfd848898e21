/*
 * Spatial reuse for per-texel gathering (issue 12): a lobe mixture learned at one texel does
 * not depend on a neighbour's samples, so the neighbour may sample from it and stay unbiased
 * (estimator.h, guided gathering). Pilot texels sit on a grid of `stride` texels in the atlas;
 * they gather first (unguided AMIS, fitting a mixture to all their samples), then every other
 * texel gathers guided by the nearest pilot of the four grid corners around it that lies on
 * the same surface: shading normals within ~25 degrees and at most 2 x stride texels away in
 * the world (charts that touch in the atlas can be far apart in the world).
 * (Ray guiding for lightmaps shares learned distributions across clusters of texels in the same
 * way: Silvennoinen and Sloan 2019.)
 * Ownership: lmb_guide_init allocates, lmb_guide_free frees; the pilots' entries are written by
 * the gather stage, one per pilot, before any guided texel reads them.
 */
#ifndef LMBAKE_GUIDE_H
#define LMBAKE_GUIDE_H

#include <lmbake/lmbake.h>

#include "gather/mixture.h"
#include "texels/texels.h"

/* A point guides another only on the same surface: shading normals within ~25 degrees (pilot
 * texels here, records in the irradiance cache). */
#define LMB_GUIDE_SAME_SURFACE_COS 0.9

typedef struct lmb_guide_pilot {
    double p[3], n[3];  /* the pilot's gather point and shading normal */
    float reach;        /* world distance within which it guides (2 x stride texels) */
    lmb_mixture mixture; /* count 0: nothing learned (a dark pilot): it guides no one */
} lmb_guide_pilot;

typedef struct lmb_guide {
    uint32_t stride, cols, rows;
    int32_t *cell;          /* per grid corner: the listed texel that is its pilot, or -1 */
    uint32_t *pilot_of;     /* per listed texel: index into pilots, or UINT32_MAX (not a pilot) */
    lmb_guide_pilot *pilots;
    uint32_t pilot_count;
} lmb_guide;

/* Chooses the pilots of atlas texels t (valid texels on the grid corners). Returns 0 when out
 * of memory. */
int lmb_guide_init(lmb_guide *g, const lmb_texels *t, uint32_t stride);
void lmb_guide_free(lmb_guide *g);

/* The mixture guiding listed texel i with gather point p and shading normal n, its lobes aimed
 * from p (lmb_mixture_reaim) into out; 0 when no pilot guides it. */
int lmb_guide_find(const lmb_guide *g, const lmb_texels *t, uint32_t i, const double p[3], const double n[3],
                   lmb_mixture *out);

#endif
