/*
 * One gather pass through the irradiance cache (DESIGN.md section 7): the gather runs only at
 * records, placed where the light changes, and every other texel interpolates them.
 *
 * Placement, coarse to fine in lightmap space, over all atlases at once: level k looks at the
 * valid texels on a grid of spacing s_k = max_spacing / 2^k texels (s = max_spacing, ..., 2, 1)
 * and turns into a record every one that the records of the levels before do not cover
 * (sum of weights below LMB_IC_COVERED). A level's candidates are decided from the earlier
 * levels only, and its records are gathered in parallel and appended in texel order, so the
 * record set does not depend on the thread count or on any split of the work. The level
 * sequence repeats (at most 4 rounds) while neighbour clamping uncovers texels; the last
 * round does not clamp, and its spacing-1 level leaves no valid texel uncovered (each is at
 * worst its own record). A later round tests again only candidates where a record that
 * weighed there at the level's last test has shrunk since (weights only fall with a reach).
 * A record's reach is r = clamp(error x R, min_spacing, max_spacing texels), R the harmonic
 * mean distance of its gather rays (Ward 1988), neighbour-clamped after every level.
 * Then translation gradients are fitted from neighbouring records (records.h), and every
 * valid texel, records included, takes the interpolation at its gather point. Texels inside
 * geometry place no records and receive nothing (0).
 * Texels whose surface turns faster than a record can follow (a small curved prop: the normal
 * turns past a record's limit from one texel to the next) are gathered on their own first, in
 * every pass, as without the cache, and take no part in placement or interpolation
 * (ic_own_texels.c).
 */
#ifndef LMBAKE_IC_PASS_H
#define LMBAKE_IC_PASS_H

#include "gather/gather.h"
#include "irradiance_cache/records.h"
#include "texels/texels.h"

/* A texel is covered when the weights of the records that reach it sum to at least this
 * (one record at a third of its reach, or two at two thirds). */
#define LMB_IC_COVERED 0.6

typedef struct lmb_ic_options {
    double error;          /* Ward's a (> 0) */
    double min_spacing;    /* texels: the smallest reach */
    double max_spacing;    /* texels: the largest reach, and the first level's grid */
    uint32_t ray_scale;    /* a record gathers with ray_scale x the pass's rays per texel, or fewer
                              where it stands for fewer texels (ic_record_step.c, ray_share) */
} lmb_ic_options;

/* A pass's records as the preview draws them: x, y, z (world) and reach per record. */
typedef struct lmb_ic_points {
    float *xyzr;           /* 4 per record; owned (free()) */
    uint32_t count;
} lmb_ic_points;

/* What one pass did, per atlas (arrays of atlas_count, owned by the caller). */
typedef struct lmb_ic_pass_stats {
    uint64_t *records;     /* records placed in the atlas */
    uint64_t *valid;       /* valid texels of the atlas */
    uint64_t *own;         /* when not NULL: valid texels gathered on their own, not through records
                              (curved at the texel's scale: ic_own_texels.c) */
    lmb_ic_points *points; /* when not NULL: receives the records (previous contents freed) */
    double *noise;         /* when not NULL: per atlas, the median relative standard error of its records'
                              gathers, sqrt(var) / lum(e), each weighted by lum(e) (0 when none was
                              estimated): post/denoise.h */
} lmb_ic_pass_stats;

/* Which texels every pass gathers on their own (ic_own_texels.c). They follow from the geometry
 * alone, so the first pass marks them and later passes given the same struct read them. Zeroed
 * to start; lmb_ic_own_texels_free frees it. */
typedef struct lmb_ic_own_texels {
    uint8_t **own;         /* per atlas, a flag per listed texel (NULL: none in that atlas) */
    uint32_t atlas_count;
    int marked;
} lmb_ic_own_texels;

void lmb_ic_own_texels_free(lmb_ic_own_texels *o);

/* Indirect irradiance of every listed texel of every atlas (t[a], out[a]: 3 floats per listed
 * texel) through a cache built for this pass. job->estimator gives the method and the rays
 * per texel; stats add up the gathers' rays.
 * shared: NULL, each pass places its own records (irradiance_cache.records: per_pass); else
 * the records of one pass refined by the next (shared): empty, this pass places records and
 * leaves them there; holding records, this pass gathers again at them (same positions and
 * reaches, this pass's light) and leaves them updated. The caller frees it. own: NULL, this
 * pass marks its texels gathered on their own for itself; else as lmb_ic_own_texels says. */
lmb_status lmb_ic_gather_pass(const lmb_gather_job *job, const lmb_ic_options *opt, uint32_t atlas_count,
                              const lmb_texels *const *t, float *const *out, lmb_ic_pass_stats *pass,
                              lmb_ic_records *shared, lmb_ic_own_texels *own, lmb_gather_stats *stats,
                              lmb_error *err);

#endif
