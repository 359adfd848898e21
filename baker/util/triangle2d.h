/* Texel geometry in atlas texel coordinates: where a texel's sub-samples lie and the closest
 * point of a triangle to one: the rule that decides which texels a triangle lists (texels.c)
 * and the layout's texel count (pack/coverage.c). */
#ifndef LMBAKE_TRIANGLE2D_H
#define LMBAKE_TRIANGLE2D_H

#include <stdint.h>

/* Distance from p to triangle uv (3 points, 6 doubles); *b1, *b2: barycentrics of corners 1
 * and 2 at the closest point. DBL_MAX for a triangle of zero area. */
double lmb_closest_on_triangle_2d(const double *uv, const double p[2], double *b1, double *b2);

/* The triangle's bounding box, {x0, y0, x1, y1}. */
void lmb_triangle_box_2d(const double *uv, double box[4]);

/* Whether no point of a triangle inside `box` can lie within `limit` of p (limit >= 0): the
 * squared distance from p to the box is above limit^2, by a margin of a millionth so that a
 * triangle whose closest point is exactly `limit` away is never skipped for a rounding. A cheap
 * test before lmb_closest_on_triangle_2d: it skips what that could not accept. */
static inline int lmb_box_beyond_2d(const double box[4], const double p[2], double limit)
{
    double dx = p[0] < box[0] ? box[0] - p[0] : (p[0] > box[2] ? p[0] - box[2] : 0);
    double dy = p[1] < box[1] ? box[1] - p[1] : (p[1] > box[3] ? p[1] - box[3] : 0);
    return dx * dx + dy * dy > limit * limit * (1 + 1e-6);
}

/* Sub-sample k of `samples` inside a texel, in [0,1)^2: stratum centres of a sx x sy grid. */
void lmb_texel_subsample(uint32_t k, uint32_t samples, double out[2]);

#endif
