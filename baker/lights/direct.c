/*
 * Direct irradiance (see direct.h). Formulas, E in lux at a point x with normal n:
 *   point:       E = I c cos(theta) / d^2 * W(d)            (KHR_lights_punctual: I in candela;
 *                W = clamp(1 - (d/range)^4, 0, 1)^2 when a range is given, as the spec suggests)
 *   spot:        the same times clamp((cos(a) - cos_o) / (cos_i - cos_o), 0, 1)^2 (the spec's
 *                smooth cone; a = angle to the spot axis)
 *   directional: E = E_sun c cos(theta)                     (intensity in lux)
 *   area:        E = sum over samples of L_e cos(theta_x) cos(theta_y) / d^2 / p_A(y) / N,
 *                triangles chosen in proportion to power (area x luminance), points uniform
 *                on the triangle: p_A(y) = P_tri / A_tri (area sampling; one-sided emitters
 *                unless the material is double-sided).
 * Every contribution needs an unoccluded shadow ray. A gather point whose hemisphere rays
 * (16, cosine-distributed) mostly hit back faces lies inside geometry and is not used;
 * a texel with no usable point is invalid and filled later by dilation.
 */
#include "direct.h"

#include "../util/lmb_math.h"
#include "../util/rng.h"

#include <omp.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define VALIDITY_RAYS 16

typedef struct emitter {
    double p[9];   /* world corners */
    double n[3];   /* unit front normal */
    double area;
    float le[3];   /* radiance, nits */
    int two_sided;
} emitter;

struct lmb_emitters {
    emitter *e;
    double *cdf; /* count + 1 */
    uint32_t count;
};

uint32_t lmb_emitters_count(const lmb_emitters *e)
{
    return e ? e->count : 0;
}

void lmb_emitters_free(lmb_emitters *e)
{
    if (!e)
        return;
    free(e->e);
    free(e->cdf);
    free(e);
}

static lmb_status add_emitter(lmb_emitters *es, uint32_t *cap, const emitter *x, lmb_error *err)
{
    if (es->count == *cap) {
        uint32_t c = *cap ? 2 * *cap : 64;
        emitter *n = realloc(es->e, (size_t)c * sizeof *n);
        if (!n)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "emitters: out of memory");
        es->e = n;
        *cap = c;
    }
    es->e[es->count++] = *x;
    return LMB_OK;
}

static void world_point(const double m[16], const float *p, double *out)
{
    for (int r = 0; r < 3; r++)
        out[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
}

lmb_status lmb_emitters_build(const lmb_scene *s, const lmb_config *cfg, lmb_emitters **out, lmb_error *err)
{
    lmb_emitters *es = calloc(1, sizeof *es);
    uint32_t cap = 0;
    lmb_status st = es ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "emitters: out of memory");
    for (uint32_t i = 0; st == LMB_OK && i < s->instance_count; i++) {
        const lmb_instance *in = &s->instances[i];
        const lmb_mesh *m = &s->meshes[in->mesh];
        for (uint32_t p = 0; st == LMB_OK && p < m->primitive_count; p++) {
            const lmb_primitive *pr = &s->primitives[m->first_primitive + p];
            if (pr->material < 0 || !lmb_material_is_emissive(&s->materials[pr->material]))
                continue;
            const lmb_material *mat = &s->materials[pr->material];
            for (uint32_t f = 0; st == LMB_OK && f < pr->triangle_count; f++) {
                if (pr->degenerate[f])
                    continue;
                emitter x;
                for (int k = 0; k < 3; k++)
                    world_point(in->world, pr->positions + 3 * pr->indices[3 * f + k], x.p + 3 * k);
                double e1[3] = {x.p[3] - x.p[0], x.p[4] - x.p[1], x.p[5] - x.p[2]};
                double e2[3] = {x.p[6] - x.p[0], x.p[7] - x.p[1], x.p[8] - x.p[2]};
                double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
                double len = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
                if (!(len > 0))
                    continue;
                for (int k = 0; k < 3; k++)
                    x.n[k] = (in->flips_winding ? -c[k] : c[k]) / len;
                x.area = 0.5 * len;
                for (int k = 0; k < 3; k++)
                    x.le[k] = (float)(mat->emissive[k] * cfg->emissive_scale);
                x.two_sided = mat->double_sided;
                st = add_emitter(es, &cap, &x, err);
            }
        }
    }
    if (st == LMB_OK) {
        es->cdf = malloc(((size_t)es->count + 1) * sizeof *es->cdf);
        if (!es->cdf)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "emitters: out of memory");
    }
    if (st != LMB_OK) {
        lmb_emitters_free(es);
        return st;
    }
    double acc = 0;
    es->cdf[0] = 0;
    for (uint32_t k = 0; k < es->count; k++) {
        const emitter *x = &es->e[k];
        double lum = 0.2126 * x->le[0] + 0.7152 * x->le[1] + 0.0722 * x->le[2];
        acc += x->area * (lum > 0 ? lum : 1e-12) * (x->two_sided ? 2 : 1);
        es->cdf[k + 1] = acc;
    }
    *out = es;
    return LMB_OK;
}

static uint32_t pick(const lmb_emitters *es, double u, double *prob)
{
    double target = u * es->cdf[es->count];
    uint32_t lo = 0, hi = es->count - 1;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (es->cdf[mid + 1] <= target)
            lo = mid + 1;
        else
            hi = mid;
    }
    *prob = (es->cdf[lo + 1] - es->cdf[lo]) / es->cdf[es->count];
    return lo;
}

typedef struct point_ctx {
    const lmb_direct_job *job;
    double o[3];    /* offset origin */
    double p[3], n[3], ng[3];
    double eps;
    uint64_t rays;
} point_ctx;

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void punctual(point_ctx *c, const lmb_light *l, double e[3])
{
    double scale = c->job->cfg->light_intensity_scale, d[3], dist = 1e300, cosang, w = 1.0;
    if (l->type == LMB_LIGHT_DIRECTIONAL) {
        for (int k = 0; k < 3; k++)
            d[k] = -l->direction[k];
    } else {
        for (int k = 0; k < 3; k++)
            d[k] = l->position[k] - c->p[k];
        dist = sqrt(dot3(d, d));
        if (!(dist > 0))
            return;
        for (int k = 0; k < 3; k++)
            d[k] /= dist;
        w = 1.0 / (dist * dist);
        if (l->range > 0) {
            double r = dist / l->range, f = 1.0 - r * r * r * r;
            f = f < 0 ? 0 : f;
            w *= f * f;
        }
        if (l->type == LMB_LIGHT_SPOT) {
            double cd = -dot3(d, l->direction), co = cos(l->outer_cone), ci = cos(l->inner_cone);
            double t = (cd - co) / fmax(1e-3, ci - co);
            t = t < 0 ? 0 : (t > 1 ? 1 : t);
            w *= t * t;
        }
    }
    cosang = dot3(c->n, d);
    if (w <= 0 || cosang <= 0 || dot3(c->ng, d) <= 0)
        return;
    c->rays++;
    if (lmb_rt_occluded(c->job->rt, c->o, d, c->eps, l->type == LMB_LIGHT_DIRECTIONAL ? 1e300 : dist * (1 - 1e-6) - c->eps))
        return;
    for (int k = 0; k < 3; k++)
        e[k] += scale * l->intensity * l->color[k] * cosang * w;
}

static void area_lights(point_ctx *c, lmb_rng *rng, double e[3])
{
    const lmb_emitters *es = c->job->emitters;
    uint32_t n = c->job->cfg->direct_samples;
    for (uint32_t s = 0; s < n; s++) {
        double prob, u1 = lmb_rng_next(rng), u2 = lmb_rng_next(rng), u3 = lmb_rng_next(rng);
        const emitter *x = &es->e[pick(es, u1, &prob)];
        double su = sqrt(u2), b0 = 1 - su, b1 = su * (1 - u3), b2 = su * u3, y[3], d[3];
        for (int k = 0; k < 3; k++) {
            y[k] = b0 * x->p[k] + b1 * x->p[3 + k] + b2 * x->p[6 + k];
            d[k] = y[k] - c->p[k];
        }
        double dist2 = dot3(d, d), dist = sqrt(dist2);
        if (!(dist > 0))
            continue;
        for (int k = 0; k < 3; k++)
            d[k] /= dist;
        double cx = dot3(c->n, d), cy = -dot3(x->n, d);
        if (x->two_sided)
            cy = fabs(cy);
        if (cx <= 0 || cy <= 0 || dot3(c->ng, d) <= 0)
            continue;
        c->rays++;
        if (lmb_rt_occluded(c->job->rt, c->o, d, c->eps, dist * (1 - 1e-4) - c->eps))
            continue;
        double g = cx * cy / dist2 * x->area / prob / n;
        for (int k = 0; k < 3; k++)
            e[k] += x->le[k] * g;
    }
}

/* Inside geometry: more than half of the hemisphere rays hit back faces. */
static int inside_geometry(point_ctx *c, lmb_rng *rng)
{
    double t1[3], t2[3], a[3] = {fabs(c->ng[0]) < 0.9 ? 1 : 0, fabs(c->ng[0]) < 0.9 ? 0 : 1, 0};
    t1[0] = a[1] * c->ng[2] - a[2] * c->ng[1];
    t1[1] = a[2] * c->ng[0] - a[0] * c->ng[2];
    t1[2] = a[0] * c->ng[1] - a[1] * c->ng[0];
    double l = sqrt(dot3(t1, t1));
    for (int k = 0; k < 3; k++)
        t1[k] /= l;
    t2[0] = c->ng[1] * t1[2] - c->ng[2] * t1[1];
    t2[1] = c->ng[2] * t1[0] - c->ng[0] * t1[2];
    t2[2] = c->ng[0] * t1[1] - c->ng[1] * t1[0];
    int back = 0;
    for (int r = 0; r < VALIDITY_RAYS; r++) {
        double u1 = lmb_rng_next(rng), u2 = lmb_rng_next(rng), rr = sqrt(u1), phi = 2 * LMB_PI * u2;
        double x = rr * cos(phi), y = rr * sin(phi), z = sqrt(fmax(0, 1 - u1)), d[3];
        for (int k = 0; k < 3; k++)
            d[k] = x * t1[k] + y * t2[k] + z * c->ng[k];
        lmb_rt_hit h;
        c->rays++;
        if (lmb_rt_intersect(c->job->rt, c->o, d, c->eps, 1e300, &h) && h.backface)
            back++;
    }
    return 2 * back > VALIDITY_RAYS;
}

static void texel_direct(const lmb_direct_job *job, lmb_texels *t, uint32_t i, float *out, uint64_t *rays)
{
    double sum[3] = {0, 0, 0};
    uint32_t used = 0;
    uint64_t key = ((uint64_t)job->atlas << 32) | t->texel[i];
    point_ctx c;
    memset(&c, 0, sizeof c);
    c.job = job;
    for (uint32_t k = 0; k < t->points_in[i]; k++) {
        const lmb_gather_point *g = &t->points[(size_t)i * t->samples + k];
        lmb_rng rng = lmb_rng_make(job->cfg->seed, key, k);
        for (int d = 0; d < 3; d++) {
            c.p[d] = g->p[d];
            c.n[d] = g->n[d];
            c.ng[d] = g->ng[d];
        }
        c.eps = job->rt->eps + 1e-4 * t->texel_size[i];
        for (int d = 0; d < 3; d++)
            c.o[d] = c.p[d] + c.ng[d] * c.eps;
        if (inside_geometry(&c, &rng))
            continue;
        double e[3] = {0, 0, 0};
        for (uint32_t l = 0; l < job->scene->light_count; l++)
            punctual(&c, &job->scene->lights[l], e);
        if (lmb_emitters_count(job->emitters))
            area_lights(&c, &rng, e);
        for (int d = 0; d < 3; d++)
            sum[d] += e[d];
        used++;
    }
    t->valid[i] = used > 0;
    for (int d = 0; d < 3; d++)
        out[3 * i + d] = used ? (float)(sum[d] / used) : 0.0f;
    *rays += c.rays;
}

lmb_status lmb_direct_compute(const lmb_direct_job *job, lmb_texels *t, float *irradiance, uint64_t *rays, lmb_error *err)
{
    (void)err;
    const uint32_t block = 1024;
    uint64_t total = 0;
    int threads = job->cfg->threads ? (int)job->cfg->threads : 0;
    for (uint32_t start = 0; start < t->count; start += block) {
        uint32_t end = start + block < t->count ? start + block : t->count;
        uint64_t block_rays = 0;
#pragma omp parallel num_threads(threads ? threads : omp_get_max_threads()) reduction(+ : block_rays)
        {
            lmb_rt_thread_init();
#pragma omp for schedule(dynamic, 16)
            for (uint32_t i = start; i < end; i++)
                texel_direct(job, t, i, irradiance, &block_rays);
        }
        total += block_rays;
        if (job->progress)
            job->progress(job->progress_user, "direct", end, t->count);
    }
    *rays += total;
    return LMB_OK;
}
