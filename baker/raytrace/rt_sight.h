/*
 * Whether two points on the level's surfaces are in sight of each other along those surfaces: the
 * test that keeps light on its own side of a wall (docs/leaks.md). A texel whose points straddle
 * a wall's foot, an irradiance-cache record and a texel it would serve, a hit and the texel its
 * bilinear lookup reads: each pair lies on one surface (or two nearly parallel ones) within a
 * few texels, and a wall standing between them blocks the segment joining them.
 *
 * Both points are lifted off their surfaces along their normals before the segment is traced,
 * so the surfaces themselves do not block it, nor does a curved surface's chord dip under it: by
 * the larger of `lift` (callers: LMB_SIGHT_LIFT texels) and LMB_SIGHT_LIFT_PER_DISTANCE x their
 * distance (a chord of length d between normals up to 18 degrees apart sinks at most d x 0.31 / 8
 * = 0.039 d under a convex surface). Pairs whose normals differ by more than that (a chart folded
 * over a box's edge, whose segment would cut through the box) are in sight by definition: a
 * wall's two sides are not one surface.
 */
#ifndef LMBAKE_RT_SIGHT_H
#define LMBAKE_RT_SIGHT_H

#include "rt_scene.h"

#include <math.h>

#define LMB_SIGHT_LIFT 0.1        /* texels */
#define LMB_SIGHT_SAME_PLANE 0.95 /* the cosine above which two points' surfaces are compared */
#define LMB_SIGHT_LIFT_PER_DISTANCE 0.05

/* 1 when nothing blocks the segment from a + l ng_a to b + l ng_b (l = max(lift, 0.05 |b - a|)),
 * or when ng_a . ng_b is below LMB_SIGHT_SAME_PLANE (ng: unit normals, front side). */
int lmb_rt_in_sight(const lmb_rt *rt, const double a[3], const double ng_a[3], const double b[3], const double ng_b[3],
                    double lift);

/* Direction j of 8 around the circle of tangents t1, t2 (every 45 degrees): the rays that look
 * along a surface for the geometry beside a point (lmb_rt_sides, texel_direct.c). */
static inline void lmb_rt_tangent_direction(const double t1[3], const double t2[3], int j, double w[3])
{
    double a = j * (3.14159265358979323846 / 4);
    for (int k = 0; k < 3; k++)
        w[k] = cos(a) * t1[k] + sin(a) * t2[k];
}

/* A face beside a point along its surface, as a plane turned to face the point: x lies on the
 * point's side when m . x >= d. */
typedef struct lmb_rt_side {
    double m[3], d;
} lmb_rt_side;

/* The faces beside surface point p (geometric normal ng): 8 rays in the tangent plane, lifted by
 * `lift`, `reach` long; the nearest face met, then the nearest turned more than 25 degrees from
 * those taken (a corner's second wall), up to `most`. Returns how many went into out. The rays
 * cover the circle every 45 degrees: a straight wall at distance s is met within 1.0824 s. */
uint32_t lmb_rt_sides(const lmb_rt *rt, const double p[3], const double ng[3], double lift, double reach,
                      lmb_rt_side *out, uint32_t most);

#endif
