/*
 * Probe light (see probes.h). At each probe, rounds of probes.rays directions of a spherical
 * Fibonacci lattice (sphere.h; each round after the first rotated at random) see: the sky where they leave the level, and where they hit a lightmapped
 * surface its outgoing diffuse radiance B = albedo / pi x E from the finished bounce cache (a
 * surface without a lightmap: its direct light, one bounce, as the final gather does); back
 * faces are black. With L(w) so sampled,
 *   L_lm = 4 pi / n sum_i L(w_i) Y_lm(w_i) + sum_delta E_delta Y_lm(w_delta)
 *          + 1 / m sum_j Le(w_j) Y_lm(w_j) / pdf(w_j)
 * (delta lights, which no ray hits, as their direction and the irradiance they bring; emitters
 * by m points sampled on them, since a lamp small in the probe's sky is hit by few of the fixed
 * rays), and the SH irradiance is E_lm = A_l L_lm (Ramamoorthi and Hanrahan 2001, eq. 8).
 * The ambient cube's six irradiances are computed for each axis normal n directly: the direct
 * light of every light and the sky at a point facing n, by the direct stage's own estimator
 * (lmb_direct_at_split: shadow rays, area-light and sky sampling with MIS; minus the `indirect`
 * lights' part), plus 4 pi / n sum_i B(w_i) max(0, n . w_i) over the rays that hit surfaces.
 * Rounds are added until the mean radiance's relative standard error is within samples.noise
 * (ray_rounds), as texels sample adaptively. Random numbers (rotations, area lights, the sky's
 * map) are keyed by (seed, probe, round or axis): a probe's values do not depend on threads or
 * on how a farm splits the probes.
 */
#include "probes.h"
#include "sphere.h"

#include "cache/back_light.h"

#include "util/lmb_math.h"
#include "util/mat4.h"
#include "util/rng.h"
#include "util/sh.h"

#include <omp.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CUBE_SAMPLES 16     /* direct-light samples per axis of the ambient cube (area lights, sky): samples.direct's default */
#define EMITTER_SAMPLES 64  /* points on emitters per probe for the SH (a small lamp is hit by few rays) */

static const double axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

typedef struct probe_job {
    const lmb_probe_set *set;
    const lmb_config *cfg;
    const lmb_direct *direct;
    const lmb_cache *cache;
    int threads;
} probe_job;

typedef struct delta_sum {
    double l[9][3]; /* radiance SH (not yet convolved) */
} delta_sum;

static void add_delta(void *user, const double dir[3], const double e[3])
{
    delta_sum *d = user;
    double y[9];
    lmb_sh9(dir[0], dir[1], dir[2], y);
    for (int k = 0; k < 9; k++)
        for (int c = 0; c < 3; c++)
            d->l[k][c] += e[c] * y[k];
}

/* The transform taking the lattice to round r's own directions (round 0: none): Shoemake's
 * uniform random unit quaternion, keyed by (seed, probe, round). */
static void round_rotation(const probe_job *job, uint32_t i, uint32_t r, double m[16])
{
    if (r == 0) {
        lmb_mat4_identity(m);
        return;
    }
    lmb_rng rng = lmb_rng_make(job->cfg->seed, 0x524f544eull ^ i, r);
    double u1 = lmb_rng_next(&rng), u2 = 2 * LMB_PI * lmb_rng_next(&rng), u3 = 2 * LMB_PI * lmb_rng_next(&rng);
    double a = sqrt(1 - u1), b = sqrt(u1);
    const double q[4] = {a * sin(u2), a * cos(u2), b * sin(u3), b * cos(u3)}, zero[3] = {0, 0, 0}, one[3] = {1, 1, 1};
    lmb_mat4_from_trs(zero, q, one, m);
}

/* The light hit h reflects toward the probe at p (0 from the back of a one-sided face): the cache's,
 * direct light there for a surface without a lightmap, or the back of a doubleSided one's own. */
static inline void reflected(const probe_job *job, uint32_t i, uint64_t stream, const double p[3], const double w[3],
                      const lmb_rt_hit *h, double b[3], uint64_t *rays)
{
    const lmb_rt *rt = job->cache->rt;
    b[0] = b[1] = b[2] = 0;
    double albedo[3], e[3];
    lmb_hit_kind kind = lmb_cache_lookup(job->cache, h, albedo, e);
    double through[3], other[3] = {e[0], e[1], e[2]}; /* a back hit's: the front's light */
    int passes = job->cache->diffuse_through && lmb_cache_diffuse_through(job->cache, h, through) > 0;
    if (kind == LMB_HIT_BACK) { /* a back that reflects: its light estimated where the ray met it */
        lmb_rng rng = lmb_rng_make(job->cfg->seed, 0x50524f42ull ^ i, stream);
        *rays += lmb_cache_back_irradiance(job->cache, job->direct, h, p, w, 0, &rng, e);
    } else if (kind == LMB_HIT_CACHED && passes) { /* the back's light it lets through, estimated there */
        lmb_rng rng = lmb_rng_make(job->cfg->seed, 0x44494646ull ^ i, stream);
        *rays += lmb_cache_back_irradiance(job->cache, job->direct, h, p, w, 0, &rng, other);
    }
    if (kind == LMB_HIT_UNMAPPED) {
        lmb_shading_point y;
        for (int k = 0; k < 3; k++) {
            y.p[k] = p[k] + h->t * w[k];
            y.n[k] = y.ng[k] = h->ng[k];
        }
        y.eps = 4 * rt->eps;
        lmb_rng rng = lmb_rng_make(job->cfg->seed, 0x50524f42ull ^ i, stream);
        *rays += lmb_direct_at(job->direct, &y, 1, &rng, e, NULL);
    }
    if (kind != LMB_HIT_DARK)
        for (int c = 0; c < 3; c++)
            b[c] = albedo[c] * e[c] + (passes && kind != LMB_HIT_UNMAPPED ? through[c] * other[c] : 0.0);
}

/* Radiance l and reflected light b arriving at the probe at p along w through the surfaces light
 * partly passes (layers) before the hit h (hit: 0 for the sky): each adds what its covered share
 * reflects, seen through the ones before it. */
static void layered(const probe_job *job, uint32_t i, uint64_t stream, const double p[3], const double w[3], int hit,
                    const lmb_rt_hit *h, const lmb_rt_layer *layers, uint32_t nl, const lmb_sky *sky, double l[3],
                    double b[3], uint64_t *rays)
{
    double through[3] = {1, 1, 1}, hb[3];
    for (uint32_t q = 0; q <= nl; q++) {
        const lmb_rt_hit *at = q < nl ? &layers[q].hit : h;
        double cover = q < nl ? layers[q].cover : 1.0;
        if (q == nl && !hit) {
            if (sky) {
                lmb_sky_radiance(sky, w, hb);
                for (int c = 0; c < 3; c++)
                    l[c] += through[c] * hb[c];
            }
            return;
        }
        reflected(job, i, stream, p, w, at, hb, rays);
        for (int c = 0; c < 3; c++) { /* emitters' own light: sampled on them below */
            b[c] += through[c] * cover * hb[c];
            l[c] += through[c] * cover * hb[c];
            if (q < nl)
                through[c] *= layers[q].pass[c];
        }
    }
}

/* One round: the n lattice directions (rotated by m) traced from probe i, their radiance's SH
 * and the reflected light's cube added to sum and cube (each round weighted 4 pi / n), and the
 * mean radiance of the even and the odd directions (two interleaved half lattices) into half.
 * Returns the rays traced. */
static uint64_t trace_round(const probe_job *job, uint32_t i, uint32_t r, const double m[16], delta_sum *sum,
                            double cube[6][3], double half[2])
{
    const lmb_rt *rt = job->cache->rt;
    const double *p = job->set->position + 3 * (size_t)i;
    const lmb_sky *sky = lmb_direct_sky(job->direct);
    uint32_t n = job->set->rays;
    uint64_t rays = 0;
    half[0] = half[1] = 0;
    for (uint32_t j = 0; j < n; j++) {
        double v[3], w[3], l[3] = {0, 0, 0}, b[3] = {0, 0, 0};
        lmb_sphere_direction(j, n, v);
        lmb_mat4_vector(m, v, w);
        lmb_rt_hit h;
        lmb_rt_layer layers[LMB_RT_MAX_LAYERS];
        uint32_t nl;
        rays++;
        if (!rt->partial_geoms) { /* nothing light passes in part: the closest hit alone */
            if (!lmb_rt_intersect(rt, p, w, rt->eps, 1e300, &h)) {
                if (sky)
                    lmb_sky_radiance(sky, w, l);
            } else {
                reflected(job, i, (uint64_t)r * n + j, p, w, &h, b, &rays);
                for (int c = 0; c < 3; c++) /* emitters' own light: sampled on them below */
                    l[c] = b[c];
            }
        } else {
            int hit = lmb_rt_intersect_layers(rt, p, w, rt->eps, 1e300, &h, layers, &nl);
            layered(job, i, (uint64_t)r * n + j, p, w, hit, &h, layers, nl, sky, l, b, &rays);
        }
        double y[9];
        lmb_sh9(w[0], w[1], w[2], y);
        for (int k = 0; k < 9; k++)
            for (int c = 0; c < 3; c++)
                sum->l[k][c] += 4 * LMB_PI / n * l[c] * y[k];
        for (int a = 0; a < 6; a++) {
            double cosang = axes[a][0] * w[0] + axes[a][1] * w[1] + axes[a][2] * w[2];
            for (int c = 0; cosang > 0 && c < 3; c++)
                cube[a][c] += 4 * LMB_PI / n * b[c] * cosang;
        }
        half[j & 1] += lmb_luminance(l) / (0.5 * n);
    }
    return rays;
}

/* Rounds of probes.rays directions until the mean radiance's relative standard error is within
 * samples.noise or samples.max_rays are spent (samples.adaptive; else one round). The error of
 * one round: the difference of its two interleaved half lattices (two estimates of the mean,
 * var(mean) ~ (h1 - h2)^2 / 4); of R > 1 rounds: the rounds' own spread, var / R. */
static uint32_t ray_rounds(const probe_job *job, uint32_t i, delta_sum *sum, double cube[6][3], uint64_t *rays)
{
    const lmb_config *cfg = job->cfg;
    uint32_t n = job->set->rays, most = cfg->adaptive ? (cfg->max_rays > n ? cfg->max_rays / n : 1) : 1;
    double means[64], first_half[2] = {0, 0};
    most = most > 64 ? 64 : most;
    uint32_t r = 0;
    while (r < most) {
        double m[16], half[2];
        round_rotation(job, i, r, m);
        *rays += trace_round(job, i, r, m, sum, cube, half);
        means[r] = 0.5 * (half[0] + half[1]);
        if (r == 0)
            memcpy(first_half, half, sizeof half);
        r++;
        double mean = 0, var = 0;
        for (uint32_t k = 0; k < r; k++)
            mean += means[k] / r;
        if (r == 1) {
            var = 0.25 * (first_half[0] - first_half[1]) * (first_half[0] - first_half[1]);
        } else {
            for (uint32_t k = 0; k < r; k++)
                var += (means[k] - mean) * (means[k] - mean) / (r - 1);
            var /= r;
        }
        if (mean <= 0 || sqrt(var) <= cfg->noise_target * mean)
            break;
    }
    return r;
}

/* One probe's 45 floats (SH then cube) into out; returns the rays traced. */
static uint64_t light_probe(const probe_job *job, uint32_t i, float *out, uint32_t *rounds)
{
    const lmb_rt *rt = job->cache->rt;
    const double *p = job->set->position + 3 * (size_t)i;
    delta_sum sum;
    double cube[6][3];
    memset(&sum, 0, sizeof sum);
    memset(cube, 0, sizeof cube);
    uint64_t rays = 0;
    uint32_t r = ray_rounds(job, i, &sum, cube, &rays);
    *rounds = r;
    for (int k = 0; k < 9; k++) /* each round summed at weight 4 pi / n: their mean */
        for (int c = 0; c < 3; c++)
            sum.l[k][c] /= r;
    for (int a = 0; a < 6; a++)
        for (int c = 0; c < 3; c++)
            cube[a][c] /= r;
    rays += lmb_direct_deltas_at(job->direct, p, add_delta, &sum);
    lmb_rng erng = lmb_rng_make(job->cfg->seed, 0x454d4954ull ^ i, 0);
    rays += lmb_direct_emitter_samples_at(job->direct, p, EMITTER_SAMPLES, &erng, add_delta, &sum);
    for (int a = 0; a < 6; a++) {
        lmb_shading_point sp;
        for (int k = 0; k < 3; k++) {
            sp.p[k] = p[k];
            sp.n[k] = sp.ng[k] = axes[a][k];
        }
        sp.eps = rt->eps;
        lmb_rng rng = lmb_rng_make(job->cfg->seed, 0x43554245ull ^ i, (uint64_t)a);
        double e[3], deferred[3] = {0, 0, 0};
        rays += lmb_direct_at_split(job->direct, &sp, CUBE_SAMPLES, &rng, e, NULL, deferred);
        for (int c = 0; c < 3; c++)
            cube[a][c] += fmax(0.0, e[c] - deferred[c]);
    }
    for (int k = 0; k < 9; k++)
        for (int c = 0; c < 3; c++)
            out[3 * k + c] = (float)(lmb_sh_cosine_band(k) * sum.l[k][c]);
    for (int a = 0; a < 6; a++)
        for (int c = 0; c < 3; c++)
            out[LMB_PROBE_SH + 3 * a + c] = (float)cube[a][c];
    return rays;
}

#define PROBE_FLOATS (LMB_PROBE_SH + LMB_PROBE_CUBE)

static lmb_status probe_range(void *user, uint64_t first, uint64_t last, lmb_buf *out,
                              uint64_t counters[LMB_STEP_COUNTERS], lmb_error *err)
{
    const probe_job *job = user;
    float *v = lmb_buf_extend(out, (size_t)(last - first) * PROBE_FLOATS * sizeof *v, err);
    if (!v)
        return err->status;
    uint64_t rays = 0, more = 0;
#pragma omp parallel num_threads(job->threads) reduction(+ : rays, more)
    {
        lmb_rt_thread_init();
#pragma omp for schedule(dynamic, 4)
        for (uint64_t i = first; i < last; i++) {
            float values[PROBE_FLOATS];
            uint32_t rounds;
            rays += light_probe(job, (uint32_t)i, values, &rounds);
            more += rounds > 1;
            memcpy(v + (i - first) * PROBE_FLOATS, values, sizeof values);
        }
    }
    counters[0] += rays;
    counters[1] += last - first;
    counters[2] += more;
    return LMB_OK;
}

lmb_status lmb_probes_light(lmb_probe_set *set, const lmb_config *cfg, const lmb_direct *direct,
                            const lmb_cache *cache, lmb_steps *steps, int dark, lmb_progress_fn progress, void *user,
                            const lmb_log *log, lmb_error *err)
{
    if (!set->count || dark) /* nothing emits: every probe is 0 (the arrays are zeroed) */
        return LMB_OK;
    if (progress)
        progress(user, "probes", 0, set->count);
    probe_job job = {set, cfg, direct, cache, cfg->threads > 0 ? (int)cfg->threads : omp_get_max_threads()};
    lmb_step_desc d = {"probes", set->count, NULL, (double)set->count * (set->rays + 6.0 * CUBE_SAMPLES), probe_range,
                       &job};
    lmb_buf bytes = {NULL, 0, 0, 0};
    uint64_t counters[LMB_STEP_COUNTERS];
    lmb_status st = lmb_steps_run(steps, &d, &bytes, counters, err);
    if (st == LMB_OK && bytes.size != (size_t)set->count * PROBE_FLOATS * sizeof(float))
        st = lmb_error_set(err, LMB_ERR_INPUT, "probes: the step holds %zu bytes for %u probes", bytes.size, set->count);
    for (uint32_t i = 0; st == LMB_OK && i < set->count; i++) {
        const float *v = (const float *)bytes.data + (size_t)i * PROBE_FLOATS;
        memcpy(set->sh + (size_t)i * LMB_PROBE_SH, v, LMB_PROBE_SH * sizeof *v);
        memcpy(set->cube + (size_t)i * LMB_PROBE_CUBE, v + LMB_PROBE_SH, LMB_PROBE_CUBE * sizeof *v);
    }
    lmb_buf_free(&bytes);
    if (st == LMB_OK && cfg->adaptive)
        lmb_info(log, "probes: %.0f rays per probe on average; %llu of %u probes took more than one round of %u "
                 "(samples.noise %g, at most samples.max_rays %u)", (double)counters[0] / set->count,
                 (unsigned long long)counters[2], set->count, set->rays, cfg->noise_target, cfg->max_rays);
    if (st == LMB_OK && progress)
        progress(user, "probes", set->count, set->count);
    return st;
}
