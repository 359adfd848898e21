/*
 * What light a surface lets through where a ray meets it, from its glTF material (docs/materials.md):
 *   - alphaMode MASK: absent where alpha = baseColorFactor.a x baseColorTexture.a x COLOR_0.a is
 *     below alphaCutoff (the ray goes on as if nothing were there), opaque elsewhere;
 *   - alphaMode BLEND: coverage: a share alpha of the surface is there, 1 - alpha of the light
 *     passes untouched;
 *   - KHR_materials_transmission: of the covered share, transmission x base colour x (1 - metallic)
 *     passes (a thin surface: glTF's specular BTDF at roughness 0 sends light straight on, tinted by
 *     the base colour; its Fresnel reflection is specular, which a diffuse bake leaves out for every
 *     surface alike), and (1 - transmission) of the diffuse colour reflects;
 *   - KHR_materials_volume (thicknessFactor > 0): a closed mesh; light is tinted on entering (a front
 *     face) by the above and by attenuationColor^(thickness / attenuationDistance) (Beer-Lambert over
 *     the thickness the material gives, as the Khronos sample viewer does), and leaves through the back
 *     faces untinted.
 * Surfaces whose material does none of this are opaque, and the ray tracer attaches no filter to them
 * (rt_scene.c): a level without such materials traces as before.
 */
#ifndef LMBAKE_RT_SURFACE_H
#define LMBAKE_RT_SURFACE_H

#include <lmbake/lmbake.h>

#include "load/textures.h"

enum {
    LMB_SURFACE_CUT = 1,     /* MASK: present or absent by alpha */
    LMB_SURFACE_PARTIAL = 2  /* BLEND or transmission: some light passes where it is present */
};

/* A primitive's surface as rays see it. */
typedef struct lmb_rt_surface {
    const lmb_material *material;   /* NULL: glTF's default material (opaque) */
    const lmb_primitive *primitive;
    const lmb_textures *textures;   /* may be NULL: factors only */
    int kind;                       /* LMB_SURFACE_* bits; 0: opaque */
} lmb_rt_surface;

/* The surface of primitive pr (material m, NULL for the default). */
lmb_rt_surface lmb_rt_surface_of(const lmb_material *m, const lmb_primitive *pr, const lmb_textures *tx);

/* 1 where a MASK surface is cut away at barycentrics (b1, b2) of its triangle tri. */
int lmb_rt_surface_cut(const lmb_rt_surface *sf, uint32_t tri, double b1, double b2);

/* At a hit on a present part: the light that passes (RGB in [0, 1]; 0 0 0 for an opaque surface) and
 * the share of the surface that is there to reflect (`cover`, 1 but for BLEND). backface: the ray met
 * the back of the triangle (a volume's exit). */
void lmb_rt_surface_pass(const lmb_rt_surface *sf, uint32_t tri, double b1, double b2, int backface, double pass[3],
                         double *cover);

#endif
