/*
 * The output glTF of a bake (lightmapped_gltf.h): each lightmapped instance's primitives with
 * new vertices where charts split them and TEXCOORD_1, the lightmap textures and their
 * MOZ_lightmap links, instanced copies' rectangles, the irradiance-cache records file, and the
 * input's textures copied beside it. The primitives are built in parallel, an instance per
 * thread; the document itself on one thread (tinygltf, write/gltf_write.h).
 */
#include "lightmapped_gltf.h"

#include "load/gltf_adapter.h"
#include "write/gltf_write.h"
#include "write/ktx2.h"

#include <omp.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* New vertices of one glTF primitive: one per (original vertex, chart). */
static lmb_status instance_primitives(const lmb_scene *s, const lmb_layout *l, uint32_t i, lmb_gltf_prim_out **out,
                                      uint32_t *count, void ***owned, uint32_t *owned_n, lmb_error *err);

/* Texture files the input references by relative path go along with the output glTF
 * (read from the view before lightmap images are added; tinygltf keeps the strings). */
void lmb_copy_input_textures(lmb_scene *s, lmb_output_dir *od, const lmb_log *log)
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
/* Instances whose vertices are built at once before they go into the document. */
#define WRITE_BATCH 256

/* Instance i into the document: its node's lightmapped mesh, a shared mesh's rectangle, or
 * (EXT_mesh_gpu_instancing) every copy of its node, once per node; node_done and shared_by
 * say what earlier instances did. */
static lmb_status write_instance(lmb_scene *s, const lmb_layout *l, uint32_t i, const lmb_gltf_prim_out *pr,
                                 uint32_t n, const int32_t *tex, const int32_t *dir_tex, uint8_t *node_done,
                                 int64_t *shared_by, lmb_error *err)
{
    const lmb_instance *in = &s->instances[i];
    const lmb_layout_instance *li = &l->instances[i];
    if (!li->lightmapped || (in->gpu_instance >= 0 && node_done[in->node]))
        return LMB_OK;
    if (in->gpu_instance < 0 && li->shared_layout && shared_by[in->mesh] >= 0) /* atlas.share_meshes */
        return lmb_gltf_share_lightmapped_mesh(s->doc, in->node, (uint32_t)shared_by[in->mesh], tex[li->atlas],
                                               li->scale_offset, err);
    int32_t t = tex[li->atlas], d = dir_tex[li->atlas];
    lmb_status st;
    if (in->gpu_instance >= 0) /* every copy of the node: one mesh, a rectangle each */
        st = instanced_node(s, l, in->node, pr, n, t, d, err);
    else if (li->shared_layout) { /* the first node of a shared mesh */
        st = lmb_gltf_lightmap_shared_mesh(s->doc, in->node, pr, n, t, d, li->scale_offset, err);
        shared_by[in->mesh] = (int64_t)in->node;
    } else
        st = lmb_gltf_lightmap_node(s->doc, in->node, pr, n, t, d, li->scale_offset, err);
    node_done[in->node] = 1;
    return st;
}

typedef struct instance_prims {
    int needed;
    lmb_gltf_prim_out *prims;
    uint32_t n, owned_n;
    void **owned;
    lmb_error err;
} instance_prims;

lmb_status lmb_write_lightmapped_gltf(lmb_scene *s, const lmb_config *cfg, const lmb_layout *l, const char *dir,
                                      const char *stem, const lmb_atlas_output *outputs, const lmb_ic_points *records,
                                      int directional, int shadowmask, const lmb_gltf_probes *probes,
                                      const lmb_light_groups *groups, lmb_error *err)
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
        char group_exr[LMB_MAX_LIGHT_GROUPS][512], group_hdr[LMB_MAX_LIGHT_GROUPS][512],
            group_ktx2[LMB_MAX_LIGHT_GROUPS][512];
        for (uint32_t g = 0; groups && g < groups->count; g++) {
            snprintf(group_exr[g], sizeof group_exr[g], "%s-lightmap-%u-group-%s.exr", stem, a, groups->name[g]);
            snprintf(group_hdr[g], sizeof group_hdr[g], "%s-lightmap-%u-group-%s.hdr", stem, a, groups->name[g]);
            snprintf(group_ktx2[g], sizeof group_ktx2[g], "%s-lightmap-%u-group-%s.ktx2", stem, a, groups->name[g]);
            files.group_ktx2[g] = f & LMB_OUTPUT_KTX2 ? group_ktx2[g] : NULL;
            files.group_name[g] = groups->name[g];
            files.group_scale[g] = groups->scale[g];
            for (int c = 0; c < 3; c++)
                files.group_intensity[g][c] = groups->weight[g][c];
            files.group_exr[g] = group_exr[g];
            files.group_hdr[g] = group_hdr[g];
        }
        files.groups = groups ? groups->count : 0;
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
    if (node_done)
        memset(node_done, 0, (size_t)s->node_count + 1);
    for (uint32_t m = 0; shared_by && m < s->mesh_count; m++)
        shared_by[m] = -1;
    /* a batch of instances at a time: their vertices in parallel (the work), then added to the
     * glTF document on one thread in instance order and freed, so only a batch's arrays are held
     * beside the document (all of them at once were 170 MB on a 2,000-node level) */
    int threads = cfg->threads ? (int)cfg->threads : omp_get_max_threads();
    for (uint32_t b0 = 0; st == LMB_OK && b0 < s->instance_count; b0 += WRITE_BATCH) {
        uint32_t b1 = s->instance_count - b0 < WRITE_BATCH ? s->instance_count : b0 + WRITE_BATCH;
        int failed = 0;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1) reduction(| : failed)
        for (uint32_t i = b0; i < b1; i++)
            if (prims[i].needed)
                failed |= instance_primitives(s, l, i, &prims[i].prims, &prims[i].n, &prims[i].owned,
                                              &prims[i].owned_n, &prims[i].err) != LMB_OK;
        for (uint32_t i = b0; failed && i < b1; i++) /* the first instance's error */
            if (prims[i].needed && prims[i].err.status != LMB_OK) {
                *err = prims[i].err;
                st = err->status;
                break;
            }
        for (uint32_t i = b0; i < b1 && st == LMB_OK; i++)
            st = write_instance(s, l, i, prims[i].prims, prims[i].n, tex, dir_tex, node_done, shared_by, err);
        for (uint32_t i = b0; i < b1; i++) {
            for (uint32_t k = 0; k < prims[i].owned_n; k++)
                free(prims[i].owned[k]);
            free(prims[i].owned);
            free(prims[i].prims);
            prims[i].owned = NULL;
            prims[i].prims = NULL;
            prims[i].owned_n = 0;
        }
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
    if (st == LMB_OK && probes)
        st = lmb_gltf_set_probes(s->doc, probes, err);
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
            } else {
                double t[6];
                lmb_layout_uv(l, i, f, t);
                if (li->shared_layout) { /* the layout it shares: back through its rectangle */
                    const double *so = li->scale_offset;
                    uv1[2 * (size_t)lo] = (float)((t[2 * (c % 3)] / w - so[2]) / so[0]);
                    uv1[2 * (size_t)lo + 1] = (float)((t[2 * (c % 3) + 1] / h - so[3]) / so[1]);
                } else {
                    uv1[2 * (size_t)lo] = (float)(t[2 * (c % 3)] / w);
                    uv1[2 * (size_t)lo + 1] = (float)(t[2 * (c % 3) + 1] / h);
                }
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
