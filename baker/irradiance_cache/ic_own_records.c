/*
 * Texels whose surface turns faster than a record can follow (ic_pass_internal.h,
 * lmb_ic_mark_own_texels).
 *
 * A record covers a texel only where its normal is close (Ward's eps_n: a record weighs at most
 * 1 - sqrt(1 - n.n_i) / normal_limit there, and a texel needs LMB_IC_COVERED). On a small curved
 * prop (a bumpy rock of a few hundred texels, 16 triangles to a texel) the normal turns past that
 * from one texel to the next, so placement ends with a record at every other texel, each gathered
 * with a coarse level's rays for the one or two texels it serves, and every texel a blend of
 * neighbours with other normals: slower than a gather per texel and further from it
 * (docs/irradiance-cache.md, "Texels the cache does not serve"). Such texels are gathered on
 * their own, as without the cache (ic_pass.c, gather_own_texels), and the records go where the
 * light can be interpolated.
 */
#include "ic_pass_internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>

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

/* Per listed texel of atlas a: 1 when it needs a record of its own. A valid texel is one when at
 * least two of its four atlas neighbours (listed, valid, same instance) turn and at most one
 * does not: a surface curved both ways at the texel's scale (a cylinder's texels along its
 * axis keep two neighbours that do not turn, and interpolate). */
static lmb_status mark_atlas(const pass_ctx *c, uint32_t a, uint8_t *own, lmb_error *err)
{
    const lmb_texels *t = c->t[a];
    size_t cells = (size_t)t->width * t->height;
    uint32_t *at = calloc(cells + 1, sizeof *at); /* texel + 1 per atlas cell, 0: none */
    if (!at)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "irradiance cache: out of memory for a %ux%u atlas", t->width,
                             t->height);
    for (uint32_t i = 0; i < t->count; i++)
        if (t->valid[i])
            at[t->texel[i]] = i + 1;
    const double limit = c->records.normal_limit;
#pragma omp parallel for num_threads(c->threads) schedule(dynamic, 4096)
    for (uint32_t i = 0; i < t->count; i++) {
        own[i] = 0;
        if (!t->valid[i])
            continue;
        uint32_t x = t->texel[i] % t->width, y = t->texel[i] / t->width, inst = instance_of(t, i);
        int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1}, present = 0, turning = 0;
        double p[3], n[3];
        lmb_ic_texel_point(c, (texel_at){a, i}, p, n);
        for (int k = 0; k < 4; k++) {
            int64_t xx = (int64_t)x + dx[k], yy = (int64_t)y + dy[k];
            if (xx < 0 || yy < 0 || xx >= t->width || yy >= t->height)
                continue;
            uint32_t j = at[(size_t)yy * t->width + (size_t)xx];
            if (!j || instance_of(t, j - 1) != inst)
                continue;
            double q[3], m[3];
            lmb_ic_texel_point(c, (texel_at){a, j - 1}, q, m);
            present++;
            turning += turns(n, m, limit);
        }
        own[i] = turning >= 2 && turning + 1 >= present;
    }
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

lmb_status lmb_ic_mark_own_texels(const pass_ctx *c, uint8_t **own, uint64_t *count, lmb_error *err)
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
