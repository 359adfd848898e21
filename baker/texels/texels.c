/*
 * Gather points per texel (see texels.h). One pass over the triangles of the atlas keeps,
 * for every sub-sample, the closest triangle (distance 0 when inside, ties: the first in
 * scene order) within one texel; a second pass turns the winners into world-space points.
 * Normals: shading normals go through the inverse transpose of the instance matrix
 * (the cofactor matrix times the sign of the determinant); the geometric normal is the
 * world-space face normal, negated for mirrored instances so it stays on the front side.
 */
#include "texels.h"

#include "util/triangle2d.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct best {
    float dist; /* texels */
    float b1, b2;
    uint32_t instance, triangle;
} best;

static void copy_band(lmb_texels *dst, const lmb_texels *band);

lmb_status lmb_texels_append(lmb_texels *dst, const lmb_texels *band, lmb_error *err)
{
    uint32_t n = dst->count + band->count;
    if (n <= dst->capacity) {
        copy_band(dst, band);
        return LMB_OK;
    }
    lmb_status st = lmb_texels_reserve(dst, n, err);
    if (st == LMB_OK)
        copy_band(dst, band);
    return st;
}

lmb_status lmb_texels_reserve(lmb_texels *dst, uint32_t n, lmb_error *err)
{
    if (n <= dst->capacity || n < dst->count)
        return LMB_OK;
    /* exact growth: no slack is left behind (memory per texel, docs/defaults.md) */
    uint32_t *texel = realloc(dst->texel, ((size_t)n + 1) * sizeof *texel);
    if (texel) dst->texel = texel;
    uint8_t *points_in = realloc(dst->points_in, (size_t)n + 1);
    if (points_in) dst->points_in = points_in;
    float *size = realloc(dst->texel_size, ((size_t)n + 1) * sizeof *size);
    if (size) dst->texel_size = size;
    lmb_point_ref *refs = realloc(dst->refs, ((size_t)n + 1) * sizeof *refs);
    if (refs) dst->refs = refs;
    uint8_t *valid = realloc(dst->valid, (size_t)n + 1);
    if (valid) dst->valid = valid;
    uint8_t *gather_at = realloc(dst->gather_at, (size_t)n + 1);
    if (gather_at) dst->gather_at = gather_at;
    uint8_t *partly = realloc(dst->edge, (size_t)n + 1);
    if (partly) dst->edge = partly;
    if (!texel || !points_in || !size || !refs || !valid || !gather_at || !partly)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "texels: out of memory for %u texels", n);
    dst->capacity = n;
    return LMB_OK;
}

static void copy_band(lmb_texels *dst, const lmb_texels *band)
{
    for (uint32_t i = 0; i < band->count; i++) {
        uint32_t j = dst->count + i;
        dst->texel[j] = band->texel[i];
        dst->points_in[j] = 1;
        dst->texel_size[j] = band->texel_size[i];
        dst->refs[j] = band->refs[(size_t)i * band->samples + band->gather_at[i]];
        dst->valid[j] = band->valid[i];
        dst->gather_at[j] = 0;
        dst->edge[j] = band->edge[i];
    }
    dst->width = band->width;
    dst->height = band->height;
    dst->samples = 1;
    dst->scene = band->scene ? band->scene : dst->scene;
    dst->layout = band->layout ? band->layout : dst->layout;
    dst->count += band->count;
}

void lmb_texels_free(lmb_texels *t)
{
    free(t->texel);
    free(t->points_in);
    free(t->texel_size);
    free(t->points);
    free(t->refs);
    free(t->valid);
    free(t->gather_at);
    free(t->edge);
    memset(t, 0, sizeof *t);
}


/* The rows triangle uv (3 atlas points) reaches: its texels' and their neighbours'. */
static void triangle_rows(const double *uv, long *y0, long *y1)
{
    *y0 = (long)floor(fmin(uv[1], fmin(uv[3], uv[5]))) - 1;
    *y1 = (long)floor(fmax(uv[1], fmax(uv[3], uv[5]))) + 1;
}

/* The rows instance i's triangle f reaches (triangle_rows); 0 for a triangle in no chart. */
static int placed_triangle_rows(const lmb_layout *l, uint32_t i, const lmb_charts *c, uint32_t f, long *y0, long *y1)
{
    if (c->chart_of[f] == UINT32_MAX)
        return 0;
    double uv[6];
    lmb_layout_uv(l, i, f, uv);
    triangle_rows(uv, y0, y1);
    return 1;
}

/* Triangles at least this many in an instance with its own layout get per-band lists. */
#define BAND_LIST_TRIANGLES 1024

/* Instance i's per-band triangle lists (counted, then filled in triangle order). */
static int band_lists(const lmb_layout *l, uint32_t i, const lmb_charts *c, uint32_t height, uint32_t band_rows,
                      uint32_t **start_out, uint32_t **list_out)
{
    uint32_t bands = (height + band_rows - 1) / band_rows;
    uint32_t *start = calloc((size_t)bands + 2, sizeof *start);
    if (!start)
        return 0;
    for (int pass = 0; pass < 2; pass++) {
        uint32_t *fill = NULL;
        if (pass == 1) {
            for (uint32_t b = 0; b < bands; b++) /* counts to starts */
                start[b + 1] += start[b];
            *list_out = malloc(((size_t)start[bands] + 1) * sizeof **list_out);
            fill = calloc((size_t)bands + 1, sizeof *fill);
            if (!*list_out || !fill) {
                free(*list_out);
                free(fill);
                free(start);
                *list_out = NULL;
                return 0;
            }
        }
        for (uint32_t f = 0; f < c->triangle_count; f++) {
            long y0, y1;
            if (!placed_triangle_rows(l, i, c, f, &y0, &y1))
                continue;
            y0 = y0 < 0 ? 0 : y0;
            y1 = y1 >= (long)height ? (long)height - 1 : y1;
            for (long b = y0 / (long)band_rows; y0 <= y1 && b <= y1 / (long)band_rows; b++) {
                if (pass == 0)
                    start[b + 1]++;
                else
                    (*list_out)[start[b] + fill[b]++] = f;
            }
        }
        free(fill);
    }
    *start_out = start;
    return 1;
}

lmb_status lmb_instance_rows_make(const lmb_scene *s, const lmb_layout *l, uint32_t atlas, uint32_t band_rows,
                                  lmb_instance_rows *out, lmb_error *err)
{
    memset(out, 0, sizeof *out);
    out->band_rows = band_rows;
    out->instance_count = l->instance_count;
    out->lo = malloc(((size_t)l->instance_count + 1) * sizeof *out->lo);
    out->hi = malloc(((size_t)l->instance_count + 1) * sizeof *out->hi);
    out->band_start = calloc((size_t)l->instance_count + 1, sizeof *out->band_start);
    out->band_triangles = calloc((size_t)l->instance_count + 1, sizeof *out->band_triangles);
    int ok = out->lo && out->hi && out->band_start && out->band_triangles;
    for (uint32_t i = 0; ok && i < l->instance_count; i++) {
        const lmb_layout_instance *li = &l->instances[i];
        out->lo[i] = INT64_MAX;
        out->hi[i] = INT64_MIN;
        if (!li->lightmapped || li->atlas != atlas)
            continue;
        const lmb_charts *c = &l->meshes[s->instances[i].mesh].charts;
        for (uint32_t f = 0; f < c->triangle_count; f++) {
            long y0, y1;
            if (!placed_triangle_rows(l, i, c, f, &y0, &y1))
                continue;
            out->lo[i] = y0 < out->lo[i] ? y0 : out->lo[i];
            out->hi[i] = y1 > out->hi[i] ? y1 : out->hi[i];
        }
        /* copies placed as rectangles span a few rows each: the instance's reach is enough */
        if (band_rows && li->uv1 && c->triangle_count >= BAND_LIST_TRIANGLES)
            ok = band_lists(l, i, c, l->height[atlas], band_rows, &out->band_start[i], &out->band_triangles[i]);
    }
    if (!ok) {
        lmb_instance_rows_free(out);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "texels: out of memory for %u instances", l->instance_count);
    }
    return LMB_OK;
}

void lmb_instance_rows_free(lmb_instance_rows *r)
{
    for (uint32_t i = 0; i < r->instance_count; i++) {
        if (r->band_start)
            free(r->band_start[i]);
        if (r->band_triangles)
            free(r->band_triangles[i]);
    }
    free(r->lo);
    free(r->hi);
    free(r->band_start);
    free(r->band_triangles);
    memset(r, 0, sizeof *r);
}

/* Sub-samples of rows [y0, y1) only: b holds (y1 - y0) rows. */
static void rasterize(const lmb_layout *l, const lmb_scene *s, uint32_t atlas, uint32_t samples, uint32_t y0_band,
                      uint32_t y1_band, const lmb_instance_rows *rows, best *b)
{
    uint32_t w = l->width[atlas];
    double offset[2 * 256]; /* the sub-samples' places in a texel (samples.texel <= 256) */
    for (uint32_t k = 0; k < samples && k < 256; k++)
        lmb_texel_subsample(k, samples, &offset[2 * k]);
    for (uint32_t i = 0; i < l->instance_count; i++) {
        const lmb_layout_instance *li = &l->instances[i];
        if (!li->lightmapped || li->atlas != atlas)
            continue;
        if (rows && (rows->hi[i] < (int64_t)y0_band || rows->lo[i] >= (int64_t)y1_band))
            continue; /* none of its triangles reaches the band */
        const lmb_charts *c = &l->meshes[s->instances[i].mesh].charts;
        /* the band's own list when the band is one of those the lists were made for */
        const uint32_t *list = NULL;
        uint32_t count = c->triangle_count;
        if (rows && rows->band_triangles && rows->band_triangles[i] && rows->band_rows &&
            y0_band % rows->band_rows == 0 && y1_band - y0_band <= rows->band_rows) {
            uint32_t band = y0_band / rows->band_rows;
            list = rows->band_triangles[i] + rows->band_start[i][band];
            count = rows->band_start[i][band + 1] - rows->band_start[i][band];
        }
        for (uint32_t n = 0; n < count; n++) {
            uint32_t f = list ? list[n] : n;
            if (c->chart_of[f] == UINT32_MAX)
                continue;
            double uv[6], box[4];
            lmb_layout_uv(l, i, f, uv);
            lmb_triangle_box_2d(uv, box);
            long x0 = (long)floor(box[0]) - 1, x1 = (long)floor(box[2]) + 1, y0, y1;
            triangle_rows(uv, &y0, &y1);
            x0 = x0 < 0 ? 0 : x0;
            y0 = y0 < (long)y0_band ? (long)y0_band : y0;
            x1 = x1 >= (long)w ? (long)w - 1 : x1;
            y1 = y1 >= (long)y1_band ? (long)y1_band - 1 : y1;
            for (long y = y0; y <= y1; y++)
                for (long x = x0; x <= x1; x++)
                    for (uint32_t k = 0; k < samples; k++) {
                        best *bb = &b[((size_t)(y - (long)y0_band) * w + (size_t)x) * samples + k];
                        if (bb->dist == 0.0f)
                            continue; /* inside an earlier triangle: nothing is closer, and ties keep the first */
                        double sp[2] = {offset[2 * k] + (double)x, offset[2 * k + 1] + (double)y}, b1 = 0, b2 = 0;
                        if (lmb_box_beyond_2d(box, sp, bb->dist < 1.0f ? (double)bb->dist : 1.0))
                            continue; /* it could not come closer than the best so far, nor within a texel */
                        double d = lmb_closest_on_triangle_2d(uv, sp, &b1, &b2);
                        if (d <= 1.0 && d < bb->dist) {
                            bb->dist = (float)d;
                            bb->b1 = (float)b1;
                            bb->b2 = (float)b2;
                            bb->instance = i;
                            bb->triangle = f;
                        }
                    }
        }
    }
}

/* Cofactor (adjugate transpose) of the upper 3x3 of a column-major 4x4, times sign(det):
 * the normal matrix, up to a positive scale. */
static void normal_matrix(const double m[16], double out[9])
{
    double a = m[0], b = m[4], c = m[8], d = m[1], e = m[5], f = m[9], g = m[2], h = m[6], i = m[10];
    double cof[9] = {e * i - f * h, -(d * i - f * g), d * h - e * g,
                     -(b * i - c * h), a * i - c * g, -(a * h - b * g),
                     b * f - c * e, -(a * f - c * d), a * e - b * d};
    double det = a * cof[0] + b * cof[1] + c * cof[2];
    double sg = det < 0 ? -1.0 : 1.0;
    /* row r of the normal matrix = cofactors of row r */
    for (int k = 0; k < 9; k++)
        out[k] = cof[k] * sg;
}

static void normalize3f(const double v[3], float out[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        out[k] = (float)(l > 0 ? v[k] / l : (k == 2));
}

/* Points are moved 1/100 texel toward their triangle's centroid: a point clamped onto a
 * chart border lies exactly where the next wall begins, and a shadow ray from there would
 * start inside that wall and leak light through it. */
static void pull_inside(const double q[9], double texel_size, double p[3])
{
    double c[3], d2 = 0;
    for (int r = 0; r < 3; r++) {
        c[r] = (q[r] + q[3 + r] + q[6 + r]) / 3.0 - p[r];
        d2 += c[r] * c[r];
    }
    double d = sqrt(d2), step = fmin(0.01 * texel_size, 0.5 * d);
    for (int r = 0; r < 3 && d > 0; r++)
        p[r] += c[r] / d * step;
}

int lmb_triangle_corner_normals(const lmb_scene *s, const lmb_layout *l, uint32_t instance, uint32_t f, double out[9])
{
    const lmb_instance *in = &s->instances[instance];
    const lmb_mesh_soup *soup = &l->meshes[in->mesh].soup;
    const uint32_t *t = soup->indices + 3 * (size_t)f;
    double nm[9];
    normal_matrix(in->world, nm);
    for (int k = 0; k < 3; k++) {
        const float *vn = soup->normals + 3 * t[k];
        for (int r = 0; r < 3; r++)
            out[3 * k + r] = nm[3 * r] * vn[0] + nm[3 * r + 1] * vn[1] + nm[3 * r + 2] * vn[2];
    }
    return !soup->flat[f];
}

static void make_point(const lmb_scene *s, const lmb_layout *l, const lmb_point_ref *b, lmb_gather_point *out)
{
    const lmb_mesh_soup *soup = &l->meshes[s->instances[b->instance].mesh].soup;
    const lmb_instance *in = &s->instances[b->instance];
    double w[3] = {1.0 - b->b1 - b->b2, b->b1, b->b2}, q[9], cn[9], n[3] = {0, 0, 0}, p[3] = {0, 0, 0};
    lmb_layout_world_triangle(s, l, b->instance, b->triangle, q);
    lmb_triangle_corner_normals(s, l, b->instance, b->triangle, cn);
    for (int k = 0; k < 3; k++)
        for (int r = 0; r < 3; r++) {
            p[r] += w[k] * q[3 * k + r];
            n[r] += w[k] * cn[3 * k + r];
        }
    double e1[3] = {q[3] - q[0], q[4] - q[1], q[5] - q[2]}, e2[3] = {q[6] - q[0], q[7] - q[1], q[8] - q[2]};
    double g[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    if (in->flips_winding)
        for (int r = 0; r < 3; r++)
            g[r] = -g[r];
    pull_inside(q, 1.0 / l->instances[b->instance].texel_density, p);
    memcpy(out->p, p, sizeof p);
    normalize3f(g, out->ng);
    normalize3f(n, out->n);
    if (soup->flat[b->triangle])
        memcpy(out->n, out->ng, sizeof out->n);
    if (!(fabsf(out->n[0]) + fabsf(out->n[1]) + fabsf(out->n[2]) > 0) || !isfinite(out->n[0]))
        memcpy(out->n, out->ng, sizeof out->n);
    out->instance = b->instance;
    out->triangle = b->triangle;
}

void lmb_texels_point(const lmb_texels *t, uint32_t i, uint32_t k, lmb_gather_point *out)
{
    size_t at = (size_t)i * t->samples + k;
    if (t->points)
        *out = t->points[at];
    else
        make_point(t->scene, t->layout, &t->refs[at], out);
}

lmb_status lmb_texels_build(const lmb_scene *s, const lmb_layout *l, uint32_t atlas, uint32_t samples, lmb_texels *out,
                            lmb_error *err)
{
    return lmb_texels_build_rows(s, l, atlas, samples, 0, l->height[atlas], NULL, out, err);
}

lmb_status lmb_texels_build_rows(const lmb_scene *s, const lmb_layout *l, uint32_t atlas, uint32_t samples,
                                 uint32_t y0, uint32_t y1, const lmb_instance_rows *rows, lmb_texels *out,
                                 lmb_error *err)
{
    memset(out, 0, sizeof *out);
    uint32_t w = l->width[atlas], h = y1 - y0;
    size_t n = (size_t)w * h * samples;
    best *b = malloc((n + 1) * sizeof *b);
    if (!b)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "texels: out of memory for a %ux%u atlas", w, h);
    for (size_t i = 0; i < n; i++)
        b[i].dist = FLT_MAX;
    rasterize(l, s, atlas, samples, y0, y1, rows, b);
    out->width = w;
    out->height = l->height[atlas];
    out->samples = samples;
    for (size_t t = 0; t < (size_t)w * h; t++)
        for (uint32_t k = 0; k < samples; k++)
            if (b[t * samples + k].dist < FLT_MAX) {
                out->count++;
                break;
            }
    out->texel = malloc(((size_t)out->count + 1) * sizeof *out->texel);
    out->points_in = calloc((size_t)out->count + 1, 1);
    out->texel_size = malloc(((size_t)out->count + 1) * sizeof *out->texel_size);
    out->points = calloc((size_t)out->count * samples + 1, sizeof *out->points);
    out->refs = calloc((size_t)out->count * samples + 1, sizeof *out->refs);
    out->scene = s;
    out->layout = l;
    out->valid = malloc((size_t)out->count + 1);
    out->gather_at = calloc((size_t)out->count + 1, 1);
    out->edge = calloc((size_t)out->count + 1, 1);
    if (!out->texel || !out->points_in || !out->texel_size || !out->points || !out->refs || !out->valid ||
        !out->gather_at || !out->edge) {
        free(b);
        lmb_texels_free(out);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "texels: out of memory for %u texels", out->count);
    }
    uint32_t c = 0;
    for (size_t t = 0; t < (size_t)w * h; t++) {
        uint32_t m = 0;
        for (uint32_t k = 0; k < samples; k++) {
            const best *bb = &b[t * samples + k];
            if (bb->dist < FLT_MAX) {
                lmb_point_ref *r = &out->refs[(size_t)c * samples + m];
                r->instance = bb->instance;
                r->triangle = bb->triangle;
                r->b1 = bb->b1;
                r->b2 = bb->b2;
                make_point(s, l, r, &out->points[(size_t)c * samples + m++]);
            }
        }
        if (!m)
            continue;
        out->texel[c] = (uint32_t)(t + (size_t)y0 * w);
        out->points_in[c] = (uint8_t)m;
        out->texel_size[c] = (float)(1.0 / l->instances[out->points[(size_t)c * samples].instance].texel_density);
        out->valid[c] = 1;
        c++;
    }
    free(b);
    return LMB_OK;
}
