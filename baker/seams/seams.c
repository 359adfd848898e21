/* Least-squares seam stitching (see seams.h). */
#include "seams.h"

#include "seam_edges.h"
#include "seam_solve.h"

#include "texels/dilate.h"
#include "texels/texels.h"
#include "util/clock.h"
#include "util/lmb_math.h"

#include <omp.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* One side of a seam: where the edge lies in the atlas, from the smaller endpoint, and in the
 * world: its endpoints, the unit direction into its triangle across the edge, the triangle's
 * front normal, and a texel's size there. */
typedef struct seam_side {
    uint32_t atlas;
    double uv[4];
    double p[6], inward[3], normal[3], texel;
} seam_side;

/* Unit shading normal at corner c of a triangle (the face normal when it is shaded flat). */
static void corner_normal(const lmb_scene *s, const lmb_layout *l, uint32_t instance, uint32_t f, int c, double n[3])
{
    double cn[9], q[9];
    if (lmb_triangle_corner_normals(s, l, instance, f, cn)) {
        memcpy(n, cn + 3 * c, 3 * sizeof *n);
    } else {
        lmb_layout_world_triangle(s, l, instance, f, q);
        double e1[3] = {q[3] - q[0], q[4] - q[1], q[5] - q[2]}, e2[3] = {q[6] - q[0], q[7] - q[1], q[8] - q[2]};
        double sg = s->instances[instance].flips_winding ? -1 : 1;
        n[0] = sg * (e1[1] * e2[2] - e1[2] * e2[1]);
        n[1] = sg * (e1[2] * e2[0] - e1[0] * e2[2]);
        n[2] = sg * (e1[0] * e2[1] - e1[1] * e2[0]);
    }
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int r = 0; r < 3; r++)
        n[r] = len > 0 ? n[r] / len : 0;
}

static void normalize(double v[3])
{
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        v[k] = len > 0 ? v[k] / len : 0;
}

/* The side of edge e in the atlas and the world, endpoints in key order (smaller first). */
static void side_of(const lmb_scene *s, const lmb_layout *l, const edge_ref *e, seam_side *side)
{
    const lmb_layout_instance *li = &l->instances[e->instance];
    double q[9];
    lmb_layout_world_triangle(s, l, e->instance, e->triangle, q);
    int ca = e->corner, cb = (e->corner + 1) % 3, cc = (e->corner + 2) % 3;
    double ed[3], in[3], e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        side->p[k] = q[3 * (e->swapped ? cb : ca) + k];
        side->p[3 + k] = q[3 * (e->swapped ? ca : cb) + k];
        ed[k] = q[3 * cb + k] - q[3 * ca + k];
        in[k] = q[3 * cc + k] - q[3 * ca + k];
        e1[k] = q[3 + k] - q[k];
        e2[k] = q[6 + k] - q[k];
    }
    normalize(ed);
    double along = in[0] * ed[0] + in[1] * ed[1] + in[2] * ed[2];
    for (int k = 0; k < 3; k++)
        side->inward[k] = in[k] - along * ed[k];
    normalize(side->inward);
    double sg = s->instances[e->instance].flips_winding ? -1 : 1;
    side->normal[0] = sg * (e1[1] * e2[2] - e1[2] * e2[1]);
    side->normal[1] = sg * (e1[2] * e2[0] - e1[0] * e2[2]);
    side->normal[2] = sg * (e1[0] * e2[1] - e1[1] * e2[0]);
    normalize(side->normal);
    side->texel = 1.0 / li->texel_density;
    double uv[6];
    lmb_layout_uv(l, e->instance, e->triangle, uv);
    int a = e->corner, b = (e->corner + 1) % 3;
    if (e->swapped) {
        int t = a;
        a = b;
        b = t;
    }
    side->atlas = li->atlas;
    side->uv[0] = uv[2 * a];
    side->uv[1] = uv[2 * a + 1];
    side->uv[2] = uv[2 * b];
    side->uv[3] = uv[2 * b + 1];
}

/* Is the pair (x, y) of equal snapped edges a seam? Smooth across (shading normals within
 * about 8 degrees at both ends) and cut in the atlas. */
static int is_seam(const lmb_scene *s, const lmb_layout *l, const edge_ref *x, const edge_ref *y, seam_side sides[2])
{
    side_of(s, l, x, &sides[0]);
    side_of(s, l, y, &sides[1]);
    if (sides[0].atlas == sides[1].atlas) {
        double d = 0;
        for (int k = 0; k < 4; k++)
            d = fmax(d, fabs(sides[0].uv[k] - sides[1].uv[k]));
        if (d < 1e-6)
            return 0; /* one chart: the same texels on both sides */
    }
    for (int end = 0; end < 2; end++) {
        int cx = (x->corner + ((end ^ x->swapped) ? 1 : 0)) % 3, cy = (y->corner + ((end ^ y->swapped) ? 1 : 0)) % 3;
        double nx[3], ny[3];
        corner_normal(s, l, x->instance, x->triangle, cx, nx);
        corner_normal(s, l, y->instance, y->triangle, cy, ny);
        if (nx[0] * ny[0] + nx[1] * ny[1] + nx[2] * ny[2] < 0.99)
            return 0;
    }
    return 1;
}

/* The 4 bilinear taps at atlas texel coordinates (x, y), clamped as the cache's lookup. */
static void bilinear_taps(double x, double y, uint32_t w, uint32_t h, uint32_t idx[4], double wt[4])
{
    x -= 0.5;
    y -= 0.5;
    double fx = floor(x), fy = floor(y), ax = x - fx, ay = y - fy;
    long x0 = (long)fx, y0 = (long)fy;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            long xx = x0 + i, yy = y0 + j;
            xx = xx < 0 ? 0 : xx >= (long)w ? (long)w - 1 : xx;
            yy = yy < 0 ? 0 : yy >= (long)h ? (long)h - 1 : yy;
            idx[2 * j + i] = (uint32_t)((size_t)yy * w + (size_t)xx);
            wt[2 * j + i] = (i ? ax : 1 - ax) * (j ? ay : 1 - ay);
        }
}

/* Points along a seam: four per texel of its longer side (two left the bilinear lookups
 * between them up to 0.5% apart on a sphere), at least two. */
static uint32_t seam_points(const seam_side sides[2])
{
    double len = 0;
    for (int k = 0; k < 2; k++)
        len = fmax(len, hypot(sides[k].uv[2] - sides[k].uv[0], sides[k].uv[3] - sides[k].uv[1]));
    double n = ceil(4 * len);
    return n < 2 ? 2 : n > 4096 ? 4096 : (uint32_t)n;
}

static void row_at(const lmb_layout *l, const seam_side sides[2], double t, seam_row *r)
{
    for (int k = 0; k < 2; k++) {
        const seam_side *sd = &sides[k];
        double x = sd->uv[0] + t * (sd->uv[2] - sd->uv[0]), y = sd->uv[1] + t * (sd->uv[3] - sd->uv[1]);
        uint32_t idx[4];
        double wt[4];
        bilinear_taps(x, y, l->width[sd->atlas], l->height[sd->atlas], idx, wt);
        r->atlas[k] = sd->atlas;
        for (int j = 0; j < 4; j++) {
            r->texel[4 * k + j] = idx[j];
            r->w[4 * k + j] = (float)(k ? -wt[j] : wt[j]);
        }
    }
}

/* Whether the two sides of some point read different light (any channel), from the atlases
 * as they are; in parallel. With none, the stitch's solution is the atlases themselves. */
static int any_side_differs(float *const *rgb, const seam_row *rows, size_t nr, int threads)
{
    int differs = 0;
#pragma omp parallel for num_threads(threads) schedule(static) reduction(| : differs)
    for (size_t r = 0; r < nr; r++) {
        double side[2][3] = {{0, 0, 0}, {0, 0, 0}};
        for (int j = 0; j < 8; j++) {
            const float *p = rgb[lmb_seam_tap_atlas(&rows[r], j)] + 3 * (size_t)rows[r].texel[j];
            for (int c = 0; c < 3; c++)
                side[j / 4][c] += fabs(rows[r].w[j]) * p[c];
        }
        differs |= side[0][0] != side[1][0] || side[0][1] != side[1][1] || side[0][2] != side[1][2];
    }
    return differs;
}

/* Does each side of the point read a valid texel? Where one side lies under other geometry
 * (a floor's seam running under a wall) its texels hold no light of their own: nothing to
 * match. */
static int seen_from_both_sides(const uint8_t *const *state, const seam_row *r)
{
    int valid[2] = {0, 0};
    for (int j = 0; j < 8; j++)
        if (r->w[j] != 0 && state[lmb_seam_tap_atlas(r, j)][r->texel[j]] == LMB_TEXEL_VALID)
            valid[j / 4] = 1;
    return valid[0] && valid[1];
}

/* Is the surface open across the seam at t along it? Nothing stands on the edge there: from a
 * point a quarter texel above the edge, both sides' surfaces half a texel away are in sight. A
 * wall standing on a floor's seam (two rooms, one lit, on either side) fails this: its light is
 * not continuous there and must not be matched. */
static int open_across(const lmb_rt *rt, const seam_side sides[2], double t)
{
    double h = 0.25 * fmin(sides[0].texel, sides[1].texel), up[3], o[3];
    for (int k = 0; k < 3; k++)
        up[k] = sides[0].normal[k] + sides[1].normal[k];
    normalize(up);
    for (int k = 0; k < 3; k++)
        o[k] = sides[0].p[k] + t * (sides[0].p[3 + k] - sides[0].p[k]) + h * up[k];
    for (int side = 0; side < 2; side++) {
        const seam_side *sd = &sides[side];
        double q[3], d[3];
        for (int k = 0; k < 3; k++) {
            q[k] = sd->p[k] + t * (sd->p[3 + k] - sd->p[k]) + h * sd->normal[k] + 0.5 * sd->texel * sd->inward[k];
            d[k] = q[k] - o[k];
        }
        double dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int k = 0; k < 3; k++)
            d[k] /= dist;
        if (lmb_rt_occluded(rt, o, d, 0, dist))
            return 0;
    }
    return 1;
}

/* The points of the seam whose two edge refs are e[0] and e[1] (rows may be NULL to count);
 * 0 when they are no seam (a hash collision, or is_seam says no). *is_edge: they are one edge. */
static uint32_t edge_rows(const lmb_scene *s, const lmb_layout *l, const lmb_rt *rt, const uint8_t *const *state,
                          double snap, const edge_ref *e, seam_row *rows, int *is_edge)
{
    int64_t ka[6], kb[6];
    int sa, sb;
    seam_side sides[2];
    *is_edge = 0;
    lmb_seam_edge_key(s, l, e[0].instance, e[0].triangle, e[0].corner, snap, ka, &sa);
    lmb_seam_edge_key(s, l, e[1].instance, e[1].triangle, e[1].corner, snap, kb, &sb);
    if (memcmp(ka, kb, sizeof ka) || !is_seam(s, l, &e[0], &e[1], sides))
        return 0;
    *is_edge = 1;
    uint32_t n = seam_points(sides), m = 0;
    for (uint32_t k = 0; k < n; k++) {
        seam_row r;
        row_at(l, sides, (k + 0.5) / n, &r);
        if (!seen_from_both_sides(state, &r) || !open_across(rt, sides, (k + 0.5) / n))
            continue;
        if (rows)
            rows[m] = r;
        m++;
    }
    return m;
}

/* Every seam point seen from both sides, in a deterministic order (the sorted edges): the
 * pairs (hashes held by exactly two refs) are found, their points counted in parallel, placed
 * by a prefix sum and computed again into *rows in parallel. */
static lmb_status seam_rows(const lmb_scene *s, const lmb_layout *l, const lmb_rt *rt, const uint8_t *const *state,
                            double snap, const edge_ref *e, size_t ne, int threads, seam_row **rows, size_t *nr,
                            uint64_t *edges, lmb_error *err)
{
    *rows = NULL;
    *nr = 0;
    *edges = 0;
    size_t pairs = 0;
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && e[j].hash == e[i].hash)
            j++;
        pairs += j - i == 2;
        i = j;
    }
    size_t *pair = malloc((pairs + 1) * sizeof *pair), *first = malloc((pairs + 1) * sizeof *first);
    if (!pair || !first) {
        free(pair);
        free(first);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "seams: out of memory for %zu edges", pairs);
    }
    pairs = 0;
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && e[j].hash == e[i].hash)
            j++;
        if (j - i == 2)
            pair[pairs++] = i;
        i = j;
    }
    uint64_t found = 0;
#pragma omp parallel num_threads(threads) reduction(+ : found)
    {
        lmb_rt_thread_init();
#pragma omp for schedule(dynamic, 256)
        for (size_t p = 0; p < pairs; p++) {
            int is_edge;
            first[p] = edge_rows(s, l, rt, state, snap, &e[pair[p]], NULL, &is_edge);
            found += (uint64_t)is_edge;
        }
    }
    size_t m = 0;
    for (size_t p = 0; p < pairs; p++) {
        size_t k = first[p];
        first[p] = m;
        m += k;
    }
    lmb_status st = LMB_OK;
    seam_row *r = m ? malloc(m * sizeof *r) : NULL;
    if (m && !r)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "seams: out of memory for %zu seam points", m);
    if (r) {
#pragma omp parallel num_threads(threads)
        {
            lmb_rt_thread_init();
#pragma omp for schedule(dynamic, 256)
            for (size_t p = 0; p < pairs; p++) {
                int is_edge;
                edge_rows(s, l, rt, state, snap, &e[pair[p]], r + first[p], &is_edge);
            }
        }
    }
    free(pair);
    free(first);
    *rows = r;
    *nr = st == LMB_OK ? m : 0;
    *edges = found;
    return st;
}

lmb_status lmb_seams_stitch(const lmb_scene *s, const lmb_layout *l, const lmb_rt *rt, float *const *rgb,
                            const uint8_t *const *state, int threads, lmb_seam_report *report, lmb_error *err)
{
    double t0 = lmb_seconds();
    memset(report, 0, sizeof *report);
    threads = threads > 0 ? threads : omp_get_max_threads();
    double snap = lmb_seam_snap_size(l);
    edge_ref *e = NULL;
    size_t ne = 0, nr = 0;
    seam_row *rows = NULL;
    lmb_status st = lmb_seam_collect_edges(s, l, snap, threads, &e, &ne, err);
    if (st != LMB_OK)
        return st;
    lmb_rt_thread_init();
    st = seam_rows(s, l, rt, state, snap, e, ne, threads, &rows, &nr, &report->edges, err);
    free(e); /* the points hold what the solve needs */
    e = NULL;
    report->equal = st == LMB_OK && nr && !any_side_differs(rgb, rows, nr, threads);
    if (report->equal)
        report->samples = nr;
    else if (st == LMB_OK && nr)
        st = lmb_seam_solve(l, rgb, state, rows, nr, threads, report, err);
    free(rows);
    free(e);
    report->seconds = lmb_seconds() - t0;
    return st;
}
