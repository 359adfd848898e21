/*
 * Charts as the packer takes them: an unwrap's chart-local uvs scaled to a texel density, in
 * chart order, with one lmb_pack_chart per chart pointing into them. Shared by the unwrap and
 * packing tests and the unwrap benchmark.
 */
#ifndef LMBAKE_TESTS_CHARTS_AT_H
#define LMBAKE_TESTS_CHARTS_AT_H

#include "pack/pack.h"
#include "unwrap/unwrap.h"

typedef struct charts_at {
    double *uv;             /* 6 per triangle, in texels, chart order (c->order) */
    lmb_pack_chart *charts; /* c->chart_count */
} charts_at;

/* 1 when made (free with charts_at_free), 0 when out of memory (nothing to free). */
int charts_at_density(const lmb_charts *c, double density, charts_at *out);
void charts_at_free(charts_at *a);

#endif
