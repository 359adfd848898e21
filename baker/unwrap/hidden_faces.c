/*
 * Hidden faces (see hidden_faces.h), in two steps:
 *
 * 1. Back to back: a triangle whose sample points (its centroid and points 98% of the way to its
 *    corners and edge midpoints) all lie on triangles of the opposite facing in its plane, within
 *    32 float steps of the mesh's largest coordinate or diagonal (1.3 mm on a 340-unit level). Planes are found by sorting the triangles on their quantized
 *    normal and offset; a triangle looks up every cell the opposite plane's key can round to
 *    (one or two per component), so a rounding boundary does not split a pair.
 * 2. Inside a solid, on either side: from just off each sample point of such a triangle, rays
 *    along that side's normal and four directions 60 degrees off it must each meet the back of a
 *    face before the front of any other (a coincident front and back, two touching solids, count
 *    as the back). The front inside: the face is pressed into a solid. The back inside: the face
 *    bounds a solid resting on the faces that cover it (a crate's bottom on a one-sided floor).
 *    Two-sided cards (two faces back to back, open space on both sides) stay lit.
 *
 * Embree (a scene of the input's triangles, built on `threads` threads) traces the rays: the
 * back and the front are told apart by a context filter, each query keeping one side only. Both
 * steps run over the triangles in parallel (OpenMP); each triangle's answer is its own.
 */
#include "hidden_faces.h"

#include "../util/frame.h"

#include <embree3/rtcore.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NORMAL_CELLS 16.0   /* normal components quantized to 1/16 */
#define NORMAL_SLACK 0.009  /* opposite normals: dot <= -0.99996, each component within 0.009 */
#define SAMPLE_POINTS 7     /* centroid, 3 corners, 3 edge midpoints (pulled in) */
#define RAY_POINTS 4        /* centroid and the 3 pulled corners trace rays */
#define RAYS_PER_POINT 5
#define MAX_CHECKS 4096     /* triangles of the opposite plane one triangle is compared with */

/* A triangle's plane, quantized, and its extent along an axis of the plane (the axis after the
 * normal's largest component): triangles are sorted by plane, then by `lo`, so a lookup visits
 * only the triangles of a plane whose extents can overlap (a level's whole floor is one plane). */
typedef struct plane_key {
    int32_t n[3];
    int64_t d;
    double lo, hi;    /* extent along the sort axis */
    double lo2, hi2;  /* and along the plane's other axis */
    double run_width; /* the largest hi - lo among the keys of this (n, d) */
    uint32_t f;
} plane_key;

static int compare_keys(const void *pa, const void *pb)
{
    const plane_key *a = pa, *b = pb;
    for (int k = 0; k < 3; k++)
        if (a->n[k] != b->n[k])
            return a->n[k] < b->n[k] ? -1 : 1;
    if (a->d != b->d)
        return a->d < b->d ? -1 : 1;
    if (a->lo != b->lo)
        return a->lo < b->lo ? -1 : 1;
    return (a->f > b->f) - (a->f < b->f);
}

/* The first key not below (n, d, lo) (f ignored). */
static size_t lower_bound(const plane_key *keys, size_t count, const int32_t n[3], int64_t d, double lo)
{
    plane_key probe = {{n[0], n[1], n[2]}, d, lo, 0, 0, 0, 0, 0};
    size_t a = 0, b = count;
    while (a < b) {
        size_t mid = a + (b - a) / 2;
        if (compare_keys(&keys[mid], &probe) < 0)
            a = mid + 1;
        else
            b = mid;
    }
    return a;
}

static int same_plane(const plane_key *k, const int32_t n[3], int64_t d)
{
    return k->n[0] == n[0] && k->n[1] == n[1] && k->n[2] == n[2] && k->d == d;
}

/* The normal's largest component, and the axis a quantized normal's plane is sorted along (the
 * one after it); the third is the plane's other axis. */
static int big_axis(const int32_t n[3])
{
    int big = 0;
    for (int k = 1; k < 3; k++)
        if (abs(n[k]) > abs(n[big]))
            big = k;
    return big;
}

static int sort_axis(const int32_t n[3])
{
    return (big_axis(n) + 1) % 3;
}

static int other_axis(const int32_t n[3])
{
    return (big_axis(n) + 2) % 3;
}

static void corner(const lmb_unwrap_input *in, uint32_t f, int k, double out[3])
{
    const float *p = in->positions + 3 * (size_t)in->indices[3 * (size_t)f + k];
    out[0] = p[0];
    out[1] = p[1];
    out[2] = p[2];
}

/* The triangle's sample points: centroid, then 98% of the way to each corner and edge midpoint. */
static void sample_points(const lmb_unwrap_input *in, uint32_t f, double pts[SAMPLE_POINTS][3])
{
    double c[3][3], g[3];
    for (int k = 0; k < 3; k++)
        corner(in, f, k, c[k]);
    for (int a = 0; a < 3; a++)
        g[a] = (c[0][a] + c[1][a] + c[2][a]) / 3.0;
    for (int a = 0; a < 3; a++) {
        pts[0][a] = g[a];
        for (int k = 0; k < 3; k++) {
            pts[1 + k][a] = g[a] + 0.98 * (c[k][a] - g[a]);
            pts[4 + k][a] = g[a] + 0.98 * (0.5 * (c[k][a] + c[(k + 1) % 3][a]) - g[a]);
        }
    }
}

/* p within triangle g (barycentrics of p's projection on g's plane, a little tolerance). */
static int point_on_triangle(const lmb_unwrap_input *in, uint32_t g, const double p[3])
{
    double a[3], b[3], c[3], v0[3], v1[3], v2[3];
    corner(in, g, 0, a);
    corner(in, g, 1, b);
    corner(in, g, 2, c);
    for (int k = 0; k < 3; k++) {
        v0[k] = b[k] - a[k];
        v1[k] = c[k] - a[k];
        v2[k] = p[k] - a[k];
    }
    double d00 = 0, d01 = 0, d11 = 0, d20 = 0, d21 = 0;
    for (int k = 0; k < 3; k++) {
        d00 += v0[k] * v0[k];
        d01 += v0[k] * v1[k];
        d11 += v1[k] * v1[k];
        d20 += v2[k] * v0[k];
        d21 += v2[k] * v1[k];
    }
    double den = d00 * d11 - d01 * d01;
    if (!(den > 0))
        return 0;
    double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den, u = 1.0 - v - w;
    const double e = -1e-6;
    return u >= e && v >= e && w >= e;
}

typedef struct side_context {
    struct RTCIntersectContext rtc; /* first: Embree hands the filter this pointer */
    int keep_back;                  /* 1: only hits on a face's back count; 0: only on its front */
} side_context;

/* Embree's RTCRayN/RTCHitN layout (rtcore_ray.h): direction at floats 4..6 N, Ng at 0..2 N. */
static void keep_one_side(const struct RTCFilterFunctionNArguments *a)
{
    const side_context *c = (const side_context *)a->context;
    const float *ray = (const float *)a->ray, *hit = (const float *)a->hit;
    unsigned n = a->N;
    for (unsigned i = 0; i < n; i++) {
        if (!a->valid[i])
            continue;
        float dn = ray[4 * n + i] * hit[i] + ray[5 * n + i] * hit[n + i] + ray[6 * n + i] * hit[2 * n + i];
        if ((dn > 0) != c->keep_back)
            a->valid[i] = 0;
    }
}

static void make_ray(struct RTCRay *r, const double o[3], const double d[3], double tfar)
{
    memset(r, 0, sizeof *r);
    r->org_x = (float)o[0];
    r->org_y = (float)o[1];
    r->org_z = (float)o[2];
    r->dir_x = (float)d[0];
    r->dir_y = (float)d[1];
    r->dir_z = (float)d[2];
    r->tnear = 0.0f;
    r->tfar = (float)tfar;
    r->mask = 0xFFFFFFFFu;
}

/* 1 if the ray from o along d meets a face's back before (within tol) any face's front. */
static int meets_back_first(RTCScene scene, const double o[3], const double d[3], double tol)
{
    side_context ctx;
    rtcInitIntersectContext(&ctx.rtc);
    ctx.rtc.filter = keep_one_side;
    ctx.keep_back = 1;
    struct RTCRayHit rh;
    make_ray(&rh.ray, o, d, INFINITY);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx.rtc, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0; /* open space that way */
    double back = rh.ray.tfar;
    if (!(back > tol))
        return 1; /* a front there would be coincident with it */
    ctx.keep_back = 0;
    struct RTCRay r;
    make_ray(&r, o, d, back - tol);
    rtcOccluded1(scene, &ctx.rtc, &r);
    return !(r.tfar < 0); /* Embree sets tfar to -inf when occluded */
}

/* 1 if just off triangle f on the side `side` (+1: its front, -1: its back) lies inside a solid:
 * rays from there along that side's normal and 60 degrees off it each meet a back first. */
static int side_inside_a_solid(RTCScene scene, const lmb_unwrap_input *in, uint32_t f, const double front[3],
                               double side, const double centre[3], double tol)
{
    double pts[SAMPLE_POINTS][3], t[3], b[3], dirs[RAYS_PER_POINT][3];
    double n[3] = {side * front[0], side * front[1], side * front[2]};
    sample_points(in, f, pts);
    lmb_frame(n, t, b);
    const double s60 = sqrt(3.0) / 2.0, c60 = 0.5;
    for (int a = 0; a < 3; a++)
        dirs[0][a] = n[a];
    for (int k = 0; k < 4; k++) {
        double phi = 0.78539816339744831 * (2 * k + 1), cp = cos(phi), sp = sin(phi);
        for (int a = 0; a < 3; a++)
            dirs[1 + k][a] = c60 * n[a] + s60 * (cp * t[a] + sp * b[a]);
    }
    for (int p = 0; p < RAY_POINTS; p++) {
        double o[3];
        for (int a = 0; a < 3; a++)
            o[a] = pts[p][a] - centre[a] + 2.0 * tol * n[a];
        for (int r = 0; r < RAYS_PER_POINT; r++)
            if (!meets_back_first(scene, o, dirs[r], tol))
                return 0;
    }
    return 1;
}

/* A face back to back with others is hidden when either side of it is inside a solid: its front
 * (pressed into a solid: a floor's tile under a crate) or its back (it bounds a solid that rests
 * on the faces covering it: a crate's bottom on a one-sided floor, whose far side is the void
 * under the floor). A two-sided card (two faces back to back, open space on both sides) is neither. */
static int hidden_face(RTCScene scene, const lmb_unwrap_input *in, uint32_t f, const double n[3],
                       const double centre[3], double tol)
{
    return side_inside_a_solid(scene, in, f, n, 1.0, centre, tol) ||
           side_inside_a_solid(scene, in, f, n, -1.0, centre, tol);
}

/* The mesh's triangles less `centre` (its box's centre: rays keep float precision for a mesh far
 * from its origin, a level of one mesh placed 10 km out). */
static RTCScene mesh_scene(RTCDevice device, const lmb_unwrap_input *in, const double centre[3])
{
    RTCScene scene = rtcNewScene(device);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!scene || !g) {
        if (g)
            rtcReleaseGeometry(g);
        if (scene)
            rtcReleaseScene(scene);
        return NULL;
    }
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_LOW); /* a few rays per triangle: build fast */
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                       in->vertex_count);
    unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                           in->triangle_count);
    if (!v || !ix) {
        rtcReleaseGeometry(g);
        rtcReleaseScene(scene);
        return NULL;
    }
    for (size_t k = 0; k < 3 * (size_t)in->vertex_count; k++)
        v[k] = (float)((double)in->positions[k] - centre[k % 3]);
    for (size_t k = 0; k < 3 * (size_t)in->triangle_count; k++)
        ix[k] = in->indices[k];
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    return scene;
}

lmb_status lmb_find_hidden_faces(const lmb_unwrap_input *in, int threads, uint8_t *hidden, uint32_t *count,
                                 lmb_error *err)
{
    uint32_t tc = in->triangle_count;
    memset(hidden, 0, tc);
    *count = 0;
    if (tc < 2 || in->vertex_count == 0)
        return LMB_OK;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t v = 0; v < in->vertex_count; v++)
        for (int a = 0; a < 3; a++) {
            double x = in->positions[3 * (size_t)v + a];
            lo[a] = x < lo[a] ? x : lo[a];
            hi[a] = x > hi[a] ? x : hi[a];
        }
    double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
    double reach = 0; /* the largest coordinate: float positions there are FLT_EPSILON x it apart */
    for (int a = 0; a < 3; a++)
        reach = fmax(reach, fmax(fabs(lo[a]), fabs(hi[a])));
    double tol = 32.0 * FLT_EPSILON * fmax(reach, diag), bucket = 4.0 * tol;
    if (!(tol > 0) || !isfinite(tol))
        return LMB_OK;

    double *plane = malloc(((size_t)tc * 4 + 1) * sizeof *plane); /* unit normal, offset */
    plane_key *keys = malloc(((size_t)tc + 1) * sizeof *keys);
    uint8_t *candidate = calloc((size_t)tc + 1, 1);
    if (!plane || !keys || !candidate) {
        free(plane);
        free(keys);
        free(candidate);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "hidden faces: out of memory");
    }
    /* each triangle's plane and key in parallel (a skipped one's key marked f = UINT32_MAX), then
     * the keys packed in triangle order */
#pragma omp parallel for num_threads(threads) schedule(static)
    for (uint32_t f = 0; f < tc; f++) {
        double a[3], b[3], c[3], *n = plane + 4 * (size_t)f;
        plane_key *key = &keys[f];
        corner(in, f, 0, a);
        corner(in, f, 1, b);
        corner(in, f, 2, c);
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if ((in->skip && in->skip[f]) || !(l > 0)) {
            n[3] = NAN;
            key->f = UINT32_MAX;
            continue;
        }
        for (int k = 0; k < 3; k++)
            n[k] /= l;
        n[3] = n[0] * a[0] + n[1] * a[1] + n[2] * a[2];
        for (int k = 0; k < 3; k++)
            key->n[k] = (int32_t)lround(n[k] * NORMAL_CELLS);
        key->d = (int64_t)floor(n[3] / bucket);
        int u = sort_axis(key->n);
        key->lo = fmin(a[u], fmin(b[u], c[u]));
        key->hi = fmax(a[u], fmax(b[u], c[u]));
        int u2 = other_axis(key->n);
        key->lo2 = fmin(a[u2], fmin(b[u2], c[u2]));
        key->hi2 = fmax(a[u2], fmax(b[u2], c[u2]));
        key->f = f;
    }
    size_t nk = 0;
    for (uint32_t f = 0; f < tc; f++)
        if (keys[f].f != UINT32_MAX)
            keys[nk++] = keys[f];
    qsort(keys, nk, sizeof *keys, compare_keys);
    for (size_t r0 = 0, r1; r0 < nk; r0 = r1) {
        double width = 0;
        for (r1 = r0; r1 < nk && same_plane(&keys[r1], keys[r0].n, keys[r0].d); r1++)
            width = fmax(width, keys[r1].hi - keys[r1].lo);
        for (size_t i = r0; i < r1; i++)
            keys[i].run_width = width;
    }

    /* step 1: back to back. A triangle compares itself with at most MAX_CHECKS others (a plane
     * of many overlapping slivers would otherwise compare every pair): past that it stays lit. */
    uint32_t candidates = 0;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 256) reduction(+ : candidates)
    for (uint32_t f = 0; f < tc; f++) {
        const double *n = plane + 4 * (size_t)f;
        uint32_t checks = 0;
        if (isnan(n[3]))
            continue;
        double pts[SAMPLE_POINTS][3];
        sample_points(in, f, pts);
        int covered[SAMPLE_POINTS] = {0}, left = SAMPLE_POINTS;
        /* the cells an opposite face's key can fall in: its normal within NORMAL_SLACK of -n per
         * component, its offset within tol of -d (1 or 2 values each) */
        int32_t nlo[3], nhi[3];
        for (int k = 0; k < 3; k++) {
            nlo[k] = (int32_t)lround((-n[k] - NORMAL_SLACK) * NORMAL_CELLS);
            nhi[k] = (int32_t)lround((-n[k] + NORMAL_SLACK) * NORMAL_CELLS);
        }
        int64_t dlo = (int64_t)floor((-n[3] - tol) / bucket), dhi = (int64_t)floor((-n[3] + tol) / bucket);
        uint32_t cells = (uint32_t)((nhi[0] - nlo[0] + 1) * (nhi[1] - nlo[1] + 1) * (nhi[2] - nlo[2] + 1) * (dhi - dlo + 1));
        for (uint32_t cell = 0; cell < cells && left > 0; cell++) {
            uint32_t c = cell;
            int32_t qn[3];
            for (int k = 0; k < 3; k++) {
                uint32_t span = (uint32_t)(nhi[k] - nlo[k] + 1);
                qn[k] = nlo[k] + (int32_t)(c % span);
                c /= span;
            }
            int64_t qd = dlo + (int64_t)c;
            size_t run = lower_bound(keys, nk, qn, qd, -INFINITY);
            if (run >= nk || !same_plane(&keys[run], qn, qd))
                continue;
            int u = sort_axis(qn), u2 = other_axis(qn);
            double flo = INFINITY, fhi = -INFINITY, flo2 = INFINITY, fhi2 = -INFINITY;
            for (int p = 0; p < SAMPLE_POINTS; p++) {
                flo = fmin(flo, pts[p][u]);
                fhi = fmax(fhi, pts[p][u]);
                flo2 = fmin(flo2, pts[p][u2]);
                fhi2 = fmax(fhi2, pts[p][u2]);
            }
            for (size_t i = lower_bound(keys, nk, qn, qd, flo - tol - keys[run].run_width);
                 i < nk && left > 0 && checks < MAX_CHECKS; i++) {
                const plane_key *k = &keys[i];
                if (!same_plane(k, qn, qd) || k->lo > fhi + tol)
                    break;
                if (k->hi < flo - tol || k->hi2 < flo2 - tol || k->lo2 > fhi2 + tol)
                    continue;
                const double *m = plane + 4 * (size_t)k->f;
                checks++;
                if (n[0] * m[0] + n[1] * m[1] + n[2] * m[2] > -0.99996 || fabs(n[3] + m[3]) > tol)
                    continue;
                for (int p = 0; p < SAMPLE_POINTS; p++)
                    if (!covered[p] && point_on_triangle(in, k->f, pts[p])) {
                        covered[p] = 1;
                        left--;
                    }
            }
        }
        if (left == 0) {
            candidate[f] = 1;
            candidates++;
        }
    }
    free(keys);

    /* step 2: inside a solid */
    lmb_status st = LMB_OK;
    if (candidates > 0) {
        char device_config[64]; /* Embree's build threads: hits and distances do not depend on the BVH */
        snprintf(device_config, sizeof device_config, "threads=%d,verbose=0", threads > 0 ? threads : 1);
        RTCDevice device = rtcNewDevice(device_config);
        double centre[3] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
        RTCScene scene = device ? mesh_scene(device, in, centre) : NULL;
        if (!scene) {
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "hidden faces: Embree could not build the mesh's scene (%d)",
                               device ? (int)rtcGetDeviceError(device) : -1);
        } else {
            uint32_t found = 0;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 64) reduction(+ : found)
            for (uint32_t f = 0; f < tc; f++)
                if (candidate[f] && hidden_face(scene, in, f, plane + 4 * (size_t)f, centre, tol)) {
                    hidden[f] = 1;
                    found++;
                }
            *count = found;
            rtcReleaseScene(scene);
        }
        if (device)
            rtcReleaseDevice(device);
    }
    free(plane);
    free(candidate);
    return st;
}
