/*
 * The bounce cache (DESIGN.md section 2, step 6): per atlas, the irradiance E of the last pass
 * as a dilated image, which gather rays read. A gather ray's hit maps through the Embree
 * geometry (instance, primitive) and triangle to the instance's lightmap UV (TEXCOORD_1) and a
 * bilinear lookup; the outgoing diffuse radiance there is B = albedo / pi x E, with albedo =
 * baseColorFactor x baseColorTexture (at the hit's UV, sRGB decoded) x (1 - metallic), the
 * diffuse part a glTF viewer shows.
 * Emission Le is not in the cache: emitters reach every point through the direct stage's
 * area-light sampling, so a gather ray that hits an emitter counts only its reflected light
 * (no light is counted twice).
 * A hit on the back of a surface returns nothing (a single-sided glTF surface is seen from
 * behind only from inside geometry), but for the back of a doubleSided one, which reflects
 * as its front does (glTF: both sides are front): no lightmap holds that side, so the caller
 * estimates its irradiance where the ray met it (lmb_cache_back_irradiance). A hit on a surface with
 * no lightmap (excluded by the config, or with a singular transform) is reported as such: the
 * gather stage then computes direct light at the hit with shadow rays, so those surfaces
 * still bounce their direct light (one bounce; their own indirect light is left out).
 */
#ifndef LMBAKE_BOUNCE_CACHE_H
#define LMBAKE_BOUNCE_CACHE_H

#include <lmbake/lmbake.h>

#include "raytrace/rt_scene.h"
#include "load/textures.h"
#include "pack/layout.h"
#include "texels/texels.h"
#include "cache/texel_sides.h"

typedef struct lmb_cache {
    const lmb_scene *scene;       /* borrowed */
    const lmb_layout *layout;     /* borrowed */
    const lmb_rt *rt;             /* borrowed */
    const lmb_textures *textures; /* borrowed, may be NULL */
    uint32_t atlas_count;
    uint32_t threads;   /* for dilation; 0: all cores (the bake sets it from the config) */
    double ray_spread;  /* a gather ray's angular width (radians): the albedo texture is averaged over
                           hit distance x this (sqrt(pi / samples.gather), the share of the cosine
                           lobe's projected solid angle one ray stands for); 0: point lookups */
    int diffuse_through; /* some material transmits diffusely (KHR_materials_diffuse_transmission) */
    int backs_reflect;  /* 1: a hit on the back of a doubleSided surface is LMB_HIT_BACK, not dark
                           (materials.reflect_sides; the bake sets it) */
    float **irradiance; /* owned: per atlas width x height x 3, dilated (NULL after lmb_cache_release) */
    uint8_t **state;    /* owned: per atlas width x height LMB_TEXEL_* */
    lmb_texel_sides *sides; /* owned: per atlas, the texels beside walls a lookup checks the side of
                               (built by the first lmb_cache_store of the atlas) */
    float **direction;  /* owned, NULL until lmb_cache_store_direction: per atlas width x height x 3,
                           the light's mean direction (directional lightmaps), dilated */
    float **shadowmask; /* owned, NULL until lmb_cache_store_shadowmask: per atlas width x height x 4,
                           the shadowmask lights' visibility (output.shadowmask), dilated */
} lmb_cache;

typedef enum lmb_hit_kind {
    LMB_HIT_DARK = 0,     /* back face: B = 0 */
    LMB_HIT_CACHED = 1,   /* e holds the cached irradiance */
    LMB_HIT_UNMAPPED = 2, /* a surface without a lightmap: the caller computes E */
    LMB_HIT_BACK = 3      /* the back of a doubleSided surface (materials.reflect_sides material): albedo
                             set; no lightmap holds that side, the caller computes E there
                             (lmb_cache_back_irradiance) */
} lmb_hit_kind;

/* Empty images for every atlas of layout. Free with lmb_cache_free, also after an error. */
lmb_status lmb_cache_init(lmb_cache *c, const lmb_scene *scene, const lmb_layout *layout, const lmb_rt *rt,
                          const lmb_textures *textures, lmb_error *err);
void lmb_cache_free(lmb_cache *c);

/* Atlas a's image := e (3 floats per listed texel of t, the texels of atlas a), dilated. */
lmb_status lmb_cache_store(lmb_cache *c, uint32_t a, const lmb_texels *t, const float *e, lmb_error *err);

/* Frees every atlas's irradiance image while nothing gathers (between a pass's gather and its
 * store, when the light is filtered and refined): no lmb_cache_lookup until the next
 * lmb_cache_store of each atlas, which allocates the image again. */
void lmb_cache_release(lmb_cache *c);

/* Atlas a's direction image := d (3 floats per listed texel of t), dilated as the irradiance. */
lmb_status lmb_cache_store_direction(lmb_cache *c, uint32_t a, const lmb_texels *t, const float *d, lmb_error *err);

/* Atlas a's shadowmask image := v (4 floats per listed texel of t), dilated as the irradiance. */
lmb_status lmb_cache_store_shadowmask(lmb_cache *c, uint32_t a, const lmb_texels *t, const float *v, lmb_error *err);

/* At a ray hit: albedo / pi (RGB, the reflected share) and, for LMB_HIT_CACHED, the irradiance E
 * (RGB); for LMB_HIT_BACK of a surface that transmits diffusely, E holds the front's (which it
 * lets through to the back). */
lmb_hit_kind lmb_cache_lookup(const lmb_cache *c, const lmb_rt_hit *hit, double albedo_over_pi[3], double e[3]);

/* KHR_materials_diffuse_transmission at a hit: its factor f (returned; 0: none) and
 * f x colour / pi into out_over_pi: the radiance leaving one side per lux on the other. */
double lmb_cache_diffuse_through(const lmb_cache *c, const lmb_rt_hit *hit, double out_over_pi[3]);

#endif
