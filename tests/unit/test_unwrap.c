/*
 * Unwrapper tests on the generated reference meshes and on degenerate / non-manifold
 * input: every charted triangle keeps its orientation, no chart overlaps itself when
 * rasterized (texel centres covered twice), each chart's UV area equals its 3D area,
 * L2 stretch <= 1.01 on the sphere and torus (planar charts exactly 1), the result is
 * deterministic, and narrow charts glue onto their neighbours without stretch or overlap.
 */
#include "check.h"

#include "../support/meshgen.h"
#include "unwrap/metrics.h"
#include "unwrap/unwrap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double *soup_positions(const float *positions, const uint32_t *indices, uint32_t nt)
{
    double *pos = malloc(sizeof(double) * 9 * nt + 1);
    for (uint32_t f = 0; pos && f < nt; f++)
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++)
                pos[9 * f + 3 * k + d] = positions[3 * indices[3 * f + k] + d];
    return pos;
}

/* Rasterizes each chart alone, scaled to `texels` texels per unit area, and counts texel
 * centres covered twice. */
static uint64_t self_overlaps(const lmb_charts *c, const double *pos, double scale)
{
    uint64_t total = 0;
    for (uint32_t k = 0; k < c->chart_count; k++) {
        uint32_t n = c->first[k + 1] - c->first[k];
        double *uv = malloc(sizeof(double) * 6 * n + 1), *p = malloc(sizeof(double) * 9 * n + 1);
        double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
        for (uint32_t i = 0; i < n; i++) {
            uint32_t f = c->order[c->first[k] + i];
            memcpy(p + 9 * i, pos + 9 * f, 9 * sizeof(double));
            for (int j = 0; j < 6; j++) {
                uv[6 * i + j] = c->uv[6 * f + j] * scale;
                lo[j % 2] = fmin(lo[j % 2], uv[6 * i + j]);
                hi[j % 2] = fmax(hi[j % 2], uv[6 * i + j]);
            }
        }
        for (uint32_t i = 0; i < 6 * n; i++)
            uv[i] -= lo[i % 2];
        lmb_uv_layout l = {n, p, uv, (uint32_t)(hi[0] - lo[0]) + 2, (uint32_t)(hi[1] - lo[1]) + 2};
        lmb_uv_metrics m;
        lmb_error err;
        if (lmb_uv_metrics_compute(&l, &m, &err) == LMB_OK)
            total += m.overlapping_texels;
        free(uv);
        free(p);
    }
    return total;
}

static void check_mesh(const char *name, const gen_mesh *g, uint32_t min_charts, uint32_t max_charts, double max_l2)
{
    lmb_unwrap_input in = {g->vertex_count, g->positions, g->triangle_count, g->indices, NULL};
    lmb_unwrap_options o;
    lmb_charts c, again;
    lmb_error err;
    lmb_unwrap_options_default(&o);
    if (lmb_unwrap_mesh(&in, &o, &c, &err) != LMB_OK) {
        fprintf(stderr, "%s: %s\n", name, err.message);
        check_failed_count++;
        return;
    }
    double *pos = soup_positions(g->positions, g->indices, g->triangle_count);
    lmb_uv_layout l = {g->triangle_count, pos, c.uv, 0, 0};
    lmb_uv_metrics m;
    CHECK_INT(lmb_uv_metrics_compute(&l, &m, &err), LMB_OK);
    printf("%s: %u triangles, %u charts (%u planar, %u splits), L2 stretch %.5f, density p1 %.3f p99 %.3f\n", name,
           g->triangle_count, c.chart_count, c.planar_charts, c.splits, m.l2_stretch, m.density_p1, m.density_p99);
    CHECK(m.l2_stretch <= max_l2);
    CHECK(c.chart_count >= min_charts && c.chart_count <= max_charts);
    /* every triangle charted, counter-clockwise in UV */
    uint32_t flipped = 0, uncharted = 0;
    for (uint32_t f = 0; f < g->triangle_count; f++) {
        const double *p = c.uv + 6 * f;
        uncharted += c.chart_of[f] == UINT32_MAX;
        flipped += !((p[2] - p[0]) * (p[5] - p[1]) - (p[4] - p[0]) * (p[3] - p[1]) > 0);
    }
    CHECK_INT(uncharted, 0);
    CHECK_INT(flipped, 0);
    /* chart UV area equals its 3D area */
    double worst = 0;
    for (uint32_t k = 0; k < c.chart_count; k++) {
        double a2 = 0, a3 = 0;
        for (uint32_t i = c.first[k]; i < c.first[k + 1]; i++) {
            uint32_t f = c.order[i];
            const double *p = c.uv + 6 * f, *q = pos + 9 * f;
            a2 += 0.5 * ((p[2] - p[0]) * (p[5] - p[1]) - (p[4] - p[0]) * (p[3] - p[1]));
            double e1[3] = {q[3] - q[0], q[4] - q[1], q[5] - q[2]}, e2[3] = {q[6] - q[0], q[7] - q[1], q[8] - q[2]};
            double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2], z = e1[0] * e2[1] - e1[1] * e2[0];
            a3 += 0.5 * sqrt(x * x + y * y + z * z);
        }
        worst = fmax(worst, fabs(a2 / a3 - 1.0));
    }
    CHECK(worst < 1e-9);
    /* injective per chart at about 1024x1024 texels for the whole mesh */
    double total3 = 0;
    for (uint32_t f = 0; f < g->triangle_count; f++) {
        const double *q = pos + 9 * f;
        double e1[3] = {q[3] - q[0], q[4] - q[1], q[5] - q[2]}, e2[3] = {q[6] - q[0], q[7] - q[1], q[8] - q[2]};
        double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2], z = e1[0] * e2[1] - e1[1] * e2[0];
        total3 += 0.5 * sqrt(x * x + y * y + z * z);
    }
    CHECK_INT(self_overlaps(&c, pos, sqrt(0.7 * 1024 * 1024 / total3)), 0);
    /* deterministic */
    CHECK_INT(lmb_unwrap_mesh(&in, &o, &again, &err), LMB_OK);
    CHECK(again.chart_count == c.chart_count && !memcmp(again.uv, c.uv, sizeof(double) * 6 * g->triangle_count));
    lmb_charts_free(&again);
    lmb_charts_free(&c);
    free(pos);
}

/* Zero-area triangles (skipped and marked uncharted), a non-manifold fin (3 triangles on
 * one edge) and a duplicate face with the same winding: no crash, no chart across them. */
static void test_degenerate_and_nonmanifold(void)
{
    const float pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 2, 0, 0, 0.5f, 0.5f, 0.5f};
    const uint32_t idx[] = {0, 1, 2, 0, 3, 1, 0, 1, 4, /* fin on edge 0-1 */
                            0, 1, 2,                   /* duplicate of triangle 0 */
                            0, 1, 5,                   /* zero area (collinear) */
                            6, 6, 6};                  /* zero area (one point) */
    lmb_unwrap_input in = {7, pos, 6, idx, NULL};
    lmb_unwrap_options o;
    lmb_charts c;
    lmb_error err;
    lmb_unwrap_options_default(&o);
    CHECK_INT(lmb_unwrap_mesh(&in, &o, &c, &err), LMB_OK);
    CHECK_INT(c.chart_of[4], UINT32_MAX);
    CHECK_INT(c.chart_of[5], UINT32_MAX);
    CHECK(c.chart_of[0] != c.chart_of[3]); /* duplicate layers never share a chart */
    CHECK_INT(c.chart_count, 4);
    lmb_charts_free(&c);
}

/* A thin wall (7 x 4 x 0.3, a closed box): with glue_below 1 its top, bottom and ends (0.3
 * wide) are glued onto the two big faces, unfolded across the creases: 2 charts instead of 6,
 * every triangle keeps its orientation and its area (no stretch), and no chart overlaps
 * itself. Gluing off: 6 charts. */
static void test_glue_thin_wall(void)
{
    const float x1 = 7, y1 = 4, z1 = 0.3f;
    const float pos[] = {0, 0, 0, x1, 0, 0, x1, y1, 0, 0, y1, 0, 0, 0, z1, x1, 0, z1, x1, y1, z1, 0, y1, z1};
    const uint32_t quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 4, 7, 3}, {1, 2, 6, 5}};
    uint32_t idx[36];
    for (int q = 0; q < 6; q++) {
        const uint32_t t[6] = {quads[q][0], quads[q][1], quads[q][2], quads[q][0], quads[q][2], quads[q][3]};
        memcpy(idx + 6 * q, t, sizeof t);
    }
    lmb_unwrap_input in = {8, pos, 12, idx, NULL};
    lmb_unwrap_options o;
    lmb_charts c;
    lmb_error err;
    lmb_unwrap_options_default(&o);
    CHECK_INT(lmb_unwrap_mesh(&in, &o, &c, &err), LMB_OK);
    CHECK_INT(c.chart_count, 6);
    CHECK_INT(c.glued, 0);
    lmb_charts_free(&c);
    o.glue_below = 1.0;
    CHECK_INT(lmb_unwrap_mesh(&in, &o, &c, &err), LMB_OK);
    CHECK_INT(c.chart_count, 2);
    CHECK_INT(c.glued, 4);
    double *p = soup_positions(pos, idx, 12);
    for (uint32_t f = 0; p && f < 12; f++) {
        const double *u = c.uv + 6 * f, *q = p + 9 * f;
        double a2 = (u[2] - u[0]) * (u[5] - u[1]) - (u[4] - u[0]) * (u[3] - u[1]), e1[3], e2[3];
        for (int d = 0; d < 3; d++) {
            e1[d] = q[3 + d] - q[d];
            e2[d] = q[6 + d] - q[d];
        }
        double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2], cz = e1[0] * e2[1] - e1[1] * e2[0];
        CHECK(a2 > 0);                                                    /* orientation kept */
        CHECK_NEAR(0.5 * a2, 0.5 * sqrt(cx * cx + cy * cy + cz * cz), 1e-9); /* area kept */
    }
    CHECK_INT(self_overlaps(&c, p, 16.0), 0);
    free(p);
    lmb_charts_free(&c);
}

int main(void)
{
    gen_mesh g;
    if (gen_cornell_box(&g) == 0) {
        check_mesh("cornell", &g, 15, 15, 1.0 + 1e-12);
        gen_mesh_free(&g);
    }
    if (gen_uv_sphere(&g, 128, 80, 1.0f) == 0) {
        check_mesh("sphere", &g, 8, 400, 1.01);
        gen_mesh_free(&g);
    }
    if (gen_torus(&g, 125, 80, 1.0f, 0.3f) == 0) {
        check_mesh("torus", &g, 8, 400, 1.01);
        gen_mesh_free(&g);
    }
    test_degenerate_and_nonmanifold();
    test_glue_thin_wall();
    return check_failures();
}
