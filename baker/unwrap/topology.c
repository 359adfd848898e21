/*
 * Welding and adjacency for the unwrapper. Vertices are merged when their positions are
 * equal (sorted, so the result does not depend on hashing); the welded triangles then go
 * into a half-edge mesh (OpenMesh, behind halfedge_adapter.h), which keeps every triangle
 * and gives, per corner, the triangle across its edge. Two triangles are neighbours only
 * across an edge that exactly two triangles share, in opposite directions: a non-manifold
 * edge or a winding flip becomes a chart seam instead of a crash or a fold.
 *
 * A soup's seams often run between coplanar triangles: a quad whose second triangle was
 * re-added on copied vertices, the tops of a row of touching crates (their edges have four
 * triangles). Those are recorded as links (coplanar_links): a planar chart grows across
 * them, since a projection needs no shared vertices, while a curved chart (LSCM, which
 * joins triangles only through shared vertices) does not.
 */
#include "halfedge_adapter.h"
#include "unwrap_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct vkey {
    float p[3];
    uint32_t v;
} vkey;

static int cmp_position(const float *x, const float *y)
{
    for (int i = 0; i < 3; i++)
        if (x[i] != y[i])
            return x[i] < y[i] ? -1 : 1;
    return 0;
}

static int cmp_vkey(const void *a, const void *b)
{
    const vkey *x = a, *y = b;
    int c = cmp_position(x->p, y->p);
    return c ? c : (x->v > y->v) - (x->v < y->v);
}

static void geometry(const lmb_unwrap_input *in, uint32_t f, lmb_topology *t)
{
    const float *a = in->positions + 3 * in->indices[3 * f], *b = in->positions + 3 * in->indices[3 * f + 1],
                *c = in->positions + 3 * in->indices[3 * f + 2];
    double e1[3], e2[3], n[3];
    for (int i = 0; i < 3; i++) {
        e1[i] = (double)b[i] - a[i];
        e2[i] = (double)c[i] - a[i];
        t->centroid[3 * f + i] = ((double)a[i] + b[i] + c[i]) / 3.0;
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    t->area[f] = 0.5 * len;
    for (int i = 0; i < 3; i++)
        t->normal[3 * f + i] = len > 0 ? n[i] / len : 0.0;
}

/* t->link: for each seam corner edge, the single other triangle on the same welded edge
 * (sorted edge list) with the same normal that runs the edge the other way (so it lies on
 * the far side of the edge, not over the first); none if there are two or more
 * (overlapping coplanar copies: which to join would be a guess) on either side. */
static int coplanar_links(lmb_topology *t, uint32_t nt, const uint8_t *skip)
{
    lmb_welded_edge *e = malloc(((size_t)nt * 3 + 1) * sizeof *e);
    if (!e)
        return 0;
    uint32_t ne = 0;
    for (uint32_t f = 0; f < nt; f++)
        for (uint32_t k = 0; k < 3; k++) {
            t->link[3 * f + k] = LMB_NONE;
            uint32_t a = t->weld[3 * f + k], b = t->weld[3 * f + (k + 1) % 3];
            if (!skip[f] && t->neighbor[3 * f + k] == LMB_NONE && a != b)
                e[ne++] = (lmb_welded_edge){a < b ? a : b, a < b ? b : a, f, k};
        }
    qsort(e, ne, sizeof *e, lmb_cmp_welded_edge);
    for (uint32_t i = 0, j; i < ne; i = j) {
        for (j = i + 1; j < ne && e[j].lo == e[i].lo && e[j].hi == e[i].hi;)
            j++;
        for (uint32_t x = i; x < j; x++) {
            const double *nx = t->normal + 3 * e[x].face;
            uint32_t found = LMB_NONE, count = 0;
            for (uint32_t y = i; y < j; y++) {
                const double *ny = t->normal + 3 * e[y].face;
                /* the edge must run the other way in y: then y lies across it, not over x */
                if (y != x && t->weld[3 * e[y].face + e[y].k] != t->weld[3 * e[x].face + e[x].k] &&
                    nx[0] * ny[0] + nx[1] * ny[1] + nx[2] * ny[2] >= LMB_PLANAR_DOT) {
                    found = e[y].face;
                    count++;
                }
            }
            if (count == 1)
                t->link[3 * e[x].face + e[x].k] = found;
        }
    }
    /* keep only links both sides agree on (a duplicate layer makes one side ambiguous) */
    for (uint32_t i = 0; i < ne; i++) {
        uint32_t f = e[i].face, g = t->link[3 * f + e[i].k], back = 0;
        for (int k = 0; g != LMB_NONE && k < 3; k++)
            back |= t->link[3 * g + k] == f;
        if (g != LMB_NONE && !back)
            t->link[3 * f + e[i].k] = LMB_NONE;
    }
    free(e);
    return 1;
}

/* Welded id per input vertex (ids in order of position) and one position per welded id. */
static uint32_t weld(const lmb_unwrap_input *in, vkey *vk, uint32_t *id, float *welded)
{
    uint32_t nv = in->vertex_count, count = 0;
    for (uint32_t v = 0; v < nv; v++) {
        memcpy(vk[v].p, in->positions + 3 * v, sizeof vk[v].p);
        vk[v].v = v;
    }
    qsort(vk, nv, sizeof *vk, cmp_vkey);
    for (uint32_t i = 0; i < nv; i++) {
        if (i > 0 && cmp_position(vk[i].p, vk[i - 1].p) != 0)
            count++;
        id[vk[i].v] = count;
        memcpy(welded + 3 * (size_t)count, vk[i].p, sizeof vk[i].p);
    }
    return count + (nv > 0);
}

lmb_status lmb_topology_build(const lmb_unwrap_input *in, const char *name, lmb_topology *t, lmb_error *err)
{
    memset(t, 0, sizeof *t);
    uint32_t nv = in->vertex_count, nt = in->triangle_count;
    vkey *vk = malloc(((size_t)nv + 1) * sizeof *vk);
    uint32_t *id = malloc(((size_t)nv + 1) * sizeof *id), *faces = malloc(((size_t)nt * 3 + 1) * sizeof *faces);
    t->weld = faces;
    t->link = malloc(((size_t)nt * 3 + 1) * sizeof *t->link);
    float *welded = malloc(((size_t)nv * 3 + 1) * sizeof *welded);
    uint8_t *skip = malloc((size_t)nt + 1);
    t->corner = malloc(((size_t)nt * 3 + 1) * sizeof *t->corner);
    t->neighbor = malloc(((size_t)nt * 3 + 1) * sizeof *t->neighbor);
    t->normal = calloc((size_t)nt * 3 + 1, sizeof *t->normal);
    t->area = calloc((size_t)nt + 1, sizeof *t->area);
    t->centroid = calloc((size_t)nt * 3 + 1, sizeof *t->centroid);
    lmb_status st = LMB_OK;
    if (!vk || !id || !faces || !t->link || !welded || !skip || !t->corner || !t->neighbor || !t->normal || !t->area ||
        !t->centroid) {
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: mesh '%s': out of memory for %u triangles",
                           name ? name : "mesh", nt);
    } else {
        uint32_t nw = weld(in, vk, id, welded);
        for (uint32_t f = 0; f < nt; f++) {
            geometry(in, f, t);
            skip[f] = (in->skip && in->skip[f]) || !(t->area[f] > 0);
            for (int k = 0; k < 3; k++)
                faces[3 * f + k] = id[in->indices[3 * f + k]];
        }
        lmb_halfedge_input h = {name, nw, welded, nt, faces, skip};
        st = lmb_halfedge_build(&h, t->corner, t->neighbor, &t->vertex_count, &t->counts, err);
        if (st == LMB_OK && !coplanar_links(t, nt, skip))
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: mesh '%s': out of memory for %u triangles",
                               name ? name : "mesh", nt);
    }
    free(vk);
    free(id);
    free(welded);
    free(skip);
    if (st != LMB_OK)
        lmb_topology_free(t);
    return st;
}

void lmb_topology_free(lmb_topology *t)
{
    free(t->corner);
    free(t->weld);
    free(t->neighbor);
    free(t->link);
    free(t->normal);
    free(t->area);
    free(t->centroid);
    memset(t, 0, sizeof *t);
}
