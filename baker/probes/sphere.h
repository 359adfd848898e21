/* Directions for probes: a spherical Fibonacci lattice, n points of equal area (Swinbanks and
 * Purser 2006; Keinert et al. 2015), the same for every probe, so an integral over the sphere is
 * a fixed quadrature with no noise of its own: 4 pi / n sum f(w_i). */
#ifndef LMBAKE_PROBES_SPHERE_H
#define LMBAKE_PROBES_SPHERE_H

#include <math.h>
#include <stdint.h>

static inline void lmb_sphere_direction(uint32_t i, uint32_t n, double w[3])
{
    const double golden = 0.6180339887498949; /* (sqrt 5 - 1) / 2 */
    double y = 1.0 - (2.0 * i + 1.0) / n, r = sqrt(fmax(0.0, 1.0 - y * y));
    double frac = i * golden - floor(i * golden), phi = 2.0 * 3.14159265358979323846 * frac;
    w[0] = r * cos(phi);
    w[1] = y;
    w[2] = r * sin(phi);
}

#endif
