/* The layout as bytes and back (plan_codec.h). */
#include "plan_codec.h"

#include <lmbake/lmbake.h>

#include <stdlib.h>
#include <string.h>

#define ABSENT UINT64_MAX

typedef struct writer {
    uint8_t *buf;
    size_t used, cap;
    int failed;
} writer;

static void put(writer *w, const void *p, size_t n)
{
    if (w->failed || !n)
        return;
    if (w->used + n > w->cap) {
        size_t cap = w->cap ? w->cap : 4096;
        while (cap < w->used + n)
            cap *= 2;
        uint8_t *b = realloc(w->buf, cap);
        if (!b) {
            w->failed = 1;
            return;
        }
        w->buf = b;
        w->cap = cap;
    }
    memcpy(w->buf + w->used, p, n);
    w->used += n;
}

static void put_u32(writer *w, uint32_t v) { put(w, &v, sizeof v); }
static void put_u64(writer *w, uint64_t v) { put(w, &v, sizeof v); }
static void put_f64(writer *w, double v) { put(w, &v, sizeof v); }

/* count elements of `size` bytes, or ABSENT for NULL */
static void put_array(writer *w, const void *p, uint64_t count, size_t size)
{
    put_u64(w, p ? count : ABSENT);
    if (p)
        put(w, p, (size_t)count * size);
}

lmb_status lmb_plan_encode(const lmb_layout *l, uint8_t **out, size_t *size, lmb_error *err)
{
    writer w = {NULL, 0, 0, 0};
    put_u32(&w, l->mesh_count);
    put_u32(&w, l->instance_count);
    put_u32(&w, l->atlas_count);
    put_u32(&w, l->chart_total);
    put_array(&w, l->width, l->atlas_count, sizeof *l->width);
    put_array(&w, l->height, l->atlas_count, sizeof *l->height);
    put_u32(&w, (uint32_t)l->density.automatic);
    put_f64(&w, l->density.scene_density);
    put_u64(&w, l->density.budget);
    put_u32(&w, l->density.capped);
    put_u32(&w, l->density.raised);
    put_u32(&w, l->density.short_of_floor);
    put_f64(&w, l->density.floor_share_min);
    put_u64(&w, l->density.texels);
    put_u32(&w, l->density.rounds);
    for (uint32_t m = 0; m < l->mesh_count; m++) {
        const lmb_layout_mesh *lm = &l->meshes[m];
        const lmb_mesh_soup *s = &lm->soup;
        const lmb_charts *c = &lm->charts;
        put_u32(&w, (uint32_t)lm->used);
        put_u32(&w, (uint32_t)lm->kept_uv1);
        put_u32(&w, s->vertex_count);
        put_u32(&w, s->triangle_count);
        put_array(&w, s->positions, 3 * (uint64_t)s->vertex_count, sizeof *s->positions);
        put_array(&w, s->normals, 3 * (uint64_t)s->vertex_count, sizeof *s->normals);
        put_array(&w, s->indices, 3 * (uint64_t)s->triangle_count, sizeof *s->indices);
        put_array(&w, s->skip, s->triangle_count, sizeof *s->skip);
        put_array(&w, s->flat, s->triangle_count, sizeof *s->flat);
        put_u32(&w, c->chart_count);
        put_u32(&w, c->triangle_count);
        put_array(&w, c->chart_of, c->triangle_count, sizeof *c->chart_of);
        put_array(&w, c->uv, 6 * (uint64_t)c->triangle_count, sizeof *c->uv);
        put_array(&w, c->first, c->first ? (uint64_t)c->chart_count + 1 : 0, sizeof *c->first);
        put_array(&w, c->order, c->triangle_count, sizeof *c->order);
        put_u32(&w, c->planar_charts);
        put_u32(&w, c->splits);
        put_u32(&w, c->glued);
        put(&w, &c->topology, sizeof c->topology); /* uint32_t fields only: no padding */
    }
    /* shared layouts: 6 per triangle of the block's mesh */
    put_u32(&w, l->block_count);
    for (uint32_t b = 0; b < l->block_count; b++) {
        put_u32(&w, l->blocks[b].mesh);
        put_array(&w, l->blocks[b].uv, 6 * (uint64_t)l->meshes[l->blocks[b].mesh].soup.triangle_count,
                  sizeof *l->blocks[b].uv);
    }
    for (uint32_t i = 0; i < l->instance_count; i++) {
        const lmb_layout_instance *in = &l->instances[i];
        put_u32(&w, (uint32_t)(in->lightmapped ? 1 : 0) | (in->probe_lit ? 2u : 0u)); /* flags */
        put_u32(&w, in->atlas);
        put_f64(&w, in->texel_density);
        put_u32(&w, (uint32_t)in->shared_layout);
        for (int k = 0; k < 4; k++)
            put_f64(&w, in->scale_offset[k]);
        put_u32(&w, in->triangle_count);
        put_u32(&w, in->block);
        for (int k = 0; k < 4; k++)
            put_f64(&w, in->rect[k]);
        /* uv1: 6 per triangle of the instance's mesh (NULL for a block's instance) */
        put_array(&w, in->uv1, 6 * (uint64_t)in->triangle_count, sizeof *in->uv1);
    }
    if (w.failed) {
        free(w.buf);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "plan: out of memory");
    }
    *out = w.buf;
    *size = w.used;
    return LMB_OK;
}

typedef struct reader {
    const uint8_t *p;
    size_t left;
    int failed;
} reader;

static void get(reader *r, void *out, size_t n)
{
    if (r->failed || n > r->left) {
        r->failed = 1;
        memset(out, 0, n);
        return;
    }
    memcpy(out, r->p, n);
    r->p += n;
    r->left -= n;
}

static uint32_t get_u32(reader *r) { uint32_t v; get(r, &v, sizeof v); return v; }
static uint64_t get_u64(reader *r) { uint64_t v; get(r, &v, sizeof v); return v; }
static double get_f64(reader *r) { double v; get(r, &v, sizeof v); return v; }

/* An array of `size`-byte elements: NULL when absent; its count must be `expect` (or any when
 * expect is ABSENT, then *count gets it) and fit in what is left. */
static void *get_array(reader *r, uint64_t expect, size_t size, uint64_t *count)
{
    uint64_t n = get_u64(r);
    if (r->failed || n == ABSENT)
        return NULL;
    if ((expect != ABSENT && n != expect) || n > r->left / (size ? size : 1)) {
        r->failed = 1;
        return NULL;
    }
    void *p = malloc((size_t)n * size + 1);
    if (!p) {
        r->failed = 1;
        return NULL;
    }
    get(r, p, (size_t)n * size);
    if (count)
        *count = n;
    return p;
}

lmb_status lmb_plan_decode(const char *name, const uint8_t *bytes, size_t size, const lmb_scene *scene,
                           lmb_layout *l, lmb_error *err)
{
    memset(l, 0, sizeof *l);
    reader r = {bytes, size, 0};
    l->mesh_count = get_u32(&r);
    l->instance_count = get_u32(&r);
    l->atlas_count = get_u32(&r);
    l->chart_total = get_u32(&r);
    /* each mesh and instance takes at least 8 bytes: a count beyond that is damage, not memory */
    if (r.failed || (uint64_t)l->mesh_count + l->instance_count > size / 8)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: the plan's layout is damaged (counts)", name);
    if (l->mesh_count != scene->mesh_count || l->instance_count != scene->instance_count)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: the plan lays out %u meshes and %u instances; '%s' has %u and %u",
                             name, l->mesh_count, l->instance_count, scene->path, scene->mesh_count,
                             scene->instance_count);
    l->meshes = calloc((size_t)l->mesh_count + 1, sizeof *l->meshes);
    l->instances = calloc((size_t)l->instance_count + 1, sizeof *l->instances);
    if (!l->meshes || !l->instances)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", name);
    l->width = get_array(&r, l->atlas_count, sizeof *l->width, NULL);
    l->height = get_array(&r, l->atlas_count, sizeof *l->height, NULL);
    l->density.automatic = (int)get_u32(&r);
    l->density.scene_density = get_f64(&r);
    l->density.budget = get_u64(&r);
    l->density.capped = get_u32(&r);
    l->density.raised = get_u32(&r);
    l->density.short_of_floor = get_u32(&r);
    l->density.floor_share_min = get_f64(&r);
    l->density.texels = get_u64(&r);
    l->density.rounds = get_u32(&r);
    for (uint32_t m = 0; m < l->mesh_count && !r.failed; m++) {
        lmb_layout_mesh *lm = &l->meshes[m];
        lmb_mesh_soup *s = &lm->soup;
        lmb_charts *c = &lm->charts;
        lm->used = (int)get_u32(&r);
        lm->kept_uv1 = (int)get_u32(&r);
        s->vertex_count = get_u32(&r);
        s->triangle_count = get_u32(&r);
        s->positions = get_array(&r, 3 * (uint64_t)s->vertex_count, sizeof *s->positions, NULL);
        s->normals = get_array(&r, 3 * (uint64_t)s->vertex_count, sizeof *s->normals, NULL);
        s->indices = get_array(&r, 3 * (uint64_t)s->triangle_count, sizeof *s->indices, NULL);
        s->skip = get_array(&r, s->triangle_count, sizeof *s->skip, NULL);
        s->flat = get_array(&r, s->triangle_count, sizeof *s->flat, NULL);
        c->chart_count = get_u32(&r);
        c->triangle_count = get_u32(&r);
        c->chart_of = get_array(&r, c->triangle_count, sizeof *c->chart_of, NULL);
        c->uv = get_array(&r, 6 * (uint64_t)c->triangle_count, sizeof *c->uv, NULL);
        c->first = get_array(&r, (uint64_t)c->chart_count + 1, sizeof *c->first, NULL);
        c->order = get_array(&r, c->triangle_count, sizeof *c->order, NULL);
        c->planar_charts = get_u32(&r);
        c->splits = get_u32(&r);
        c->glued = get_u32(&r);
        get(&r, &c->topology, sizeof c->topology);
        /* indices must name vertices; chart offsets must stay inside `order` */
        for (uint64_t k = 0; s->indices && !r.failed && k < 3 * (uint64_t)s->triangle_count; k++)
            r.failed = s->indices[k] >= s->vertex_count;
        for (uint64_t k = 0; c->first && !r.failed && k <= c->chart_count; k++)
            r.failed = c->first[k] > c->triangle_count;
        /* chart numbers and the chart order must name charts and triangles */
        for (uint64_t k = 0; c->chart_of && !r.failed && k < c->triangle_count; k++)
            r.failed = c->chart_of[k] != UINT32_MAX && c->chart_of[k] >= c->chart_count;
        for (uint64_t k = 0; c->order && !r.failed && c->first && k < c->first[c->chart_count]; k++)
            r.failed = c->order[k] >= c->triangle_count;

    }
    l->block_count = r.failed ? 0 : get_u32(&r);
    r.failed |= (uint64_t)l->block_count > size / 8;
    l->blocks = r.failed ? NULL : calloc((size_t)l->block_count + 1, sizeof *l->blocks);
    if (!r.failed && !l->blocks)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "%s: out of memory", name);
    for (uint32_t b = 0; b < l->block_count && !r.failed; b++) {
        uint64_t n = 0;
        l->blocks[b].mesh = get_u32(&r);
        r.failed |= l->blocks[b].mesh >= l->mesh_count;
        l->blocks[b].uv = r.failed ? NULL : get_array(&r, ABSENT, sizeof *l->blocks[b].uv, &n);
        r.failed |= !l->blocks[b].uv ||
                    n != 6 * (uint64_t)l->meshes[l->blocks[b].mesh].soup.triangle_count ||
                    l->meshes[l->blocks[b].mesh].charts.triangle_count != l->meshes[l->blocks[b].mesh].soup.triangle_count ||
                    !l->meshes[l->blocks[b].mesh].charts.chart_of;
    }
    for (uint32_t i = 0; i < l->instance_count && !r.failed; i++) {
        lmb_layout_instance *in = &l->instances[i];
        uint32_t mesh_triangles = l->meshes[scene->instances[i].mesh].soup.triangle_count;
        uint32_t flags = get_u32(&r);
        in->lightmapped = (int)(flags & 1u);
        in->probe_lit = (int)(flags >> 1 & 1u);
        r.failed |= flags > 3 || (in->lightmapped && in->probe_lit);
        l->density.probe_lit += (uint32_t)in->probe_lit;
        in->atlas = get_u32(&r);
        in->texel_density = get_f64(&r);
        in->shared_layout = (int)get_u32(&r);
        for (int k = 0; k < 4; k++)
            in->scale_offset[k] = get_f64(&r);
        in->triangle_count = get_u32(&r);
        in->block = get_u32(&r);
        for (int k = 0; k < 4; k++)
            in->rect[k] = get_f64(&r);
        uint64_t n = 0;
        in->uv1 = get_array(&r, ABSENT, sizeof *in->uv1, &n);
        r.failed |= in->lightmapped && in->atlas >= l->atlas_count;
        r.failed |= (in->lightmapped || in->uv1) && in->triangle_count != mesh_triangles;
        r.failed |= in->uv1 && n != 6 * (uint64_t)in->triangle_count;
        /* a lightmapped instance's triangles are its uv1 or a block of its own mesh */
        r.failed |= in->lightmapped && !in->uv1 &&
                    (in->block >= l->block_count || l->blocks[in->block].mesh != scene->instances[i].mesh);
    }
    if (r.failed || r.left)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: the plan's layout is damaged (%s)", name,
                             r.failed ? "an array or index out of range" : "bytes after its end");
    return LMB_OK;
}
