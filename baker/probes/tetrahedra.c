/*
 * The probe set's tetrahedra (docs/probes.md#tetrahedra): the 3D Delaunay tetrahedralization of
 * the probe positions by qhull (libqhull_r, Debian's libqhull-dev: the Delaunay of a point set is
 * the lower hull of the points lifted onto a paraboloid, "qhull d Qbb QJ"), the mesh Unity's
 * light probe groups and Godot's LightmapGI interpolate over: a point inside a tetrahedron takes
 * its four probes' SH with its barycentric weights. A regular grid's cells hold 8 cospherical
 * probes, which qhull's exact mode (Qt) resolves by merging facets: 0.55 s for level-single-10's
 * 5,248 probes, flat as a level is. Joggled input (QJ: each coordinate moved by qhull's joggle,
 * 1.4e-5 of level-single-10's extent of 235, so no 5 points are cospherical) takes 0.1-0.2 s; it
 * splits each such cell into tetrahedra plus slivers whose volume from the probes' own positions
 * is 0. Those are dropped (counted), as are the flat ones Qt left between two cells triangulated
 * differently; the volumes and orientations below read the probes' own positions. Each
 * tetrahedron is written with a positive volume: (p1 - p0) x (p2 - p0) . (p3 - p0) > 0.
 * Deterministic: one thread, facets in qhull's own order for the same points, and QJ's random
 * joggle drawn from qhull's fixed default seed (no QR option: QR-1 would seed it by the time).
 */
#define _POSIX_C_SOURCE 200809L
#include "probes.h"

#include "util/frame.h"

#include <libqhull_r/qhull_ra.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* 6 x the tetrahedron's signed volume: (b - a) x (c - a) . (d - a) */
static double signed_volume6(const double *p, const uint32_t v[4])
{
    const double *a = p + 3 * (size_t)v[0];
    double e[3][3], x[3];
    for (int j = 0; j < 3; j++)
        for (int k = 0; k < 3; k++)
            e[j][k] = p[3 * (size_t)v[j + 1] + k] - a[k];
    lmb_cross3(e[0], e[1], x);
    return lmb_dot3(x, e[2]);
}

lmb_status lmb_probe_tetrahedra(const lmb_probe_set *set, lmb_probe_tetrahedra_out *out, lmb_error *err)
{
    memset(out, 0, sizeof *out);
    if (set->count < 4)
        return LMB_OK;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    coordT *points = malloc(3 * (size_t)set->count * sizeof *points);
    if (!points)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for the tetrahedra");
    for (size_t i = 0; i < 3 * (size_t)set->count; i++) {
        points[i] = set->position[i];
        lo[i % 3] = fmin(lo[i % 3], points[i]);
        hi[i % 3] = fmax(hi[i % 3], points[i]);
    }
    double extent = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    /* flatter than this (relative to the set's extent cubed, x 6) holds no volume */
    double flat = 1e-9 * extent * extent * extent;
    char *messages = NULL;
    size_t message_size = 0;
    FILE *errors = open_memstream(&messages, &message_size);
    qhT qh_qh, *qh = &qh_qh;
    QHULL_LIB_CHECK
    qh_zero(qh, errors);
    char options[] = "qhull d Qbb QJ";
    int code = errors ? qh_new_qhull(qh, 3, (int)set->count, points, False, options, NULL, errors) : -1;
    lmb_status st = LMB_OK;
    if (code == 0) {
        facetT *facet;
        vertexT *vertex, **vertexp;
        size_t cap = 0;
        FORALLfacets {
            if (!facet->upperdelaunay)
                cap++;
        }
        out->tetrahedra = malloc((4 * cap + 1) * sizeof *out->tetrahedra);
        if (!out->tetrahedra)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for %zu tetrahedra", cap);
        FORALLfacets {
            if (st != LMB_OK || facet->upperdelaunay)
                continue;
            uint32_t v[4], k = 0;
            FOREACHvertex_(facet->vertices) {
                if (k < 4)
                    v[k] = (uint32_t)qh_pointid(qh, vertex->point);
                k++;
            }
            if (k != 4) /* QJ makes every cell a simplex */
                continue;
            double vol = signed_volume6(set->position, v);
            if (fabs(vol) <= flat) {
                out->flat++;
                continue;
            }
            if (vol < 0) {
                uint32_t t = v[2];
                v[2] = v[3];
                v[3] = t;
            }
            memcpy(out->tetrahedra + 4 * (size_t)out->count, v, sizeof v);
            out->count++;
        }
    } else if (errors) {
        fflush(errors);
        /* a flat or tiny set (a one-layer volume): no tetrahedra, and why */
        const char *m = messages ? messages : "";
        const char *stop = strstr(m, ".  "); /* qhull's first sentence; its advice on options follows */
        int len = (int)(stop ? (size_t)(stop - m) : strcspn(m, "\n"));
        snprintf(out->why, sizeof out->why, "%.*s", len, m);
    } else {
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "probes: cannot start qhull (no memory stream)");
    }
    qh_freeqhull(qh, !qh_ALL);
    int curlong, totlong;
    qh_memfreeshort(qh, &curlong, &totlong);
    if (errors)
        fclose(errors);
    free(messages);
    free(points);
    if (st != LMB_OK)
        lmb_probe_tetrahedra_free(out);
    return st;
}

lmb_status lmb_probe_set_tetrahedra(lmb_probe_set *set, lmb_error *err)
{
    if (set->tets_made)
        return LMB_OK;
    lmb_status st = lmb_probe_tetrahedra(set, &set->tets, err);
    set->tets_made = st == LMB_OK;
    return st;
}

void lmb_probe_tetrahedra_free(lmb_probe_tetrahedra_out *out)
{
    free(out->tetrahedra);
    memset(out, 0, sizeof *out);
}
