/* The irradiance on the back of a doubleSided surface (see back_light.h). */
#include "back_light.h"

#include "util/frame.h"
#include "util/lmb_math.h"

#include <math.h>

/* Cosine rays per estimate (stratified in u1 when more than one). One is enough: 16 moved the
 * card scene's gathered noise from 16.6% to 16.1% (docs/materials.md, the denoiser's level);
 * the noise is in which outer rays meet the back, not in the estimate at it. */
#define LMB_BACK_RAYS 1

uint64_t lmb_cache_back_irradiance(const lmb_cache *c, const lmb_direct *d, const lmb_rt_hit *h, const double o[3],
                                   const double w[3], int direct_at_hits, lmb_rng *rng, double e[3])
{
    const lmb_rt *rt = c->rt;
    lmb_shading_point y;
    for (int k = 0; k < 3; k++) {
        y.p[k] = o[k] + h->t * w[k];
        y.n[k] = y.ng[k] = -h->ng[k]; /* the back: the side opposite the front's normal */
    }
    y.eps = 4 * rt->eps;
    uint64_t rays = lmb_direct_at(d, &y, 1, rng, e, NULL);
    double t1[3], t2[3], q[3], ind[3] = {0, 0, 0};
    lmb_frame(y.n, t1, t2);
    for (int k = 0; k < 3; k++)
        q[k] = y.p[k] + y.ng[k] * y.eps;
    for (uint32_t s = 0; s < LMB_BACK_RAYS; s++) { /* stratified in u1 */
        double u1 = (s + lmb_rng_next(rng)) / LMB_BACK_RAYS, u2 = lmb_rng_next(rng);
        double r = sqrt(u1), phi = 2 * LMB_PI * u2, cz = sqrt(fmax(0, 1 - u1)), v[3];
        for (int k = 0; k < 3; k++)
            v[k] = r * cos(phi) * t1[k] + r * sin(phi) * t2[k] + cz * y.n[k];
        lmb_rt_hit z;
        rays++;
        if (!(cz > 0) || !lmb_rt_intersect(rt, q, v, y.eps, 1e300, &z))
            continue;
        double albedo[3], ez[3];
        if (lmb_cache_lookup(c, &z, albedo, ez) != LMB_HIT_CACHED)
            continue;
        if (direct_at_hits) {
            lmb_shading_point sz;
            double dz[3];
            for (int k = 0; k < 3; k++) {
                sz.p[k] = q[k] + z.t * v[k];
                sz.n[k] = sz.ng[k] = z.ng[k];
            }
            sz.eps = 4 * rt->eps;
            rays += lmb_direct_at(d, &sz, 1, rng, dz, NULL);
            for (int k = 0; k < 3; k++)
                ez[k] += dz[k];
        }
        for (int k = 0; k < 3; k++) /* cosine sampling: E ~ pi L = pi albedo / pi E(z) */
            ind[k] += LMB_PI * albedo[k] * ez[k];
    }
    for (int k = 0; k < 3; k++)
        e[k] += ind[k] / LMB_BACK_RAYS;
    return rays;
}
