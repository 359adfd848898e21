/*
 * Material textures the baker needs (emissive for area lights, base colour for the albedo of bounces), decoded
 * once through the OpenImageIO adapter from the glTF's external files, buffer views or
 * data URIs, converted from sRGB to linear (glTF colour textures are sRGB), and sampled
 * bilinearly with repeat wrapping (glTF's default sampler; samplers are not read yet).
 */
#ifndef LMBAKE_TEXTURES_H
#define LMBAKE_TEXTURES_H

#include <lmbake/lmbake.h>

typedef struct lmb_texture {
    uint32_t width, height;
    float *rgb;     /* linear, rows top to bottom; NULL when not loaded */
    double mean[3]; /* average texel, for importance */
} lmb_texture;

typedef struct lmb_textures {
    uint32_t count; /* the glTF's textures */
    lmb_texture *t; /* indexed like the glTF's textures */
} lmb_textures;

/* Loads every texture a material of scene uses as its emissive texture (when it emits) or its
 * base colour texture (when it reflects diffusely: metallic < 1). A texture that cannot be
 * read is a warning (the material then uses its factor alone). */
lmb_status lmb_textures_load(const lmb_scene *scene, lmb_textures *out, const lmb_log *log, lmb_error *err);

/* Bilinear lookup at glTF UV (u, v), (0, 0) = the image's top-left corner. */
void lmb_texture_sample(const lmb_texture *t, double u, double v, float out[3]);

void lmb_textures_free(lmb_textures *t);

#endif
