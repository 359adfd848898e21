/*
 * atlas.keep_uv1: a mesh that already has TEXCOORD_1 on every primitive keeps it. Its UVs
 * ([0,1], glTF's top-left origin) become one chart; each instance gets a square of S x S
 * texels, S chosen so the texel density matches the config (S = density x sqrt(world area /
 * UV area)), and the squares share atlases, placed on shelves without rotation, so an engine
 * maps the untouched TEXCOORD_1 with one scale and offset per instance (bevy's uv_rect,
 * Unity's lightmapScaleOffset). The layout is checked: overlapping texels are reported, not
 * fixed.
 */
#include "keep_uv1.h"

#include "unwrap/metrics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int lmb_mesh_has_uv1(const lmb_scene *s, uint32_t mesh)
{
    const lmb_mesh *m = &s->meshes[mesh];
    if (!m->primitive_count)
        return 0;
    for (uint32_t p = 0; p < m->primitive_count; p++)
        if (!s->primitives[m->first_primitive + p].uv1)
            return 0;
    return 1;
}

lmb_status lmb_charts_from_uv1(const lmb_scene *s, uint32_t mesh, const lmb_mesh_soup *soup, lmb_charts *c,
                               lmb_error *err)
{
    const lmb_mesh *m = &s->meshes[mesh];
    uint32_t nt = soup->triangle_count, n = 0, f = 0;
    memset(c, 0, sizeof *c);
    c->triangle_count = nt;
    c->chart_of = malloc(((size_t)nt + 1) * sizeof *c->chart_of);
    c->uv = calloc((size_t)nt * 6 + 1, sizeof *c->uv);
    c->order = malloc(((size_t)nt + 1) * sizeof *c->order);
    c->first = malloc(2 * sizeof *c->first);
    if (!c->chart_of || !c->uv || !c->order || !c->first) {
        lmb_charts_free(c);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "keep_uv1: out of memory");
    }
    for (uint32_t p = 0; p < m->primitive_count; p++) {
        const lmb_primitive *pr = &s->primitives[m->first_primitive + p];
        for (uint32_t t = 0; t < pr->triangle_count; t++, f++) {
            c->chart_of[f] = soup->skip[f] ? UINT32_MAX : 0;
            for (int k = 0; k < 3; k++) {
                c->uv[6 * f + 2 * k] = pr->uv1[2 * pr->indices[3 * t + k]];
                c->uv[6 * f + 2 * k + 1] = pr->uv1[2 * pr->indices[3 * t + k] + 1];
            }
            if (!soup->skip[f])
                c->order[n++] = f;
        }
    }
    c->chart_count = 1;
    c->first[0] = 0;
    c->first[1] = n;
    return LMB_OK;
}

uint32_t lmb_uv1_atlas_size(double world_area, const lmb_charts *c, double density, uint32_t max_size)
{
    double uv_area = 0;
    for (uint32_t f = 0; f < c->triangle_count; f++) {
        const double *u = c->uv + 6 * f;
        if (c->chart_of[f] != UINT32_MAX)
            uv_area += 0.5 * fabs((u[2] - u[0]) * (u[5] - u[1]) - (u[4] - u[0]) * (u[3] - u[1]));
    }
    double s = uv_area > 0 ? density * sqrt(world_area / uv_area) : 16;
    s = ceil(s / 4) * 4;
    return s < 16 ? 16 : s > max_size ? max_size : (uint32_t)s;
}

