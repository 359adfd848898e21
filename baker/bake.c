/*
 * The bake pipeline driver: layout (unwrap + pack) -> ray-tracing scene, textures, lights ->
 * lighting (lighting.h: texels, direct light, bounce passes, final gather, dilation) ->
 * images (write/atlas_images.h); then the final gather's irradiance-cache records
 * (write/records_file.h) and the glTF with TEXCOORD_1 and MOZ_lightmap. Output is written
 * into a staging folder beside outdir and swapped into place only when everything succeeded
 * (write/output_dir.h), so a failed or killed bake leaves nothing behind; outdir may
 * not be the input's own folder (the input and its .bin files are never written over).
 */
#include <lmbake/lmbake.h>

#include "util/clock.h"
#include "steps/plan.h"
#include "steps/runner.h"
#include "lighting.h"
#include "lights/direct.h"
#include "load/gltf_adapter.h"
#include "load/textures.h"
#include "pack/layout.h"
#include "post/dilate.h"
#include "post/fireflies.h"
#include "seams/seams.h"
#include "texels/texels.h"
#include "write/gltf_write.h"
#include "write/ktx2.h"
#include "write/atlas_images.h"
#include "write/output_dir.h"
#include "write/records_file.h"

#include <omp.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* New vertices of one glTF primitive: one per (original vertex, chart). */
static lmb_status instance_primitives(const lmb_scene *s, const lmb_layout *l, uint32_t i, lmb_gltf_prim_out **out,
                                      uint32_t *count, void ***owned, uint32_t *owned_n, lmb_error *err);

/* Texture files the input references by relative path go along with the output glTF
 * (read from the view before lightmap images are added; tinygltf keeps the strings). */
static void copy_textures(lmb_scene *s, lmb_output_dir *od, const lmb_log *log)
{
    const lmb_gltf_view *v = lmb_gltf_get_view(s->doc);
    for (uint32_t k = 0; k < v->image_count; k++) {
        const char *uri = v->image_uris[k];
        lmb_error e;
        if (uri[0] && strncmp(uri, "data:", 5) != 0 && lmb_output_dir_copy_input_file(od, s->path, uri, &e) != LMB_OK)
            lmb_warn(log, "%s: texture not copied to the output: %s", s->path, e.message);
    }
}

/* The rectangles of every EXT_mesh_gpu_instancing copy of `node` (in the extension's order;
 * copies without a lightmap get 0s), written with the node's lightmapped mesh. */
static lmb_status instanced_node(const lmb_scene *s, const lmb_layout *l, uint32_t node, const lmb_gltf_prim_out *prims,
                                 uint32_t n, int32_t texture, int32_t direction_texture, lmb_error *err)
{
    uint32_t copies = 0;
    for (uint32_t i = 0; i < s->instance_count; i++)
        if (s->instances[i].node == node && s->instances[i].gpu_instance >= 0)
            copies = (uint32_t)s->instances[i].gpu_instance + 1 > copies ? (uint32_t)s->instances[i].gpu_instance + 1
                                                                        : copies;
    float *so = calloc(4 * (size_t)copies + 1, sizeof *so);
    if (!so)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: out of memory");
    for (uint32_t i = 0; i < s->instance_count; i++)
        if (s->instances[i].node == node && s->instances[i].gpu_instance >= 0 && l->instances[i].lightmapped)
            for (int k = 0; k < 4; k++)
                so[4 * (size_t)s->instances[i].gpu_instance + k] = (float)l->instances[i].scale_offset[k];
    lmb_status st = lmb_gltf_lightmap_instanced_node(s->doc, node, prims, n, texture, direction_texture, so, copies, err);
    free(so);
    return st;
}

/* One instance's new primitives (instance_primitives) and the arrays they point into. */
typedef struct instance_prims {
    int needed;
    lmb_gltf_prim_out *prims;
    uint32_t n, owned_n;
    void **owned;
    lmb_error err;
} instance_prims;

static lmb_status write_gltf(lmb_scene *s, const lmb_config *cfg, const lmb_layout *l, const char *dir,
                             const char *stem, const lmb_atlas_output *outputs, const lmb_ic_points *records,
                             int directional, int shadowmask, lmb_error *err)
{
    int32_t *tex = malloc(((size_t)l->atlas_count + 1) * 2 * sizeof *tex), *dir_tex = tex + l->atlas_count + 1;
    if (!tex)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: out of memory");
    lmb_status st = LMB_OK;
    if (s->default_albedo_given)
        lmb_gltf_set_default_albedo(s->doc, s->default_albedo);
    for (uint32_t a = 0; a < l->atlas_count && st == LMB_OK; a++) {
        char png[512], hdr[512], exr[512], ktx2[512], rgbm[512], dpng[512], dexr[512], dktx2[512], mask[512];
        snprintf(png, sizeof png, "%s-lightmap-%u.png", stem, a);
        snprintf(hdr, sizeof hdr, "%s-lightmap-%u.hdr", stem, a);
        snprintf(exr, sizeof exr, "%s-lightmap-%u.exr", stem, a);
        snprintf(ktx2, sizeof ktx2, "%s-lightmap-%u.ktx2", stem, a);
        snprintf(rgbm, sizeof rgbm, "%s-lightmap-%u-rgbm.png", stem, a);
        snprintf(dpng, sizeof dpng, "%s-lightmap-%u-dir.png", stem, a);
        snprintf(dexr, sizeof dexr, "%s-lightmap-%u-dir.exr", stem, a);
        snprintf(dktx2, sizeof dktx2, "%s-lightmap-%u-dir.ktx2", stem, a);
        snprintf(mask, sizeof mask, "%s-lightmap-%u-shadowmask.png", stem, a);
        unsigned f = cfg->output_formats;
        lmb_gltf_lightmap_files files = {
            .atlas = a, .width = l->width[a], .height = l->height[a],
            .radiance = cfg->output_scale == LMB_SCALE_RADIANCE,
            .png = png, .hdr = hdr,
            .exr = f & LMB_OUTPUT_EXR ? exr : NULL,
            .ktx2 = f & LMB_OUTPUT_KTX2 ? ktx2 : NULL,
            .rgbm = f & LMB_OUTPUT_RGBM ? rgbm : NULL,
            .rgbm_range = outputs[a].rgbm_range,
            .ktx2_vkformat = lmb_ktx2_vkformat((lmb_ktx2_format)cfg->ktx2_format),
            .direction_png = directional ? dpng : NULL,
            .direction_exr = directional ? dexr : NULL,
            .direction_ktx2 = directional && (f & LMB_OUTPUT_KTX2) ? dktx2 : NULL,
            .shadowmask = shadowmask ? mask : NULL};
        tex[a] = lmb_gltf_add_lightmap_texture(s->doc, &files, err);
        dir_tex[a] = directional && tex[a] >= 0 ? lmb_gltf_add_direction_texture(s->doc, dpng, err) : -1;
        if (tex[a] < 0 || (directional && dir_tex[a] < 0))
            st = LMB_ERR_INTERNAL;
    }
    uint8_t *node_done = calloc((size_t)s->node_count + 1, 1);
    int64_t *shared_by = malloc(((size_t)s->mesh_count + 1) * sizeof *shared_by); /* mesh -> its first node's index */
    instance_prims *prims = calloc((size_t)s->instance_count + 1, sizeof *prims);
    if (!node_done || !shared_by || !prims)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: out of memory");
    for (uint32_t m = 0; shared_by && m < s->mesh_count; m++)
        shared_by[m] = -1;
    /* which instances write primitives of their own (the rest share a node's or a mesh's), as
     * the writing below visits them */
    for (uint32_t i = 0; st == LMB_OK && i < s->instance_count; i++) {
        const lmb_instance *in = &s->instances[i];
        const lmb_layout_instance *li = &l->instances[i];
        if (!li->lightmapped || (in->gpu_instance >= 0 && node_done[in->node]))
            continue;
        if (in->gpu_instance < 0 && li->shared_layout && shared_by[in->mesh] >= 0)
            continue;
        prims[i].needed = 1;
        if (in->gpu_instance < 0 && li->shared_layout)
            shared_by[in->mesh] = in->node;
        node_done[in->node] = 1;
    }
    /* their vertices in parallel (the work); the glTF document is written on one thread */
    int threads = cfg->threads ? (int)cfg->threads : omp_get_max_threads(), failed = 0;
    uint32_t to_build = st == LMB_OK ? s->instance_count : 0;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) reduction(| : failed)
    for (uint32_t i = 0; i < to_build; i++)
        if (prims[i].needed)
            failed |= instance_primitives(s, l, i, &prims[i].prims, &prims[i].n, &prims[i].owned, &prims[i].owned_n,
                                          &prims[i].err) != LMB_OK;
    for (uint32_t i = 0; failed && i < s->instance_count; i++) /* the first instance's error */
        if (prims[i].needed && prims[i].err.status != LMB_OK) {
            *err = prims[i].err;
            st = err->status;
            break;
        }
    if (node_done)
        memset(node_done, 0, (size_t)s->node_count + 1);
    for (uint32_t m = 0; shared_by && m < s->mesh_count; m++)
        shared_by[m] = -1;
    for (uint32_t i = 0; i < s->instance_count && st == LMB_OK; i++) {
        const lmb_instance *in = &s->instances[i];
        const lmb_layout_instance *li = &l->instances[i];
        if (!li->lightmapped || (in->gpu_instance >= 0 && node_done[in->node]))
            continue;
        if (in->gpu_instance < 0 && li->shared_layout && shared_by[in->mesh] >= 0) { /* atlas.share_meshes */
            st = lmb_gltf_share_lightmapped_mesh(s->doc, in->node, (uint32_t)shared_by[in->mesh], tex[li->atlas],
                                                 li->scale_offset, err);
            continue;
        }
        const lmb_gltf_prim_out *pr = prims[i].prims;
        uint32_t n = prims[i].n;
        int32_t t = tex[l->instances[i].atlas], d = dir_tex[l->instances[i].atlas];
        if (in->gpu_instance >= 0) /* every copy of the node: one mesh, a rectangle each */
            st = instanced_node(s, l, in->node, pr, n, t, d, err);
        else if (li->shared_layout) { /* the first node of a shared mesh */
            st = lmb_gltf_lightmap_shared_mesh(s->doc, in->node, pr, n, t, d, li->scale_offset, err);
            shared_by[in->mesh] = in->node;
        } else
            st = lmb_gltf_lightmap_node(s->doc, in->node, pr, n, t, d, l->instances[i].scale_offset, err);
        node_done[in->node] = 1;
    }
    for (uint32_t i = 0; prims && i < s->instance_count; i++) {
        for (uint32_t k = 0; k < prims[i].owned_n; k++)
            free(prims[i].owned[k]);
        free(prims[i].owned);
        free(prims[i].prims);
    }
    free(prims);
    free(node_done);
    free(shared_by);
    if (st == LMB_OK)
        st = lmb_gltf_set_light_modes(s->doc, s->lights, s->light_count, err);
    char path[8600], bin[512], rec[512];
    lmb_records_file_name(stem, rec, sizeof rec);
    if (st == LMB_OK && records->count) /* the file itself, before the glTF that names it */
        st = lmb_write_records(dir, rec, records, err);
    if (st == LMB_OK && records->count)
        st = lmb_gltf_set_records(s->doc, rec, records->count, err);
    snprintf(path, sizeof path, "%s/%s.gltf", dir, stem);
    snprintf(bin, sizeof bin, "%s-lightmap.bin", stem);
    if (st == LMB_OK)
        st = lmb_gltf_save(s->doc, path, bin, err);
    free(tex);
    return st;
}

static int keep(void ***owned, uint32_t *n, void *p)
{
    void **q = realloc(*owned, (*n + 1) * sizeof *q);
    if (!q || !p) {
        free(p);
        if (q)
            *owned = q;
        return 0;
    }
    *owned = q;
    q[(*n)++] = p;
    return 1;
}

static int key_order(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static lmb_status instance_primitives(const lmb_scene *s, const lmb_layout *l, uint32_t i, lmb_gltf_prim_out **out,
                                      uint32_t *count, void ***owned, uint32_t *owned_n, lmb_error *err)
{
    const lmb_mesh *mesh = &s->meshes[s->instances[i].mesh];
    const lmb_layout_mesh *lm = &l->meshes[s->instances[i].mesh];
    const lmb_layout_instance *li = &l->instances[i];
    double w = l->width[li->atlas], h = l->height[li->atlas];
    *out = calloc(mesh->primitive_count + 1, sizeof **out);
    if (!*out)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: out of memory");
    uint32_t tbase = 0;
    for (uint32_t p = 0; p < mesh->primitive_count; p++) {
        const lmb_primitive *pr = &s->primitives[mesh->first_primitive + p];
        uint32_t nt = pr->triangle_count, nv = 0;
        /* key (vertex, chart) -> new vertex, by sorting the 3 nt corners */
        uint64_t *key = malloc(((size_t)3 * nt + 1) * sizeof *key);
        uint32_t *idx = malloc(((size_t)3 * nt + 1) * sizeof *idx), *src = malloc(((size_t)3 * nt + 1) * sizeof *src);
        float *pos = malloc(((size_t)9 * nt + 1) * sizeof *pos), *nrm = pr->normals ? malloc(((size_t)9 * nt + 1) * sizeof *nrm) : NULL;
        float *uv0 = pr->uv0 ? malloc(((size_t)6 * nt + 1) * sizeof *uv0) : NULL, *uv1 = malloc(((size_t)6 * nt + 1) * sizeof *uv1);
        int ok = keep(owned, owned_n, key) & keep(owned, owned_n, idx) & keep(owned, owned_n, src) &
                 keep(owned, owned_n, pos) & keep(owned, owned_n, uv1);
        if (pr->normals)
            ok &= keep(owned, owned_n, nrm);
        if (pr->uv0)
            ok &= keep(owned, owned_n, uv0);
        if (!ok)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: out of memory");
        /* brute force but linear: new vertex per corner, then merge equal (vertex, chart) keys */
        for (uint32_t c = 0; c < 3 * nt; c++) {
            uint32_t f = tbase + c / 3, chart = lm->charts.chart_of[f];
            key[c] = ((uint64_t)pr->indices[c] << 32) | (chart == UINT32_MAX ? 0xFFFFFFFFu : chart);
        }
        /* map each distinct key to the first corner that has it (sorted copy + binary search) */
        uint64_t *sorted = malloc(((size_t)3 * nt + 1) * sizeof *sorted);
        if (!keep(owned, owned_n, sorted))
            return lmb_error_set(err, LMB_ERR_INTERNAL, "glTF output: out of memory");
        memcpy(sorted, key, (size_t)3 * nt * sizeof *sorted);
        qsort(sorted, (size_t)3 * nt, sizeof *sorted, key_order); /* O(n log n): shell sort took seconds at 1M */
        uint32_t distinct = 0;
        for (uint32_t a = 0; a < 3 * nt; a++)
            if (a == 0 || sorted[a] != sorted[a - 1])
                sorted[distinct++] = sorted[a];
        for (uint32_t c = 0; c < 3 * nt; c++) {
            uint32_t lo = 0, hi = distinct;
            while (lo < hi) {
                uint32_t mid = (lo + hi) / 2;
                if (sorted[mid] < key[c])
                    lo = mid + 1;
                else
                    hi = mid;
            }
            idx[c] = lo;
            uint32_t v = pr->indices[c], f = tbase + c / 3;
            src[lo] = v;
            memcpy(pos + 3 * (size_t)lo, pr->positions + 3 * (size_t)v, 3 * sizeof(float));
            if (nrm)
                memcpy(nrm + 3 * (size_t)lo, pr->normals + 3 * (size_t)v, 3 * sizeof(float));
            if (uv0)
                memcpy(uv0 + 2 * (size_t)lo, pr->uv0 + 2 * (size_t)v, 2 * sizeof(float));
            if (lm->kept_uv1) { /* its own TEXCOORD_1, untouched: the node's rectangle places it */
                uv1[2 * (size_t)lo] = (float)lm->charts.uv[6 * (size_t)f + 2 * (c % 3)];
                uv1[2 * (size_t)lo + 1] = (float)lm->charts.uv[6 * (size_t)f + 2 * (c % 3) + 1];
            } else if (li->shared_layout) { /* the layout it shares: back through its rectangle */
                const double *so = li->scale_offset;
                uv1[2 * (size_t)lo] = (float)((li->uv1[6 * (size_t)f + 2 * (c % 3)] / w - so[2]) / so[0]);
                uv1[2 * (size_t)lo + 1] = (float)((li->uv1[6 * (size_t)f + 2 * (c % 3) + 1] / h - so[3]) / so[1]);
            } else {
                uv1[2 * (size_t)lo] = (float)(li->uv1[6 * (size_t)f + 2 * (c % 3)] / w);
                uv1[2 * (size_t)lo + 1] = (float)(li->uv1[6 * (size_t)f + 2 * (c % 3) + 1] / h);
            }
        }
        nv = distinct;
        lmb_gltf_prim_out *o = &(*out)[(*count)++];
        o->gltf_primitive = pr->gltf_primitive;
        o->vertex_count = nv;
        o->source = src;
        o->positions = pos;
        o->normals = nrm;
        o->uv0 = uv0;
        o->uv1 = uv1;
        o->triangle_count = nt;
        o->indices = idx;
        tbase += nt;
    }
    return LMB_OK;
}

/* The post stage on the final lightmaps (docs/artists.md): fireflies spread to their
 * neighbours, then seams stitched. */
static lmb_status post_process(const lmb_scene *s, const lmb_config *cfg, const lmb_layout *l, const lmb_rt *rt,
                               lmb_cache *cache, lmb_progress_fn progress, void *user, lmb_bake_stats *stats,
                               const lmb_log *log, lmb_error *err)
{
    lmb_status st = LMB_OK;
    if (st == LMB_OK && cfg->firefly_spread && !cfg->reference) {
        lmb_firefly_stats fs = {0, 0, 0};
        for (uint32_t a = 0; st == LMB_OK && a < l->atlas_count; a++) {
            if (progress)
                progress(user, "fireflies", a, l->atlas_count);
            uint64_t before = fs.texels, last = ~0ull;
            /* a spike shared with its neighbours may leave them above the bound: again, a few times */
            for (int pass = 0; pass < LMB_FIREFLY_PASSES && st == LMB_OK && fs.texels != last; pass++) {
                last = fs.texels;
                double total = fs.total;
                st = lmb_fireflies_spread(cache->irradiance[a], cache->state[a], l->width[a], l->height[a],
                                          (int)cfg->threads, &fs, err);
                if (pass)
                    fs.total = total; /* the atlas's light counts once */
            }
            if (st == LMB_OK && fs.texels > before) /* padding follows the texels it was dilated from */
                st = lmb_dilate(cache->irradiance[a], cache->state[a], l->width[a], l->height[a], (int)cfg->threads,
                                err);
        }
        if (progress && st == LMB_OK)
            progress(user, "fireflies", l->atlas_count, l->atlas_count);
        stats->firefly_texels = fs.texels;
        stats->firefly_moved = fs.total > 0 ? fs.moved / fs.total : 0;
        if (st == LMB_OK && fs.texels)
            lmb_info(log, "fireflies: %llu texels above %gx the median around them; %.4f%% of the light moved to their "
                     "neighbours (none removed)", (unsigned long long)fs.texels, LMB_FIREFLY_FACTOR,
                     100 * stats->firefly_moved);
    }
    if (st == LMB_OK && cfg->seam_stitch) {
        lmb_seam_report sr;
        if (progress)
            progress(user, "seams", 0, 1);
        st = lmb_seams_stitch(s, l, rt, cache->irradiance, (const uint8_t *const *)cache->state, (int)cfg->threads, &sr,
                              err);
        if (progress && st == LMB_OK)
            progress(user, "seams", 1, 1);
        stats->seam_edges = sr.edges;
        stats->seam_jump_before = sr.jump_before;
        stats->seam_jump_after = sr.jump_after;
        if (st == LMB_OK && sr.edges)
            lmb_info(log, "seams: %llu edges stitched (%llu points, %llu left unmatched, %llu texels) in %.2fs; largest "
                     "jump %.2f%% -> %.2f%%; points over 1%%: %llu -> %llu", (unsigned long long)sr.edges,
                     (unsigned long long)sr.samples, (unsigned long long)sr.dropped, (unsigned long long)sr.texels,
                     sr.seconds, 100 * sr.jump_before, 100 * sr.jump_after, (unsigned long long)sr.over_1pct_before,
                     (unsigned long long)sr.over_1pct);
    }
    return st;
}

lmb_status lmb_bake(lmb_scene *s, const lmb_config *cfg, const char *outdir, lmb_progress_fn progress, void *user,
                    lmb_bake_stats *stats, const lmb_log *log, lmb_error *err)
{
    return lmb_bake_planned(s, cfg, NULL, outdir, progress, user, stats, log, err);
}

lmb_status lmb_bake_planned(lmb_scene *s, const lmb_config *cfg, const char *plan_path, const char *outdir,
                            lmb_progress_fn progress, void *user, lmb_bake_stats *stats, const lmb_log *log,
                            lmb_error *err)
{
    lmb_farm_run run = {LMB_FARM_LOCAL, NULL, 0, 0, 1, 0, 0, 0, 1, 0};
    return lmb_bake_farm(s, cfg, plan_path, &run, outdir, progress, user, stats, log, err);
}

lmb_status lmb_bake_farm(lmb_scene *s, const lmb_config *cfg, const char *plan_path, lmb_farm_run *run,
                         const char *outdir, lmb_progress_fn progress, void *user, lmb_bake_stats *stats,
                         const lmb_log *log, lmb_error *err)
{
    lmb_bake_stats unused;
    if (!stats)
        stats = &unused;
    int worker = run->mode == LMB_FARM_WORKER, finishes = worker && outdir && run->worker == 0;
    int shard = run->mode == LMB_FARM_STEP || (worker && !finishes), writes = !shard;
    if (run->mode != LMB_FARM_LOCAL && !plan_path)
        return lmb_error_set(err, LMB_ERR_USAGE, "a farm step, worker or finish needs the plan ('lmbake plan')");
    if (shard && (run->shards == 0 || run->shard >= run->shards))
        return lmb_error_set(err, LMB_ERR_USAGE, "shard %u of %u: out of range", run->shard + 1, run->shards);
    run->ended = 0;
    double t0 = lmb_seconds();
    memset(stats, 0, sizeof *stats);
    lmb_scene_set_light_modes(s, cfg, shard ? NULL : log); /* mixed lighting: which lights the bake holds */
    lmb_output_dir od;
    memset(&od, 0, sizeof od);
    lmb_status st = writes ? lmb_output_dir_open(&od, outdir, s->path, log, err) : LMB_OK;
    if (st != LMB_OK)
        return st;
    lmb_part_identity id;
    memset(&id, 0, sizeof id);
    lmb_steps *steps = NULL;
    lmb_layout l;
    lmb_rt rt;
    lmb_emitters *em = NULL;
    lmb_direct *direct = NULL;
    lmb_sky *sky = NULL;
    lmb_textures tx;
    lmb_cache cache;
    lmb_ic_points records = {NULL, 0};
    memset(&l, 0, sizeof l);
    memset(&rt, 0, sizeof rt);
    memset(&tx, 0, sizeof tx);
    memset(&cache, 0, sizeof cache);
    st = lmb_sky_create(cfg, s, log, &sky, err); /* before the layout: a bad sky.image stops the bake at once */
    if (st == LMB_OK && plan_path) /* the plan stage's layout (steps/plan.h), checked against this scene and config */
        st = lmb_plan_read(plan_path, s, cfg, &l, &id, err);
    else if (st == LMB_OK)
        st = lmb_layout_build(s, cfg, progress, user, log, &l, err);
    if (st == LMB_OK && progress)
        progress(user, "scene set-up", 0, 1); /* ray-tracing scene, textures, lights, bounce cache */
    if (st == LMB_OK)
        st = lmb_rt_build(s, &rt, err);
    if (st == LMB_OK && !shard)
        lmb_info(log, "ray tracing: %llu triangles placed, %llu stored (meshes used more than once are Embree "
                 "instances), built in %.2f s", (unsigned long long)rt.placed_triangles,
                 (unsigned long long)rt.stored_triangles, rt.build_seconds);
    if (st == LMB_OK)
        st = lmb_textures_load(s, &tx, log, err);
    if (st == LMB_OK)
        st = lmb_emitters_build(s, cfg, &tx, &em, err);
    if (st == LMB_OK)
        st = lmb_direct_create(s, cfg, &rt, em, sky, &direct, err);
    if (st == LMB_OK)
        st = lmb_cache_init(&cache, s, &l, &rt, &tx, err);
    cache.threads = cfg->threads;
    if (st == LMB_OK && progress)
        progress(user, "scene set-up", 1, 1);
    lmb_steps_mode mode = run->mode == LMB_FARM_STEP ? LMB_STEPS_SHARD : run->mode == LMB_FARM_FINISH ? LMB_STEPS_FINISH
                                                                                                   : LMB_STEPS_LOCAL;
    lmb_steps_worker sw = {run->shards, run->worker, run->workers, run->wait_timeout};
    if (st == LMB_OK && worker)
        st = lmb_steps_create_worker(run->farm_dir, &id, &sw, (double)cfg->farm_min_step_rays, log, &steps, err);
    else if (st == LMB_OK)
        st = lmb_steps_create(mode, run->farm_dir, &id, run->step, run->shard, run->shards,
                              (double)cfg->farm_min_step_rays, log, &steps, err);
    double tl = lmb_seconds();
    if (st == LMB_OK && !shard && !lmb_direct_any_light(direct))
        lmb_warn(log, "%s: nothing emits light (no KHR_lights_punctual light, no emissive material, no sky): the "
                 "lightmaps are black", s->path);
    if (st == LMB_OK)
        st = lmb_light_atlases(cfg, direct, &cache, steps, progress, user, stats, &records, log, err);
    if (st == LMB_OK && worker)
        st = lmb_steps_worker_end(steps, err);
    if (worker && !finishes) {
        run->steps = lmb_steps_count(steps);
        goto done;
    }
    if (shard) { /* the shard's part is written (stopped), or the bake ended before its step */
        if (st == LMB_OK) {
            st = lmb_steps_write_end(steps, err);
            run->ended = 1;
        } else if (st == LMB_STEP_STOPPED) {
            st = LMB_OK;
        }
        run->steps = lmb_steps_count(steps);
        goto done;
    }
    run->steps = lmb_steps_count(steps);
    if (st == LMB_OK)
        st = post_process(s, cfg, &l, &rt, &cache, progress, user, stats, log, err);
    lmb_atlas_output *outputs = calloc((size_t)l.atlas_count + 1, sizeof *outputs);
    if (st == LMB_OK && !outputs)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "output: out of memory");
    uint64_t clamped = 0;
    for (uint32_t a = 0; st == LMB_OK && a < l.atlas_count; a++) {
        if (progress)
            progress(user, "images", a, l.atlas_count);
        st = lmb_write_atlas_images(cfg, od.staging, od.stem, a, cache.irradiance[a], cache.state[a], l.width[a],
                                    l.height[a], &outputs[a], err);
        clamped += outputs[a].rgbm_clamped;
        if (st == LMB_OK && outputs[a].rgbm_clamped)
            lmb_warn(log, "atlas %u: %llu texels brighter than RGBM's range %g were clamped (output.rgbm_range; auto "
                     "fits the brightest texel)", a, (unsigned long long)outputs[a].rgbm_clamped, outputs[a].rgbm_range);
    }
    if (progress && st == LMB_OK)
        progress(user, "images", l.atlas_count, l.atlas_count);
    stats->rgbm_clamped = clamped;
    for (uint32_t a = 0; st == LMB_OK && cache.shadowmask && a < l.atlas_count; a++)
        st = lmb_write_shadowmask_image(od.staging, od.stem, a, cache.shadowmask[a], l.width[a], l.height[a], err);
    for (uint32_t a = 0; st == LMB_OK && cache.direction && a < l.atlas_count; a++)
        st = lmb_write_direction_images(cfg, od.staging, od.stem, a, cache.direction[a], l.width[a], l.height[a], err);
    stats->light_seconds = lmb_seconds() - tl;
    stats->atlases = l.atlas_count;
    stats->texel_density = l.density.scene_density;
    stats->density_auto = l.density.automatic;
    stats->density_capped = l.density.capped;
    stats->density_raised = l.density.raised;
    if (st == LMB_OK && progress)
        progress(user, "glTF", 0, 1);
    if (st == LMB_OK) {
        copy_textures(s, &od, log);
        st = write_gltf(s, cfg, &l, od.staging, od.stem, outputs, &records, cache.direction != NULL,
                        cache.shadowmask != NULL, err);
    }
    free(outputs);
    if (st == LMB_OK)
        st = lmb_output_dir_commit(&od, err);
    else
        lmb_output_dir_abort(&od);
    if (st == LMB_OK && progress)
        progress(user, "glTF", 1, 1);
    if (st == LMB_OK)
        snprintf(stats->gltf_path, sizeof stats->gltf_path, "%s/%s.gltf", outdir, od.stem);
done:
    lmb_steps_free(steps);
    lmb_part_identity_free(&id);
    lmb_cache_free(&cache);
    free(records.xyzr);
    lmb_direct_free(direct);
    lmb_sky_free(sky);
    lmb_emitters_free(em);
    lmb_textures_free(&tx);
    lmb_rt_free(&rt);
    lmb_layout_free(&l);
    stats->seconds = lmb_seconds() - t0;
    return st;
}
