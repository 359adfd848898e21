/*
 * The back of a doubleSided surface (glTF: both sides are front, so both reflect). No lightmap
 * holds that side's light: engines draw the back with the front's lightmap (as Unity's
 * double-sided GI does), so a second one would not be shown; but a bounce off the back must
 * carry the back's own light (the underside of a leaf card over a sunlit ground is lit by the
 * ground, not by the sun on its top). Where a ray meets such a back, its irradiance is
 * estimated there, from one sample of each part:
 *   E_back(y) ~ E_direct(y) + pi B(z)
 * with E_direct the direct stage's estimate at y facing the back (lights, emitters, the sky;
 * one sample of the sampled ones) and z the first hit of one cosine-distributed ray from y on
 * the back's side, B(z) its cached outgoing radiance (a front face's; 0 for a miss, whose sky
 * is in E_direct, and for another back). Each is an unbiased estimate of what it stands for,
 * so the gather that averages many such rays stays unbiased for the cached light: nested Monte
 * Carlo with one inner sample. Rays meet backs only where backs are open to the light (cards,
 * leaves, a level's outside walls), so a level of closed rooms pays nothing.
 */
#ifndef LMBAKE_BACK_LIGHT_H
#define LMBAKE_BACK_LIGHT_H

#include "cache/bounce_cache.h"
#include "lights/direct.h"
#include "util/rng.h"

/* E at the back of the surface hit h by the ray o + t w (LMB_HIT_BACK), into e; rng is advanced.
 * direct_at_hits: the cache holds indirect light only (gather.direct_at_hits), so the inner
 * hit adds its direct light. Returns the rays traced. */
uint64_t lmb_cache_back_irradiance(const lmb_cache *c, const lmb_direct *d, const lmb_rt_hit *h, const double o[3],
                                   const double w[3], int direct_at_hits, lmb_rng *rng, double e[3]);

#endif
