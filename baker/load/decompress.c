/* Compressed geometry decoded into an in-memory .glb (see decompress.h). */
#include "decompress.h"
#include "draco_adapter.h"
#include "load_internal.h"
#include "uri.h"
#include "../util/file.h"

#include <cJSON.h>
#include <meshoptimizer.h>
#include <nettle/base64.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The new binary buffer: every input buffer, then the decoded data, each 4-byte aligned. */
typedef struct blob {
    uint8_t *data;
    size_t size, cap;
} blob;

static int blob_add(blob *b, const void *p, size_t n, size_t *at)
{
    size_t start = (b->size + 3) & ~(size_t)3;
    if (start + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < start + n + 1)
            cap *= 2;
        uint8_t *d = realloc(b->data, cap);
        if (!d)
            return 0;
        b->data = d;
        b->cap = cap;
    }
    memset(b->data + b->size, 0, start - b->size);
    if (n && p)
        memcpy(b->data + start, p, n);
    else if (n)
        memset(b->data + start, 0, n);
    b->size = start + n;
    *at = start;
    return 1;
}

/* An input buffer: its bytes (owned when `own`), where it sits in the blob, and whether it is
 * EXT_meshopt_compression's fallback (no data: only compressed views may use it). */
typedef struct src_buffer {
    uint8_t *data;
    size_t size, at;
    int own, fallback;
} src_buffer;

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static double num(const cJSON *o, const char *key, double fallback)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valuedouble : fallback;
}

static const cJSON *ext_of(const cJSON *o, const char *name)
{
    return cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(o, "extensions"), name);
}

/* Removes extension `name` from o's extensions (and the extensions object when it is empty). */
static void drop_ext(cJSON *o, const char *name)
{
    cJSON *e = cJSON_GetObjectItemCaseSensitive(o, "extensions");
    cJSON_DeleteItemFromObjectCaseSensitive(e, name);
    if (e && !e->child)
        cJSON_DeleteItemFromObjectCaseSensitive(o, "extensions");
}

static void drop_name(cJSON *root, const char *list, const char *name)
{
    cJSON *a = cJSON_GetObjectItemCaseSensitive(root, list);
    for (int i = cJSON_GetArraySize(a) - 1; i >= 0; i--) {
        cJSON *s = cJSON_GetArrayItem(a, i);
        if (cJSON_IsString(s) && !strcmp(s->valuestring, name))
            cJSON_DeleteItemFromArray(a, i);
    }
    if (a && !a->child)
        cJSON_DeleteItemFromObjectCaseSensitive(root, list);
}

static void set_num(cJSON *o, const char *key, double v)
{
    cJSON_DeleteItemFromObjectCaseSensitive(o, key);
    cJSON_AddNumberToObject(o, key, v);
}

/* Buffer i's bytes: a data URI (base64, nettle), a file inside the input's folder, the .glb's
 * binary chunk, or none for a meshopt fallback. */
static lmb_status load_buffer(const char *path, const cJSON *b, uint32_t i, const uint8_t *bin, size_t bin_size,
                              int glb, src_buffer *out, lmb_error *err)
{
    memset(out, 0, sizeof *out);
    const cJSON *fb = ext_of(b, "EXT_meshopt_compression");
    out->fallback = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(fb, "fallback"));
    const cJSON *uri = cJSON_GetObjectItemCaseSensitive(b, "uri");
    if (!cJSON_IsString(uri)) {
        if (glb && i == 0) {
            out->data = (uint8_t *)bin;
            out->size = bin_size;
            return LMB_OK;
        }
        if (out->fallback)
            return LMB_OK;
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: buffer %u has no uri and is not the .glb's binary chunk", path, i);
    }
    char rel[4096];
    lmb_uri_kind kind = lmb_uri_check(uri->valuestring, rel, sizeof rel);
    if (kind == LMB_URI_EMBEDDED) {
        const char *comma = strchr(uri->valuestring, ',');
        if (!comma || !strstr(uri->valuestring, ";base64,"))
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: buffer %u: a data uri that is not base64", path, i);
        size_t len = strlen(comma + 1), n = BASE64_DECODE_LENGTH(len);
        out->data = malloc(n + 1);
        out->own = 1;
        struct base64_decode_ctx ctx;
        base64_decode_init(&ctx);
        if (!out->data || !base64_decode_update(&ctx, &n, out->data, len, comma + 1) || !base64_decode_final(&ctx))
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: buffer %u: its data uri is not valid base64", path, i);
        out->size = n;
        return LMB_OK;
    }
    if (kind != LMB_URI_INSIDE)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: buffer %u: uri '%.200s' %s", path, i, uri->valuestring,
                             lmb_uri_refusal(kind));
    char folder[4096], file[8300], real[4096];
    const char *slash = strrchr(path, '/');
    snprintf(folder, sizeof folder, "%.*s", slash ? (int)(slash - path) : 1, slash ? path : ".");
    snprintf(file, sizeof file, "%s/%s", folder, rel);
    if (!lmb_path_inside(folder, file, real, sizeof real))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: buffer %u: '%.200s' is not a file inside the input's folder", path,
                             i, uri->valuestring);
    char *data = NULL;
    lmb_status st = lmb_read_file(real, "buffer", &data, &out->size, err);
    out->data = (uint8_t *)data;
    out->own = 1;
    return st;
}

/* Decodes meshopt view v (EXT_meshopt_compression, spec: mode, filter, count, byteStride) into
 * the blob and points the view there. */
static lmb_status decode_meshopt(const char *path, uint32_t vi, cJSON *v, const cJSON *ext, const src_buffer *bufs,
                                 uint32_t nbuf, blob *b, lmb_error *err)
{
    double bi = num(ext, "buffer", -1), off = num(ext, "byteOffset", 0), len = num(ext, "byteLength", -1);
    double count = num(ext, "count", -1), stride = num(ext, "byteStride", -1);
    const cJSON *mode = cJSON_GetObjectItemCaseSensitive(ext, "mode"), *filter = cJSON_GetObjectItemCaseSensitive(ext, "filter");
    if (!(bi >= 0 && bi < nbuf) || !(off >= 0) || !(len >= 0) || !(count >= 0) || !(stride >= 1 && stride <= 256) ||
        !cJSON_IsString(mode))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: bufferView %u: EXT_meshopt_compression needs buffer, byteLength, "
                             "count, byteStride and mode", path, vi);
    const src_buffer *s = &bufs[(uint32_t)bi];
    if (!s->data || off + len > (double)s->size)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: bufferView %u: its compressed bytes [%.0f, %.0f) are not in buffer "
                             "%.0f (%zu bytes)", path, vi, off, off + len, bi, s->size);
    size_t n = (size_t)count, sz = (size_t)stride, total = n * sz;
    if (count > 1e9 || total > ((size_t)1 << 30)) /* sizes before memory: a few bytes can claim gigabytes */
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: bufferView %u: EXT_meshopt_compression says %.0f elements of %zu "
                             "bytes, over lmbake's 1 GB for one buffer view", path, vi, count, sz);
    size_t at;
    if (!blob_add(b, NULL, total, &at))
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory decoding bufferView %u", path, vi);
    uint8_t *dst = b->data + at;
    const unsigned char *src = s->data + (size_t)off;
    int rc;
    if (!strcmp(mode->valuestring, "ATTRIBUTES"))
        rc = meshopt_decodeVertexBuffer(dst, n, sz, src, (size_t)len);
    else if (!strcmp(mode->valuestring, "TRIANGLES") && (sz == 2 || sz == 4))
        rc = meshopt_decodeIndexBuffer(dst, n, sz, src, (size_t)len);
    else if (!strcmp(mode->valuestring, "INDICES") && (sz == 2 || sz == 4))
        rc = meshopt_decodeIndexSequence(dst, n, sz, src, (size_t)len);
    else
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: bufferView %u: EXT_meshopt_compression mode '%.40s' with "
                             "byteStride %zu is not one the extension defines", path, vi, mode->valuestring, sz);
    if (rc != 0)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: bufferView %u: its EXT_meshopt_compression stream (%s, %zu x %zu "
                             "bytes) does not decode (meshoptimizer: %d)", path, vi, mode->valuestring, n, sz, rc);
    if (cJSON_IsString(filter) && strcmp(filter->valuestring, "NONE")) {
        if (!strcmp(filter->valuestring, "OCTAHEDRAL") && (sz == 4 || sz == 8))
            meshopt_decodeFilterOct(dst, n, sz);
        else if (!strcmp(filter->valuestring, "QUATERNION") && sz == 8)
            meshopt_decodeFilterQuat(dst, n, sz);
        else if (!strcmp(filter->valuestring, "EXPONENTIAL") && sz % 4 == 0)
            meshopt_decodeFilterExp(dst, n, sz);
        else
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: bufferView %u: EXT_meshopt_compression filter '%.40s' with "
                                 "byteStride %zu is not one the extension defines", path, vi, filter->valuestring, sz);
    }
    set_num(v, "buffer", 0);
    set_num(v, "byteOffset", (double)at);
    set_num(v, "byteLength", (double)total);
    drop_ext(v, "EXT_meshopt_compression");
    return LMB_OK;
}

static int component_size(int type)
{
    return type == 5120 || type == 5121 ? 1 : type == 5122 || type == 5123 ? 2 : type == 5125 || type == 5126 ? 4 : 0;
}

static int type_components(const char *t)
{
    static const char *const names[] = {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"};
    static const int comps[] = {1, 2, 3, 4, 4, 9, 16};
    for (int k = 0; t && k < 7; k++)
        if (!strcmp(t, names[k]))
            return comps[k];
    return 0;
}

/* A new buffer view over `bytes` in the blob (4-byte element stride for vertex data). */
static int add_view(cJSON *root, blob *b, const void *bytes, size_t n, size_t stride, size_t *index)
{
    size_t at;
    if (!blob_add(b, bytes, n, &at))
        return 0;
    cJSON *views = cJSON_GetObjectItemCaseSensitive(root, "bufferViews");
    cJSON *v = cJSON_CreateObject();
    if (!views || !v)
        return 0;
    cJSON_AddNumberToObject(v, "buffer", 0);
    cJSON_AddNumberToObject(v, "byteOffset", (double)at);
    cJSON_AddNumberToObject(v, "byteLength", (double)n);
    if (stride)
        cJSON_AddNumberToObject(v, "byteStride", (double)stride);
    *index = (size_t)cJSON_GetArraySize(views);
    cJSON_AddItemToArray(views, v);
    return 1;
}

/* Decodes primitive p of mesh m (KHR_draco_mesh_compression) and points its accessors at the
 * decoded indices and attributes. */
static lmb_status decode_draco(const char *path, const char *label, uint32_t pi, cJSON *root, cJSON *prim,
                               const cJSON *ext, blob *b, lmb_error *err)
{
    cJSON *views = cJSON_GetObjectItemCaseSensitive(root, "bufferViews");
    cJSON *accessors = cJSON_GetObjectItemCaseSensitive(root, "accessors");
    double vi = num(ext, "bufferView", -1);
    const cJSON *v = vi >= 0 ? cJSON_GetArrayItem(views, (int)vi) : NULL;
    double off = num(v, "byteOffset", 0), len = num(v, "byteLength", -1);
    if (!v || !(len >= 0) || off + len > (double)b->size)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s primitive %u: KHR_draco_mesh_compression bufferView %.0f is "
                             "missing or past its buffer", path, label, pi, vi);
    uint8_t *copy = malloc((size_t)len + 1);
    if (!copy)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
    memcpy(copy, b->data + (size_t)off, (size_t)len);
    lmb_draco_mesh *dm = NULL;
    uint32_t points = 0, faces = 0;
    lmb_error e;
    lmb_status st = lmb_draco_decode(copy, (size_t)len, &dm, &points, &faces, &e);
    free(copy);
    if (st != LMB_OK)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s primitive %u: %s", path, label, pi, e.message);
    /* indices */
    size_t idx_view;
    uint32_t *ix = malloc(((size_t)3 * faces + 1) * sizeof *ix);
    if (!ix)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
    if (st == LMB_OK) {
        lmb_draco_indices(dm, ix);
        if (!add_view(root, b, ix, (size_t)3 * faces * sizeof *ix, 0, &idx_view))
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
    }
    free(ix);
    if (st == LMB_OK) {
        cJSON *acc = cJSON_CreateObject();
        cJSON_AddNumberToObject(acc, "bufferView", (double)idx_view);
        cJSON_AddNumberToObject(acc, "componentType", 5125);
        cJSON_AddNumberToObject(acc, "count", 3.0 * faces);
        cJSON_AddStringToObject(acc, "type", "SCALAR");
        set_num(prim, "indices", (double)cJSON_GetArraySize(accessors));
        cJSON_AddItemToArray(accessors, acc);
    }
    /* attributes */
    const cJSON *attr, *ids = cJSON_GetObjectItemCaseSensitive(ext, "attributes");
    cJSON *attrs = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
    cJSON_ArrayForEach(attr, ids)
    {
        if (st != LMB_OK)
            break;
        const cJSON *ai = cJSON_GetObjectItemCaseSensitive(attrs, attr->string);
        cJSON *acc = cJSON_IsNumber(ai) ? cJSON_GetArrayItem(accessors, ai->valueint) : NULL;
        const cJSON *type = cJSON_GetObjectItemCaseSensitive(acc, "type");
        int ct = (int)num(acc, "componentType", 0), comps = type_components(cJSON_IsString(type) ? type->valuestring : NULL);
        int cs = component_size(ct);
        if (!acc || !cJSON_IsNumber(attr) || !cs || !comps) {
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: %s primitive %u: Draco attribute %s has no usable accessor", path,
                               label, pi, attr->string);
            break;
        }
        size_t elem = (size_t)cs * (size_t)comps, stride = (elem + 3) & ~(size_t)3;
        uint8_t *vals = malloc((size_t)points * elem + 1), *packed = calloc((size_t)points * stride + 1, 1);
        if (!vals || !packed)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
        else if (!lmb_draco_attribute(dm, attr->valueint, ct, comps, vals))
            st = lmb_error_set(err, LMB_ERR_INPUT, "%s: %s primitive %u: Draco attribute %s (id %d) is not in the "
                               "stream or does not convert to its accessor's type", path, label, pi, attr->string,
                               attr->valueint);
        size_t view;
        if (st == LMB_OK) {
            for (uint32_t k = 0; k < points; k++)
                memcpy(packed + (size_t)k * stride, vals + (size_t)k * elem, elem);
            if (!add_view(root, b, packed, (size_t)points * stride, stride != elem ? stride : 0, &view))
                st = lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
        }
        free(vals);
        free(packed);
        if (st == LMB_OK) {
            set_num(acc, "bufferView", (double)view);
            set_num(acc, "byteOffset", 0);
            set_num(acc, "count", (double)points);
            cJSON_DeleteItemFromObjectCaseSensitive(acc, "sparse");
        }
    }
    lmb_draco_free(dm);
    /* the primitive's other attributes without a buffer view (and not sparse) are zeros (glTF
     * 2.0 section 3.6.2.1): written out, so the output keeps them as the input had them */
    cJSON *other;
    cJSON_ArrayForEach(other, attrs)
    {
        cJSON *acc = cJSON_IsNumber(other) ? cJSON_GetArrayItem(accessors, other->valueint) : NULL;
        if (st != LMB_OK || !acc || cJSON_GetObjectItemCaseSensitive(ids, other->string) ||
            cJSON_GetObjectItemCaseSensitive(acc, "bufferView") || cJSON_GetObjectItemCaseSensitive(acc, "sparse"))
            continue;
        const cJSON *type = cJSON_GetObjectItemCaseSensitive(acc, "type");
        int cs = component_size((int)num(acc, "componentType", 0));
        int comps = type_components(cJSON_IsString(type) ? type->valuestring : NULL);
        double count = num(acc, "count", -1);
        size_t elem = (size_t)cs * (size_t)comps, stride = (elem + 3) & ~(size_t)3, view;
        if (!cs || !comps || !(count >= 0 && count <= 1e8))
            continue;
        if (!add_view(root, b, NULL, (size_t)count * stride, stride != elem ? stride : 0, &view))
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
        else
            set_num(acc, "bufferView", (double)view);
    }
    if (st == LMB_OK)
        drop_ext(prim, "KHR_draco_mesh_compression");
    return st;
}

/* Whether anything in root is compressed. */
static int compressed(const cJSON *root)
{
    const cJSON *v, *m, *p;
    cJSON_ArrayForEach(v, cJSON_GetObjectItemCaseSensitive(root, "bufferViews"))
        if (ext_of(v, "EXT_meshopt_compression"))
            return 1;
    cJSON_ArrayForEach(m, cJSON_GetObjectItemCaseSensitive(root, "meshes"))
        cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(m, "primitives"))
            if (ext_of(p, "KHR_draco_mesh_compression"))
                return 1;
    return 0;
}

/* The .glb of root's JSON and the blob (glTF 2.0 section 4.4). */
static lmb_status write_glb(const char *path, cJSON *root, const blob *b, lmb_decompressed *out, lmb_error *err)
{
    char *json = cJSON_PrintUnformatted(root);
    if (!json)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
    size_t jl = strlen(json), jp = (jl + 3) & ~(size_t)3, bp = (b->size + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jp + 8 + bp;
    uint8_t *g = malloc(total + 1);
    if (!g || total > 0xFFFFFFFFu) {
        free(json);
        free(g);
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: the decoded level is over 4 GB", path);
    }
    uint32_t h[5] = {0x46546C67u, 2, (uint32_t)total, (uint32_t)jp, 0x4E4F534Au};
    memcpy(g, h, sizeof h);
    memcpy(g + 20, json, jl);
    memset(g + 20 + jl, ' ', jp - jl);
    uint32_t c[2] = {(uint32_t)bp, 0x004E4942u};
    memcpy(g + 20 + jp, c, sizeof c);
    if (b->size)
        memcpy(g + 28 + jp, b->data, b->size);
    memset(g + 28 + jp + b->size, 0, bp - b->size);
    free(json);
    out->glb = g;
    out->size = total;
    return LMB_OK;
}

lmb_status lmb_decompress(const char *path, lmb_decompressed *out, lmb_error *err)
{
    memset(out, 0, sizeof *out);
    char *buf = NULL;
    size_t size = 0;
    lmb_status st = lmb_read_file(path, "glTF", &buf, &size, err);
    if (st != LMB_OK)
        return st;
    const unsigned char *u = (const unsigned char *)buf;
    int glb = size >= 20 && !memcmp(buf, "glTF", 4);
    const char *json = buf;
    size_t jl = size;
    const uint8_t *bin = NULL;
    size_t bin_size = 0;
    if (glb) { /* preflight checked the JSON chunk */
        jl = le32(u + 12);
        json = buf + 20;
        size_t at = 20 + ((jl + 3) & ~(size_t)3);
        if (at + 8 <= size && le32(u + at + 4) == 0x004E4942u && le32(u + at) <= size - at - 8) {
            bin = u + at + 8;
            bin_size = le32(u + at);
        }
    }
    cJSON *root = cJSON_ParseWithLength(json, jl);
    if (!root || !compressed(root)) {
        cJSON_Delete(root);
        free(buf);
        return LMB_OK;
    }
    blob b = {NULL, 0, 0};
    cJSON *buffers = cJSON_GetObjectItemCaseSensitive(root, "buffers");
    uint32_t nbuf = (uint32_t)cJSON_GetArraySize(buffers);
    src_buffer *bufs = calloc((size_t)nbuf + 1, sizeof *bufs);
    if (!bufs)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
    for (uint32_t i = 0; st == LMB_OK && i < nbuf; i++) {
        st = load_buffer(path, cJSON_GetArrayItem(buffers, (int)i), i, bin, bin_size, glb, &bufs[i], err);
        if (st == LMB_OK && !bufs[i].fallback && !blob_add(&b, bufs[i].data, bufs[i].size, &bufs[i].at))
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", path);
    }
    cJSON *views = cJSON_GetObjectItemCaseSensitive(root, "bufferViews"), *v;
    uint32_t vi = 0;
    cJSON_ArrayForEach(v, views)
    {
        if (st != LMB_OK)
            break;
        const cJSON *ext = ext_of(v, "EXT_meshopt_compression");
        if (ext) {
            st = decode_meshopt(path, vi, v, ext, bufs, nbuf, &b, err);
            out->meshopt_views++;
        } else {
            double bi = num(v, "buffer", -1);
            if (bi >= 0 && bi < nbuf && bufs[(uint32_t)bi].fallback)
                st = lmb_error_set(err, LMB_ERR_INPUT, "%s: bufferView %u reads buffer %.0f, EXT_meshopt_compression's "
                                   "fallback, which holds no data", path, vi, bi);
            else if (bi >= 0 && bi < nbuf) {
                set_num(v, "byteOffset", (double)bufs[(uint32_t)bi].at + num(v, "byteOffset", 0));
                set_num(v, "buffer", 0);
            }
        }
        vi++;
    }
    cJSON *m, *p;
    uint32_t mi = 0;
    cJSON_ArrayForEach(m, cJSON_GetObjectItemCaseSensitive(root, "meshes"))
    {
        uint32_t pi = 0;
        char label[160];
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(m, "name");
        lmb_object_label(label, "mesh", mi, cJSON_IsString(name) ? name->valuestring : NULL);
        cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(m, "primitives"))
        {
            const cJSON *ext = ext_of(p, "KHR_draco_mesh_compression");
            if (ext && st == LMB_OK) {
                st = decode_draco(path, label, pi, root, p, ext, &b, err);
                out->draco_primitives++;
            }
            pi++;
        }
        mi++;
    }
    for (uint32_t i = 0; bufs && i < nbuf; i++)
        if (bufs[i].own)
            free(bufs[i].data);
    free(bufs);
    if (st == LMB_OK) {
        cJSON *one = cJSON_CreateArray(), *b0 = cJSON_CreateObject();
        cJSON_AddNumberToObject(b0, "byteLength", (double)b.size);
        cJSON_AddItemToArray(one, b0);
        cJSON_ReplaceItemInObjectCaseSensitive(root, "buffers", one);
        for (int k = 0; k < 2; k++) {
            const char *list = k ? "extensionsRequired" : "extensionsUsed";
            drop_name(root, list, "EXT_meshopt_compression");
            drop_name(root, list, "KHR_draco_mesh_compression");
        }
        st = write_glb(path, root, &b, out, err);
    }
    free(b.data);
    cJSON_Delete(root);
    free(buf);
    return st;
}
