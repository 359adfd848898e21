/*
 * The denoiser (baker/post/denoise.h) on lightmaps whose truth is known, a 64 x 48 atlas of
 * texels 1 cm apart on the floor (instance 0) and, in columns 48 and up, a wall (instance 1,
 * facing +x) that the atlas puts right beside it:
 *   - a linear ramp of light without noise comes out as it went in, borders included (the
 *     plane fit; a weighted mean would bend it at every border);
 *   - the ramp with 5% correlated noise (blotches 4 texels wide, like the irradiance cache's
 *     records) comes out at least 3x closer to the truth, rms over the floor;
 *   - a hard shadow edge (light 1 | 0) with 2% white noise and per-texel variances: the dark
 *     side stays exactly 0 and the lit side's texels at the edge keep their mean within 2%;
 *   - the wall's light (10x the floor's) does not leak onto the floor beside it, or back;
 *   - 1 and 2 threads give the same bytes;
 *   - as steps of a local bake (denoise_steps.h: ranges of 64k texels, each level written back
 *     while later ranges are filtered) over a 420 x 400 atlas with gaps and the 64 x 48 one, the
 *     light is the same bytes as each atlas filtered whole (lmb_denoise_atlas), both with a
 *     noise level and with per-texel variances.
 */
#include "check.h"

#include "post/denoise.h"
#include "post/denoise_steps.h"
#include "util/rng.h"

#include <stdlib.h>

#define W 64
#define H 48
#define WALL_X 48

typedef struct atlas {
    lmb_texels t;
    uint32_t texel[W * H];
    uint8_t valid[W * H];
    float size[W * H];
    lmb_gather_point points[W * H];
} atlas;

/* Every texel listed and valid; floor at z = 0 up to column WALL_X, the wall beyond it. */
static void make_atlas(atlas *a)
{
    memset(a, 0, sizeof *a);
    for (uint32_t i = 0; i < W * H; i++) {
        uint32_t x = i % W, y = i / W;
        a->texel[i] = i;
        a->valid[i] = 1;
        a->size[i] = 0.01f;
        lmb_gather_point *p = &a->points[i];
        if (x < WALL_X) {
            p->p[0] = 0.01 * x, p->p[1] = 0.01 * y, p->p[2] = 0;
            p->n[2] = p->ng[2] = 1;
            p->instance = 0;
        } else {
            p->p[0] = 1.0, p->p[1] = 0.01 * y, p->p[2] = 0.01 * (x - WALL_X);
            p->n[0] = p->ng[0] = 1;
            p->instance = 1;
        }
    }
    a->t.width = W, a->t.height = H, a->t.samples = 1, a->t.count = W * H;
    a->t.texel = a->texel, a->t.valid = a->valid, a->t.texel_size = a->size, a->t.points = a->points;
}

static float ramp(uint32_t x, uint32_t y)
{
    return x < WALL_X ? 1.0f + 0.02f * (float)x + 0.01f * (float)y : 10.0f;
}

static void set_grey(float *rgb, uint32_t i, float v)
{
    rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = v;
}

static void test_ramp_kept(void)
{
    static atlas a;
    make_atlas(&a);
    static float rgb[3 * W * H];
    for (uint32_t i = 0; i < W * H; i++)
        set_grey(rgb, i, ramp(i % W, i / W));
    lmb_denoise_options opt = {4, 0.05, NULL, 2, 1};
    lmb_denoise_stats st = {0};
    lmb_error err = {0};
    CHECK_INT(lmb_denoise_atlas(&a.t, rgb, &opt, &st, &err), LMB_OK);
    double worst = 0;
    for (uint32_t i = 0; i < W * H; i++) {
        double d = fabs(rgb[3 * i + 1] / ramp(i % W, i / W) - 1);
        worst = d > worst ? d : worst;
    }
    CHECK(worst < 1e-5);
    CHECK_INT(st.texels, W * H);
}

/* Noise that is constant over blocks of 4 x 4 texels (a record's error copied to what it serves). */
static float blotch(uint32_t x, uint32_t y, double amount)
{
    lmb_rng r = lmb_rng_make(11, x / 4, y / 4);
    double u = lmb_rng_next(&r) + lmb_rng_next(&r) + lmb_rng_next(&r) - 1.5; /* variance 1/4 */
    return (float)(1 + 2 * amount * u);
}

static void test_blotches_removed(void)
{
    static atlas a;
    make_atlas(&a);
    static float rgb[3 * W * H];
    double before = 0, after = 0;
    for (uint32_t i = 0; i < W * H; i++) {
        float truth = ramp(i % W, i / W), v = truth * blotch(i % W, i / W, 0.05);
        set_grey(rgb, i, v);
        if (i % W < WALL_X)
            before += (v / truth - 1) * (v / truth - 1);
    }
    lmb_denoise_options opt = {4, 0.05, NULL, 2, 1};
    lmb_denoise_stats st = {0};
    lmb_error err = {0};
    CHECK_INT(lmb_denoise_atlas(&a.t, rgb, &opt, &st, &err), LMB_OK);
    for (uint32_t i = 0; i < W * H; i++) {
        float truth = ramp(i % W, i / W);
        if (i % W < WALL_X)
            after += (rgb[3 * i] / truth - 1) * (rgb[3 * i] / truth - 1);
    }
    before = sqrt(before / (WALL_X * H));
    after = sqrt(after / (WALL_X * H));
    printf("blotches of 5%%: rms %.3f%% before, %.3f%% after\n", 100 * before, 100 * after);
    CHECK(before > 0.03);
    CHECK(after < before / 3);
}

static void test_shadow_edge(int threads, float *out)
{
    static atlas a;
    make_atlas(&a);
    static float rgb[3 * W * H], var[W * H];
    for (uint32_t i = 0; i < W * H; i++) {
        uint32_t x = i % W, y = i / W;
        lmb_rng r = lmb_rng_make(5, x, y);
        double u = lmb_rng_next(&r) + lmb_rng_next(&r) + lmb_rng_next(&r) - 1.5;
        int lit = x < 24 || x >= WALL_X;
        set_grey(rgb, i, lit ? (float)(1 + 0.04 * u) : 0.0f);
        var[i] = lit ? 0.02f * 0.02f : 0.0f;
    }
    lmb_denoise_options opt = {2, 0, var, 2, threads};
    lmb_denoise_stats st = {0};
    lmb_error err = {0};
    CHECK_INT(lmb_denoise_atlas(&a.t, rgb, &opt, &st, &err), LMB_OK);
    int dark_changed = 0;
    double edge = 0;
    for (uint32_t y = 0; y < H; y++) {
        for (uint32_t x = 24; x < WALL_X; x++)
            dark_changed += rgb[3 * (y * W + x)] != 0.0f;
        edge += rgb[3 * (y * W + 23)];
    }
    CHECK_INT(dark_changed, 0);
    CHECK_NEAR(edge / H, 1.0, 0.02);
    memcpy(out, rgb, sizeof rgb);
}

static void test_no_leak_across_surfaces(void)
{
    static atlas a;
    make_atlas(&a);
    static float rgb[3 * W * H];
    for (uint32_t i = 0; i < W * H; i++)
        set_grey(rgb, i, i % W < WALL_X ? 1.0f * blotch(i % W, i / W, 0.05) : 10.0f);
    lmb_denoise_options opt = {4, 1.0, NULL, 100, 1}; /* a light term that stops nothing */
    lmb_denoise_stats st = {0};
    lmb_error err = {0};
    CHECK_INT(lmb_denoise_atlas(&a.t, rgb, &opt, &st, &err), LMB_OK);
    float floor_most = 0, wall_least = 100;
    for (uint32_t i = 0; i < W * H; i++) {
        if (i % W < WALL_X)
            floor_most = rgb[3 * i] > floor_most ? rgb[3 * i] : floor_most;
        else
            wall_least = rgb[3 * i] < wall_least ? rgb[3 * i] : wall_least;
    }
    CHECK(floor_most < 1.1f);
    CHECK_NEAR(wall_least, 10.0, 1e-5);
}

/* A 420 x 400 floor (1 cm texels) whose listed texels skip a pattern of atlas texels, with
 * ripples and 5% noise: more texels than a range of a streamed step, so a level is written
 * back while later ranges are filtered. Owned arrays: free_big. */
#define BW 420
#define BH 400
typedef struct big {
    lmb_texels t;
    float *rgb, *var;
} big;

static void make_big(big *b)
{
    memset(b, 0, sizeof *b);
    uint32_t n = 0;
    b->t.texel = malloc(sizeof(uint32_t) * BW * BH);
    b->t.valid = malloc(BW * BH);
    b->t.texel_size = malloc(sizeof(float) * BW * BH);
    b->t.points = calloc(BW * BH, sizeof(lmb_gather_point));
    b->rgb = malloc(3 * sizeof(float) * BW * BH);
    b->var = malloc(sizeof(float) * BW * BH);
    for (uint32_t y = 0; y < BH; y++)
        for (uint32_t x = 0; x < BW; x++) {
            if ((x * 7 + y * 3) % 11 == 0)
                continue; /* not listed */
            lmb_rng r = lmb_rng_make(9, x, y);
            b->t.texel[n] = y * BW + x;
            b->t.valid[n] = (x + y) % 17 != 0;
            b->t.texel_size[n] = 0.01f;
            lmb_gather_point *p = &b->t.points[n];
            p->p[0] = 0.01 * x, p->p[1] = 0.01 * y;
            p->n[2] = p->ng[2] = 1;
            p->instance = x < BW / 2 ? 0 : 1;
            set_grey(b->rgb, n, (float)((1 + 0.3 * sin(0.37 * x) * cos(0.23 * y)) * (1 + 0.1 * (lmb_rng_next(&r) - 0.5))));
            b->var[n] = 0.03f * 0.03f;
            n++;
        }
    b->t.width = BW, b->t.height = BH, b->t.samples = 1, b->t.count = n;
}

static void free_big(big *b)
{
    free(b->t.texel);
    free(b->t.valid);
    free(b->t.texel_size);
    free(b->t.points);
    free(b->rgb);
    free(b->var);
}

static void test_steps_match_whole(int with_variance)
{
    big b;
    make_big(&b);
    static atlas a;
    make_atlas(&a);
    static float small[3 * W * H], small_whole[3 * W * H];
    for (uint32_t i = 0; i < W * H; i++)
        set_grey(small, i, blotch(i % W, i / W, 0.05));
    memcpy(small_whole, small, sizeof small);
    size_t bytes = 3 * sizeof(float) * b.t.count;
    float *whole = malloc(bytes);
    memcpy(whole, b.rgb, bytes);
    lmb_error err = {0};
    lmb_denoise_stats st = {0}, st_whole = {0};
    lmb_denoise_options opt = {3, 0.05, with_variance ? b.var : NULL, 2, 2};
    CHECK_INT(lmb_denoise_atlas(&b.t, whole, &opt, &st_whole, &err), LMB_OK);
    lmb_denoise_options opt_small = {3, 0.05, NULL, 2, 2};
    CHECK_INT(lmb_denoise_atlas(&a.t, small_whole, &opt_small, &st_whole, &err), LMB_OK);

    lmb_steps *steps;
    CHECK_INT(lmb_steps_create(LMB_STEPS_LOCAL, NULL, NULL, 0, 0, 1, 0.0, NULL, &steps, &err), LMB_OK);
    lmb_denoise_part parts[2] = {{&b.t, b.rgb, with_variance ? b.var : NULL, 0.05}, {&a.t, small, NULL, 0.05}};
    lmb_denoise_run run = {3, 2, 2, "test light"};
    CHECK_INT(lmb_denoise_steps(steps, parts, 2, &run, &st, &err), LMB_OK);
    CHECK_INT(lmb_steps_count(steps), 3);
    CHECK(b.t.count > 2 * LMB_STEP_STREAM_ITEMS);
    CHECK(memcmp(whole, b.rgb, bytes) == 0);
    CHECK(memcmp(small_whole, small, sizeof small) == 0);
    CHECK_INT(st.texels, st_whole.texels);
    CHECK(memcmp(whole, b.rgb, bytes) != 0 || st.before != st.after); /* it did filter */
    lmb_steps_free(steps);
    free(whole);
    free_big(&b);
}

int main(void)
{
    test_ramp_kept();
    test_blotches_removed();
    static float one[3 * W * H], two[3 * W * H];
    test_shadow_edge(1, one);
    test_shadow_edge(2, two);
    CHECK(memcmp(one, two, sizeof one) == 0);
    test_no_leak_across_surfaces();
    test_steps_match_whole(0);
    test_steps_match_whole(1);
    return check_failures();
}
