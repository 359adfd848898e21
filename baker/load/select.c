/*
 * Which instances get a lightmap. Order of precedence, first match wins:
 *   1. a node extras flag (cfg->extras_key, e.g. "extras": {"lightmap": false}) forces it;
 *   2. a name matching an `exclude` glob removes it;
 *   3. a name matching an `include` glob keeps it (default "*": everything);
 * and whatever the rules say, an instance without usable triangles or with a singular
 * transform is skipped, with the reason recorded for `lmbake inspect`. Before all of them, what
 * moves or stands in for something else (a skinned mesh, morph targets, a lower level of
 * detail: lmb_motion) is neither lightmapped nor an occluder unless its extras flag is true:
 * the light probes light it (Unity, Godot and Unreal bake only static scenery the same way). EXT_mesh_gpu_instancing
 * copies are lightmapped like nodes: they share one TEXCOORD_1 layout, each with its own
 * rectangle of the atlas (pack/rect_instances.c).
 */
#include <lmbake/lmbake.h>

#include "../util/mat4.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static int matches_any(const char (*patterns)[LMB_PATTERN_LEN], uint32_t count, const char *node_name,
                       const char *mesh_name, const char **hit)
{
    for (uint32_t i = 0; i < count; i++)
        if (lmb_glob_match(patterns[i], node_name) || lmb_glob_match(patterns[i], mesh_name)) {
            *hit = patterns[i];
            return 1;
        }
    return 0;
}

void lmb_scene_select_lightmapped(lmb_scene *s, const lmb_config *cfg)
{
    for (uint32_t i = 0; i < s->instance_count; i++) {
        lmb_instance *in = &s->instances[i];
        const lmb_mesh *mesh = &s->meshes[in->mesh];
        const char *name = in->name, *hit = NULL;
        in->lightmapped = 0;
        in->occludes = 1;
        in->skip_reason[0] = '\0';
        if (in->motion != LMB_STATIC && in->extras_lightmap != 1) {
            static const char *const why[] = {"", "skinned", "morph targets", "a lower level of detail"};
            snprintf(in->skip_reason, sizeof in->skip_reason, "%s: lit by the probes, casts no baked shadow",
                     why[in->motion]);
            in->occludes = 0;
        } else if (mesh->triangle_count == mesh->degenerate_count)
            snprintf(in->skip_reason, sizeof in->skip_reason, "%s",
                     mesh->triangle_count ? "every triangle has zero area" : "no triangles");
        else if (!lmb_mat4_is_finite(in->world) || fabs(lmb_mat4_det3(in->world)) < 1e-30)
            snprintf(in->skip_reason, sizeof in->skip_reason, "singular transform");
        else if (in->extras_lightmap == 0)
            snprintf(in->skip_reason, sizeof in->skip_reason, "extras.%.60s is false", cfg->extras_key);
        else if (in->extras_lightmap == 1)
            in->lightmapped = 1;
        else if (matches_any(cfg->exclude, cfg->exclude_count, name, mesh->name, &hit))
            snprintf(in->skip_reason, sizeof in->skip_reason, "matches exclude '%.60s'", hit);
        else if (!matches_any(cfg->include, cfg->include_count, name, mesh->name, &hit))
            snprintf(in->skip_reason, sizeof in->skip_reason, "matches no include pattern");
        else
            in->lightmapped = 1;
    }
}
