/*
 * Direct irradiance (see direct.h). Formulas, E in lux at a point x with normal n:
 *   point:       E = I c cos(theta) / d^2 * W(d)            (KHR_lights_punctual: I in candela;
 *                W = clamp(1 - (d/range)^4, 0, 1)^2 when a range is given, as the spec suggests)
 *   spot:        the same times clamp((cos(a) - cos_o) / (cos_i - cos_o), 0, 1)^2 (the spec's
 *                smooth cone; a = angle to the spot axis)
 *   directional: E = E_sun c cos(theta)                     (intensity in lux; with lights.sun_angle
 *                a disc of that angular diameter: directions uniform in its cone, each
 *                E_sun c cos(theta) / mean cos over the cone, so E_sun is the illuminance at
 *                normal incidence)
 *   sky:         sky.c (map and cosine samples, multiple importance sampling)
 *   area:        E = sum over samples of L_e cos(theta_x) cos(theta_y) / d^2 / p_A(y) / N,
 *                triangles chosen in proportion to power (area x luminance), points uniform
 *                on the triangle: p_A(y) = P_tri / A_tri (area sampling; one-sided emitters
 *                unless the material is double-sided and lights.emission_sides is
 *                "material").
 * Every contribution needs an unoccluded shadow ray. A gather point whose hemisphere rays
 * (16, cosine-distributed) mostly hit back faces lies inside geometry and is not used;
 * a texel with no usable point is invalid and filled later by dilation.
 */
#include "direct.h"
#include "direct_internal.h"

#include "../util/frame.h"
#include "../util/lmb_math.h"
#include "../util/qmc.h"
#include "../util/rng.h"


#include <math.h>
#include <stdlib.h>
#include <string.h>

#define VALIDITY_RAYS 16
/* Up to this many point/spot lights are all evaluated at every point (exact, no noise);
 * beyond it, per point the lights that can reach it are evaluated, or samples.direct of them
 * drawn by their unshadowed irradiance there (local_lights), so the shadow rays do not grow
 * with the light count. Directional lights are always evaluated. */
#define EXACT_LOCAL_LIGHTS 8

const lmb_direct_options *lmb_direct_opts(const lmb_direct *d)
{
    return &d->opt;
}

const lmb_rt *lmb_direct_rt(const lmb_direct *d)
{
    return d->rt;
}

int lmb_direct_any_light(const lmb_direct *d)
{
    return (d->lights.local_count + d->lights.directional_count > 0 && d->opt.light_scale > 0) ||
           lmb_emitters_count(d->emitters) > 0 || d->sky != NULL;
}

int lmb_direct_has_sampled(const lmb_direct *d)
{
    return (d->lights.directional_count > 0 && d->opt.sun_angle > 0) || d->lights.local_count > EXACT_LOCAL_LIGHTS ||
           lmb_emitters_count(d->emitters) > 0 || d->sky != NULL;
}

int lmb_direct_has_deferred(const lmb_direct *d)
{
    return d->lights.indirect_count > 0;
}

uint32_t lmb_direct_shadowmask_channels(const lmb_direct *d)
{
    return d->lights.mask_channels;
}

/* Adds one light's contribution rgb, arriving from unit direction d, to e (and to c->dir); an
 * `indirect` light's also to c->deferred. */
static void add_light(point_ctx *c, const lmb_light *l, const double d[3], const double rgb[3], double e[3])
{
    double lum = lmb_luminance(rgb);
    int deferred = l && l->mode == LMB_LIGHT_INDIRECT;
    for (int k = 0; k < 3; k++) {
        e[k] += rgb[k];
        if (deferred)
            c->deferred[k] += rgb[k];
        else
            c->dir[k] += lum * d[k];
    }
}

int lmb_light_direction(const point_ctx *c, const lmb_light *l, double d[3], double *dist)
{
    *dist = 1e300;
    if (l->type == LMB_LIGHT_DIRECTIONAL) {
        for (int k = 0; k < 3; k++)
            d[k] = -l->direction[k];
        return 1;
    }
    for (int k = 0; k < 3; k++)
        d[k] = l->position[k] - c->p[k];
    *dist = sqrt(lmb_dot3(d, d));
    if (!(*dist > 0))
        return 0;
    for (int k = 0; k < 3; k++)
        d[k] /= *dist;
    return 1;
}

double lmb_punctual_falloff(const lmb_light *l, const double d[3], double dist)
{
    if (l->type == LMB_LIGHT_DIRECTIONAL)
        return 1.0;
    double w = 1.0 / (dist * dist);
    if (l->range > 0) {
        double r = dist / l->range, f = 1.0 - r * r * r * r;
        f = f < 0 ? 0 : f;
        w *= f * f;
    }
    if (l->type == LMB_LIGHT_SPOT) {
        double cd = -lmb_dot3(d, l->direction), co = cos(l->outer_cone), ci = cos(l->inner_cone);
        double t = (cd - co) / fmax(1e-3, ci - co);
        t = t < 0 ? 0 : (t > 1 ? 1 : t);
        w *= t * t;
    }
    return w;
}

/* Whether light l can reach c's point were nothing in the way: its unit direction d, distance,
 * cosine at the point and falloff (lmb_punctual_falloff), each > 0 when it can. */
static int punctual_reaches(const point_ctx *c, const lmb_light *l, double d[3], double *dist, double *cosang,
                            double *w)
{
    if (!lmb_light_direction(c, l, d, dist))
        return 0;
    *w = lmb_punctual_falloff(l, d, *dist);
    *cosang = lmb_dot3(c->n, d);
    return *w > 0 && *cosang > 0 && lmb_dot3(c->ng, d) > 0;
}

/* Adds the light's contribution times `weight` to e. */
static void punctual(point_ctx *c, const lmb_light *l, double weight, double e[3])
{
    double scale = c->d->opt.light_scale, d[3], dist, cosang, w;
    if (!punctual_reaches(c, l, d, &dist, &cosang, &w))
        return;
    c->rays++;
    double pass[3];
    if (lmb_rt_transmittance(c->d->rt, c->o, d, c->eps,
                             l->type == LMB_LIGHT_DIRECTIONAL ? 1e300 : dist * (1 - 1e-6) - c->eps, pass))
        return;
    double rgb[3];
    for (int k = 0; k < 3; k++)
        rgb[k] = weight * scale * l->intensity * l->color[k] * cosang * w * pass[k];
    add_light(c, l, d, rgb, e);
}

void lmb_sun_disc_init(double sun_angle, const lmb_light *l, lmb_sun_disc *disc)
{
    disc->cos_max = cos(0.5 * sun_angle * LMB_PI / 180.0);
    for (int k = 0; k < 3; k++)
        disc->axis[k] = -l->direction[k];
    lmb_frame(disc->axis, disc->t, disc->b);
}

void lmb_sun_disc_direction(const lmb_sun_disc *disc, double u1, double u2, double d[3])
{
    double ct = 1 - u1 * (1 - disc->cos_max), st = sqrt(fmax(0.0, 1 - ct * ct)), phi = 2 * LMB_PI * u2;
    for (int k = 0; k < 3; k++)
        d[k] = ct * disc->axis[k] + st * (cos(phi) * disc->t[k] + sin(phi) * disc->b[k]);
}

/* A directional light as a disc of angular diameter lights.sun_angle: c->samples directions
 * uniform in its cone (solid angle), each with a shadow ray, at scrambled Sobol points (a
 * stratified disc: its penumbrae converge faster than with independent directions). */
static void sun_disc(point_ctx *c, const lmb_light *l, uint32_t which, double e[3])
{
    lmb_sun_disc disc;
    lmb_sun_disc_init(c->d->opt.sun_angle, l, &disc);
    uint32_t n = c->samples;
    double scale = c->d->opt.light_scale * l->intensity / (0.5 * (1 + disc.cos_max)) / n;
    lmb_qmc_seq seq = lmb_qmc_sequence(lmb_mix64(c->sequence ^ (0x53554e00ull + which)));
    for (uint32_t s = 0; s < n; s++) {
        double u[2], d[3];
        lmb_qmc_point(&seq, c->first + s, u);
        lmb_sun_disc_direction(&disc, u[0], u[1], d);
        double cosang = lmb_dot3(c->n, d);
        if (cosang <= 0 || lmb_dot3(c->ng, d) <= 0)
            continue;
        c->rays++;
        double pass[3];
        if (lmb_rt_transmittance(c->d->rt, c->o, d, c->eps, 1e300, pass))
            continue;
        double rgb[3];
        for (int k = 0; k < 3; k++)
            rgb[k] = scale * l->color[k] * cosang * pass[k];
        add_light(c, l, d, rgb, e);
    }
}

/* A point or spot light's irradiance at c's point were nothing in the way (luminance, lux): what
 * the many-light sampler draws in proportion to. 0 exactly where the light cannot reach the
 * point (behind it, outside its range or cone), so drawing by it is unbiased. */
static double unshadowed_luminance(const point_ctx *c, const lmb_light *l)
{
    double d[3], dist, cosang, w;
    if (!punctual_reaches(c, l, d, &dist, &cosang, &w))
        return 0;
    return l->intensity * lmb_luminance_f(l->color) * cosang * w;
}

/* Point and spot lights: all of them when few (EXACT_LOCAL_LIGHTS), else the lights that can
 * reach the point, each with its unshadowed irradiance there (the shadow ray is then the only
 * noise left: Shirley, Wang and Zimmerman 1996, "Monte Carlo techniques for direct lighting
 * calculations", sec. 4): every one of them exactly when they are no more than the samples, else
 * c->samples drawn in proportion to it along a scrambled Sobol sequence (stratified picks). A
 * lamp's hot spot is then lit by that lamp in nearly every sample; drawn by power alone, a level
 * of ten lamps gave each hot spot a tenth of the samples and the quick look's texels 13% rms
 * noise after 9 x 9 averaging. Beyond MANY_LIGHTS_BY_CONTRIBUTION lights, the per-point pass
 * would cost more than the rays: the draws are by power. */
#define MANY_LIGHTS_BY_CONTRIBUTION 256

static void local_lights(point_ctx *c, lmb_rng *rng, double e[3])
{
    const light_set *ls = &c->d->lights;
    const lmb_light *all = c->d->scene->lights;
    uint32_t n = c->samples;
    if (ls->local_count <= EXACT_LOCAL_LIGHTS) {
        for (uint32_t i = 0; i < ls->local_count; i++)
            punctual(c, &all[ls->local[i]], 1.0, e);
        return;
    }
    if (ls->local_count > MANY_LIGHTS_BY_CONTRIBUTION) {
        for (uint32_t s = 0; s < n; s++) {
            double p;
            uint32_t k = lmb_cdf_pick(ls->cdf, ls->local_count, lmb_rng_next(rng), &p);
            punctual(c, &all[ls->local[k]], 1.0 / (p * n), e);
        }
        return;
    }
    double cdf[MANY_LIGHTS_BY_CONTRIBUTION + 1];
    uint32_t reach[MANY_LIGHTS_BY_CONTRIBUTION], m = 0;
    cdf[0] = 0;
    for (uint32_t i = 0; i < ls->local_count; i++) {
        double u = unshadowed_luminance(c, &all[ls->local[i]]);
        if (u > 0) {
            reach[m] = ls->local[i];
            cdf[m + 1] = cdf[m] + u;
            m++;
        }
    }
    if (m <= n) {
        for (uint32_t i = 0; i < m; i++)
            punctual(c, &all[reach[i]], 1.0, e);
        return;
    }
    lmb_qmc_seq seq = lmb_qmc_sequence(lmb_mix64(c->sequence ^ 0x4c4f43414cull));
    for (uint32_t s = 0; s < n; s++) {
        double u[2], p;
        lmb_qmc_point(&seq, c->first + s, u);
        uint32_t k = lmb_cdf_pick(cdf, m, u[0], &p);
        punctual(c, &all[reach[k]], 1.0 / (p * n), e);
    }
}

int lmb_emitter_radiance(const emitter *x, double b1, double b2, const double d[3], double *cos_y, double le[3])
{
    double cy = -lmb_dot3(x->n, d);
    if (x->two_sided)
        cy = fabs(cy);
    if (cy <= 0)
        return 0;
    float t[3] = {1, 1, 1};
    double b0 = 1 - b1 - b2;
    if (x->tex)
        lmb_texture_sample(x->tex, LMB_TEX_COLOUR, b0 * x->uv[0] + b1 * x->uv[2] + b2 * x->uv[4],
                           b0 * x->uv[1] + b1 * x->uv[3] + b2 * x->uv[5], t);
    for (int k = 0; k < 3; k++)
        le[k] = x->le[k] * t[k];
    *cos_y = cy;
    return 1;
}

/* Area lights by multiple importance sampling (Veach 1997, power heuristic with beta = 2 and
 * sample counts n_l, n_b: w_l = (n_l p_l)^2 / ((n_l p_l)^2 + (n_b p_b)^2); the balance heuristic
 * left 4x the variance under a disk light, where light sampling alone is nearly exact): n_l
 * points on emitters chosen by power (pdf in solid angle p_l = P(tri) / A_tri x d^2 / cos_y)
 * and n_b = n_l / COSINE_SHARE cosine-distributed directions (p_b = cos_x / pi) that count when
 * their first hit is an emitter. Light sampling alone has unbounded variance where an emitter
 * meets the surface (corners of an emissive room); the cosine rays cover it. They are a
 * quarter of the light samples: under a light that is small in the sky (a ceiling lamp) they
 * rarely hit it, and at one each they were half the rays for a few percent of the light.
 * Both techniques draw scrambled Sobol points (util/qmc.h): the light sample's first
 * coordinate picks the triangle and, rescaled to its share of the CDF, is reused for the
 * point on it, so the 2D points stay stratified over the lights' whole area. */
#define COSINE_SHARE 4

static void area_lights(point_ctx *c, double e[3])
{
    const lmb_emitters *es = c->d->emitters;
    uint32_t n = c->samples, m = (n + COSINE_SHARE - 1) / COSINE_SHARE;
    double total = es->cdf[es->count];
    lmb_qmc_seq light_seq = lmb_qmc_sequence(lmb_mix64(c->sequence ^ 0x41524541ull));
    lmb_qmc_seq cos_seq = lmb_qmc_sequence(lmb_mix64(c->sequence ^ 0x434f5300ull));
    for (uint32_t s = 0; s < n; s++) {
        /* light sample */
        double prob, u[2];
        lmb_qmc_point(&light_seq, c->first + s, u);
        uint32_t pick = lmb_emitter_pick(es, u[0], &prob);
        const emitter *x = &es->e[pick];
        double lo = es->cdf[pick] / total, u2 = prob > 0 ? (u[0] - lo) / prob : 0.5, u3 = u[1];
        u2 = u2 < 0 ? 0 : (u2 > 1 ? 1 : u2);
        double su = sqrt(u2), b1 = su * (1 - u3), b2 = su * u3, y[3], d[3], le[3], cy;
        for (int k = 0; k < 3; k++) {
            y[k] = (1 - b1 - b2) * x->p[k] + b1 * x->p[3 + k] + b2 * x->p[6 + k];
            d[k] = y[k] - c->p[k];
        }
        double dist2 = lmb_dot3(d, d), dist = sqrt(dist2);
        if (dist > 0) {
            for (int k = 0; k < 3; k++)
                d[k] /= dist;
            double cx = lmb_dot3(c->n, d);
            if (cx > 0 && lmb_dot3(c->ng, d) > 0 && lmb_emitter_radiance(x, b1, b2, d, &cy, le)) {
                c->rays++;
                double pass[3];
                if (!lmb_rt_transmittance(c->d->rt, c->o, d, c->eps, dist * (1 - 1e-4) - c->eps, pass)) {
                    double pl = prob / x->area * dist2 / cy, pb = cx * LMB_INV_PI;
                    double nl = n * pl, mb = m * pb;
                    double g = cx * nl / (nl * nl + mb * mb), rgb[3]; /* (cx / (n pl)) x power weight */
                    for (int k = 0; k < 3; k++)
                        rgb[k] = le[k] * g * pass[k];
                    add_light(c, NULL, d, rgb, e);
                }
            }
        }
    }
    for (uint32_t s = 0; s < m; s++) {
        /* cosine sample */
        double v[2], t1[3], t2[3], w[3];
        lmb_qmc_point(&cos_seq, c->first / n * m + s, v); /* round r: cosine points r m .. */
        double v1 = v[0], v2 = v[1];
        double r = sqrt(v1), phi = 2 * LMB_PI * v2, cz = sqrt(fmax(0, 1 - v1));
        lmb_frame(c->n, t1, t2);
        for (int k = 0; k < 3; k++)
            w[k] = r * cos(phi) * t1[k] + r * sin(phi) * t2[k] + cz * c->n[k];
        if (!(cz > 0) || lmb_dot3(c->ng, w) <= 0)
            continue;
        lmb_rt_hit h;
        lmb_rt_layer layers[LMB_RT_MAX_LAYERS];
        uint32_t nlayers;
        c->rays++;
        if (!lmb_rt_intersect_layers(c->d->rt, c->o, w, c->eps, 1e300, &h, layers, &nlayers))
            continue;
        double pass[3] = {1, 1, 1}; /* what the surfaces before the emitter let through */
        for (uint32_t j = 0; j < nlayers; j++)
            for (int k = 0; k < 3; k++)
                pass[k] *= layers[j].pass[k];
        const uint32_t *map = c->d->emitter_of[h.geom];
        uint32_t k1 = map ? map[h.prim] : 0;
        if (!k1)
            continue;
        const emitter *x = &es->e[k1 - 1];
        double le[3], cy;
        if (!lmb_emitter_radiance(x, h.u, h.v, w, &cy, le))
            continue;
        double pt = (es->cdf[k1] - es->cdf[k1 - 1]) / total;
        double pl = pt / x->area * h.t * h.t / cy, pb = cz * LMB_INV_PI;
        double nl = n * pl, mb = m * pb;
        double g = cz * mb / (nl * nl + mb * mb), rgb[3]; /* (cz / (m pb)) x power weight */
        for (int k = 0; k < 3; k++)
            rgb[k] = le[k] * g * pass[k];
        add_light(c, NULL, w, rgb, e);
    }
}

/* How many of VALIDITY_RAYS hemisphere rays hit back faces (inside geometry: more than half);
 * *nearest: the closest hit's distance (INFINITY: none). */
static int back_face_hits(point_ctx *c, lmb_rng *rng, double *nearest)
{
    double t1[3], t2[3], a[3] = {fabs(c->ng[0]) < 0.9 ? 1 : 0, fabs(c->ng[0]) < 0.9 ? 0 : 1, 0};
    t1[0] = a[1] * c->ng[2] - a[2] * c->ng[1];
    t1[1] = a[2] * c->ng[0] - a[0] * c->ng[2];
    t1[2] = a[0] * c->ng[1] - a[1] * c->ng[0];
    double l = sqrt(lmb_dot3(t1, t1));
    for (int k = 0; k < 3; k++)
        t1[k] /= l;
    t2[0] = c->ng[1] * t1[2] - c->ng[2] * t1[1];
    t2[1] = c->ng[2] * t1[0] - c->ng[0] * t1[2];
    t2[2] = c->ng[0] * t1[1] - c->ng[1] * t1[0];
    int back = 0;
    *nearest = INFINITY;
    for (int r = 0; r < VALIDITY_RAYS; r++) {
        double u1 = lmb_rng_next(rng), u2 = lmb_rng_next(rng), rr = sqrt(u1), phi = 2 * LMB_PI * u2;
        double x = rr * cos(phi), y = rr * sin(phi), z = sqrt(fmax(0, 1 - u1)), d[3];
        for (int k = 0; k < 3; k++)
            d[k] = x * t1[k] + y * t2[k] + z * c->ng[k];
        lmb_rt_hit h;
        c->rays++;
        if (lmb_rt_intersect(c->d->rt, c->o, d, c->eps, 1e300, &h)) {
            back += h.backface;
            *nearest = h.t < *nearest ? h.t : *nearest;
        }
    }
    return back;
}

void lmb_point_init(point_ctx *c, const lmb_direct *d, const lmb_shading_point *sp)
{
    memset(c, 0, sizeof *c);
    c->d = d;
    for (int k = 0; k < 3; k++) {
        c->p[k] = sp->p[k];
        c->n[k] = sp->n[k];
        c->ng[k] = sp->ng[k];
        c->o[k] = sp->p[k] + sp->ng[k] * sp->eps;
    }
    c->eps = sp->eps;
}

uint32_t lmb_direct_at(const lmb_direct *d, const lmb_shading_point *sp, uint32_t samples, lmb_rng *rng, double e[3],
                       double dir[3])
{
    return lmb_direct_at_split(d, sp, samples, rng, e, dir, NULL);
}

uint32_t lmb_direct_at_split(const lmb_direct *d, const lmb_shading_point *sp, uint32_t samples, lmb_rng *rng,
                             double e[3], double dir[3], double deferred[3])
{
    /* one draw at the start of the caller's stream: its QMC points are scrambled by the stream */
    lmb_direct_draw draw = {LMB_DIRECT_ALL, samples, samples, lmb_mix64(rng->key ^ rng->counter), 0};
    return lmb_direct_eval(d, sp, &draw, rng, e, dir, deferred);
}

uint32_t lmb_direct_eval(const lmb_direct *d, const lmb_shading_point *sp, const lmb_direct_draw *draw, lmb_rng *rng,
                         double e[3], double dir[3], double deferred[3])
{
    point_ctx c;
    lmb_point_init(&c, d, sp);
    c.samples = draw->samples ? draw->samples : d->opt.samples;
    c.sequence = draw->sequence;
    c.first = draw->first;
    int exact = (draw->parts & LMB_DIRECT_EXACT) != 0, sampled = (draw->parts & LMB_DIRECT_SAMPLED) != 0;
    e[0] = e[1] = e[2] = 0;
    for (uint32_t l = 0; l < d->lights.directional_count; l++) {
        const lmb_light *sun = &d->scene->lights[d->lights.directional[l]];
        if (d->opt.sun_angle > 0 && sampled)
            sun_disc(&c, sun, l, e);
        else if (d->opt.sun_angle <= 0 && exact)
            punctual(&c, sun, 1.0, e);
    }
    if (d->lights.local_count <= EXACT_LOCAL_LIGHTS ? exact : sampled)
        local_lights(&c, rng, e);
    if (lmb_emitters_count(d->emitters) && sampled)
        area_lights(&c, e);
    if (d->sky && sampled)
        c.rays += lmb_sky_irradiance(d->sky, d->rt, c.o, c.n, c.ng, c.eps,
                                     draw->sky_samples ? draw->sky_samples : d->opt.sky_samples, rng, e, c.dir);
    if (dir)
        memcpy(dir, c.dir, sizeof c.dir);
    if (deferred)
        memcpy(deferred, c.deferred, sizeof c.deferred);
    return (uint32_t)c.rays;
}

int lmb_point_inside_geometry(const lmb_direct *d, const lmb_shading_point *sp, uint32_t atlas, uint32_t texel,
                              uint32_t k, lmb_rng *rng, uint32_t *rays, lmb_point_sight *sight)
{
    const lmb_point_validity *v = d->validity;
    uint8_t *memo = NULL;
    if (v && atlas < v->atlas_count && k < v->samples && ((uint64_t)texel + 1) * v->samples <= v->size[atlas])
        memo = &v->entry[atlas][(uint64_t)texel * v->samples + k];
    if (memo && *memo != LMB_VALIDITY_UNKNOWN) {
        rng->counter += 2 * VALIDITY_RAYS; /* the draws back_face_hits takes */
        uint8_t state = *memo & LMB_VALIDITY_STATE;
        sight->sees_back = state != LMB_VALIDITY_CLEAR;
        sight->near = (*memo & LMB_VALIDITY_NEAR) != 0;
        return state == LMB_VALIDITY_INSIDE;
    }
    point_ctx c;
    lmb_point_init(&c, d, sp);
    double nearest;
    int back = back_face_hits(&c, rng, &nearest);
    *rays += (uint32_t)c.rays;
    sight->sees_back = back > 0;
    sight->near = nearest <= sight->near_range;
    int inside = 2 * back > VALIDITY_RAYS;
    if (memo) /* one thread owns a texel's points */
        *memo = (uint8_t)((inside ? LMB_VALIDITY_INSIDE : back ? LMB_VALIDITY_NEAR_BACK : LMB_VALIDITY_CLEAR) |
                          (sight->near ? LMB_VALIDITY_NEAR : 0));
    return inside;
}

void lmb_direct_set_validity(lmb_direct *d, struct lmb_point_validity *validity)
{
    d->validity = validity;
}

void lmb_texel_shading_point(const lmb_direct *d, const lmb_texels *t, uint32_t i, uint32_t k, lmb_shading_point *sp)
{
    lmb_gather_point g;
    lmb_texels_point(t, i, k, &g);
    for (int r = 0; r < 3; r++) {
        sp->p[r] = g.p[r];
        sp->n[r] = g.n[r];
        sp->ng[r] = g.ng[r];
    }
    sp->eps = d->rt->eps + 1e-4 * t->texel_size[i];
}

int lmb_texel_point_cut(const lmb_direct *d, const lmb_texels *t, uint32_t i, uint32_t k)
{
    if (!d->rt->cut_geoms || !t->refs)
        return 0;
    const lmb_point_ref *r = &t->refs[(size_t)i * t->samples + k];
    return lmb_rt_triangle_cut(d->rt, d->scene, r->instance, r->triangle, r->b1, r->b2);
}

/* Splits the scene's lights into directional and local, with the local lights' power CDF
 * (power ~ 4 pi I for a point light, 2 pi (1 - cos outer) I for a spot, times luminance). */
static int light_set_build(const lmb_scene *s, light_set *ls)
{
    memset(ls, 0, sizeof *ls);
    ls->local = malloc(((size_t)s->light_count + 1) * sizeof *ls->local);
    ls->directional = malloc(((size_t)s->light_count + 1) * sizeof *ls->directional);
    ls->cdf = malloc(((size_t)s->light_count + 2) * sizeof *ls->cdf);
    if (!ls->local || !ls->directional || !ls->cdf)
        return 0;
    ls->cdf[0] = 0;
    for (int k = 0; k < LMB_SHADOWMASK_CHANNELS; k++)
        ls->mask_light[k] = -1;
    for (uint32_t i = 0; i < s->light_count; i++) {
        const lmb_light *l = &s->lights[i];
        if (l->mode == LMB_LIGHT_REALTIME) /* not in the bake */
            continue;
        ls->indirect_count += l->mode == LMB_LIGHT_INDIRECT;
        if (l->shadowmask_channel >= 0 && l->shadowmask_channel < LMB_SHADOWMASK_CHANNELS) {
            ls->mask_light[l->shadowmask_channel] = (int)i;
            ls->mask_channels = (uint32_t)l->shadowmask_channel + 1 > ls->mask_channels ? (uint32_t)l->shadowmask_channel + 1
                                                                                        : ls->mask_channels;
        }
        if (l->type == LMB_LIGHT_DIRECTIONAL) {
            ls->directional[ls->directional_count++] = i;
            continue;
        }
        double lum = 0.2126 * l->color[0] + 0.7152 * l->color[1] + 0.0722 * l->color[2];
        double solid = l->type == LMB_LIGHT_SPOT ? 2 * LMB_PI * (1 - cos(l->outer_cone)) : 4 * LMB_PI;
        ls->local[ls->local_count] = i;
        ls->cdf[ls->local_count + 1] = ls->cdf[ls->local_count] + fmax(1e-12, l->intensity * lum * solid);
        ls->local_count++;
    }
    return 1;
}

static void light_set_free(light_set *ls)
{
    free(ls->local);
    free(ls->directional);
    free(ls->cdf);
}

lmb_status lmb_direct_create(const lmb_scene *scene, const lmb_direct_options *opt, const lmb_rt *rt,
                             const lmb_emitters *emitters, const lmb_sky *sky, lmb_direct **out, lmb_error *err)
{
    lmb_direct *d = calloc(1, sizeof *d);
    if (!d || !light_set_build(scene, &d->lights)) {
        if (d)
            light_set_free(&d->lights);
        free(d);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "direct: out of memory");
    }
    d->scene = scene;
    d->opt = *opt;
    d->rt = rt;
    d->emitters = emitters;
    d->sky = sky;
    d->emitter_of = calloc((size_t)rt->geom_count + 1, sizeof *d->emitter_of);
    lmb_status st = d->emitter_of ? LMB_OK : LMB_ERR_INTERNAL;
    /* emitters come grouped by (instance, primitive); geometries in the same order */
    uint32_t g = 0;
    for (uint32_t k = 0; st == LMB_OK && emitters && k < emitters->count; k++) {
        const emitter *x = &emitters->e[k];
        while (g < rt->geom_count && (rt->geoms[g].instance != x->instance || rt->geoms[g].primitive != x->primitive))
            g++;
        if (g == rt->geom_count) {
            st = LMB_ERR_INTERNAL;
            break;
        }
        if (!d->emitter_of[g]) {
            d->emitter_of[g] = calloc((size_t)scene->primitives[x->primitive].triangle_count + 1, sizeof **d->emitter_of);
            if (!d->emitter_of[g]) {
                st = LMB_ERR_INTERNAL;
                break;
            }
        }
        d->emitter_of[g][x->triangle] = k + 1;
    }
    if (st != LMB_OK) {
        lmb_direct_free(d);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "direct: out of memory (emitter map)");
    }
    *out = d;
    return LMB_OK;
}

void lmb_direct_free(lmb_direct *d)
{
    if (!d)
        return;
    light_set_free(&d->lights);
    for (uint32_t g = 0; d->emitter_of && g < d->rt->geom_count; g++)
        free(d->emitter_of[g]);
    free(d->emitter_of);
    free(d);
}
