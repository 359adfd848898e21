/*
 * UV layout metrics against values worked out by hand: exact texel-centre counts with
 * the top-left rule on shared edges, coverage, overlap, Sander L2 stretch of a known
 * anisotropic map, area-weighted density percentiles.
 */
#include "check.h"

#include "unwrap/metrics.h"

#include <math.h>

/* A quad split along its diagonal: 3D corners (0,0,0)-(sx,sy,0), UV (0,0)-(w,h). */
static void quad(double w, double h, double sx, double sy, double pos[18], double uv[12])
{
    const double c[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const int tri[6] = {0, 1, 2, 0, 2, 3};
    for (int k = 0; k < 6; k++) {
        pos[3 * k] = c[tri[k]][0] * sx;
        pos[3 * k + 1] = c[tri[k]][1] * sy;
        pos[3 * k + 2] = 0;
        uv[2 * k] = c[tri[k]][0] * w;
        uv[2 * k + 1] = c[tri[k]][1] * h;
    }
}

static void nop(void *user, uint32_t x, uint32_t y)
{
    (void)user; (void)x; (void)y;
}

/* Right triangle (0,0),(8,0),(0,8): centres with x + y < 7 are inside (28); the 8 on the
 * hypotenuse x + y = 7 belong to the triangle on the other side of it. */
static void test_raster_counts(void)
{
    const double lower[6] = {0, 0, 8, 0, 0, 8}, upper[6] = {8, 0, 8, 8, 0, 8};
    CHECK_INT(lmb_raster_triangle_centres(lower, 64, 64, nop, NULL), 28);
    CHECK_INT(lmb_raster_triangle_centres(upper, 64, 64, nop, NULL), 36);
    const double reversed[6] = {0, 0, 0, 8, 8, 0}; /* clockwise: same texels */
    CHECK_INT(lmb_raster_triangle_centres(reversed, 64, 64, nop, NULL), 28);
    const double clipped[6] = {-4, -4, 12, -4, -4, 12}; /* clipped to a 4x4 atlas: all 16 */
    CHECK_INT(lmb_raster_triangle_centres(clipped, 4, 4, nop, NULL), 16);
    const double flat[6] = {0, 0, 4, 4, 8, 8};
    CHECK_INT(lmb_raster_triangle_centres(flat, 64, 64, nop, NULL), 0);
}

/* A quad filling the atlas, mapped isometrically: coverage 1, no overlap, stretch 1. */
static void test_full_isometric(void)
{
    double pos[18], uv[12];
    quad(16, 8, 16, 8, pos, uv);
    lmb_uv_layout l = {2, pos, uv, 16, 8};
    lmb_uv_metrics m;
    lmb_error err;
    CHECK_INT(lmb_uv_metrics_compute(&l, &m, &err), LMB_OK);
    CHECK_INT(m.covered_texels, 128);
    CHECK_INT(m.overlapping_texels, 0);
    CHECK_NEAR(m.coverage, 1.0, 0);
    CHECK_NEAR(m.l2_stretch, 1.0, 1e-12);
    CHECK_NEAR(m.density_p1, 1.0, 1e-12);
    CHECK_NEAR(m.density_p99, 1.0, 1e-12);
}

/* 3D twice as wide as the UVs: S_s = (2,0,0), S_t = (0,1,0), per-triangle L2^2 = (4+1)/2;
 * normalized by sqrt(A2d/A3d) = sqrt(1/2): L2 = sqrt(5/4). Same for any global scale. */
static void test_anisotropic_stretch(void)
{
    double pos[18], uv[12];
    quad(8, 8, 16 * 3.0, 8 * 3.0, pos, uv);
    lmb_uv_layout l = {2, pos, uv, 32, 32};
    lmb_uv_metrics m;
    lmb_error err;
    CHECK_INT(lmb_uv_metrics_compute(&l, &m, &err), LMB_OK);
    CHECK_NEAR(m.l2_stretch, sqrt(1.25), 1e-12);
    CHECK_NEAR(m.coverage, 64.0 / 1024.0, 0);
}

/* The same quad twice on the same texels: every covered texel overlaps. */
static void test_overlap(void)
{
    double pos[36], uv[24];
    quad(4, 4, 4, 4, pos, uv);
    quad(4, 4, 4, 4, pos + 18, uv + 12);
    lmb_uv_layout l = {4, pos, uv, 8, 8};
    lmb_uv_metrics m;
    lmb_error err;
    CHECK_INT(lmb_uv_metrics_compute(&l, &m, &err), LMB_OK);
    CHECK_INT(m.covered_texels, 16);
    CHECK_INT(m.overlapping_texels, 16);
}

/* Two quads of equal 3D area, UV densities 1 and 3: mean 2, normalized 0.5 and 1.5;
 * area-weighted p1 = p50 = 0.5 (half the area reaches 50%), p99 = 1.5. */
static void test_density_percentiles(void)
{
    double pos[36], uv[24];
    quad(4, 4, 4, 4, pos, uv);
    quad(4 * sqrt(3.0), 4 * sqrt(3.0), 4, 4, pos + 18, uv + 12);
    for (int k = 0; k < 6; k++)
        uv[12 + 2 * k] += 10; /* side by side */
    lmb_uv_layout l = {4, pos, uv, 32, 32};
    lmb_uv_metrics m;
    lmb_error err;
    CHECK_INT(lmb_uv_metrics_compute(&l, &m, &err), LMB_OK);
    CHECK_NEAR(m.density_p1, 0.5, 1e-9);
    CHECK_NEAR(m.density_p50, 0.5, 1e-9);
    CHECK_NEAR(m.density_p99, 1.5, 1e-9);
    /* each quad is conformal but their scales differ, which Sander's L2 penalizes:
     * L2^2 = 1 and 1/3 over equal 3D areas -> 2/3, times A2d/A3d = 64/32 -> sqrt(4/3) */
    CHECK_NEAR(m.l2_stretch, sqrt(4.0 / 3.0), 1e-9);
}

int main(void)
{
    test_raster_counts();
    test_full_isometric();
    test_anisotropic_stretch();
    test_overlap();
    test_density_percentiles();
    return check_failures();
}
