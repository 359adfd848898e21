/*
 * UV layout quality metrics (definitions in metrics.h and docs/unwrap.md).
 * Rasterization snaps UVs to 1/256 texel and evaluates edge functions in 64-bit integers,
 * so the top-left rule is exact: a texel centre on an edge shared by two triangles is
 * counted once, and overlap counts only real overlaps.
 * L2 stretch: Sander, Snyder, Gortler, Hoppe, "Texture Mapping Progressive Meshes",
 * SIGGRAPH 2001, section 3: per triangle L2 = sqrt((a + c) / 2) with a = |S_s|^2, c = |S_t|^2;
 * over the mesh sqrt(sum L2^2 A3d / sum A3d), times sqrt(sum A2d / sum A3d) so that a
 * parameterization that is isometric up to one global scale gives exactly 1.
 */
#include "metrics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SUB 256 /* fixed-point steps per texel */

typedef struct ipt {
    int64_t x, y;
} ipt;

static int64_t edge(ipt a, ipt b, int64_t px, int64_t py)
{
    return (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x);
}

/* Top-left rule for a counter-clockwise triangle: the edge owns centres exactly on it
 * when it runs downward, or horizontally to the right. Opposite directions never both. */
static int owns(ipt a, ipt b)
{
    int64_t dx = b.x - a.x, dy = b.y - a.y;
    return dy < 0 || (dy == 0 && dx > 0);
}

static int64_t snap(double v)
{
    return (int64_t)llround(v * SUB);
}

uint64_t lmb_raster_triangle_centres(const double uv[6], uint32_t width, uint32_t height,
                                     void (*visit)(void *user, uint32_t x, uint32_t y), void *user)
{
    ipt p[3];
    for (int i = 0; i < 3; i++) {
        if (!isfinite(uv[2 * i]) || !isfinite(uv[2 * i + 1]) || fabs(uv[2 * i]) > 1e7 || fabs(uv[2 * i + 1]) > 1e7)
            return 0;
        p[i].x = snap(uv[2 * i]);
        p[i].y = snap(uv[2 * i + 1]);
    }
    int64_t area2 = edge(p[0], p[1], p[2].x, p[2].y);
    if (area2 == 0)
        return 0;
    if (area2 < 0) {
        ipt t = p[1];
        p[1] = p[2];
        p[2] = t;
    }
    int64_t minx = p[0].x, maxx = p[0].x, miny = p[0].y, maxy = p[0].y;
    for (int i = 1; i < 3; i++) {
        minx = p[i].x < minx ? p[i].x : minx;
        maxx = p[i].x > maxx ? p[i].x : maxx;
        miny = p[i].y < miny ? p[i].y : miny;
        maxy = p[i].y > maxy ? p[i].y : maxy;
    }
    /* texels whose centre SUB*x + SUB/2 lies in [min, max] */
    int64_t x0 = (minx - SUB / 2 + SUB - 1) / SUB, x1 = (maxx - SUB / 2) / SUB;
    int64_t y0 = (miny - SUB / 2 + SUB - 1) / SUB, y1 = (maxy - SUB / 2) / SUB;
    if (minx - SUB / 2 < 0) x0 = 0;
    if (miny - SUB / 2 < 0) y0 = 0;
    if (x1 >= (int64_t)width) x1 = (int64_t)width - 1;
    if (y1 >= (int64_t)height) y1 = (int64_t)height - 1;
    int own[3] = {owns(p[0], p[1]), owns(p[1], p[2]), owns(p[2], p[0])};
    uint64_t n = 0;
    for (int64_t y = y0; y <= y1; y++) {
        int64_t cy = y * SUB + SUB / 2;
        for (int64_t x = x0; x <= x1; x++) {
            int64_t cx = x * SUB + SUB / 2;
            int64_t e0 = edge(p[0], p[1], cx, cy), e1 = edge(p[1], p[2], cx, cy), e2 = edge(p[2], p[0], cx, cy);
            if ((e0 > 0 || (e0 == 0 && own[0])) && (e1 > 0 || (e1 == 0 && own[1])) && (e2 > 0 || (e2 == 0 && own[2]))) {
                visit(user, (uint32_t)x, (uint32_t)y);
                n++;
            }
        }
    }
    return n;
}

typedef struct counter {
    uint8_t *hits;
    uint32_t width;
} counter;

static void count_hit(void *user, uint32_t x, uint32_t y)
{
    counter *c = user;
    uint8_t *h = &c->hits[(size_t)y * c->width + x];
    if (*h < 255)
        (*h)++;
}

static double tri_area3(const double *q)
{
    double e1[3], e2[3];
    for (int i = 0; i < 3; i++) {
        e1[i] = q[3 + i] - q[i];
        e2[i] = q[6 + i] - q[i];
    }
    double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2], cz = e1[0] * e2[1] - e1[1] * e2[0];
    return 0.5 * sqrt(cx * cx + cy * cy + cz * cz);
}

static double tri_area2(const double *u)
{
    return 0.5 * ((u[2] - u[0]) * (u[5] - u[1]) - (u[4] - u[0]) * (u[3] - u[1]));
}

/* Sander 2001 per-triangle squared L2 stretch, (a + c) / 2, of the map UV -> 3D. */
static double l2_squared(const double *q, const double *u, double a2)
{
    double s1 = u[0], t1 = u[1], s2 = u[2], t2 = u[3], s3 = u[4], t3 = u[5];
    double a = 0, c = 0;
    for (int i = 0; i < 3; i++) {
        double ss = (q[i] * (t2 - t3) + q[3 + i] * (t3 - t1) + q[6 + i] * (t1 - t2)) / (2 * a2);
        double st = (q[i] * (s3 - s2) + q[3 + i] * (s1 - s3) + q[6 + i] * (s2 - s1)) / (2 * a2);
        a += ss * ss;
        c += st * st;
    }
    return 0.5 * (a + c);
}

typedef struct weighted {
    double value, weight;
} weighted;

static int by_value(const void *a, const void *b)
{
    double x = ((const weighted *)a)->value, y = ((const weighted *)b)->value;
    return (x > y) - (x < y);
}

/* Area-weighted percentile over sorted samples: the first value whose cumulative weight
 * reaches q of the total. */
static double percentile(const weighted *w, uint32_t n, double total, double q)
{
    double acc = 0;
    for (uint32_t i = 0; i < n; i++) {
        acc += w[i].weight;
        if (acc >= q * total)
            return w[i].value;
    }
    return n ? w[n - 1].value : 0;
}

lmb_status lmb_uv_metrics_compute(const lmb_uv_layout *l, lmb_uv_metrics *m, lmb_error *err)
{
    memset(m, 0, sizeof *m);
    size_t texels = (size_t)l->width * l->height;
    counter c = {calloc(texels ? texels : 1, 1), l->width};
    weighted *dens = malloc(((size_t)l->triangle_count + 1) * sizeof *dens);
    if (!c.hits || !dens) {
        free(c.hits);
        free(dens);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "uv metrics: out of memory for a %ux%u atlas", l->width, l->height);
    }
    double sum_a3 = 0, sum_a2 = 0, sum_l2 = 0;
    uint32_t nd = 0;
    for (uint32_t t = 0; t < l->triangle_count; t++) {
        const double *q = l->pos + 9 * t, *u = l->uv + 6 * t;
        double a3 = tri_area3(q), a2 = tri_area2(u);
        if (lmb_raster_triangle_centres(u, l->width, l->height, count_hit, &c) == 0 && a2 == 0)
            m->degenerate_uv++;
        if (a2 == 0 || a3 == 0)
            continue;
        sum_a3 += a3;
        sum_a2 += fabs(a2);
        sum_l2 += l2_squared(q, u, a2) * a3;
        dens[nd].value = fabs(a2) / a3;
        dens[nd].weight = a3;
        nd++;
    }
    for (size_t i = 0; i < texels; i++) {
        m->covered_texels += c.hits[i] > 0;
        m->overlapping_texels += c.hits[i] > 1;
    }
    m->coverage = texels ? (double)m->covered_texels / (double)texels : 0;
    if (sum_a3 > 0) {
        m->l2_stretch = sqrt(sum_l2 / sum_a3) * sqrt(sum_a2 / sum_a3);
        double mean = sum_a2 / sum_a3;
        for (uint32_t i = 0; i < nd; i++)
            dens[i].value /= mean;
        qsort(dens, nd, sizeof *dens, by_value);
        m->density_p1 = percentile(dens, nd, sum_a3, 0.01);
        m->density_p50 = percentile(dens, nd, sum_a3, 0.50);
        m->density_p99 = percentile(dens, nd, sum_a3, 0.99);
    }
    free(c.hits);
    free(dens);
    return LMB_OK;
}
