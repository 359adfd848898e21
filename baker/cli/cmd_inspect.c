/*
 * `lmbake inspect SCENE`: what a level holds and what a bake will do with it: meshes,
 * primitives, triangles (unique and instanced), instances and whether each is lightmapped
 * (and if not, why), materials (albedo, emissive = area light), punctual lights.
 * --json prints the same facts for scripts.
 */
#include "cli_common.h"
#include "commands.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char help[] =
    "usage: lmbake inspect SCENE [-c CONFIG] [--json] [--quiet]\n"
    "\n"
    "Lists what SCENE (.gltf or .glb) holds and what a bake will lightmap.\n"
    "\n"
    "  -c, --config FILE   bake config (YAML) deciding what is lightmapped\n"
    "      --json          machine-readable output on stdout\n"
    "  -q, --quiet         no warnings on stderr\n"
    "  -h, --help          this help\n"
    "\n"
    "exit codes: 0 ok, 1 usage error, 2 bad input, 3 internal error\n";

static const char *light_type_name(lmb_light_type t)
{
    return t == LMB_LIGHT_POINT ? "point" : t == LMB_LIGHT_SPOT ? "spot" : "directional";
}

/* JSON string with the escapes RFC 8259 requires. */
static void json_str(const char *s)
{
    putchar('"');
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            printf("\\%c", c);
        else if (c < 0x20)
            printf("\\u%04x", c);
        else
            putchar(c);
    }
    putchar('"');
}

/* One material line: what its diffuse albedo is made of (textures.h lmb_material_albedo) and its emission. */
static void print_material(uint32_t m, const lmb_material *mat)
{
    if (mat->spec_gloss) {
        printf("  [%u] '%s': spec-gloss, diffuse (%.3g, %.3g, %.3g)%s x (1 - max specular (%.3g, %.3g, %.3g)%s)", m,
               mat->name, mat->base_color[0], mat->base_color[1], mat->base_color[2],
               mat->base_color_texture.texture >= 0 ? " x texture" : "", mat->specular[0], mat->specular[1],
               mat->specular[2], mat->specular_texture.texture >= 0 ? " x texture" : "");
        if (mat->specular_texture.texture < 0 &&
            fmaxf(mat->specular[0], fmaxf(mat->specular[1], mat->specular[2])) >= 1.0f)
            printf(" (specular 1, the extension's default: no diffuse, so a lightmap shows black on it in viewers)");
    } else {
        printf("  [%u] '%s': base colour (%.3g, %.3g, %.3g)%s, metallic %.3g%s", m, mat->name, mat->base_color[0],
               mat->base_color[1], mat->base_color[2], mat->base_color_texture.texture >= 0 ? " x texture" : "",
               mat->metallic, mat->metallic_texture.texture >= 0 && mat->metallic > 0 ? " x texture (blue)" : "");
        if (mat->metallic >= 1.0f && mat->metallic_texture.texture < 0)
            printf(" (fully metallic: no diffuse, so a lightmap shows black on it in viewers)");
    }
    if (mat->unlit)
        printf(", unlit (reflects no light in the bake)");
    if (mat->alpha_mode == LMB_ALPHA_MASK)
        printf(", alpha MASK (cut away where alpha < %.3g: light passes)", mat->alpha_cutoff);
    else if (mat->alpha_mode == LMB_ALPHA_BLEND)
        printf(", alpha BLEND (1 - alpha of the light passes; alpha %.3g%s)", mat->base_color[3],
               mat->base_color_texture.texture >= 0 ? " x texture" : "");
    if (mat->transmission > 0)
        printf(", transmission %.3g%s (light passes tinted by the base colour%s)", mat->transmission,
               mat->transmission_texture.texture >= 0 ? " x texture" : "", mat->volume ? " and the volume" : "");
    if (lmb_material_is_emissive(mat))
        printf(", emissive (%.4g, %.4g, %.4g) nits (strength %.4g)%s -> area light", mat->emissive[0],
               mat->emissive[1], mat->emissive[2], mat->emissive_strength,
               mat->emissive_texture.texture >= 0 ? " x texture" : "");
}

/* "lightmapped" below is the selection (lightmap.include/exclude); the layout may still send a
 * mesh drawn more than once to the light probes when the texel budget cannot hold its charts
 * (pack/probe_lit.c), which only the bake knows: say which meshes could go. */
static void print_probe_candidates(const lmb_scene *s)
{
    uint32_t *drawn = calloc((size_t)s->mesh_count + 1, sizeof *drawn), meshes = 0, copies = 0;
    if (!drawn)
        return;
    for (uint32_t i = 0; i < s->instance_count; i++)
        drawn[s->instances[i].mesh] += s->instances[i].lightmapped != 0;
    for (uint32_t m = 0; m < s->mesh_count; m++)
        if (drawn[m] >= 2) {
            meshes++;
            copies += drawn[m];
        }
    free(drawn);
    if (meshes)
        printf("  (%u lightmapped mesh(es) drawn more than once, %u copies: if the texel budget cannot hold their "
               "charts, the bake lights them by the light probes instead and its warning names them)\n",
               meshes, copies);
}

static void print_text(const lmb_scene *s, const lmb_scene_stats *st)
{
    printf("scene: %s\n", s->path);
    printf("  nodes %u, meshes %u, primitives %u, instances %u, materials %u, lights %u\n", s->node_count,
           s->mesh_count, s->primitive_count, s->instance_count, s->material_count, s->light_count);
    printf("  triangles: %llu unique, %llu in nodes", (unsigned long long)st->triangles_unique,
           (unsigned long long)st->triangles_in_nodes);
    if (s->gpu_instanced_nodes)
        printf(", %llu with EXT_mesh_gpu_instancing copies", (unsigned long long)st->triangles_instanced);
    printf(" (%llu unique with zero area)\n", (unsigned long long)st->degenerate_unique);
    if (st->triangles_skipped)
        printf("  skipped: %llu more triangles in primitives without POSITION (%llu with them)\n",
               (unsigned long long)st->triangles_skipped,
               (unsigned long long)(st->triangles_unique + st->triangles_skipped));
    printf("meshes:\n");
    for (uint32_t m = 0; m < s->mesh_count; m++) {
        const lmb_mesh *mesh = &s->meshes[m];
        int uv1 = 0;
        for (uint32_t p = 0; p < mesh->primitive_count; p++)
            uv1 |= s->primitives[mesh->first_primitive + p].uv1 != NULL;
        printf("  [%u] '%s': %u primitives, %u triangles", m, mesh->name, mesh->primitive_count, mesh->triangle_count);
        if (mesh->degenerate_count)
            printf(" (%u zero-area)", mesh->degenerate_count);
        if (mesh->skipped_primitives)
            printf(", %u primitives skipped (points, lines or no POSITION)", mesh->skipped_primitives);
        printf("%s\n", uv1 ? ", has TEXCOORD_1" : "");
    }
    printf("instances:\n");
    for (uint32_t i = 0; i < s->instance_count; i++) {
        const lmb_instance *in = &s->instances[i];
        printf("  [%u] '%s' -> mesh '%s'%s: %s%s\n", i, in->name, s->meshes[in->mesh].name,
               in->flips_winding ? " (mirrored)" : "", in->lightmapped ? "lightmapped" : "skipped: ",
               in->skip_reason);
    }
    print_probe_candidates(s);
    printf("materials:\n");
    for (uint32_t m = 0; m < s->material_count; m++) {
        const lmb_material *mat = &s->materials[m];
        print_material(m, mat);
        printf("\n");
    }
    printf("lights:\n");
    for (uint32_t l = 0; l < s->light_count; l++) {
        const lmb_light *li = &s->lights[l];
        printf("  [%u] %s '%s': intensity %.4g %s, colour (%.3g, %.3g, %.3g)", l, light_type_name(li->type), li->name,
               li->intensity, li->type == LMB_LIGHT_DIRECTIONAL ? "lux" : "cd", li->color[0], li->color[1], li->color[2]);
        if (li->type != LMB_LIGHT_DIRECTIONAL)
            printf(", at (%.4g, %.4g, %.4g)", li->position[0], li->position[1], li->position[2]);
        if (li->type != LMB_LIGHT_POINT)
            printf(", pointing (%.3f, %.3f, %.3f)", li->direction[0], li->direction[1], li->direction[2]);
        if (li->type == LMB_LIGHT_SPOT)
            printf(", cone %.3g..%.3g rad", li->inner_cone, li->outer_cone);
        printf("\n");
    }
    printf("summary: %u of %u instances lightmapped (%llu triangles); %u emissive materials, %llu emissive triangles "
           "(area lights); %u punctual lights\n",
           st->lightmapped_instances, s->instance_count, (unsigned long long)st->lightmapped_triangles,
           st->emissive_materials, (unsigned long long)st->emissive_triangles, s->light_count);
}

static void print_json(const lmb_scene *s, const lmb_scene_stats *st)
{
    printf("{\"scene\": ");
    json_str(s->path);
    printf(", \"nodes\": %u, \"meshes\": %u, \"primitives\": %u, \"instances\": %u, \"materials\": %u, "
           "\"lights\": %u,\n \"triangles\": {\"unique\": %llu, \"in_nodes\": %llu, \"instanced\": %llu, "
           "\"zero_area_unique\": %llu, \"skipped_no_position\": %llu, \"lightmapped\": %llu, \"emissive\": %llu},\n \"mesh_list\": [",
           s->node_count, s->mesh_count, s->primitive_count, s->instance_count, s->material_count, s->light_count,
           (unsigned long long)st->triangles_unique, (unsigned long long)st->triangles_in_nodes,
           (unsigned long long)st->triangles_instanced, (unsigned long long)st->degenerate_unique,
           (unsigned long long)st->triangles_skipped,
           (unsigned long long)st->lightmapped_triangles, (unsigned long long)st->emissive_triangles);
    for (uint32_t m = 0; m < s->mesh_count; m++) {
        printf("%s{\"name\": ", m ? ", " : "");
        json_str(s->meshes[m].name);
        printf(", \"triangles\": %u, \"zero_area\": %u}", s->meshes[m].triangle_count, s->meshes[m].degenerate_count);
    }
    printf("],\n \"instance_list\": [");
    for (uint32_t i = 0; i < s->instance_count; i++) {
        const lmb_instance *in = &s->instances[i];
        printf("%s\n  {\"name\": ", i ? "," : "");
        json_str(in->name);
        printf(", \"mesh\": %u, \"mirrored\": %s, \"lightmapped\": %s, \"skip_reason\": ", in->mesh,
               in->flips_winding ? "true" : "false", in->lightmapped ? "true" : "false");
        json_str(in->skip_reason);
        printf("}");
    }
    printf("],\n \"material_list\": [");
    for (uint32_t m = 0; m < s->material_count; m++) {
        const lmb_material *mat = &s->materials[m];
        printf("%s\n  {\"name\": ", m ? "," : "");
        json_str(mat->name);
        printf(", \"model\": \"%s\", \"base_color\": [%.6g, %.6g, %.6g, %.6g], \"metallic\": %.6g, "
               "\"emissive\": [%.6g, %.6g, %.6g], \"emissive_strength\": %.6g}",
               mat->unlit ? "unlit" : mat->spec_gloss ? "spec-gloss" : "metal-rough", mat->base_color[0],
               mat->base_color[1], mat->base_color[2], mat->base_color[3], mat->metallic, mat->emissive[0],
               mat->emissive[1], mat->emissive[2], mat->emissive_strength);
    }
    printf("],\n \"light_list\": [");
    for (uint32_t l = 0; l < s->light_count; l++) {
        const lmb_light *li = &s->lights[l];
        printf("%s\n  {\"name\": ", l ? "," : "");
        json_str(li->name);
        printf(", \"type\": \"%s\", \"intensity\": %.6g, \"color\": [%.6g, %.6g, %.6g], \"position\": [%.6g, %.6g, %.6g], "
               "\"direction\": [%.6g, %.6g, %.6g]}",
               light_type_name(li->type), li->intensity, li->color[0], li->color[1], li->color[2], li->position[0],
               li->position[1], li->position[2], li->direction[0], li->direction[1], li->direction[2]);
    }
    printf("]}\n");
}

int cmd_inspect(int argc, char **argv)
{
    const char *scene_path = NULL, *config_path = NULL;
    int json = 0, quiet = 0;
    for (int i = 1; i < argc; i++) {
        const char *v;
        int r;
        if (cli_is_flag(argv[i], "--help", "-h")) {
            fputs(help, stdout);
            return LMB_OK;
        } else if ((r = cli_opt_value(argc, argv, &i, "--config", "-c", &v)) != 0) {
            if (r < 0)
                return cli_usage_error("inspect", "%s needs a file", argv[i]);
            config_path = v;
        } else if (cli_is_flag(argv[i], "--json", NULL)) {
            json = 1;
        } else if (cli_is_flag(argv[i], "--quiet", "-q")) {
            quiet = 1;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            return cli_usage_error("inspect", "unknown option '%s'", argv[i]);
        } else if (scene_path) {
            return cli_usage_error("inspect", "one scene at a time ('%s' and '%s')", scene_path, argv[i]);
        } else {
            scene_path = argv[i];
        }
    }
    if (!scene_path)
        return cli_usage_error("inspect", "no SCENE given");
    lmb_config cfg;
    lmb_error err = {LMB_OK, ""};
    lmb_config_default(&cfg);
    if (config_path && lmb_config_load(config_path, &cfg, &err) != LMB_OK)
        return cli_fail(&err);
    cli_warnings warnings = {0, quiet};
    lmb_log log = cli_log(&warnings);
    if (lmb_config_lint(&cfg, &log, &err) != LMB_OK)
        return cli_fail(&err);
    lmb_scene *scene;
    if (lmb_scene_load(scene_path, &cfg, &scene, &log, &err) != LMB_OK)
        return cli_fail(&err);
    lmb_scene_select_lightmapped(scene, &cfg);
    lmb_scene_stats st;
    lmb_scene_stats_compute(scene, &st);
    if (json)
        print_json(scene, &st);
    else
        print_text(scene, &st);
    lmb_scene_free(scene);
    return LMB_OK;
}
