/* Layouts kept between bakes (layout_cache.h): the key, and the file in the cache folder. */
#define _GNU_SOURCE
#include "layout_cache.h"

#include "steps/part_file.h"
#include "steps/plan_codec.h"
#include "util/clock.h"
#include "pack/pack.h"
#include "write/output_dir.h"

#include <nettle/sha2.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <utime.h>

/* Top-level config sections the layout never reads (lmb_layout_build and what it calls read
 * texel_density, density_overrides, atlas.*, samples.texel, lightmap.* through the lightmapped
 * choice, probes.*). A section not listed here counts as a layout key. */
static const char *const lighting_only[] = {"samples", "bounces", "bounces_auto", "gather", "denoise",
                                            "irradiance_cache", "farm", "seed", "threads", "output",
                                            "lights", "sky", "materials", "seams"};

static int lighting_only_section(const char *line, size_t len)
{
    for (size_t k = 0; k < sizeof lighting_only / sizeof *lighting_only; k++) {
        size_t n = strlen(lighting_only[k]);
        if (len > n && !strncmp(line, lighting_only[k], n) && line[n] == ':')
            return 1;
    }
    return 0;
}

/* The config's text (lmb_config_write, threads aside) without its lighting-only sections; of
 * `samples`, samples.texel (the gather points per texel) stays: the texel count it makes is
 * checked against memory before the layout. One output choice shapes the layout: a block
 * format packs charts on its block grid (lmb_pack_block_for); a line says so. */
static char *layout_config_text(const lmb_config *cfg)
{
    lmb_config bare = *cfg;
    bare.threads = 0;
    size_t n = lmb_config_write(&bare, NULL, 0);
    char *full = malloc(n + 1), *out = malloc(n + 1);
    if (!full || !out) {
        free(full);
        free(out);
        return NULL;
    }
    lmb_config_write(&bare, full, n + 1);
    size_t o = 0;
    int skipping = 0, in_samples = 0;
    for (const char *line = full; *line;) {
        const char *end = strchr(line, '\n');
        size_t len = end ? (size_t)(end - line) + 1 : strlen(line);
        if (line[0] != ' ' && line[0] != '#') { /* a top-level key */
            skipping = lighting_only_section(line, len);
            in_samples = !strncmp(line, "samples:", 8);
        }
        int keep = !skipping || (in_samples && (!strncmp(line, "samples:", 8) || !strncmp(line, "  texel:", 8)));
        if (keep) {
            memcpy(out + o, line, len);
            o += len;
        }
        line += len;
    }
    out[o] = '\0';
    free(full);
    if (lmb_pack_block_for(cfg) > 1) {
        char line[64];
        int k = snprintf(line, sizeof line, "# atlas blocks: %u\n", lmb_pack_block_for(cfg));
        char *grown = realloc(out, o + (size_t)k + 1);
        if (!grown) {
            free(out);
            return NULL;
        }
        memcpy(grown + o, line, (size_t)k + 1);
        out = grown;
    }
    return out;
}

static void hash_bytes(struct sha256_ctx *c, const void *data, size_t n)
{
    uint64_t size = data ? n : UINT64_MAX; /* an absent array differs from an empty one */
    sha256_update(c, sizeof size, (const uint8_t *)&size);
    if (data && n)
        sha256_update(c, n, data);
}

static void hash_string(struct sha256_ctx *c, const char *s)
{
    hash_bytes(c, s, s ? strlen(s) : 0);
}

/* What the layout reads of the scene: not its lights, materials or textures. */
static void hash_scene_geometry(const lmb_scene *s, struct sha256_ctx *c)
{
    uint32_t counts[6] = {s->mesh_count, s->primitive_count, s->instance_count, s->probe_volume_count, s->node_count,
                          s->gpu_instanced_nodes};
    sha256_update(c, sizeof counts, (const uint8_t *)counts);
    for (uint32_t i = 0; i < s->primitive_count; i++) {
        const lmb_primitive *p = &s->primitives[i];
        int32_t head[6] = {(int32_t)p->gltf_mesh, (int32_t)p->gltf_primitive, p->material, (int32_t)p->vertex_count,
                           (int32_t)p->triangle_count, (int32_t)p->degenerate_count};
        sha256_update(c, sizeof head, (const uint8_t *)head);
        size_t v = p->vertex_count, t = p->triangle_count;
        hash_bytes(c, p->positions, 3 * v * sizeof(float));
        hash_bytes(c, p->normals, 3 * v * sizeof(float));
        hash_bytes(c, p->uv0, 2 * v * sizeof(float));
        hash_bytes(c, p->uv1, 2 * v * sizeof(float));
        hash_bytes(c, p->indices, 3 * t * sizeof(uint32_t));
        hash_bytes(c, p->degenerate, t);
    }
    for (uint32_t m = 0; m < s->mesh_count; m++) {
        const lmb_mesh *mesh = &s->meshes[m];
        hash_string(c, mesh->name);
        uint32_t v[6] = {mesh->first_primitive, mesh->primitive_count, mesh->triangle_count, mesh->degenerate_count,
                         mesh->skipped_primitives, mesh->skipped_triangles};
        sha256_update(c, sizeof v, (const uint8_t *)v);
    }
    for (uint32_t i = 0; i < s->instance_count; i++) {
        const lmb_instance *in = &s->instances[i];
        hash_string(c, in->name);
        hash_string(c, in->skip_reason);
        int32_t v[6] = {(int32_t)in->node, in->gpu_instance, (int32_t)in->mesh, in->flips_winding, in->lightmapped,
                        in->extras_lightmap};
        sha256_update(c, sizeof v, (const uint8_t *)v);
        sha256_update(c, sizeof in->world, (const uint8_t *)in->world);
    }
    for (uint32_t k = 0; k < s->probe_volume_count; k++) {
        const lmb_node_probe_volume *pv = &s->probe_volumes[k];
        hash_string(c, pv->name);
        sha256_update(c, sizeof pv->node, (const uint8_t *)&pv->node);
        sha256_update(c, sizeof pv->world, (const uint8_t *)pv->world);
        sha256_update(c, sizeof pv->resolution, (const uint8_t *)pv->resolution);
    }
}

lmb_status lmb_layout_key(const lmb_scene *scene, const lmb_config *cfg, uint8_t scene_hash[32], char **config_text,
                          lmb_error *err)
{
    struct sha256_ctx c;
    sha256_init(&c);
    hash_scene_geometry(scene, &c);
    sha256_digest(&c, 32, scene_hash);
    *config_text = layout_config_text(cfg);
    if (!*config_text)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "layout cache: out of memory");
    return LMB_OK;
}

/* The identity the cache's files carry: the version, the scene's layout hash as `input`, the
 * layout config text; and the file's name in dir from both. */
static lmb_status cache_identity(const lmb_scene *scene, const lmb_config *cfg, const char *dir,
                                 lmb_part_identity *id, char *path, size_t size, lmb_error *err)
{
    memset(id, 0, sizeof *id);
    snprintf(id->version, sizeof id->version, "%s", LMB_VERSION_STRING);
    lmb_status st = lmb_layout_key(scene, cfg, id->input, &id->config_text, err);
    if (st != LMB_OK)
        return st;
    lmb_sha256(id->config_text, strlen(id->config_text), id->config);
    uint8_t both[64 + 32], key[32];
    memcpy(both, id->input, 32);
    memcpy(both + 32, id->config, 32);
    memset(both + 64, 0, 32);
    memcpy(both + 64, id->version, strnlen(id->version, 31));
    lmb_sha256(both, sizeof both, key);
    char hex[33];
    for (int i = 0; i < 16; i++)
        snprintf(hex + 2 * i, 3, "%02x", key[i]);
    snprintf(path, size, "%s/layout-%s.lmbp", dir, hex);
    return LMB_OK;
}

lmb_status lmb_layout_cache_path(const lmb_scene *scene, const lmb_config *cfg, const char *dir, char *path, size_t size,
                                 lmb_error *err)
{
    lmb_part_identity id;
    lmb_status st = cache_identity(scene, cfg, dir, &id, path, size, err);
    lmb_part_identity_free(&id);
    return st;
}

/* The layout in path, when it is there and whole; 0 otherwise (a damaged file is said). */
static int read_back(const char *path, const lmb_part_identity *id, const lmb_scene *scene, const lmb_log *log,
                     lmb_layout *l)
{
    struct stat sb;
    if (stat(path, &sb) != 0)
        return 0;
    lmb_part_place want = {LMB_PART_PLAN, 0, 0, 1}, got;
    void *body = NULL;
    size_t size = 0;
    lmb_error e = {LMB_OK, ""};
    lmb_status st = lmb_part_read(path, id, &want, &got, &body, &size, &e);
    if (st == LMB_OK)
        st = lmb_plan_decode(path, body, size, scene, l, &e);
    free(body);
    if (st != LMB_OK) {
        lmb_layout_free(l);
        memset(l, 0, sizeof *l);
        lmb_warn(log, "layout cache: %s; building the layout instead", e.message);
        return 0;
    }
    utime(path, NULL); /* the watch keeps the layouts used last */
    return 1;
}

lmb_status lmb_layout_cached(const lmb_scene *scene, const lmb_config *cfg, const char *dir, lmb_progress_fn progress,
                             void *user, const lmb_log *log, lmb_layout *l, int *reused, lmb_error *err)
{
    *reused = 0;
    memset(l, 0, sizeof *l);
    lmb_part_identity id;
    char path[4200];
    double t0 = lmb_seconds();
    lmb_status st = cache_identity(scene, cfg, dir, &id, path, sizeof path, err);
    if (st == LMB_OK && read_back(path, &id, scene, log, l)) {
        *reused = 1;
        lmb_info(log, "layout: read back from %s in %.2f s (the geometry and the layout's config keys are those of "
                 "an earlier bake)", path, lmb_seconds() - t0);
        lmb_part_identity_free(&id);
        return LMB_OK;
    }
    if (st == LMB_OK)
        st = lmb_layout_build(scene, cfg, progress, user, log, l, err);
    uint8_t *body = NULL;
    size_t size = 0;
    lmb_error e = {LMB_OK, ""};
    lmb_part_place place = {LMB_PART_PLAN, 0, 0, 1};
    if (st == LMB_OK) {
        int made = 0;
        lmb_status kept = lmb_make_folders(dir, &made, &e);
        if (kept == LMB_OK)
            kept = lmb_plan_encode(l, &body, &size, &e);
        if (kept == LMB_OK)
            kept = lmb_part_write(path, &id, &place, body, size, &e);
        if (kept == LMB_OK)
            lmb_info(log, "layout: built in %.2f s and kept in %s for the next bake", lmb_seconds() - t0, path);
        else
            lmb_warn(log, "layout cache: %s; the next bake lays the level out again", e.message);
    }
    free(body);
    lmb_part_identity_free(&id);
    return st;
}
