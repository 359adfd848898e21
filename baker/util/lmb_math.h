/* Constants that -std=c11 does not provide (M_PI needs _DEFAULT_SOURCE). */
#ifndef LMBAKE_LMB_MATH_H
#define LMBAKE_LMB_MATH_H

#define LMB_PI 3.14159265358979323846
#define LMB_PI_2 1.57079632679489661923
#define LMB_INV_PI 0.31830988618379067154

#endif
