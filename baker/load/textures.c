/* Material textures: decoding, sampling, UV transforms and the albedo they give (see textures.h).
 * sRGB decode: IEC 61966-2-1. */
#include "textures.h"
#include "uri.h"

#include "gltf_adapter.h"
#include "image/image_adapter.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void lmb_textures_free(lmb_textures *t)
{
    for (uint32_t i = 0; t->t && i < t->count; i++) {
        free(t->t[i].pixels[LMB_TEX_COLOUR]);
        free(t->t[i].pixels[LMB_TEX_DATA]);
        free(t->t[i].alpha);
        for (uint32_t k = 0; k < t->t[i].mips; k++)
            free(t->t[i].mip[k]);
    }
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

/* Sizes before memory: an image whose header declares more pixels than this is
 * refused before decoding (8192 x 8192: 0.8 GB as float RGB, 1 GB while decoding). */
#define LMB_MAX_TEXTURE_PIXELS ((uint64_t)1 << 26)

/* Textures are read at most this many pixels a side: the baker samples a texture where gather
 * rays hit (bounce albedo) and where emitters are sampled, at the scale of lightmap texels, far
 * coarser than a texture's pixels; a larger image is read reduced by a whole factor. */
#define LMB_TEXTURE_MAX_SIDE 4096u

/* sRGB decoding memo: decoded 8-bit images hold at most 256 distinct values, and each value's
 * conversion is kept in the slot of its nearest 8-bit code and reused when the same float comes
 * again (the same function of the same input: results are unchanged), so a 64-Mpixel texture
 * costs 256 powf, not 200 million (a 1.6 KB JPEG declaring 63488 x 767 took 12 s under the
 * sanitizers before it). */
typedef struct srgb_memo {
    float in[256], out[256];
} srgb_memo;

static void srgb_memo_init(srgb_memo *m)
{
    for (int k = 0; k < 256; k++)
        m->in[k] = -1.0f; /* no decoded value is negative */
}

/* values as stored -> the texture's space (colour: linear from sRGB; data: unchanged) */
static void to_space(float *px, size_t count, lmb_tex_space space, srgb_memo *m)
{
    if (space != LMB_TEX_COLOUR)
        return;
    for (size_t i = 0; i < count; i++) {
        float v = px[i];
        int k = v >= 0.0f && v <= 1.0f ? (int)(v * 255.0f + 0.5f) : -1;
        if (k >= 0 && m->in[k] == v) {
            px[i] = m->out[k];
            continue;
        }
        px[i] = srgb_to_linear(v);
        if (k >= 0) {
            m->in[k] = v;
            m->out[k] = px[i];
        }
    }
}

/* Adds a band of rows (values already in the texture's space) into one row of the reduced
 * image: each reduced pixel gets the sum of the up to factor columns it covers. */
static void add_band_f32(const float *band, uint32_t iw, uint32_t rows, uint32_t factor, float *row)
{
    for (uint32_t y = 0; y < rows; y++)
        for (uint32_t x = 0; x < iw; x++)
            for (int c = 0; c < 3; c++)
                row[3 * (size_t)(x / factor) + (size_t)c] += band[3 * ((size_t)y * iw + x) + (size_t)c];
}

/* The same for 8-bit values, through a table of what each code is in the texture's space. */
static void add_band_u8(const uint8_t *band, uint32_t iw, uint32_t rows, uint32_t factor, const float table[256],
                        float *row)
{
    for (uint32_t y = 0; y < rows; y++)
        for (uint32_t x = 0; x < iw; x++)
            for (int c = 0; c < 3; c++)
                row[3 * (size_t)(x / factor) + (size_t)c] += table[band[3 * ((size_t)y * iw + x) + (size_t)c]];
}

/* Reads an image of w x h reduced by `factor`: each pixel of the result is the mean, in the
 * texture's space (after sRGB decoding), of the up to factor x factor pixels it covers. Reads a
 * band of `factor` rows at a time, so memory follows the result, not the image; 8-bit images
 * are read as stored and decoded through a table. */
static lmb_status read_reduced(const char *name, const uint8_t *bytes, size_t size, uint32_t factor,
                               lmb_tex_space space, uint32_t *w, uint32_t *h, float **rgb, lmb_error *err)
{
    lmb_image_rows *r = NULL;
    uint32_t iw, ih;
    lmb_status st = lmb_image_rows_open(name, bytes, size, &r, &iw, &ih, err);
    if (st != LMB_OK)
        return st;
    int u8 = lmb_image_rows_is_u8(r);
    uint32_t ow = (iw + factor - 1) / factor, oh = (ih + factor - 1) / factor;
    size_t band_values = 3 * (size_t)iw * factor;
    void *band = malloc(band_values * (u8 ? 1 : sizeof(float)) + 1);
    float *out = calloc(3 * (size_t)ow * oh + 1, sizeof *out);
    if (!band || !out)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory for a %ux%u reduced image", name, ow, oh);
    srgb_memo memo;
    srgb_memo_init(&memo);
    float table[256];
    for (int k = 0; k < 256; k++) {
        table[k] = (float)k / 255.0f;
        to_space(&table[k], 1, space, &memo);
    }
    for (uint32_t oy = 0; oy < oh && st == LMB_OK; oy++) {
        uint32_t y0 = oy * factor, y1 = y0 + factor < ih ? y0 + factor : ih;
        float *row = out + 3 * (size_t)ow * oy;
        if (u8) {
            st = lmb_image_rows_read_u8(r, y0, y1, band, err);
            if (st == LMB_OK)
                add_band_u8(band, iw, y1 - y0, factor, table, row);
        } else {
            st = lmb_image_rows_read(r, y0, y1, band, err);
            if (st == LMB_OK) {
                to_space(band, 3 * (size_t)iw * (y1 - y0), space, &memo);
                add_band_f32(band, iw, y1 - y0, factor, row);
            }
        }
        for (uint32_t ox = 0; ox < ow && st == LMB_OK; ox++) {
            uint32_t cols = (ox + 1) * factor < iw ? factor : iw - ox * factor;
            float inv = 1.0f / (float)(cols * (y1 - y0));
            for (int c = 0; c < 3; c++)
                row[3 * (size_t)ox + (size_t)c] *= inv;
        }
    }
    lmb_image_rows_close(r);
    free(band);
    if (st != LMB_OK) {
        free(out);
        return st;
    }
    *w = ow;
    *h = oh;
    *rgb = out;
    return LMB_OK;
}

/* Decodes name (a file, or bytes) into the texture's space after checking its declared size
 * (*fatal: it was too large); an image over LMB_TEXTURE_MAX_SIDE a side is read reduced. */
static lmb_status decode_checked(const lmb_scene *s, int32_t src, const char *name, const uint8_t *bytes, size_t size,
                                 lmb_tex_space space, uint32_t *w, uint32_t *h, float **rgb, int *fatal,
                                 const lmb_log *log, lmb_error *err)
{
    lmb_status st = lmb_image_size(name, bytes, size, w, h, err);
    if (st != LMB_OK)
        return st;
    if ((uint64_t)*w * *h > LMB_MAX_TEXTURE_PIXELS) {
        *fatal = 1;
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: image %d is %ux%u: over lmbake's limit of %llu pixels (8192 x "
                             "8192); refused before decoding", s->path, src, *w, *h,
                             (unsigned long long)LMB_MAX_TEXTURE_PIXELS);
    }
    uint32_t side = *w > *h ? *w : *h;
    uint32_t factor = (side + LMB_TEXTURE_MAX_SIDE - 1) / LMB_TEXTURE_MAX_SIDE;
    if (factor > 1) {
        uint32_t iw = *w, ih = *h;
        st = read_reduced(name, bytes, size, factor, space, w, h, rgb, err);
        if (st == LMB_OK)
            lmb_info(log, "%s: image %d is %ux%u: read reduced %ux to %ux%u (lmbake reads textures at most %u a side)",
                     s->path, src, iw, ih, factor, *w, *h, LMB_TEXTURE_MAX_SIDE);
        return st;
    }
    st = lmb_image_read_rgb(name, bytes, size, w, h, rgb, err);
    if (st == LMB_OK) {
        srgb_memo memo;
        srgb_memo_init(&memo);
        to_space(*rgb, 3 * (size_t)*w * *h, space, &memo);
    }
    return st;
}

/* Reads texture tex's image in `space` (colour: linear). */
static lmb_status read_pixels(const lmb_scene *s, const lmb_gltf_view *v, uint32_t tex, lmb_tex_space space,
                              uint32_t *w, uint32_t *h, float **rgb, int *fatal, const lmb_log *log, lmb_error *err)
{
    int32_t src = v->textures[tex].source;
    if (src < 0 || (uint32_t)src >= v->image_count)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: texture %u has no usable image", s->path, tex);
    const lmb_gltf_image *img = &v->images[src];
    if (img->bytes)
        return decode_checked(s, src, mem_name(img->mime), img->bytes, img->size, space, w, h, rgb, fatal, log, err);
    /* files only from the input's folder and below (issue 15; load/uri.h) */
    char folder[4096], rel[4096], path[8300], real[4096];
    const char *slash = strrchr(s->path, '/');
    snprintf(folder, sizeof folder, "%.*s", slash ? (int)(slash - s->path) : 1, slash ? s->path : ".");
    lmb_uri_kind kind = lmb_uri_check(img->uri, rel, sizeof rel);
    if (kind != LMB_URI_INSIDE)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: image %d: uri '%s' %s", s->path, src, img->uri,
                             lmb_uri_refusal(kind));
    snprintf(path, sizeof path, "%s/%s", folder, rel);
    if (!lmb_path_inside(folder, path, real, sizeof real))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: image %d: '%s' is not a file inside the input's folder", s->path,
                             src, img->uri);
    return decode_checked(s, src, real, NULL, 0, space, w, h, rgb, fatal, log, err);
}

static int wrap_mode(int32_t gl, const char *axis, const lmb_scene *s, uint32_t tex, const lmb_log *log)
{
    if (gl == LMB_WRAP_REPEAT || gl == LMB_WRAP_MIRRORED_REPEAT || gl == LMB_WRAP_CLAMP_TO_EDGE)
        return gl;
    lmb_warn(log, "%s: texture %u: sampler %s %d is not a glTF wrap mode; using REPEAT", s->path, tex, axis, gl);
    return LMB_WRAP_REPEAT;
}

/* The colour image's mip chain: each level the mean of 2 x 2 texels of the one above (an odd
 * edge's last texel counted once), linear light, down to 1 x 1. Out of memory: fewer levels. */
static void build_mips(lmb_texture *t)
{
    const float *src = t->pixels[LMB_TEX_COLOUR];
    uint32_t w = t->width, h = t->height;
    t->mips = 0;
    while ((w > 1 || h > 1) && t->mips < LMB_TEXTURE_MIPS) {
        uint32_t nw = (w + 1) / 2, nh = (h + 1) / 2;
        float *dst = malloc(3 * (size_t)nw * nh * sizeof *dst + 1);
        if (!dst)
            return;
        for (uint32_t y = 0; y < nh; y++)
            for (uint32_t x = 0; x < nw; x++) {
                uint32_t x1 = 2 * x + 1 < w ? 2 * x + 1 : 2 * x, y1 = 2 * y + 1 < h ? 2 * y + 1 : 2 * y;
                for (int c = 0; c < 3; c++)
                    dst[3 * ((size_t)y * nw + x) + (size_t)c] =
                        0.25f * (src[3 * ((size_t)(2 * y) * w + 2 * x) + (size_t)c] + src[3 * ((size_t)(2 * y) * w + x1) + (size_t)c] +
                                 src[3 * ((size_t)y1 * w + 2 * x) + (size_t)c] + src[3 * ((size_t)y1 * w + x1) + (size_t)c]);
            }
        t->mip[t->mips] = dst;
        t->mip_w[t->mips] = nw;
        t->mip_h[t->mips] = nh;
        t->mips++;
        src = dst;
        w = nw;
        h = nh;
    }
}

/* Makes texture tex available in `space` (decoding the image once per space). */
static lmb_status load_one(const lmb_scene *s, const lmb_gltf_view *v, uint32_t tex, lmb_tex_space space,
                           lmb_texture *out, int *fatal, const lmb_log *log, lmb_error *err)
{
    if (out->pixels[space])
        return LMB_OK;
    float *px = NULL;
    uint32_t w, h;
    lmb_status st = read_pixels(s, v, tex, space, &w, &h, &px, fatal, log, err);
    if (st != LMB_OK)
        return st;
    size_t n = (size_t)w * h;
    if (space == LMB_TEX_COLOUR) {
        for (int c = 0; c < 3; c++) {
            double sum = 0;
            for (size_t i = 0; i < n; i++)
                sum += px[3 * i + c];
            out->mean[c] = n ? sum / (double)n : 0;
        }
    }
    out->width = w;
    out->height = h;
    out->pixels[space] = px;
    if (space == LMB_TEX_COLOUR)
        build_mips(out);
    const lmb_gltf_texture *gt = &v->textures[tex];
    out->wrap_s = wrap_mode(gt->wrap_s, "wrapS", s, tex, log);
    out->wrap_t = wrap_mode(gt->wrap_t, "wrapT", s, tex, log);
    out->nearest = gt->mag_filter == LMB_FILTER_NEAREST;
    return LMB_OK;
}

/* Loads the texture of slot `ref` for `role` of material m; a texture that cannot be read is a
 * warning, one too large to decode an error (into *st). */
static void load_for(const lmb_scene *s, const lmb_gltf_view *v, const lmb_material *m, const lmb_texture_ref *ref,
                     lmb_tex_space space, const char *role, lmb_textures *out, const lmb_log *log, lmb_status *st,
                     lmb_error *err)
{
    int32_t tex = ref->texture;
    if (tex < 0 || *st != LMB_OK)
        return;
    if ((uint32_t)tex >= v->texture_count) {
        lmb_warn(log, "%s: material '%s' names %s texture %d, which does not exist; using its factor", s->path,
                 m->name, role, tex);
        return;
    }
    lmb_error e;
    int fatal = 0;
    if (load_one(s, v, (uint32_t)tex, space, &out->t[tex], &fatal, log, &e) != LMB_OK) {
        if (fatal)
            *st = lmb_error_set(err, LMB_ERR_INPUT, "material '%s': %s texture: %s", m->name, role, e.message);
        else
            lmb_warn(log, "material '%s': %s texture not used: %s", m->name, role, e.message);
    }
}

/* Reads the alpha of texture tex (base colour of a MASK or BLEND material) at the size its
 * colour is read at (the same reduction); its sampler is set as load_one sets it. */
static lmb_status read_alpha(const lmb_scene *s, const lmb_gltf_view *v, uint32_t tex, lmb_texture *out,
                             const lmb_log *log, lmb_error *err)
{
    if (out->has_alpha)
        return LMB_OK;
    int32_t src = v->textures[tex].source;
    if (src < 0 || (uint32_t)src >= v->image_count)
        return lmb_error_set(err, LMB_ERR_INPUT, "texture %u has no usable image", tex);
    const lmb_gltf_image *img = &v->images[src];
    char name[8300];
    const uint8_t *bytes = img->bytes;
    if (bytes) {
        snprintf(name, sizeof name, "%s", mem_name(img->mime));
    } else { /* the same containment as read_pixels */
        char folder[4096], rel[4096], real[4096];
        const char *slash = strrchr(s->path, '/');
        snprintf(folder, sizeof folder, "%.*s", slash ? (int)(slash - s->path) : 1, slash ? s->path : ".");
        lmb_uri_kind kind = lmb_uri_check(img->uri, rel, sizeof rel);
        if (kind != LMB_URI_INSIDE)
            return lmb_error_set(err, LMB_ERR_INPUT, "image %d: uri '%s' %s", src, img->uri, lmb_uri_refusal(kind));
        snprintf(name, sizeof name, "%s/%s", folder, rel);
        if (!lmb_path_inside(folder, name, real, sizeof real))
            return lmb_error_set(err, LMB_ERR_INPUT, "image %d: '%s' is not a file inside the input's folder", src,
                                 img->uri);
        snprintf(name, sizeof name, "%s", real);
    }
    uint32_t w, h;
    lmb_status st = lmb_image_size(name, bytes, img->size, &w, &h, err);
    if (st != LMB_OK)
        return st;
    if ((uint64_t)w * h > LMB_MAX_TEXTURE_PIXELS)
        return lmb_error_set(err, LMB_ERR_INPUT, "image %d is %ux%u: over lmbake's limit of %llu pixels", src, w, h,
                             (unsigned long long)LMB_MAX_TEXTURE_PIXELS);
    uint32_t side = w > h ? w : h, factor = (side + LMB_TEXTURE_MAX_SIDE - 1) / LMB_TEXTURE_MAX_SIDE;
    float *alpha = NULL;
    uint32_t aw = 0, ah = 0;
    st = lmb_image_read_alpha(name, bytes, img->size, factor ? factor : 1, &aw, &ah, &alpha, err);
    if (st != LMB_OK)
        return st;
    if (out->pixels[LMB_TEX_COLOUR] || out->pixels[LMB_TEX_DATA]) {
        if (alpha && (aw != out->width || ah != out->height)) {
            free(alpha);
            return lmb_error_set(err, LMB_ERR_INTERNAL, "image %d: alpha read at %ux%u, colour at %ux%u", src, aw, ah,
                                 out->width, out->height);
        }
    } else {
        out->width = aw;
        out->height = ah;
        const lmb_gltf_texture *gt = &v->textures[tex];
        out->wrap_s = wrap_mode(gt->wrap_s, "wrapS", s, tex, log);
        out->wrap_t = wrap_mode(gt->wrap_t, "wrapT", s, tex, log);
        out->nearest = gt->mag_filter == LMB_FILTER_NEAREST;
    }
    out->alpha = alpha;
    out->has_alpha = 1;
    return LMB_OK;
}

/* A MASK or BLEND material's base colour alpha: a texture that cannot be read is an error for
 * MASK (its cut-outs would vanish: light would be blocked where the level has holes) and a
 * warning for BLEND (its factor alone then gives the coverage). */
static void load_alpha_for(const lmb_scene *s, const lmb_gltf_view *v, const lmb_material *m, lmb_textures *out,
                           const lmb_log *log, lmb_status *st, lmb_error *err)
{
    int32_t tex = m->base_color_texture.texture;
    if (m->alpha_mode == LMB_ALPHA_OPAQUE || tex < 0 || *st != LMB_OK)
        return;
    lmb_error e;
    if ((uint32_t)tex >= v->texture_count) {
        if (m->alpha_mode == LMB_ALPHA_MASK)
            *st = lmb_error_set(err, LMB_ERR_INPUT, "%s: material '%s' (alphaMode MASK) names base colour texture %d, "
                                "which does not exist: its cut-outs cannot be read", s->path, m->name, tex);
        return;
    }
    if (read_alpha(s, v, (uint32_t)tex, &out->t[tex], log, &e) == LMB_OK)
        return;
    if (m->alpha_mode == LMB_ALPHA_MASK)
        *st = lmb_error_set(err, LMB_ERR_INPUT, "%s: material '%s' (alphaMode MASK): the alpha of its base colour "
                            "texture %d cannot be read, so its cut-outs are unknown: %s", s->path, m->name, tex, e.message);
    else
        lmb_warn(log, "%s: material '%s' (alphaMode BLEND): the alpha of its base colour texture %d cannot be read; "
                 "its baseColorFactor alpha alone is the coverage: %s", s->path, m->name, tex, e.message);
}

lmb_status lmb_textures_load(const lmb_scene *s, lmb_textures *out, const lmb_log *log, lmb_error *err)
{
    const lmb_gltf_view *v = lmb_gltf_get_view(s->doc);
    memset(out, 0, sizeof *out);
    out->count = v->texture_count;
    out->t = calloc((size_t)v->texture_count + 1, sizeof *out->t);
    if (!out->t)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "textures: out of memory");
    lmb_status st = LMB_OK;
    for (uint32_t i = 0; i < s->material_count && st == LMB_OK; i++) {
        const lmb_material *m = &s->materials[i];
        if (lmb_material_is_emissive(m))
            load_for(s, v, m, &m->emissive_texture, LMB_TEX_COLOUR, "emissive", out, log, &st, err);
        load_alpha_for(s, v, m, out, log, &st, err);
        if (m->transmission > 0) { /* the tint of light through it: its base colour, even where unlit or metal */
            load_for(s, v, m, &m->transmission_texture, LMB_TEX_DATA, "transmission", out, log, &st, err);
            load_for(s, v, m, &m->base_color_texture, LMB_TEX_COLOUR, "base colour", out, log, &st, err);
        }
        if (m->unlit)
            continue;
        if (m->spec_gloss) {
            load_for(s, v, m, &m->base_color_texture, LMB_TEX_COLOUR, "diffuse", out, log, &st, err);
            load_for(s, v, m, &m->specular_texture, LMB_TEX_COLOUR, "specular-glossiness", out, log, &st, err);
            continue;
        }
        /* metalness = metallicFactor x texture blue <= metallicFactor: a texture can only lower it */
        if (m->metallic < 1 || (m->metallic_texture.texture >= 0 && m->metallic > 0))
            load_for(s, v, m, &m->base_color_texture, LMB_TEX_COLOUR, "base colour", out, log, &st, err);
        if (m->metallic > 0)
            load_for(s, v, m, &m->metallic_texture, LMB_TEX_DATA, "metallicRoughness", out, log, &st, err);
    }
    return st;
}

const lmb_texture *lmb_textures_get(const lmb_textures *tx, const lmb_texture_ref *ref, lmb_tex_space space)
{
    if (!tx || ref->texture < 0 || (uint32_t)ref->texture >= tx->count || !tx->t[ref->texture].pixels[space])
        return NULL;
    return &tx->t[ref->texture];
}

/* Texel index i of an axis of n texels under a wrap mode (glTF 2.0 section 3.8.4.3, as OpenGL). */
static long wrap(long i, long n, int mode)
{
    if (mode == LMB_WRAP_CLAMP_TO_EDGE)
        return i < 0 ? 0 : i >= n ? n - 1 : i;
    if (mode == LMB_WRAP_MIRRORED_REPEAT) {
        long m = i % (2 * n);
        m += m < 0 ? 2 * n : 0;
        return m < n ? m : 2 * n - 1 - m;
    }
    long m = i % n;
    return m + (m < 0 ? n : 0);
}

static const float *texel(const lmb_texture *t, const float *px, uint32_t w, uint32_t h, int stride, long x, long y)
{
    x = wrap(x, (long)w, t->wrap_s);
    y = wrap(y, (long)h, t->wrap_t);
    return px + (size_t)stride * ((size_t)y * w + (size_t)x);
}

/* Texel coordinates beyond this are folded back by whole periods first (REPEAT and
 * MIRRORED_REPEAT repeat every 2 texture sizes; CLAMP does not care), so a huge UV cannot
 * overflow the integer texel index. */
static double fold(double x, long n)
{
    double period = 2.0 * (double)n, limit = 1e9;
    if (fabs(x) < limit)
        return x;
    return fmod(x, period);
}

/* `stride` channels per texel of px, the first `stride` of them looked up at glTF UV (u, v)
 * with t's wrap modes and filter. */
static void sample_px(const lmb_texture *t, const float *px, uint32_t w, uint32_t h, int stride, double u, double v,
                      float *out)
{
    double x = u * w, y = v * h;
    if (!isfinite(x) || !isfinite(y)) /* a broken UV or transform reads texel (0, 0) */
        x = y = 0;
    if (t->wrap_s == LMB_WRAP_CLAMP_TO_EDGE)
        x = fmax(-1.0, fmin(x, (double)w + 1.0));
    else
        x = fold(x, (long)w);
    if (t->wrap_t == LMB_WRAP_CLAMP_TO_EDGE)
        y = fmax(-1.0, fmin(y, (double)h + 1.0));
    else
        y = fold(y, (long)h);
    if (t->nearest) {
        const float *a = texel(t, px, w, h, stride, (long)floor(x), (long)floor(y));
        for (int k = 0; k < stride; k++)
            out[k] = a[k];
        return;
    }
    x -= 0.5;
    y -= 0.5;
    double fx = floor(x), fy = floor(y), ax = x - fx, ay = y - fy;
    long x0 = (long)fx, y0 = (long)fy;
    const float *a = texel(t, px, w, h, stride, x0, y0), *b = texel(t, px, w, h, stride, x0 + 1, y0),
                *c = texel(t, px, w, h, stride, x0, y0 + 1), *d = texel(t, px, w, h, stride, x0 + 1, y0 + 1);
    for (int k = 0; k < stride; k++)
        out[k] = (float)((1 - ay) * ((1 - ax) * a[k] + ax * b[k]) + ay * ((1 - ax) * c[k] + ax * d[k]));
}

void lmb_texture_sample(const lmb_texture *t, lmb_tex_space space, double u, double v, float out[3])
{
    sample_px(t, t->pixels[space], t->width, t->height, 3, u, v, out);
}

/* Level k of the colour chain: 0 the image, k > 0 mip[k - 1]. */
static void level_sample(const lmb_texture *t, uint32_t k, double u, double v, float out[3])
{
    if (k == 0)
        sample_px(t, t->pixels[LMB_TEX_COLOUR], t->width, t->height, 3, u, v, out);
    else
        sample_px(t, t->mip[k - 1], t->mip_w[k - 1], t->mip_h[k - 1], 3, u, v, out);
}

void lmb_texture_sample_footprint(const lmb_texture *t, double u, double v, double texels, float out[3])
{
    double lod = texels > 1 ? log2(texels) : 0;
    if (!(lod > 0) || !t->mips) {
        level_sample(t, 0, u, v, out);
        return;
    }
    if (lod >= t->mips) {
        level_sample(t, t->mips, u, v, out);
        return;
    }
    uint32_t k = (uint32_t)lod;
    float a[3], b[3];
    double f = lod - k;
    level_sample(t, k, u, v, a);
    level_sample(t, k + 1, u, v, b);
    for (int c = 0; c < 3; c++)
        out[c] = (float)((1 - f) * a[c] + f * b[c]);
}

float lmb_texture_sample_alpha(const lmb_texture *t, double u, double v)
{
    if (!t->alpha)
        return 1.0f;
    float a;
    sample_px(t, t->alpha, t->width, t->height, 1, u, v, &a);
    return a;
}

/*
 * KHR_texture_transform: uv' = T(offset) R(rotation) S(scale) uv, which gives
 *   u' =  sx cos(r) u + sy sin(r) v + ox
 *   v' = -sx sin(r) u + sy cos(r) v + oy
 * The rotation turns the UVs counter-clockwise in UV space (u right, v down), as the
 * extension's text says and its worked example shows (offset (0, 1), rotation pi/2, scale 0.5
 * maps the unit square onto the image's lower-left quadrant, [0, 0.5] x [0.5, 1]); three.js,
 * Babylon.js, Blender and the TextureTransformTest sample model agree. The GLSL listing in the
 * extension, read as column-major GLSL, turns the other way (KhronosGroup/glTF issue #1563).
 */
void lmb_texture_transform_matrix(const double offset[2], double rotation, const double scale[2], double uv[6])
{
    double c = cos(rotation), s = sin(rotation);
    uv[0] = scale[0] * c;
    uv[1] = scale[1] * s;
    uv[2] = offset[0];
    uv[3] = -scale[0] * s;
    uv[4] = scale[1] * c;
    uv[5] = offset[1];
}

void lmb_texture_ref_apply(const lmb_texture_ref *ref, double u, double v, double *tu, double *tv)
{
    *tu = ref->uv[0] * u + ref->uv[1] * v + ref->uv[2];
    *tv = ref->uv[3] * u + ref->uv[4] * v + ref->uv[5];
}

/* Slot ref's texture UV (its TEXCOORD set through its transform) at barycentrics b of triangle
 * tri of pr; 0 when the primitive lacks that set. */
static inline int slot_uv(const lmb_texture_ref *ref, const lmb_primitive *pr, uint32_t tri, const double b[3], double *tu,
                   double *tv)
{
    const float *uv = ref->texcoord == 0 ? pr->uv0 : ref->texcoord == 1 ? pr->uv1 : NULL;
    if (!uv)
        return 0;
    const uint32_t *ix = pr->indices + 3 * (size_t)tri;
    double u = 0, v = 0;
    for (int k = 0; k < 3; k++) {
        u += b[k] * uv[2 * ix[k]];
        v += b[k] * uv[2 * ix[k] + 1];
    }
    lmb_texture_ref_apply(ref, u, v, tu, tv);
    return 1;
}

/* Looks slot ref up at barycentrics (b0, b1, b2) of triangle tri of pr; 0 when it cannot (out left as is). */
static inline int sample_slot(const lmb_textures *tx, const lmb_texture_ref *ref, lmb_tex_space space,
                       const lmb_primitive *pr, uint32_t tri, const double b[3], float out[3])
{
    const lmb_texture *t = lmb_textures_get(tx, ref, space);
    double tu, tv;
    if (!t || !slot_uv(ref, pr, tri, b, &tu, &tv))
        return 0;
    lmb_texture_sample(t, space, tu, tv, out);
    return 1;
}

/* COLOR_0 (RGBA) interpolated at barycentrics b; 1 1 1 1 without it. */
static void vertex_colour(const lmb_primitive *pr, uint32_t tri, const double b[3], double out[4])
{
    out[0] = out[1] = out[2] = out[3] = 1.0;
    if (!pr->colors)
        return;
    const uint32_t *ix = pr->indices + 3 * (size_t)tri;
    for (int c = 0; c < 4; c++)
        out[c] = b[0] * pr->colors[4 * (size_t)ix[0] + c] + b[1] * pr->colors[4 * (size_t)ix[1] + c] +
                 b[2] * pr->colors[4 * (size_t)ix[2] + c];
}

double lmb_material_alpha(const lmb_textures *tx, const lmb_material *m, const lmb_primitive *pr, uint32_t tri,
                          double b1, double b2)
{
    double b[3] = {1.0 - b1 - b2, b1, b2}, vc[4], tu, tv;
    vertex_colour(pr, tri, b, vc);
    double a = m->base_color[3] * vc[3];
    const lmb_texture_ref *ref = &m->base_color_texture;
    if (tx && ref->texture >= 0 && (uint32_t)ref->texture < tx->count && tx->t[ref->texture].alpha &&
        slot_uv(ref, pr, tri, b, &tu, &tv))
        a *= lmb_texture_sample_alpha(&tx->t[ref->texture], tu, tv);
    return a;
}

double lmb_material_transmission(const lmb_textures *tx, const lmb_material *m, const lmb_primitive *pr, uint32_t tri,
                                 double b1, double b2)
{
    if (!(m->transmission > 0))
        return 0.0;
    double b[3] = {1.0 - b1 - b2, b1, b2};
    float t[3] = {1, 1, 1};
    sample_slot(tx, &m->transmission_texture, LMB_TEX_DATA, pr, tri, b, t);
    return m->transmission * t[0];
}

void lmb_material_base_colour(const lmb_textures *tx, const lmb_material *m, const lmb_primitive *pr, uint32_t tri,
                              double b1, double b2, double out[3])
{
    double b[3] = {1.0 - b1 - b2, b1, b2}, vc[4];
    float base[3] = {1, 1, 1};
    sample_slot(tx, &m->base_color_texture, LMB_TEX_COLOUR, pr, tri, b, base);
    vertex_colour(pr, tri, b, vc);
    for (int k = 0; k < 3; k++)
        out[k] = m->base_color[k] * base[k] * vc[k];
}

/* Texture texels per object unit on triangle tri of pr through slot ref (its UV set, transform
 * and the image's size): sqrt of the triangle's area in texels over its area; 0 when unknown. */
static double texels_per_unit(const lmb_texture *t, const lmb_texture_ref *ref, const lmb_primitive *pr, uint32_t tri)
{
    const float *uv = ref->texcoord == 0 ? pr->uv0 : ref->texcoord == 1 ? pr->uv1 : NULL;
    if (!uv)
        return 0;
    const uint32_t *ix = pr->indices + 3 * (size_t)tri;
    double q[3][2], e[2][3];
    for (int k = 0; k < 3; k++) {
        lmb_texture_ref_apply(ref, uv[2 * ix[k]], uv[2 * ix[k] + 1], &q[k][0], &q[k][1]);
        q[k][0] *= t->width;
        q[k][1] *= t->height;
    }
    for (int d = 0; d < 3; d++) {
        e[0][d] = (double)pr->positions[3 * ix[1] + d] - pr->positions[3 * ix[0] + d];
        e[1][d] = (double)pr->positions[3 * ix[2] + d] - pr->positions[3 * ix[0] + d];
    }
    double tex = fabs((q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]));
    double cx = e[0][1] * e[1][2] - e[0][2] * e[1][1], cy = e[0][2] * e[1][0] - e[0][0] * e[1][2],
           cz = e[0][0] * e[1][1] - e[0][1] * e[1][0], geo = sqrt(cx * cx + cy * cy + cz * cz);
    return geo > 0 && tex > 0 ? sqrt(tex / geo) : 0;
}

void lmb_material_albedo(const lmb_textures *tx, const lmb_material *m, const lmb_primitive *pr, uint32_t tri,
                         double b1, double b2, double albedo[3])
{
    lmb_material_albedo_over(tx, m, pr, tri, b1, b2, 0.0, 1.0, albedo);
}

void lmb_material_albedo_over(const lmb_textures *tx, const lmb_material *m, const lmb_primitive *pr, uint32_t tri,
                              double b1, double b2, double footprint, double scale, double albedo[3])
{
    double b[3] = {1.0 - b1 - b2, b1, b2};
    albedo[0] = albedo[1] = albedo[2] = 0;
    if (m->unlit)
        return;
    float base[3] = {1, 1, 1};
    double vc[4] = {1, 1, 1, 1};
    const lmb_texture *bt = footprint > 0 ? lmb_textures_get(tx, &m->base_color_texture, LMB_TEX_COLOUR) : NULL;
    double tu, tv, per_unit = bt && bt->mips ? texels_per_unit(bt, &m->base_color_texture, pr, tri) : 0;
    if (per_unit > 0 && slot_uv(&m->base_color_texture, pr, tri, b, &tu, &tv))
        lmb_texture_sample_footprint(bt, tu, tv, footprint * per_unit / (scale > 0 ? scale : 1.0), base);
    else
        sample_slot(tx, &m->base_color_texture, LMB_TEX_COLOUR, pr, tri, b, base);
    if (pr->colors)
        vertex_colour(pr, tri, b, vc);
    double keep; /* the share of base colour that is diffuse */
    if (m->spec_gloss) {
        float sp[3] = {1, 1, 1};
        sample_slot(tx, &m->specular_texture, LMB_TEX_COLOUR, pr, tri, b, sp);
        double mx = fmax(m->specular[0] * sp[0], fmax(m->specular[1] * sp[1], m->specular[2] * sp[2]));
        keep = 1.0 - mx;
    } else {
        float mr[3] = {1, 1, 1};
        if (m->metallic > 0)
            sample_slot(tx, &m->metallic_texture, LMB_TEX_DATA, pr, tri, b, mr);
        keep = 1.0 - m->metallic * mr[2];
    }
    keep = keep < 0 ? 0 : keep > 1 ? 1 : keep;
    if (m->transmission > 0) /* glTF: transmission replaces diffuse */
        keep *= 1.0 - lmb_material_transmission(tx, m, pr, tri, b1, b2);
    if (m->diffuse_transmission > 0) /* KHR_materials_diffuse_transmission: its share goes through */
        keep *= 1.0 - m->diffuse_transmission;
    if (!pr->colors) {
        for (int k = 0; k < 3; k++)
            albedo[k] = keep * m->base_color[k] * base[k];
        return;
    }
    for (int k = 0; k < 3; k++)
        albedo[k] = keep * m->base_color[k] * base[k] * vc[k];
}
