/* Seam edges (see seam_edges.h): each mesh's chart-interior edges found once, then every
 * instance's other edges hashed by their snapped world endpoints and sorted in parallel. */
#include "seam_edges.h"

#include <omp.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void snapped_endpoint(const double *p, double snap, int64_t out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = (int64_t)llround(p[r] / snap);
}

static int endpoint_less(const int64_t a[3], const int64_t b[3])
{
    for (int r = 0; r < 3; r++)
        if (a[r] != b[r])
            return a[r] < b[r];
    return 0;
}

static uint64_t hash_key(const int64_t k[6])
{
    uint64_t h = 1469598103934665603ull;
    for (int i = 0; i < 6; i++) {
        h ^= (uint64_t)k[i];
        h *= 1099511628211ull;
        h ^= h >> 29;
    }
    return h;
}

/* The snapped endpoints of an edge, smaller first; *swapped as in edge_ref. */
void lmb_seam_edge_key(const lmb_scene *s, const lmb_layout *l, uint32_t instance, uint32_t f, int corner, double snap,
                       int64_t key[6], int *swapped)
{
    double q[9];
    lmb_layout_world_triangle(s, l, instance, f, q);
    int64_t a[3], b[3];
    snapped_endpoint(q + 3 * corner, snap, a);
    snapped_endpoint(q + 3 * ((corner + 1) % 3), snap, b);
    *swapped = endpoint_less(b, a);
    memcpy(key, *swapped ? b : a, sizeof a);
    memcpy(key + 3, *swapped ? a : b, sizeof a);
}

static int edge_ref_order(const void *pa, const void *pb)
{
    const edge_ref *a = pa, *b = pb;
    if (a->hash != b->hash)
        return a->hash < b->hash ? -1 : 1;
    if (a->instance != b->instance)
        return a->instance < b->instance ? -1 : 1;
    if (a->triangle != b->triangle)
        return a->triangle < b->triangle ? -1 : 1;
    return (int)a->corner - (int)b->corner;
}

/* The snapping grid: 1/1000 of the finest texel of any lightmapped instance. */
double lmb_seam_snap_size(const lmb_layout *l)
{
    double d = 0;
    for (uint32_t i = 0; i < l->instance_count; i++)
        if (l->instances[i].lightmapped && l->instances[i].texel_density > d)
            d = l->instances[i].texel_density;
    return d > 0 ? 1e-3 / d : 1e-6;
}

/* Sorts e[0..n) by edge_ref_order with `threads` threads: runs sorted at once, then merged
 * pairwise (in parallel). edge_ref_order is a total order (no two refs are equal), so the
 * result is the one order whatever the threads. tmp: room for n refs. */
static void sort_edges(edge_ref *e, edge_ref *tmp, size_t n, int threads)
{
    size_t runs = (size_t)threads * 2, run = (n + runs - 1) / (runs ? runs : 1);
    if (n < 65536 || threads < 2 || !run) {
        qsort(e, n, sizeof *e, edge_ref_order);
        return;
    }
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (size_t r = 0; r < runs; r++) {
        size_t lo = r * run < n ? r * run : n, hi = lo + run < n ? lo + run : n;
        qsort(e + lo, hi - lo, sizeof *e, edge_ref_order);
    }
    edge_ref *src = e, *dst = tmp;
    for (size_t width = run; width < n; width *= 2) {
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
        for (size_t lo = 0; lo < n; lo += 2 * width) {
            size_t mid = lo + width < n ? lo + width : n, hi = lo + 2 * width < n ? lo + 2 * width : n;
            size_t i = lo, j = mid, k = lo;
            while (i < mid && j < hi)
                dst[k++] = edge_ref_order(&src[i], &src[j]) < 0 ? src[i++] : src[j++];
            while (i < mid)
                dst[k++] = src[i++];
            while (j < hi)
                dst[k++] = src[j++];
        }
        edge_ref *t = src;
        src = dst;
        dst = t;
    }
    if (src != e)
        memcpy(e, src, n * sizeof *e);
}

/* A mesh edge by its two endpoints' object-space coordinates (bit for bit), smaller first. */
typedef struct mesh_edge {
    float key[6];
    uint32_t triangle;
    uint8_t corner;
} mesh_edge;

static int mesh_edge_order(const void *pa, const void *pb)
{
    const mesh_edge *a = pa, *b = pb;
    int c = memcmp(a->key, b->key, sizeof a->key);
    if (c)
        return c;
    if (a->triangle != b->triangle)
        return a->triangle < b->triangle ? -1 : 1;
    return (int)a->corner - (int)b->corner;
}

/* Per edge (3 per triangle) of mesh m: 1 when it lies inside one chart: exactly two of the mesh's
 * triangles share its endpoints, in the same chart, with the same chart UVs at both ends. Such
 * an edge has the same texels on both sides in every instance (is_seam says no to it), so it is
 * never collected: a level's copies cost the seams only their charts' borders. NULL when out of
 * memory (every edge is then collected). */
static uint8_t *chart_interior_edges(const lmb_layout *l, uint32_t m)
{
    const lmb_mesh_soup *soup = &l->meshes[m].soup;
    const lmb_charts *c = &l->meshes[m].charts;
    size_t n = 3 * (size_t)soup->triangle_count;
    uint8_t *interior = calloc(n + 1, 1);
    mesh_edge *e = malloc((n + 1) * sizeof *e);
    if (!interior || !e || c->triangle_count != soup->triangle_count) {
        free(e);
        free(interior);
        return NULL;
    }
    for (uint32_t f = 0; f < soup->triangle_count; f++)
        for (int k = 0; k < 3; k++) {
            mesh_edge *x = &e[3 * (size_t)f + k];
            const float *a = soup->positions + 3 * soup->indices[3 * f + k],
                        *b = soup->positions + 3 * soup->indices[3 * f + (k + 1) % 3];
            int swap = memcmp(b, a, 3 * sizeof *a) < 0;
            memcpy(x->key, swap ? b : a, 3 * sizeof *a);
            memcpy(x->key + 3, swap ? a : b, 3 * sizeof *a);
            x->triangle = f;
            x->corner = (uint8_t)k;
        }
    qsort(e, n, sizeof *e, mesh_edge_order);
    for (size_t i = 0; i < n;) {
        size_t j = i + 1;
        while (j < n && !memcmp(e[j].key, e[i].key, sizeof e[i].key))
            j++;
        if (j - i == 2) {
            uint32_t f = e[i].triangle, g = e[i + 1].triangle;
            int fa = e[i].corner, fb = (fa + 1) % 3, ga = e[i + 1].corner, gb = (ga + 1) % 3;
            const double *uf = c->uv + 6 * (size_t)f, *ug = c->uv + 6 * (size_t)g;
            /* the edge runs f: fa -> fb and, the other way, g: gb -> ga (or the same way: a fold) */
            int same = soup->indices[3 * f + fa] == soup->indices[3 * g + gb] ||
                       !memcmp(soup->positions + 3 * soup->indices[3 * f + fa],
                               soup->positions + 3 * soup->indices[3 * g + gb], 3 * sizeof(float));
            int g0 = same ? gb : ga, g1 = same ? ga : gb;
            if (c->chart_of[f] != UINT32_MAX && c->chart_of[f] == c->chart_of[g] && !soup->skip[f] && !soup->skip[g] &&
                uf[2 * fa] == ug[2 * g0] && uf[2 * fa + 1] == ug[2 * g0 + 1] && uf[2 * fb] == ug[2 * g1] &&
                uf[2 * fb + 1] == ug[2 * g1 + 1])
                interior[3 * (size_t)f + fa] = interior[3 * (size_t)g + ga] = 1;
        }
        i = j;
    }
    free(e);
    return interior;
}

/* Every lightmapped triangle's edges but those inside a chart, sorted by hash; in parallel over
 * instances (each writes its own range, found by a prefix sum of their edges). */
lmb_status lmb_seam_collect_edges(const lmb_scene *s, const lmb_layout *l, double snap, int threads, edge_ref **out,
                                  size_t *count, lmb_error *err)
{
    for (uint32_t m = 0; m < l->mesh_count; m++)
        if (l->meshes[m].used && l->meshes[m].soup.triangle_count >= LMB_SEAM_MAX_TRIANGLES)
            return lmb_error_set(err, LMB_ERR_INPUT, "seams: mesh '%s' has %u triangles, more than the %u whose edges can be stitched",
                                 s->meshes[m].name, l->meshes[m].soup.triangle_count, LMB_SEAM_MAX_TRIANGLES - 1);
    size_t *first = malloc(((size_t)l->instance_count + 1) * sizeof *first);
    uint8_t **interior = calloc((size_t)l->mesh_count + 1, sizeof *interior);
    size_t *mesh_edges = calloc((size_t)l->mesh_count + 1, sizeof *mesh_edges);
    if (!first || !interior || !mesh_edges) {
        free(first);
        free(interior);
        free(mesh_edges);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "seams: out of memory for %u instances", l->instance_count);
    }
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (uint32_t m = 0; m < l->mesh_count; m++) {
        if (!l->meshes[m].used)
            continue;
        const lmb_mesh_soup *soup = &l->meshes[m].soup;
        interior[m] = chart_interior_edges(l, m);
        for (uint32_t f = 0; f < soup->triangle_count; f++)
            for (int k = 0; k < 3 && !soup->skip[f]; k++)
                mesh_edges[m] += !(interior[m] && interior[m][3 * (size_t)f + k]);
    }
    size_t n = 0;
    for (uint32_t i = 0; i < l->instance_count; i++) {
        first[i] = n;
        n += l->instances[i].lightmapped ? mesh_edges[s->instances[i].mesh] : 0;
    }
    first[l->instance_count] = n;
    edge_ref *e = malloc((n + 1) * sizeof *e), *tmp = malloc((n + 1) * sizeof *tmp);
    if (!e || !tmp) {
        free(first);
        free(e);
        free(tmp);
        for (uint32_t m = 0; m < l->mesh_count; m++)
            free(interior[m]);
        free(interior);
        free(mesh_edges);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "seams: out of memory for %zu edges", n);
    }
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (uint32_t i = 0; i < l->instance_count; i++) {
        if (!l->instances[i].lightmapped)
            continue;
        const lmb_mesh_soup *soup = &l->meshes[s->instances[i].mesh].soup;
        const uint8_t *inside = interior[s->instances[i].mesh];
        size_t m = first[i];
        for (uint32_t f = 0; f < soup->triangle_count; f++) {
            if (soup->skip[f])
                continue;
            for (int c = 0; c < 3; c++) {
                if (inside && inside[3 * (size_t)f + c])
                    continue;
                int64_t key[6];
                int swapped;
                lmb_seam_edge_key(s, l, i, f, c, snap, key, &swapped);
                e[m++] = (edge_ref){hash_key(key), i, f, (uint32_t)c, (uint32_t)swapped};
            }
        }
    }
    sort_edges(e, tmp, n, threads);
    free(tmp);
    free(first);
    for (uint32_t m = 0; m < l->mesh_count; m++)
        free(interior[m]);
    free(interior);
    free(mesh_edges);
    *out = e;
    *count = n;
    return LMB_OK;
}
