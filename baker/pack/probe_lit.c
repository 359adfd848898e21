/* Props the light probes light when the texel budget cannot hold their charts (probe_lit.h). */
#include "probe_lit.h"

#include <stdlib.h>
#include <string.h>

typedef struct mesh_cost {
    uint32_t mesh, copies;
    double charts, area, floor_per_area;
} mesh_cost;

/* Most floor texels per world area first; the mesh index breaks ties (a fixed order). */
static int by_cost_desc(const void *pa, const void *pb)
{
    const mesh_cost *a = pa, *b = pb;
    if (a->floor_per_area != b->floor_per_area)
        return a->floor_per_area > b->floor_per_area ? -1 : 1;
    return a->mesh < b->mesh ? -1 : a->mesh > b->mesh;
}

int lmb_probe_lit_choose(const lmb_scene *s, const lmb_layout *l, const uint32_t *list, uint32_t n,
                         const double *area, double floor_texels, uint64_t budget, const uint8_t *forced,
                         uint32_t *keep, uint8_t *moved, lmb_probe_lit_choice *out)
{
    memset(out, 0, sizeof *out);
    memset(moved, 0, s->instance_count);
    mesh_cost *cost = calloc((size_t)s->mesh_count + 1, sizeof *cost);
    uint8_t *go = calloc((size_t)s->mesh_count + 1, 1);
    if (!cost || !go) {
        free(cost);
        free(go);
        return -1;
    }
    double all_charts = 0;
    for (uint32_t m = 0; m < s->mesh_count; m++)
        cost[m].mesh = m;
    for (uint32_t k = 0; k < n; k++) {
        mesh_cost *c = &cost[s->instances[list[k]].mesh];
        double charts = l->meshes[c->mesh].charts.chart_count;
        c->copies++;
        c->charts += charts;
        c->area += area[k];
        all_charts += charts;
    }
    uint32_t used = 0;
    for (uint32_t m = 0; m < s->mesh_count; m++) {
        mesh_cost *c = &cost[m];
        if (!c->copies)
            continue;
        c->floor_per_area = all_charts > 0 ? floor_texels * c->charts / all_charts / (c->area > 0 ? c->area : 1e-300) : 0;
        cost[used++] = *c;
    }
    qsort(cost, used, sizeof *cost, by_cost_desc);
    double kept_floor = floor_texels, target = LMB_PROBE_LIT_FLOOR_SHARE * (double)budget;
    uint32_t lightmapped_meshes = used;
    for (uint32_t j = 0; forced && j < used && lightmapped_meshes > 1; j++) { /* those that fit no atlas */
        if (!forced[cost[j].mesh])
            continue;
        go[cost[j].mesh] = 1;
        kept_floor -= all_charts > 0 ? floor_texels * cost[j].charts / all_charts : 0;
        lightmapped_meshes--;
        out->moved_meshes++;
    }
    for (uint32_t j = 0; j < used && kept_floor > target && lightmapped_meshes > 1; j++) {
        if (cost[j].copies < 2 || go[cost[j].mesh])
            continue;
        go[cost[j].mesh] = 1;
        kept_floor -= all_charts > 0 ? floor_texels * cost[j].charts / all_charts : 0;
        lightmapped_meshes--;
        out->moved_meshes++;
    }
    for (uint32_t k = 0; k < n; k++) {
        if (go[s->instances[list[k]].mesh]) {
            moved[list[k]] = 1;
            out->moved++;
        } else {
            keep[out->kept++] = list[k];
        }
    }
    out->kept_floor = kept_floor;
    free(cost);
    free(go);
    return 0;
}
