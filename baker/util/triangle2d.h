/* Texel geometry in atlas texel coordinates: where a texel's sub-samples lie and the closest
 * point of a triangle to one: the rule that decides which texels a triangle lists (texels.c)
 * and the layout's texel count (pack/coverage.c). */
#ifndef LMBAKE_TRIANGLE2D_H
#define LMBAKE_TRIANGLE2D_H

#include <stdint.h>

/* Distance from p to triangle uv (3 points, 6 doubles); *b1, *b2: barycentrics of corners 1
 * and 2 at the closest point. DBL_MAX for a triangle of zero area. */
double lmb_closest_on_triangle_2d(const double *uv, const double p[2], double *b1, double *b2);

/* Sub-sample k of `samples` inside a texel, in [0,1)^2: stratum centres of a sx x sy grid. */
void lmb_texel_subsample(uint32_t k, uint32_t samples, double out[2]);

#endif
