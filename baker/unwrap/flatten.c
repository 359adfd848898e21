/*
 * Flattening one chart. A planar chart (all normals within 1e-7 of their mean) is
 * projected onto its plane: exact, stretch 1. Otherwise least squares conformal maps
 * (Levy, Petitjean, Ray, Maillot, "Least Squares Conformal Maps for Automatic Texture Atlas
 * Generation", SIGGRAPH 2002, eq. 3-5): per triangle, in its own orthonormal 2D frame,
 * W_1 = z_3 - z_2, W_2 = z_1 - z_3, W_3 = z_2 - z_1 (complex) and the residual
 * sum_j W_j U_j / sqrt(2 A_T) must vanish for a conformal map. Two vertices are pinned
 * (the extremes along the chart's longest extent, at their projected positions), and the
 * normal equations A^T A x = A^T b are solved by sparse Cholesky (CHOLMOD, simplicial:
 * symmetric positive definite, exact, deterministic, fast on mesh-like sparsity, from
 * Debian's libsuitesparse-dev). Finally the chart is scaled so its UV area equals its 3D
 * area, and mirrored if needed so UV winding matches the 3D winding.
 */
#include "unwrap_internal.h"

#include "util/spd_solve.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Orthonormal basis (e1, e2) of the plane with normal n, chosen deterministically. */
static void plane_basis(const double n[3], double e1[3], double e2[3])
{
    double a[3] = {0, 0, 0};
    int k = fabs(n[0]) < fabs(n[1]) ? (fabs(n[0]) < fabs(n[2]) ? 0 : 2) : (fabs(n[1]) < fabs(n[2]) ? 1 : 2);
    a[k] = 1;
    e1[0] = a[1] * n[2] - a[2] * n[1];
    e1[1] = a[2] * n[0] - a[0] * n[2];
    e1[2] = a[0] * n[1] - a[1] * n[0];
    double l = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int i = 0; i < 3; i++)
        e1[i] /= l;
    e2[0] = n[1] * e1[2] - n[2] * e1[1];
    e2[1] = n[2] * e1[0] - n[0] * e1[2];
    e2[2] = n[0] * e1[1] - n[1] * e1[0];
}

typedef struct chart_verts {
    uint32_t count;
    uint32_t *ids;   /* sorted mesh vertex ids (lmb_topology.corner) */
    uint32_t *local; /* 3 per chart triangle: index into ids */
    double *pos;     /* 3 per local vertex */
    double *uv;      /* 2 per local vertex */
} chart_verts;

static void chart_verts_free(chart_verts *c)
{
    free(c->ids);
    free(c->local);
    free(c->pos);
    free(c->uv);
}

static int gather_vertices(const lmb_unwrap_input *in, const lmb_topology *t, const uint32_t *tris, uint32_t n,
                           chart_verts *c)
{
    memset(c, 0, sizeof *c);
    c->ids = malloc((3 * (size_t)n + 1) * sizeof *c->ids);
    c->local = malloc((3 * (size_t)n + 1) * sizeof *c->local);
    if (!c->ids || !c->local)
        return 0;
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            c->ids[3 * i + k] = t->corner[3 * tris[i] + k];
    qsort(c->ids, 3 * (size_t)n, sizeof *c->ids, lmb_cmp_u32);
    uint32_t m = 0;
    for (uint32_t i = 0; i < 3 * n; i++)
        if (i == 0 || c->ids[i] != c->ids[m - 1])
            c->ids[m++] = c->ids[i];
    c->count = m;
    c->pos = malloc(((size_t)m * 3 + 1) * sizeof *c->pos);
    c->uv = calloc((size_t)m * 2 + 1, sizeof *c->uv);
    if (!c->pos || !c->uv)
        return 0;
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            uint32_t v = in->indices[3 * tris[i] + k], l = lmb_lower_bound(c->ids, m, t->corner[3 * tris[i] + k]);
            c->local[3 * i + k] = l;
            for (int d = 0; d < 3; d++)
                c->pos[3 * l + d] = in->positions[3 * v + d];
        }
    return 1;
}

/* The two LSCM rows of triangle (a, b, c) with positions pa, pb, pc: coefficients on
 * (u_a, v_a, u_b, v_b, u_c, v_c). */
static void lscm_rows(const double *pa, const double *pb, const double *pc, double re[6], double im[6])
{
    double e1[3], e2[3], x[3], y[3];
    for (int i = 0; i < 3; i++) {
        e1[i] = pb[i] - pa[i];
        e2[i] = pc[i] - pa[i];
    }
    double l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    double ux[3] = {e1[0] / l1, e1[1] / l1, e1[2] / l1};
    double px = e2[0] * ux[0] + e2[1] * ux[1] + e2[2] * ux[2];
    double q[3] = {e2[0] - px * ux[0], e2[1] - px * ux[1], e2[2] - px * ux[2]};
    double py = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    x[0] = 0; y[0] = 0; x[1] = l1; y[1] = 0; x[2] = px; y[2] = py;
    double s = 1.0 / sqrt(l1 * py); /* 1 / sqrt(2 A_T) */
    for (int j = 0; j < 3; j++) {
        int k = (j + 2) % 3, i = (j + 1) % 3; /* W_j = z_k - z_i with (j, i, k) cyclic */
        double wr = (x[k] - x[i]) * s, wi = (y[k] - y[i]) * s;
        re[2 * j] = wr;  re[2 * j + 1] = -wi;
        im[2 * j] = wi;  im[2 * j + 1] = wr;
    }
}

/* LSCM over the chart's local vertices; c->uv holds the planar projection on entry (used for
 * the pins) and the conformal map on success. Returns 0 if the solve failed. */
static int solve_lscm(uint32_t n, chart_verts *c)
{
    uint32_t m = c->count, pin[2] = {0, 0};
    double lo = 1e300, hi = -1e300;
    double minu = 1e300, maxu = -1e300, minv = 1e300, maxv = -1e300;
    for (uint32_t v = 0; v < m; v++) {
        minu = fmin(minu, c->uv[2 * v]); maxu = fmax(maxu, c->uv[2 * v]);
        minv = fmin(minv, c->uv[2 * v + 1]); maxv = fmax(maxv, c->uv[2 * v + 1]);
    }
    int axis = (maxu - minu) >= (maxv - minv) ? 0 : 1;
    for (uint32_t v = 0; v < m; v++) {
        double p = c->uv[2 * v + axis];
        if (p < lo) { lo = p; pin[0] = v; }
        if (p > hi) { hi = p; pin[1] = v; }
    }
    if (pin[0] == pin[1] || m < 3)
        return 0;
    /* variable index per local vertex: 2 * free index, pinned: none */
    uint32_t *var = malloc(((size_t)m + 1) * sizeof *var);
    if (!var)
        return 0;
    uint32_t nf = 0;
    for (uint32_t v = 0; v < m; v++)
        var[v] = (v == pin[0] || v == pin[1]) ? LMB_NONE : 2 * nf++;
    size_t nvar = 2 * (size_t)nf;
    int ok = 0;
    lmb_spd sys;
    double *xv = malloc((nvar + 1) * sizeof *xv);
    if (lmb_spd_begin(&sys, nvar, (size_t)n * 2 * 21 + 1, 1) && xv) {
        cholmod_triplet *T = sys.a;
        int *ti = T->i, *tj = T->j;
        double *tx = T->x, *bx = sys.b->x;
        for (uint32_t f = 0; f < n; f++) {
            const uint32_t *lv = c->local + 3 * f;
            double rows[2][6];
            lscm_rows(c->pos + 3 * lv[0], c->pos + 3 * lv[1], c->pos + 3 * lv[2], rows[0], rows[1]);
            for (int r = 0; r < 2; r++) {
                double pinned = 0; /* row . x over pinned variables */
                for (int a = 0; a < 6; a++)
                    if (var[lv[a / 2]] == LMB_NONE)
                        pinned += rows[r][a] * c->uv[2 * lv[a / 2] + a % 2];
                for (int a = 0; a < 6; a++) {
                    uint32_t ia = var[lv[a / 2]];
                    if (ia == LMB_NONE)
                        continue;
                    ia += (uint32_t)(a % 2);
                    bx[ia] -= rows[r][a] * pinned;
                    for (int bq = 0; bq < 6; bq++) {
                        uint32_t ib = var[lv[bq / 2]];
                        if (ib == LMB_NONE)
                            continue;
                        ib += (uint32_t)(bq % 2);
                        if (ia > ib)
                            continue; /* upper triangle (stype 1) */
                        ti[T->nnz] = (int)ia;
                        tj[T->nnz] = (int)ib;
                        tx[T->nnz] = rows[r][a] * rows[r][bq];
                        T->nnz++;
                    }
                }
            }
        }
        if (lmb_spd_solve(&sys, xv)) {
            ok = 1;
            for (uint32_t v = 0; v < m; v++)
                if (var[v] != LMB_NONE) {
                    c->uv[2 * v] = xv[var[v]];
                    c->uv[2 * v + 1] = xv[var[v] + 1];
                    ok &= isfinite(c->uv[2 * v]) && isfinite(c->uv[2 * v + 1]);
                }
        }
    }
    lmb_spd_end(&sys);
    free(xv);
    free(var);
    return ok;
}

lmb_status lmb_flatten(const lmb_unwrap_input *in, const lmb_topology *t, const uint32_t *tris, uint32_t n,
                       double *uv, int *planar, lmb_error *err)
{
    chart_verts c;
    if (!gather_vertices(in, t, tris, n, &c)) {
        chart_verts_free(&c);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: out of memory");
    }
    double nm[3] = {0, 0, 0}, e1[3], e2[3], a3 = 0;
    for (uint32_t i = 0; i < n; i++) {
        for (int d = 0; d < 3; d++)
            nm[d] += t->area[tris[i]] * t->normal[3 * tris[i] + d];
        a3 += t->area[tris[i]];
    }
    double len = sqrt(nm[0] * nm[0] + nm[1] * nm[1] + nm[2] * nm[2]);
    if (!(len > 0)) {
        nm[0] = 0; nm[1] = 0; nm[2] = 1; len = 1;
    }
    for (int d = 0; d < 3; d++)
        nm[d] /= len;
    plane_basis(nm, e1, e2);
    *planar = 1;
    for (uint32_t i = 0; i < n && *planar; i++) {
        const double *fn = t->normal + 3 * tris[i];
        *planar = fn[0] * nm[0] + fn[1] * nm[1] + fn[2] * nm[2] >= 1.0 - 1e-7;
    }
    for (uint32_t v = 0; v < c.count; v++) {
        const double *p = c.pos + 3 * v;
        c.uv[2 * v] = p[0] * e1[0] + p[1] * e1[1] + p[2] * e1[2];
        c.uv[2 * v + 1] = p[0] * e2[0] + p[1] * e2[1] + p[2] * e2[2];
    }
    if (!*planar && !solve_lscm(n, &c)) {
        /* keep the projection; the validity check decides whether the chart must split */
        for (uint32_t v = 0; v < c.count; v++) {
            const double *p = c.pos + 3 * v;
            c.uv[2 * v] = p[0] * e1[0] + p[1] * e1[1] + p[2] * e1[2];
            c.uv[2 * v + 1] = p[0] * e2[0] + p[1] * e2[1] + p[2] * e2[2];
        }
    }
    /* scale to the 3D area, and mirror if the map reverses the winding */
    double a2 = 0;
    for (uint32_t i = 0; i < n; i++) {
        const double *p0 = c.uv + 2 * c.local[3 * i], *p1 = c.uv + 2 * c.local[3 * i + 1], *p2 = c.uv + 2 * c.local[3 * i + 2];
        a2 += 0.5 * ((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1]));
    }
    double s = fabs(a2) > 0 ? sqrt(a3 / fabs(a2)) : 1.0, flip = a2 < 0 ? -1.0 : 1.0;
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            const double *p = c.uv + 2 * c.local[3 * i + k];
            uv[6 * tris[i] + 2 * k] = s * p[0];
            uv[6 * tris[i] + 2 * k + 1] = s * flip * p[1];
        }
    chart_verts_free(&c);
    return LMB_OK;
}
