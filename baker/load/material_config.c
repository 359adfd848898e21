/*
 * Materials as the bake config amends them (materials.default, materials.override): what a
 * level needs when its file leaves materials out or sets them for rendering, not for bouncing
 * light. glTF's default material (a primitive with no material) is white and fully metallic,
 * so its diffuse albedo is 0 and it bounces nothing: correct by the spec, a surprise in a bake
 * (Godot's importer makes such primitives dielectric; Unity's bake counts rough metal as half
 * diffuse). lmbake keeps the spec and says so, unless materials.default.albedo gives one.
 */
#include "load_internal.h"

#include <stdlib.h>
#include <string.h>

lmb_status lmb_apply_material_config(lmb_scene *s, const lmb_config *cfg, const lmb_log *log)
{
    int have_default = cfg && cfg->default_albedo[0] >= 0;
    for (int k = 0; k < 3; k++)
        s->default_albedo[k] = have_default ? cfg->default_albedo[k] : 0.0;
    s->default_albedo_given = have_default;
    /* primitives drawn with glTF's default material */
    uint32_t drawn = 0, bare = 0;
    for (uint32_t i = 0; i < s->instance_count; i++) {
        const lmb_mesh *m = &s->meshes[s->instances[i].mesh];
        for (uint32_t p = 0; p < m->primitive_count; p++) {
            drawn++;
            bare += s->primitives[m->first_primitive + p].material < 0;
        }
    }
    if (bare && have_default)
        lmb_info(log, "%s: %u of %u drawn primitive(s) have no material: they bounce light with albedo [%g, %g, %g] "
                 "(materials.default.albedo)", s->path, bare, drawn, s->default_albedo[0], s->default_albedo[1],
                 s->default_albedo[2]);
    else if (bare)
        lmb_warn(log, "%s: %u of %u drawn primitive(s) have no material, so they get glTF's default material, which is "
                 "fully metallic: they reflect no light into the bake (diffuse albedo 0) and show black under a "
                 "lightmap; set materials.default.albedo (e.g. [0.7, 0.7, 0.7]) to give them one", s->path, bare, drawn);
    /* overrides: the first entry whose glob matches a material's name */
    uint32_t n = cfg ? cfg->material_override_count : 0;
    uint32_t *used = calloc((size_t)n + 1, sizeof *used);
    if (!used)
        return LMB_ERR_INTERNAL;
    for (uint32_t i = 0; i < s->material_count; i++) {
        lmb_material *mat = &s->materials[i];
        for (uint32_t k = 0; k < n; k++) {
            const lmb_material_override *o = &cfg->material_overrides[k];
            if (!lmb_glob_match(o->pattern, mat->name))
                continue;
            used[k]++;
            if (o->albedo[0] >= 0) { /* a plain diffuse surface of that albedo */
                for (int c = 0; c < 3; c++)
                    mat->base_color[c] = (float)o->albedo[c];
                mat->base_color_texture.texture = -1;
                mat->metallic = 0.0f;
                mat->metallic_texture.texture = -1;
                mat->spec_gloss = 0;
                mat->unlit = 0;
            }
            if (o->emissive[0] >= 0) {
                for (int c = 0; c < 3; c++)
                    mat->emissive[c] = (float)o->emissive[c];
                mat->emissive_strength = 1.0f;
                mat->emissive_texture.texture = -1;
            }
            break;
        }
    }
    for (uint32_t k = 0; k < n; k++) {
        if (used[k])
            lmb_info(log, "materials.override '%s': %u material(s)", cfg->material_overrides[k].pattern, used[k]);
        else
            lmb_warn(log, "materials.override '%s' matches no material name in %s", cfg->material_overrides[k].pattern,
                     s->path);
    }
    free(used);
    return LMB_OK;
}
