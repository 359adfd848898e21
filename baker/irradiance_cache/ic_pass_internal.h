/*
 * What the irradiance-cache pass (ic_pass.c) shares with its record gathers
 * (ic_record_step.c): the pass's state, and the step that gathers records.
 */
#ifndef LMBAKE_IC_PASS_INTERNAL_H
#define LMBAKE_IC_PASS_INTERNAL_H

#include "steps/runner.h"
#include "gather/gather.h"
#include "gather/mixture.h"
#include "irradiance_cache/ic_pass.h"
#include "irradiance_cache/records.h"

/* A listed texel of some atlas. Lists of them (a level's candidates) hold its id instead, the
 * texels of the atlases before it plus its index: 4 bytes, not 8 (lmb_ic_texel_at). */
typedef struct texel_at {
    uint32_t atlas, index;
} texel_at;

typedef struct pass_ctx {
    const lmb_gather_job *job;    /* with the record's rays */
    const lmb_gather_job *own_job; /* the same for own texels: no second gather for samples.noise (a
                                      texel's gather, as without the cache; the denoiser reads their noise) */
    const lmb_ic_options *opt;
    uint32_t atlas_count;
    const lmb_texels *const *t;
    uint32_t *first_id;           /* per atlas (+1): the id of its first texel */
    uint8_t **is_record;          /* per atlas, per listed texel */
    lmb_ic_records records;
    int threads;
    uint64_t valid_total, levels, level;
    uint64_t reported;            /* progress never goes back (the last level may run several rounds) */
    char stage[96];
    uint32_t group;               /* placement levels so far (lmb_ic_record.group) */
    uint32_t regather_group;      /* the group being gathered again (step names) */
    uint32_t spacing;             /* the placement level's grid spacing (texels) being gathered */
    /* texels gathered on their own (ic_own_texels.c): per atlas, per listed texel, a flag (NULL
     * for an atlas without any), their irradiance (3 floats) and its estimated variance */
    uint8_t **own;
    int own_borrowed;             /* own belongs to the caller's lmb_ic_own_texels */
    float **own_e, **own_var;
    int own_level;                /* the gathers running are own texels' (no records made of them) */
    uint32_t own_part;            /* their steps so far (step names) */
    /* guided gathering (gather/guide.h): per record, the mixture it gathered by or learned in
     * this pass; has_mix[k] is set once record k's whole group is gathered, so a record is
     * guided only by records of earlier groups (deterministic at any thread count) */
    int guided;
    uint32_t lobes;
    lmb_mixture_kept *mix;
    uint8_t *has_mix;
    uint32_t mix_cap;
    /* placement rounds after the first (ic_pass.c, uncovered_again): per level, the reach of
     * each record when the level's candidates were last tested, and how many records there were */
    double **tested_reach;
    uint32_t *tested_count;
} pass_ctx;

/* The texel of an id, and the id of a texel. */
texel_at lmb_ic_texel_at(const pass_ctx *c, uint32_t id);
static inline uint32_t lmb_ic_texel_id(const pass_ctx *c, texel_at x)
{
    return c->first_id[x.atlas] + x.index;
}

/* The world position and shading normal a texel gathers at. */
void lmb_ic_texel_point(const pass_ctx *c, texel_at x, double p[3], double n[3]);

/* The pass's own texels (ic_own_texels.c): the valid texels whose surface turns faster than a
 * record can follow (c->own: kept's when it is marked already, else marked here and, with kept,
 * handed to it), each gathered on its own with a texel's rays (c->own_e, c->own_var), before any
 * record is placed or gathered again. Freed by lmb_ic_free_own_texels (idempotent; the flags only
 * when the pass owns them). */
lmb_status lmb_ic_gather_own_texels(pass_ctx *c, lmb_ic_own_texels *kept, lmb_gather_stats *stats, lmb_error *err);
void lmb_ic_free_own_texels(pass_ctx *c);

static inline int lmb_ic_is_own(const pass_ctx *c, uint32_t atlas, uint32_t i)
{
    return c->own && c->own[atlas] && c->own[atlas][i];
}

/* Progress: done_in_level of level_total gathers of the current level. */
void lmb_ic_report(pass_ctx *c, uint64_t done_in_level, uint64_t level_total);

/*
 * Gathers at the m texels of ids at[] (one step of the bake). slots == NULL: new records, appended
 * to rec[] (*made of them; NULL made: every texel makes one); with `candidates`, a texel the
 * records so far cover makes none (level placement: the test runs in the step, beside the
 * gathers). slots != NULL: records placed by an earlier pass (`irradiance_cache.records:
 * shared`), record slots[k], updated with this pass's irradiance and rotation gradient,
 * keeping position and reach. Guided: each gathers by the nearest record of an earlier group
 * on the same surface (its mixture re-aimed), or learns one.
 */
lmb_status lmb_ic_gather_records(pass_ctx *c, const uint32_t *at, uint64_t m, const uint32_t *slots, int candidates,
                                 lmb_ic_record *rec, uint64_t *made, uint64_t done_before, uint64_t total,
                                 lmb_gather_stats *stats, lmb_error *err);

#endif
