/* Constants that -std=c11 does not provide (M_PI needs _DEFAULT_SOURCE), and luminance. */
#ifndef LMBAKE_LMB_MATH_H
#define LMBAKE_LMB_MATH_H

#define LMB_PI 3.14159265358979323846
#define LMB_PI_2 1.57079632679489661923
#define LMB_INV_PI 0.31830988618379067154

/* Luminance of linear RGB (Rec. 709 weights): what adaptation, limits and reports compare. */
static inline double lmb_luminance(const double c[3])
{
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

static inline double lmb_luminance_f(const float c[3])
{
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

#endif
