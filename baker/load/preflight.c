/*
 * Preflight: a look at the glTF's JSON (with cJSON) before tinygltf parses it, so that
 * files lmbake cannot bake fail with a message naming the reason rather than with the
 * symptom tinygltf would report later ("'uri' is missing", "invalid bufferView"):
 *   - asset.version must be 2.x (and minVersion, if any, <= 2.0);
 *   - extensionsRequired must only name extensions lmbake implements or can bake without
 *     (extensions.c); an alternative image format (KHR_texture_basisu, EXT_texture_webp, ...)
 *     only if every texture lmbake reads keeps a fallback `source` image;
 *   - (compressed geometry is decoded after this, before tinygltf: decompress.h);
 *   - alphaMode must be OPAQUE, MASK or BLEND and alphaCutoff a number in [0, 1], naming the
 *     material (tinygltf reads a malformed cutoff as 0.5 without a word);
 *   - a buffer's uri must name a file inside the input's folder (uri.h).
 * For .glb the JSON chunk is read from the container (glTF 2.0 spec section 4.4).
 */
#include "preflight.h"
#include "extensions.h"
#include "uri.h"
#include "load_internal.h"
#include "../util/file.h"

#include <cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Locates the JSON text: the whole file, or a .glb's first chunk. */
static lmb_status json_span(const char *path, const char *buf, size_t size, const char **json,
                            size_t *len, lmb_error *err)
{
    const unsigned char *u = (const unsigned char *)buf;
    if (size < 4 || memcmp(buf, "glTF", 4) != 0) {
        *json = buf;
        *len = size;
        return LMB_OK;
    }
    if (size < 20)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: truncated .glb header (%zu bytes)", path, size);
    uint32_t version = le32(u + 4), chunk_len = le32(u + 12), chunk_type = le32(u + 16);
    if (version != 2)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: .glb container version %u; lmbake reads glTF 2.0", path, version);
    if (chunk_type != 0x4E4F534Au || chunk_len > size - 20)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: .glb first chunk is not a complete JSON chunk", path);
    *json = buf + 20;
    *len = chunk_len;
    return LMB_OK;
}

static lmb_status check_version(const char *path, const cJSON *root, lmb_error *err)
{
    const cJSON *asset = cJSON_GetObjectItemCaseSensitive(root, "asset");
    const cJSON *version = cJSON_GetObjectItemCaseSensitive(asset, "version");
    const cJSON *min = cJSON_GetObjectItemCaseSensitive(asset, "minVersion");
    if (!cJSON_IsString(version))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: asset.version is missing; a glTF 2.0 file must state it", path);
    if (strncmp(version->valuestring, "2.", 2) != 0)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: asset.version is '%s'; lmbake reads glTF 2.x", path,
                             version->valuestring);
    if (cJSON_IsString(min) && strcmp(min->valuestring, "2.0") != 0)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: asset.minVersion is '%s'; lmbake reads glTF 2.0", path,
                             min->valuestring);
    return LMB_OK;
}

static int texture_index(const cJSON *info)
{
    const cJSON *i = cJSON_GetObjectItemCaseSensitive(info, "index");
    return cJSON_IsNumber(i) && i->valuedouble >= 0 && i->valuedouble < 1e9 ? (int)i->valuedouble : -1;
}

/* Textures lmbake reads (textures.c): base colour, metallicRoughness, emissive, spec-gloss diffuse
 * and specular. Returns the material that reads texture `tex` through `slot`, or -1. */
static int material_reading(const cJSON *root, int tex, const char **slot)
{
    static const char *const pbr_slots[] = {"baseColorTexture", "metallicRoughnessTexture"};
    static const char *const sg_slots[] = {"diffuseTexture", "specularGlossinessTexture"};
    const cJSON *m;
    int mi = 0;
    cJSON_ArrayForEach(m, cJSON_GetObjectItemCaseSensitive(root, "materials"))
    {
        const cJSON *pbr = cJSON_GetObjectItemCaseSensitive(m, "pbrMetallicRoughness");
        const cJSON *sg = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(m, "extensions"),
                                                           "KHR_materials_pbrSpecularGlossiness");
        for (int k = 0; k < 2; k++) {
            if (texture_index(cJSON_GetObjectItemCaseSensitive(pbr, pbr_slots[k])) == tex)
                return *slot = pbr_slots[k], mi;
            if (texture_index(cJSON_GetObjectItemCaseSensitive(sg, sg_slots[k])) == tex)
                return *slot = sg_slots[k], mi;
        }
        if (texture_index(cJSON_GetObjectItemCaseSensitive(m, "emissiveTexture")) == tex)
            return *slot = "emissiveTexture", mi;
        mi++;
    }
    return -1;
}

/* A required image-format extension (KHR_texture_basisu, ...): every texture lmbake reads that
 * carries it must also have a core `source` (PNG or JPEG), which is what lmbake decodes. */
static lmb_status check_image_fallback(const char *path, const cJSON *root, const char *ext, lmb_error *err)
{
    const cJSON *t;
    int ti = 0;
    cJSON_ArrayForEach(t, cJSON_GetObjectItemCaseSensitive(root, "textures"))
    {
        const cJSON *e = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(t, "extensions"), ext);
        const char *slot = NULL;
        int m;
        if (e && !cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(t, "source")) &&
            (m = material_reading(root, ti, &slot)) >= 0) {
            const cJSON *name = cJSON_GetObjectItemCaseSensitive(
                cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(root, "materials"), m), "name");
            char label[160];
            return lmb_error_set(err, LMB_ERR_INPUT,
                                 "%s: requires %s, and texture %d (the %s of %s) has no fallback image (`source`) "
                                 "lmbake can decode; export PNG or JPEG fallbacks",
                                 path, ext, ti, slot,
                                 lmb_object_label(label, "material", (uint32_t)m, cJSON_IsString(name) ? name->valuestring : NULL));
        }
        ti++;
    }
    return LMB_OK;
}

static lmb_status check_required(const char *path, const cJSON *root, lmb_error *err)
{
    char missing[512] = "";
    const cJSON *e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(root, "extensionsRequired"))
    {
        if (!cJSON_IsString(e))
            continue;
        const lmb_extension_info *info = lmb_extension_find(e->valuestring);
        if (info && info->support == LMB_EXT_IMAGE) {
            lmb_status st = check_image_fallback(path, root, e->valuestring, err);
            if (st != LMB_OK)
                return st;
        } else if (!info) {
            size_t len = strlen(missing);
            snprintf(missing + len, sizeof missing - len, "%s%s", len ? ", " : "", e->valuestring);
        }
    }
    if (*missing)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: requires glTF extension(s) lmbake does not support: %s",
                             path, missing);
    return LMB_OK;
}

/* alphaMode and alphaCutoff as written (glTF 2.0 section 5.19): tinygltf would read a cutoff
 * that is not a number as the default 0.5, silently; here it is named. */
static lmb_status check_alpha(const char *path, const cJSON *root, lmb_error *err)
{
    const cJSON *mat;
    uint32_t mi = 0;
    char label[160];
    cJSON_ArrayForEach(mat, cJSON_GetObjectItemCaseSensitive(root, "materials"))
    {
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(mat, "name");
        const cJSON *mode = cJSON_GetObjectItemCaseSensitive(mat, "alphaMode");
        const cJSON *cut = cJSON_GetObjectItemCaseSensitive(mat, "alphaCutoff");
        lmb_object_label(label, "material", mi, cJSON_IsString(name) ? name->valuestring : NULL);
        if (mode && (!cJSON_IsString(mode) || (strcmp(mode->valuestring, "OPAQUE") && strcmp(mode->valuestring, "MASK") &&
                                               strcmp(mode->valuestring, "BLEND"))))
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: alphaMode %.40s%s%s is not OPAQUE, MASK or BLEND", path,
                                 label, cJSON_IsString(mode) ? "'" : "", cJSON_IsString(mode) ? mode->valuestring : "(not a string)",
                                 cJSON_IsString(mode) ? "'" : "");
        if (cut && !cJSON_IsNumber(cut))
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: alphaCutoff is not a number; it must be a number in [0, 1]",
                                 path, label);
        if (cut && !(cut->valuedouble >= 0.0 && cut->valuedouble <= 1.0))
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: alphaCutoff %g is outside [0, 1]", path, label,
                                 cut->valuedouble);
        mi++;
    }
    return LMB_OK;
}

/* Buffers are read only from the input's folder (load/uri.h): a buffer whose uri points
 * elsewhere is an error (without it there is no geometry). */
static lmb_status check_buffer_uris(const char *path, const cJSON *root, lmb_error *err)
{
    const cJSON *buffer;
    uint32_t bi = 0;
    cJSON_ArrayForEach(buffer, cJSON_GetObjectItemCaseSensitive(root, "buffers"))
    {
        const cJSON *uri = cJSON_GetObjectItemCaseSensitive(buffer, "uri");
        char rel[4096];
        if (!cJSON_IsString(uri)) { /* the .glb's own chunk (or an error tinygltf names) */
            bi++;
            continue;
        }
        lmb_uri_kind kind = lmb_uri_check(uri->valuestring, rel, sizeof rel);
        if (kind != LMB_URI_INSIDE && kind != LMB_URI_EMBEDDED)
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: buffer %u: uri '%.200s' %s; without it there is no geometry",
                                 path, bi, uri->valuestring, lmb_uri_refusal(kind));
        if (kind == LMB_URI_INSIDE) { /* a link out of the folder: there, but not inside */
            char folder[4096], file[8300], real[4096];
            const char *slash = strrchr(path, '/');
            snprintf(folder, sizeof folder, "%.*s", slash ? (int)(slash - path) : 1, slash ? path : ".");
            snprintf(file, sizeof file, "%s/%s", folder, rel);
            if (access(file, F_OK) == 0 && !lmb_path_inside(folder, file, real, sizeof real))
                return lmb_error_set(err, LMB_ERR_INPUT,
                                     "%s: buffer %u: uri '%.200s' is not a file inside the input's folder (a link "
                                     "out of it?); without it there is no geometry", path, bi, uri->valuestring);
            /* sizes before memory (issue 15): the declared length must be in the file */
            const cJSON *len = cJSON_GetObjectItemCaseSensitive(buffer, "byteLength");
            struct stat sb;
            if (cJSON_IsNumber(len) && stat(file, &sb) == 0 && len->valuedouble > (double)sb.st_size)
                return lmb_error_set(err, LMB_ERR_INPUT, "%s: buffer %u declares %.0f bytes but '%.200s' holds %lld",
                                     path, bi, len->valuedouble, uri->valuestring, (long long)sb.st_size);
        } else { /* data: base64 gives at most 3 bytes per 4 characters */
            const cJSON *len = cJSON_GetObjectItemCaseSensitive(buffer, "byteLength");
            const char *comma = strchr(uri->valuestring, ',');
            double most = comma ? 0.75 * (double)strlen(comma + 1) + 3 : 0;
            if (cJSON_IsNumber(len) && len->valuedouble > most)
                return lmb_error_set(err, LMB_ERR_INPUT, "%s: buffer %u declares %.0f bytes but its data uri holds at "
                                     "most %.0f", path, bi, len->valuedouble, most);
        }
        bi++;
    }
    return LMB_OK;
}

lmb_status lmb_preflight(const char *path, lmb_error *err)
{
    char *buf = NULL;
    size_t size = 0, len = 0;
    const char *json = NULL;
    lmb_status st = lmb_read_file(path, "glTF", &buf, &size, err);
    if (st != LMB_OK)
        return st;
    if ((st = json_span(path, buf, size, &json, &len, err)) != LMB_OK) {
        free(buf);
        return st;
    }
    cJSON *root = cJSON_ParseWithLength(json, len);
    if (!root || !cJSON_IsObject(root)) {
        /* cJSON points at where parsing stopped: turn it into a line number */
        const char *at = cJSON_GetErrorPtr();
        unsigned line = 1;
        if (at && at >= json && at <= json + len)
            for (const char *c = json; c < at; c++)
                line += *c == '\n';
        cJSON_Delete(root);
        free(buf);
        return lmb_error_set(err, LMB_ERR_INPUT, "%s:%u: not valid glTF JSON (a JSON object was expected)", path, line);
    }
    st = check_version(path, root, err);
    if (st == LMB_OK)
        st = check_required(path, root, err);
    if (st == LMB_OK)
        st = check_alpha(path, root, err);
    if (st == LMB_OK)
        st = check_buffer_uris(path, root, err);
    cJSON_Delete(root);
    free(buf);
    return st;
}
