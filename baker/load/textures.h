/*
 * Material textures the baker reads (emissive for area lights; base colour, metalness and
 * spec-gloss diffuse/specular for the albedo of bounces), decoded once through the
 * OpenImageIO adapter from the glTF's external files, buffer views or data URIs.
 *   - Colour textures (base colour, emissive, spec-gloss diffuse and specular) are sRGB
 *     encoded and converted to linear; data textures (metallicRoughness) are linear and kept
 *     as stored (glTF 2.0 section 3.9.2 / 3.9.3; KHR_materials_pbrSpecularGlossiness).
 *   - Lookups follow the texture's sampler: wrapS / wrapT (REPEAT, MIRRORED_REPEAT,
 *     CLAMP_TO_EDGE; glTF 2.0 section 3.8.4), and magFilter NEAREST picks the nearest texel
 *     (otherwise bilinear). Minification filters and mipmaps do not apply: the baker looks a
 *     texture up at points, not over a pixel's footprint.
 *   - KHR_texture_transform is an affine map of the UVs before the lookup (lmb_texture_ref.uv).
 */
#ifndef LMBAKE_TEXTURES_H
#define LMBAKE_TEXTURES_H

#include <lmbake/lmbake.h>

typedef enum lmb_tex_space {
    LMB_TEX_COLOUR = 0, /* sRGB-encoded colour, decoded to linear */
    LMB_TEX_DATA = 1    /* linear data, as stored */
} lmb_tex_space;

/* glTF sampler wrap modes (GL enums) and the NEAREST magnification filter. */
enum { LMB_WRAP_REPEAT = 10497, LMB_WRAP_MIRRORED_REPEAT = 33648, LMB_WRAP_CLAMP_TO_EDGE = 33071 };
enum { LMB_FILTER_NEAREST = 9728 };

#define LMB_TEXTURE_MIPS 13 /* down to 1 x 1 from 4096 */

typedef struct lmb_texture {
    uint32_t width, height;
    float *pixels[2]; /* per lmb_tex_space: RGB, rows top to bottom; NULL when not loaded in that space */
    double mean[3];   /* average colour texel, for importance */
    int wrap_s, wrap_t; /* LMB_WRAP_* */
    int nearest;        /* magFilter NEAREST: nearest texel; else bilinear */
    float *alpha;       /* width x height alpha in [0, 1] when a MASK or BLEND material reads it, else NULL */
    int has_alpha;      /* its alpha was read (alpha NULL and has_alpha 1: the image has none: opaque) */
    uint32_t mips;      /* colour mip levels below the image (each the 2 x 2 mean of the one above), 0: none */
    float *mip[LMB_TEXTURE_MIPS];        /* owned: level k + 1's RGB, linear */
    uint32_t mip_w[LMB_TEXTURE_MIPS], mip_h[LMB_TEXTURE_MIPS];
} lmb_texture;

typedef struct lmb_textures {
    uint32_t count; /* the glTF's textures */
    lmb_texture *t; /* indexed like the glTF's textures */
} lmb_textures;

/* Loads every texture the baker will read: a material's emissive texture when it emits, and,
 * when it reflects diffusely, its base colour (or spec-gloss diffuse) texture, its
 * metallicRoughness texture (when metallicFactor > 0) or its specularGlossiness texture. A
 * texture that cannot be read is a warning (the material then uses its factor alone). */
lmb_status lmb_textures_load(const lmb_scene *scene, lmb_textures *out, const lmb_log *log, lmb_error *err);

void lmb_textures_free(lmb_textures *t);

/* The texture a slot reads, if it was loaded in `space`; else NULL. */
const lmb_texture *lmb_textures_get(const lmb_textures *tx, const lmb_texture_ref *ref, lmb_tex_space space);

/* Lookup at glTF UV (u, v) ((0, 0) = the image's top-left corner, (1, 1) its bottom-right),
 * with the texture's wrap modes and filter, in `space` (which must be loaded). */
void lmb_texture_sample(const lmb_texture *t, lmb_tex_space space, double u, double v, float out[3]);

/* The colour at glTF UV (u, v) averaged over a square of `texels` image texels a side (a ray's
 * footprint): trilinear between the mip levels around log2(texels); at most 1 texel, the plain
 * lookup. */
void lmb_texture_sample_footprint(const lmb_texture *t, double u, double v, double texels, float out[3]);

/* The alpha channel at glTF UV (u, v), as lmb_texture_sample filters colour; 1 when the image
 * has no alpha (or it was not read). */
float lmb_texture_sample_alpha(const lmb_texture *t, double u, double v);

/* KHR_texture_transform's matrix T(offset) x R(rotation) x S(scale) as the 2 x 3 affine map
 * of lmb_texture_ref.uv (see textures.c for the rotation's direction). */
void lmb_texture_transform_matrix(const double offset[2], double rotation, const double scale[2], double uv[6]);

/* Applies ref's UV map to (u, v). */
void lmb_texture_ref_apply(const lmb_texture_ref *ref, double u, double v, double *tu, double *tv);

/* The alpha of material m on primitive pr at barycentrics (b1, b2) of triangle tri:
 * baseColorFactor.a x baseColorTexture.a x COLOR_0.a (glTF 2.0 section 3.9.2). */
double lmb_material_alpha(const lmb_textures *tx, const lmb_material *m, const lmb_primitive *pr, uint32_t tri,
                          double b1, double b2);

/* KHR_materials_transmission's factor x texture (red) at the same place; 0 without it. */
double lmb_material_transmission(const lmb_textures *tx, const lmb_material *m, const lmb_primitive *pr, uint32_t tri,
                                 double b1, double b2);

/* The base colour (linear RGB: factor x texture x COLOR_0), the tint of transmitted light. */
void lmb_material_base_colour(const lmb_textures *tx, const lmb_material *m, const lmb_primitive *pr, uint32_t tri,
                              double b1, double b2, double out[3]);

/* lmb_material_albedo with the base colour texture averaged over `footprint` world units around
 * the point (a bounce ray's footprint at its hit, mapped into the texture by the triangle's UV
 * density; `scale`: world units per object unit of the instance); footprint 0: a point lookup. */
void lmb_material_albedo_over(const lmb_textures *tx, const lmb_material *m, const lmb_primitive *pr, uint32_t tri,
                              double b1, double b2, double footprint, double scale, double albedo[3]);

/* The diffuse albedo (linear RGB, what a viewer multiplies the lightmap by, times pi) of
 * material m on primitive pr at barycentrics (b1, b2) of triangle tri:
 *   metal-rough:  baseColorFactor x baseColorTexture x COLOR_0 x (1 - metallicFactor x metallicTexture.b)
 *                 x (1 - transmission)
 *   spec-gloss:   diffuseFactor x diffuseTexture x COLOR_0 x (1 - max(specularFactor x specularTexture.rgb))
 *   unlit:        0 (its colour does not depend on light; it reflects none)
 * A texture that is missing, not loaded or whose TEXCOORD set the primitive lacks counts as 1. */
void lmb_material_albedo(const lmb_textures *tx, const lmb_material *m, const lmb_primitive *pr, uint32_t tri,
                         double b1, double b2, double albedo[3]);

#endif
