/* Decoded material textures (see textures.h). sRGB decode: IEC 61966-2-1. */
#include "textures.h"

#include "gltf_adapter.h"
#include "write/image_adapter.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void lmb_textures_free(lmb_textures *t)
{
    for (uint32_t i = 0; t->t && i < t->count; i++)
        free(t->t[i].rgb);
    free(t->t);
    memset(t, 0, sizeof *t);
}

static float srgb_to_linear(float c)
{
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

/* A name whose extension lets OIIO pick the decoder for in-memory bytes. */
static const char *mem_name(const char *mime)
{
    if (mime && !strcmp(mime, "image/jpeg"))
        return "embedded.jpg";
    if (mime && !strcmp(mime, "image/webp"))
        return "embedded.webp";
    return "embedded.png";
}

static lmb_status load_one(const lmb_scene *s, const lmb_gltf_view *v, uint32_t tex, lmb_texture *out, lmb_error *err)
{
    int32_t src = v->texture_source[tex];
    if (src < 0 || (uint32_t)src >= v->image_count)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: texture %u has no usable image", s->path, tex);
    const lmb_gltf_image *img = &v->images[src];
    float *rgb = NULL;
    lmb_status st;
    if (img->bytes) {
        st = lmb_image_read_rgb(mem_name(img->mime), img->bytes, img->size, &out->width, &out->height, &rgb, err);
    } else {
        char path[8192];
        const char *slash = strrchr(s->path, '/');
        int dir = slash ? (int)(slash - s->path) : 1;
        snprintf(path, sizeof path, "%.*s/%s", dir, slash ? s->path : ".", img->uri);
        st = lmb_image_read_rgb(path, NULL, 0, &out->width, &out->height, &rgb, err);
    }
    if (st != LMB_OK)
        return st;
    size_t n = (size_t)out->width * out->height;
    for (size_t i = 0; i < 3 * n; i++)
        rgb[i] = srgb_to_linear(rgb[i]);
    for (int c = 0; c < 3; c++) {
        double sum = 0;
        for (size_t i = 0; i < n; i++)
            sum += rgb[3 * i + c];
        out->mean[c] = n ? sum / (double)n : 0;
    }
    out->rgb = rgb;
    return LMB_OK;
}

/* Loads texture `tex` for `role` of material m once; a texture that cannot be read is a warning. */
static void load_for(const lmb_scene *s, const lmb_gltf_view *v, const lmb_material *m, int32_t tex, const char *role,
                     lmb_textures *out, const lmb_log *log)
{
    if (tex < 0)
        return;
    if ((uint32_t)tex >= v->texture_count) {
        lmb_warn(log, "%s: material '%s' names %s texture %d, which does not exist; using its factor", s->path,
                 m->name, role, tex);
        return;
    }
    if (out->t[tex].rgb)
        return;
    lmb_error e;
    if (load_one(s, v, (uint32_t)tex, &out->t[tex], &e) != LMB_OK)
        lmb_warn(log, "material '%s': %s texture not used: %s", m->name, role, e.message);
}

lmb_status lmb_textures_load(const lmb_scene *s, lmb_textures *out, const lmb_log *log, lmb_error *err)
{
    const lmb_gltf_view *v = lmb_gltf_get_view(s->doc);
    memset(out, 0, sizeof *out);
    out->count = v->texture_count;
    out->t = calloc((size_t)v->texture_count + 1, sizeof *out->t);
    if (!out->t)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "textures: out of memory");
    for (uint32_t m = 0; m < s->material_count; m++) {
        const lmb_material *mat = &s->materials[m];
        if (lmb_material_is_emissive(mat))
            load_for(s, v, mat, mat->emissive_texture, "emissive", out, log);
        if (mat->metallic < 1)
            load_for(s, v, mat, mat->base_color_texture, "base colour", out, log);
    }
    return LMB_OK;
}

static const float *texel(const lmb_texture *t, long x, long y)
{
    long w = (long)t->width, h = (long)t->height;
    x %= w;
    y %= h;
    x += x < 0 ? w : 0;
    y += y < 0 ? h : 0;
    return t->rgb + 3 * ((size_t)y * t->width + (size_t)x);
}

void lmb_texture_sample(const lmb_texture *t, double u, double v, float out[3])
{
    double x = u * t->width - 0.5, y = v * t->height - 0.5;
    double fx = floor(x), fy = floor(y), ax = x - fx, ay = y - fy;
    long x0 = (long)fx, y0 = (long)fy;
    const float *a = texel(t, x0, y0), *b = texel(t, x0 + 1, y0), *c = texel(t, x0, y0 + 1), *d = texel(t, x0 + 1, y0 + 1);
    for (int k = 0; k < 3; k++)
        out[k] = (float)((1 - ay) * ((1 - ax) * a[k] + ax * b[k]) + ay * ((1 - ax) * c[k] + ax * d[k]));
}
