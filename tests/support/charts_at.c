/* An unwrap's charts at a texel density, as the packer takes them (see charts_at.h). */
#include "charts_at.h"

#include <stdlib.h>
#include <string.h>

int charts_at_density(const lmb_charts *c, double density, charts_at *out)
{
    uint32_t n = c->first[c->chart_count];
    out->uv = malloc(sizeof(double) * 6 * n + 1);
    out->charts = calloc((size_t)c->chart_count + 1, sizeof *out->charts);
    if (!out->uv || !out->charts) {
        charts_at_free(out);
        return 0;
    }
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k < 6; k++)
            out->uv[6 * i + k] = c->uv[6 * c->order[i] + k] * density;
    for (uint32_t k = 0; k < c->chart_count; k++) {
        out->charts[k].triangle_count = c->first[k + 1] - c->first[k];
        out->charts[k].uv = out->uv + 6 * c->first[k];
    }
    return 1;
}

void charts_at_free(charts_at *a)
{
    free(a->uv);
    free(a->charts);
    memset(a, 0, sizeof *a);
}
