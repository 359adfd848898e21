/*
 * Instances as rectangles of shared atlases (see rect_instances.h). Instances form groups that
 * share one TEXCOORD_1 layout, the "block" (normalized to [0, 1]^2, W x H texels at its first
 * member's density):
 *  - a kept-TEXCOORD_1 mesh (atlas.keep_uv1): the block is its UVs as they are, W = H = S,
 *    S = density x sqrt(world area / UV area) (keep_uv1.c); every instance is a group of its own,
 *    or, for EXT_mesh_gpu_instancing copies, the copies of one node are one group;
 *  - the copies of an EXT_mesh_gpu_instancing node, or (atlas.share_meshes) the nodes of one mesh,
 *    with a mesh lmbake unwraps: the mesh's charts are packed once (pack.h) into one W x H block.
 * The block is packed at the density of the group's member with the smallest texel scale
 * t = sqrt(A) x d (A world area, d texel density), and each member m gets it at s_m = t_m / t_0
 * >= 1, rounded up to whole texels, so no member's charts come closer than atlas.padding texels
 * (a member scaled down from a larger one's block would shrink its padding, and its charts would
 * share texels). Every member of a group lands in one atlas and shares one TEXCOORD_1 (the
 * copies of a node are one mesh in the output, with one material: one lightmap texture).
 * A copy that is not a uniformly scaled version of the first (its triangles' area ratios spread)
 * has stretched texels: the log says how many. With an automatic density, a group too large for
 * one atlas is lowered (x 0.85, a warning) and the placement redone.
 */
#include "rect_instances.h"

#include "keep_uv1.h"
#include "pack.h"
#include "rects.h"
#include "unwrap/metrics.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* World area of instance i's lightmapped triangles. */
static double world_area(const lmb_scene *s, const lmb_layout *l, uint32_t i)
{
    const lmb_charts *c = &l->meshes[s->instances[i].mesh].charts;
    double q[9], world = 0;
    for (uint32_t f = 0; f < c->triangle_count; f++)
        if (c->chart_of[f] != UINT32_MAX) {
            lmb_layout_world_triangle(s, l, i, f, q);
            world += lmb_triangle_area(q);
        }
    return world;
}

/* Instance i's own TEXCOORD_1 checked in its side x side square: overlapping texels and UVs
 * outside [0, 1] (they would read a neighbour's texels) are reported. */
static lmb_status check_kept_uv1(const lmb_scene *s, const lmb_layout *l, uint32_t i, uint32_t side,
                                 const lmb_log *log, lmb_error *err)
{
    const lmb_charts *c = &l->meshes[s->instances[i].mesh].charts;
    double *pos = malloc(sizeof(double) * 9 * c->triangle_count + 1);
    double *uv = malloc(sizeof(double) * 6 * c->triangle_count + 1);
    if (!pos || !uv) {
        free(pos);
        free(uv);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    }
    uint32_t outside = 0;
    for (uint32_t f = 0; f < c->triangle_count; f++) {
        lmb_layout_world_triangle(s, l, i, f, pos + 9 * f);
        int out = 0;
        for (int k = 0; k < 6; k++) {
            double u = c->chart_of[f] == UINT32_MAX ? 0 : c->uv[6 * f + k];
            out |= u < 0 || u > 1;
            uv[6 * f + k] = u * side;
        }
        outside += out && c->chart_of[f] != UINT32_MAX;
    }
    lmb_uv_layout lay = {c->triangle_count, pos, uv, side, side};
    lmb_uv_metrics m;
    lmb_status st = lmb_uv_metrics_compute(&lay, &m, err);
    free(pos);
    free(uv);
    if (st == LMB_OK && m.overlapping_texels)
        lmb_warn(log, "instance '%s': its own TEXCOORD_1 (atlas.keep_uv1) overlaps itself on %llu texels of its %ux%u "
                 "square: those texels mix light from two places",
                 s->instances[i].name, (unsigned long long)m.overlapping_texels, side, side);
    if (st == LMB_OK && outside)
        lmb_warn(log, "instance '%s': %u triangles of its own TEXCOORD_1 (atlas.keep_uv1) leave [0, 1]: their texels "
                 "fall outside its square, on padding or a neighbour's texels", s->instances[i].name, outside);
    return st;
}

typedef struct group {
    uint32_t first, count; /* members: order[first .. first + count) */
    double *block;         /* 6 per mesh triangle: the shared layout in [0, 1]^2 (0 for skipped triangles) */
    double w, h;           /* the block's size at the first member's density, texels */
} group;

/* Group g's block from an unwrapped mesh: its first member's charts, packed alone. */
static lmb_status pack_block(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, uint32_t i, group *g,
                             lmb_error *err)
{
    const lmb_charts *c = &l->meshes[s->instances[i].mesh].charts;
    double *uv1 = calloc((size_t)6 * c->triangle_count + 1, sizeof *uv1);
    lmb_pack_chart *charts = calloc((size_t)c->chart_count + 1, sizeof *charts);
    double *buf = malloc(sizeof(double) * 6 * c->triangle_count + 1);
    lmb_pack_result r;
    memset(&r, 0, sizeof r);
    lmb_status st = uv1 && charts && buf ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    if (st == LMB_OK)
        lmb_layout_scale_instance(s, l, i, uv1); /* chart-local texel units */
    for (uint32_t k = 0, at = 0; st == LMB_OK && k < c->chart_count; k++) {
        uint32_t len = c->first[k + 1] - c->first[k];
        for (uint32_t t = 0; t < len; t++)
            memcpy(buf + 6 * (at + t), uv1 + 6 * c->order[c->first[k] + t], 6 * sizeof(double));
        charts[k].triangle_count = len;
        charts[k].uv = buf + 6 * at;
        charts[k].group = 0;
        at += len;
    }
    lmb_pack_options opt = {cfg->max_atlas_size, cfg->padding, 1, cfg->threads, lmb_pack_block_for(cfg)};
    if (st == LMB_OK)
        st = lmb_pack_charts(charts, c->chart_count, &opt, &r, err);
    if (st == LMB_OK) {
        g->w = r.width[0];
        g->h = r.height[0];
        for (uint32_t k = 0; k < c->chart_count; k++) {
            const double *m = r.placements[k].m;
            for (uint32_t t = c->first[k]; t < c->first[k + 1]; t++) {
                uint32_t f = c->order[t];
                for (int v = 0; v < 3; v++) {
                    double x = uv1[6 * f + 2 * v], y = uv1[6 * f + 2 * v + 1];
                    g->block[6 * f + 2 * v] = (m[0] * x + m[1] * y + m[2]) / g->w;
                    g->block[6 * f + 2 * v + 1] = (m[3] * x + m[4] * y + m[5]) / g->h;
                }
            }
        }
    }
    lmb_pack_result_free(&r);
    free(uv1);
    free(charts);
    free(buf);
    return st;
}

/* Group g's block: the kept TEXCOORD_1, or the packed charts. */
static lmb_status make_block(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, uint32_t i, group *g,
                             const lmb_log *log, lmb_error *err)
{
    const lmb_layout_mesh *lm = &l->meshes[s->instances[i].mesh];
    const lmb_charts *c = &lm->charts;
    g->block = calloc((size_t)6 * c->triangle_count + 1, sizeof *g->block);
    if (!g->block)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    if (!lm->kept_uv1)
        return pack_block(s, cfg, l, i, g, err);
    uint32_t side = lmb_uv1_atlas_size(world_area(s, l, i), c, l->instances[i].texel_density, cfg->max_atlas_size);
    g->w = g->h = side;
    for (uint32_t k = 0; k < 6 * c->triangle_count; k++)
        g->block[k] = c->chart_of[k / 6] == UINT32_MAX ? 0 : c->uv[k];
    return check_kept_uv1(s, l, i, side, log, err);
}

/* Copies whose triangles' world areas are not in one ratio to the first member's: stretched. */
static uint32_t stretched_members(const lmb_scene *s, const lmb_layout *l, const uint32_t *order, const group *g)
{
    const lmb_charts *c = &l->meshes[s->instances[order[g->first]].mesh].charts;
    uint32_t stretched = 0;
    for (uint32_t j = 1; j < g->count; j++) {
        double lo = INFINITY, hi = 0, q[9];
        for (uint32_t f = 0; f < c->triangle_count; f++) {
            if (c->chart_of[f] == UINT32_MAX)
                continue;
            lmb_layout_world_triangle(s, l, order[g->first], f, q);
            double a0 = lmb_triangle_area(q);
            lmb_layout_world_triangle(s, l, order[g->first + j], f, q);
            double r = a0 > 0 ? lmb_triangle_area(q) / a0 : 1;
            lo = r < lo ? r : lo;
            hi = r > hi ? r : hi;
        }
        stretched += hi > 1.1 * lo;
    }
    return stretched;
}

/* Instances a and b share one layout: copies of one instanced node, or (atlas.share_meshes) nodes of
 * one mesh that lmbake unwraps. */
static int same_layout(const lmb_scene *s, const lmb_config *cfg, const lmb_layout *l, uint32_t a, uint32_t b)
{
    const lmb_instance *x = &s->instances[a], *y = &s->instances[b];
    if (x->gpu_instance >= 0 || y->gpu_instance >= 0)
        return x->gpu_instance >= 0 && y->gpu_instance >= 0 && x->node == y->node;
    return cfg->share_meshes && x->mesh == y->mesh && !l->meshes[x->mesh].kept_uv1;
}

/* Groups: consecutive runs of order[] (instances that share a layout together, in instance
 * order; any other instance alone). Returns the group count. */
static uint32_t make_groups(const lmb_scene *s, const lmb_config *cfg, const lmb_layout *l, const uint32_t *list,
                            uint32_t n, uint32_t *order, group *groups)
{
    uint32_t ng = 0, placed = 0;
    uint8_t *taken = calloc((size_t)n + 1, 1);
    if (!taken)
        return UINT32_MAX;
    for (uint32_t j = 0; j < n; j++) {
        if (taken[j])
            continue;
        groups[ng].first = placed;
        groups[ng].count = 0;
        for (uint32_t k = j; k < n; k++)
            if (k == j || (!taken[k] && same_layout(s, cfg, l, list[j], list[k]))) {
                taken[k] = 1;
                order[placed++] = list[k];
                groups[ng].count++;
            }
        ng++;
    }
    free(taken);
    return ng;
}

/* Member j's texel scale: texels per unit of the mesh's charts (sqrt(world area) x density). */
static double texel_scale(const lmb_layout *l, const uint32_t *order, const double *area, uint32_t j)
{
    return sqrt(area[j]) * l->instances[order[j]].texel_density;
}

typedef struct scaled_member {
    double t;
    uint32_t instance;
    double area;
} scaled_member;

static int by_scale(const void *pa, const void *pb)
{
    const scaled_member *a = pa, *b = pb;
    if (a->t != b->t)
        return a->t < b->t ? -1 : 1;
    return a->instance < b->instance ? -1 : a->instance > b->instance;
}

/* Puts group g's smallest member (by texel scale) first, the rest after it by scale: the block
 * is packed at the first member's density and every other member gets it scaled up, so no
 * member's charts come closer than atlas.padding texels. Kept-TEXCOORD_1 groups stay in
 * instance order (their block is their UVs). Returns 0 when out of memory. */
static int smallest_first(const lmb_scene *s, const lmb_layout *l, const group *g, uint32_t *order, double *area)
{
    if (g->count < 2 || l->meshes[s->instances[order[g->first]].mesh].kept_uv1)
        return 1;
    scaled_member *m = malloc(sizeof *m * g->count);
    if (!m)
        return 0;
    for (uint32_t k = 0; k < g->count; k++)
        m[k] = (scaled_member){texel_scale(l, order, area, g->first + k), order[g->first + k], area[g->first + k]};
    qsort(m, g->count, sizeof *m, by_scale);
    for (uint32_t k = 0; k < g->count; k++) {
        order[g->first + k] = m[k].instance;
        area[g->first + k] = m[k].area;
    }
    free(m);
    return 1;
}

lmb_status lmb_layout_rect_instances(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, const uint32_t *list,
                                     uint32_t n, const lmb_log *log, lmb_error *err)
{
    uint32_t *order = malloc(((size_t)n + 1) * sizeof *order);
    group *groups = calloc((size_t)n + 1, sizeof *groups);
    lmb_rect_item *items = calloc((size_t)n + 1, sizeof *items);
    double *area = malloc(((size_t)n + 1) * sizeof *area);
    lmb_rect_result r;
    memset(&r, 0, sizeof r);
    l->unfit_mesh = UINT32_MAX;
    uint32_t ng = order && groups && items && area ? make_groups(s, cfg, l, list, n, order, groups) : UINT32_MAX;
    lmb_status st = ng != UINT32_MAX ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    for (uint32_t j = 0; st == LMB_OK && j < n; j++)
        area[j] = world_area(s, l, order[j]);
    for (uint32_t g = 0; st == LMB_OK && g < ng; g++) {
        if (!smallest_first(s, l, &groups[g], order, area))
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
        if (st == LMB_OK)
            st = make_block(s, cfg, l, order[groups[g].first], &groups[g], log, err);
        uint32_t stretched = st == LMB_OK ? stretched_members(s, l, order, &groups[g]) : 0;
        if (stretched)
            lmb_warn(log, "'%s': %u of the %u instances that share its lightmap layout are not uniformly scaled "
                     "versions of it: their texels are stretched", s->instances[order[groups[g].first]].name,
                     stretched, groups[g].count);
    }
    /* place; an automatic density lowers a group that does not fit one atlas and retries */
    for (int attempt = 0; st == LMB_OK; attempt++) {
        for (uint32_t g = 0; g < ng; g++) {
            double t0 = texel_scale(l, order, area, groups[g].first);
            for (uint32_t j = groups[g].first; j < groups[g].first + groups[g].count; j++) {
                double sc = t0 > 0 ? texel_scale(l, order, area, j) / t0 : 1;
                items[j].w = (uint32_t)fmax(1.0, ceil(groups[g].w * sc - 1e-9));
                items[j].h = (uint32_t)fmax(1.0, ceil(groups[g].h * sc - 1e-9));
                items[j].group = g;
            }
        }
        lmb_rect_result_free(&r);
        st = lmb_place_rects(items, n, cfg->padding, lmb_pack_block_for(cfg), cfg->max_atlas_size, &r, err);
        if (st != LMB_ERR_INPUT || !l->density.automatic || attempt >= 24 || r.failed_group >= ng)
            break;
        group *g = &groups[r.failed_group];
        uint32_t first = order[g->first];
        lmb_warn(log, "'%s' and its %u copies lowered to %.4g texels per unit to fit one %ux%u atlas",
                 s->instances[first].name, g->count - 1, 0.85 * l->instances[first].texel_density, cfg->max_atlas_size,
                 cfg->max_atlas_size);
        for (uint32_t j = g->first; j < g->first + g->count; j++)
            l->instances[order[j]].texel_density *= 0.85;
        /* the block again at the lower density: its padding stays atlas.padding texels */
        free(g->block);
        g->block = NULL;
        st = make_block(s, cfg, l, first, g, NULL, err);
    }
    if (st == LMB_ERR_INPUT && r.failed_group < ng && l->density.automatic) /* the layout may light it by probes */
        l->unfit_mesh = s->instances[order[groups[r.failed_group].first]].mesh;
    if (st == LMB_ERR_INPUT && r.failed_group < ng)
        st = lmb_error_set(err, LMB_ERR_INPUT,
                           "instance '%s' (mesh '%s') and the copies that share its layout do not fit in one %ux%u "
                           "atlas at %g texels per unit: lower texel_density (or a density_overrides entry), use "
                           "texel_density: auto, or raise atlas.max_size",
                           s->instances[order[groups[r.failed_group].first]].name,
                           s->meshes[s->instances[order[groups[r.failed_group].first]].mesh].name, cfg->max_atlas_size,
                           cfg->max_atlas_size, l->instances[order[groups[r.failed_group].first]].texel_density);
    uint32_t base = l->atlas_count;
    if (st == LMB_OK) {
        uint32_t *nw = realloc(l->width, (base + r.atlas_count + 1) * sizeof *nw);
        if (nw) l->width = nw;
        uint32_t *nh = realloc(l->height, (base + r.atlas_count + 1) * sizeof *nh);
        if (nh) l->height = nh;
        if (!nw || !nh)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    }
    for (uint32_t a = 0; st == LMB_OK && a < r.atlas_count; a++) {
        l->width[base + a] = r.width[a];
        l->height[base + a] = r.height[a];
    }
    if (st == LMB_OK)
        l->atlas_count += r.atlas_count;
    lmb_layout_block *blocks = st == LMB_OK ? realloc(l->blocks, ((size_t)l->block_count + ng + 1) * sizeof *blocks) : NULL;
    if (st == LMB_OK && !blocks)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    if (blocks)
        l->blocks = blocks;
    for (uint32_t g = 0; st == LMB_OK && g < ng; g++) {
        uint32_t block = l->block_count++;
        l->blocks[block].mesh = s->instances[order[groups[g].first]].mesh;
        l->blocks[block].uv = groups[g].block; /* the layout owns it now */
        groups[g].block = NULL;
        for (uint32_t j = groups[g].first; j < groups[g].first + groups[g].count; j++) {
            lmb_layout_instance *li = &l->instances[order[j]];
            li->atlas = base + r.atlas[j];
            li->shared_layout = !l->meshes[s->instances[order[j]].mesh].kept_uv1;
            double W = l->width[li->atlas], H = l->height[li->atlas], rw = items[j].w, rh = items[j].h;
            li->scale_offset[0] = rw / W;
            li->scale_offset[1] = rh / H;
            li->scale_offset[2] = r.x[j] / W;
            li->scale_offset[3] = r.y[j] / H;
            li->block = block; /* its triangles: the block at (x, y), w x h texels (lmb_layout_uv) */
            li->rect[0] = rw;
            li->rect[1] = rh;
            li->rect[2] = r.x[j];
            li->rect[3] = r.y[j];
            l->chart_total += l->meshes[s->instances[order[j]].mesh].charts.chart_count;
        }
    }
    for (uint32_t g = 0; groups && g < ng; g++)
        free(groups[g].block);
    lmb_rect_result_free(&r);
    free(order);
    free(groups);
    free(items);
    free(area);
    return st;
}
