/*
 * The sampling helpers shared by the lights and the gather (util/sampling.h): a tabulated CDF
 * picks each segment in proportion to its weight and never one of zero weight; the cosine-power
 * lobe's pdf integrates to 1 over the hemisphere and its samples follow it (the mean of
 * (w.n)^k under the lobe is (a + 1) / (a + k + 1)).
 */
#include "check.h"

#include "util/rng.h"
#include "util/sampling.h"

static void test_cdf(void)
{
    const double cdf[5] = {0, 1, 1, 3, 4}; /* weights 1, 0, 2, 1 */
    double prob = -1;
    CHECK_INT(lmb_cdf_pick(cdf, 4, 0.0, &prob), 0);
    CHECK(fabs(prob - 0.25) < 1e-15);
    CHECK_INT(lmb_cdf_pick(cdf, 4, 0.2499, &prob), 0);
    CHECK_INT(lmb_cdf_pick(cdf, 4, 0.25, &prob), 2); /* u x total on the boundary of the empty segment */
    CHECK(fabs(prob - 0.5) < 1e-15);
    CHECK_INT(lmb_cdf_pick(cdf, 4, 0.7499, &prob), 2);
    CHECK_INT(lmb_cdf_pick(cdf, 4, 0.75, &prob), 3);
    CHECK_INT(lmb_cdf_pick(cdf, 4, 0.999999, &prob), 3);
    CHECK_INT(lmb_cdf_segment(cdf, 4, 0.0), 0);
    CHECK_INT(lmb_cdf_segment(cdf, 4, 1.0), 2);
    CHECK_INT(lmb_cdf_segment(cdf, 4, 2.9999), 2);
    CHECK_INT(lmb_cdf_segment(cdf, 4, 3.0), 3);
    const double lead[4] = {0, 0, 0, 5}; /* two empty segments first */
    CHECK_INT(lmb_cdf_segment(lead, 3, 0.0), 2);
    CHECK_INT(lmb_cdf_pick(lead, 3, 0.0, &prob), 2);
    CHECK(fabs(prob - 1.0) < 1e-15);
    /* frequencies: 40,000 stratified picks land in proportion to the weights */
    uint32_t hits[4] = {0, 0, 0, 0};
    for (uint32_t k = 0; k < 40000; k++)
        hits[lmb_cdf_pick(cdf, 4, (k + 0.5) / 40000.0, &prob)]++;
    CHECK_INT(hits[0], 10000);
    CHECK_INT(hits[1], 0);
    CHECK_INT(hits[2], 20000);
    CHECK_INT(hits[3], 10000);
}

static void test_lobe(void)
{
    const double axis[3] = {0.36, 0.48, 0.8}; /* unit */
    for (int e = 0; e < 3; e++) {
        lmb_lobe lobe = {{axis[0], axis[1], axis[2]}, e == 0 ? 1.0 : e == 1 ? 7.5 : 60.0};
        /* the pdf integrates to 1: uniform directions on the sphere, 200,000 of them */
        lmb_rng rng = lmb_rng_make(7, (uint64_t)e, 0);
        double integral = 0, moment = 0;
        const uint32_t n = 200000;
        for (uint32_t k = 0; k < n; k++) {
            double z = 1 - 2 * lmb_rng_next(&rng), phi = 2 * LMB_PI * lmb_rng_next(&rng), r = sqrt(1 - z * z);
            double w[3] = {r * cos(phi), r * sin(phi), z};
            integral += lmb_lobe_pdf(&lobe, w) * 4 * LMB_PI / n;
        }
        /* samples: E[(w.n)^2] = (a + 1) / (a + 3) */
        for (uint32_t k = 0; k < n; k++) {
            double w[3], u1 = lmb_rng_next(&rng), u2 = lmb_rng_next(&rng);
            lmb_lobe_sample(&lobe, u1, u2, w);
            double c = lmb_dot3(w, lobe.axis);
            CHECK(c > 0 && fabs(lmb_dot3(w, w) - 1) < 1e-6);
            moment += c * c / n;
        }
        double want = (lobe.a + 1) / (lobe.a + 3);
        printf("lobe a = %g: pdf integral %.4f (want 1), E[(w.n)^2] %.5f (want %.5f)\n", lobe.a, integral, moment, want);
        CHECK(fabs(integral - 1) < (e == 2 ? 0.05 : 0.01));
        CHECK(fabs(moment - want) < 2e-3);
    }
}

int main(void)
{
    test_cdf();
    test_lobe();
    return check_failures();
}
