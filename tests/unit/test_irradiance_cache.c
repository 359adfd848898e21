/*
 * Irradiance-cache records (baker/irradiance_cache/records.h) on hand-made record sets:
 *   - a constant field on a plane interpolates to that constant everywhere (to 1e-12);
 *   - at a corner, points on the floor never use the wall's records (normals 90 degrees
 *     apart) although they lie within the wall records' reach, and the other side of a thin
 *     wall (normal facing away) is never used either;
 *   - a record above a point, on a parallel shelf, is not used for the floor under it;
 *   - gradients fitted from neighbours recover a linear field's slope (within 1%), and the
 *     interpolation then reproduces the field between records (within 1%);
 *   - neighbour clamping: a record's harmonic distance ends at most a neighbour's plus the
 *     distance between them;
 *   - the two facts that let later placement rounds skip candidates (ic_pass.c,
 *     uncovered_again): on random record sets, clamping never grows a reach, and a record's
 *     weight at any point never grows when its reach shrinks, so a weight sum falls only
 *     where a reach shrank;
 *   - the texels a record serves (lmb_ic_add_shares, what sets its rays when gathered again):
 *     a lone record that reaches only its own point serves exactly 1; on a floor grid every
 *     point gives out 1 in all (to the rounding), an inner record serves the points per record,
 *     and a parallel sweep gives the same integers as a serial one.
 */
#include "check.h"

#include "irradiance_cache/records.h"

#include <math.h>
#include <stdlib.h>
#include <stdint.h>

static lmb_ic_record rec(double x, double y, double z, double nx, double ny, double nz, double e, double reach)
{
    lmb_ic_record r;
    memset(&r, 0, sizeof r);
    r.p[0] = x;
    r.p[1] = y;
    r.p[2] = z;
    r.n[0] = nx;
    r.n[1] = ny;
    r.n[2] = nz;
    r.e[0] = r.e[1] = r.e[2] = e;
    r.r = r.r_min = r.r_max = reach;
    r.harmonic = reach / 0.3;
    return r;
}

/* Floor z = 0 (normal +z) on a grid of spacing h, value f(x, y). */
static void floor_grid(lmb_ic_records *s, double h, int n, double (*f)(double, double))
{
    lmb_error err;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            lmb_ic_record r = rec(i * h, j * h, 0, 0, 0, 1, f(i * h, j * h), 1.5 * h);
            CHECK(lmb_ic_records_append(s, &r, 1, &err) == LMB_OK);
        }
}

static double constant(double x, double y)
{
    (void)x;
    (void)y;
    return 3.5;
}

static double linear(double x, double y)
{
    return 2.0 + 0.5 * x - 0.25 * y;
}

static void test_constant_plane(void)
{
    lmb_ic_records s;
    lmb_error err;
    lmb_ic_records_init(&s, 0.3);
    floor_grid(&s, 0.1, 20, constant);
    CHECK(lmb_ic_records_index(&s, 0, &err) == LMB_OK);
    CHECK(lmb_ic_records_fit_gradients(&s, 1, &err) == LMB_OK);
    double n[3] = {0, 0, 1}, worst = 0;
    for (int k = 0; k < 400; k++) {
        double p[3] = {0.0123 + 0.0047 * k, 0.05 + 0.0041 * k, 0}, e[3];
        double sum = lmb_ic_interpolate(&s, p, n, e);
        CHECK(sum > 0);
        worst = fmax(worst, fabs(e[0] - 3.5));
    }
    CHECK(worst < 1e-12);
    lmb_ic_records_free(&s);
}

static void test_corner_and_facing_away(void)
{
    lmb_ic_records s;
    lmb_error err;
    lmb_ic_records_init(&s, 0.3);
    lmb_ic_record r[] = {
        rec(0.5, 0.5, 0, 0, 0, 1, 1.0, 0.3),      /* floor */
        rec(0.5, 0.0, 0.05, 0, 1, 0, 100.0, 0.3), /* the wall at y = 0, facing +y, close to the floor */
        rec(0.5, 0.5, -0.01, 0, 0, -1, 50.0, 0.3), /* under a thin floor, facing down */
        rec(0.5, 0.5, 0.1, 0, 0, 1, 7.0, 0.3),    /* a shelf 10 cm above, facing up */
    };
    CHECK(lmb_ic_records_append(&s, r, 4, &err) == LMB_OK);
    CHECK(lmb_ic_records_index(&s, 0, &err) == LMB_OK);
    double up[3] = {0, 0, 1};
    /* floor points near the corner: within the wall record's reach, never its value */
    for (int k = 0; k < 10; k++) {
        double p[3] = {0.45 + 0.01 * k, 0.3 + 0.01 * k, 0}, e[3];
        CHECK(lmb_ic_weight(&s, &s.rec[1], p, up) == 0);
        CHECK(lmb_ic_weight(&s, &s.rec[2], p, up) == 0);
        CHECK(lmb_ic_weight(&s, &s.rec[3], p, up) == 0); /* the shelf: p lies behind its plane */
        CHECK(lmb_ic_interpolate(&s, p, up, e) > 0);
        CHECK_NEAR(e[0], 1.0, 1e-12);
    }
    lmb_ic_records_free(&s);
}

static void test_gradients(void)
{
    lmb_ic_records s;
    lmb_error err;
    lmb_ic_records_init(&s, 0.3);
    floor_grid(&s, 0.1, 20, linear);
    CHECK(lmb_ic_records_index(&s, 0, &err) == LMB_OK);
    CHECK(lmb_ic_records_fit_gradients(&s, 2, &err) == LMB_OK);
    const lmb_ic_record *mid = &s.rec[10 * 20 + 10];
    CHECK_NEAR(mid->grad_t[0][0], 0.5, 0.005);
    CHECK_NEAR(mid->grad_t[0][1], -0.25, 0.0025);
    CHECK_NEAR(mid->grad_t[0][2], 0.0, 1e-9);
    double n[3] = {0, 0, 1}, worst = 0;
    for (int k = 0; k < 200; k++) { /* inside the grid, off the records */
        double x = 0.3 + 0.0061 * k, y = 0.35 + 0.0057 * k, p[3] = {x, y, 0}, e[3];
        lmb_ic_interpolate(&s, p, n, e);
        worst = fmax(worst, fabs(e[0] / linear(x, y) - 1));
    }
    CHECK(worst < 0.01);
    lmb_ic_records_free(&s);
}

static void test_neighbour_clamp(void)
{
    lmb_ic_records s;
    lmb_error err;
    lmb_ic_records_init(&s, 0.5);
    lmb_ic_record a = rec(0, 0, 0, 0, 0, 1, 1, 1.0), b = rec(0.2, 0, 0, 0, 0, 1, 1, 1.0);
    a.harmonic = 2.0;  /* reach 1.0 at error 0.5 */
    b.harmonic = 0.05; /* saw a nearby occluder that a's rays missed */
    a.r_min = b.r_min = 0.01;
    a.r_max = b.r_max = 10;
    CHECK(lmb_ic_records_append(&s, &a, 1, &err) == LMB_OK);
    CHECK(lmb_ic_records_append(&s, &b, 1, &err) == LMB_OK);
    CHECK(lmb_ic_records_index(&s, 0, &err) == LMB_OK);
    CHECK(lmb_ic_records_clamp(&s, 1, &err) == LMB_OK);
    /* records keep their lengths in single precision: 1e-7 relative */
    CHECK_NEAR(s.rec[0].harmonic, 0.25, 3e-8);
    CHECK_NEAR(s.rec[0].r, 0.125, 2e-8);
    CHECK_NEAR(s.rec[1].harmonic, 0.05, 1e-8);
    lmb_ic_records_free(&s);
}

/* A deterministic generator for the random sets below (xorshift64*). */
static double uniform(uint64_t *state)
{
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    return (double)((*state * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

static void random_unit(uint64_t *state, double n[3])
{
    double len = 0;
    do {
        for (int k = 0; k < 3; k++)
            n[k] = 2 * uniform(state) - 1;
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    } while (len < 0.1 || len > 1);
    for (int k = 0; k < 3; k++)
        n[k] /= len;
}

static void test_reach_only_shrinks(void)
{
    uint64_t state = 0x9e3779b97f4a7c15ull;
    lmb_error err;
    int weights_checked = 0, shrunk = 0, fell = 0;
    for (int set = 0; set < 20; set++) {
        lmb_ic_records s;
        lmb_ic_records_init(&s, 0.3);
        for (int i = 0; i < 200; i++) {
            double p[3] = {uniform(&state), uniform(&state), 0.2 * uniform(&state)}, n[3];
            random_unit(&state, n);
            n[2] = fabs(n[2]) + 1; /* mostly up: neighbours that see each other */
            double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            lmb_ic_record r = rec(p[0], p[1], p[2], n[0] / len, n[1] / len, n[2] / len, 1, 0);
            r.harmonic = 0.01 + 0.5 * uniform(&state);
            r.r_min = 0.005;
            r.r_max = 0.2;
            r.r = lmb_ic_reach(&s, &r);
            CHECK(lmb_ic_records_append(&s, &r, 1, &err) == LMB_OK);
        }
        CHECK(lmb_ic_records_index(&s, 0, &err) == LMB_OK);
        double before[200];
        for (int i = 0; i < 200; i++)
            before[i] = s.rec[i].r;
        CHECK(lmb_ic_records_clamp(&s, 1, &err) == LMB_OK);
        for (int i = 0; i < 200; i++) {
            CHECK(s.rec[i].r <= before[i]);
            shrunk += s.rec[i].r < before[i];
        }
        /* a record's weight at points around it, with its reach of before and of now */
        for (int i = 0; i < 200; i++)
            for (int k = 0; k < 10; k++) {
                double p[3], n[3], len = 0;
                random_unit(&state, n);
                for (int a = 0; a < 3; a++) { /* within the old reach, normal near the record's */
                    p[a] = s.rec[i].p[a] + before[i] * (uniform(&state) - 0.5);
                    n[a] = s.rec[i].n[a] + 0.3 * n[a];
                    len += n[a] * n[a];
                }
                for (int a = 0; a < 3; a++)
                    n[a] /= sqrt(len);
                lmb_ic_record then = s.rec[i];
                then.r = before[i];
                double w_then = lmb_ic_weight(&s, &then, p, n), w_now = lmb_ic_weight(&s, &s.rec[i], p, n);
                CHECK(w_now <= w_then);
                weights_checked += w_then > 0;
                fell += w_now < w_then;
            }
        lmb_ic_records_free(&s);
    }
    CHECK(shrunk > 100);           /* the sets did exercise clamping */
    CHECK(weights_checked > 1000); /* and weights that were not 0 */
    CHECK(fell > 100);             /* some of which the shrinking lowered */
}

static void test_shares(void)
{
    lmb_ic_records s;
    lmb_error err;
    lmb_ic_records_init(&s, 0.3);
    floor_grid(&s, 0.1, 20, constant);                     /* records 0..399, reach 0.15 */
    lmb_ic_record lone = rec(10, 10, 0, 0, 0, 1, 1, 0.05); /* record 400, far from the grid */
    CHECK(lmb_ic_records_append(&s, &lone, 1, &err) == LMB_OK);
    CHECK(lmb_ic_records_index(&s, 0, &err) == LMB_OK);
    enum { SIDE = 76, POINTS = SIDE * SIDE };
    uint64_t serial[401] = {0}, parallel[401] = {0};
    double n[3] = {0, 0, 1};
    /* points every 0.025 over [0, 1.9]: 16 per record of the grid */
    for (int k = 0; k < POINTS; k++) {
        double p[3] = {0.0125 + 0.025 * (k % SIDE), 0.0125 + 0.025 * (k / SIDE), 0};
        lmb_ic_add_shares(&s, p, n, serial);
    }
#pragma omp parallel for schedule(dynamic, 7)
    for (int k = 0; k < POINTS; k++) {
        double p[3] = {0.0125 + 0.025 * (k % SIDE), 0.0125 + 0.025 * (k / SIDE), 0};
        lmb_ic_add_shares(&s, p, n, parallel);
    }
    double lone_p[3] = {10, 10, 0};
    lmb_ic_add_shares(&s, lone_p, n, serial);
    lmb_ic_add_shares(&s, lone_p, n, parallel);
    CHECK(serial[400] == LMB_IC_SHARE_ONE);
    uint64_t total = 0;
    int same = 1;
    for (int k = 0; k < 401; k++) {
        total += serial[k];
        same &= serial[k] == parallel[k];
    }
    CHECK(same);
    /* each point's parts are rounded once per record that weighs there (at most ~9) */
    double points = (double)total / LMB_IC_SHARE_ONE;
    CHECK(fabs(points - (POINTS + 1)) < (POINTS + 1) * 9.0 / LMB_IC_SHARE_ONE);
    /* an inner record (row 10, column 10) serves about the 16 points of its cell */
    double inner = (double)serial[10 * 20 + 10] / LMB_IC_SHARE_ONE;
    CHECK(inner > 14 && inner < 18);
    lmb_ic_records_free(&s);
}

int main(void)
{
    test_constant_plane();
    test_corner_and_facing_away();
    test_gradients();
    test_neighbour_clamp();
    test_reach_only_shrinks();
    test_shares();
    return check_failed_count != 0;
}
