/*
 * glTF materials -> lmb_material (the load stage): the factors and texture slots the baker
 * reads, with each slot's KHR_texture_transform turned into an affine UV map and its texCoord
 * override applied (the extension's texCoord wins over the textureInfo's). A
 * KHR_materials_pbrSpecularGlossiness material takes its diffuse factor and texture as the
 * base colour, metallic 0, and keeps its specular factor and texture: the extension's
 * c_diff = diffuse x (1 - max(specular.rgb)) is evaluated per texel (textures.c). The
 * extension wins over pbrMetallicRoughness when both are given, as it says implementations
 * that support it must.
 */
#include "load_internal.h"
#include "textures.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Converts one textureInfo; a non-finite transform is an error naming material and slot. */
static lmb_status texture_ref(const char *path, const char *material, const char *slot,
                              const lmb_gltf_texture_info *g, lmb_texture_ref *r, lmb_error *err)
{
    r->texture = g->index;
    r->texcoord = g->has_transform && g->transform_texcoord >= 0 ? g->transform_texcoord : g->texcoord;
    r->uv[0] = r->uv[4] = 1.0;
    r->uv[1] = r->uv[2] = r->uv[3] = r->uv[5] = 0.0;
    if (!g->has_transform)
        return LMB_OK;
    const double v[5] = {g->offset[0], g->offset[1], g->rotation, g->scale[0], g->scale[1]};
    for (int k = 0; k < 5; k++)
        if (!isfinite(v[k]))
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: %s KHR_texture_transform has a value that is not a "
                                 "finite number", path, material, slot);
    lmb_texture_transform_matrix(g->offset, g->rotation, g->scale, r->uv);
    return LMB_OK;
}

/* alphaMode, alphaCutoff, KHR_materials_transmission and _volume: what light the surface lets
 * through (docs/materials.md). preflight.c has checked alphaCutoff in the JSON; the values here
 * are checked again for a document that did not come through it. */
static lmb_status load_passage(const char *path, const lmb_gltf_material *g, const char *label, lmb_material *m,
                               lmb_error *err)
{
    if (g->alpha_mode < 0)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: alphaMode must be OPAQUE, MASK or BLEND", path, label);
    m->alpha_mode = (lmb_alpha_mode)g->alpha_mode;
    if (!(g->alpha_cutoff >= 0.0 && g->alpha_cutoff <= 1.0))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: alphaCutoff %g must be a number in [0, 1]", path, label,
                             g->alpha_cutoff);
    m->alpha_cutoff = (float)g->alpha_cutoff;
    m->transmission_texture.texture = -1;
    m->volume_tint[0] = m->volume_tint[1] = m->volume_tint[2] = 1.0f;
    if (!(g->diffuse_transmission >= 0.0 && g->diffuse_transmission <= 1.0))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: KHR_materials_diffuse_transmission diffuseTransmissionFactor %g "
                             "must be a number in [0, 1]", path, label, g->diffuse_transmission);
    m->diffuse_transmission = (float)g->diffuse_transmission;
    for (int c = 0; c < 3; c++) {
        if (!(g->diffuse_transmission_color[c] >= 0.0 && g->diffuse_transmission_color[c] <= 1.0))
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: KHR_materials_diffuse_transmission "
                                 "diffuseTransmissionColorFactor[%d] %g must be in [0, 1]", path, label, c,
                                 g->diffuse_transmission_color[c]);
        m->diffuse_transmission_color[c] = (float)g->diffuse_transmission_color[c];
    }
    if (!g->has_transmission)
        return LMB_OK;
    if (!(g->transmission >= 0.0 && g->transmission <= 1.0))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: KHR_materials_transmission transmissionFactor %g must be a "
                             "number in [0, 1]", path, label, g->transmission);
    m->transmission = (float)g->transmission;
    lmb_status st = texture_ref(path, label, "transmissionTexture", &g->transmission_texture, &m->transmission_texture,
                                err);
    if (st != LMB_OK || !g->has_volume)
        return st;
    if (!(g->thickness >= 0.0) || !(g->attenuation_distance > 0.0))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: KHR_materials_volume needs thicknessFactor >= 0 and "
                             "attenuationDistance > 0 (got %g and %g)", path, label, g->thickness,
                             g->attenuation_distance);
    m->volume = g->thickness > 0.0;
    for (int c = 0; c < 3; c++) {
        double col = g->attenuation_color[c];
        if (!(col >= 0.0 && col <= 1.0))
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: KHR_materials_volume attenuationColor[%d] %g must be in "
                                 "[0, 1]", path, label, c, col);
        /* Beer-Lambert over the thickness the material states (the glTF sample viewer's model):
         * isinf(distance): no attenuation */
        m->volume_tint[c] = isinf(g->attenuation_distance) ? 1.0f
                                                           : (float)pow(col, g->thickness / g->attenuation_distance);
    }
    return LMB_OK;
}

static lmb_status load_one(const char *path, const lmb_gltf_material *g, const char *label, lmb_material *m,
                           lmb_error *err)
{
    lmb_status pst = load_passage(path, g, label, m, err);
    if (pst != LMB_OK)
        return pst;
    if (!(g->emissive_strength >= 0.0) || g->emissive_strength > 1e30)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: KHR_materials_emissive_strength %g must be a finite number >= 0",
                             path, label, g->emissive_strength);
    for (int c = 0; c < 3; c++)
        m->emissive[c] = (float)(g->emissive[c] * g->emissive_strength);
    m->emissive_strength = (float)g->emissive_strength;
    m->double_sided = g->double_sided;
    m->unlit = g->unlit;
    m->spec_gloss = g->spec_gloss;
    lmb_status st = texture_ref(path, label, "emissiveTexture", &g->emissive_texture, &m->emissive_texture, err);
    if (st != LMB_OK)
        return st;
    if (g->spec_gloss) {
        for (int c = 0; c < 4; c++)
            m->base_color[c] = (float)g->diffuse[c];
        for (int c = 0; c < 3; c++)
            m->specular[c] = (float)g->specular[c];
        m->metallic = 0.0f;
        m->metallic_texture.texture = -1;
        st = texture_ref(path, label, "diffuseTexture", &g->diffuse_texture, &m->base_color_texture, err);
        if (st == LMB_OK)
            st = texture_ref(path, label, "specularGlossinessTexture", &g->specular_glossiness_texture,
                             &m->specular_texture, err);
        return st;
    }
    for (int c = 0; c < 4; c++)
        m->base_color[c] = (float)g->base_color[c];
    m->metallic = (float)g->metallic;
    m->specular_texture.texture = -1;
    st = texture_ref(path, label, "baseColorTexture", &g->base_color_texture, &m->base_color_texture, err);
    if (st == LMB_OK)
        st = texture_ref(path, label, "metallicRoughnessTexture", &g->metallic_roughness_texture,
                         &m->metallic_texture, err);
    return st;
}

lmb_status lmb_load_materials(const char *path, const lmb_gltf_view *v, lmb_scene *s, lmb_error *err)
{
    s->materials = calloc(v->material_count + 1, sizeof *s->materials);
    if (!s->materials)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
    for (uint32_t i = 0; i < v->material_count; i++) {
        const lmb_gltf_material *g = &v->materials[i];
        lmb_material *m = &s->materials[i];
        char label[160];
        lmb_object_label(label, "material", i, g->name);
        m->name = lmb_strdup(g->name && *g->name ? g->name : label);
        if (!m->name)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
        s->material_count = i + 1;
        lmb_status st = load_one(path, g, label, m, err);
        if (st != LMB_OK)
            return st;
    }
    return LMB_OK;
}
