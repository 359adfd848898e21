/*
 * Welding and adjacency for the unwrapper. Vertices are merged when their positions are
 * bit-identical (sorted, so the result does not depend on hashing); edges are matched by
 * sorting (welded a, welded b) keys. Two triangles are neighbours only across an edge
 * that exactly two triangles share, in opposite directions: a non-manifold edge or a
 * winding flip becomes a chart seam instead of a crash or a fold.
 */
#include "unwrap_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct vkey {
    float p[3];
    uint32_t v;
} vkey;

static int cmp_vkey(const void *a, const void *b)
{
    const vkey *x = a, *y = b;
    for (int i = 0; i < 3; i++)
        if (x->p[i] != y->p[i])
            return x->p[i] < y->p[i] ? -1 : 1;
    return (x->v > y->v) - (x->v < y->v);
}

typedef struct ekey {
    uint32_t lo, hi; /* welded ids, lo < hi */
    uint32_t corner; /* 3 * triangle + k */
    int forward;     /* the triangle runs lo -> hi */
} ekey;

static int cmp_ekey(const void *a, const void *b)
{
    const ekey *x = a, *y = b;
    if (x->lo != y->lo)
        return x->lo < y->lo ? -1 : 1;
    if (x->hi != y->hi)
        return x->hi < y->hi ? -1 : 1;
    return (x->corner > y->corner) - (x->corner < y->corner);
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

static int skipped(const lmb_unwrap_input *in, const lmb_topology *t, uint32_t f)
{
    return (in->skip && in->skip[f]) || !(t->area[f] > 0);
}

lmb_status lmb_topology_build(const lmb_unwrap_input *in, lmb_topology *t, lmb_error *err)
{
    memset(t, 0, sizeof *t);
    uint32_t nv = in->vertex_count, nt = in->triangle_count;
    vkey *vk = malloc(((size_t)nv + 1) * sizeof *vk);
    ekey *ek = malloc(((size_t)nt * 3 + 1) * sizeof *ek);
    t->weld = malloc(((size_t)nv + 1) * sizeof *t->weld);
    t->neighbor = malloc(((size_t)nt * 3 + 1) * sizeof *t->neighbor);
    t->normal = calloc((size_t)nt * 3 + 1, sizeof *t->normal);
    t->area = calloc((size_t)nt + 1, sizeof *t->area);
    t->centroid = calloc((size_t)nt * 3 + 1, sizeof *t->centroid);
    if (!vk || !ek || !t->weld || !t->neighbor || !t->normal || !t->area || !t->centroid) {
        free(vk);
        free(ek);
        lmb_topology_free(t);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "unwrap: out of memory for %u triangles", nt);
    }
    for (uint32_t v = 0; v < nv; v++) {
        memcpy(vk[v].p, in->positions + 3 * v, sizeof vk[v].p);
        vk[v].v = v;
    }
    qsort(vk, nv, sizeof *vk, cmp_vkey);
    for (uint32_t i = 0; i < nv; i++) {
        if (i > 0 && memcmp(vk[i].p, vk[i - 1].p, sizeof vk[i].p) != 0)
            t->welded_count++;
        t->weld[vk[i].v] = t->welded_count;
    }
    t->welded_count += nv > 0;
    uint32_t ne = 0;
    for (uint32_t f = 0; f < nt; f++) {
        geometry(in, f, t);
        for (int k = 0; k < 3; k++) {
            t->neighbor[3 * f + k] = LMB_NONE;
            if (skipped(in, t, f))
                continue;
            uint32_t a = t->weld[in->indices[3 * f + k]], b = t->weld[in->indices[3 * f + (k + 1) % 3]];
            if (a == b)
                continue;
            ek[ne].lo = a < b ? a : b;
            ek[ne].hi = a < b ? b : a;
            ek[ne].corner = 3 * f + (uint32_t)k;
            ek[ne].forward = a < b;
            ne++;
        }
    }
    qsort(ek, ne, sizeof *ek, cmp_ekey);
    for (uint32_t i = 0; i < ne;) {
        uint32_t j = i;
        while (j < ne && ek[j].lo == ek[i].lo && ek[j].hi == ek[i].hi)
            j++;
        if (j - i == 2 && ek[i].forward != ek[i + 1].forward) {
            t->neighbor[ek[i].corner] = ek[i + 1].corner / 3;
            t->neighbor[ek[i + 1].corner] = ek[i].corner / 3;
        } else if (j - i > 2) {
            t->nonmanifold_edges++;
        }
        i = j;
    }
    free(vk);
    free(ek);
    return LMB_OK;
}

void lmb_topology_free(lmb_topology *t)
{
    free(t->weld);
    free(t->neighbor);
    free(t->normal);
    free(t->area);
    free(t->centroid);
    memset(t, 0, sizeof *t);
}
