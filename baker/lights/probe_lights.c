/*
 * What a light probe needs of the lights (probes/probe_light.c): a probe records the radiance
 * arriving from every direction, so delta lights (point, spot, directional) are given as a
 * direction and the irradiance they bring to a surface facing them, and emitters by points
 * sampled on them. Bake modes as for texels: `realtime` lights are not in
 * the light set at all; `indirect` lights give no direct light here (their bounced light comes
 * from the surfaces the cache lights).
 */
#include "direct.h"
#include "direct_internal.h"

#include "../util/lmb_math.h"
#include "../util/frame.h"

#include <math.h>

uint32_t lmb_direct_deltas_at(const lmb_direct *d, const double p[3], lmb_delta_fn fn, void *user)
{
    const light_set *ls = &d->lights;
    const lmb_light *all = d->scene->lights;
    uint32_t rays = 0, count = ls->local_count + ls->directional_count;
    for (uint32_t i = 0; i < count; i++) {
        const lmb_light *l = &all[i < ls->local_count ? ls->local[i] : ls->directional[i - ls->local_count]];
        if (l->mode != LMB_LIGHT_BAKED)
            continue;
        point_ctx c;
        lmb_shading_point sp = {{p[0], p[1], p[2]}, {0, 1, 0}, {0, 1, 0}, 0};
        lmb_point_init(&c, d, &sp);
        double dir[3], dist;
        if (!lmb_light_direction(&c, l, dir, &dist))
            continue;
        double w = lmb_punctual_falloff(l, dir, dist) * d->opt.light_scale * l->intensity;
        if (!(w > 0))
            continue;
        rays++;
        double pass[3];
        if (lmb_rt_transmittance(d->rt, p, dir, d->rt->eps, l->type == LMB_LIGHT_DIRECTIONAL ? 1e300 : dist * (1 - 1e-6),
                                 pass))
            continue;
        double e[3] = {w * l->color[0] * pass[0], w * l->color[1] * pass[1], w * l->color[2] * pass[2]};
        fn(user, dir, e);
    }
    return rays;
}

uint32_t lmb_direct_emitter_samples_at(const lmb_direct *d, const double p[3], uint32_t samples, lmb_rng *rng,
                                       lmb_delta_fn fn, void *user)
{
    const lmb_emitters *es = d->emitters;
    if (!es || !es->count || !samples)
        return 0;
    uint32_t rays = 0;
    for (uint32_t s = 0; s < samples; s++) {
        double prob, u1 = lmb_rng_next(rng), u2 = lmb_rng_next(rng), u3 = lmb_rng_next(rng);
        const emitter *x = &es->e[lmb_emitter_pick(es, u1, &prob)];
        double su = sqrt(u2), b1 = su * (1 - u3), b2 = su * u3, w[3], le[3], cy;
        for (int k = 0; k < 3; k++)
            w[k] = (1 - b1 - b2) * x->p[k] + b1 * x->p[3 + k] + b2 * x->p[6 + k] - p[k];
        double dist2 = lmb_dot3(w, w), dist = sqrt(dist2);
        if (!(dist > 0) || !(prob > 0))
            continue;
        for (int k = 0; k < 3; k++)
            w[k] /= dist;
        if (!lmb_emitter_radiance(x, b1, b2, w, &cy, le))
            continue;
        rays++;
        double pass[3];
        if (lmb_rt_transmittance(d->rt, p, w, d->rt->eps, dist * (1 - 1e-4), pass))
            continue;
        double weight = x->area * cy / (prob * dist2 * samples), e[3]; /* 1 / (pdf in solid angle x samples) */
        for (int k = 0; k < 3; k++)
            e[k] = le[k] * weight * pass[k];
        fn(user, w, e);
    }
    return rays;
}

const lmb_sky *lmb_direct_sky(const lmb_direct *d)
{
    return d->sky;
}
