/*
 * KTX 2.0 writer (see ktx2.h). Layout, all little-endian:
 *   identifier (12) | header: vkFormat, typeSize (1 for block formats), pixelWidth,
 *   pixelHeight, pixelDepth (0: 2D), layerCount 0, faceCount 1, levelCount (1, or the mip
 *   chain's), supercompressionScheme (0 or 2 = Zstandard) | index: dfdByteOffset,
 *   dfdByteLength, kvdByteOffset, kvdByteLength, sgdByteOffset 0, sgdByteLength 0 | level
 *   index, level 0 first: byteOffset, byteLength, uncompressedByteLength (u64 each) | DFD:
 *   dfdTotalSize, one Basic block | key/value data, each entry padded to 4 bytes | the levels,
 *   smallest first, each aligned to lcm(texel block size, 4) uncompressed (8 covers the packed
 *   formats, 16 the blocks), 1 supercompressed (spec section 3.9); each level supercompressed
 *   on its own.
 * Texel encodings: E5B9G9R9 as the Vulkan specification's shared-exponent conversion
 * ("Fundamentals: Shared exponent", N = 9, B = 15, Emax = 31); B10G11R11 as unsigned 11- and
 * 10-bit floats rounded to nearest even from half floats; half floats rounded to nearest even;
 * BC6H by bc6h.c, ASTC by astcenc (astc_adapter.h). Mip levels are 2 x 2 box averages.
 */
#include "ktx2.h"

#include "astc_adapter.h"
#include "bc6h.h"
#include "texels/dilate.h"
#include "util/clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zstd.h>

uint32_t lmb_ktx2_vkformat(lmb_ktx2_format f)
{
    switch (f) {
    case LMB_KTX2_E5B9G9R9: return 123u;
    case LMB_KTX2_B10G11R11: return 122u;
    case LMB_KTX2_RGBA16F: return 97u;
    case LMB_KTX2_BC6H: return 143u;
    case LMB_KTX2_ASTC_HDR: return 1000066000u;
    }
    return 0;
}

int lmb_ktx2_is_block(lmb_ktx2_format f)
{
    return f == LMB_KTX2_BC6H || f == LMB_KTX2_ASTC_HDR;
}

static float clamp_nonneg(float v, float max)
{
    return !(v > 0) ? 0.0f : v > max ? max : v; /* NaN and negatives -> 0 */
}

uint16_t lmb_float_to_half(float f)
{
    uint32_t x;
    if (!(f == f))
        return 0;
    if (f > 65504.0f)
        f = 65504.0f;
    if (f < -65504.0f)
        f = -65504.0f;
    memcpy(&x, &f, sizeof x);
    uint32_t sign = (x >> 16) & 0x8000u, mant = x & 0x7fffffu;
    int e = (int)((x >> 23) & 0xffu) - 127 + 15;
    if (e <= 0) { /* a half subnormal, or 0 */
        if (e < -10)
            return (uint16_t)sign;
        mant |= 0x800000u;
        int shift = 14 - e;
        uint32_t h = mant >> shift, rest = mant & ((1u << shift) - 1), half_way = 1u << (shift - 1);
        if (rest > half_way || (rest == half_way && (h & 1u)))
            h++;
        return (uint16_t)(sign | h);
    }
    uint32_t h = ((uint32_t)e << 10) | (mant >> 13), rest = mant & 0x1fffu;
    if (rest > 0x1000u || (rest == 0x1000u && (h & 1u)))
        h++; /* a carry into the exponent is the right rounding */
    if (h >= 0x7c00u)
        h = 0x7bffu;
    return (uint16_t)(sign | h);
}

/* An unsigned float of `mantissa` bits and a 5-bit exponent from a non-negative half's 15 bits. */
static uint32_t small_float(uint16_t half, int mantissa)
{
    uint32_t v = half & 0x7fffu, drop = 10u - (uint32_t)mantissa, max = (30u << mantissa) | ((1u << mantissa) - 1u);
    uint32_t r = (v + (1u << (drop - 1)) - 1u + ((v >> drop) & 1u)) >> drop;
    return r > max ? max : r;
}

uint32_t lmb_pack_b10g11r11(float r, float g, float b)
{
    uint32_t rr = small_float(lmb_float_to_half(clamp_nonneg(r, 65024.0f)), 6);
    uint32_t gg = small_float(lmb_float_to_half(clamp_nonneg(g, 65024.0f)), 6);
    uint32_t bb = small_float(lmb_float_to_half(clamp_nonneg(b, 64512.0f)), 5);
    return rr | gg << 11 | bb << 22;
}

uint32_t lmb_pack_e5b9g9r9(float r, float g, float b)
{
    const int n = 9, bias = 15;
    const double max_value = 511.0 / 512.0 * 65536.0; /* (2^N - 1) / 2^N x 2^(Emax - B) */
    double c[3] = {clamp_nonneg(r, (float)max_value), clamp_nonneg(g, (float)max_value),
                   clamp_nonneg(b, (float)max_value)};
    double m = c[0] > c[1] ? c[0] : c[1];
    m = m > c[2] ? m : c[2];
    int e = (m > 0 ? (int)floor(log2(m)) : -bias - 1);
    e = (e < -bias - 1 ? -bias - 1 : e) + 1 + bias;
    double scale = ldexp(1.0, e - bias - n);
    if (floor(m / scale + 0.5) == 512.0) {
        e++;
        scale *= 2;
    }
    uint32_t out = (uint32_t)e << 27;
    for (int k = 0; k < 3; k++) {
        uint32_t s = (uint32_t)floor(c[k] / scale + 0.5);
        out |= (s > 511 ? 511 : s) << (9 * k);
    }
    return out;
}

/* ---- the container ------------------------------------------------------------------- */

typedef struct bytes {
    uint8_t *p;
    size_t n, cap;
    int failed;
} bytes;

static void put(bytes *b, const void *data, size_t n)
{
    if (b->failed)
        return;
    if (b->n + n > b->cap) {
        size_t cap = b->cap ? b->cap : 1024;
        while (cap < b->n + n)
            cap *= 2;
        uint8_t *p = realloc(b->p, cap);
        if (!p) {
            b->failed = 1;
            return;
        }
        b->p = p;
        b->cap = cap;
    }
    memcpy(b->p + b->n, data, n);
    b->n += n;
}

static void put32(bytes *b, uint32_t v)
{
    uint8_t le[4] = {(uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24)};
    put(b, le, 4);
}

static void put64(bytes *b, uint64_t v)
{
    put32(b, (uint32_t)v);
    put32(b, (uint32_t)(v >> 32));
}

static void set32(bytes *b, size_t at, uint32_t v)
{
    if (!b->failed)
        for (int k = 0; k < 4; k++)
            b->p[at + (size_t)k] = (uint8_t)(v >> (8 * k));
}

static void set64(bytes *b, size_t at, uint64_t v)
{
    set32(b, at, (uint32_t)v);
    set32(b, at + 4, (uint32_t)(v >> 32));
}

static void pad_to(bytes *b, size_t align)
{
    static const uint8_t zero[8] = {0};
    while (b->n % align)
        put(b, zero, 1);
}

static uint32_t float_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

/* Data Format Descriptor sample: bit offset, bit length, channel id | qualifier bits (the
 * byte at bits 24..31: channel 0 R, 1 G, 2 B, 15 A; 0x20 exponent, 0x40 signed, 0x80 float),
 * sample position 0, lower and upper. */
static void sample(bytes *b, uint32_t offset, uint32_t bits, uint32_t channel, uint32_t lower, uint32_t upper)
{
    put32(b, offset | (bits - 1) << 16 | channel << 24);
    put32(b, 0);
    put32(b, lower);
    put32(b, upper);
}

/* The Basic DFD of format f: colour model RGBSDA, BT.709 primaries, linear transfer, straight
 * alpha, 1x1x1x1 blocks, bytesPlane0 = the texel's size; for the block formats, model BC6H (133)
 * or ASTC (162), 4x4 blocks of 16 bytes and one 128-bit sample (as KTX-Software's dfdutils
 * writes them: BC6H unsigned float in [0, 1], ASTC HDR signed float in [-1, 1]). */
static void dfd(bytes *b, lmb_ktx2_format f)
{
    if (lmb_ktx2_is_block(f)) {
        int bc6h = f == LMB_KTX2_BC6H;
        put32(b, 4 + 24 + 16);
        put32(b, 0);
        put32(b, 2 | (24 + 16) << 16);
        put32(b, (bc6h ? 133u : 162u) | 1 << 8 | 1 << 16);
        put32(b, 3 | 3 << 8); /* 4x4x1x1 */
        put32(b, 16);
        put32(b, 0);
        sample(b, 0, 128, bc6h ? 0x80 : 0xC0, bc6h ? 0 : float_bits(-1.0f), float_bits(1.0f));
        return;
    }
    uint32_t samples = f == LMB_KTX2_E5B9G9R9 ? 6 : f == LMB_KTX2_B10G11R11 ? 3 : 4;
    uint32_t block = 24 + 16 * samples;
    put32(b, 4 + block);      /* dfdTotalSize */
    put32(b, 0);              /* vendor Khronos, descriptor type 0: basic */
    put32(b, 2 | block << 16); /* version 2 (1.3), block size */
    put32(b, 1 | 1 << 8 | 1 << 16 | 0 << 24); /* model RGBSDA, primaries BT709, transfer linear, flags */
    put32(b, 0);              /* texel block dimensions 1x1x1x1 */
    put32(b, f == LMB_KTX2_RGBA16F ? 8 : 4); /* bytesPlane0..3 */
    put32(b, 0);              /* bytesPlane4..7 */
    if (f == LMB_KTX2_E5B9G9R9) {
        for (uint32_t c = 0; c < 3; c++) { /* each colour: its 9-bit mantissa, then the shared exponent */
            sample(b, 9 * c, 9, c, 0, 8448);
            sample(b, 27, 5, c | 0x20, 15, 31);
        }
    } else if (f == LMB_KTX2_B10G11R11) {
        sample(b, 0, 11, 0 | 0x80, float_bits(0.0f), float_bits(1.0f));
        sample(b, 11, 11, 1 | 0x80, float_bits(0.0f), float_bits(1.0f));
        sample(b, 22, 10, 2 | 0x80, float_bits(0.0f), float_bits(1.0f));
    } else {
        static const uint32_t channels[4] = {0, 1, 2, 15};
        for (uint32_t c = 0; c < 4; c++)
            sample(b, 16 * c, 16, channels[c] | 0xC0, float_bits(-1.0f), float_bits(1.0f));
    }
}

/* One key/value entry: length, key NUL value NUL, padding to 4. */
static void key_value(bytes *b, const char *key, const char *value)
{
    size_t k = strlen(key) + 1, v = strlen(value) + 1;
    put32(b, (uint32_t)(k + v));
    put(b, key, k);
    put(b, value, v);
    pad_to(b, 4);
}

uint8_t *lmb_ktx2_lookup_texels(const uint8_t *state, uint32_t w, uint32_t h)
{
    uint8_t *care = calloc((size_t)w * h + 1, 1);
    for (uint32_t y = 0; care && y < h; y++)
        for (uint32_t x = 0; x < w; x++) {
            if (state[(size_t)y * w + x] == LMB_TEXEL_EMPTY)
                continue;
            for (uint32_t yy = y > 1 ? y - 2 : 0; yy <= y + 2 && yy < h; yy++)
                for (uint32_t xx = x > 1 ? x - 2 : 0; xx <= x + 2 && xx < w; xx++)
                    care[(size_t)yy * w + xx] = 1;
        }
    return care;
}

/* The bytes of one level: packed texels or blocks. Returns the size, 0 when out of memory. */
static size_t encode_level(uint32_t w, uint32_t h, uint32_t d, const float *rgb, const lmb_ktx2_options *o,
                           const uint8_t *care, uint8_t **out, lmb_ktx2_report *report, lmb_error *err,
                           lmb_status *st)
{
    lmb_ktx2_format f = o->format;
    *st = LMB_OK;
    if (lmb_ktx2_is_block(f)) {
        size_t size = f == LMB_KTX2_BC6H ? lmb_bc6h_size(w, h) : lmb_astc_size(w, h);
        *out = malloc(size + 1);
        if (!*out) {
            *st = lmb_error_set(err, LMB_ERR_INTERNAL, "ktx2: out of memory for a %ux%u level", w, h);
            return 0;
        }
        uint64_t clamped = 0;
        double t0 = lmb_seconds();
        if (f == LMB_KTX2_BC6H)
            clamped = lmb_bc6h_encode(w, h, rgb, care, o->threads, *out);
        else
            *st = lmb_astc_hdr_encode(w, h, rgb, o->threads, *out, &clamped, err);
        if (report) {
            report->clamped += clamped;
            report->encode_seconds += lmb_seconds() - t0;
        }
        return size;
    }
    size_t texel = f == LMB_KTX2_RGBA16F ? 8 : 4, size = (size_t)w * h * (d ? d : 1) * texel;
    uint8_t *raw = malloc(size + 1);
    *out = raw;
    if (!raw) {
        *st = lmb_error_set(err, LMB_ERR_INTERNAL, "ktx2: out of memory for a %ux%u level", w, h);
        return 0;
    }
    for (size_t i = 0; i < size / texel; i++) {
        const float *p = rgb + 3 * i;
        uint8_t *q = raw + texel * i;
        if (f == LMB_KTX2_RGBA16F) {
            uint16_t v[4] = {lmb_float_to_half(p[0] > 0 ? p[0] : 0), lmb_float_to_half(p[1] > 0 ? p[1] : 0),
                             lmb_float_to_half(p[2] > 0 ? p[2] : 0), 0x3c00u};
            for (int k = 0; k < 4; k++) {
                q[2 * k] = (uint8_t)v[k];
                q[2 * k + 1] = (uint8_t)(v[k] >> 8);
            }
        } else {
            uint32_t v = f == LMB_KTX2_E5B9G9R9 ? lmb_pack_e5b9g9r9(p[0], p[1], p[2]) : lmb_pack_b10g11r11(p[0], p[1], p[2]);
            for (int k = 0; k < 4; k++)
                q[k] = (uint8_t)(v >> (8 * k));
        }
    }
    return size;
}

/* The next mip level: each texel the mean of the (up to) 2 x 2 texels above it. */
static float *half_size(const float *rgb, uint32_t w, uint32_t h, uint32_t *nw, uint32_t *nh)
{
    *nw = w > 1 ? w / 2 : 1;
    *nh = h > 1 ? h / 2 : 1;
    float *out = malloc((size_t)*nw * *nh * 3 * sizeof *out + 1);
    for (uint32_t y = 0; out && y < *nh; y++)
        for (uint32_t x = 0; x < *nw; x++)
            for (int c = 0; c < 3; c++) {
                uint32_t x0 = 2 * x < w ? 2 * x : w - 1, x1 = 2 * x + 1 < w ? 2 * x + 1 : w - 1;
                uint32_t y0 = 2 * y < h ? 2 * y : h - 1, y1 = 2 * y + 1 < h ? 2 * y + 1 : h - 1;
                double sum = (double)rgb[3 * ((size_t)y0 * w + x0) + c] + rgb[3 * ((size_t)y0 * w + x1) + c] +
                             rgb[3 * ((size_t)y1 * w + x0) + c] + rgb[3 * ((size_t)y1 * w + x1) + c];
                out[3 * ((size_t)y * *nw + x) + c] = (float)(sum / 4);
            }
    return out;
}

#define LMB_KTX2_MAX_LEVELS 32

/* One level's bytes as the file holds them (supercompressed or not) and its raw size. */
typedef struct level_bytes {
    uint8_t *data;
    size_t size, raw_size;
} level_bytes;

static void free_levels(level_bytes *lv, uint32_t n)
{
    for (uint32_t k = 0; k < n; k++)
        free(lv[k].data);
}

/* Encodes (and supercompresses) every level into lv; *count levels. */
static lmb_status encode_levels(uint32_t w, uint32_t h, uint32_t d, const float *rgb, const lmb_ktx2_options *o,
                                level_bytes *lv, uint32_t *count, lmb_ktx2_report *report, lmb_error *err)
{
    uint32_t n = 1;
    if (o->mipmaps && !d)
        for (uint32_t m = w > h ? w : h; m > 1; m /= 2)
            n++;
    *count = 0;
    const float *level = rgb;
    float *owned = NULL;
    uint32_t lw = w, lh = h;
    lmb_status st = LMB_OK;
    for (uint32_t k = 0; k < n && st == LMB_OK; k++) {
        if (k > 0) {
            uint32_t nw, nh;
            float *next = half_size(level, lw, lh, &nw, &nh);
            free(owned);
            owned = next;
            level = next;
            lw = nw;
            lh = nh;
            if (!next) {
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "ktx2: out of memory for mip level %u", k);
                break;
            }
        }
        uint8_t *raw = NULL;
        size_t raw_size = encode_level(lw, lh, d, level, o, k == 0 ? o->care : NULL, &raw, report, err, &st);
        if (st != LMB_OK) {
            free(raw);
            break;
        }
        lv[k] = (level_bytes){raw, raw_size, raw_size};
        (*count)++;
        if (o->zstd_level > 0) {
            size_t bound = ZSTD_compressBound(raw_size);
            uint8_t *z = malloc(bound + 1);
            if (!z) {
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "ktx2: out of memory for zstd");
                break;
            }
            size_t zs = ZSTD_compress(z, bound, raw, raw_size, o->zstd_level);
            if (ZSTD_isError(zs)) {
                free(z);
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "ktx2: zstd: %s", ZSTD_getErrorName(zs));
                break;
            }
            free(raw);
            lv[k].data = z;
            lv[k].size = zs;
        }
    }
    free(owned);
    return st;
}

lmb_status lmb_ktx2_encode(uint32_t w, uint32_t h, const float *rgb, const lmb_ktx2_options *o, uint8_t **out,
                           size_t *size, lmb_ktx2_report *report, lmb_error *err)
{
    return lmb_ktx2_encode_3d(w, h, 0, rgb, o, out, size, report, err);
}

lmb_status lmb_ktx2_encode_3d(uint32_t w, uint32_t h, uint32_t d, const float *rgb, const lmb_ktx2_options *o,
                              uint8_t **out, size_t *size, lmb_ktx2_report *report, lmb_error *err)
{
    *out = NULL;
    *size = 0;
    lmb_ktx2_format f = o->format;
    if (d && lmb_ktx2_is_block(f))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "ktx2: 3D textures are written in packed formats only");
    level_bytes lv[LMB_KTX2_MAX_LEVELS] = {{0}};
    uint32_t levels = 0;
    lmb_status st = encode_levels(w, h, d, rgb, o, lv, &levels, report, err);
    if (st != LMB_OK) {
        free_levels(lv, levels);
        return st;
    }
    static const uint8_t id[12] = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
    bytes b = {0};
    put(&b, id, sizeof id);
    put32(&b, lmb_ktx2_vkformat(f));
    put32(&b, lmb_ktx2_is_block(f) ? 1 : f == LMB_KTX2_RGBA16F ? 2 : 4); /* typeSize */
    put32(&b, w);
    put32(&b, h);
    put32(&b, d); /* pixelDepth: 0 for 2D */
    put32(&b, 0); /* layerCount */
    put32(&b, 1); /* faceCount */
    put32(&b, levels);
    put32(&b, o->zstd_level > 0 ? 2 : 0);
    size_t index = b.n;
    for (int k = 0; k < 4; k++)
        put32(&b, 0); /* dfd and kvd offsets and lengths, set below */
    put64(&b, 0);     /* sgdByteOffset */
    put64(&b, 0);     /* sgdByteLength */
    size_t level_index = b.n;
    for (uint32_t k = 0; k < levels; k++) {
        put64(&b, 0);
        put64(&b, 0);
        put64(&b, 0);
    }
    size_t dfd_at = b.n;
    dfd(&b, f);
    size_t kvd_at = b.n;
    key_value(&b, "KTXorientation", d ? "rdi" : "rd");
    key_value(&b, "KTXwriter", "lmbake " LMB_VERSION_STRING);
    size_t kvd_end = b.n;
    /* levels smallest first (spec section 3.9), each at a multiple of lcm(texel block size, 4)
     * uncompressed (16 for blocks, 8 covers the packed formats' 4 and 8), anywhere supercompressed */
    size_t align = o->zstd_level > 0 ? 1 : lmb_ktx2_is_block(f) ? 16 : 8;
    for (uint32_t k = levels; k-- > 0;) {
        pad_to(&b, align);
        size_t at = b.n;
        put(&b, lv[k].data, lv[k].size);
        set64(&b, level_index + 24 * k, at);
        set64(&b, level_index + 24 * k + 8, lv[k].size);
        set64(&b, level_index + 24 * k + 16, lv[k].raw_size);
    }
    set32(&b, index, (uint32_t)dfd_at);
    set32(&b, index + 4, (uint32_t)(kvd_at - dfd_at));
    set32(&b, index + 8, (uint32_t)kvd_at);
    set32(&b, index + 12, (uint32_t)(kvd_end - kvd_at));
    free_levels(lv, levels);
    if (b.failed) {
        free(b.p);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "ktx2: out of memory");
    }
    *out = b.p;
    *size = b.n;
    return LMB_OK;
}

/* data (freed here) written to path whole. */
static lmb_status write_whole(const char *path, uint8_t *data, size_t size, lmb_error *err)
{
    FILE *fp = fopen(path, "wb");
    int ok = fp && fwrite(data, 1, size, fp) == size;
    if (fp && fclose(fp) != 0)
        ok = 0;
    free(data);
    return ok ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "%s: cannot write the KTX2 file", path);
}

lmb_status lmb_ktx2_write(const char *path, uint32_t w, uint32_t h, const float *rgb, const lmb_ktx2_options *o,
                          lmb_ktx2_report *report, lmb_error *err)
{
    uint8_t *data;
    size_t size;
    lmb_status st = lmb_ktx2_encode(w, h, rgb, o, &data, &size, report, err);
    if (st != LMB_OK)
        return st;
    return write_whole(path, data, size, err);
}

lmb_status lmb_ktx2_write_3d(const char *path, uint32_t w, uint32_t h, uint32_t d, const float *rgb,
                             const lmb_ktx2_options *o, lmb_error *err)
{
    uint8_t *data;
    size_t size;
    lmb_status st = lmb_ktx2_encode_3d(w, h, d, rgb, o, &data, &size, NULL, err);
    if (st != LMB_OK)
        return st;
    return write_whole(path, data, size, err);
}
