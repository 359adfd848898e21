/*
 * Load-stage tests on real glTF files (assets/scenes, from ../shared/assets with their
 * licenses): node transforms, mirrored instances, sparse accessors, strip/fan winding,
 * GPU instancing, lights and emissive strength, lightmap selection by glob and extras,
 * KHR_texture_transform and metalness textures on a real Blender export.
 * usage: test_load SCENES_DIR
 */
#include "check.h"

#include <lmbake/lmbake.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *scenes;

static lmb_scene *load(const char *rel, const lmb_config *cfg)
{
    char path[1024];
    lmb_error err = {LMB_OK, ""};
    lmb_scene *s = NULL;
    snprintf(path, sizeof path, "%s/%s", scenes, rel);
    if (lmb_scene_load(path, cfg, &s, NULL, &err) != LMB_OK) {
        fprintf(stderr, "cannot load %s: %s\n", path, err.message);
        check_failed_count++;
        return NULL;
    }
    return s;
}

/* Box.gltf: the root node's matrix turns Y-up into Z-up; its child holds the mesh. */
static void test_node_matrix(void)
{
    lmb_scene *s = load("khr-Box/glTF/Box.gltf", NULL);
    if (!s)
        return;
    CHECK_INT(s->instance_count, 1);
    CHECK_INT(s->meshes[0].triangle_count, 12);
    CHECK_INT(s->primitives[0].vertex_count, 24);
    CHECK(s->primitives[0].normals != NULL);
    const double want[16] = {1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1};
    for (int i = 0; i < 16; i++)
        CHECK_NEAR(s->instances[0].world[i], want[i], 1e-12);
    CHECK_INT(s->instances[0].flips_winding, 0);
    lmb_scene_free(s);
}

/* One mesh on two nodes: two instances, the second translated by (1, 0, 0). */
static void test_shared_mesh(void)
{
    lmb_scene *s = load("khr-SimpleMeshes/glTF/SimpleMeshes.gltf", NULL);
    if (!s)
        return;
    CHECK_INT(s->instance_count, 2);
    CHECK_INT(s->instances[0].mesh, s->instances[1].mesh);
    CHECK_NEAR(s->instances[0].world[12], 0.0, 0);
    CHECK_NEAR(s->instances[1].world[12], 1.0, 0);
    lmb_scene_free(s);
}

/* Mirrored nodes: scale (-1,-1,-1) on a node or on its parent flips the winding; two
 * negative scales in a chain cancel. NegativeScaleFront, NotShinyMinus1, Shiny1, Dark1. */
static void test_negative_scale(void)
{
    lmb_scene *s = load("khr-NegativeScaleTest/glTF/NegativeScaleTest.gltf", NULL);
    if (!s)
        return;
    int mirrored = 0;
    for (uint32_t i = 0; i < s->instance_count; i++) {
        mirrored += s->instances[i].flips_winding;
        if (!strcmp(s->instances[i].name, "ShinyMinus1"))
            CHECK_INT(s->instances[i].flips_winding, 0); /* (-1)^3 * (-1)^3 = +1 */
        if (!strcmp(s->instances[i].name, "Shiny1"))
            CHECK_INT(s->instances[i].flips_winding, 1);
    }
    CHECK_INT(s->instance_count, 11);
    CHECK_INT(mirrored, 4);
    lmb_scene_free(s);
}

/* Sparse POSITION accessor: the substituted values reach the accessor's stated bounds
 * (max (6, 4, 0)); the base data alone stays lower. */
static void test_sparse(void)
{
    lmb_scene *s = load("khr-SimpleSparseAccessor/glTF/SimpleSparseAccessor.gltf", NULL);
    if (!s)
        return;
    const lmb_primitive *p = &s->primitives[0];
    double mx[3] = {-1e9, -1e9, -1e9}, mn[3] = {1e9, 1e9, 1e9};
    for (uint32_t v = 0; v < p->vertex_count; v++)
        for (int c = 0; c < 3; c++) {
            double x = p->positions[3 * v + c];
            mx[c] = x > mx[c] ? x : mx[c];
            mn[c] = x < mn[c] ? x : mn[c];
        }
    CHECK_INT(p->vertex_count, 14);
    CHECK_INT(p->triangle_count, 12);
    CHECK_NEAR(mx[0], 6.0, 0);
    CHECK_NEAR(mx[1], 4.0, 0);
    CHECK_NEAR(mn[1], 0.0, 0);
    lmb_scene_free(s);
}

static double normal_z(const lmb_primitive *p, uint32_t t)
{
    const float *a = p->positions + 3 * p->indices[3 * t], *b = p->positions + 3 * p->indices[3 * t + 1],
                *c = p->positions + 3 * p->indices[3 * t + 2];
    return (double)(b[0] - a[0]) * (c[1] - a[1]) - (double)(b[1] - a[1]) * (c[0] - a[0]);
}

/* TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN in the XY plane: every triangle of every
 * mode faces +Z, i.e. strips alternate correctly and fans keep their winding. Points and
 * lines are skipped. */
static void test_primitive_modes(void)
{
    lmb_scene *s = load("khr-MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf", NULL);
    if (!s)
        return;
    CHECK_INT(s->primitive_count, 3);
    uint32_t tris = 0, skipped = 0;
    for (uint32_t m = 0; m < s->mesh_count; m++)
        skipped += s->meshes[m].skipped_primitives;
    for (uint32_t p = 0; p < s->primitive_count; p++)
        for (uint32_t t = 0; t < s->primitives[p].triangle_count; t++, tris++)
            CHECK(normal_z(&s->primitives[p], t) > 0.0);
    CHECK_INT(tris, 16);
    CHECK_INT(skipped, 4);
    lmb_scene_free(s);
}

/* Non-indexed: triangle (0, 1, 2). */
static void test_without_indices(void)
{
    lmb_scene *s = load("khr-TriangleWithoutIndices/glTF/TriangleWithoutIndices.gltf", NULL);
    if (!s)
        return;
    CHECK_INT(s->primitives[0].triangle_count, 1);
    CHECK_INT(s->primitives[0].indices[0], 0);
    CHECK_INT(s->primitives[0].indices[1], 1);
    CHECK_INT(s->primitives[0].indices[2], 2);
    lmb_scene_free(s);
}

/* EXT_mesh_gpu_instancing: 125 copies, each its own instance at a distinct place. */
static void test_gpu_instancing(void)
{
    lmb_scene *s = load("khr-SimpleInstancing/glTF/SimpleInstancing.gltf", NULL);
    if (!s)
        return;
    CHECK_INT(s->instance_count, 125);
    CHECK_INT(s->gpu_instanced_nodes, 1);
    int distinct = 1;
    for (uint32_t i = 0; i < s->instance_count; i++)
        for (uint32_t j = i + 1; j < s->instance_count; j++)
            if (s->instances[i].world[12] == s->instances[j].world[12] &&
                s->instances[i].world[13] == s->instances[j].world[13] &&
                s->instances[i].world[14] == s->instances[j].world[14])
                distinct = 0;
    CHECK(distinct);
    CHECK_INT(s->instances[7].gpu_instance, 7);
    lmb_scene_free(s);
}

/* KHR_lights_punctual: 5 point lights with the file's intensities (cd) and colours. */
static void test_lights(void)
{
    lmb_scene *s = load("khr-LightsPunctualLamp/glTF/LightsPunctualLamp.gltf", NULL);
    if (!s)
        return;
    CHECK_INT(s->light_count, 5);
    double total = 0;
    for (uint32_t l = 0; l < s->light_count; l++) {
        CHECK_INT(s->lights[l].type, LMB_LIGHT_POINT);
        total += s->lights[l].intensity;
    }
    CHECK_NEAR(total, 15 + 1.5 + 80 + 80 + 180, 1e-4);
    CHECK_NEAR(s->lights[0].color[1], 0.6318749785423279, 1e-6);
    lmb_scene_free(s);
}

/* Cornell box (bevy): the ceiling light's emissive factor 1 x KHR_materials_emissive_strength 100. */
static void test_emissive_strength(void)
{
    lmb_scene *s = load("cornell-box-bevy/CornellBox.glb", NULL);
    if (!s)
        return;
    int found = 0;
    for (uint32_t m = 0; m < s->material_count; m++)
        if (lmb_material_is_emissive(&s->materials[m])) {
            found++;
            CHECK_NEAR(s->materials[m].emissive_strength, 100.0, 0);
            CHECK_NEAR(s->materials[m].emissive[0], 100.0, 1e-4);
        }
    CHECK_INT(found, 1);
    lmb_scene_stats st;
    lmb_scene_select_lightmapped(s, &(lmb_config){0});
    lmb_scene_stats_compute(s, &st);
    CHECK_INT(st.triangles_unique, 36);
    CHECK_INT(st.emissive_triangles, 2);
    lmb_scene_free(s);
}

/* Selection: exclude globs win over include globs; zero-area meshes are skipped. */
static void test_selection(void)
{
    lmb_config cfg;
    lmb_config_default(&cfg);
    lmb_scene *s = load("khr-NegativeScaleTest/glTF/NegativeScaleTest.gltf", &cfg);
    if (!s)
        return;
    snprintf(cfg.exclude[0], LMB_PATTERN_LEN, "*Minus1");
    cfg.exclude_count = 1;
    lmb_scene_select_lightmapped(s, &cfg);
    int on = 0;
    for (uint32_t i = 0; i < s->instance_count; i++) {
        on += s->instances[i].lightmapped;
        if (!strcmp(s->instances[i].name, "DarkMinus1")) {
            CHECK_INT(s->instances[i].lightmapped, 0);
            CHECK_CONTAINS(s->instances[i].skip_reason, "exclude '*Minus1'");
        }
    }
    CHECK_INT(on, 11 - 3);
    /* include only "Dark*": Dark1 and DarkMinus1 (DarkMinus1 still excluded) */
    snprintf(cfg.include[0], LMB_PATTERN_LEN, "Dark*");
    cfg.include_count = 1;
    lmb_scene_select_lightmapped(s, &cfg);
    on = 0;
    for (uint32_t i = 0; i < s->instance_count; i++)
        on += s->instances[i].lightmapped;
    CHECK_INT(on, 1);
    lmb_scene_free(s);
}

static const lmb_material *material_named(const lmb_scene *s, const char *name)
{
    for (uint32_t i = 0; i < s->material_count; i++)
        if (!strcmp(s->materials[i].name, name))
            return &s->materials[i];
    fprintf(stderr, "no material '%s'\n", name);
    check_failed_count++;
    return NULL;
}

/* bevy's MixedLightingExample (a Blender export): the wood's base colour and metallicRoughness
 * textures carry KHR_texture_transform (offset, rotation 5 degrees, scale 3): the slot's UV map
 * is T x R x S; metallicFactor is the default 1 with the metalness texture beside it. */
static void test_texture_transform(void)
{
    lmb_scene *s = load("mixed-lighting-bevy/MixedLightingExample.gltf", NULL);
    if (!s)
        return;
    const lmb_material *wood = material_named(s, "wood Brown"), *fabric = material_named(s, "fabric Mystere Mango Velvet");
    if (wood && fabric) {
        const double r = 0.0872664675116539, ox = -0.8635583765172254, oy = 1.125025697811076;
        const double want[6] = {3 * cos(r), 3 * sin(r), ox, -3 * sin(r), 3 * cos(r), oy};
        CHECK_INT(wood->base_color_texture.texture, 9);
        CHECK_INT(wood->base_color_texture.texcoord, 0);
        CHECK_INT(wood->metallic_texture.texture, 8);
        CHECK_NEAR(wood->metallic, 1.0, 0);
        CHECK_INT(wood->spec_gloss, 0);
        for (int k = 0; k < 6; k++) {
            CHECK_NEAR(wood->base_color_texture.uv[k], want[k], 1e-12);
            CHECK_NEAR(wood->metallic_texture.uv[k], want[k], 1e-12);
        }
        const double identity[6] = {1, 0, 0, 0, 1, 0};
        CHECK_INT(fabric->base_color_texture.texture, 1);
        for (int k = 0; k < 6; k++)
            CHECK_NEAR(fabric->base_color_texture.uv[k], identity[k], 0);
        CHECK_INT(fabric->metallic_texture.texture, -1);
    }
    lmb_scene_free(s);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_load SCENES_DIR\n");
        return 2;
    }
    scenes = argv[1];
    test_node_matrix();
    test_shared_mesh();
    test_negative_scale();
    test_sparse();
    test_primitive_modes();
    test_without_indices();
    test_gpu_instancing();
    test_lights();
    test_emissive_strength();
    test_selection();
    test_texture_transform();
    return check_failures();
}
