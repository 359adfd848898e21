/*
 * A light group's cache key (group_cache.h, lmb_group_cache_keys): a SHA-256 of what decides the
 * group's light and of nothing else, so that a bake reads back every group an edit leaves as it
 * was. It holds:
 *   - lmbake's version;
 *   - the glTF's JSON with every punctual light taken out (the lights' definitions, each node's
 *     reference to one, and the name, transform and extras of a node that held nothing but a
 *     light), its buffers and image files as the bake reads them, and the sky image for the
 *     group that holds the sky (lmb_part_input_hash); the materials' emission only for a group
 *     that holds the emissive surfaces and is not a unit group (for the others each emissive
 *     factor reads [1, 1, 1] and the strength is left out; a unit group hashes which materials
 *     emit: their emission is its weight);
 *   - the config's text with every group's scale 1; the sky's keys only for the group that holds
 *     the sky, its sky.intensity 1 when that group is a unit group (then it is its weight);
 *     lights.emissive_scale only for the group of the emissive surfaces, 1 in a unit group;
 *   - the group's place and name, whether it holds the sky and the emissive surfaces;
 *   - the lights it holds as the bake reads them: type, mode, world position and direction,
 *     range, cones, and intensity and colour unless the group is a unit group
 *     (lmb_light_groups.unit: they are its weight, applied after).
 * So another group's light or sky edited, a unit group's light dimmed, tinted or switched off,
 * or a unit group's sky dimmed (or tinted, without a ground colour), keeps the key. A JSON cJSON cannot parse (it parsed for the
 * loader) is hashed as it is: no group is read back wrongly, only lit again.
 */
#include "group_cache.h"

#include "steps/part_file.h"
#include "util/file.h"

#include <cJSON.h>
#include <nettle/sha2.h>
#include <stdlib.h>
#include <string.h>

#define GROUP_KEY_FORMAT 5u /* 2: the JSON without punctual lights, the group's own lights; 3: emission;
                                  4: a unit group's kept files hold its light at intensity 1;
                                  5: a unit sky group's at sky.color white */

static uint32_t le32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* The glTF's JSON: a .glb's JSON chunk, else the whole file. */
static void json_of(const char *file, size_t size, const char **json, size_t *len)
{
    const uint8_t *b = (const uint8_t *)file;
    *json = file;
    *len = size;
    if (size >= 20 && !memcmp(b, "glTF", 4) && le32(b + 16) == 0x4E4F534Au && le32(b + 12) <= size - 20) {
        *json = file + 20;
        *len = le32(b + 12);
    }
}

/* Whether every key of obj is one of names. */
static int only_keys(const cJSON *obj, const char *const *names, int count)
{
    for (const cJSON *k = obj ? obj->child : NULL; k; k = k->next) {
        int listed = 0;
        for (int i = 0; i < count && !listed; i++)
            listed = !strcmp(k->string, names[i]);
        if (!listed)
            return 0;
    }
    return 1;
}

/* Each material's emission as [1, 1, 1] where it emits (its factor not black), without its
 * strength: what is left of it when the emission is a weight or not read at all. */
static void emission_left_out(cJSON *root)
{
    const cJSON *materials = cJSON_GetObjectItemCaseSensitive(root, "materials");
    for (cJSON *m = cJSON_IsArray(materials) ? materials->child : NULL; m; m = m->next) {
        cJSON *ext = cJSON_GetObjectItemCaseSensitive(m, "extensions");
        cJSON_DeleteItemFromObjectCaseSensitive(ext, "KHR_materials_emissive_strength");
        if (ext && !ext->child)
            cJSON_DeleteItemFromObjectCaseSensitive(m, "extensions");
        const cJSON *factor = cJSON_GetObjectItemCaseSensitive(m, "emissiveFactor");
        int emits = 0;
        for (const cJSON *v = cJSON_IsArray(factor) ? factor->child : NULL; v; v = v->next)
            emits |= cJSON_IsNumber(v) && v->valuedouble != 0;
        if (emits) {
            const double one[3] = {1, 1, 1};
            cJSON_ReplaceItemInObjectCaseSensitive(m, "emissiveFactor", cJSON_CreateDoubleArray(one, 3));
        }
    }
}

/* The JSON text without its punctual lights, and with emission_left_out when asked (owned,
 * free()); NULL when cJSON cannot parse it. */
static char *without_lights(const char *json, size_t len, int no_emission)
{
    cJSON *root = cJSON_ParseWithLength(json, len);
    if (!root)
        return NULL;
    if (no_emission)
        emission_left_out(root);
    cJSON *ext = cJSON_GetObjectItemCaseSensitive(root, "extensions");
    cJSON_DeleteItemFromObjectCaseSensitive(ext, "KHR_lights_punctual");
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    static const char *const placing[] = {"name", "translation", "rotation", "scale", "matrix", "extras"};
    static const char *const grouping[] = {"lightmap_group"};
    for (cJSON *node = cJSON_IsArray(nodes) ? nodes->child : NULL; node; node = node->next) {
        cJSON *ne = cJSON_GetObjectItemCaseSensitive(node, "extensions");
        if (!cJSON_GetObjectItemCaseSensitive(ne, "KHR_lights_punctual"))
            continue;
        cJSON_DeleteItemFromObjectCaseSensitive(ne, "KHR_lights_punctual");
        if (ne && !ne->child)
            cJSON_DeleteItemFromObjectCaseSensitive(node, "extensions");
        /* a node that held only its light: what placed the light, which the group's own lights
         * carry (their world position and direction) */
        if (only_keys(node, placing, 6) && only_keys(cJSON_GetObjectItemCaseSensitive(node, "extras"), grouping, 1))
            for (int k = 0; k < 6; k++)
                cJSON_DeleteItemFromObjectCaseSensitive(node, placing[k]);
    }
    char *text = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    return text;
}

/* Group g's own lights as the bake reads them (what only_group in group_lighting.c lights), in
 * the scene's order (the order the direct stage samples them in). */
static void hash_group_lights(const lmb_scene *s, const lmb_light_groups *groups, uint32_t g, struct sha256_ctx *c)
{
    for (uint32_t i = 0; i < s->light_count; i++) {
        const lmb_light *l = &s->lights[i];
        if (groups->of_light[i] != (int32_t)g)
            continue;
        uint32_t head[2] = {(uint32_t)l->type, (uint32_t)l->mode}; /* not which light it is: what it does */
        float shape[3] = {l->range, l->inner_cone, l->outer_cone};
        sha256_update(c, sizeof head, (const uint8_t *)head);
        sha256_update(c, sizeof shape, (const uint8_t *)shape);
        sha256_update(c, sizeof l->position, (const uint8_t *)l->position);
        sha256_update(c, sizeof l->direction, (const uint8_t *)l->direction);
        if (!groups->unit[g]) {
            sha256_update(c, sizeof l->intensity, (const uint8_t *)&l->intensity);
            sha256_update(c, sizeof l->color, (const uint8_t *)l->color);
        }
    }
}

/* The config as group g's light reads it: every group's scale 1 (the scales only weigh the sum);
 * the sky's keys as a level without a sky has them unless g holds the sky, and sky.intensity 1
 * (and sky.color white, lmb_sky_color_is_weight) when g is the sky's unit group (they are g's weight). */
static void group_config(const lmb_config *cfg, const lmb_light_groups *groups, uint32_t g, lmb_config *out)
{
    *out = *cfg;
    for (uint32_t k = 0; k < out->light_group_count; k++)
        out->light_groups[k].scale = 1;
    if (groups->sky != (int32_t)g) {
        lmb_config d;
        lmb_config_default(&d);
        out->sky_intensity = d.sky_intensity;
        out->sky_rotation = d.sky_rotation;
        out->sky_cosine_only = d.sky_cosine_only;
        memcpy(out->sky_color, d.sky_color, sizeof d.sky_color);
        memcpy(out->sky_ground, d.sky_ground, sizeof d.sky_ground);
        memcpy(out->sky_up, d.sky_up, sizeof d.sky_up);
        memcpy(out->sky_image, d.sky_image, sizeof d.sky_image);
    } else if (groups->unit[g]) {
        out->sky_intensity = 1;
        for (int c = 0; c < 3 && groups->sky_color_weight; c++)
            out->sky_color[c] = 1;
    }
    if (groups->emissive != (int32_t)g) {
        lmb_config d;
        lmb_config_default(&d);
        out->emissive_scale = d.emissive_scale;
    } else if (groups->unit[g]) {
        out->emissive_scale = 1;
    }
}

lmb_status lmb_group_cache_keys(const lmb_scene *scene, const lmb_config *cfg, const lmb_light_groups *groups,
                                uint8_t (*keys)[32], lmb_error *err)
{
    char *file = NULL, *bare[2] = {NULL, NULL};
    size_t size = 0, len[2] = {0, 0};
    const char *json[2] = {NULL, NULL}; /* [0] the materials' emission as it is, [1] left out */
    lmb_status st = lmb_read_file(scene->path, "input", &file, &size, err);
    for (int k = 0; k < 2 && st == LMB_OK; k++) {
        json_of(file, size, &json[k], &len[k]);
        bare[k] = without_lights(json[k], len[k], k);
        if (bare[k]) { /* else the file as it is (the JSON parsed for the loader, not for cJSON) */
            json[k] = bare[k];
            len[k] = strlen(bare[k]);
        }
    }
    for (uint32_t g = 0; g < groups->count && st == LMB_OK; g++) {
        int emission = groups->emissive == (int32_t)g && !groups->unit[g];
        lmb_config gc;
        group_config(cfg, groups, g, &gc);
        gc.threads = 0; /* as lmb_part_identity_make: the thread count never changes a result */
        size_t n = lmb_config_write(&gc, NULL, 0);
        char *text = malloc(n + 1);
        if (!text) {
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "light groups: out of memory");
            break;
        }
        lmb_config_write(&gc, text, n + 1);
        uint8_t input[32];
        lmb_part_input_hash(scene, &gc, json[!emission], len[!emission], input); /* the sky image: its group's */
        struct sha256_ctx c;
        uint32_t head[4] = {GROUP_KEY_FORMAT, g, groups->sky == (int32_t)g, groups->emissive == (int32_t)g};
        sha256_init(&c);
        sha256_update(&c, sizeof LMB_VERSION_STRING, (const uint8_t *)LMB_VERSION_STRING);
        sha256_update(&c, sizeof input, input);
        sha256_update(&c, n, (const uint8_t *)text);
        sha256_update(&c, sizeof head, (const uint8_t *)head);
        sha256_update(&c, strlen(groups->name[g]) + 1, (const uint8_t *)groups->name[g]);
        hash_group_lights(scene, groups, g, &c);
        for (uint32_t m = 0; groups->emissive == (int32_t)g && groups->unit[g] && m < scene->material_count; m++) {
            uint8_t emits = (uint8_t)lmb_material_is_emissive(&scene->materials[m]);
            sha256_update(&c, 1, &emits);
        }
        sha256_digest(&c, 32, keys[g]);
        free(text);
    }
    free(bare[0]);
    free(bare[1]);
    free(file);
    return st;
}
