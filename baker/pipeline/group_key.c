/*
 * A light group's cache key (group_cache.h, lmb_group_cache_keys): a SHA-256 of what decides the
 * group's light and of nothing else, so that a bake reads back every group an edit leaves as it
 * was. It holds lmbake's version; the glTF's JSON with every punctual light taken out (the
 * lights' definitions, each node's reference to one, and the name, transform and extras of a
 * node that held nothing but a light); the buffers, image files and sky image as the bake reads
 * them (lmb_part_input_hash); the config's text with every group's scale 1; the group's place
 * and name; and the lights the group holds as the bake reads them: type, mode, world position
 * and direction, range, cones, and intensity and colour unless the group is lit at unit
 * intensity (lmb_light_groups.unit: they are its weight, applied after). Another group's light
 * edited, moved or switched off, or a unit group's light dimmed or tinted, keeps the key. A JSON
 * cJSON cannot parse (it parsed for the loader) is hashed as it is: no group is read back
 * wrongly, only lit again.
 */
#include "group_cache.h"

#include "steps/part_file.h"
#include "util/file.h"

#include <cJSON.h>
#include <nettle/sha2.h>
#include <stdlib.h>
#include <string.h>

#define GROUP_KEY_FORMAT 2u /* 2: the JSON without punctual lights, the group's own lights */

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

/* The JSON text without its punctual lights (owned, free()); NULL when cJSON cannot parse it. */
static char *without_lights(const char *json, size_t len)
{
    cJSON *root = cJSON_ParseWithLength(json, len);
    if (!root)
        return NULL;
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

lmb_status lmb_group_cache_keys(const lmb_scene *scene, const lmb_config *cfg, const lmb_light_groups *groups,
                                uint8_t (*keys)[32], lmb_error *err)
{
    lmb_config bare = *cfg; /* the scales only weigh the groups' sum: no group's light reads them */
    for (uint32_t k = 0; k < bare.light_group_count; k++)
        bare.light_groups[k].scale = 1;
    lmb_part_identity id;
    lmb_status st = lmb_part_identity_make(scene, &bare, &id, err);
    char *file = NULL;
    size_t size = 0;
    if (st == LMB_OK)
        st = lmb_read_file(scene->path, "input", &file, &size, err);
    if (st != LMB_OK) {
        lmb_part_identity_free(&id);
        return st;
    }
    const char *json;
    size_t len;
    json_of(file, size, &json, &len);
    char *bare_json = without_lights(json, len);
    uint8_t input[32];
    if (bare_json)
        lmb_part_input_hash(scene, &bare, bare_json, strlen(bare_json), input);
    else
        memcpy(input, id.input, sizeof input);
    free(bare_json);
    free(file);
    for (uint32_t g = 0; g < groups->count; g++) {
        struct sha256_ctx c;
        uint32_t head[2] = {GROUP_KEY_FORMAT, g};
        sha256_init(&c);
        sha256_update(&c, sizeof id.version, (const uint8_t *)id.version);
        sha256_update(&c, sizeof input, input);
        sha256_update(&c, sizeof id.config, id.config);
        sha256_update(&c, sizeof head, (const uint8_t *)head);
        sha256_update(&c, strlen(groups->name[g]) + 1, (const uint8_t *)groups->name[g]);
        hash_group_lights(scene, groups, g, &c);
        sha256_digest(&c, 32, keys[g]);
    }
    lmb_part_identity_free(&id);
    return LMB_OK;
}
