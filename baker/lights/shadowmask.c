/* The shadowmask's visibilities (output.shadowmask; see direct.h, lmb_shadowmask_at and
 * docs/mixed-lighting.md). */
#include "direct_internal.h"

#include "../util/frame.h"
#include "../util/lmb_math.h"
#include "../util/rng.h"

#include <math.h>

/* Visibility of light l from c's point: the share of shadow rays that reach it (a disc's
 * `samples` directions for a sun with lights.sun_angle, one ray otherwise); 0 where the
 * surface faces away. A ray through surfaces light partly passes counts the luminance of what
 * they let through (a shadowmask holds one value per light: the tint is lost). */
static double seen_through(point_ctx *c, const double d[3], double tmax)
{
    double pass[3];
    c->rays++;
    if (lmb_rt_transmittance(c->d->rt, c->o, d, c->eps, tmax, pass))
        return 0;
    return pass[0] == 1 && pass[1] == 1 && pass[2] == 1 ? 1 : lmb_luminance(pass);
}

static double visibility(point_ctx *c, const lmb_light *l, lmb_rng *rng)
{
    double d[3], dist = 1e300;
    if (l->type == LMB_LIGHT_DIRECTIONAL && c->d->opt.sun_angle > 0) {
        double seen = 0;
        lmb_sun_disc disc;
        lmb_sun_disc_init(c->d->opt.sun_angle, l, &disc);
        for (uint32_t s = 0; s < c->samples; s++) {
            double u1 = lmb_rng_next(rng), u2 = lmb_rng_next(rng);
            lmb_sun_disc_direction(&disc, u1, u2, d);
            if (lmb_dot3(c->n, d) <= 0 || lmb_dot3(c->ng, d) <= 0)
                continue;
            seen += seen_through(c, d, 1e300);
        }
        return c->samples ? seen / c->samples : 0;
    }
    if (!lmb_light_direction(c, l, d, &dist))
        return 0;
    if (lmb_dot3(c->n, d) <= 0 || lmb_dot3(c->ng, d) <= 0)
        return 0;
    return seen_through(c, d, l->type == LMB_LIGHT_DIRECTIONAL ? 1e300 : dist * (1 - 1e-6) - c->eps);
}

uint32_t lmb_shadowmask_at(const lmb_direct *d, const lmb_shading_point *sp, lmb_rng *rng,
                           double vis[LMB_SHADOWMASK_CHANNELS])
{
    point_ctx c;
    lmb_point_init(&c, d, sp);
    c.samples = d->opt.samples;
    for (uint32_t k = 0; k < LMB_SHADOWMASK_CHANNELS; k++)
        vis[k] = k < d->lights.mask_channels ? visibility(&c, &d->scene->lights[d->lights.mask_light[k]], rng) : 0;
    return (uint32_t)c.rays;
}

