/* The staged bake's file container (part_file.h), SHA-256 by nettle. */
#define _GNU_SOURCE
#include "part_file.h"

#include "load/gltf_adapter.h"
#include "load/uri.h"
#include "util/file.h"

#include <errno.h>
#include <fcntl.h>
#include <nettle/sha2.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

static const char magic[8] = {'L', 'M', 'B', 'A', 'K', 'E', 1, '\n'};
/* magic, 5 x u32, version, 3 hashes, 2 x u64 */
#define HEADER_BYTES (8 + 5 * 4 + 32 + 3 * 32 + 2 * 8)

void lmb_sha256(const void *data, size_t n, uint8_t out[32])
{
    struct sha256_ctx c;
    sha256_init(&c);
    sha256_update(&c, n, data);
    sha256_digest(&c, 32, out);
}

void lmb_sha256_hex(const void *data, size_t n, char hex[65])
{
    uint8_t d[32];
    lmb_sha256(data, n, d);
    for (int i = 0; i < 32; i++)
        snprintf(hex + 2 * i, 3, "%02x", d[i]);
}

static void hex8(const uint8_t *sha, char out[17])
{
    for (int i = 0; i < 8; i++)
        snprintf(out + 2 * i, 3, "%02x", sha[i]);
}

/* A file by its path relative to folder: the path, then its size and contents; one that
 * cannot be read counts by its path alone (the bake skips it with a warning, and so does every
 * machine that cannot read it). */
static void hash_file(const char *folder, const char *relative, struct sha256_ctx *c)
{
    char path[8300], resolved[4096];
    snprintf(path, sizeof path, "%s/%s", folder, relative);
    sha256_update(c, strlen(relative) + 1, (const uint8_t *)relative);
    char *data = NULL;
    size_t size = 0;
    lmb_error ignored;
    if (lmb_path_inside(folder, path, resolved, sizeof resolved) &&
        lmb_read_file(resolved, "input", &data, &size, &ignored) == LMB_OK) {
        uint64_t n = size;
        sha256_update(c, sizeof n, (const uint8_t *)&n);
        sha256_update(c, size, (const uint8_t *)data);
    }
    free(data);
}

/* The folder of a file path ("." for a bare name). */
static void folder_of(const char *file, char *out, size_t size)
{
    const char *slash = strrchr(file, '/');
    snprintf(out, size, "%.*s", slash ? (int)(slash - file) : 1, slash ? file : ".");
}

/* The image files the glTF references by relative path (textures change a bake too). */
static void hash_image_files(const lmb_scene *scene, struct sha256_ctx *c)
{
    char folder[4096], relative[4096];
    folder_of(scene->path, folder, sizeof folder);
    const lmb_gltf_view *v = lmb_gltf_get_view(scene->doc);
    for (uint32_t k = 0; k < v->image_count; k++)
        if (lmb_uri_check(v->image_uris[k], relative, sizeof relative) == LMB_URI_INSIDE)
            hash_file(folder, relative, c);
}

/* The config's sky.image, read beside the config. */
static void hash_sky_image(const lmb_config *cfg, struct sha256_ctx *c)
{
    char folder[4096];
    if (!cfg->sky_image[0])
        return;
    folder_of(cfg->config_path, folder, sizeof folder);
    hash_file(folder, cfg->sky_image, c);
}

void lmb_part_input_hash(const lmb_scene *scene, const lmb_config *cfg, const void *file, size_t size, uint8_t out[32])
{
    struct sha256_ctx c;
    sha256_init(&c);
    sha256_update(&c, size, (const uint8_t *)file);
    const lmb_gltf_view *v = lmb_gltf_get_view(scene->doc);
    for (uint32_t b = 0; b < v->buffer_count; b++) { /* as loaded: external files and data URIs */
        uint64_t n = v->buffers[b].size;
        sha256_update(&c, sizeof n, (const uint8_t *)&n);
        if (n)
            sha256_update(&c, n, v->buffers[b].data);
    }
    hash_image_files(scene, &c);
    hash_sky_image(cfg, &c);
    sha256_digest(&c, 32, out);
}

lmb_status lmb_part_identity_make(const lmb_scene *scene, const lmb_config *cfg, lmb_part_identity *id,
                                  lmb_error *err)
{
    memset(id, 0, sizeof *id);
    snprintf(id->version, sizeof id->version, "%s", LMB_VERSION_STRING);
    char *file;
    size_t size;
    lmb_status st = lmb_read_file(scene->path, "input", &file, &size, err);
    if (st != LMB_OK)
        return st;
    lmb_part_input_hash(scene, cfg, file, size, id->input);
    free(file);
    struct sha256_ctx c;
    lmb_config bare = *cfg;
    bare.threads = 0;
    size_t n = lmb_config_write(&bare, NULL, 0);
    id->config_text = malloc(n + 1);
    if (!id->config_text)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory");
    lmb_config_write(&bare, id->config_text, n + 1);
    sha256_init(&c);
    sha256_update(&c, n, (const uint8_t *)id->config_text);
    sha256_digest(&c, 32, id->config);
    return LMB_OK;
}

void lmb_part_identity_free(lmb_part_identity *id)
{
    free(id->config_text);
    id->config_text = NULL;
}

static void put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void put_u64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t get_u64(const uint8_t *p)
{
    return (uint64_t)get_u32(p) | (uint64_t)get_u32(p + 4) << 32;
}

lmb_status lmb_part_write(const char *path, const lmb_part_identity *id, const lmb_part_place *place,
                          const void *body, size_t body_length, lmb_error *err)
{
    lmb_part_piece whole = {body, body_length};
    return lmb_part_write_pieces(path, id, place, &whole, 1, err);
}

lmb_status lmb_part_write_pieces(const char *path, const lmb_part_identity *id, const lmb_part_place *place,
                                 const lmb_part_piece *pieces, size_t n, lmb_error *err)
{
    size_t body_length = 0;
    for (size_t i = 0; i < n; i++)
        body_length += pieces[i].size;
    uint8_t h[HEADER_BYTES], *p = h;
    size_t config_length = id->config_text ? strlen(id->config_text) : 0;
    memcpy(p, magic, 8), p += 8;
    put_u32(p, LMB_PART_FORMAT), p += 4;
    put_u32(p, place->kind), p += 4;
    put_u32(p, place->step), p += 4;
    put_u32(p, place->shard), p += 4;
    put_u32(p, place->shards), p += 4;
    memset(p, 0, 32);
    memcpy(p, id->version, strnlen(id->version, 31)), p += 32;
    memcpy(p, id->input, 32), p += 32;
    memcpy(p, id->config, 32), p += 32;
    memcpy(p, id->plan, 32), p += 32;
    put_u64(p, config_length), p += 8;
    put_u64(p, body_length);
    struct sha256_ctx c;
    uint8_t sum[32];
    sha256_init(&c);
    sha256_update(&c, sizeof h, h);
    sha256_update(&c, config_length, (const uint8_t *)id->config_text);
    for (size_t i = 0; i < n; i++)
        sha256_update(&c, pieces[i].size, pieces[i].data);
    sha256_digest(&c, 32, sum);

    char host[256], tmp[4600];
    if (gethostname(host, sizeof host) != 0)
        snprintf(host, sizeof host, "localhost");
    host[sizeof host - 1] = '\0';
    snprintf(tmp, sizeof tmp, "%s.tmp-%s-%ld", path, host, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    if (!f)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "cannot write '%s': %s", tmp, strerror(errno));
    int bad = fwrite(h, 1, sizeof h, f) != sizeof h;
    bad |= config_length && fwrite(id->config_text, 1, config_length, f) != config_length;
    for (size_t i = 0; i < n; i++)
        bad |= pieces[i].size && fwrite(pieces[i].data, 1, pieces[i].size, f) != pieces[i].size;
    bad |= fwrite(sum, 1, 32, f) != 32;
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, path) != 0) {
        lmb_status st = lmb_error_set(err, LMB_ERR_INTERNAL, "cannot write '%s': %s", path, strerror(errno));
        remove(tmp);
        return st;
    }
    return LMB_OK;
}

/* One line of a config text (lmb_config_write): its key (after any indent) and value. */
static void split_line(const char *line, size_t length, const char **key, size_t *key_length, const char **value,
                       size_t *value_length)
{
    size_t indent = strspn(line, " ");
    const char *colon = memchr(line, ':', length);
    *key = line + indent;
    *key_length = colon ? (size_t)(colon - *key) : length - indent;
    *value = colon ? colon + 1 + (colon + 1 < line + length && colon[1] == ' ') : line + length;
    *value_length = (size_t)(line + length - *value);
}

/* The first key whose line differs in two config texts: "config key 'samples.gather' is 512
 * there, 256 here" (a section's keys are named with the section). */
static void config_difference(const char *there, const char *here, char *out, size_t size)
{
    char section[128] = "";
    snprintf(out, size, "the config differs");
    while (*there || *here) {
        size_t a = strcspn(there, "\n"), b = strcspn(here, "\n");
        const char *ka, *va, *kb, *vb;
        size_t kal, val, kbl, vbl;
        split_line(there, a, &ka, &kal, &va, &val);
        split_line(here, b, &kb, &kbl, &vb, &vbl);
        int indented = here[0] == ' ';
        if (a != b || memcmp(there, here, a)) {
            if (kal == kbl && !memcmp(ka, kb, kal))
                snprintf(out, size, "config key '%s%.*s' is %.*s there, %.*s here", indented ? section : "", (int)kbl,
                         kb, (int)val, va, (int)vbl, vb);
            return;
        }
        if (!indented && here[0] != '#' && vbl == 0)
            snprintf(section, sizeof section, "%.*s.", (int)kbl, kb);
        there += a + (there[a] == '\n');
        here += b + (here[b] == '\n');
    }
}

static lmb_status refuse(const char *path, lmb_error *err, const char *what)
{
    return lmb_error_set(err, LMB_ERR_INPUT, "'%s': %s", path, what);
}

/* Checks a whole file's bytes (checksum, identity, place: lmb_part_read's order) and finds its
 * body: *body_offset and *body_length into h. */
static lmb_status check_part(const char *path, const uint8_t *h, size_t size, const lmb_part_identity *expect,
                             const lmb_part_place *want, lmb_part_place *got, size_t *body_offset,
                             size_t *body_length, lmb_error *err)
{
    char why[600];
    if (size < HEADER_BYTES + 32 || memcmp(h, magic, 8)) {
        int ours = size >= 8 && !memcmp(h, magic, 8);
        return refuse(path, err, ours ? "truncated (shorter than its header)" : "not an lmbake plan or part file");
    }
    uint32_t format = get_u32(h + 8);
    uint64_t config_length = get_u64(h + 8 + 20 + 32 + 96), length = get_u64(h + 8 + 20 + 32 + 96 + 8);
    if (format != LMB_PART_FORMAT) {
        snprintf(why, sizeof why, "file format %u; this lmbake reads format %u", format, LMB_PART_FORMAT);
        return refuse(path, err, why);
    }
    if (config_length > size || length > size || HEADER_BYTES + config_length + length + 32 != size)
        return refuse(path, err, "truncated or padded: its length is not what its header says");
    uint8_t sum[32];
    struct sha256_ctx c;
    sha256_init(&c);
    sha256_update(&c, size - 32, h);
    sha256_digest(&c, 32, sum);
    if (memcmp(sum, h + size - 32, 32))
        return refuse(path, err, "damaged: its SHA-256 does not match its contents");
    lmb_part_place place = {get_u32(h + 12), get_u32(h + 16), get_u32(h + 20), get_u32(h + 24)};
    const uint8_t *version = h + 28, *input = h + 60, *config = h + 92, *plan = h + 124;
    const char *config_text = (const char *)h + HEADER_BYTES;
    char a[17], b[17];
    why[0] = '\0';
    if (strncmp((const char *)version, expect->version, 32))
        snprintf(why, sizeof why, "made by lmbake %.32s; this is lmbake %s", (const char *)version, expect->version);
    else if (memcmp(input, expect->input, 32))
        hex8(input, a), hex8(expect->input, b),
            snprintf(why, sizeof why, "made from another input (SHA-256 %s..., the plan's is %s...)", a, b);
    else if (memcmp(config, expect->config, 32)) {
        char *there = strndup(config_text, config_length);
        char diff[400];
        config_difference(there ? there : "", expect->config_text ? expect->config_text : "", diff, sizeof diff);
        free(there);
        snprintf(why, sizeof why, "made with another config: %s", diff);
    } else if (memcmp(plan, expect->plan, 32))
        hex8(plan, a), hex8(expect->plan, b),
            snprintf(why, sizeof why, "belongs to another plan (%s..., this one is %s...)", a, b);
    else if (place.kind != want->kind)
        snprintf(why, sizeof why, "is a %s file, not a %s file",
                 place.kind == LMB_PART_PLAN ? "plan" : place.kind == LMB_PART_SHARD ? "shard" : "state",
                 want->kind == LMB_PART_PLAN ? "plan" : want->kind == LMB_PART_SHARD ? "shard" : "state");
    else if (place.step != want->step)
        snprintf(why, sizeof why, "is of step %u, not step %u", place.step, want->step);
    else if (want->shards && (place.shard != want->shard || place.shards != want->shards))
        snprintf(why, sizeof why, "is shard %u/%u, not %u/%u", place.shard + 1, place.shards, want->shard + 1,
                 want->shards);
    if (why[0])
        return refuse(path, err, why);
    *got = place;
    *body_offset = HEADER_BYTES + (size_t)config_length;
    *body_length = (size_t)length;
    return LMB_OK;
}

lmb_status lmb_part_read(const char *path, const lmb_part_identity *expect, const lmb_part_place *want,
                         lmb_part_place *got, void **body, size_t *body_length, lmb_error *err)
{
    *body = NULL;
    *body_length = 0;
    char *file;
    size_t size, offset, length;
    lmb_status st = lmb_read_file(path, "part", &file, &size, err);
    if (st != LMB_OK)
        return st;
    st = check_part(path, (const uint8_t *)file, size, expect, want, got, &offset, &length, err);
    if (st != LMB_OK) {
        free(file);
        return st;
    }
    *body_length = length;
    memmove(file, file + offset, length);
    *body = file;
    return LMB_OK;
}

lmb_status lmb_part_map(const char *path, const lmb_part_identity *expect, const lmb_part_place *want,
                        lmb_part_place *got, lmb_part_view *view, lmb_error *err)
{
    memset(view, 0, sizeof *view);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return lmb_error_set(err, LMB_ERR_INPUT, "cannot open part '%s': %s", path, strerror(errno));
    struct stat sb;
    if (fstat(fd, &sb) != 0) {
        lmb_status st = lmb_error_set(err, LMB_ERR_INPUT, "cannot read part '%s': %s", path, strerror(errno));
        close(fd);
        return st;
    }
    size_t size = (size_t)sb.st_size;
    if (size < HEADER_BYTES + 32) { /* too short to be a part (and mmap refuses a length of 0): read, refused */
        uint8_t small[HEADER_BYTES + 32];
        ssize_t n = size ? read(fd, small, size) : 0;
        close(fd);
        size_t offset, length;
        return check_part(path, small, n > 0 ? (size_t)n : 0, expect, want, got, &offset, &length, err);
    }
    /* MAP_POPULATE: the page cache's pages mapped in one call, not a fault per page */
    void *map = mmap(NULL, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
    close(fd);
    if (map == MAP_FAILED)
        return lmb_error_set(err, LMB_ERR_INPUT, "cannot map part '%s': %s", path, strerror(errno));
    size_t offset, length;
    lmb_status st = check_part(path, map, size, expect, want, got, &offset, &length, err);
    if (st != LMB_OK) {
        munmap(map, size);
        return st;
    }
    view->map = map;
    view->map_length = size;
    view->body = (const uint8_t *)map + offset;
    view->body_length = length;
    view->sum = (const uint8_t *)map + size - 32;
    return LMB_OK;
}

void lmb_part_unmap(lmb_part_view *view)
{
    if (view->map)
        munmap(view->map, view->map_length);
    memset(view, 0, sizeof *view);
}
