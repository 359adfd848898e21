/*
 * Unwrap + pack quality on issue 3's reference meshes, each packed into one atlas of about
 * 1024 x 1024 (padding 2) at a fixed density (the one tools/bench_unwrap.c found), measured
 * with the metrics of docs/unwrap.md: zero overlapping texels, L2 stretch <= 1.01, and coverage at
 * least xatlas's: Cornell box 0.894, sphere 0.662, torus 0.553.
 */
#include "check.h"

#include "../support/charts_at.h"
#include "../support/meshgen.h"
#include "pack/pack.h"
#include "unwrap/metrics.h"
#include "unwrap/unwrap.h"

#include <stdlib.h>
#include <string.h>

static void check(const char *name, const gen_mesh *g, double density, double min_coverage)
{
    lmb_unwrap_input in = {g->vertex_count, g->positions, g->triangle_count, g->indices, NULL};
    lmb_unwrap_options o;
    lmb_charts c;
    lmb_error err;
    lmb_unwrap_options_default(&o);
    if (lmb_unwrap_mesh(&in, &o, &c, &err) != LMB_OK) {
        fprintf(stderr, "%s: %s\n", name, err.message);
        check_failed_count++;
        return;
    }
    uint32_t n = c.first[c.chart_count];
    double *pos = malloc(sizeof(double) * 9 * n + 1);
    charts_at at;
    if (!charts_at_density(&c, density, &at)) {
        check_failed_count++;
        return;
    }
    double *uv = at.uv;
    lmb_pack_options po = {1024, 2, 0, 0, 1};
    lmb_pack_result r;
    CHECK_INT(lmb_pack_charts(at.charts, c.chart_count, &po, &r, &err), LMB_OK);
    CHECK_INT(r.atlas_count, 1);
    for (uint32_t k = 0; k < c.chart_count; k++)
        for (uint32_t i = c.first[k]; i < c.first[k + 1]; i++)
            for (int v = 0; v < 3; v++) {
                const double *m = r.placements[k].m;
                double x = uv[6 * i + 2 * v], y = uv[6 * i + 2 * v + 1];
                uv[6 * i + 2 * v] = m[0] * x + m[1] * y + m[2];
                uv[6 * i + 2 * v + 1] = m[3] * x + m[4] * y + m[5];
                for (int d = 0; d < 3; d++)
                    pos[9 * i + 3 * v + d] = g->positions[3 * g->indices[3 * c.order[i] + v] + d];
            }
    lmb_uv_layout l = {n, pos, uv, r.width[0], r.height[0]};
    lmb_uv_metrics m;
    CHECK_INT(lmb_uv_metrics_compute(&l, &m, &err), LMB_OK);
    printf("%s: %u charts, atlas %ux%u, coverage %.4f (bound %.3f), L2 stretch %.5f, overlapping texels %llu\n", name,
           c.chart_count, r.width[0], r.height[0], m.coverage, min_coverage, m.l2_stretch,
           (unsigned long long)m.overlapping_texels);
    CHECK(r.width[0] <= 1024 && r.height[0] <= 1024 && (r.width[0] >= 920 || r.height[0] >= 920));
    CHECK_INT(m.overlapping_texels, 0);
    CHECK(m.coverage >= min_coverage);
    CHECK(m.l2_stretch <= 1.01);
    lmb_pack_result_free(&r);
    lmb_charts_free(&c);
    charts_at_free(&at);
    free(pos);
}

int main(void)
{
    gen_mesh g;
    if (gen_cornell_box(&g) == 0) {
        check("cornell", &g, 288.729, 0.894);
        gen_mesh_free(&g);
    }
    if (gen_uv_sphere(&g, 128, 80, 1.0f) == 0) {
        check("sphere 128x80", &g, 237.006, 0.662);
        gen_mesh_free(&g);
    }
    if (gen_torus(&g, 125, 80, 1.0f, 0.3f) == 0) {
        check("torus 125x80", &g, 226.127, 0.553);
        gen_mesh_free(&g);
    }
    return check_failures();
}
