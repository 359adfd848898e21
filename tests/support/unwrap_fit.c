/* Unwrap + pack a generated mesh into one ~size x size atlas (see unwrap_fit.h). */
#define _POSIX_C_SOURCE 200809L
#include "unwrap_fit.h"

#include "pack/pack.h"
#include "unwrap/metrics.h"
#include "unwrap/unwrap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct packed {
    lmb_pack_result r;
    double *uv; /* scaled chart uvs, chart order */
    lmb_pack_chart *charts;
} packed;

static void packed_free(packed *p)
{
    lmb_pack_result_free(&p->r);
    free(p->uv);
    free(p->charts);
    memset(p, 0, sizeof *p);
}

/* Packs at density d; returns 1 if it fits one atlas of size x size. */
static int try_pack(const lmb_charts *c, double d, uint32_t size, uint32_t padding, packed *p)
{
    memset(p, 0, sizeof *p);
    uint32_t n = c->first[c->chart_count];
    p->uv = malloc(sizeof(double) * 6 * n + 1);
    p->charts = calloc(c->chart_count + 1, sizeof *p->charts);
    if (!p->uv || !p->charts)
        return 0;
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k < 6; k++)
            p->uv[6 * i + k] = c->uv[6 * c->order[i] + k] * d;
    for (uint32_t k = 0; k < c->chart_count; k++) {
        p->charts[k].triangle_count = c->first[k + 1] - c->first[k];
        p->charts[k].uv = p->uv + 6 * c->first[k];
    }
    lmb_pack_options o = {size, padding};
    lmb_error err;
    if (lmb_pack_charts(p->charts, c->chart_count, &o, &p->r, &err) != LMB_OK)
        return 0;
    return p->r.atlas_count == 1;
}

int fit_mesh(const gen_mesh *g, uint32_t size, uint32_t padding, fit_result *r)
{
    memset(r, 0, sizeof *r);
    lmb_unwrap_input in = {g->vertex_count, g->positions, g->triangle_count, g->indices, NULL};
    lmb_unwrap_options o;
    lmb_charts c;
    lmb_error err;
    lmb_unwrap_options_default(&o);
    double t0 = now();
    if (lmb_unwrap_mesh(&in, &o, &c, &err) != LMB_OK)
        return -1;
    r->chart_seconds = now() - t0;
    r->charts = c.chart_count;
    double area = 0;
    for (uint32_t f = 0; f < c.triangle_count; f++) {
        const double *u = c.uv + 6 * f;
        area += 0.5 * fabs((u[2] - u[0]) * (u[5] - u[1]) - (u[4] - u[0]) * (u[3] - u[1]));
    }
    /* bisection on the density between one that fits and one that does not */
    double hi = sqrt((double)size * size / area), lo = hi * 0.5;
    packed p;
    int ok = 0;
    while (!ok && lo > 1e-9) {
        ok = try_pack(&c, lo, size, padding, &p);
        packed_free(&p);
        r->packs++;
        if (!ok) {
            hi = lo;
            lo *= 0.7;
        }
    }
    for (int i = 0; ok && i < 8; i++) {
        double mid = 0.5 * (lo + hi);
        int fits = try_pack(&c, mid, size, padding, &p);
        packed_free(&p);
        r->packs++;
        if (fits)
            lo = mid;
        else
            hi = mid;
    }
    t0 = now();
    ok = ok && try_pack(&c, lo, size, padding, &p);
    r->pack_seconds = now() - t0;
    if (!ok) {
        packed_free(&p);
        lmb_charts_free(&c);
        return -1;
    }
    r->density = lo;
    r->width = p.r.width[0];
    r->height = p.r.height[0];
    /* placed uvs and positions, chart order */
    uint32_t n = c.first[c.chart_count];
    double *pos = malloc(sizeof(double) * 9 * n + 1), *uv = malloc(sizeof(double) * 6 * n + 1);
    for (uint32_t k = 0; pos && uv && k < c.chart_count; k++) {
        const double *m = p.r.placements[k].m;
        for (uint32_t i = c.first[k]; i < c.first[k + 1]; i++) {
            uint32_t f = c.order[i];
            for (int v = 0; v < 3; v++) {
                double x = p.uv[6 * i + 2 * v], y = p.uv[6 * i + 2 * v + 1];
                uv[6 * i + 2 * v] = m[0] * x + m[1] * y + m[2];
                uv[6 * i + 2 * v + 1] = m[3] * x + m[4] * y + m[5];
                for (int d = 0; d < 3; d++)
                    pos[9 * i + 3 * v + d] = g->positions[3 * g->indices[3 * f + v] + d];
            }
        }
    }
    lmb_uv_layout l = {n, pos, uv, r->width, r->height};
    lmb_uv_metrics m;
    int rc = (pos && uv && lmb_uv_metrics_compute(&l, &m, &err) == LMB_OK) ? 0 : -1;
    if (!rc) {
        r->coverage = m.coverage;
        r->l2_stretch = m.l2_stretch;
        r->density_p1 = m.density_p1;
        r->density_p50 = m.density_p50;
        r->density_p99 = m.density_p99;
        r->overlapping_texels = m.overlapping_texels;
    }
    free(pos);
    free(uv);
    packed_free(&p);
    lmb_charts_free(&c);
    return rc;
}
