/*
 * Scrambled Sobol points (baker/util/qmc.h): the first 2^m points of any key form a (0, m, 2)-net
 * (exactly one point in every elementary box of area 2^-m, for every split of m into columns
 * and rows), so are the points [2^m j, 2^m (j + 1)) for every j (a later round of the direct
 * light stays stratified on its own); different keys give different points; and the
 * scrambled points are uniform: over 64 keys the mean of 4 points estimates 1/2 without bias
 * and a smooth integrand's error falls faster than independent points' (N^-1/2). The Pascal
 * matrix product by shifts and masks equals the column-by-column product of the definition, and
 * the points equal the definition's (Burley 2020, section 3: scramble the index, take both
 * dimensions, scramble each), so the bakes' light is the same as before that speed-up.
 */
#include "check.h"

#include "util/qmc.h"
#include "util/rng.h"

#include <stdlib.h>

/* 1 when points [first, first + 2^m) of key fill every elementary box of area 2^-m once. */
static int is_net(uint64_t key, uint32_t first, int m)
{
    uint32_t n = 1u << m;
    for (int cols = 0; cols <= m; cols++) {
        int rows = m - cols;
        uint8_t *seen = calloc(n, 1);
        int ok = 1;
        for (uint32_t i = 0; i < n; i++) {
            double u[2];
            lmb_qmc_2d(key, first + i, u);
            uint32_t x = (uint32_t)(u[0] * (1u << cols)), y = (uint32_t)(u[1] * (1u << rows));
            uint32_t box = (y << cols) | x;
            ok &= u[0] >= 0 && u[0] < 1 && u[1] >= 0 && u[1] < 1 && !seen[box];
            seen[box] = 1;
        }
        free(seen);
        if (!ok)
            return 0;
    }
    return 1;
}

static void test_nets(void)
{
    for (uint64_t key = 1; key <= 20; key++)
        for (int m = 0; m <= 10; m++) {
            CHECK(is_net(lmb_mix64(key), 0, m));
            CHECK(is_net(lmb_mix64(key), 3u << m, m)); /* a later block of 2^m */
        }
}

static void test_keys_differ(void)
{
    double a[2], b[2];
    int same = 0;
    for (uint32_t i = 0; i < 64; i++) {
        lmb_qmc_2d(lmb_mix64(7), i, a);
        lmb_qmc_2d(lmb_mix64(8), i, b);
        same += a[0] == b[0] && a[1] == b[1];
    }
    CHECK_INT(same, 0);
}

/* f(u, v) = u v^2 + sin(3 u) over [0,1)^2: the error of 64 points, rms over 256 keys,
 * against what independent points give (sigma / 8 with sigma^2 the integrand's variance). */
static void test_error_falls_faster(void)
{
    const double exact = 1.0 / 6.0 + (1 - cos(3.0)) / 3.0;
    double se = 0, mean4 = 0;
    for (uint64_t key = 0; key < 256; key++) {
        double sum = 0, s4 = 0;
        for (uint32_t i = 0; i < 64; i++) {
            double u[2];
            lmb_qmc_2d(lmb_mix64(1000 + key), i, u);
            double f = u[0] * u[1] * u[1] + sin(3 * u[0]);
            sum += f;
            if (i < 4)
                s4 += u[0];
        }
        se += (sum / 64 - exact) * (sum / 64 - exact);
        mean4 += s4 / 4;
    }
    double rms = sqrt(se / 256);
    /* the integrand's variance, by a fine midpoint rule */
    double m1 = 0, m2 = 0;
    for (int i = 0; i < 400; i++)
        for (int j = 0; j < 400; j++) {
            double u = (i + 0.5) / 400, v = (j + 0.5) / 400, f = u * v * v + sin(3 * u);
            m1 += f;
            m2 += f * f;
        }
    m1 /= 160000;
    m2 /= 160000;
    double independent = sqrt(m2 - m1 * m1) / 8;
    printf("64 scrambled Sobol points: rms error %.2e, independent points %.2e (ratio %.3f)\n", rms, independent,
           rms / independent);
    CHECK(rms < 0.1 * independent);
    CHECK_NEAR(mean4 / 256, 0.5, 0.02); /* 4 points: each coordinate stratified in quarters, unbiased */
}

/* The definition: the second dimension as the XOR of the Pascal matrix's columns (one per set
 * bit of i, each column the one before XOR itself shifted right). */
static uint32_t pascal_by_columns(uint32_t i)
{
    uint32_t y = 0;
    for (uint32_t v = 0x80000000u; i; i >>= 1, v ^= v >> 1)
        if (i & 1)
            y ^= v;
    return y;
}

static void point_by_definition(uint64_t key, uint32_t index, double u[2])
{
    uint32_t i = lmb_qmc_owen(index, lmb_qmc_hash(key));
    uint32_t x = lmb_qmc_owen(lmb_qmc_reverse(i), lmb_qmc_hash(key ^ 0x9E3779B97F4A7C15ull));
    uint32_t y = lmb_qmc_owen(pascal_by_columns(i), lmb_qmc_hash(key ^ 0xD1B54A32D192ED03ull));
    u[0] = x * (1.0 / 4294967296.0);
    u[1] = y * (1.0 / 4294967296.0);
}

static void test_same_as_definition(void)
{
    uint32_t pascal_wrong = 0, points_wrong = 0;
    for (uint32_t i = 0; i < (1u << 20); i++)
        pascal_wrong += lmb_qmc_reverse(lmb_qmc_pascal(i)) != pascal_by_columns(i);
    for (uint64_t n = 0; n < 1000000; n++) {
        uint32_t i = (uint32_t)(lmb_mix64(n ^ 0x5eed) >> 32);
        pascal_wrong += lmb_qmc_reverse(lmb_qmc_pascal(i)) != pascal_by_columns(i);
        uint64_t key = lmb_mix64(n);
        double a[2], b[2];
        lmb_qmc_2d(key, i, a);
        point_by_definition(key, i, b);
        points_wrong += a[0] != b[0] || a[1] != b[1];
    }
    CHECK_INT(pascal_wrong, 0);
    CHECK_INT(points_wrong, 0);
}

int main(void)
{
    test_same_as_definition();
    test_nets();
    test_keys_differ();
    test_error_falls_faster();
    return check_failures();
}
