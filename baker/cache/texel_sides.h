/*
 * Which side of a wall a lightmap texel holds (docs/leaks.md). A gather ray that meets a floor
 * beside a wall reads the floor's lightmap bilinearly, and the 2 x 2 texels it reads may lie
 * across the wall: the straddling texel at the wall's foot, or dilated texels under it. Texels
 * with geometry within LMB_NEAR_TEXELS texels (LMB_EDGE_NEAR, set by the lights stage) keep
 * their gather point (the anchor their light was computed on, texel_direct.c); a lookup whose
 * footprint holds one reads it only if its anchor is in sight of the hit along the surface
 * (raytrace/rt_sight.h), and reads no dilated texel there: light stays in its room. Elsewhere a
 * lookup is the plain bilinear one, so levels without contacts are read as before.
 */
#ifndef LMBAKE_CACHE_TEXEL_SIDES_H
#define LMBAKE_CACHE_TEXEL_SIDES_H

#include <lmbake/lmbake.h>

#include "raytrace/rt_scene.h"
#include "texels/texels.h"

typedef struct lmb_texel_anchor {
    uint32_t texel;   /* y x width + x */
    float lift;       /* world units: LMB_SIGHT_LIFT texels */
    double p[3];      /* the texel's gather point, world */
    double ng[3];     /* its geometric normal, front side */
} lmb_texel_anchor;

typedef struct lmb_texel_sides {
    uint8_t *near;             /* per atlas texel: 1 when it has an anchor (owned) */
    lmb_texel_anchor *anchors; /* sorted by texel (owned) */
    uint32_t count;
} lmb_texel_sides;

/* The anchors of t's valid LMB_EDGE_NEAR texels in an atlas of w x h texels. */
lmb_status lmb_texel_sides_build(lmb_texel_sides *s, const lmb_texels *t, uint32_t w, uint32_t h, lmb_error *err);
void lmb_texel_sides_free(lmb_texel_sides *s);

/* 1 when texel (y x width + x) may be read from hit point p (geometric normal ng): it has no
 * anchor, or its anchor is in sight of p. */
int lmb_texel_sides_in_sight(const lmb_texel_sides *s, const lmb_rt *rt, uint32_t texel, const double p[3],
                             const float ng[3]);

#endif
