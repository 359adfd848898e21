/*
 * The texels stage: gather points per lightmap texel. Every triangle is rasterized
 * conservatively into its atlas; each texel gets up to `samples` stratified sub-sample
 * points; a sub-sample inside a triangle lies on it, one outside every triangle but within
 * a texel of one (an edge texel the triangle only partly covers) is clamped onto the
 * closest triangle, so edge texels are lit by their own surface and bilinear filtering at
 * chart borders reads meaningful values. Points carry the world position, the shading
 * normal and the geometric normal; the lights stage decides which are inside geometry.
 */
#ifndef LMBAKE_TEXELS_H
#define LMBAKE_TEXELS_H

#include <lmbake/lmbake.h>

#include "pack/layout.h"
#include "util/triangle2d.h"

typedef struct lmb_gather_point {
    double p[3];   /* world position on the surface */
    float n[3];    /* shading normal, world, unit */
    float ng[3];   /* geometric normal, world, unit, front side */
    uint32_t instance, triangle; /* triangle: index into the instance's mesh soup */
} lmb_gather_point;

/* A gather point by where it lies: 16 bytes instead of 56; lmb_texels_point expands it. */
typedef struct lmb_point_ref {
    uint32_t instance, triangle;
    float b1, b2; /* barycentrics of corners 1 and 2 */
} lmb_point_ref;

/* A texel's edge flags. COVERED: valid but some of its points are inside geometry, see a back face
 * or lie across geometry from its gather point (post/rim.c limits these). NEAR: a wall thinner
 * than LMB_THIN_TEXELS texels stands within LMB_BESIDE_TEXELS texels of its gather point along
 * its surface, or geometry split its points (a thin wall's foot): a lookup from a hit may read
 * this texel across that wall, so the bounce cache checks the hit's side (cache/texel_sides.h).
 * Only texels some of whose hemisphere rays hit within LMB_NEAR_TEXELS texels are looked at that
 * closely. */
enum { LMB_EDGE_COVERED = 1, LMB_EDGE_NEAR = 2 };
#define LMB_NEAR_TEXELS 3.0
#define LMB_BESIDE_TEXELS 1.5
#define LMB_THIN_TEXELS 2.0

typedef struct lmb_texels {
    uint32_t width, height, samples;
    uint32_t count;            /* texels that hold at least one point */
    uint32_t *texel;           /* per listed texel: y * width + x */
    uint8_t *points_in;        /* per listed texel: points (1..samples) */
    float *texel_size;         /* per listed texel: world units per texel */
    lmb_gather_point *points;  /* count * samples; the first points_in[i] of each are set; NULL
                                  after lmb_texels_append (points are expanded from refs) */
    lmb_point_ref *refs;       /* count * samples, beside points: where each point lies */
    const lmb_scene *scene;    /* what refs refer to */
    const lmb_layout *layout;
    uint8_t *valid;            /* per listed texel: 1, or 0 when inside geometry (set by the lights stage) */
    uint8_t *gather_at;        /* per listed texel: its first point outside geometry, where indirect
                                  light is gathered (set by the lights stage) */
    uint8_t *edge;             /* per listed texel: LMB_EDGE_* flags (set by the lights stage) */
    uint32_t capacity;         /* texels the per-texel arrays hold room for (lmb_texels_reserve); 0: count */
} lmb_texels;

/* Gather points for atlas `atlas` of layout l. `samples` per texel, 1..256. */
lmb_status lmb_texels_build(const lmb_scene *scene, const lmb_layout *l, uint32_t atlas, uint32_t samples,
                            lmb_texels *out, lmb_error *err);

/* Each instance's reach in atlas rows (its triangles' texels and their neighbours), so that a
 * band of rows visits only the instances that cross it: a level of many small instances (the
 * copies of an instancing node) is banded in time that grows with the band, not with the level.
 * An instance with its own layout and many triangles (a level's one big mesh) also lists, per
 * band of `band_rows` rows, the triangles that reach it (in triangle order), so that a band
 * visits those only. Owned: lmb_instance_rows_free. */
typedef struct lmb_instance_rows {
    uint32_t instance_count;
    int64_t *lo, *hi;     /* per instance; lo > hi: no row (not in the atlas) */
    uint32_t band_rows;   /* the bands the lists are made for: band b is rows [b band_rows, (b + 1) band_rows) */
    uint32_t **band_start; /* per instance NULL, or per band b its list's start in band_triangles (bands + 1) */
    uint32_t **band_triangles; /* per instance NULL, or the lists, one after the other */
} lmb_instance_rows;

lmb_status lmb_instance_rows_make(const lmb_scene *scene, const lmb_layout *l, uint32_t atlas, uint32_t band_rows,
                                  lmb_instance_rows *out, lmb_error *err);
void lmb_instance_rows_free(lmb_instance_rows *r);

/* The same for atlas rows [y0, y1) only (texel indices stay y * width + x of the atlas):
 * the lights stage builds an atlas band by band so that sub-sampled points for the whole
 * atlas never exist at once. rows: the atlas's lmb_instance_rows, or NULL (every instance is
 * visited). */
lmb_status lmb_texels_build_rows(const lmb_scene *scene, const lmb_layout *l, uint32_t atlas, uint32_t samples,
                                 uint32_t y0, uint32_t y1, const lmb_instance_rows *rows, lmb_texels *out,
                                 lmb_error *err);

/* Appends band's texels to dst keeping one point each, the one indirect light is gathered
 * at (band->gather_at, set by the lights stage), as a 16-byte reference: dst then has
 * samples = 1 and no expanded points (memory: about 60 bytes per texel in all). */
lmb_status lmb_texels_append(lmb_texels *dst, const lmb_texels *band, lmb_error *err);

/* Room for n texels in dst's per-texel arrays (of one point each, as lmb_texels_append keeps
 * them), so that the appends up to n move nothing: a step's bands appended one by one grew every
 * array exactly each time, a copy of the whole atlas's arrays per band once they no longer fit
 * in place. Reserve what the bands hold, no more: no slack is left behind. */
lmb_status lmb_texels_reserve(lmb_texels *dst, uint32_t n, lmb_error *err);

void lmb_texels_free(lmb_texels *t);

/* Point k of listed texel i, stored or expanded from its reference (the same doubles either
 * way: both come from one function). */
void lmb_texels_point(const lmb_texels *t, uint32_t i, uint32_t k, lmb_gather_point *out);

/* The shading normals at the corners of triangle f of an instance, in world space, not
 * normalised (the vertex normals through the inverse transpose of the instance matrix).
 * Returns 0 when the triangle is shaded flat (no NORMAL: out is then meaningless). */
int lmb_triangle_corner_normals(const lmb_scene *s, const lmb_layout *l, uint32_t instance, uint32_t f, double out[9]);

#endif
