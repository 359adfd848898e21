/*
 * glTF accessor decoding (glTF 2.0 spec section 3.6 "Binary data storage"; normalized
 * integers from section 3.11). Every read is bounds-checked before it happens, so a
 * malformed file is an error message, never an out-of-bounds read.
 */
#include "accessor.h"

/* Sizes before memory (issue 15): an accessor without a bufferView (zeros, maybe sparse) may
 * declare at most this many elements: 16M, 0.4 GB as VEC3 doubles. */
#define LMB_MAX_UNBACKED_ELEMENTS (1u << 24)

#include <stdlib.h>
#include <string.h>

enum {
    CT_BYTE = 5120, CT_UBYTE = 5121, CT_SHORT = 5122, CT_USHORT = 5123, CT_UINT = 5125,
    CT_FLOAT = 5126
};

static size_t component_size(int32_t type)
{
    switch (type) {
    case CT_BYTE: case CT_UBYTE: return 1;
    case CT_SHORT: case CT_USHORT: return 2;
    case CT_UINT: case CT_FLOAT: return 4;
    default: return 0;
    }
}

/* One component at p as a double, following the normalization rules of the spec. */
static double decode(const uint8_t *p, int32_t type, int normalized)
{
    switch (type) {
    case CT_BYTE: { int8_t v; memcpy(&v, p, 1); return normalized ? (v / 127.0 < -1.0 ? -1.0 : v / 127.0) : v; }
    case CT_UBYTE: { uint8_t v = *p; return normalized ? v / 255.0 : v; }
    case CT_SHORT: { int16_t v; memcpy(&v, p, 2); return normalized ? (v / 32767.0 < -1.0 ? -1.0 : v / 32767.0) : v; }
    case CT_USHORT: { uint16_t v; memcpy(&v, p, 2); return normalized ? v / 65535.0 : v; }
    case CT_UINT: { uint32_t v; memcpy(&v, p, 4); return normalized ? v / 4294967295.0 : v; }
    default: { float v; memcpy(&v, p, 4); return v; }
    }
}

/* A checked span of `count` elements of `elem` bytes every `stride` bytes inside a view. */
typedef struct span {
    const uint8_t *base;
    size_t stride;
} span;

static lmb_status view_span(const lmb_accessor_ctx *ctx, int32_t view_index, size_t offset,
                            size_t count, size_t elem, int allow_stride, const char *what,
                            span *out, lmb_error *err)
{
    const lmb_gltf_view *v = ctx->view;
    if (view_index < 0 || (uint32_t)view_index >= v->buffer_view_count)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: bufferView %d does not exist (the file has %u)",
                             ctx->path, what, view_index, v->buffer_view_count);
    const lmb_gltf_buffer_view *bv = &v->buffer_views[view_index];
    if (bv->buffer < 0 || (uint32_t)bv->buffer >= v->buffer_count)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: bufferView %d names buffer %d, which does not exist",
                             ctx->path, what, view_index, bv->buffer);
    const lmb_gltf_buffer *b = &v->buffers[bv->buffer];
    if (bv->offset > b->size || bv->length > b->size - bv->offset)
        return lmb_error_set(err, LMB_ERR_INPUT,
                             "%s: %s: bufferView %d (offset %zu, length %zu) runs past the end of buffer %d (%zu bytes)",
                             ctx->path, what, view_index, bv->offset, bv->length, bv->buffer, b->size);
    size_t stride = (allow_stride && bv->stride) ? bv->stride : elem;
    if (stride < elem)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: bufferView %d byteStride %zu is smaller than an element (%zu bytes)",
                             ctx->path, what, view_index, stride, elem);
    if (count > 0) {
        if (offset > bv->length || (count - 1) > (bv->length - offset) / stride ||
            (count - 1) * stride + elem > bv->length - offset)
            return lmb_error_set(err, LMB_ERR_INPUT,
                                 "%s: %s: %zu elements of %zu bytes from offset %zu do not fit in bufferView %d (%zu bytes)",
                                 ctx->path, what, count, elem, offset, view_index, bv->length);
    }
    out->base = b->data + bv->offset + offset;
    out->stride = stride;
    return LMB_OK;
}

static lmb_status check_accessor(const lmb_accessor_ctx *ctx, int32_t index, const char *what,
                                 const lmb_gltf_accessor **out, lmb_error *err)
{
    if (index < 0 || (uint32_t)index >= ctx->view->accessor_count)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: accessor %d does not exist (the file has %u)",
                             ctx->path, what, index, ctx->view->accessor_count);
    const lmb_gltf_accessor *a = &ctx->view->accessors[index];
    if (!component_size(a->component_type))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: accessor %d has invalid componentType %d",
                             ctx->path, what, index, a->component_type);
    *out = a;
    return LMB_OK;
}

/* Applies the sparse substitution of accessor a onto dst (count * comps doubles). */
static lmb_status apply_sparse(const lmb_accessor_ctx *ctx, const lmb_gltf_accessor *a, int32_t index,
                               double *dst, int comps, const char *what, lmb_error *err)
{
    size_t isz = component_size(a->sparse_indices_type), csz = component_size(a->component_type);
    if (a->sparse_indices_type != CT_UBYTE && a->sparse_indices_type != CT_USHORT &&
        a->sparse_indices_type != CT_UINT)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: accessor %d sparse indices have invalid componentType %d",
                             ctx->path, what, index, a->sparse_indices_type);
    if (a->sparse_count > a->count)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: accessor %d has %zu sparse values for %zu elements",
                             ctx->path, what, index, a->sparse_count, a->count);
    span si, sv;
    lmb_status st = view_span(ctx, a->sparse_indices_view, a->sparse_indices_offset, a->sparse_count, isz, 0, what, &si, err);
    if (st == LMB_OK)
        st = view_span(ctx, a->sparse_values_view, a->sparse_values_offset, a->sparse_count, csz * (size_t)comps, 0, what, &sv, err);
    if (st != LMB_OK)
        return st;
    for (size_t k = 0; k < a->sparse_count; k++) {
        double target = decode(si.base + k * isz, a->sparse_indices_type, 0);
        if (target >= (double)a->count)
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: accessor %d sparse index %.0f is out of range (count %zu)",
                                 ctx->path, what, index, target, a->count);
        for (int c = 0; c < comps; c++)
            dst[(size_t)target * comps + c] = decode(sv.base + k * sv.stride + c * csz, a->component_type, a->normalized);
    }
    return LMB_OK;
}

/* Decodes accessor index into a new array of doubles (count * components). */
static lmb_status read_doubles(const lmb_accessor_ctx *ctx, int32_t index, int comps, const char *what,
                               double **out, size_t *count, lmb_error *err)
{
    const lmb_gltf_accessor *a = NULL;
    lmb_status st = check_accessor(ctx, index, what, &a, err);
    if (st != LMB_OK)
        return st;
    if (a->components != comps)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: accessor %d has %d components per element, expected %d",
                             ctx->path, what, index, a->components, comps);
    if (a->count > (size_t)1 << 31)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: accessor %d count %zu is too large", ctx->path, what, index, a->count);
    size_t csz = component_size(a->component_type);
    /* sizes before memory (issue 15): the elements must be in the file before they are decoded */
    span s = {0};
    if (a->buffer_view >= 0 &&
        (st = view_span(ctx, a->buffer_view, a->offset, a->count, csz * (size_t)comps, 1, what, &s, err)) != LMB_OK)
        return st;
    if (a->buffer_view < 0 && a->count > LMB_MAX_UNBACKED_ELEMENTS)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: accessor %d declares %zu elements with no bufferView (at most %u "
                             "without data in the file)", ctx->path, what, index, a->count, LMB_MAX_UNBACKED_ELEMENTS);
    double *dst = calloc(a->count * (size_t)comps + 1, sizeof *dst);
    if (!dst)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: %s: out of memory", ctx->path, what);
    if (a->buffer_view >= 0) {
        for (size_t i = 0; i < a->count; i++)
            for (int c = 0; c < comps; c++)
                dst[i * comps + c] = decode(s.base + i * s.stride + c * csz, a->component_type, a->normalized);
    } else if (a->sparse_count == 0 && a->count > 0) {
        free(dst);
        return lmb_error_set(err, LMB_ERR_INPUT,
                             "%s: %s: accessor %d has no bufferView and no sparse data (a compressed or stripped file?)",
                             ctx->path, what, index);
    }
    if (a->sparse_count && (st = apply_sparse(ctx, a, index, dst, comps, what, err)) != LMB_OK) {
        free(dst);
        return st;
    }
    *out = dst;
    *count = a->count;
    return LMB_OK;
}

lmb_status lmb_accessor_read_floats(const lmb_accessor_ctx *ctx, int32_t index, int components,
                                    const char *what, float **out, size_t *count, lmb_error *err)
{
    double *d = NULL;
    size_t n = 0;
    lmb_status st = read_doubles(ctx, index, components, what, &d, &n, err);
    if (st != LMB_OK)
        return st;
    float *f = malloc((n * (size_t)components + 1) * sizeof *f);
    if (!f) {
        free(d);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: %s: out of memory", ctx->path, what);
    }
    for (size_t i = 0; i < n * (size_t)components; i++)
        f[i] = (float)d[i];
    free(d);
    *out = f;
    *count = n;
    return LMB_OK;
}

lmb_status lmb_accessor_read_indices(const lmb_accessor_ctx *ctx, int32_t index, const char *what,
                                     uint32_t **out, size_t *count, lmb_error *err)
{
    const lmb_gltf_accessor *a = NULL;
    lmb_status st = check_accessor(ctx, index, what, &a, err);
    if (st != LMB_OK)
        return st;
    if (a->component_type != CT_UBYTE && a->component_type != CT_USHORT && a->component_type != CT_UINT)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: index accessor %d has componentType %d; indices must be unsigned byte, short or int",
                             ctx->path, what, index, a->component_type);
    if (a->normalized)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: index accessor %d must not be normalized", ctx->path, what, index);
    double *d = NULL;
    size_t n = 0;
    if ((st = read_doubles(ctx, index, 1, what, &d, &n, err)) != LMB_OK)
        return st;
    uint32_t *u = malloc((n + 1) * sizeof *u);
    if (!u) {
        free(d);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: %s: out of memory", ctx->path, what);
    }
    for (size_t i = 0; i < n; i++)
        u[i] = (uint32_t)d[i];
    free(d);
    *out = u;
    *count = n;
    return LMB_OK;
}
