/* Unwrap + pack a generated mesh into one ~size x size atlas (see unwrap_fit.h). */
#include "util/clock.h"
#include "unwrap_fit.h"
#include "charts_at.h"

#include "pack/pack.h"
#include "unwrap/metrics.h"
#include "unwrap/unwrap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct packed {
    lmb_pack_result r;
    charts_at at; /* the charts at the density packed */
} packed;

static void packed_free(packed *p)
{
    lmb_pack_result_free(&p->r);
    charts_at_free(&p->at);
}

/* Packs at density d; returns 1 if it fits one atlas of size x size. */
static int try_pack(const lmb_charts *c, double d, uint32_t size, uint32_t padding, packed *p)
{
    memset(p, 0, sizeof *p);
    if (!charts_at_density(c, d, &p->at))
        return 0;
    lmb_pack_options o = {size, padding, 0, 0, 1};
    lmb_error err;
    if (lmb_pack_charts(p->at.charts, c->chart_count, &o, &p->r, &err) != LMB_OK)
        return 0;
    return p->r.atlas_count == 1;
}

/* Packs at density d and measures it; returns 1 if it fits one atlas of size x size. */
static int measure(const gen_mesh *g, const lmb_charts *c, double d, uint32_t size, uint32_t padding, fit_result *r)
{
    packed p;
    double t0 = lmb_seconds();
    int ok = try_pack(c, d, size, padding, &p);
    double t = lmb_seconds() - t0;
    if (!ok) {
        packed_free(&p);
        return 0;
    }
    uint32_t n = c->first[c->chart_count];
    double *pos = malloc(sizeof(double) * 9 * n + 1), *uv = malloc(sizeof(double) * 6 * n + 1);
    for (uint32_t k = 0; pos && uv && k < c->chart_count; k++) {
        const double *m = p.r.placements[k].m;
        for (uint32_t i = c->first[k]; i < c->first[k + 1]; i++) {
            uint32_t f = c->order[i];
            for (int v = 0; v < 3; v++) {
                double x = p.at.uv[6 * i + 2 * v], y = p.at.uv[6 * i + 2 * v + 1];
                uv[6 * i + 2 * v] = m[0] * x + m[1] * y + m[2];
                uv[6 * i + 2 * v + 1] = m[3] * x + m[4] * y + m[5];
                for (int q = 0; q < 3; q++)
                    pos[9 * i + 3 * v + q] = g->positions[3 * g->indices[3 * f + v] + q];
            }
        }
    }
    lmb_uv_layout l = {n, pos, uv, p.r.width[0], p.r.height[0]};
    lmb_uv_metrics m;
    lmb_error err;
    ok = pos && uv && lmb_uv_metrics_compute(&l, &m, &err) == LMB_OK;
    if (ok) {
        r->density = d;
        r->width = p.r.width[0];
        r->height = p.r.height[0];
        r->coverage = m.coverage;
        r->l2_stretch = m.l2_stretch;
        r->density_p1 = m.density_p1;
        r->density_p50 = m.density_p50;
        r->density_p99 = m.density_p99;
        r->overlapping_texels = m.overlapping_texels;
        r->pack_seconds = t;
    }
    free(pos);
    free(uv);
    packed_free(&p);
    return ok;
}

int fit_mesh(const gen_mesh *g, uint32_t size, uint32_t padding, fit_result *r)
{
    memset(r, 0, sizeof *r);
    lmb_unwrap_input in = {g->vertex_count, g->positions, g->triangle_count, g->indices, NULL};
    lmb_unwrap_options o;
    lmb_charts c;
    lmb_error err;
    lmb_unwrap_options_default(&o);
    double t0 = lmb_seconds();
    if (lmb_unwrap_mesh(&in, &o, &c, &err) != LMB_OK)
        return -1;
    double chart_seconds = lmb_seconds() - t0;
    double area = 0;
    for (uint32_t f = 0; f < c.triangle_count; f++) {
        const double *u = c.uv + 6 * f;
        area += 0.5 * fabs((u[2] - u[0]) * (u[5] - u[1]) - (u[4] - u[0]) * (u[3] - u[1]));
    }
    /* bisection on the density between one that fits and one that does not; every density
     * that fits is measured and the best coverage kept (coverage is not monotonic in it) */
    double hi = sqrt((double)size * size / area), lo = hi * 0.5;
    fit_result best, cur;
    memset(&best, 0, sizeof best);
    uint32_t packs = 0;
    int ok = 0;
    while (!ok && lo > 1e-9) {
        memset(&cur, 0, sizeof cur);
        ok = measure(g, &c, lo, size, padding, &cur);
        packs++;
        if (ok)
            best = cur;
        else {
            hi = lo;
            lo *= 0.7;
        }
    }
    for (int i = 0; ok && i < 8; i++) {
        double mid = 0.5 * (lo + hi);
        memset(&cur, 0, sizeof cur);
        int fits = measure(g, &c, mid, size, padding, &cur);
        packs++;
        if (fits) {
            lo = mid;
            /* "about size x size": the longer side within 10% of it */
            int near = (cur.width > cur.height ? cur.width : cur.height) >= 0.9 * size;
            int best_near = (best.width > best.height ? best.width : best.height) >= 0.9 * size;
            if ((near && !best_near) || (near == best_near && cur.coverage > best.coverage))
                best = cur;
        } else {
            hi = mid;
        }
    }
    /* a finer look just below the largest density that fits: a slightly smaller scale can
     * tile the charts better (small inputs only, where a pack takes milliseconds) */
    for (int i = 1; ok && c.chart_count <= 50 && i <= 24; i++) {
        memset(&cur, 0, sizeof cur);
        if (measure(g, &c, lo * (1.0 - 0.01 * i), size, padding, &cur) && cur.coverage > best.coverage &&
            (cur.width > cur.height ? cur.width : cur.height) >= 0.9 * size)
            best = cur;
        packs++;
    }
    uint32_t charts = c.chart_count;
    lmb_charts_free(&c);
    if (!ok)
        return -1;
    *r = best;
    r->charts = charts;
    r->chart_seconds = chart_seconds;
    r->packs = packs;
    return 0;
}
