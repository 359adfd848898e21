/* Light groups' light kept between bakes (see group_cache.h). */
#define _POSIX_C_SOURCE 200809L /* strnlen */
#include "group_cache.h"

#include "steps/part_file.h"
#include "write/output_dir.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <utime.h>

#define GROUP_CACHE_FORMAT 1u

static void cache_path(const char *dir, const uint8_t key[32], char *path, size_t size)
{
    char hex[33];
    for (int i = 0; i < 16; i++)
        snprintf(hex + 2 * i, 3, "%02x", key[i]);
    snprintf(path, size, "%s/group-%s.lmbg", dir, hex);
}

/* The group's own files of atlas a: DIR/group-KEY-aA.lmbf beside its light. */
static void files_path(const char *dir, const uint8_t key[32], uint32_t a, char *path, size_t size)
{
    char hex[33];
    for (int i = 0; i < 16; i++)
        snprintf(hex + 2 * i, 3, "%02x", key[i]);
    snprintf(path, size, "%s/group-%s-a%u.lmbf", dir, hex, a);
}

/* The identity the files carry: their key (the part file's checks then name a mismatch). */
static void cache_identity(const uint8_t key[32], lmb_part_identity *id)
{
    memset(id, 0, sizeof *id);
    snprintf(id->version, sizeof id->version, "%s", LMB_VERSION_STRING);
    memcpy(id->input, key, 32);
    memcpy(id->config, key, 32);
    id->config_text = (char *)"light group";
}

/* The body: a header, then per atlas its states, light and directions, the probes' light and the
 * records. */
typedef struct body_header {
    uint32_t format, atlases, has_direction, probes, records, pad;
    uint64_t texels, valid_texels;
} body_header;

void lmb_group_cache_write(const char *dir, const uint8_t key[32], uint32_t g, const lmb_group_light *gl,
                           const lmb_cache *cache, uint32_t probes, uint64_t texels, uint64_t valid_texels,
                           const lmb_log *log)
{
    uint32_t n = cache->atlas_count, records = gl->records ? gl->records[g].count : 0;
    body_header h = {GROUP_CACHE_FORMAT, n, gl->direction != NULL, gl->sh && gl->sh[g] ? probes : 0, records, 0,
                     texels, valid_texels};
    size_t count = 0;
    lmb_part_piece *pieces = calloc(3 * (size_t)n + 4, sizeof *pieces);
    if (!pieces)
        return;
    pieces[count++] = (lmb_part_piece){&h, sizeof h};
    for (uint32_t a = 0; a < n; a++) {
        size_t texels_a = (size_t)cache->layout->width[a] * cache->layout->height[a];
        pieces[count++] = (lmb_part_piece){cache->state[a], texels_a};
        pieces[count++] = (lmb_part_piece){gl->irradiance[(size_t)g * n + a], 3 * texels_a * sizeof(float)};
        if (gl->direction)
            pieces[count++] = (lmb_part_piece){gl->direction[(size_t)g * n + a], 3 * texels_a * sizeof(float)};
    }
    if (h.probes) {
        pieces[count++] = (lmb_part_piece){gl->sh[g], (size_t)probes * LMB_PROBE_SH * sizeof(float)};
        pieces[count++] = (lmb_part_piece){gl->cube[g], (size_t)probes * LMB_PROBE_CUBE * sizeof(float)};
    }
    if (records)
        pieces[count++] = (lmb_part_piece){gl->records[g].xyzr, 4 * (size_t)records * sizeof(float)};
    char path[4200];
    cache_path(dir, key, path, sizeof path);
    lmb_part_identity id;
    cache_identity(key, &id);
    lmb_part_place place = {LMB_PART_STATE, 0, 0, 1};
    lmb_error e = {LMB_OK, ""};
    int made = 0;
    lmb_status st = lmb_make_folders(dir, &made, &e);
    if (st == LMB_OK)
        st = lmb_part_write_pieces(path, &id, &place, pieces, count, &e);
    if (st != LMB_OK)
        lmb_warn(log, "light group cache: %s (the next bake lights this group again)", e.message);
    free(pieces);
}

int lmb_group_cache_has(const char *dir, const uint8_t key[32])
{
    char path[4200];
    cache_path(dir, key, path, sizeof path);
    FILE *f = fopen(path, "rb");
    if (f)
        fclose(f);
    return f != NULL;
}

int lmb_group_cache_read(const char *dir, const uint8_t key[32], uint32_t g, lmb_group_light *gl, lmb_cache *cache,
                         uint32_t probes, uint64_t *texels, uint64_t *valid_texels, const lmb_log *log)
{
    char path[4200];
    cache_path(dir, key, path, sizeof path);
    FILE *exists = fopen(path, "rb");
    if (!exists)
        return 0;
    fclose(exists);
    lmb_part_identity id;
    cache_identity(key, &id);
    lmb_part_place want = {LMB_PART_STATE, 0, 0, 1}, got;
    lmb_part_view view; /* mapped: the arrays are copied once, out of the page cache */
    size_t size = 0, at = sizeof(body_header);
    lmb_error e = {LMB_OK, ""};
    uint32_t n = cache->atlas_count;
    int mapped = lmb_part_map(path, &id, &want, &got, &view, &e) == LMB_OK;
    const void *body = mapped ? view.body : NULL;
    size = mapped ? view.body_length : 0;
    int ok = mapped && size >= sizeof(body_header);
    body_header h;
    if (ok) {
        memcpy(&h, body, sizeof h);
        ok = h.format == GROUP_CACHE_FORMAT && h.atlases == n && h.has_direction == (gl->direction != NULL) &&
             h.probes == (gl->sh ? probes : 0);
    }
    size_t need = at;
    for (uint32_t a = 0; ok && a < n; a++)
        need += (size_t)cache->layout->width[a] * cache->layout->height[a] * (1 + (h.has_direction ? 6 : 3) * sizeof(float));
    if (ok)
        need += (size_t)h.probes * (LMB_PROBE_SH + LMB_PROBE_CUBE) * sizeof(float) + 4 * (size_t)h.records * sizeof(float);
    ok = ok && need == size;
    const uint8_t *b = body;
    for (uint32_t a = 0; ok && a < n; a++) {
        size_t t = (size_t)cache->layout->width[a] * cache->layout->height[a], k = (size_t)g * n + a;
        memcpy(cache->state[a], b + at, t);
        at += t;
        gl->irradiance[k] = malloc(3 * t * sizeof(float) + 1);
        if (gl->direction)
            gl->direction[k] = malloc(3 * t * sizeof(float) + 1);
        ok = gl->irradiance[k] && (!gl->direction || gl->direction[k]);
        if (ok) {
            memcpy(gl->irradiance[k], b + at, 3 * t * sizeof(float));
            at += 3 * t * sizeof(float);
        }
        if (ok && gl->direction) {
            memcpy(gl->direction[k], b + at, 3 * t * sizeof(float));
            at += 3 * t * sizeof(float);
        }
    }
    if (ok && h.probes) {
        gl->sh[g] = malloc((size_t)probes * LMB_PROBE_SH * sizeof(float) + 1);
        gl->cube[g] = malloc((size_t)probes * LMB_PROBE_CUBE * sizeof(float) + 1);
        ok = gl->sh[g] && gl->cube[g];
        if (ok) {
            memcpy(gl->sh[g], b + at, (size_t)probes * LMB_PROBE_SH * sizeof(float));
            at += (size_t)probes * LMB_PROBE_SH * sizeof(float);
            memcpy(gl->cube[g], b + at, (size_t)probes * LMB_PROBE_CUBE * sizeof(float));
            at += (size_t)probes * LMB_PROBE_CUBE * sizeof(float);
        }
    }
    if (ok && gl->records) {
        gl->records[g].count = h.records;
        gl->records[g].xyzr = malloc(4 * (size_t)h.records * sizeof(float) + 1);
        ok = gl->records[g].xyzr != NULL;
        if (ok)
            memcpy(gl->records[g].xyzr, b + at, 4 * (size_t)h.records * sizeof(float));
    }
    if (mapped)
        lmb_part_unmap(&view);
    if (!ok) { /* nothing half read stays: the group is lit instead */
        for (uint32_t a = 0; a < n; a++) {
            size_t k = (size_t)g * n + a;
            free(gl->irradiance[k]);
            gl->irradiance[k] = NULL;
            if (gl->direction) {
                free(gl->direction[k]);
                gl->direction[k] = NULL;
            }
        }
        if (gl->sh) {
            free(gl->sh[g]);
            free(gl->cube[g]);
            gl->sh[g] = gl->cube[g] = NULL;
        }
        if (gl->records) {
            free(gl->records[g].xyzr);
            gl->records[g] = (lmb_ic_points){NULL, 0};
        }
        lmb_warn(log, "light group cache: %s: %s; lighting the group instead", path,
                 e.message[0] ? e.message : "not this layout's (sizes differ)");
        return 0;
    }
    *texels = h.texels;
    *valid_texels = h.valid_texels;
    utime(path, NULL); /* the watch keeps what was used last */
    return 1;
}

/* The whole of a file (owned, free()); NULL when it cannot be read. */
static uint8_t *slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    uint8_t *data = NULL;
    long n = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    if (n >= 0 && fseek(f, 0, SEEK_SET) == 0)
        data = malloc((size_t)n + 1);
    if (data && fread(data, 1, (size_t)n, f) != (size_t)n) {
        free(data);
        data = NULL;
    }
    fclose(f);
    *size = data ? (size_t)n : 0;
    return data;
}

/* The body: the files' count and sizes, then the files. */
typedef struct files_header {
    uint64_t count;
    uint64_t size[LMB_GROUP_FILES];
} files_header;

void lmb_group_cache_keep_files(const char *dir, const uint8_t key[32], uint32_t a, const char *const *paths,
                                uint32_t count, const lmb_log *log)
{
    char path[4200];
    files_path(dir, key, a, path, sizeof path);
    files_header head = {count, {0}};
    uint8_t *data[LMB_GROUP_FILES] = {NULL};
    lmb_part_piece pieces[1 + LMB_GROUP_FILES] = {{&head, sizeof head}};
    int read = count <= LMB_GROUP_FILES;
    for (uint32_t k = 0; read && k < count; k++) {
        size_t size = 0;
        data[k] = slurp(paths[k], &size);
        head.size[k] = size;
        pieces[1 + k] = (lmb_part_piece){data[k], size};
        read = data[k] != NULL;
    }
    lmb_part_identity id;
    cache_identity(key, &id);
    lmb_part_place place = {LMB_PART_STATE, a, 0, 1};
    lmb_error e = {LMB_OK, ""};
    lmb_status st = read ? lmb_part_write_pieces(path, &id, &place, pieces, 1 + count, &e)
                         : lmb_error_set(&e, LMB_ERR_INTERNAL, "%s: cannot read the group's files", path);
    if (st != LMB_OK)
        lmb_warn(log, "light group cache: %s (the next bake encodes this group's files again)", e.message);
    for (uint32_t k = 0; k < LMB_GROUP_FILES; k++)
        free(data[k]);
}

int lmb_group_cache_copy_files(const char *dir, const uint8_t key[32], uint32_t a, const char *const *paths,
                               uint32_t count, const lmb_log *log)
{
    char path[4200];
    files_path(dir, key, a, path, sizeof path);
    FILE *exists = fopen(path, "rb");
    if (!exists)
        return 0;
    fclose(exists);
    lmb_part_identity id;
    cache_identity(key, &id);
    lmb_part_place want = {LMB_PART_STATE, a, 0, 1}, got;
    lmb_part_view view;
    lmb_error e = {LMB_OK, ""};
    files_header head;
    memset(&head, 0, sizeof head);
    int ok = lmb_part_map(path, &id, &want, &got, &view, &e) == LMB_OK;
    if (ok) {
        ok = view.body_length >= sizeof head;
        if (ok)
            memcpy(&head, view.body, sizeof head);
        uint64_t total = 0;
        ok = ok && head.count == count;
        for (uint32_t k = 0; ok && k < count; k++) {
            ok = head.size[k] <= view.body_length - sizeof head - total;
            total += ok ? head.size[k] : 0;
        }
        ok = ok && total == view.body_length - sizeof head;
        if (!ok)
            snprintf(e.message, sizeof e.message, "%.900s: not a group's files", path);
        const uint8_t *at = view.body + sizeof head;
        for (uint32_t k = 0; k < count && ok; k++) {
            FILE *f = fopen(paths[k], "wb");
            ok = f && fwrite(at, 1, head.size[k], f) == head.size[k];
            if (f && fclose(f) != 0)
                ok = 0;
            if (!ok)
                snprintf(e.message, sizeof e.message, "cannot write %.900s", paths[k]);
            at += head.size[k];
        }
        lmb_part_unmap(&view);
    }
    if (!ok) {
        lmb_warn(log, "light group cache: %s; encoding the group's files instead", e.message);
        return 0;
    }
    utime(path, NULL);
    return 1;
}
