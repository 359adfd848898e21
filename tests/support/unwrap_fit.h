/*
 * Shared by the unwrap quality test and the unwrap benchmark: unwrap a generated mesh and
 * pack it into one atlas of about size x size texels at the highest texel density that
 * fits (found by bisection), then measure the result with the metrics of docs/unwrap.md.
 */
#ifndef LMBAKE_TESTS_UNWRAP_FIT_H
#define LMBAKE_TESTS_UNWRAP_FIT_H

#include "meshgen.h"

#include <stdint.h>

typedef struct fit_result {
    uint32_t charts, width, height;
    double density; /* texels per unit */
    double coverage, l2_stretch, density_p1, density_p50, density_p99;
    uint64_t overlapping_texels;
    double chart_seconds; /* one unwrap */
    double pack_seconds;  /* the final pack */
    uint32_t packs;       /* packs tried during the bisection */
} fit_result;

/* 0 on success. */
int fit_mesh(const gen_mesh *g, uint32_t size, uint32_t padding, fit_result *r);

#endif
