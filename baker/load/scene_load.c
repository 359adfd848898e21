/*
 * The load stage: glTF file -> lmb_scene. Preflight (preflight.c) refuses what lmbake
 * cannot honour, the tinygltf adapter parses, then this builds meshes, materials, instances and
 * lights in plain C, checking everything tinygltf lets through (see ../shared INDEX notes:
 * Draco accessors without data, cycles, out-of-range indices). On error nothing leaks and
 * *out stays NULL.
 */
#include "extensions.h"
#include "load_internal.h"
#include "preflight.h"
#include "decompress.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

char *lmb_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

const char *lmb_object_label(char *buf, const char *kind, uint32_t index, const char *name)
{
    if (name && *name)
        snprintf(buf, 160, "%s '%s'", kind, name);
    else
        snprintf(buf, 160, "%s %u", kind, index);
    return buf;
}

static int listed(const char *const *names, uint32_t count, const char *name)
{
    for (uint32_t k = 0; k < count; k++)
        if (!strcmp(names[k], name))
            return 1;
    return 0;
}

static void warn_one(const char *path, const char *name, int required, const lmb_log *log)
{
    const lmb_extension_info *info = lmb_extension_find(name);
    if (info && info->support != LMB_EXT_SUPPORTED)
        lmb_warn(log, "%s: %s %s: %s", path, required ? "requires" : "uses", name, info->effect);
}

/* One warning per extension the file uses or requires whose effect the bake leaves out
 * (extensions.c), naming the file and the extension. */
static void warn_ignored_extensions(const char *path, const lmb_gltf_view *v, const lmb_log *log)
{
    for (uint32_t i = 0; i < v->extensions_used_count; i++)
        warn_one(path, v->extensions_used[i],
                 listed(v->extensions_required, v->extensions_required_count, v->extensions_used[i]), log);
    for (uint32_t i = 0; i < v->extensions_required_count; i++) /* required but (wrongly) not in extensionsUsed */
        if (!listed(v->extensions_used, v->extensions_used_count, v->extensions_required[i]))
            warn_one(path, v->extensions_required[i], 1, log);
}

static lmb_status load_meshes(const lmb_accessor_ctx *ctx, lmb_scene *s, const lmb_log *log, lmb_error *err)
{
    const lmb_gltf_view *v = ctx->view;
    s->meshes = calloc(v->mesh_count + 1, sizeof *s->meshes);
    s->primitives = calloc(v->primitive_count + 1, sizeof *s->primitives);
    if (!s->meshes || !s->primitives)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", ctx->path);
    for (uint32_t m = 0; m < v->mesh_count; m++) {
        lmb_mesh *mesh = &s->meshes[m];
        char label[160];
        lmb_object_label(label, "mesh", m, v->meshes[m].name);
        mesh->name = lmb_strdup(v->meshes[m].name && *v->meshes[m].name ? v->meshes[m].name : label);
        if (!mesh->name)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", ctx->path);
        s->mesh_count = m + 1;
        mesh->first_primitive = s->primitive_count;
        for (uint32_t p = 0; p < v->meshes[m].primitive_count; p++) {
            lmb_primitive prim;
            int skipped;
            memset(&prim, 0, sizeof prim);
            lmb_status st = lmb_load_primitive(ctx, m, p, mesh->name, s->material_count, &prim, &skipped, log, err);
            if (st != LMB_OK) {
                lmb_primitive_release(&prim);
                return st;
            }
            if (skipped) {
                mesh->skipped_primitives++;
                mesh->skipped_triangles += prim.triangle_count;
                lmb_primitive_release(&prim);
                continue;
            }
            mesh->triangle_count += prim.triangle_count;
            mesh->degenerate_count += prim.degenerate_count;
            s->primitives[s->primitive_count++] = prim;
            mesh->primitive_count++;
        }
        if (mesh->degenerate_count)
            lmb_warn(log, "%s: mesh '%s': %u of %u triangles have zero area and are left out of lightmapping",
                     ctx->path, mesh->name, mesh->degenerate_count, mesh->triangle_count);
    }
    return LMB_OK;
}

lmb_status lmb_scene_load(const char *path, const lmb_config *cfg, lmb_scene **out,
                          const lmb_log *log, lmb_error *err)
{
    const char *extras_key = cfg && cfg->extras_key[0] ? cfg->extras_key : NULL;
    *out = NULL;
    lmb_scene *s = calloc(1, sizeof *s);
    if (!s)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
    lmb_status st = lmb_preflight(path, err);
    lmb_decompressed dc = {NULL, 0, 0, 0};
    if (st == LMB_OK)
        st = lmb_decompress(path, &dc, err);
    if (st == LMB_OK && dc.glb) {
        lmb_info(log, "%s: compressed geometry decoded (%u EXT_meshopt_compression buffer views, %u "
                 "KHR_draco_mesh_compression primitives); the output is written uncompressed", path, dc.meshopt_views,
                 dc.draco_primitives);
        st = lmb_gltf_open_glb(path, dc.glb, dc.size, extras_key, &s->doc, log, err);
    } else if (st == LMB_OK) {
        st = lmb_gltf_open(path, extras_key, &s->doc, log, err);
    }
    free(dc.glb);
    if (st == LMB_OK && !(s->path = lmb_strdup(path)))
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
    if (st == LMB_OK) {
        const lmb_gltf_view *v = lmb_gltf_get_view(s->doc);
        lmb_accessor_ctx ctx = {v, path};
        s->node_count = v->node_count;
        warn_ignored_extensions(path, v, log);
        for (uint32_t m = 0; m < v->material_count; m++)
            if (v->materials[m].diffuse_transmission_textures) {
                char label[160];
                lmb_warn(log, "%s: %s: KHR_materials_diffuse_transmission's textures are not read; its factors are "
                         "(transmission %g, colour %g %g %g)", path,
                         lmb_object_label(label, "material", m, v->materials[m].name),
                         v->materials[m].diffuse_transmission, v->materials[m].diffuse_transmission_color[0],
                         v->materials[m].diffuse_transmission_color[1], v->materials[m].diffuse_transmission_color[2]);
            }
        st = lmb_load_materials(path, v, s, err);
        if (st == LMB_OK)
            st = load_meshes(&ctx, s, log, err);
        if (st == LMB_OK)
            st = lmb_load_nodes(&ctx, s, log, err);
        if (st == LMB_OK && lmb_apply_material_config(s, cfg, log) != LMB_OK)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
    }
    if (st != LMB_OK) {
        lmb_scene_free(s);
        return st;
    }
    *out = s;
    return LMB_OK;
}

void lmb_scene_free(lmb_scene *s)
{
    if (!s)
        return;
    for (uint32_t i = 0; i < s->primitive_count; i++)
        lmb_primitive_release(&s->primitives[i]);
    for (uint32_t i = 0; i < s->mesh_count; i++)
        free(s->meshes[i].name);
    for (uint32_t i = 0; i < s->instance_count; i++)
        free(s->instances[i].name);
    for (uint32_t i = 0; i < s->material_count; i++)
        free(s->materials[i].name);
    for (uint32_t i = 0; i < s->light_count; i++) {
        free(s->lights[i].name);
        free(s->lights[i].node_name);
        free(s->lights[i].group);
    }
    free(s->primitives);
    free(s->meshes);
    free(s->instances);
    free(s->materials);
    free(s->lights);
    for (uint32_t i = 0; i < s->probe_volume_count; i++)
        free(s->probe_volumes[i].name);
    free(s->probe_volumes);
    free(s->path);
    if (s->doc)
        lmb_gltf_close(s->doc);
    free(s);
}
