/* Which group each light source is in (see light_groups.h). */
#include "light_groups.h"

#include "util/lmb_math.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int32_t find_group(const lmb_light_groups *g, const char *name)
{
    for (uint32_t k = 0; k < g->count; k++)
        if (!strcmp(g->name[k], name))
            return (int32_t)k;
    return -1;
}

/* The group named `name`, added (scale 1) when there is none yet; -1 when the groups are full. */
static int32_t group_named(lmb_light_groups *g, const char *name)
{
    int32_t k = find_group(g, name);
    if (k >= 0 || g->count >= LMB_MAX_LIGHT_GROUPS)
        return k;
    snprintf(g->name[g->count], sizeof g->name[g->count], "%s", name);
    g->scale[g->count] = 1.0;
    return (int32_t)g->count++;
}

void lmb_light_groups_free(lmb_light_groups *g)
{
    free(g->of_light);
    free(g->merged);
    memset(g, 0, sizeof *g);
}

/* Whether every emissive surface the bake places emits one radiance le (emissiveFactor x strength
 * x lights.emissive_scale, as lmb_emitters_build computes it), and their textures cannot tell a
 * tint from a new power: no emissive texture, or one emissive material alone. Then the emitters'
 * power CDF is the same at any le, and an emission lit at 1 and weighed by le is exact. */
static int shared_emission(const lmb_scene *s, double scale, float le[3])
{
    int32_t first = -1, textured = 0, same = 1;
    for (uint32_t i = 0; i < s->instance_count; i++) {
        const lmb_mesh *m = &s->meshes[s->instances[i].mesh];
        for (uint32_t p = 0; p < m->primitive_count; p++) {
            int32_t k = s->primitives[m->first_primitive + p].material;
            if (k < 0 || !lmb_material_is_emissive(&s->materials[k]))
                continue;
            const lmb_material *mat = &s->materials[k];
            float e[3];
            for (int c = 0; c < 3; c++)
                e[c] = (float)(mat->emissive[c] * scale);
            textured |= mat->emissive_texture.texture >= 0;
            if (first < 0) {
                first = k;
                memcpy(le, e, sizeof e);
            } else if (k != first) {
                same &= !memcmp(le, e, sizeof e);
                same &= !textured;
            }
        }
    }
    return first >= 0 && same;
}

/* The order in which one_per_light's sources get a group of their own when not all can: a
 * directional light first (it lights the whole level), brighter before dimmer by the luminance of
 * its intensity x colour; then the sky (it too lights the whole level; its power is not known
 * before a bake); then the local lights and the emissive surfaces by their power: a light's
 * luminance x intensity x the solid angle it shines into (4 pi; a spot 2 pi (1 - cos of its
 * cone's middle angle), as pbrt-v4's SpotLight::Phi), the surfaces' pi x sum of area x luminance
 * of their emission (lmb_emitters_power); equal ones in the file's order, the sky and the
 * surfaces after the lights. A share of the level's light without a bake: a local light's power
 * all lands on the level, a directional light's on all of it. */
enum { RANK_DIRECTIONAL, RANK_SKY, RANK_LOCAL };
typedef struct ranked_light {
    uint32_t light; /* the scene light, or light_count: the sky, light_count + 1: the emissive surfaces */
    int rank;
    double power;
} ranked_light;

static int rank_order(const void *pa, const void *pb)
{
    const ranked_light *a = pa, *b = pb;
    if (a->rank != b->rank)
        return a->rank < b->rank ? -1 : 1;
    if (a->power != b->power)
        return a->power > b->power ? -1 : 1;
    return a->light < b->light ? -1 : a->light > b->light;
}

static ranked_light rank_of(const lmb_light *l, uint32_t i)
{
    double lum = 0.2126 * l->color[0] + 0.7152 * l->color[1] + 0.0722 * l->color[2];
    double solid = 4 * LMB_PI;
    if (l->type == LMB_LIGHT_SPOT)
        solid = 2 * LMB_PI * (1 - cos(0.5 * ((double)l->inner_cone + (double)l->outer_cone)));
    int directional = l->type == LMB_LIGHT_DIRECTIONAL;
    return (ranked_light){i, directional ? RANK_DIRECTIONAL : RANK_LOCAL,
                          lum * (double)l->intensity * (directional ? 1.0 : solid)};
}

/* A group named base (each character a group's name cannot hold as '_'; `fallback` when nothing
 * is left; "-2", "-3", ... when taken, and never "rest"), at the given scale. */
static int32_t group_of_own(lmb_light_groups *g, const char *from, const char *fallback, double scale)
{
    char base[LMB_PATTERN_LEN - 8], name[LMB_PATTERN_LEN];
    size_t n = 0;
    for (; from[n] && n + 1 < sizeof base; n++) {
        char ch = from[n];
        int ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '-';
        base[n] = ok ? ch : '_';
    }
    base[n] = 0;
    if (!n)
        snprintf(base, sizeof base, "%s", fallback);
    snprintf(name, sizeof name, "%s", base);
    for (uint32_t k = 2; find_group(g, name) >= 0 || !strcmp(name, "rest"); k++)
        snprintf(name, sizeof name, "%s-%u", base, k);
    int32_t k = group_named(g, name);
    if (k >= 0)
        g->scale[k] = scale;
    return k;
}

/* A group for light i alone, named after it (its name, else its node's). */
static int32_t group_of_light(lmb_light_groups *g, const lmb_light *l, uint32_t i, double scale)
{
    char fallback[32];
    snprintf(fallback, sizeof fallback, "light-%u", i);
    const char *from = l->name && l->name[0] ? l->name : l->node_name && l->node_name[0] ? l->node_name : "";
    return group_of_own(g, from, fallback, scale);
}

lmb_status lmb_light_groups_resolve(const lmb_scene *s, const lmb_config *cfg, int has_sky, double emissive_power,
                                    lmb_light_groups *out, lmb_error *err)
{
    int has_emissive = emissive_power > 0;
    memset(out, 0, sizeof *out);
    out->sky = out->emissive = -1;
    int any_extra = 0;
    for (uint32_t i = 0; i < s->light_count; i++)
        any_extra |= s->lights[i].group && s->lights[i].group[0] && s->lights[i].mode != LMB_LIGHT_REALTIME;
    if (!cfg->light_group_count && !any_extra)
        return LMB_OK;
    const char *where = cfg->config_path[0] ? cfg->config_path : "the config";
    if (cfg->shadowmask)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: output.light_groups and output.shadowmask: a bake holds one or "
                             "the other (light groups with shadowmasks are not built yet)", where);
    out->of_light = malloc(((size_t)s->light_count + 1) * sizeof *out->of_light);
    out->merged = calloc((size_t)s->light_count + 1, 1);
    int32_t *entry_of = malloc(((size_t)s->light_count + 1) * sizeof *entry_of); /* one_per_light's entry, or -1 */
    ranked_light *ranked = malloc(((size_t)s->light_count + 2) * sizeof *ranked);
    if (!out->of_light || !out->merged || !entry_of || !ranked) {
        free(entry_of);
        free(ranked);
        lmb_light_groups_free(out);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: out of memory");
    }
    int32_t of_entry[LMB_MAX_LIGHT_GROUPS]; /* config entry j's group (-1: one_per_light) */
    for (uint32_t j = 0; j < cfg->light_group_count; j++) {
        of_entry[j] = -1;
        if (cfg->light_groups[j].one_per_light)
            continue;
        snprintf(out->name[out->count], sizeof out->name[out->count], "%s", cfg->light_groups[j].name);
        out->scale[out->count] = cfg->light_groups[j].scale;
        of_entry[j] = (int32_t)out->count++;
    }
    uint32_t pending = 0; /* lights of one_per_light entries */
    for (uint32_t i = 0; i < s->light_count; i++) {
        const lmb_light *l = &s->lights[i];
        out->of_light[i] = -1;
        entry_of[i] = -1;
        if (l->mode == LMB_LIGHT_REALTIME)
            continue;
        int32_t k = -1;
        if (l->group && l->group[0]) {
            k = group_named(out, l->group);
            if (k < 0) {
                free(entry_of);
                free(ranked);
                lmb_light_groups_free(out);
                return lmb_error_set(err, LMB_ERR_INPUT, "%s: light '%s' (node '%s'): extras.lightmap_group '%s' would "
                                     "make more than %d light groups (output.light_groups holds at most %d)", s->path,
                                     l->name, l->node_name, l->group, LMB_MAX_LIGHT_GROUPS, LMB_MAX_LIGHT_GROUPS);
            }
        }
        for (uint32_t j = 0; k < 0 && entry_of[i] < 0 && j < cfg->light_group_count; j++) {
            const lmb_light_group_spec *e = &cfg->light_groups[j];
            const char *p = e->pattern[0] ? e->pattern : e->one_per_light ? "*" : "";
            if (!p[0] || !(lmb_glob_match(p, l->name) || lmb_glob_match(p, l->node_name)))
                continue;
            if (e->one_per_light)
                entry_of[i] = (int32_t)j;
            else
                k = of_entry[j];
        }
        if (entry_of[i] >= 0)
            ranked[pending++] = rank_of(l, i);
        out->of_light[i] = k; /* -1: the rest's or its own, below */
    }
    for (uint32_t j = 0; j < cfg->light_group_count; j++) {
        if (has_sky && out->sky < 0 && cfg->light_groups[j].sky)
            out->sky = of_entry[j];
        if (has_emissive && out->emissive < 0 && cfg->light_groups[j].emissive)
            out->emissive = of_entry[j];
    }
    /* one_per_light for every light (no match) gives the sky and the emissive surfaces their own
     * groups too, when no entry claims them */
    int32_t every = -1; /* that entry */
    for (uint32_t j = 0; j < cfg->light_group_count && every < 0; j++)
        if (cfg->light_groups[j].one_per_light && !cfg->light_groups[j].pattern[0])
            every = (int32_t)j;
    int sky_own = every >= 0 && has_sky && out->sky < 0, emissive_own = every >= 0 && has_emissive && out->emissive < 0;
    if (sky_own)
        ranked[pending++] = (ranked_light){s->light_count, RANK_SKY, 0};
    if (emissive_own)
        ranked[pending++] = (ranked_light){s->light_count + 1, RANK_LOCAL, emissive_power};
    /* a group per source while the groups last; when they do not all fit with the rest's, the
     * last group is `rest` and the sources that rank lowest share it */
    int others = (has_sky && out->sky < 0 && !sky_own) || (has_emissive && out->emissive < 0 && !emissive_own);
    for (uint32_t i = 0; i < s->light_count; i++)
        others |= s->lights[i].mode != LMB_LIGHT_REALTIME && out->of_light[i] < 0 && entry_of[i] < 0;
    uint32_t room = LMB_MAX_LIGHT_GROUPS - out->count, own = pending;
    if (pending + (uint32_t)others > room)
        own = room > 0 ? room - 1 : 0;
    qsort(ranked, pending, sizeof *ranked, rank_order);
    for (uint32_t r = own; r < pending; r++) {
        if (ranked[r].light < s->light_count)
            out->merged[ranked[r].light] = 1;
        else if (ranked[r].light == s->light_count)
            sky_own = 0, out->sky_merged = 1;
        else
            emissive_own = 0, out->emissive_merged = 1;
    }
    for (uint32_t i = 0; i < s->light_count; i++) /* their groups in the file's order, then the sky's, the surfaces' */
        if (entry_of[i] >= 0 && !out->merged[i])
            out->of_light[i] = group_of_light(out, &s->lights[i], i, cfg->light_groups[entry_of[i]].scale);
    if (sky_own)
        out->sky = group_of_own(out, "sky", "sky", cfg->light_groups[every].scale);
    if (emissive_own)
        out->emissive = group_of_own(out, "emissive", "emissive", cfg->light_groups[every].scale);
    free(ranked);
    /* what no group claims: the group "rest" */
    int unclaimed = (has_sky && out->sky < 0) || (has_emissive && out->emissive < 0);
    for (uint32_t i = 0; i < s->light_count; i++)
        unclaimed |= s->lights[i].mode != LMB_LIGHT_REALTIME && out->of_light[i] < 0;
    int32_t rest = unclaimed ? group_named(out, "rest") : -1;
    if (unclaimed && rest < 0) {
        free(entry_of);
        lmb_light_groups_free(out);
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %d light groups hold some of the level's light and the rest needs "
                             "one more (at most %d): name a group for every light, or give one sky: true / emissive: "
                             "true", where, LMB_MAX_LIGHT_GROUPS, LMB_MAX_LIGHT_GROUPS);
    }
    if (has_sky && out->sky < 0)
        out->sky = rest;
    if (has_emissive && out->emissive < 0)
        out->emissive = rest;
    for (uint32_t i = 0; i < s->light_count; i++) {
        if (s->lights[i].mode != LMB_LIGHT_REALTIME && out->of_light[i] < 0)
            out->of_light[i] = rest;
        if (out->of_light[i] >= 0)
            out->lights[out->of_light[i]]++;
    }
    /* a config group that holds nothing is a mistake (a typo in match, a renamed light) */
    for (uint32_t j = 0; j < cfg->light_group_count; j++) {
        int32_t k = of_entry[j];
        int matched = 0;
        for (uint32_t i = 0; k < 0 && i < s->light_count; i++)
            matched |= entry_of[i] == (int32_t)j;
        matched |= (int32_t)j == every && (sky_own || emissive_own || out->sky_merged || out->emissive_merged);
        if (k < 0 && !matched) {
            const lmb_light_group_spec *g = &cfg->light_groups[j];
            lmb_error_set(err, LMB_ERR_INPUT, "%s:%u: output.light_groups (one_per_light) holds no light: no light's "
                          "name or node name matches '%s' (%s)", where, g->line, g->pattern[0] ? g->pattern : "*",
                          s->path);
            free(entry_of);
            lmb_light_groups_free(out);
            return LMB_ERR_INPUT;
        }
        if (k >= 0 && !out->lights[k] && out->sky != k && out->emissive != k) {
            const lmb_light_group_spec *g = &cfg->light_groups[j];
            char what[512];
            snprintf(what, sizeof what, "%s%s%s%s%s", g->pattern[0] ? "no light's name or node name matches '" : "",
                     g->pattern, g->pattern[0] ? "'" : "no match", g->sky && !has_sky ? ", the level has no sky" : "",
                     g->emissive && !has_emissive ? ", nothing in it emits" : "");
            lmb_error_set(err, LMB_ERR_INPUT, "%s:%u: output.light_groups '%s' holds no light: %s, and no light's "
                          "extras.lightmap_group names it (%s)", where, g->line, g->name, what, s->path);
            free(entry_of);
            lmb_light_groups_free(out);
            return LMB_ERR_INPUT;
        }
    }
    free(entry_of);
    /* unit groups: one light alone; the config's sky alone (sky.intensity its weight: a sky
     * from the file's image-based light is lit as it is); the emissive surfaces alone, when
     * they share one emission (its weight, per channel) */
    float le[3] = {1, 1, 1};
    int one_emission = has_emissive && shared_emission(s, cfg->emissive_scale, le);
    for (uint32_t k = 0; k < out->count; k++) {
        int sky_alone = out->sky == (int32_t)k && !out->lights[k] && out->emissive != (int32_t)k &&
                        cfg->sky_intensity > 0;
        int emission_alone = out->emissive == (int32_t)k && !out->lights[k] && out->sky != (int32_t)k && one_emission;
        if (sky_alone)
            out->sky_color_weight = lmb_sky_color_is_weight(cfg);
        out->unit[k] = sky_alone || emission_alone ||
                       (out->lights[k] == 1 && out->sky != (int32_t)k && out->emissive != (int32_t)k);
        for (int c = 0; c < 3; c++)
            out->weight[k][c] = sky_alone      ? cfg->sky_intensity * (out->sky_color_weight ? cfg->sky_color[c] : 1.0)
                                : emission_alone ? (double)le[c]
                                                 : 1.0;
        for (uint32_t i = 0; out->unit[k] && i < s->light_count; i++)
            if (out->of_light[i] == (int32_t)k)
                for (int c = 0; c < 3; c++)
                    out->weight[k][c] = (double)s->lights[i].intensity * (double)s->lights[i].color[c];
    }
    return LMB_OK;
}

int lmb_sky_color_is_weight(const lmb_config *cfg)
{
    return !(cfg->sky_ground[0] >= 0);
}

/* One line per group: what it holds, its scale, and a unit group's weight (the watch reads the
 * lines to say which group an edit relit, and by how much: tools/preview/watch.mjs). */
void lmb_light_groups_report(const lmb_light_groups *g, const lmb_scene *s, const lmb_log *log)
{
    for (uint32_t k = 0; k < g->count; k++) {
        char first[160] = "", weight[160] = "";
        for (uint32_t i = 0; i < s->light_count && !first[0]; i++)
            if (g->of_light[i] == (int32_t)k)
                snprintf(first, sizeof first, " ('%s'%s)", s->lights[i].name, g->lights[k] > 1 ? ", ..." : "");
        if (g->unit[k])
            snprintf(weight, sizeof weight, " (lit at unit %s, weighed by %s: [%g, %g, %g])",
                     g->emissive == (int32_t)k ? "emission" : "intensity",
                     g->sky == (int32_t)k        ? (g->sky_color_weight ? "sky.intensity x sky.color" : "sky.intensity")
                     : g->emissive == (int32_t)k ? "the surfaces' emissive colour x strength"
                                                 : "the light's intensity x colour",
                     g->weight[k][0], g->weight[k][1], g->weight[k][2]);
        lmb_info(log, "light group '%s': %u light(s)%s%s%s, scale %g%s", g->name[k], g->lights[k], first,
                 g->sky == (int32_t)k ? ", the sky" : "", g->emissive == (int32_t)k ? ", the emissive surfaces" : "",
                 g->scale[k], weight);
    }
    uint32_t merged = 0;
    char names[400] = "", who[160] = "";
    for (uint32_t i = 0; g->merged && i < s->light_count; i++)
        if (g->merged[i] && merged++ < 6) {
            size_t n = strlen(names);
            snprintf(names + n, sizeof names - n, "%s'%s'", n ? ", " : "", s->lights[i].name);
        }
    /* "4 light(s)", "5 light(s) and the emissive surfaces", "the sky and the emissive surfaces" */
    if (merged)
        snprintf(who, sizeof who, "%u light(s)", merged);
    const char *others[2] = {g->sky_merged ? "the sky" : NULL, g->emissive_merged ? "the emissive surfaces" : NULL};
    for (int k = 0; k < 2; k++)
        if (others[k]) {
            size_t n = strlen(who);
            snprintf(who + n, sizeof who - n, "%s%s", n ? " and " : "", others[k]);
        }
    if (who[0])
        lmb_info(log, "light groups: one_per_light: %s share 'rest'%s%s%s%s: at most %d groups, and they rank lowest (a "
                 "directional light first, then the sky, then by power: docs/light-groups.md)", who, merged ? " (" : "",
                 names, merged > 6 ? ", ..." : "", merged ? ")" : "", LMB_MAX_LIGHT_GROUPS);
}
