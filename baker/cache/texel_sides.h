/*
 * Which side of a wall a lightmap texel holds (docs/leaks.md). A gather ray that meets a floor
 * beside a wall reads the floor's lightmap bilinearly, and the 2 x 2 texels it reads may lie
 * across the wall: the straddling texel at the wall's foot, or dilated texels under it. Texels
 * with geometry beside them along their surface (LMB_EDGE_NEAR, set by the lights stage) keep the
 * planes of the nearest faces 8 rays in the tangent plane of their gather point meet (the wall's
 * face on their side); a lookup whose footprint holds one reads it only if the hit lies on the
 * texel's side of those planes, and reads no dilated texel there: light stays in its room. A
 * plane test, not a ray: a level of walls thinner than its texels has a third of its texels
 * beside geometry, and every gather ray that lands near one would trace up to four more.
 * Elsewhere a lookup is the plain bilinear one, so levels without contacts are read as before.
 */
#ifndef LMBAKE_CACHE_TEXEL_SIDES_H
#define LMBAKE_CACHE_TEXEL_SIDES_H

#include <lmbake/lmbake.h>

#include "raytrace/rt_scene.h"
#include "texels/texels.h"

/* A side of the geometry beside a texel: points x with m . x >= d are on the texel's side of that
 * face's plane (raytrace/rt_sight.h, lmb_rt_sides). */
typedef struct lmb_side_plane {
    float m[3], d;
} lmb_side_plane;

#define LMB_SIDE_PLANES 2

typedef struct lmb_texel_anchor {
    uint32_t texel;   /* y x width + x */
    uint32_t planes;  /* 0..LMB_SIDE_PLANES */
    lmb_side_plane plane[LMB_SIDE_PLANES]; /* the nearest faces its tangent rays met (distinct
                                              orientations), facing its gather point */
} lmb_texel_anchor;

typedef struct lmb_texel_sides {
    uint64_t *near;            /* per atlas texel a bit: 1 when it has an anchor (owned; a bit, not a
                                  byte: every lookup reads it, and 1.3 million texels fit in L2 so) */
    uint32_t *rank;            /* per 64 texels: the anchors before them (owned): a texel's anchor is
                                  rank[word] + the bits set below it, no search */
    lmb_texel_anchor *anchors; /* sorted by texel (owned) */
    uint32_t count;
} lmb_texel_sides;

/* The anchors of t's valid LMB_EDGE_NEAR texels in an atlas of w x h texels (8 rays each). */
lmb_status lmb_texel_sides_build(lmb_texel_sides *s, const lmb_texels *t, const lmb_rt *rt, uint32_t w, uint32_t h,
                                 int threads, lmb_error *err);
void lmb_texel_sides_free(lmb_texel_sides *s);

static inline int lmb_texel_sides_near(const lmb_texel_sides *s, uint32_t texel)
{
    return s->near && (s->near[texel >> 6] >> (texel & 63) & 1);
}

/* 1 when texel (y x width + x) may be read from hit point p: it has no anchor, or p lies on the
 * texel's side of its planes. */
int lmb_texel_sides_in_sight(const lmb_texel_sides *s, uint32_t texel, const double p[3]);

#endif
