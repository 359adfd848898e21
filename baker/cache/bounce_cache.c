/* The bounce cache (see bounce_cache.h). */
#include "bounce_cache.h"

#include "texels/dilate.h"
#include "util/lmb_math.h"
#include "util/mat4.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void lmb_cache_free(lmb_cache *c)
{
    for (uint32_t a = 0; a < c->atlas_count; a++) {
        if (c->irradiance)
            free(c->irradiance[a]);
        if (c->state)
            free(c->state[a]);
        if (c->direction)
            free(c->direction[a]);
        if (c->shadowmask)
            free(c->shadowmask[a]);
        if (c->sides)
            lmb_texel_sides_free(&c->sides[a]);
    }
    free(c->sides);
    free(c->irradiance);
    free(c->state);
    free(c->direction);
    free(c->shadowmask);
    memset(c, 0, sizeof *c);
}

lmb_status lmb_cache_init(lmb_cache *c, const lmb_scene *scene, const lmb_layout *layout, const lmb_rt *rt,
                          const lmb_textures *textures, lmb_error *err)
{
    memset(c, 0, sizeof *c);
    c->scene = scene;
    c->layout = layout;
    c->rt = rt;
    c->textures = textures;
    c->atlas_count = layout->atlas_count;
    for (uint32_t m = 0; m < scene->material_count; m++)
        c->diffuse_through |= scene->materials[m].diffuse_transmission > 0;
    c->irradiance = calloc((size_t)c->atlas_count + 1, sizeof *c->irradiance);
    c->state = calloc((size_t)c->atlas_count + 1, sizeof *c->state);
    c->sides = calloc((size_t)c->atlas_count + 1, sizeof *c->sides);
    if (!c->irradiance || !c->state || !c->sides)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "bounce cache: out of memory");
    for (uint32_t a = 0; a < c->atlas_count; a++) {
        size_t n = (size_t)layout->width[a] * layout->height[a];
        c->irradiance[a] = calloc(3 * n + 1, sizeof **c->irradiance);
        c->state[a] = calloc(n + 1, 1);
        if (!c->irradiance[a] || !c->state[a])
            return lmb_error_set(err, LMB_ERR_INTERNAL, "bounce cache: out of memory for atlas %u", a);
    }
    return LMB_OK;
}

/* img := e at t's texels (0 at invalid ones), st := their states; then dilated. */
static lmb_status scatter(float *img, uint8_t *st, uint32_t w, uint32_t h, const lmb_texels *t, const float *e,
                          int threads, lmb_error *err)
{
    memset(img, 0, (size_t)w * h * 3 * sizeof *img);
    memset(st, LMB_TEXEL_EMPTY, (size_t)w * h);
    for (uint32_t i = 0; i < t->count; i++) {
        st[t->texel[i]] = t->valid[i] ? LMB_TEXEL_VALID : LMB_TEXEL_INSIDE;
        for (int k = 0; k < 3; k++)
            img[3 * (size_t)t->texel[i] + k] = t->valid[i] ? e[3 * (size_t)i + k] : 0.0f;
    }
    return lmb_dilate(img, st, w, h, threads, err);
}

void lmb_cache_release(lmb_cache *c)
{
    for (uint32_t a = 0; a < c->atlas_count; a++) {
        free(c->irradiance[a]);
        c->irradiance[a] = NULL;
    }
}

lmb_status lmb_cache_store(lmb_cache *c, uint32_t a, const lmb_texels *t, const float *e, lmb_error *err)
{
    if (!c->sides[a].near && t->edge) {
        lmb_status st = lmb_texel_sides_build(&c->sides[a], t, c->rt, c->layout->width[a], c->layout->height[a],
                                              (int)c->threads, err);
        if (st != LMB_OK)
            return st;
    }
    if (!c->irradiance[a])
        c->irradiance[a] = malloc((3 * (size_t)c->layout->width[a] * c->layout->height[a] + 1) * sizeof **c->irradiance);
    if (!c->irradiance[a])
        return lmb_error_set(err, LMB_ERR_INTERNAL, "bounce cache: out of memory for atlas %u", a);
    return scatter(c->irradiance[a], c->state[a], c->layout->width[a], c->layout->height[a], t, e, (int)c->threads, err);
}

lmb_status lmb_cache_store_direction(lmb_cache *c, uint32_t a, const lmb_texels *t, const float *d, lmb_error *err)
{
    size_t n = (size_t)c->layout->width[a] * c->layout->height[a];
    if (!c->direction)
        c->direction = calloc((size_t)c->atlas_count + 1, sizeof *c->direction);
    if (c->direction && !c->direction[a])
        c->direction[a] = malloc((3 * n + 1) * sizeof **c->direction);
    uint8_t *st = malloc(n + 1);
    lmb_status s = c->direction && c->direction[a] && st
                       ? scatter(c->direction[a], st, c->layout->width[a], c->layout->height[a], t, d, (int)c->threads, err)
                       : lmb_error_set(err, LMB_ERR_INTERNAL, "bounce cache: out of memory for atlas %u's directions", a);
    free(st);
    return s;
}

/* Dilation works on 3 channels: the 4 visibilities go through it as (0, 1, 2) and (3, -, -). */
lmb_status lmb_cache_store_shadowmask(lmb_cache *c, uint32_t a, const lmb_texels *t, const float *v, lmb_error *err)
{
    uint32_t w = c->layout->width[a], h = c->layout->height[a];
    size_t n = (size_t)w * h;
    if (!c->shadowmask)
        c->shadowmask = calloc((size_t)c->atlas_count + 1, sizeof *c->shadowmask);
    if (c->shadowmask && !c->shadowmask[a])
        c->shadowmask[a] = malloc((4 * n + 1) * sizeof **c->shadowmask);
    float *img = malloc((3 * n + 1) * sizeof *img), *part = malloc((3 * (size_t)t->count + 1) * sizeof *part);
    uint8_t *st = malloc(n + 1);
    lmb_status s = c->shadowmask && c->shadowmask[a] && img && part && st
                       ? LMB_OK
                       : lmb_error_set(err, LMB_ERR_INTERNAL, "bounce cache: out of memory for atlas %u's shadowmask", a);
    for (int half = 0; half < 2 && s == LMB_OK; half++) {
        for (uint32_t i = 0; i < t->count; i++)
            for (int k = 0; k < 3; k++)
                part[3 * (size_t)i + k] = half == 0 ? v[4 * (size_t)i + k] : k == 0 ? v[4 * (size_t)i + 3] : 0.0f;
        s = scatter(img, st, w, h, t, part, (int)c->threads, err);
        for (size_t p = 0; p < n && s == LMB_OK; p++)
            for (int k = 0; k < (half ? 1 : 3); k++)
                c->shadowmask[a][4 * p + (half ? 3 : k)] = img[3 * p + k];
    }
    free(img);
    free(part);
    free(st);
    return s;
}

/* Diffuse albedo / pi of primitive pr's material at barycentrics (b1, b2) of triangle f, its
 * texture averaged over the footprint of a ray that met it at distance t (ray_spread) on
 * instance i. */
static void albedo_at(const lmb_cache *c, const lmb_primitive *pr, uint32_t f, double b1, double b2, double t,
                      uint32_t i, double out[3])
{
    if (pr->material < 0) { /* glTF default material: fully metallic, no diffuse, unless materials.default.albedo */
        for (int j = 0; j < 3; j++)
            out[j] = c->scene->default_albedo[j] * LMB_INV_PI;
        return;
    }
    double footprint = c->ray_spread > 0 && isfinite(t) ? t * c->ray_spread : 0;
    double scale = footprint > 0 ? cbrt(fabs(lmb_mat4_det3(c->scene->instances[i].world))) : 1.0;
    lmb_material_albedo_over(c->textures, &c->scene->materials[pr->material], pr, f, b1, b2, footprint, scale, out);
    for (int j = 0; j < 3; j++)
        out[j] *= LMB_INV_PI;
}

/* The 2 x 2 texels a bilinear lookup at atlas texel coordinates (x, y) reads (texel centres at
 * half integers, clamped to the atlas) and their weights. */
static void footprint(uint32_t w, uint32_t h, double x, double y, uint32_t texel[4], double weight[4])
{
    x -= 0.5;
    y -= 0.5;
    double fx = floor(x), fy = floor(y), ax = x - fx, ay = y - fy;
    long x0 = (long)fx, y0 = (long)fy;
    long xs[2] = {x0 < 0 ? 0 : x0 >= (long)w ? (long)w - 1 : x0, x0 + 1 < 0 ? 0 : x0 + 1 >= (long)w ? (long)w - 1 : x0 + 1};
    long ys[2] = {y0 < 0 ? 0 : y0 >= (long)h ? (long)h - 1 : y0, y0 + 1 < 0 ? 0 : y0 + 1 >= (long)h ? (long)h - 1 : y0 + 1};
    double wx[2] = {1 - ax, ax}, wy[2] = {1 - ay, ay};
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            texel[2 * j + i] = (uint32_t)((size_t)ys[j] * w + (size_t)xs[i]);
            weight[2 * j + i] = wx[i] * wy[j];
        }
}

/* The cached irradiance of the front at the hit (its lightmap, bilinear). Where the footprint
 * holds a texel beside a wall, texels across it and dilated ones weigh nothing and the others
 * are renormalised (texel_sides.h); none left: 0. */
static void front_light(const lmb_cache *c, const lmb_rt_geom *g, const lmb_rt_hit *hit, double e[3])
{
    const lmb_layout_instance *li = &c->layout->instances[g->instance];
    double uv[6];
    lmb_layout_uv(c->layout, g->instance, (size_t)g->first_triangle + hit->prim, uv);
    double b1 = hit->u, b2 = hit->v, b0 = 1.0 - b1 - b2;
    double x = b0 * uv[0] + b1 * uv[2] + b2 * uv[4], y = b0 * uv[1] + b1 * uv[3] + b2 * uv[5];
    uint32_t a = li->atlas, texel[4];
    double weight[4];
    footprint(c->layout->width[a], c->layout->height[a], x, y, texel, weight);
    const lmb_texel_sides *s = &c->sides[a];
    int beside = 0;
    for (int k = 0; k < 4 && s->near; k++)
        beside |= lmb_texel_sides_near(s, texel[k]);
    double sum = 0;
    if (beside)
        for (int k = 0; k < 4; k++) {
            if (weight[k] > 0 && (c->state[a][texel[k]] != LMB_TEXEL_VALID ||
                                  !lmb_texel_sides_in_sight(s, texel[k], hit->p)))
                weight[k] = 0;
            sum += weight[k];
        }
    e[0] = e[1] = e[2] = 0;
    if (beside && !(sum > 0))
        return;
    const float *img = c->irradiance[a];
    for (int k = 0; k < 4; k++)
        for (int ch = 0; ch < 3; ch++)
            e[ch] += weight[k] * img[3 * (size_t)texel[k] + ch];
    if (beside)
        for (int ch = 0; ch < 3; ch++)
            e[ch] /= sum;
}

lmb_hit_kind lmb_cache_lookup(const lmb_cache *c, const lmb_rt_hit *hit, double albedo_over_pi[3], double e[3])
{
    e[0] = e[1] = e[2] = 0;
    albedo_over_pi[0] = albedo_over_pi[1] = albedo_over_pi[2] = 0;
    const lmb_rt_geom *g = &c->rt->geoms[hit->geom];
    const lmb_primitive *pr = &c->scene->primitives[g->primitive];
    const lmb_material *m = pr->material >= 0 ? &c->scene->materials[pr->material] : NULL;
    const lmb_layout_instance *li = &c->layout->instances[g->instance];
    if (hit->backface) {
        int through = m && m->diffuse_transmission > 0;
        if (!through && (!c->backs_reflect || !m || !m->double_sided))
            return LMB_HIT_DARK;
        albedo_at(c, pr, hit->prim, hit->u, hit->v, hit->t, g->instance, albedo_over_pi);
        if (through && li->lightmapped) /* the front's light, which it lets through to the back */
            front_light(c, g, hit, e);
        return LMB_HIT_BACK;
    }
    albedo_at(c, pr, hit->prim, hit->u, hit->v, hit->t, g->instance, albedo_over_pi);
    if (!li->lightmapped)
        return LMB_HIT_UNMAPPED;
    front_light(c, g, hit, e);
    return LMB_HIT_CACHED;
}

double lmb_cache_diffuse_through(const lmb_cache *c, const lmb_rt_hit *hit, double out_over_pi[3])
{
    const lmb_primitive *pr = &c->scene->primitives[c->rt->geoms[hit->geom].primitive];
    const lmb_material *m = pr->material >= 0 ? &c->scene->materials[pr->material] : NULL;
    double f = m ? m->diffuse_transmission : 0.0;
    for (int k = 0; k < 3; k++)
        out_over_pi[k] = f > 0 ? f * m->diffuse_transmission_color[k] * LMB_INV_PI : 0.0;
    return f;
}
