/* The gather points' validity memo in the layout cache (validity_cache.h). */
#define _GNU_SOURCE
#include "validity_cache.h"

#include "steps/part_file.h"
#include "watch/layout_cache.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zstd.h>

#define MAGIC "LMBVALID"
#define FORMAT 3u /* 3: entries carry LMB_VALIDITY_NEAR */

/* The memo's file: the layout's file name with .lmbp replaced by -seedN.lmbv. */
static int memo_path(const lmb_scene *scene, const lmb_config *cfg, const char *dir, char *path, size_t size)
{
    lmb_error e = {LMB_OK, ""};
    if (lmb_layout_cache_path(scene, cfg, dir, path, size, &e) != LMB_OK)
        return 0;
    size_t n = strlen(path);
    if (n < 5 || strcmp(path + n - 5, ".lmbp"))
        return 0;
    path[n - 5] = '\0';
    size_t left = size - (n - 5);
    return snprintf(path + n - 5, left, "-seed%llu.lmbv", (unsigned long long)cfg->seed) < (int)left;
}

/* The header: magic, format, samples, atlas count; then per atlas its entries and the bytes of
 * their compressed form, the SHA-256 of the entries, the compressed bytes. */
typedef struct memo_header {
    char magic[8];
    uint32_t format, samples, atlas_count, pad;
} memo_header;

int lmb_validity_cache_read(const lmb_scene *scene, const lmb_config *cfg, const char *dir, lmb_point_validity *v,
                            const lmb_log *log)
{
    char path[4300];
    if (!memo_path(scene, cfg, dir, path, sizeof path))
        return 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    memo_header h;
    int ok = fread(&h, sizeof h, 1, f) == 1 && !memcmp(h.magic, MAGIC, 8) && h.format == FORMAT &&
             h.samples == v->samples && h.atlas_count == v->atlas_count;
    void *packed = NULL;
    for (uint32_t a = 0; ok && a < v->atlas_count; a++) {
        uint64_t sizes[2];
        uint8_t want[32], got_hash[32];
        ok = fread(sizes, sizeof sizes, 1, f) == 1 && sizes[0] == v->size[a] &&
             sizes[1] <= ZSTD_compressBound(v->size[a]) && fread(want, 32, 1, f) == 1;
        void *p = ok ? realloc(packed, sizes[1] + 1) : NULL;
        ok = p != NULL;
        if (p)
            packed = p;
        ok = ok && fread(packed, 1, sizes[1], f) == sizes[1];
        size_t got = ok ? ZSTD_decompress(v->entry[a], v->size[a], packed, sizes[1]) : 0;
        ok = ok && !ZSTD_isError(got) && got == v->size[a];
        if (ok)
            lmb_sha256(v->entry[a], v->size[a], got_hash);
        ok = ok && !memcmp(want, got_hash, 32);
    }
    ok = ok && fgetc(f) == EOF;
    free(packed);
    fclose(f);
    if (!ok) {
        for (uint32_t a = 0; a < v->atlas_count; a++)
            memset(v->entry[a], LMB_VALIDITY_UNKNOWN, v->size[a]);
        lmb_warn(log, "layout cache: %s is damaged or of another layout; the gather points are tested again", path);
        return 0;
    }
    return 1;
}

void lmb_validity_cache_write(const lmb_scene *scene, const lmb_config *cfg, const char *dir,
                              const lmb_point_validity *v, const lmb_log *log)
{
    char path[4300], tmp[4400];
    if (!memo_path(scene, cfg, dir, path, sizeof path))
        return;
    snprintf(tmp, sizeof tmp, "%s.%ld.part", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    memo_header h = {MAGIC, FORMAT, v->samples, v->atlas_count, 0};
    int ok = f && fwrite(&h, sizeof h, 1, f) == 1;
    void *packed = NULL;
    for (uint32_t a = 0; ok && a < v->atlas_count; a++) {
        size_t bound = ZSTD_compressBound(v->size[a]);
        void *p = realloc(packed, bound + 1);
        ok = p != NULL;
        if (p)
            packed = p;
        size_t n = ok ? ZSTD_compress(packed, bound, v->entry[a], v->size[a], 1) : 0;
        ok = ok && !ZSTD_isError(n);
        uint64_t sizes[2] = {v->size[a], n};
        uint8_t hash[32];
        lmb_sha256(v->entry[a], v->size[a], hash);
        ok = ok && fwrite(sizes, sizeof sizes, 1, f) == 1 && fwrite(hash, 32, 1, f) == 1 && fwrite(packed, 1, n, f) == n;
    }
    free(packed);
    if (f && fclose(f) != 0)
        ok = 0;
    if (ok && rename(tmp, path) == 0)
        return;
    unlink(tmp);
    lmb_warn(log, "layout cache: cannot write %s; the next bake tests the gather points again", path);
}
