/*
 * Texels whose surface turns faster than a record can follow, gathered on their own
 * (ic_pass_internal.h: lmb_ic_gather_own_texels).
 *
 * A record covers a texel only where its normal is close (Ward's eps_n: a record weighs at most
 * 1 - sqrt(1 - n.n_i) / normal_limit there, and a texel needs LMB_IC_COVERED). On a small curved
 * prop (a bumpy rock of a few hundred texels, 16 triangles to a texel) the normal turns past that
 * from one texel to the next, so placement ends with a record at every other texel, each gathered
 * with a coarse level's rays for the one or two texels it serves, and every texel a blend of
 * neighbours with other normals: slower than a gather per texel and further from it
 * (docs/irradiance-cache.md, "Texels the cache does not serve"). Such texels are gathered on
 * their own, as without the cache, and the records go where the light can be interpolated.
 */
#include "ic_pass_internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* A neighbour turns when a record at it would fall below LMB_IC_COVERED here by the normal
 * alone: sqrt(1 - n.n_j) > (1 - LMB_IC_COVERED) x normal_limit. */
static int turns(const double n[3], const double m[3], double limit)
{
    double c = n[0] * m[0] + n[1] * m[1] + n[2] * m[2];
    return sqrt(fmax(0.0, 1.0 - c)) > (1.0 - LMB_IC_COVERED) * limit;
}

static uint32_t instance_of(const lmb_texels *t, uint32_t i)
{
    return t->refs[(size_t)i * t->samples + t->gather_at[i]].instance;
}

/* Per listed texel of atlas a: 1 when it is gathered on its own. A valid texel is one when at
 * least two of its four atlas neighbours (listed, valid, same instance) turn and at most one
 * does not: a surface curved both ways at the texel's scale (a cylinder's texels along its
 * axis keep two neighbours that do not turn, and interpolate). Each valid texel's normal is
 * made once (a texel is its neighbours' neighbour four times over). */
static lmb_status mark_atlas(const pass_ctx *c, uint32_t a, uint8_t *own, lmb_error *err)
{
    const lmb_texels *t = c->t[a];
    size_t cells = (size_t)t->width * t->height;
    uint32_t *at = calloc(cells + 1, sizeof *at); /* texel + 1 per atlas cell, 0: none */
    double *normal = malloc((3 * (size_t)t->count + 1) * sizeof *normal);
    if (!at || !normal) {
        free(at);
        free(normal);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for a %ux%u atlas", t->width,
                             t->height);
    }
    for (uint32_t i = 0; i < t->count; i++)
        if (t->valid[i])
            at[t->texel[i]] = i + 1;
#pragma omp parallel for num_threads(c->threads) schedule(dynamic, 4096)
    for (uint32_t i = 0; i < t->count; i++) {
        double p[3];
        if (t->valid[i])
            lmb_ic_texel_point(c, (texel_at){a, i}, p, normal + 3 * (size_t)i);
    }
    const double limit = c->records.normal_limit;
#pragma omp parallel for num_threads(c->threads) schedule(dynamic, 4096)
    for (uint32_t i = 0; i < t->count; i++) {
        own[i] = 0;
        if (!t->valid[i])
            continue;
        uint32_t x = t->texel[i] % t->width, y = t->texel[i] / t->width, inst = instance_of(t, i);
        int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1}, present = 0, turning = 0;
        for (int k = 0; k < 4; k++) {
            int64_t xx = (int64_t)x + dx[k], yy = (int64_t)y + dy[k];
            if (xx < 0 || yy < 0 || xx >= t->width || yy >= t->height)
                continue;
            uint32_t j = at[(size_t)yy * t->width + (size_t)xx];
            if (!j || instance_of(t, j - 1) != inst)
                continue;
            present++;
            turning += turns(normal + 3 * (size_t)i, normal + 3 * (size_t)(j - 1), limit);
        }
        own[i] = turning >= 2 && turning + 1 >= present;
    }
    free(normal);
    free(at);
    return LMB_OK;
}

/* An instance whose curved texels are at least this share of its valid texels is curved at the
 * texel's scale as a whole: its other texels lie between curved ones, where records serve a
 * texel or two and blend normals they do not share, so every one of its texels gets its own. */
#define OWN_INSTANCE_SHARE 0.25

/* Every valid texel of an instance whose curved texels reach OWN_INSTANCE_SHARE becomes one too.
 * Counted over all atlases (an instance's charts may lie in several). */
static lmb_status whole_instances(const pass_ctx *c, uint8_t **own, lmb_error *err)
{
    uint32_t instances = 0;
    for (uint32_t a = 0; a < c->atlas_count; a++)
        for (uint32_t i = 0; i < c->t[a]->count; i++)
            if (instance_of(c->t[a], i) + 1 > instances)
                instances = instance_of(c->t[a], i) + 1;
    uint64_t *curved = calloc((size_t)instances + 1, sizeof *curved), *valid = calloc((size_t)instances + 1, sizeof *valid);
    if (!curved || !valid) {
        free(curved);
        free(valid);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %u instances", instances);
    }
    for (uint32_t a = 0; a < c->atlas_count; a++)
        for (uint32_t i = 0; i < c->t[a]->count; i++)
            if (c->t[a]->valid[i]) {
                valid[instance_of(c->t[a], i)]++;
                curved[instance_of(c->t[a], i)] += own[a][i];
            }
    for (uint32_t a = 0; a < c->atlas_count; a++)
        for (uint32_t i = 0; i < c->t[a]->count; i++) {
            uint32_t k = instance_of(c->t[a], i);
            if (c->t[a]->valid[i] && (double)curved[k] >= OWN_INSTANCE_SHARE * (double)valid[k])
                own[a][i] = 1;
        }
    free(curved);
    free(valid);
    return LMB_OK;
}

/* own[a] := a flag per listed texel of atlas a (NULL when the atlas has none); *count := how many. */
static lmb_status mark_own_texels(const pass_ctx *c, uint8_t **own, uint64_t *count, lmb_error *err)
{
    *count = 0;
    lmb_status st = LMB_OK;
    for (uint32_t a = 0; a < c->atlas_count && st == LMB_OK; a++) {
        own[a] = malloc((size_t)c->t[a]->count + 1);
        st = own[a] ? mark_atlas(c, a, own[a], err)
                    : lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for atlas %u", a);
    }
    if (st == LMB_OK)
        st = whole_instances(c, own, err);
    for (uint32_t a = 0; a < c->atlas_count && st == LMB_OK; a++) {
        uint64_t n = 0;
        for (uint32_t i = 0; i < c->t[a]->count; i++)
            n += own[a][i];
        if (!n) {
            free(own[a]);
            own[a] = NULL;
        }
        *count += n;
    }
    return st;
}

/* Own texels per step: their records (168 bytes each) are held a part at a time. */
#define OWN_PART 65536

/*
 * The texels whose surface turns faster than a record can follow, gathered on their own in
 * every pass, with a texel's rays and no second gather for samples.noise, as
 * without the cache: they place no records, are no candidates, take no record's share and read
 * no interpolation. Nothing when there are none: a flat level's pass is what it was.
 */
lmb_status lmb_ic_gather_own_texels(pass_ctx *c, lmb_ic_own_texels *kept, lmb_gather_stats *stats, lmb_error *err)
{
    uint64_t n = 0;
    lmb_status st = LMB_OK;
    c->own_e = calloc((size_t)c->atlas_count + 1, sizeof *c->own_e);
    c->own_var = calloc((size_t)c->atlas_count + 1, sizeof *c->own_var);
    if (!c->own_e || !c->own_var)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory");
    if (kept && kept->marked) { /* an earlier pass marked them */
        c->own = kept->own;
        c->own_borrowed = 1;
        for (uint32_t a = 0; a < c->atlas_count; a++)
            for (uint32_t i = 0; c->own[a] && i < c->t[a]->count; i++)
                n += c->own[a][i];
    } else {
        c->own = calloc((size_t)c->atlas_count + 1, sizeof *c->own);
        st = c->own ? mark_own_texels(c, c->own, &n, err)
                    : lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory");
        if (st == LMB_OK && kept) { /* handed over: later passes read them */
            kept->own = c->own;
            kept->atlas_count = c->atlas_count;
            kept->marked = 1;
            c->own_borrowed = 1;
        }
    }
    if (st != LMB_OK || !n)
        return st;
    uint32_t *ids = malloc((size_t)n * sizeof *ids);
    lmb_ic_record *part = malloc((size_t)(n < OWN_PART ? n : OWN_PART) * sizeof *part);
    if (!ids || !part)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for %llu texels",
                           (unsigned long long)n);
    uint64_t k = 0;
    for (uint32_t a = 0; a < c->atlas_count && st == LMB_OK; a++) {
        if (!c->own[a])
            continue;
        c->own_e[a] = calloc(3 * (size_t)c->t[a]->count + 1, sizeof **c->own_e);
        c->own_var[a] = calloc((size_t)c->t[a]->count + 1, sizeof **c->own_var);
        if (!c->own_e[a] || !c->own_var[a])
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for atlas %u", a);
        for (uint32_t i = 0; i < c->t[a]->count; i++)
            if (c->own[a][i])
                ids[k++] = c->first_id[a] + i;
    }
    c->spacing = 1; /* a texel's rays (ic_record_step.c, ray_share) */
    c->own_level = 1;
    for (uint64_t first = 0; first < n && st == LMB_OK; first += OWN_PART, c->own_part++) {
        uint64_t m = n - first < OWN_PART ? n - first : OWN_PART, made = 0;
        st = lmb_ic_gather_records(c, ids + first, m, NULL, 0, part, &made, first, n, stats, err);
        for (uint64_t q = 0; st == LMB_OK && q < made; q++) {
            memcpy(c->own_e[part[q].atlas] + 3 * (size_t)part[q].texel, part[q].e, sizeof part[q].e);
            c->own_var[part[q].atlas][part[q].texel] = part[q].var;
        }
    }
    c->own_level = 0;
    free(part);
    free(ids);
    return st;
}

void lmb_ic_own_texels_free(lmb_ic_own_texels *o)
{
    for (uint32_t a = 0; o->own && a < o->atlas_count; a++)
        free(o->own[a]);
    free(o->own);
    memset(o, 0, sizeof *o);
}

void lmb_ic_free_own_texels(pass_ctx *c)
{
    for (uint32_t a = 0; a < c->atlas_count; a++) {
        if (c->own && !c->own_borrowed)
            free(c->own[a]);
        if (c->own_e)
            free(c->own_e[a]);
        if (c->own_var)
            free(c->own_var[a]);
    }
    if (!c->own_borrowed)
        free(c->own);
    free(c->own_e);
    free(c->own_var);
    c->own = NULL;
    c->own_borrowed = 0;
    c->own_e = c->own_var = NULL;
}
