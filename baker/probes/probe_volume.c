/* Irradiance volumes from the probes (see probes.h): bevy's layout of ambient cubes. */
#include "probes.h"

#include "write/ktx2.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

lmb_status lmb_probe_volume_make(const lmb_probe_set *set, uint32_t g, const float *cube, lmb_probe_volume *out,
                                 lmb_error *err)
{
    const float *cubes = cube ? cube : set->cube;
    memset(out, 0, sizeof *out);
    const lmb_probe_grid *grid = &set->grids[g];
    size_t n = (size_t)grid->res[0] * grid->res[1] * grid->res[2];
    float *sum = calloc(n * LMB_PROBE_CUBE + 1, sizeof *sum), *next = malloc((n * LMB_PROBE_CUBE + 1) * sizeof *next);
    uint32_t *count = calloc(n + 1, sizeof *count);
    uint8_t *has = calloc(n + 1, 1), *had = malloc(n + 1);
    if (!sum || !next || !count || !has || !had) {
        free(sum);
        free(next);
        free(count);
        free(has);
        free(had);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for a volume of %zu voxels", n);
    }
    for (uint32_t i = 0; i < set->count; i++) {
        if (set->cell[i] < grid->first_voxel || set->cell[i] - grid->first_voxel >= n)
            continue;
        size_t v = set->cell[i] - grid->first_voxel;
        count[v]++;
        for (int k = 0; k < LMB_PROBE_CUBE; k++)
            sum[v * LMB_PROBE_CUBE + k] += cubes[(size_t)i * LMB_PROBE_CUBE + k];
    }
    for (size_t v = 0; v < n; v++) {
        has[v] = count[v] > 0;
        out->filled += !has[v];
        for (int k = 0; has[v] && k < LMB_PROBE_CUBE; k++)
            sum[v * LMB_PROBE_CUBE + k] /= (float)count[v];
    }
    /* fill: each pass, an empty voxel with filled neighbours (6-connected) takes their mean */
    const uint32_t *r = grid->res;
    for (int changed = 1; changed;) {
        changed = 0;
        memcpy(had, has, n);
        memcpy(next, sum, n * LMB_PROBE_CUBE * sizeof *next);
        for (uint32_t z = 0; z < r[2]; z++)
            for (uint32_t y = 0; y < r[1]; y++)
                for (uint32_t x = 0; x < r[0]; x++) {
                    size_t v = ((size_t)z * r[1] + y) * r[0] + x;
                    if (had[v])
                        continue;
                    int64_t nb[6] = {x > 0 ? (int64_t)v - 1 : -1, x + 1 < r[0] ? (int64_t)v + 1 : -1,
                                     y > 0 ? (int64_t)(v - r[0]) : -1, y + 1 < r[1] ? (int64_t)(v + r[0]) : -1,
                                     z > 0 ? (int64_t)(v - (size_t)r[0] * r[1]) : -1,
                                     z + 1 < r[2] ? (int64_t)(v + (size_t)r[0] * r[1]) : -1};
                    uint32_t m = 0;
                    float acc[LMB_PROBE_CUBE] = {0};
                    for (int j = 0; j < 6; j++)
                        if (nb[j] >= 0 && had[nb[j]]) {
                            m++;
                            for (int k = 0; k < LMB_PROBE_CUBE; k++)
                                acc[k] += sum[(size_t)nb[j] * LMB_PROBE_CUBE + k];
                        }
                    if (!m)
                        continue;
                    for (int k = 0; k < LMB_PROBE_CUBE; k++)
                        next[v * LMB_PROBE_CUBE + k] = acc[k] / (float)m;
                    has[v] = 1;
                    changed = 1;
                }
        memcpy(sum, next, n * LMB_PROBE_CUBE * sizeof *sum);
    }
    free(next);
    free(count);
    free(has);
    free(had);
    out->cube = sum;
    for (int k = 0; k < 3; k++) {
        out->res[k] = r[k];
        out->lo[k] = grid->lo[k];
        out->hi[k] = grid->lo[k] + r[k] * grid->cell[k];
    }
    return LMB_OK;
}

void lmb_probe_volume_free(lmb_probe_volume *v)
{
    free(v->cube);
    memset(v, 0, sizeof *v);
}

lmb_status lmb_probe_volume_write_ktx2(const lmb_probe_volume *v, double scale, const char *path, lmb_error *err)
{
    uint32_t rx = v->res[0], ry = v->res[1], rz = v->res[2];
    size_t texels = (size_t)rx * 2 * ry * 3 * rz;
    float *rgb = malloc((3 * texels + 1) * sizeof *rgb);
    if (!rgb)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for the volume's texture");
    for (uint32_t z = 0; z < rz; z++)
        for (uint32_t y = 0; y < ry; y++)
            for (uint32_t x = 0; x < rx; x++) {
                const float *cube = v->cube + (((size_t)z * ry + y) * rx + x) * LMB_PROBE_CUBE;
                for (int face = 0; face < 6; face++) {
                    size_t p = z + (size_t)(face / 2) * rz, t = y + (size_t)(face % 2) * ry;
                    float *q = rgb + 3 * ((p * 2 * ry + t) * rx + x);
                    for (int c = 0; c < 3; c++)
                        q[c] = (float)(cube[3 * face + c] * scale);
                }
            }
    lmb_ktx2_options o = {LMB_KTX2_E5B9G9R9, 0, 0, 1, NULL};
    lmb_status st = lmb_ktx2_write_3d(path, rx, 2 * ry, 3 * rz, rgb, &o, err);
    free(rgb);
    return st;
}
