/*
 * The glTF node graph -> world-space instances and lights. Checks the graph first (child
 * indices in range, at most one parent, no cycles: glTF spec 3.5.2 requires a forest),
 * then walks it from the scene's roots composing matrices (glTF: local = T * R * S or the
 * node's matrix). A mesh on several nodes gives one instance per node; EXT_mesh_gpu_instancing
 * expands to one instance per copy. A negative determinant flips the winding.
 */
#include "load_internal.h"
#include "../util/lmb_math.h"
#include "../util/mat4.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

typedef struct walk {
    const lmb_accessor_ctx *ctx;
    lmb_scene *scene;
    const lmb_log *log;
    uint32_t instance_cap, light_cap, volume_cap;
} walk;

static lmb_status check_graph(const lmb_accessor_ctx *ctx, lmb_error *err)
{
    const lmb_gltf_view *v = ctx->view;
    char a[160], b[160];
    int32_t *parent = malloc((v->node_count + 1) * sizeof *parent);
    if (!parent)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", ctx->path);
    for (uint32_t i = 0; i < v->node_count; i++)
        parent[i] = -1;
    lmb_status st = LMB_OK;
    for (uint32_t i = 0; i < v->node_count && st == LMB_OK; i++) {
        const lmb_gltf_node *n = &v->nodes[i];
        for (uint32_t k = 0; k < n->child_count && st == LMB_OK; k++) {
            int32_t c = v->children[n->first_child + k];
            if (c < 0 || (uint32_t)c >= v->node_count)
                st = lmb_error_set(err, LMB_ERR_INPUT, "%s: %s lists child %d, which does not exist (the file has %u nodes)",
                                   ctx->path, lmb_object_label(a, "node", i, n->name), c, v->node_count);
            else if ((uint32_t)c == i)
                st = lmb_error_set(err, LMB_ERR_INPUT, "%s: %s lists itself as a child: the node graph has a cycle",
                                   ctx->path, lmb_object_label(a, "node", i, n->name));
            else if (parent[c] >= 0)
                st = lmb_error_set(err, LMB_ERR_INPUT, "%s: %s has two parents (node %d and %s): the node graph must be a tree",
                                   ctx->path, lmb_object_label(a, "node", (uint32_t)c, v->nodes[c].name), parent[c],
                                   lmb_object_label(b, "node", i, n->name));
            else
                parent[c] = (int32_t)i;
        }
    }
    /* With one parent each, a cycle is a parent chain longer than the node count. */
    for (uint32_t i = 0; i < v->node_count && st == LMB_OK; i++) {
        uint32_t steps = 0;
        for (int32_t p = parent[i]; p >= 0 && st == LMB_OK; p = parent[p])
            if (++steps > v->node_count)
                st = lmb_error_set(err, LMB_ERR_INPUT, "%s: the node graph has a cycle through %s",
                                   ctx->path, lmb_object_label(a, "node", i, v->nodes[i].name));
    }
    for (uint32_t i = 0; i < v->node_count && st == LMB_OK; i++) {
        const lmb_gltf_node *n = &v->nodes[i];
        if (n->mesh >= 0 && (uint32_t)n->mesh >= v->mesh_count)
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: %s uses mesh %d, which does not exist (the file has %u)",
                               ctx->path, lmb_object_label(a, "node", i, n->name), n->mesh, v->mesh_count);
        else if (n->light < -1 || (n->light >= 0 && (uint32_t)n->light >= v->light_count))
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: %s uses light %d, which does not exist (the file has %u)",
                               ctx->path, lmb_object_label(a, "node", i, n->name), n->light, v->light_count);
    }
    for (uint32_t r = 0; r < v->scene_root_count && st == LMB_OK; r++) {
        int32_t root = v->scene_roots[r];
        if (root < 0 || (uint32_t)root >= v->node_count)
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: the scene lists node %d, which does not exist (the file has %u nodes)",
                               ctx->path, root, v->node_count);
        else if (parent[root] >= 0)
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: the scene lists %s as a root, but it is a child of node %d",
                               ctx->path, lmb_object_label(a, "node", (uint32_t)root, v->nodes[root].name), parent[root]);
    }
    free(parent);
    return st;
}

static void *grow(void *p, uint32_t *cap, uint32_t need, size_t elem)
{
    if (need <= *cap)
        return p;
    uint32_t c = *cap ? *cap * 2 : 16;
    while (c < need)
        c *= 2;
    void *q = realloc(p, (size_t)c * elem);
    if (q)
        *cap = c;
    return q;
}

/* A NAME_LOD<n> node (n >= 1, "_lod" in any case) when a node NAME_LOD0 exists: a lower level of
 * detail kept as a sibling, as DCC exports and Unity's LOD groups name them. Only such names
 * scan the nodes. */
static int lower_lod_by_name(const lmb_gltf_view *v, const char *name)
{
    size_t n = name ? strlen(name) : 0, k = n;
    while (k > 0 && name[k - 1] >= '0' && name[k - 1] <= '9')
        k--;
    if (k == n || k < 5 || strncasecmp(name + k - 4, "_lod", 4) || atoi(name + k) < 1)
        return 0;
    for (uint32_t i = 0; i < v->node_count; i++) {
        const char *o = v->nodes[i].name;
        if (o && strlen(o) == k + 1 && !strncmp(o, name, k) && o[k] == '0')
            return 1;
    }
    return 0;
}

static lmb_status add_instance(walk *w, uint32_t node, int32_t gpu, const double world[16], lmb_error *err)
{
    lmb_scene *s = w->scene;
    const lmb_gltf_node *n = &w->ctx->view->nodes[node];
    void *p = grow(s->instances, &w->instance_cap, s->instance_count + 1, sizeof *s->instances);
    if (!p)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", w->ctx->path);
    s->instances = p;
    lmb_instance *in = &s->instances[s->instance_count];
    memset(in, 0, sizeof *in);
    char base[160], name[192];
    if (n->name && *n->name)
        snprintf(base, sizeof base, "%s", n->name);
    else
        snprintf(base, sizeof base, "node %u", node);
    if (gpu >= 0)
        snprintf(name, sizeof name, "%s#%d", base, gpu);
    else
        snprintf(name, sizeof name, "%s", base);
    in->name = lmb_strdup(name);
    if (!in->name)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", w->ctx->path);
    s->instance_count++;
    in->node = node;
    in->gpu_instance = gpu;
    in->mesh = (uint32_t)n->mesh;
    memcpy(in->world, world, sizeof in->world);
    in->flips_winding = lmb_mat4_det3(world) < 0.0;
    in->extras_lightmap = n->extras_lightmap;
    in->motion = n->skinned ? LMB_SKINNED : n->morphing ? LMB_MORPHING
               : n->lod_of >= 0 || lower_lod_by_name(w->ctx->view, n->name) ? LMB_LOWER_LOD
                                                                             : LMB_STATIC;
    in->occludes = in->motion == LMB_STATIC || in->extras_lightmap == 1; /* as lmb_scene_select_lightmapped says */
    if (!lmb_mat4_is_finite(world) || fabs(lmb_mat4_det3(world)) < 1e-30)
        lmb_warn(w->log, "%s: %s has a singular or non-finite transform; it will not be lightmapped", w->ctx->path, name);
    return LMB_OK;
}

/* At most this many EXT_mesh_gpu_instancing copies per node: each gets its own texels, so a
 * level with more is not a lightmapping job (2^20, over 500x Blender's 1,900-teapot test). */
#define LMB_MAX_GPU_COPIES (1u << 20)

/* EXT_mesh_gpu_instancing: one instance per element of its TRS accessors. A copy whose
 * transform cannot be inverted (a zero scale, NaN) is an error: its texels would have no
 * surface, and a copy hidden by a zero scale is not drawn by engines either. */
static lmb_status add_gpu_instances(walk *w, uint32_t node, const double world[16], lmb_error *err)
{
    const lmb_gltf_node *n = &w->ctx->view->nodes[node];
    int32_t acc[3] = {n->gpu_translation, n->gpu_rotation, n->gpu_scale};
    static const int comps[3] = {3, 4, 3};
    static const char *const names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
    float *data[3] = {NULL, NULL, NULL};
    size_t count = 0, have = 0;
    char what[224], label[160];
    lmb_status st = LMB_OK;
    lmb_object_label(label, "node", node, n->name);
    for (int k = 0; k < 3 && st == LMB_OK; k++) {
        size_t c;
        if (acc[k] < 0)
            continue;
        snprintf(what, sizeof what, "%s EXT_mesh_gpu_instancing %s", label, names[k]);
        st = lmb_accessor_read_floats(w->ctx, acc[k], comps[k], what, &data[k], &c, err);
        if (st == LMB_OK && have && c != count)
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: %s has %zu elements but the other attributes have %zu",
                               w->ctx->path, what, c, count);
        count = c;
        have = 1;
    }
    if (st == LMB_OK && count > LMB_MAX_GPU_COPIES)
        st = lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: EXT_mesh_gpu_instancing has %zu copies; at most %u are baked "
                           "per node (each copy gets its own lightmap texels)", w->ctx->path, label, count,
                           LMB_MAX_GPU_COPIES);
    for (size_t i = 0; i < count && st == LMB_OK; i++) {
        double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1}, local[16], inst[16];
        for (int c = 0; c < 3; c++) {
            if (data[0]) t[c] = data[0][3 * i + c];
            if (data[2]) s[c] = data[2][3 * i + c];
        }
        for (int c = 0; c < 4 && data[1]; c++)
            q[c] = data[1][4 * i + c];
        lmb_mat4_from_trs(t, q, s, local);
        lmb_mat4_mul(world, local, inst);
        if (!lmb_mat4_is_finite(local) || fabs(lmb_mat4_det3(local)) < 1e-30)
            st = lmb_error_set(err, LMB_ERR_INPUT,
                               "%s: %s: EXT_mesh_gpu_instancing copy %zu has a transform that cannot be inverted "
                               "(translation %g %g %g, rotation %g %g %g %g, scale %g %g %g)",
                               w->ctx->path, label, i, t[0], t[1], t[2], q[0], q[1], q[2], q[3], s[0], s[1], s[2]);
        else
            st = add_instance(w, node, (int32_t)i, inst, err);
    }
    for (int k = 0; k < 3; k++)
        free(data[k]);
    if (st == LMB_OK)
        w->scene->gpu_instanced_nodes++;
    return st;
}

static lmb_status add_light(walk *w, uint32_t node, const double world[16], lmb_error *err)
{
    const lmb_gltf_node *n = &w->ctx->view->nodes[node];
    const lmb_gltf_light *gl = &w->ctx->view->lights[n->light];
    lmb_scene *s = w->scene;
    char label[160];
    lmb_object_label(label, "light", (uint32_t)n->light, gl->name);
    lmb_light l;
    memset(&l, 0, sizeof l);
    if (!strcmp(gl->type, "point"))
        l.type = LMB_LIGHT_POINT;
    else if (!strcmp(gl->type, "spot"))
        l.type = LMB_LIGHT_SPOT;
    else if (!strcmp(gl->type, "directional"))
        l.type = LMB_LIGHT_DIRECTIONAL;
    else
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s has type '%s'; KHR_lights_punctual knows point, spot and directional",
                             w->ctx->path, label, gl->type);
    if (!(gl->intensity >= 0.0) || !isfinite(gl->intensity))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s has intensity %g; it must be a finite number >= 0",
                             w->ctx->path, label, gl->intensity);
    /* KHR_lights_punctual's colour is linear RGB in [0, 1] (its schema); a negative channel would
     * be negative light, which the direct light's sampling cannot draw */
    for (int c = 0; c < 3; c++)
        if (!(gl->color[c] >= 0.0) || !isfinite(gl->color[c]))
            return lmb_error_set(err, LMB_ERR_INPUT,
                                 "%s: %s has colour (%g, %g, %g); each channel must be a finite number >= 0",
                                 w->ctx->path, label, gl->color[0], gl->color[1], gl->color[2]);
    if (l.type == LMB_LIGHT_SPOT &&
        !(gl->inner_cone >= 0.0 && gl->inner_cone < gl->outer_cone && gl->outer_cone <= LMB_PI_2 + 1e-9))
        return lmb_error_set(err, LMB_ERR_INPUT,
                             "%s: %s: spot cone angles inner %g, outer %g must satisfy 0 <= inner < outer <= pi/2",
                             w->ctx->path, label, gl->inner_cone, gl->outer_cone);
    /* extras.lightmap_mode: the light's own, else its node's */
    const char *mode = gl->lightmap_mode && *gl->lightmap_mode ? gl->lightmap_mode : n->lightmap_mode;
    l.mode = LMB_LIGHT_BAKED;
    l.shadowmask_channel = -1;
    if (mode && *mode && lmb_light_mode_parse(mode, &l.mode) != 0)
        return lmb_error_set(err, LMB_ERR_INPUT,
                             "%s: %s (node %u): extras.lightmap_mode is %s%s%s; expected \"baked\", \"indirect\" or \"realtime\"",
                             w->ctx->path, label, node, strcmp(mode, "?") ? "'" : "", strcmp(mode, "?") ? mode : "not a string",
                             strcmp(mode, "?") ? "'" : "");
    /* extras.lightmap_group: the light's own, else its node's (docs/light-groups.md) */
    const char *group = gl->lightmap_group && *gl->lightmap_group ? gl->lightmap_group : n->lightmap_group;
    if (group && !strcmp(group, "?"))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s (node %u): extras.lightmap_group is not a string; expected a "
                             "light group's name", w->ctx->path, label, node);
    void *p = grow(s->lights, &w->light_cap, s->light_count + 1, sizeof *s->lights);
    if (!p)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", w->ctx->path);
    s->lights = p;
    l.name = lmb_strdup(gl->name && *gl->name ? gl->name : label);
    char node_label[160];
    lmb_object_label(node_label, "node", node, n->name);
    l.node_name = lmb_strdup(n->name && *n->name ? n->name : node_label);
    l.group = lmb_strdup(group ? group : "");
    if (!l.name || !l.node_name || !l.group) {
        free(l.name);
        free(l.node_name);
        free(l.group);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", w->ctx->path);
    }
    l.gltf_light = (uint32_t)n->light;
    l.node = node;
    for (int c = 0; c < 3; c++)
        l.color[c] = (float)gl->color[c];
    l.intensity = (float)gl->intensity;
    l.range = (float)gl->range;
    l.inner_cone = (float)gl->inner_cone;
    l.outer_cone = (float)gl->outer_cone;
    static const double origin[3] = {0, 0, 0}, forward[3] = {0, 0, -1};
    lmb_mat4_point(world, origin, l.position);
    lmb_mat4_vector(world, forward, l.direction);
    double len = sqrt(l.direction[0] * l.direction[0] + l.direction[1] * l.direction[1] + l.direction[2] * l.direction[2]);
    for (int c = 0; c < 3; c++)
        l.direction[c] = len > 0 ? l.direction[c] / len : (c == 2 ? -1.0 : 0.0);
    s->lights[s->light_count++] = l;
    return LMB_OK;
}

/* Depth-first over a tree already checked acyclic; the depth is bounded by node_count. */
/* A node's extras.lightmap_probes as a probe volume; a malformed one or a flat transform is an
 * error naming the file and the node. */
static lmb_status add_probe_volume(walk *w, uint32_t node, const double world[16], lmb_error *err)
{
    const lmb_gltf_node *n = &w->ctx->view->nodes[node];
    char name[160];
    snprintf(name, sizeof name, "%s", n->name && n->name[0] ? n->name : "");
    if (!name[0])
        snprintf(name, sizeof name, "node %u", node);
    if (n->lightmap_probes[0] < 0)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: node '%s': extras.lightmap_probes must be [x, y, z], integers in "
                             "1..256 (the volume's resolution)", w->scene->path, name);
    if (!lmb_mat4_is_finite(world) || fabs(lmb_mat4_det3(world)) < 1e-30)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: node '%s': extras.lightmap_probes: its transform is flat or not "
                             "finite, so it places no volume", w->scene->path, name);
    lmb_scene *s = w->scene;
    if (s->probe_volume_count == w->volume_cap) {
        uint32_t cap = w->volume_cap ? 2 * w->volume_cap : 4;
        lmb_node_probe_volume *v = realloc(s->probe_volumes, cap * sizeof *v);
        if (!v)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory");
        s->probe_volumes = v;
        w->volume_cap = cap;
    }
    lmb_node_probe_volume *v = &s->probe_volumes[s->probe_volume_count];
    v->name = malloc(strlen(name) + 1);
    if (!v->name)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "out of memory");
    memcpy(v->name, name, strlen(name) + 1);
    v->node = node;
    memcpy(v->world, world, sizeof v->world);
    for (int k = 0; k < 3; k++)
        v->resolution[k] = (uint32_t)n->lightmap_probes[k];
    s->probe_volume_count++;
    return LMB_OK;
}

static lmb_status visit(walk *w, uint32_t node, const double parent_world[16], lmb_error *err)
{
    const lmb_gltf_node *n = &w->ctx->view->nodes[node];
    double local[16], world[16];
    if (n->has_matrix)
        memcpy(local, n->matrix, sizeof local);
    else
        lmb_mat4_from_trs(n->translation, n->rotation, n->scale, local);
    lmb_mat4_mul(parent_world, local, world);
    lmb_status st = LMB_OK;
    if (n->mesh >= 0)
        st = n->has_gpu_instancing ? add_gpu_instances(w, node, world, err) : add_instance(w, node, -1, world, err);
    if (st == LMB_OK && n->light >= 0)
        st = add_light(w, node, world, err);
    if (st == LMB_OK && n->lightmap_probes[0])
        st = add_probe_volume(w, node, world, err);
    for (uint32_t k = 0; k < n->child_count && st == LMB_OK; k++)
        st = visit(w, (uint32_t)w->ctx->view->children[n->first_child + k], world, err);
    return st;
}

lmb_status lmb_load_nodes(const lmb_accessor_ctx *ctx, lmb_scene *scene, const lmb_log *log, lmb_error *err)
{
    lmb_status st = check_graph(ctx, err);
    if (st != LMB_OK)
        return st;
    walk w = {ctx, scene, log, 0, 0, 0};
    double identity[16];
    lmb_mat4_identity(identity);
    for (uint32_t r = 0; r < ctx->view->scene_root_count && st == LMB_OK; r++)
        st = visit(&w, (uint32_t)ctx->view->scene_roots[r], identity, err);
    return st;
}
