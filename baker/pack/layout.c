/*
 * Scene lightmap layout (see layout.h). Texel density per instance: density.h (an
 * override, the explicit texel_density, or auto from the texel budget). Each chart of an instance is scaled by density * sqrt(world area / UV area), so texels
 * are square in world units whatever the instance's (even non-uniform) scale.
 * Atlases: everything is packed in one run, every instance whole in one atlas (pack.h's
 * groups); kept TEXCOORD_1 instances get atlases of their own first.
 */
#include "../util/clock.h"
#include "layout.h"
#include "coverage.h"
#include "layout_internal.h"
#include "density.h"
#include "hidden_skip.h"
#include "keep_uv1.h"
#include "rect_instances.h"
#include "pack.h"
#include "unwrap/metrics.h"
#include "../util/mat4.h"

#include <omp.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static lmb_status build_soup(const lmb_scene *s, uint32_t mesh, lmb_mesh_soup *soup, lmb_error *err)
{
    const lmb_mesh *m = &s->meshes[mesh];
    memset(soup, 0, sizeof *soup);
    for (uint32_t p = 0; p < m->primitive_count; p++) {
        soup->vertex_count += s->primitives[m->first_primitive + p].vertex_count;
        soup->triangle_count += s->primitives[m->first_primitive + p].triangle_count;
    }
    soup->positions = malloc(((size_t)soup->vertex_count * 3 + 1) * sizeof *soup->positions);
    soup->indices = malloc(((size_t)soup->triangle_count * 3 + 1) * sizeof *soup->indices);
    soup->skip = malloc((size_t)soup->triangle_count + 1);
    soup->flat = calloc((size_t)soup->triangle_count + 1, 1);
    soup->normals = calloc((size_t)soup->vertex_count * 3 + 1, sizeof *soup->normals);
    if (!soup->positions || !soup->indices || !soup->skip || !soup->normals || !soup->flat)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "mesh '%s': out of memory", m->name);
    uint32_t vbase = 0, tbase = 0;
    for (uint32_t p = 0; p < m->primitive_count; p++) {
        const lmb_primitive *pr = &s->primitives[m->first_primitive + p];
        memcpy(soup->positions + 3 * (size_t)vbase, pr->positions, (size_t)pr->vertex_count * 3 * sizeof(float));
        for (uint32_t i = 0; i < 3 * pr->triangle_count; i++)
            soup->indices[3 * (size_t)tbase + i] = pr->indices[i] + vbase;
        memcpy(soup->skip + tbase, pr->degenerate, pr->triangle_count);
        if (pr->normals)
            memcpy(soup->normals + 3 * (size_t)vbase, pr->normals, (size_t)pr->vertex_count * 3 * sizeof(float));
        else /* glTF 3.7.2.1: no NORMAL means flat normals, whatever vertices the faces share */
            memset(soup->flat + tbase, 1, pr->triangle_count);
        vbase += pr->vertex_count;
        tbase += pr->triangle_count;
    }
    return LMB_OK;
}

double lmb_triangle_area(const double q[9])
{
    double e1[3] = {q[3] - q[0], q[4] - q[1], q[5] - q[2]}, e2[3] = {q[6] - q[0], q[7] - q[1], q[8] - q[2]};
    double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2], z = e1[0] * e2[1] - e1[1] * e2[0];
    return 0.5 * sqrt(x * x + y * y + z * z);
}

void lmb_layout_world_triangle(const lmb_scene *s, const lmb_layout *l, uint32_t i, uint32_t f, double out[9])
{
    const lmb_instance *in = &s->instances[i];
    const lmb_mesh_soup *soup = &l->meshes[in->mesh].soup;
    for (int k = 0; k < 3; k++) {
        const float *p = soup->positions + 3 * soup->indices[3 * f + k];
        double q[3] = {p[0], p[1], p[2]};
        lmb_mat4_point(in->world, q, out + 3 * k);
    }
}

/* Scales instance i's charts into uv (6 per mesh triangle; texel units, chart-local) and returns
 * its texel area. */
double lmb_layout_scale_instance(const lmb_scene *s, const lmb_layout *l, uint32_t i, double *uv)
{
    const lmb_layout_instance *li = &l->instances[i];
    const lmb_layout_mesh *lm = &l->meshes[s->instances[i].mesh];
    const lmb_charts *c = &lm->charts;
    double texels = 0;
    for (uint32_t k = 0; k < c->chart_count; k++) {
        double aw = 0, auv = 0, q[9];
        for (uint32_t j = c->first[k]; j < c->first[k + 1]; j++) {
            uint32_t f = c->order[j];
            const double *u = c->uv + 6 * f;
            lmb_layout_world_triangle(s, l, i, f, q);
            aw += lmb_triangle_area(q);
            auv += 0.5 * fabs((u[2] - u[0]) * (u[5] - u[1]) - (u[4] - u[0]) * (u[3] - u[1]));
        }
        double sc = auv > 0 ? li->texel_density * sqrt(aw / auv) : 0;
        for (uint32_t j = c->first[k]; j < c->first[k + 1]; j++) {
            uint32_t f = c->order[j];
            for (int d = 0; d < 6; d++)
                uv[6 * f + d] = c->uv[6 * f + d] * sc;
        }
        texels += aw * li->texel_density * li->texel_density;
    }
    return texels;
}

/* Packs the charts of instances list[0..n) together, each instance whole in one atlas (a
 * group of the packer). Returns the instance that did not fit in *failed (or UINT32_MAX). */
static lmb_status pack_instances(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, const uint32_t *list,
                                 uint32_t n, uint32_t *failed, lmb_error *err)
{
    uint32_t nc = 0;
    *failed = UINT32_MAX;
    for (uint32_t j = 0; j < n; j++)
        nc += l->meshes[s->instances[list[j]].mesh].charts.chart_count;
    lmb_pack_chart *charts = calloc((size_t)nc + 1, sizeof *charts);
    uint32_t *owner = malloc(((size_t)nc + 1) * sizeof *owner), *chart_id = malloc(((size_t)nc + 1) * sizeof *chart_id);
    double **bufs = calloc((size_t)nc + 1, sizeof *bufs);
    lmb_pack_result r;
    memset(&r, 0, sizeof r);
    lmb_status st = (!charts || !owner || !chart_id || !bufs)
                        ? lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory") : LMB_OK;
    uint32_t q = 0;
    for (uint32_t j = 0; j < n && st == LMB_OK; j++) {
        const lmb_charts *c = &l->meshes[s->instances[list[j]].mesh].charts;
        const double *uv1 = l->instances[list[j]].uv1;
        for (uint32_t k = 0; k < c->chart_count && st == LMB_OK; k++, q++) {
            uint32_t len = c->first[k + 1] - c->first[k];
            bufs[q] = malloc(sizeof(double) * 6 * len + 1);
            if (!bufs[q]) {
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
                break;
            }
            for (uint32_t t = 0; t < len; t++)
                memcpy(bufs[q] + 6 * t, uv1 + 6 * c->order[c->first[k] + t], 6 * sizeof(double));
            charts[q].triangle_count = len;
            charts[q].uv = bufs[q];
            charts[q].group = j;
            owner[q] = list[j];
            chart_id[q] = k;
        }
    }
    lmb_pack_options opt = {cfg->max_atlas_size, cfg->padding, 1, cfg->threads, lmb_pack_block_for(cfg)};
    if (st == LMB_OK)
        st = lmb_pack_charts(charts, nc, &opt, &r, err);
    if (st == LMB_ERR_INPUT && r.failed_group < n) {
        uint32_t i = list[r.failed_group];
        *failed = i;
        if (r.failed_chart != UINT32_MAX) {
            /* name the instance and mesh the chart belongs to: that is what a user can change */
            char detail[sizeof err->message];
            const char *rest = strstr(err->message, " is ");
            snprintf(detail, sizeof detail, "%s", rest ? rest + 4 : err->message);
            st = lmb_error_set(err, LMB_ERR_INPUT, "instance '%s' (mesh '%s'): a chart is %s (texel_density %g)",
                               s->instances[i].name, s->meshes[s->instances[i].mesh].name, detail,
                               l->instances[i].texel_density);
        } else {
            st = lmb_error_set(err, LMB_ERR_INPUT,
                               "instance '%s' (mesh '%s') does not fit in one %ux%u atlas at %g texels per unit: "
                               "lower texel_density (or a density_overrides entry; about %.4g is estimated to fit), "
                               "use texel_density: auto, or raise atlas.max_size",
                               s->instances[i].name, s->meshes[s->instances[i].mesh].name, cfg->max_atlas_size,
                               cfg->max_atlas_size, l->instances[i].texel_density, lmb_density_fit(s, l, cfg, i));
        }
    }
    if (st == LMB_OK) {
        uint32_t base = l->atlas_count;
        uint32_t *w = realloc(l->width, (base + r.atlas_count + 1) * sizeof *w);
        if (w) l->width = w;
        uint32_t *h = realloc(l->height, (base + r.atlas_count + 1) * sizeof *h);
        if (h) l->height = h;
        if (!w || !h)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "pack: out of memory");
        for (uint32_t a = 0; st == LMB_OK && a < r.atlas_count; a++) {
            l->width[base + a] = r.width[a];
            l->height[base + a] = r.height[a];
        }
        if (st == LMB_OK)
            l->atlas_count += r.atlas_count;
        for (uint32_t c = 0; st == LMB_OK && c < nc; c++) {
            const lmb_charts *ch = &l->meshes[s->instances[owner[c]].mesh].charts;
            lmb_layout_instance *li = &l->instances[owner[c]];
            const double *m = r.placements[c].m;
            li->atlas = base + r.placements[c].atlas;
            for (uint32_t t = ch->first[chart_id[c]]; t < ch->first[chart_id[c] + 1]; t++) {
                double *u = li->uv1 + 6 * ch->order[t];
                for (int k = 0; k < 3; k++) {
                    double x = u[2 * k], y = u[2 * k + 1];
                    u[2 * k] = m[0] * x + m[1] * y + m[2];
                    u[2 * k + 1] = m[3] * x + m[4] * y + m[5];
                }
            }
        }
        l->chart_total += nc;
    }
    lmb_pack_result_free(&r);
    for (uint32_t c = 0; bufs && c < nc; c++)
        free(bufs[c]);
    free(bufs);
    free(charts);
    free(owner);
    free(chart_id);
    return st;
}

/* Packs; with texel_density auto, an instance the estimate let through but the packer could
 * not fit is lowered (x 0.85, a warning names it) and the packing redone. */
static lmb_status pack_level(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, const uint32_t *list,
                             uint32_t n, const lmb_log *log, lmb_error *err)
{
    for (int attempt = 0;; attempt++) {
        uint32_t failed;
        lmb_status st = pack_instances(s, cfg, l, list, n, &failed, err);
        if (st != LMB_ERR_INPUT || !l->density.automatic || failed == UINT32_MAX || attempt >= 24 ||
            l->meshes[s->instances[failed].mesh].kept_uv1 || lmb_density_override_for(s, cfg, failed) > 0)
            return st;
        lmb_layout_instance *li = &l->instances[failed];
        li->texel_density *= 0.85;
        lmb_warn(log, "instance '%s' (mesh '%s') lowered to %.4g texels per unit to fit one %ux%u atlas",
                 s->instances[failed].name, s->meshes[s->instances[failed].mesh].name, li->texel_density,
                 cfg->max_atlas_size, cfg->max_atlas_size);
        /* a failed packing wrote nothing back: only this instance's charts change scale */
        lmb_layout_scale_instance(s, l, failed, li->uv1);
    }
}

/* A mesh and its triangles, for ordering the unwrap (largest first). */
typedef struct mesh_size {
    uint64_t triangles;
    uint32_t mesh;
} mesh_size;

static int by_triangles_desc(const void *pa, const void *pb)
{
    const mesh_size *a = pa, *b = pb;
    if (a->triangles != b->triangles)
        return a->triangles < b->triangles ? 1 : -1;
    return a->mesh < b->mesh ? -1 : a->mesh > b->mesh;
}

/* Every used mesh unwrapped (or its TEXCOORD_1 kept), the meshes in parallel, largest first:
 * a mesh's charts depend on the mesh and the options only, not on the thread that made them.
 * Progress comes from the driving thread (OpenMP's thread 0) as meshes finish. glue_all: the
 * second unwrap of a level whose charts cannot keep the texel budget (the soups exist; every
 * chart is glued onto a neighbour where it can be, whatever its width). */
static lmb_status unwrap_meshes(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, lmb_progress_fn progress,
                                void *user, int glue_all, lmb_error *err)
{
    uint64_t total = 0;
    for (uint32_t m = 0; m < s->mesh_count; m++)
        total += l->meshes[m].used ? s->meshes[m].triangle_count : 0;
    for (uint32_t m = 0; m < s->mesh_count; m++) {
        lmb_status st = LMB_OK;
        if (glue_all)
            lmb_charts_free(&l->meshes[m].charts);
        else if (l->meshes[m].used)
            st = build_soup(s, m, &l->meshes[m].soup, err);
        if (st != LMB_OK)
            return st;
    }
    lmb_status hidden_st = glue_all || !cfg->skip_hidden ? LMB_OK : lmb_layout_skip_hidden(s, cfg, l, err);
    if (hidden_st != LMB_OK) /* once: the glue_all pass keeps the skip flags */
        return hidden_st;
    /* narrow charts are glued at the density each mesh is expected to get */
    double *expected = calloc((size_t)s->mesh_count + 1, sizeof *expected);
    mesh_size *order = calloc((size_t)s->mesh_count + 1, sizeof *order);
    lmb_error *errs = calloc((size_t)s->mesh_count + 1, sizeof *errs);
    if (!expected || !order || !errs) {
        free(expected);
        free(order);
        free(errs);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    }
    lmb_density_expected(s, cfg, l, expected);
    uint32_t n = 0;
    for (uint32_t m = 0; m < s->mesh_count; m++)
        if (l->meshes[m].used)
            order[n++] = (mesh_size){s->meshes[m].triangle_count, m};
    qsort(order, n, sizeof *order, by_triangles_desc);
    uint64_t done = 0, reported = 0; /* triangles of the meshes finished; the last count thread 0 reported */
    if (progress)
        progress(user, "unwrap", 0, total);
    int64_t failed = INT64_MAX;
    int threads = cfg->threads ? (int)cfg->threads : omp_get_max_threads();
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (uint32_t k = 0; k < n; k++) {
        uint32_t m = order[k].mesh;
        lmb_layout_mesh *lm = &l->meshes[m];
        lmb_unwrap_options opt;
        lmb_unwrap_options_default(&opt);
        opt.name = s->meshes[m].name;
        opt.glue_below = cfg->min_chart_texels > 0 && expected[m] > 0 ? cfg->min_chart_texels / expected[m] : 0;
        if (glue_all)
            opt.glue_below = INFINITY;
        double t0 = lmb_seconds();
        lmb_unwrap_input in = {lm->soup.vertex_count, lm->soup.positions, lm->soup.triangle_count, lm->soup.indices,
                               lm->soup.skip};
        lm->kept_uv1 = cfg->keep_uv1 && lmb_mesh_has_uv1(s, m);
        lmb_status st = lm->kept_uv1 ? lmb_charts_from_uv1(s, m, &lm->soup, &lm->charts, &errs[m])
                                     : lmb_unwrap_mesh(&in, &opt, &lm->charts, &errs[m]);
        lm->chart_seconds += lmb_seconds() - t0;
        if (st != LMB_OK) {
#pragma omp critical(lmb_unwrap_failed)
            failed = (int64_t)m < failed ? (int64_t)m : failed;
        }
        uint64_t now;
#pragma omp atomic capture
        now = done += s->meshes[m].triangle_count;
        if (progress && omp_get_thread_num() == 0) {
            progress(user, "unwrap", now, total);
            reported = now;
        }
    }
    lmb_status st = LMB_OK;
    if (failed != INT64_MAX) { /* the first mesh's error, whatever the threads did */
        *err = errs[failed];
        st = err->status;
    } else if (progress && reported != total) {
        progress(user, "unwrap", total, total);
    }
    free(expected);
    free(order);
    free(errs);
    return st;
}

/* One placement of the lightmapped instances list[0..n) (their charts unwrapped, measures
 * taken): densities for `budget` texels (quietly: lmb_layout_build said them for the whole
 * budget), then packing. log: the packer's messages, NULL to keep a trial quiet. */
lmb_status lmb_layout_place(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, const uint32_t *all, uint32_t n,
                            const lmb_density_measures *measures, uint64_t budget, const lmb_log *log, lmb_error *err)
{
    uint32_t *list = malloc(((size_t)n + 1) * sizeof *list);
    if (!list)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    memcpy(list, all, (size_t)n * sizeof *list);
    lmb_status st = lmb_density_choose(s, cfg, l, list, n, measures, budget, NULL, &l->density, err);
    /* atlas.share_meshes: the lightmapped nodes (not instanced copies) of each mesh */
    uint32_t *users = calloc((size_t)s->mesh_count + 1, sizeof *users);
    uint8_t *as_rect = calloc((size_t)s->instance_count + 1, 1);
    if (st == LMB_OK && (!users || !as_rect))
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    for (uint32_t j = 0; st == LMB_OK && j < n; j++)
        users[s->instances[list[j]].mesh] += s->instances[list[j]].gpu_instance < 0;
    for (uint32_t j = 0; st == LMB_OK && j < n; j++) {
        const lmb_instance *in = &s->instances[list[j]];
        as_rect[list[j]] = l->meshes[in->mesh].kept_uv1 || in->gpu_instance >= 0 ||
                           (cfg->share_meshes && users[in->mesh] >= 2);
    }
    int out_of_memory = 0, threads = cfg->threads ? (int)cfg->threads : omp_get_max_threads();
    uint32_t to_scale = st == LMB_OK ? n : 0;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16) reduction(| : out_of_memory)
    for (uint32_t j = 0; j < to_scale; j++) { /* the packed instances' charts at their density: their own uv1 */
        lmb_layout_instance *li = &l->instances[list[j]];
        li->lightmapped = 1;
        li->block = UINT32_MAX;
        li->triangle_count = l->meshes[s->instances[list[j]].mesh].soup.triangle_count;
        if (as_rect[list[j]])
            continue; /* a rectangle: its block and place say where its triangles are */
        li->uv1 = calloc((size_t)li->triangle_count * 6 + 1, sizeof *li->uv1);
        if (!li->uv1)
            out_of_memory = 1;
        else
            lmb_layout_scale_instance(s, l, list[j], li->uv1);
    }
    if (out_of_memory)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    free(users);
    /* kept TEXCOORD_1 and instanced copies: rectangles of shared atlases, after the packed ones;
     * the rest is packed chart by chart */
    uint32_t packed = 0, kept = 0;
    uint32_t *kept_list = malloc(((size_t)n + 1) * sizeof *kept_list);
    if (st == LMB_OK && !kept_list)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    for (uint32_t j = 0; st == LMB_OK && j < n; j++) {
        lmb_layout_instance *li = &l->instances[list[j]];
        li->scale_offset[0] = li->scale_offset[1] = 1;
        if (as_rect[list[j]])
            kept_list[kept++] = list[j];
        else
            list[packed++] = list[j];
    }
    if (st == LMB_OK && packed)
        st = pack_level(s, cfg, l, list, packed, log, err);
    if (st == LMB_OK && kept)
        st = lmb_layout_rect_instances(s, cfg, l, kept_list, kept, log, err);
    free(kept_list);
    free(as_rect);
    free(list);
    return st;
}

/* Undoes place(): the charts stay, every placement goes. */
void lmb_layout_unplace(lmb_layout *l)
{
    for (uint32_t i = 0; i < l->instance_count; i++) {
        free(l->instances[i].uv1);
        memset(&l->instances[i], 0, sizeof l->instances[i]);
    }
    for (uint32_t b = 0; l->blocks && b < l->block_count; b++)
        free(l->blocks[b].uv);
    free(l->blocks);
    free(l->width);
    free(l->height);
    l->blocks = NULL;
    l->width = l->height = NULL;
    l->block_count = l->atlas_count = l->chart_total = 0;
}

/* Charts the instances list[0..n) place: their meshes' charts, once per instance. */
static uint64_t placed_charts(const lmb_scene *s, const lmb_layout *l, const uint32_t *list, uint32_t n)
{
    uint64_t charts = 0;
    for (uint32_t k = 0; k < n; k++)
        charts += l->meshes[s->instances[list[k]].mesh].charts.chart_count;
    return charts;
}

lmb_status lmb_layout_build(const lmb_scene *s, const lmb_config *cfg, lmb_progress_fn progress, void *user,
                            const lmb_log *log, lmb_layout *l, lmb_error *err)
{
    memset(l, 0, sizeof *l);
    l->mesh_count = s->mesh_count;
    l->instance_count = s->instance_count;
    l->unfit_mesh = UINT32_MAX;
    l->meshes = calloc((size_t)s->mesh_count + 1, sizeof *l->meshes);
    l->instances = calloc((size_t)s->instance_count + 1, sizeof *l->instances);
    uint32_t *list = malloc(((size_t)s->instance_count + 1) * sizeof *list), n = 0;
    if (!l->meshes || !l->instances || !list) {
        free(list);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    }
    for (uint32_t i = 0; i < s->instance_count; i++)
        if (s->instances[i].lightmapped) {
            l->meshes[s->instances[i].mesh].used = 1;
            list[n++] = i;
        }
    lmb_status st = unwrap_meshes(s, cfg, l, progress, user, 0, err);
    if (st == LMB_OK)
        lmb_layout_report_hidden(s, l, log);
    lmb_density_measures measures = {NULL, NULL, NULL};
    if (st == LMB_OK && progress)
        progress(user, "texel density", 0, 1);
    if (st == LMB_OK)
        st = lmb_density_measure(s, cfg, l, list, n, &measures, err);
    /* densities for the whole budget: its messages, and explicit densities refused before packing */
    if (st == LMB_OK)
        st = lmb_density_choose(s, cfg, l, list, n, &measures, lmb_config_atlas_texels(cfg), log, &l->density, err);
    if (st == LMB_OK && progress)
        progress(user, "texel density", 1, 1);
    if (st == LMB_OK && progress)
        progress(user, "pack", 0, 1);
    double t0 = lmb_seconds();
    int over = 0;
    if (st == LMB_OK)
        st = lmb_layout_place_within_budget(s, cfg, l, list, n, &measures, log, 1, &over, err);
    int unfit = st == LMB_ERR_INPUT && l->unfit_mesh != UINT32_MAX; /* copies that fit no atlas at any density */
    if (st == LMB_OK && over) {
        /* no density keeps the budget with these charts: glue every chart that can be, and again
         * (unless gluing leaves every mesh's charts as they were) */
        uint64_t before = placed_charts(s, l, list, n);
        st = unwrap_meshes(s, cfg, l, NULL, NULL, 1, err);
        uint64_t after = st == LMB_OK ? placed_charts(s, l, list, n) : before;
        if (st == LMB_OK && after != before) {
            lmb_density_measures_free(&measures);
            st = lmb_density_measure(s, cfg, l, list, n, &measures, err);
            if (st == LMB_OK)
                st = lmb_layout_place_within_budget(s, cfg, l, list, n, &measures, log, 1, &over, err);
        }
        if (st == LMB_OK)
            lmb_info(log, "texel budget: the charts could not keep it at any density; every chart that can be was "
                     "glued onto a neighbour: %llu charts, were %llu%s", (unsigned long long)after,
                     (unsigned long long)before, over ? ", and still no density keeps it" : "");
    }
    if ((st == LMB_OK && over) || unfit) /* still none: the props whose charts cost the most go to the probes */
        st = lmb_layout_light_by_probes(s, cfg, l, list, n, &measures, log, st, err);
    l->pack_seconds = lmb_seconds() - t0;
    if (progress && st == LMB_OK)
        progress(user, "pack", 1, 1);
    lmb_density_measures_free(&measures);
    free(list);
    return st;
}

void lmb_layout_free(lmb_layout *l)
{
    for (uint32_t m = 0; l->meshes && m < l->mesh_count; m++) {
        free(l->meshes[m].soup.positions);
        free(l->meshes[m].soup.normals);
        free(l->meshes[m].soup.indices);
        free(l->meshes[m].soup.skip);
        free(l->meshes[m].soup.flat);
        lmb_charts_free(&l->meshes[m].charts);
    }
    for (uint32_t i = 0; l->instances && i < l->instance_count; i++)
        free(l->instances[i].uv1);
    for (uint32_t b = 0; l->blocks && b < l->block_count; b++)
        free(l->blocks[b].uv);
    free(l->blocks);
    free(l->meshes);
    free(l->instances);
    free(l->width);
    free(l->height);
    memset(l, 0, sizeof *l);
}
