/*
 * What a light probe needs of the lights (probes/probe_light.c): a probe records the radiance
 * arriving from every direction, so delta lights (point, spot, directional) are given as a
 * direction and the irradiance they bring to a surface facing them, and emitters as the
 * radiance a ray that hits them sees. Bake modes as for texels: `realtime` lights are not in
 * the light set at all; `indirect` lights give no direct light here (their bounced light comes
 * from the surfaces the cache lights).
 */
#include "direct.h"
#include "direct_internal.h"

#include "../util/lmb_math.h"

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
        double w = lmb_punctual_falloff(l, dir, dist) * d->cfg->light_intensity_scale * l->intensity;
        if (!(w > 0))
            continue;
        rays++;
        if (lmb_rt_occluded(d->rt, p, dir, d->rt->eps, l->type == LMB_LIGHT_DIRECTIONAL ? 1e300 : dist * (1 - 1e-6)))
            continue;
        double e[3] = {w * l->color[0], w * l->color[1], w * l->color[2]};
        fn(user, dir, e);
    }
    return rays;
}

int lmb_direct_emitted_at_hit(const lmb_direct *d, const lmb_rt_hit *h, const double w[3], double le[3])
{
    const uint32_t *map = d->emitter_of ? d->emitter_of[h->geom] : NULL;
    uint32_t k1 = map ? map[h->prim] : 0;
    double cy;
    le[0] = le[1] = le[2] = 0;
    return k1 && lmb_emitter_radiance(&d->emitters->e[k1 - 1], h->u, h->v, w, &cy, le);
}

const lmb_sky *lmb_direct_sky(const lmb_direct *d)
{
    return d->sky;
}
