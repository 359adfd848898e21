/*
 * The final-gather estimators (baker/gather/estimator.c) on analytic environments, no ray
 * tracing: radiance Lb from everywhere plus bright caps (direction d, half-angle b, extra
 * radiance L). Over the hemisphere around n, a cap fully above the horizon adds
 * L pi sin^2(b) (d.n) to the irradiance (the cosine integral over a spherical cap), so
 * E = pi Lb + sum L pi sin^2(b) (d.n) exactly.
 * Checks: AMIS with one iteration is classic gathering bit for bit; classic, AMIS and defensive
 * AMIS are unbiased (mean over many seeds within 3 standard errors of E); on one small bright
 * cap AMIS finds it and lowers the variance; defensive AMIS stays within its variance bound
 * against classic on two opposite caps; nothing seen means no adaptation and E = 0.
 */
#include "check.h"

#include "gather/estimator.h"

#include <stdlib.h>

typedef struct cap {
    double d[3], cos_b, l;
} cap;

typedef struct env {
    double lb;
    cap caps[2];
    int count;
    unsigned long calls;
} env;

static double env_radiance(void *user, const double w[3], uint32_t sample, double out[3])
{
    env *e = user;
    double l = e->lb;
    (void)sample;
    e->calls++;
    for (int i = 0; i < e->count; i++)
        if (lmb_dot3(w, e->caps[i].d) >= e->caps[i].cos_b)
            l += e->caps[i].l;
    out[0] = out[1] = out[2] = l;
    return INFINITY;
}

static cap make_cap(double theta_deg, double phi_deg, double half_deg, double l)
{
    double t = theta_deg * LMB_PI / 180, p = phi_deg * LMB_PI / 180;
    cap c = {{sin(t) * cos(p), sin(t) * sin(p), cos(t)}, cos(half_deg * LMB_PI / 180), l};
    return c;
}

static double exact(const env *e)
{
    double s = LMB_PI * e->lb;
    for (int i = 0; i < e->count; i++)
        s += e->caps[i].l * LMB_PI * (1 - e->caps[i].cos_b * e->caps[i].cos_b) * e->caps[i].d[2];
    return s;
}

static const double N[3] = {0, 0, 1};
static int unbiased_weights; /* run(): AMIS with the unbiased estimate instead of the paper's */

typedef struct moments {
    double mean, var, se;
} moments;

/* E over `seeds` seeds (red channel; all channels are equal here). */
static moments run(env *e, lmb_gather_method m, uint32_t rays, uint32_t iters, double def, int seeds,
                   lmb_estimator_scratch *s, lmb_estimate *last)
{
    lmb_estimator_options o = {.method = m, .rays = rays, .iterations = iters, .defensive = def, .unbiased = unbiased_weights};
    double sum = 0, sum2 = 0;
    for (int k = 0; k < seeds; k++) {
        lmb_estimate est;
        CHECK_INT(lmb_estimate_irradiance(&o, N, N, lmb_rng_make(7, (uint64_t)k, 3), env_radiance, e, s, &est), LMB_OK);
        sum += est.e[0];
        sum2 += est.e[0] * est.e[0];
        if (last)
            *last = est;
    }
    moments r;
    r.mean = sum / seeds;
    r.var = (sum2 - sum * r.mean) / (seeds - 1);
    r.se = sqrt(r.var / seeds);
    return r;
}

/* Classic gathering and AMIS with the unbiased estimate: mean within 3 standard errors of the
 * exact value (4000 seeds x 256 rays, 4 iterations). */
static void check_unbiased(const char *name, env *e, lmb_gather_method m, lmb_estimator_scratch *s)
{
    unbiased_weights = 1;
    moments r = run(e, m, 256, 4, 0.1, 4000, s, NULL);
    double ex = exact(e);
    printf("%-34s mean %.5f exact %.5f (%+.2f SE), sd %.4f\n", name, r.mean, ex, (r.mean - ex) / r.se, sqrt(r.var));
    CHECK(fabs(r.mean - ex) <= 3 * r.se);
}

/* AMIS re-weights every sample with lobes fitted to it (eqs. 2-4), so it is consistent, not
 * unbiased: the bias shrinks like 1/N. Returns the relative bias at `rays` (2000 seeds). */
static double amis_bias(const char *name, env *e, lmb_gather_method m, uint32_t rays, lmb_estimator_scratch *s)
{
    moments r = run(e, m, rays, 4, 0.1, 2000, s, NULL);
    double ex = exact(e);
    printf("%-28s %5u rays: mean %.5f exact %.5f, bias %+.2f%% (%+.1f SE), sd %.4f\n", name, rays, r.mean, ex,
           100 * (r.mean - ex) / ex, (r.mean - ex) / r.se, sqrt(r.var));
    return (r.mean - ex) / ex;
}

int main(void)
{
    lmb_estimator_scratch s = {0};

    /* 1. AMIS with one iteration = classic, bit for bit, and the same rays */
    env spot = {1.0, {make_cap(40, 30, 6, 400.0)}, 1, 0};
    for (uint64_t seed = 0; seed < 50; seed++) {
        lmb_estimator_options oc = {.method = LMB_GATHER_COSINE, .rays = 333, .iterations = 1},
                              oa = {.method = LMB_GATHER_AMIS, .rays = 333, .iterations = 1},
                              ou = {.method = LMB_GATHER_AMIS, .rays = 333, .iterations = 1, .unbiased = 1},
                              od = {.method = LMB_GATHER_AMIS_DEFENSIVE, .rays = 333, .iterations = 1, .defensive = 0.1,
                                    .unbiased = 1};
        lmb_estimate c, a, u;
        lmb_estimate_irradiance(&oc, N, N, lmb_rng_make(seed, 1, 2), env_radiance, &spot, &s, &c);
        lmb_estimate_irradiance(&oa, N, N, lmb_rng_make(seed, 1, 2), env_radiance, &spot, &s, &a);
        lmb_estimate_irradiance(&ou, N, N, lmb_rng_make(seed, 1, 2), env_radiance, &spot, &s, &u);
        CHECK(memcmp(c.e, a.e, sizeof c.e) == 0);
        CHECK(memcmp(c.e, u.e, sizeof c.e) == 0);
        lmb_estimate_irradiance(&od, N, N, lmb_rng_make(seed, 1, 2), env_radiance, &spot, &s, &u);
        CHECK(memcmp(c.e, u.e, sizeof c.e) == 0); /* the default method with T = 1, too */
        CHECK_INT(c.traced, a.traced);
        CHECK_INT(a.traced, 333);
    }

    /* 2. classic is unbiased (4000 seeds x 256 rays, 3 standard errors); AMIS and defensive
     * AMIS converge: at 4x the rays the bias is at most half, and within 3% at 4096 rays */
    env two = {1.0, {make_cap(60, 0, 6, 400.0), make_cap(60, 180, 6, 400.0)}, 2, 0};
    env sky = {1.0, {{{0, 0, 1}, 2.0, 0}}, 0, 0};
    check_unbiased("classic, one cap", &spot, LMB_GATHER_COSINE, &s);
    check_unbiased("classic, two caps", &two, LMB_GATHER_COSINE, &s);
    check_unbiased("AMIS unbiased, one cap", &spot, LMB_GATHER_AMIS, &s);
    check_unbiased("AMIS unbiased, two caps", &two, LMB_GATHER_AMIS, &s);
    check_unbiased("AMIS unbiased, uniform sky", &sky, LMB_GATHER_AMIS, &s);
    check_unbiased("defensive unbiased, one cap", &spot, LMB_GATHER_AMIS_DEFENSIVE, &s);
    check_unbiased("defensive unbiased, two caps", &two, LMB_GATHER_AMIS_DEFENSIVE, &s);
    unbiased_weights = 0; /* the paper's estimate from here on */
    env *envs[3] = {&spot, &two, &sky};
    const char *names[3] = {"one cap", "two caps", "uniform sky"};
    for (int k = 0; k < 3; k++)
        for (int m = LMB_GATHER_AMIS; m <= LMB_GATHER_AMIS_DEFENSIVE; m++) {
            char name[64];
            snprintf(name, sizeof name, "%s, %s", m == LMB_GATHER_AMIS ? "AMIS" : "defensive", names[k]);
            double b1 = amis_bias(name, envs[k], (lmb_gather_method)m, 1024, &s);
            double b4 = amis_bias(name, envs[k], (lmb_gather_method)m, 4096, &s);
            CHECK(fabs(b4) <= 0.5 * fabs(b1) + 0.002);
            CHECK(fabs(b4) <= 0.03);
        }

    /* 3. one small bright cap (a hotspot 30x brighter than everything else together): AMIS points
     * its last lobe at it and has less variance */
    lmb_estimate last;
    spot.caps[0].l = 4000;
    moments mc = run(&spot, LMB_GATHER_COSINE, 1024, 4, 0, 400, &s, NULL);
    moments ma = run(&spot, LMB_GATHER_AMIS, 1024, 4, 0, 400, &s, &last);
    double ang = acos(fmin(1, lmb_dot3(last.last.axis, spot.caps[0].d))) * 180 / LMB_PI;
    printf("one cap: variance classic %.5g, AMIS %.5g (ratio %.3f); last lobe %.2f deg off the cap, exponent %.1f\n",
           mc.var, ma.var, ma.var / mc.var, ang, last.last.a);
    unbiased_weights = 1;
    moments mu = run(&spot, LMB_GATHER_AMIS, 1024, 4, 0, 400, &s, NULL);
    unbiased_weights = 0;
    printf("one cap, unbiased estimate: variance %.5g (ratio to classic %.3f)\n", mu.var, mu.var / mc.var);
    CHECK(ma.var < 0.5 * mc.var);
    CHECK(mu.var < 0.5 * mc.var);
    CHECK(ang < 3.0);
    CHECK(last.last.a > 20);
    CHECK_INT(last.adapted, 3);

    /* 4. two opposite caps: a single lobe cannot fit both; defensive AMIS stays within its bound
     * E[f^2/q] <= E[f^2/(d p_cos)]: var_def <= (var_cls + E^2) / d - E^2 */
    double d = 0.1, ex2 = exact(&two);
    moments tc = run(&two, LMB_GATHER_COSINE, 1024, 4, 0, 400, &s, NULL);
    moments ta = run(&two, LMB_GATHER_AMIS, 1024, 4, 0, 400, &s, NULL);
    moments td = run(&two, LMB_GATHER_AMIS_DEFENSIVE, 1024, 4, d, 400, &s, NULL);
    printf("two caps: variance classic %.5g, AMIS %.5g, defensive %.5g (bound %.5g)\n", tc.var, ta.var, td.var,
           (tc.var + ex2 * ex2) / d - ex2 * ex2);
    CHECK(td.var <= (tc.var + ex2 * ex2) / d - ex2 * ex2);

    /* 5. several lobes and guided gathering (issue 12): a pilot point fits a mixture to all its
     * samples (gather.lobes 2); on two opposite caps (12 degrees: a cosine sample finds each
     * with probability 0.02, so a pilot of 1024 rays sees both) it finds both, each lobe within
     * 3 degrees of its cap; a neighbour sampling d p_cos + (1 - d) G from it is unbiased (4000 seeds) and
     * has less variance than classic gathering and than unguided defensive AMIS; on a uniform
     * sky the fit says "diffuse" (no lobe) and guided gathering is classic gathering */
    {
        env two = {1.0, {make_cap(60, 0, 12, 100.0), make_cap(60, 180, 12, 100.0)}, 2, 0};
        lmb_estimator_options learn = {.method = LMB_GATHER_AMIS_DEFENSIVE, .rays = 1024, .iterations = 4,
                                       .defensive = 0.1, .unbiased = 1, .learn_lobes = 2};
        lmb_estimate pilot;
        CHECK_INT(lmb_estimate_irradiance(&learn, N, N, lmb_rng_make(99, 1, 2), env_radiance, &two, &s, &pilot),
                  LMB_OK);
        printf("two caps, learned: %u lobes, diffuse share %.3f\n", pilot.learned.count, pilot.learned.diffuse);
        CHECK_INT(pilot.learned.count, 2);
        for (int c = 0; c < 2; c++) {
            double best = 180;
            for (uint32_t k = 0; k < pilot.learned.count; k++) {
                double ang = acos(fmin(1, lmb_dot3(pilot.learned.lobe[k].axis, two.caps[c].d))) * 180 / LMB_PI;
                best = fmin(best, ang);
            }
            printf("  cap %d: nearest lobe %.2f deg off\n", c, best);
            CHECK(best < 3.0);
        }
        lmb_estimator_options g = learn;
        g.learn_lobes = 0;
        g.guide = &pilot.learned;
        CHECK(lmb_estimator_guided(&g));
        double sum = 0, sum2 = 0, ex = exact(&two);
        const int seeds = 4000;
        for (int k = 0; k < seeds; k++) {
            lmb_estimate est;
            g.rays = 256;
            lmb_estimate_irradiance(&g, N, N, lmb_rng_make(7, (uint64_t)k, 3), env_radiance, &two, &s, &est);
            sum += est.e[0];
            sum2 += est.e[0] * est.e[0];
        }
        double mean = sum / seeds, var = (sum2 - sum * mean) / (seeds - 1), se = sqrt(var / seeds);
        unbiased_weights = 1;
        moments cl = run(&two, LMB_GATHER_COSINE, 256, 4, 0.1, 400, &s, NULL);
        moments un = run(&two, LMB_GATHER_AMIS_DEFENSIVE, 256, 4, 0.1, 400, &s, NULL);
        unbiased_weights = 0;
        printf("two caps, guided: mean %.5f exact %.5f (%+.2f SE), variance %.4g (classic %.4g, unguided %.4g)\n",
               mean, ex, (mean - ex) / se, var, cl.var, un.var);
        CHECK(fabs(mean - ex) <= 3 * se);
        CHECK(var < 0.5 * cl.var);
        CHECK(var < 0.5 * un.var);

        CHECK_INT(lmb_estimate_irradiance(&learn, N, N, lmb_rng_make(99, 1, 2), env_radiance, &sky, &s, &pilot),
                  LMB_OK);
        printf("uniform sky, learned: %u lobes, diffuse share %.3f\n", pilot.learned.count, pilot.learned.diffuse);
        CHECK_INT(pilot.learned.count, 0);
        CHECK(pilot.learned.diffuse == 1.0);
    }

    /* 6. variance-aware shares: on one small cap, the shares given to the iterations sum to 1
     * and favour the adapted iterations */
    {
        lmb_estimator_options o = {.method = LMB_GATHER_AMIS_DEFENSIVE, .rays = 1024, .iterations = 4,
                                   .defensive = 0.1, .unbiased = 1};
        lmb_estimate est;
        lmb_estimate_irradiance(&o, N, N, lmb_rng_make(5, 1, 2), env_radiance, &spot, &s, &est);
        double total = 0;
        for (int t = 0; t < 4; t++)
            total += est.share[t];
        printf("one cap, iteration shares %.3f %.3f %.3f %.3f\n", est.share[0], est.share[1], est.share[2],
               est.share[3]);
        CHECK(fabs(total - 1) < 1e-12);
        CHECK(est.share[0] < est.share[3]);
    }

    /* 7. nothing seen: E = 0, no adaptation, the cosine lobe stays */
    env dark = {0.0, {{{0, 0, 1}, 2.0, 0}}, 0, 0};
    lmb_estimator_options o = {.method = LMB_GATHER_AMIS, .rays = 256, .iterations = 4};
    lmb_estimate z;
    lmb_estimate_irradiance(&o, N, N, lmb_rng_make(1, 2, 3), env_radiance, &dark, &s, &z);
    CHECK(z.e[0] == 0 && z.e[1] == 0 && z.e[2] == 0);
    CHECK_INT(z.adapted, 0);
    CHECK(z.last.a == 1.0 && z.last.axis[2] == 1.0);

    /* 8. below the geometric normal nothing is traced: a tilted ng halves the rays */
    double ng[3] = {1, 0, 0};
    dark.calls = 0;
    lmb_estimate_irradiance(&o, N, ng, lmb_rng_make(1, 2, 3), env_radiance, &dark, &s, &z);
    printf("ng tilted 90 degrees: %u of 256 rays traced\n", z.traced);
    CHECK_INT(dark.calls, z.traced);
    CHECK(z.traced > 100 && z.traced < 156);

    lmb_estimator_scratch_free(&s);
    return check_failures();
}
