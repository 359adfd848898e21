/* The probes' placement in the layout cache (probe_cache.h): the body's layout, and its file. */
#define _GNU_SOURCE
#include "probe_cache.h"

#include "steps/part_file.h"
#include "watch/layout_cache.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define MAGIC "LMBPROBE"
#define FORMAT 1u

typedef struct cache_header {
    char magic[8];
    uint32_t format, pad;
    uint64_t body_size;
    uint8_t sum[32]; /* SHA-256 of the body */
} cache_header;

/* The body: these counts, the spacing, each grid, the positions, their voxels, the tetrahedra
 * and qhull's word on them (all in this machine's byte order, as every cache file). */
typedef struct body_counts {
    uint32_t count, grid_count, tet_count, tet_flat;
    uint32_t refined, moved, wall_probes, dropped_inside, dropped_outside, pad;
    double spacing;
} body_counts;

typedef struct body_grid {
    double lo[3], cell[3], world[16];
    uint32_t res[3], first_voxel, volume, from_node, node, pad;
} body_grid;

/* The file: the layout's name with .lmbp replaced by -probes.lmbq. */
static int cache_path(const lmb_scene *scene, const lmb_config *cfg, const char *dir, char *path, size_t size)
{
    lmb_error e = {LMB_OK, ""};
    if (lmb_layout_cache_path(scene, cfg, dir, path, size, &e) != LMB_OK)
        return 0;
    size_t n = strlen(path);
    if (n < 5 || strcmp(path + n - 5, ".lmbp"))
        return 0;
    path[n - 5] = '\0';
    return snprintf(path + n - 5, size - (n - 5), "-probes.lmbq") < (int)(size - (n - 5));
}

static size_t body_size(uint32_t count, uint32_t grids, uint32_t tets)
{
    return sizeof(body_counts) + (size_t)grids * sizeof(body_grid) + 3 * (size_t)count * sizeof(double) +
           (size_t)count * sizeof(uint32_t) + 4 * (size_t)tets * sizeof(uint32_t) + sizeof((lmb_probe_tetrahedra_out *)0)->why;
}

/* Takes n bytes at *at into dst (0: the body ends first). */
static int take(const uint8_t *body, size_t size, size_t *at, void *dst, size_t n)
{
    if (n > size - *at)
        return 0;
    memcpy(dst, body + *at, n);
    *at += n;
    return 1;
}

/* The node grid's name: the scene's probe volume of its node (the set names it in messages). */
static const char *node_name(const lmb_scene *scene, uint32_t node)
{
    for (uint32_t k = 0; k < scene->probe_volume_count; k++)
        if (scene->probe_volumes[k].node == node)
            return scene->probe_volumes[k].name;
    return NULL;
}

/* The set from the body; 0 when the body does not hold one whole. */
static int parse(const lmb_scene *scene, const lmb_config *cfg, const uint8_t *body, size_t size, lmb_probe_set *set)
{
    size_t at = 0;
    body_counts c;
    if (!take(body, size, &at, &c, sizeof c) || !c.count || c.count > LMB_PROBES_MAX || c.grid_count > 1u << 20 ||
        c.tet_count > 16u * c.count || body_size(c.count, c.grid_count, c.tet_count) != size)
        return 0;
    set->count = c.count;
    set->grid_count = c.grid_count;
    set->refined = c.refined;
    set->moved = c.moved;
    set->wall_probes = c.wall_probes;
    set->dropped_inside = c.dropped_inside;
    set->dropped_outside = c.dropped_outside;
    set->spacing = c.spacing;
    set->rays = cfg->probe_rays;
    set->grids = calloc((size_t)c.grid_count + 1, sizeof *set->grids);
    set->position = malloc(3 * (size_t)c.count * sizeof *set->position);
    set->cell = malloc((size_t)c.count * sizeof *set->cell);
    set->tets.tetrahedra = malloc(4 * (size_t)c.tet_count * sizeof *set->tets.tetrahedra + 1);
    set->sh = calloc((size_t)c.count * LMB_PROBE_SH, sizeof *set->sh);
    set->cube = calloc((size_t)c.count * LMB_PROBE_CUBE, sizeof *set->cube);
    if (!set->grids || !set->position || !set->cell || !set->tets.tetrahedra || !set->sh || !set->cube)
        return 0;
    for (uint32_t g = 0; g < c.grid_count; g++) {
        body_grid b;
        if (!take(body, size, &at, &b, sizeof b))
            return 0;
        lmb_probe_grid *pg = &set->grids[g];
        memcpy(pg->lo, b.lo, sizeof pg->lo);
        memcpy(pg->cell, b.cell, sizeof pg->cell);
        memcpy(pg->world, b.world, sizeof pg->world);
        memcpy(pg->res, b.res, sizeof pg->res);
        pg->first_voxel = b.first_voxel;
        pg->volume = b.volume;
        pg->from_node = (int)b.from_node;
        pg->node = b.node;
        pg->node_name = pg->from_node ? node_name(scene, b.node) : NULL;
        if (pg->from_node && !pg->node_name)
            return 0;
    }
    if (!take(body, size, &at, set->position, 3 * (size_t)c.count * sizeof *set->position) ||
        !take(body, size, &at, set->cell, (size_t)c.count * sizeof *set->cell) ||
        !take(body, size, &at, set->tets.tetrahedra, 4 * (size_t)c.tet_count * sizeof *set->tets.tetrahedra) ||
        !take(body, size, &at, set->tets.why, sizeof set->tets.why))
        return 0;
    set->tets.why[sizeof set->tets.why - 1] = '\0';
    set->tets.count = c.tet_count;
    set->tets.flat = c.tet_flat;
    for (size_t k = 0; k < 4 * (size_t)c.tet_count; k++)
        if (set->tets.tetrahedra[k] >= c.count)
            return 0;
    set->tets_made = 1;
    return at == size;
}

int lmb_probe_cache_read(const lmb_scene *scene, const lmb_config *cfg, const char *dir, lmb_probe_set *set,
                         const lmb_log *log)
{
    char path[4300];
    memset(set, 0, sizeof *set);
    if (!cache_path(scene, cfg, dir, path, sizeof path))
        return 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    cache_header h;
    uint8_t *body = NULL, sum[32];
    int ok = fread(&h, sizeof h, 1, f) == 1 && !memcmp(h.magic, MAGIC, 8) && h.format == FORMAT &&
             h.body_size < (1ull << 34);
    body = ok ? malloc(h.body_size + 1) : NULL;
    ok = body && fread(body, 1, h.body_size, f) == h.body_size && fgetc(f) == EOF;
    fclose(f);
    if (ok)
        lmb_sha256(body, h.body_size, sum);
    ok = ok && !memcmp(sum, h.sum, 32) && parse(scene, cfg, body, h.body_size, set);
    free(body);
    if (!ok) {
        lmb_probe_set_free(set);
        lmb_warn(log, "layout cache: %s is damaged or of another format; the probes are placed again", path);
        return 0;
    }
    lmb_info(log, "probes: %u read back with the layout (%u added along walls, %u tetrahedra; their rays and qhull "
             "not run again)", set->count, set->wall_probes, set->tets.count);
    return 1;
}

static void put(uint8_t *body, size_t *at, const void *src, size_t n)
{
    if (n)
        memcpy(body + *at, src, n);
    *at += n;
}

void lmb_probe_cache_write(const lmb_scene *scene, const lmb_config *cfg, const char *dir, const lmb_probe_set *set,
                           const lmb_log *log)
{
    char path[4300], tmp[4400];
    if (!set->count || !set->tets_made || !cache_path(scene, cfg, dir, path, sizeof path))
        return;
    size_t size = body_size(set->count, set->grid_count, set->tets.count), at = 0;
    uint8_t *body = malloc(size);
    if (!body) {
        lmb_warn(log, "layout cache: out of memory for %s; the next bake places the probes again", path);
        return;
    }
    body_counts c = {set->count, set->grid_count, set->tets.count, set->tets.flat, set->refined, set->moved,
                     set->wall_probes, set->dropped_inside, set->dropped_outside, 0, set->spacing};
    put(body, &at, &c, sizeof c);
    for (uint32_t g = 0; g < set->grid_count; g++) {
        const lmb_probe_grid *pg = &set->grids[g];
        body_grid b;
        memset(&b, 0, sizeof b);
        memcpy(b.lo, pg->lo, sizeof b.lo);
        memcpy(b.cell, pg->cell, sizeof b.cell);
        memcpy(b.world, pg->world, sizeof b.world);
        memcpy(b.res, pg->res, sizeof b.res);
        b.first_voxel = pg->first_voxel;
        b.volume = pg->volume;
        b.from_node = (uint32_t)pg->from_node;
        b.node = pg->node;
        put(body, &at, &b, sizeof b);
    }
    put(body, &at, set->position, 3 * (size_t)set->count * sizeof *set->position);
    put(body, &at, set->cell, (size_t)set->count * sizeof *set->cell);
    put(body, &at, set->tets.tetrahedra, 4 * (size_t)set->tets.count * sizeof *set->tets.tetrahedra);
    put(body, &at, set->tets.why, sizeof set->tets.why);
    cache_header h;
    memset(&h, 0, sizeof h);
    memcpy(h.magic, MAGIC, 8);
    h.format = FORMAT;
    h.body_size = size;
    lmb_sha256(body, size, h.sum);
    snprintf(tmp, sizeof tmp, "%s.%ld.part", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    int ok = f && fwrite(&h, sizeof h, 1, f) == 1 && fwrite(body, 1, size, f) == size;
    free(body);
    if (f && fclose(f) != 0)
        ok = 0;
    if (ok && rename(tmp, path) == 0)
        return;
    unlink(tmp);
    lmb_warn(log, "layout cache: cannot write %s; the next bake places the probes again", path);
}
