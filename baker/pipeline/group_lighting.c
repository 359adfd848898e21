/* The lighting of each light group on its own, and their sum (see group_lighting.h). */
#include "group_lighting.h"

#include "pipeline/group_cache.h"
#include "pipeline/group_store.h"

#include "util/lmb_math.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

void lmb_group_light_free(lmb_group_light *gl)
{
    size_t n = (size_t)gl->groups * gl->atlases;
    for (size_t k = 0; gl->irradiance && k < n; k++)
        free(gl->irradiance[k]);
    for (size_t k = 0; gl->direction && k < n; k++)
        free(gl->direction[k]);
    for (uint32_t g = 0; gl->sh && g < gl->groups; g++) {
        free(gl->sh[g]);
        free(gl->cube[g]);
    }
    for (uint32_t g = 0; gl->records && g < gl->groups; g++)
        free(gl->records[g].xyzr);
    free(gl->irradiance);
    free(gl->direction);
    free(gl->sh);
    free(gl->cube);
    free(gl->records);
    free(gl->key);
    free(gl->cached);
    lmb_group_store_close(gl);
    free(gl->file);
    free(gl->away);
    free(gl->texels);
    memset(gl, 0, sizeof *gl);
}

static lmb_status light_alloc(lmb_group_light *gl, uint32_t groups, const lmb_layout *layout, int directional,
                              int probes, lmb_error *err)
{
    uint32_t atlases = layout->atlas_count;
    memset(gl, 0, sizeof *gl);
    gl->groups = groups;
    gl->atlases = atlases;
    size_t n = (size_t)groups * atlases + 1;
    gl->irradiance = calloc(n, sizeof *gl->irradiance);
    gl->direction = directional ? calloc(n, sizeof *gl->direction) : NULL;
    gl->sh = probes ? calloc((size_t)groups + 1, sizeof *gl->sh) : NULL;
    gl->cube = probes ? calloc((size_t)groups + 1, sizeof *gl->cube) : NULL;
    gl->records = calloc((size_t)groups + 1, sizeof *gl->records);
    gl->key = calloc((size_t)groups + 1, sizeof *gl->key);
    gl->cached = calloc((size_t)groups + 1, 1);
    gl->away = calloc((size_t)groups + 1, 1);
    gl->file = malloc(((size_t)groups + 1) * sizeof *gl->file);
    gl->texels = calloc((size_t)atlases + 1, sizeof *gl->texels);
    for (uint32_t g = 0; gl->file && g < groups; g++)
        gl->file[g] = -1;
    for (uint32_t a = 0; gl->texels && a < atlases; a++)
        gl->texels[a] = (uint64_t)layout->width[a] * layout->height[a];
    if (!gl->irradiance || (directional && !gl->direction) || (probes && (!gl->sh || !gl->cube)) || !gl->records ||
        !gl->key || !gl->cached || !gl->away || !gl->file || !gl->texels) {
        lmb_group_light_free(gl);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: out of memory");
    }
    return LMB_OK;
}

/* Group g's light out of the cache and the probes into gl (the cache's images taken, not copied:
 * the next group's passes make new ones); a dark group's is 0. */
static lmb_status keep_group(const lmb_group_env *env, uint32_t g, int dark, const lmb_ic_points *records,
                             lmb_group_light *gl, lmb_error *err)
{
    lmb_cache *c = env->cache;
    for (uint32_t a = 0; a < c->atlas_count; a++) {
        size_t n = 3 * (size_t)c->layout->width[a] * c->layout->height[a] + 1, k = (size_t)g * c->atlas_count + a;
        if (dark) {
            gl->irradiance[k] = calloc(n, sizeof **gl->irradiance);
        } else {
            gl->irradiance[k] = c->irradiance[a];
            c->irradiance[a] = NULL;
        }
        if (gl->direction && (dark || !c->direction || !c->direction[a])) {
            gl->direction[k] = calloc(n, sizeof **gl->direction);
        } else if (gl->direction) {
            gl->direction[k] = c->direction[a];
            c->direction[a] = NULL;
        }
        if (!gl->irradiance[k] || (gl->direction && !gl->direction[k]))
            return lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: out of memory for atlas %u", a);
    }
    if (!dark && records->count) {
        gl->records[g].xyzr = malloc(4 * (size_t)records->count * sizeof *records->xyzr + 1);
        if (!gl->records[g].xyzr)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: out of memory for records");
        memcpy(gl->records[g].xyzr, records->xyzr, 4 * (size_t)records->count * sizeof *records->xyzr);
        gl->records[g].count = records->count;
    }
    const lmb_probe_set *p = env->probes;
    if (gl->sh && p && p->count) {
        gl->sh[g] = calloc((size_t)p->count * LMB_PROBE_SH + 1, sizeof **gl->sh);
        gl->cube[g] = calloc((size_t)p->count * LMB_PROBE_CUBE + 1, sizeof **gl->cube);
        if (!gl->sh[g] || !gl->cube[g])
            return lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: out of memory for %u probes", p->count);
        if (!dark) {
            memcpy(gl->sh[g], p->sh, (size_t)p->count * LMB_PROBE_SH * sizeof *p->sh);
            memcpy(gl->cube[g], p->cube, (size_t)p->count * LMB_PROBE_CUBE * sizeof *p->cube);
        }
    }
    return LMB_OK;
}

/* What group g's lighting changes of a light, to put back. */
typedef struct saved_light {
    lmb_light_mode mode;
    float intensity, color[3];
} saved_light;

/* The lights of the level that are not in group g are left out while it is lit (as realtime
 * lights are); a unit group's light shines at intensity 1 and white (lmb_light_groups.unit: its
 * intensity and colour are the group's weight). saved: what to put back. */
static void only_group(lmb_scene *s, const lmb_light_groups *groups, uint32_t g, saved_light *saved)
{
    for (uint32_t i = 0; i < s->light_count; i++) {
        lmb_light *l = &s->lights[i];
        saved[i] = (saved_light){l->mode, l->intensity, {l->color[0], l->color[1], l->color[2]}};
        if (groups->of_light[i] != (int32_t)g)
            l->mode = LMB_LIGHT_REALTIME;
        else if (groups->unit[g]) {
            l->intensity = 1.0f;
            l->color[0] = l->color[1] = l->color[2] = 1.0f;
        }
    }
}

static void restore_lights(lmb_scene *s, const saved_light *saved)
{
    for (uint32_t i = 0; i < s->light_count; i++) {
        s->lights[i].mode = saved[i].mode;
        s->lights[i].intensity = saved[i].intensity;
        memcpy(s->lights[i].color, saved[i].color, sizeof saved[i].color);
    }
}

/* Group g: its lights alone through the lighting passes and the probes. */
static lmb_status light_group(const lmb_group_env *env, const lmb_light_groups *groups, uint32_t g,
                              lmb_bake_stats *stats, lmb_ic_points *records, int *dark, lmb_error *err)
{
    const lmb_config *cfg = env->cfg;
    lmb_direct *direct = NULL;
    lmb_status st = lmb_direct_create(env->scene, env->direct_opt, env->rt,
                                      groups->emissive == (int32_t)g ? env->emitters : NULL,
                                      groups->sky == (int32_t)g ? env->sky : NULL, &direct, err);
    if (st != LMB_OK)
        return st;
    if (env->validity)
        lmb_direct_set_validity(direct, env->validity);
    *dark = !lmb_direct_any_light(direct);
    lmb_info(env->log, "light group '%s' (%u of %u): lighting%s", groups->name[g], g + 1, groups->count,
             *dark ? ": nothing in it emits, its lightmap is black" : "");
    if (!*dark) {
        free(records->xyzr); /* the last group's records are the ones written */
        records->xyzr = NULL;
        records->count = 0;
        st = lmb_light_atlases(cfg, direct, env->cache, env->steps, env->hooks, stats, records, env->log, err);
    }
    if (st == LMB_OK && env->probes)
        st = lmb_probes_light(env->probes, cfg, direct, env->cache, env->steps, *dark,
                              env->hooks ? env->hooks->progress : NULL, env->hooks ? env->hooks->progress_user : NULL,
                              env->log, err);
    lmb_direct_set_validity(direct, NULL);
    lmb_direct_free(direct);
    return st;
}

lmb_status lmb_group_lighting(const lmb_group_env *env, const lmb_light_groups *groups, lmb_bake_stats *stats,
                              lmb_ic_points *records, lmb_group_light *out, lmb_error *err)
{
    lmb_scene *s = env->scene;
    memset(out, 0, sizeof *out);
    lmb_status st = env->keep ? light_alloc(out, groups->count, env->cache->layout, env->cfg->directional,
                                            env->probes != NULL, err)
                              : LMB_OK;
    saved_light *saved = malloc(((size_t)s->light_count + 1) * sizeof *saved);
    if (st == LMB_OK && !saved)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: out of memory");
    uint32_t probes = env->probes ? env->probes->count : 0;
    if (st == LMB_OK && env->keep) { /* what the groups cost beyond a bake without them */
        uint64_t texels = 0;
        for (uint32_t a = 0; a < env->cache->atlas_count; a++)
            texels += (uint64_t)env->cache->layout->width[a] * env->cache->layout->height[a];
        unsigned per = env->cfg->directional ? 24u : 12u;
        lmb_info(env->log, "light groups: each group's light kept until the files are written, in a file in TMPDIR "
                 "while no stage reads it: %u group(s) x %u bytes x %llu texels = %.1f MB", groups->count, per,
                 (unsigned long long)texels,
                 (double)groups->count * per * (double)texels / 1048576.0);
    }
    if (st == LMB_OK && env->keep && env->cache_dir)
        st = lmb_group_cache_keys(s, env->cfg, groups, out->key, err);
    for (uint32_t g = 0; g < groups->count && st == LMB_OK; g++) {
        lmb_bake_stats other;
        memset(&other, 0, sizeof other);
        lmb_bake_stats *gs = g ? &other : stats;
        int dark = 0;
        if (env->keep && env->cache_dir) { /* kept by an earlier bake with the same key: read back */
            uint64_t texels = 0, valid = 0;
            if (lmb_group_cache_read(env->cache_dir, out->key[g], g, out, env->cache, probes, &texels,
                                                     &valid, env->log)) {
                out->cached[g] = 1;
                lmb_group_light_put_away(out, g, env->log);
                gs->texels = texels;
                gs->valid_texels = valid;
                lmb_info(env->log, "light group '%s' (%u of %u): read back from the cache (its lights, the level and "
                         "the config but the groups' scales are an earlier bake's)", groups->name[g], g + 1,
                         groups->count);
                continue;
            }
        }
        only_group(s, groups, g, saved);
        if (st == LMB_OK)
            st = light_group(env, groups, g, gs, records, &dark, err);
        restore_lights(s, saved);
        if (g)
            stats->rays += other.rays;
        if (st == LMB_OK && env->keep)
            st = keep_group(env, g, dark, records, out, err);
        if (st == LMB_OK && env->keep) /* out of memory until a stage reads it (group_store.h) */
            lmb_group_light_put_away(out, g, env->log);
    }
    free(saved);
    /* the records written: the last group's (lit or read back) */
    if (st == LMB_OK && env->keep && groups->count) {
        const lmb_ic_points *last = &out->records[groups->count - 1];
        free(records->xyzr);
        records->xyzr = last->count ? malloc(4 * (size_t)last->count * sizeof *records->xyzr + 1) : NULL;
        records->count = records->xyzr ? last->count : 0;
        if (records->xyzr)
            memcpy(records->xyzr, last->xyzr, 4 * (size_t)last->count * sizeof *records->xyzr);
    }
    if (st != LMB_OK)
        lmb_group_light_free(out);
    return st;
}

void lmb_group_swap(lmb_group_light *gl, uint32_t g, lmb_cache *cache)
{
    for (uint32_t a = 0; a < cache->atlas_count; a++) {
        float **k = &gl->irradiance[(size_t)g * gl->atlases + a], *t = *k;
        *k = cache->irradiance[a];
        cache->irradiance[a] = t;
    }
}

/* Texels a compose reads of each group at once: G x 3 x 4 x 65536 bytes (6 MB for 8 groups, twice
 * with directions), the groups' files read in spans of 768 KB. */
#define COMPOSE_SPAN 65536

/* One texel of the sum: eg[g x stride] its light in group g, dg likewise its directions (NULL:
 * none); e, d: the sum's (lmb_group_compose). */
static void compose_texel(const lmb_light_groups *groups, uint32_t G, const float *eg0, const float *dg0, size_t stride,
                          float *e, float *d)
{
    double sum[3] = {0, 0, 0}, v[3] = {0, 0, 0};
    for (uint32_t g = 0; g < G; g++) {
        const float *eg = eg0 + g * stride; /* as its files hold it */
        double part[3];
        for (int c = 0; c < 3; c++) {
            part[c] = groups->scale[g] * groups->weight[g][c] * (double)eg[c];
            sum[c] += part[c];
        }
        if (d) {
            const float *dg = dg0 + g * stride;
            double w = 0.2126 * part[0] + 0.7152 * part[1] + 0.0722 * part[2];
            for (int c = 0; c < 3; c++)
                v[c] += w * (double)dg[c];
        }
    }
    for (int c = 0; c < 3; c++)
        e[c] = (float)sum[c];
    if (d) {
        double lum = 0.2126 * sum[0] + 0.7152 * sum[1] + 0.0722 * sum[2], len = 0;
        for (int c = 0; c < 3; c++) {
            v[c] = lum > 0 ? v[c] / lum : 0;
            len += v[c] * v[c];
        }
        len = sqrt(len);
        for (int c = 0; c < 3; c++)
            d[c] = (float)(len > 1 ? v[c] / len : v[c]);
    }
}

lmb_status lmb_group_compose(const lmb_light_groups *groups, const lmb_group_light *gl, lmb_cache *cache,
                             lmb_probe_set *probes, lmb_error *err)
{
    uint32_t G = gl->groups;
    if (gl->direction && !cache->direction)
        cache->direction = calloc((size_t)cache->atlas_count + 1, sizeof *cache->direction);
    if (gl->direction && !cache->direction)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: out of memory");
    /* each group's span of texels (from memory or its file), COMPOSE_SPAN texels at a time */
    size_t span = COMPOSE_SPAN;
    float *ge = malloc(((size_t)G * 3 * span + 1) * sizeof *ge), *gd = gl->direction ? malloc(((size_t)G * 3 * span + 1) * sizeof *gd) : NULL;
    lmb_status st = ge && (!gl->direction || gd) ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: out of memory");
    for (uint32_t a = 0; a < cache->atlas_count && st == LMB_OK; a++) {
        size_t n = (size_t)cache->layout->width[a] * cache->layout->height[a];
        float *e = malloc((3 * n + 1) * sizeof *e), *d = gl->direction ? malloc((3 * n + 1) * sizeof *d) : NULL;
        if (!e || (gl->direction && !d)) {
            free(e);
            free(d);
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: out of memory for atlas %u", a);
            break;
        }
        int threads = cache->threads > 0 ? (int)cache->threads : omp_get_max_threads();
        for (size_t i0 = 0; i0 < n && st == LMB_OK; i0 += span) {
            size_t i1 = i0 + span < n ? i0 + span : n;
            for (uint32_t g = 0; g < G && st == LMB_OK; g++)
                st = lmb_group_light_read_span(gl, g, a, i0, i1, ge + (size_t)g * 3 * span,
                                               gd ? gd + (size_t)g * 3 * span : NULL, err);
#pragma omp parallel for num_threads(threads) schedule(static)
            for (size_t i = i0; i < i1; i++) /* each texel on its own: the same floats at any thread count */
                compose_texel(groups, G, ge + 3 * (i - i0), gd ? gd + 3 * (i - i0) : NULL, 3 * span, e + 3 * i,
                              d ? d + 3 * i : NULL);
        }
        if (st != LMB_OK) {
            free(e);
            free(d);
            break;
        }
        free(cache->irradiance[a]);
        cache->irradiance[a] = e;
        if (d) {
            free(cache->direction[a]);
            cache->direction[a] = d;
        }
    }
    free(ge);
    free(gd);
    if (st != LMB_OK)
        return st;
    for (uint32_t p = 0; gl->sh && probes && p < probes->count; p++) {
        double sh[LMB_PROBE_SH] = {0}, cube[LMB_PROBE_CUBE] = {0};
        for (uint32_t g = 0; g < G; g++) { /* channel k % 3 of each */
            const float *gs = gl->sh[g] + (size_t)p * LMB_PROBE_SH, *gc = gl->cube[g] + (size_t)p * LMB_PROBE_CUBE;
            for (int k = 0; k < LMB_PROBE_SH; k++)
                sh[k] += groups->scale[g] * groups->weight[g][k % 3] * (double)gs[k];
            for (int k = 0; k < LMB_PROBE_CUBE; k++)
                cube[k] += groups->scale[g] * groups->weight[g][k % 3] * (double)gc[k];
        }
        for (int k = 0; k < LMB_PROBE_SH; k++)
            probes->sh[(size_t)p * LMB_PROBE_SH + k] = (float)sh[k];
        for (int k = 0; k < LMB_PROBE_CUBE; k++)
            probes->cube[(size_t)p * LMB_PROBE_CUBE + k] = (float)cube[k];
    }
    return LMB_OK;
}
