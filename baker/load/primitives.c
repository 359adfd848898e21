/*
 * glTF primitive -> lmbake triangle list. Strips and fans become lists with the winding
 * the glTF spec defines (section 3.7.2.1), points and lines are skipped with a warning,
 * attributes are checked (counts, finite values, index range) and zero-area triangles are
 * flagged so the unwrapper and baker leave them out.
 */
#include "load_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MODE_POINTS = 0, MODE_LINES, MODE_LINE_LOOP, MODE_LINE_STRIP, MODE_TRIANGLES, MODE_STRIP, MODE_FAN };

static const char *mode_name(int mode)
{
    static const char *const names[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP",
                                        "TRIANGLES", "TRIANGLE_STRIP", "TRIANGLE_FAN"};
    return mode >= 0 && mode <= 6 ? names[mode] : "unknown";
}

void lmb_primitive_release(lmb_primitive *p)
{
    free(p->positions);
    free(p->normals);
    free(p->uv0);
    free(p->uv1);
    free(p->colors);
    free(p->indices);
    free(p->degenerate);
    memset(p, 0, sizeof *p);
}

/* Triangle k of a list/strip/fan over the vertex sequence seq (spec 3.7.2.1). */
static void assemble(int mode, const uint32_t *seq, size_t k, uint32_t tri[3])
{
    if (mode == MODE_TRIANGLES) {
        tri[0] = seq[3 * k]; tri[1] = seq[3 * k + 1]; tri[2] = seq[3 * k + 2];
    } else if (mode == MODE_STRIP) {
        /* odd triangles swap their first two vertices to keep the winding */
        tri[0] = seq[k + (k & 1)]; tri[1] = seq[k + 1 - (k & 1)]; tri[2] = seq[k + 2];
    } else {
        tri[0] = seq[k + 1]; tri[1] = seq[k + 2]; tri[2] = seq[0];
    }
}

static size_t triangle_count_of(int mode, size_t n)
{
    if (mode == MODE_TRIANGLES)
        return n / 3;
    return n >= 3 ? n - 2 : 0;
}

/* Reads an optional per-vertex attribute and checks its count and values. */
static lmb_status read_attribute(const lmb_accessor_ctx *ctx, int32_t accessor, int comps,
                                 const char *what, size_t vertex_count, float **out, lmb_error *err)
{
    size_t n;
    *out = NULL;
    if (accessor < 0)
        return LMB_OK;
    lmb_status st = lmb_accessor_read_floats(ctx, accessor, comps, what, out, &n, err);
    if (st != LMB_OK)
        return st;
    if (n != vertex_count) {
        free(*out);
        *out = NULL;
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s has %zu elements but POSITION has %zu",
                             ctx->path, what, n, vertex_count);
    }
    for (size_t i = 0; i < n * (size_t)comps; i++)
        if (!isfinite((*out)[i])) {
            free(*out);
            *out = NULL;
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: vertex %zu is not a finite number (NaN or Inf)",
                                 ctx->path, what, i / (size_t)comps);
        }
    return LMB_OK;
}

/* COLOR_0 (glTF 2.0 section 3.7.2.1: VEC3 or VEC4, float or normalized unsigned byte/short,
 * linear) as RGBA, alpha 1 where the accessor is VEC3; it multiplies the base colour. Optional
 * data: one that cannot be read (no buffer view, a count or value that is wrong) is a warning
 * naming it, and the primitive is baked without it. */
static lmb_status read_colors(const lmb_accessor_ctx *ctx, int32_t accessor, const char *what, size_t vertex_count,
                              float **out, const lmb_log *log, lmb_error *err)
{
    char attr[224];
    *out = NULL;
    if (accessor < 0)
        return LMB_OK;
    snprintf(attr, sizeof attr, "%s COLOR_0", what);
    int comps = (uint32_t)accessor < ctx->view->accessor_count ? ctx->view->accessors[accessor].components : 0;
    if (comps != 3 && comps != 4) {
        lmb_warn(log, "%s: %s must be VEC3 or VEC4 (glTF 2.0 section 3.7.2.1); not used", ctx->path, attr);
        return LMB_OK;
    }
    float *c = NULL;
    lmb_error e;
    if (read_attribute(ctx, accessor, comps, attr, vertex_count, &c, &e) != LMB_OK) {
        lmb_warn(log, "%s; the vertex colours are not used", e.message);
        return LMB_OK;
    }
    float *rgba = malloc((4 * vertex_count + 1) * sizeof *rgba);
    if (!rgba) {
        free(c);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: %s: out of memory", ctx->path, attr);
    }
    for (size_t i = 0; i < vertex_count; i++)
        for (int k = 0; k < 4; k++)
            rgba[4 * i + (size_t)k] = k < comps ? c[(size_t)comps * i + (size_t)k] : 1.0f;
    free(c);
    *out = rgba;
    return LMB_OK;
}

/* Zero area in object space: the cross product vanishes against the edge lengths. */
static int is_degenerate(const float *pos, const uint32_t t[3])
{
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
        return 1;
    const float *a = pos + 3 * t[0], *b = pos + 3 * t[1], *c = pos + 3 * t[2];
    double e1[3], e2[3];
    for (int i = 0; i < 3; i++) {
        e1[i] = (double)b[i] - a[i];
        e2[i] = (double)c[i] - a[i];
    }
    double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
           cz = e1[0] * e2[1] - e1[1] * e2[0];
    double area2 = sqrt(cx * cx + cy * cy + cz * cz);
    double l1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    double l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    return !(area2 > 1e-12 * (l1 > l2 ? l1 : l2)) || area2 == 0.0;
}

static lmb_status build_triangles(const lmb_accessor_ctx *ctx, const lmb_gltf_primitive *gp,
                                  const char *what, lmb_primitive *out, const lmb_log *log, lmb_error *err)
{
    uint32_t *seq = NULL;
    size_t n = out->vertex_count;
    char label[224];
    if (gp->indices >= 0) {
        snprintf(label, sizeof label, "%s indices", what);
        lmb_status st = lmb_accessor_read_indices(ctx, gp->indices, label, &seq, &n, err);
        if (st != LMB_OK)
            return st;
        for (size_t i = 0; i < n; i++)
            if (seq[i] >= out->vertex_count) {
                uint32_t bad = seq[i];
                free(seq);
                return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: index %zu is %u, out of range (%u vertices)",
                                     ctx->path, label, i, bad, out->vertex_count);
            }
    } else {
        seq = malloc((n + 1) * sizeof *seq);
        if (!seq)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: %s: out of memory", ctx->path, what);
        for (size_t i = 0; i < n; i++)
            seq[i] = (uint32_t)i;
    }
    if (gp->mode == MODE_TRIANGLES && n % 3)
        lmb_warn(log, "%s: %s: %zu vertices is not a multiple of 3; the last %zu are ignored", ctx->path,
                 what, n, n % 3);
    size_t tc = triangle_count_of(gp->mode, n);
    out->indices = malloc((3 * tc + 1) * sizeof *out->indices);
    out->degenerate = calloc(tc + 1, 1);
    if (!out->indices || !out->degenerate) {
        free(seq);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: %s: out of memory", ctx->path, what);
    }
    for (size_t k = 0; k < tc; k++) {
        assemble(gp->mode, seq, k, out->indices + 3 * k);
        out->degenerate[k] = (uint8_t)is_degenerate(out->positions, out->indices + 3 * k);
        out->degenerate_count += out->degenerate[k];
    }
    out->triangle_count = (uint32_t)tc;
    free(seq);
    return LMB_OK;
}

lmb_status lmb_load_primitive(const lmb_accessor_ctx *ctx, uint32_t mesh_index, uint32_t prim_index,
                              const char *mesh_name, uint32_t material_count, lmb_primitive *out,
                              int *skipped, const lmb_log *log, lmb_error *err)
{
    const lmb_gltf_mesh *gm = &ctx->view->meshes[mesh_index];
    const lmb_gltf_primitive *gp = &ctx->view->primitives[gm->first_primitive + prim_index];
    char what[192], attr[224];
    snprintf(what, sizeof what, "mesh '%s' primitive %u", mesh_name, prim_index);
    *skipped = 0;
    out->gltf_mesh = mesh_index;
    out->gltf_primitive = prim_index;
    out->material = gp->material;
    if (gp->mode < 0 || gp->mode > MODE_FAN)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s has invalid mode %d", ctx->path, what, gp->mode);
    if (gp->mode < MODE_TRIANGLES) {
        lmb_warn(log, "%s: %s is %s, not triangles: skipped", ctx->path, what, mode_name(gp->mode));
        *skipped = 1;
        return LMB_OK;
    }
    if (gp->material < -1 || (gp->material >= 0 && (uint32_t)gp->material >= material_count))
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s uses material %d, which does not exist (the file has %u)",
                             ctx->path, what, gp->material, material_count);
    if (gp->position < 0) {
        /* glTF 3.7.2.1: without positions a primitive is not rendered; skip it, but count its triangles */
        int32_t counted = gp->indices >= 0 ? gp->indices : gp->any_attribute;
        size_t n = counted >= 0 && (uint32_t)counted < ctx->view->accessor_count ? ctx->view->accessors[counted].count : 0;
        lmb_warn(log, "%s: %s has no POSITION attribute: skipped", ctx->path, what);
        *skipped = 1;
        out->triangle_count = (uint32_t)triangle_count_of(gp->mode, n);
        return LMB_OK;
    }
    size_t nv;
    snprintf(attr, sizeof attr, "%s POSITION", what);
    lmb_status st = lmb_accessor_read_floats(ctx, gp->position, 3, attr, &out->positions, &nv, err);
    if (st != LMB_OK)
        return st;
    out->vertex_count = (uint32_t)nv;
    for (size_t i = 0; i < 3 * nv; i++)
        if (!isfinite(out->positions[i]))
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: %s: vertex %zu is not a finite number (NaN or Inf)",
                                 ctx->path, attr, i / 3);
    snprintf(attr, sizeof attr, "%s NORMAL", what);
    if ((st = read_attribute(ctx, gp->normal, 3, attr, nv, &out->normals, err)) != LMB_OK)
        return st;
    snprintf(attr, sizeof attr, "%s TEXCOORD_0", what);
    if ((st = read_attribute(ctx, gp->texcoord0, 2, attr, nv, &out->uv0, err)) != LMB_OK)
        return st;
    snprintf(attr, sizeof attr, "%s TEXCOORD_1", what);
    if ((st = read_attribute(ctx, gp->texcoord1, 2, attr, nv, &out->uv1, err)) != LMB_OK)
        return st;
    if ((st = read_colors(ctx, gp->color0, what, nv, &out->colors, log, err)) != LMB_OK)
        return st;
    return build_triangles(ctx, gp, what, out, log, err);
}
