/* Counting the texels a layout makes (see coverage.h). Every triangle marks the texels of its
 * bounding box, grown by one, that have a sub-sample within one texel of it: the texels stage's
 * rule (texels.c), without building the points. Instances are marked in parallel; a texel is
 * only ever set to 1, so the count does not depend on the order. */
#include "coverage.h"

#include "util/triangle2d.h"

#include <omp.h>

#include <math.h>
#include <stdlib.h>

static void mark_triangle(const double uv[6], uint32_t w, uint32_t h, uint32_t samples, uint8_t *map)
{
    double box[4];
    lmb_triangle_box_2d(uv, box);
    long x0 = (long)floor(box[0]) - 1, x1 = (long)floor(box[2]) + 1;
    long y0 = (long)floor(box[1]) - 1, y1 = (long)floor(box[3]) + 1;
    x0 = x0 < 0 ? 0 : x0;
    y0 = y0 < 0 ? 0 : y0;
    x1 = x1 >= (long)w ? (long)w - 1 : x1;
    y1 = y1 >= (long)h ? (long)h - 1 : y1;
    for (long y = y0; y <= y1; y++)
        for (long x = x0; x <= x1; x++) {
            uint8_t *t = &map[(size_t)y * w + (size_t)x];
            uint8_t seen;
#pragma omp atomic read
            seen = *t;
            for (uint32_t k = 0; !seen && k < samples; k++) {
                double p[2], b1, b2;
                lmb_texel_subsample(k, samples, p);
                p[0] += (double)x;
                p[1] += (double)y;
                if (!lmb_box_beyond_2d(box, p, 1.0) && lmb_closest_on_triangle_2d(uv, p, &b1, &b2) <= 1.0) {
                    seen = 1;
#pragma omp atomic write
                    *t = 1;
                }
            }
        }
}

uint8_t *lmb_layout_texel_map(const lmb_scene *s, const lmb_layout *l, uint32_t a, uint32_t samples, uint32_t threads)
{
    uint32_t w = l->width[a], h = l->height[a];
    uint8_t *map = calloc((size_t)w * h + 1, 1);
    if (!map)
        return NULL;
    int nt = threads ? (int)threads : omp_get_max_threads();
#pragma omp parallel for num_threads(nt) schedule(dynamic, 4)
    for (uint32_t i = 0; i < l->instance_count; i++) {
        const lmb_layout_instance *li = &l->instances[i];
        if (!li->lightmapped || li->atlas != a)
            continue;
        const lmb_charts *c = &l->meshes[s->instances[i].mesh].charts;
        for (uint32_t f = 0; f < c->triangle_count; f++)
            if (c->chart_of[f] != UINT32_MAX) {
                double uv[6];
                lmb_layout_uv(l, i, f, uv);
                mark_triangle(uv, w, h, samples, map);
            }
    }
    return map;
}

uint64_t lmb_layout_count_texels(const lmb_scene *s, const lmb_layout *l, uint32_t samples, uint32_t threads,
                                 lmb_error *err, lmb_status *status)
{
    uint64_t total = 0;
    *status = LMB_OK;
    for (uint32_t a = 0; a < l->atlas_count; a++) {
        uint8_t *map = lmb_layout_texel_map(s, l, a, samples, threads);
        if (!map) {
            *status = lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory counting atlas %u's texels", a);
            return 0;
        }
        uint64_t n = 0;
        for (size_t k = 0; k < (size_t)l->width[a] * l->height[a]; k++)
            n += map[k];
        total += n;
        free(map);
    }
    return total;
}
