/*
 * The extension table. The rule: lmbake bakes diffuse irradiance, so an extension that only
 * changes specular reflection, layers on top of the base (sheen, clear coat), refraction,
 * animation or metadata changes nothing the bake reads, and a file requiring it is baked with
 * a warning naming the file and the extension. Compressed geometry (Draco, meshopt) is decoded
 * before the file is read (decompress.h). KHR_materials_diffuse_transmission is baked with a
 * warning as an opaque surface (its diffusely transmitted light is not modelled yet). One
 * lmbake does not know is not listed: requiring it is an error. EXT_lights_image_based is the sky when the config sets none
 * (lights/sky.c: its irradiance spherical harmonics; its specular cube maps are not read).
 * Choices worth knowing:
 *   - KHR_materials_unlit: an unlit surface shows its base colour whatever the light, so it
 *     reflects none in the bake (albedo 0: no invented bounce off a backdrop or sky dome); it
 *     still blocks light and still emits its emissiveFactor, if any.
 *   - KHR_materials_transmission / volume: a thin surface that lets transmission x base colour
 *     of the light through (a volume: tinted once more by its attenuation over its thickness on
 *     entering) and reflects the rest of its diffuse colour (docs/materials.md).
 *   - KHR_materials_variants: the primitive's default material is baked.
 */
#include "extensions.h"

#include <string.h>

static const lmb_extension_info table[] = {
    {"KHR_lights_punctual", LMB_EXT_SUPPORTED, NULL},
    {"EXT_lights_image_based", LMB_EXT_SUPPORTED, NULL},
    {"KHR_materials_emissive_strength", LMB_EXT_SUPPORTED, NULL},
    {"EXT_mesh_gpu_instancing", LMB_EXT_SUPPORTED, NULL},
    {"KHR_mesh_quantization", LMB_EXT_SUPPORTED, NULL},
    {"MSFT_lod", LMB_EXT_SUPPORTED, NULL}, /* lower levels of detail: lit by the probes (select.c) */
    {"EXT_meshopt_compression", LMB_EXT_SUPPORTED, NULL},    /* decoded before loading: decompress.h */
    {"KHR_draco_mesh_compression", LMB_EXT_SUPPORTED, NULL}, /* decoded before loading: decompress.h */
    {"KHR_texture_transform", LMB_EXT_SUPPORTED, NULL},
    {"KHR_materials_pbrSpecularGlossiness", LMB_EXT_SUPPORTED, NULL},
    {"KHR_materials_sheen", LMB_EXT_IGNORED, "the sheen layer is not baked; the base colour is the albedo"},
    {"KHR_materials_clearcoat", LMB_EXT_IGNORED, "the clear coat is not baked; the base colour is the albedo"},
    {"KHR_materials_specular", LMB_EXT_IGNORED, "it changes specular reflection only, which a diffuse bake ignores"},
    {"KHR_materials_ior", LMB_EXT_IGNORED, "it changes specular reflection only, which a diffuse bake ignores"},
    {"KHR_materials_iridescence", LMB_EXT_IGNORED, "it changes specular reflection only, which a diffuse bake ignores"},
    {"KHR_materials_anisotropy", LMB_EXT_IGNORED, "it changes specular reflection only, which a diffuse bake ignores"},
    {"KHR_materials_dispersion", LMB_EXT_IGNORED, "it changes refraction only, which a diffuse bake ignores"},
    {"KHR_materials_transmission", LMB_EXT_SUPPORTED, NULL},
    {"KHR_materials_volume", LMB_EXT_SUPPORTED, NULL},
    {"KHR_materials_diffuse_transmission", LMB_EXT_SUPPORTED, NULL}, /* cache/back_light.h */
    {"KHR_materials_variants", LMB_EXT_IGNORED, "each primitive is baked with its default material, not the variants"},
    {"KHR_materials_unlit", LMB_EXT_IGNORED,
     "unlit materials reflect no light in the bake (their colour does not depend on light) but still block it"},
    {"KHR_animation_pointer", LMB_EXT_IGNORED, "animations are not baked; the static values are"},
    {"KHR_xmp_json_ld", LMB_EXT_IGNORED, "metadata only"},
    {"KHR_texture_basisu", LMB_EXT_IMAGE, "KTX2 images are not decoded; textures use their fallback image"},
    {"EXT_texture_webp", LMB_EXT_SUPPORTED, NULL}, /* WebP through OpenImageIO; its source where there is no core one */
    {"EXT_texture_avif", LMB_EXT_IMAGE, "textures use their fallback (PNG or JPEG) image"},
    {"MSFT_texture_dds", LMB_EXT_IMAGE, "textures use their fallback (PNG or JPEG) image"},
};

const lmb_extension_info *lmb_extension_find(const char *name)
{
    for (size_t i = 0; i < sizeof table / sizeof *table; i++)
        if (!strcmp(table[i].name, name))
            return &table[i];
    return NULL;
}
