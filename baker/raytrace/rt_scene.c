/*
 * Embree 3 scene of the whole level (see rt_scene.h). One triangle geometry per
 * (instance, primitive), vertices transformed to world space at build time (simpler than
 * Embree instancing, and the scenes lmbake bakes fit easily in memory); built with
 * RTC_SCENE_FLAG_ROBUST so rays along shared edges do not slip through.
 */
#include "rt_scene.h"

#include "../util/mat4.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <xmmintrin.h>
#include <pmmintrin.h>

void lmb_rt_thread_init(void)
{
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

void lmb_rt_free(lmb_rt *rt)
{
    if (rt->scene)
        rtcReleaseScene(rt->scene);
    if (rt->device)
        rtcReleaseDevice(rt->device);
    free(rt->geoms);
    memset(rt, 0, sizeof *rt);
}

static lmb_status add_geometry(lmb_rt *rt, const lmb_scene *s, uint32_t i, uint32_t p, uint32_t first, double lo[3],
                               double hi[3], lmb_error *err)
{
    const lmb_instance *in = &s->instances[i];
    const lmb_primitive *pr = &s->primitives[p];
    RTCGeometry g = rtcNewGeometry(rt->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), pr->vertex_count);
    unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                           pr->triangle_count);
    if (!v || !ix) {
        rtcReleaseGeometry(g);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "ray tracing: out of memory for instance '%s'", in->name);
    }
    for (uint32_t k = 0; k < pr->vertex_count; k++) {
        double q[3] = {pr->positions[3 * k], pr->positions[3 * k + 1], pr->positions[3 * k + 2]}, w[3];
        lmb_mat4_point(in->world, q, w);
        for (int d = 0; d < 3; d++) {
            v[3 * k + d] = (float)w[d];
            lo[d] = fmin(lo[d], w[d]);
            hi[d] = fmax(hi[d], w[d]);
        }
    }
    memcpy(ix, pr->indices, (size_t)pr->triangle_count * 3 * sizeof(unsigned));
    rtcCommitGeometry(g);
    unsigned id = rtcAttachGeometry(rt->scene, g);
    rtcReleaseGeometry(g);
    rt->geoms[id].instance = i;
    rt->geoms[id].primitive = p;
    rt->geoms[id].first_triangle = first;
    rt->geoms[id].flips_winding = in->flips_winding;
    return LMB_OK;
}

lmb_status lmb_rt_build(const lmb_scene *s, lmb_rt *rt, lmb_error *err)
{
    memset(rt, 0, sizeof *rt);
    uint32_t n = 0;
    for (uint32_t i = 0; i < s->instance_count; i++)
        n += s->meshes[s->instances[i].mesh].primitive_count;
    rt->geoms = calloc((size_t)n + 1, sizeof *rt->geoms);
    rt->device = rtcNewDevice(NULL);
    if (!rt->geoms || !rt->device) {
        lmb_rt_free(rt);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "ray tracing: cannot create the Embree device");
    }
    rt->scene = rtcNewScene(rt->device);
    rtcSetSceneFlags(rt->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(rt->scene, RTC_BUILD_QUALITY_MEDIUM);
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    lmb_status st = LMB_OK;
    for (uint32_t i = 0; i < s->instance_count && st == LMB_OK; i++) {
        const lmb_mesh *m = &s->meshes[s->instances[i].mesh];
        uint32_t first = 0;
        for (uint32_t p = 0; p < m->primitive_count && st == LMB_OK; p++) {
            if (s->primitives[m->first_primitive + p].triangle_count)
                st = add_geometry(rt, s, i, m->first_primitive + p, first, lo, hi, err);
            first += s->primitives[m->first_primitive + p].triangle_count;
        }
    }
    if (st != LMB_OK) {
        lmb_rt_free(rt);
        return st;
    }
    rt->geom_count = n;
    rtcCommitScene(rt->scene);
    double d2 = 0;
    for (int d = 0; d < 3; d++)
        d2 += hi[d] > lo[d] ? (hi[d] - lo[d]) * (hi[d] - lo[d]) : 0;
    rt->extent = d2 > 0 ? sqrt(d2) : 1.0;
    rt->eps = 1e-5 * rt->extent;
    return LMB_OK;
}

static void make_ray(struct RTCRay *r, const double o[3], const double d[3], double tmin, double tmax)
{
    r->org_x = (float)o[0]; r->org_y = (float)o[1]; r->org_z = (float)o[2];
    r->dir_x = (float)d[0]; r->dir_y = (float)d[1]; r->dir_z = (float)d[2];
    r->tnear = (float)tmin;
    r->tfar = tmax > 3e38 ? INFINITY : (float)tmax;
    r->time = 0;
    r->mask = 0xFFFFFFFFu;
    r->id = 0;
    r->flags = 0;
}

int lmb_rt_occluded(const lmb_rt *rt, const double o[3], const double d[3], double tmin, double tmax)
{
    struct RTCIntersectContext ctx;
    struct RTCRay r;
    rtcInitIntersectContext(&ctx);
    make_ray(&r, o, d, tmin, tmax);
    rtcOccluded1(rt->scene, &ctx, &r);
    return r.tfar < 0; /* Embree sets tfar to -inf on a hit */
}

int lmb_rt_intersect(const lmb_rt *rt, const double o[3], const double d[3], double tmin, double tmax, lmb_rt_hit *hit)
{
    struct RTCIntersectContext ctx;
    struct RTCRayHit rh;
    rtcInitIntersectContext(&ctx);
    make_ray(&rh.ray, o, d, tmin, tmax);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rt->scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    hit->t = rh.ray.tfar;
    hit->geom = rh.hit.geomID;
    hit->prim = rh.hit.primID;
    hit->u = rh.hit.u;
    hit->v = rh.hit.v;
    /* Embree's Ng = (v1 - v0) x (v2 - v0) over the stored (world) winding */
    double ng[3] = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z}, l = sqrt(ng[0] * ng[0] + ng[1] * ng[1] + ng[2] * ng[2]);
    double sg = rt->geoms[hit->geom].flips_winding ? -1.0 : 1.0;
    for (int k = 0; k < 3; k++)
        hit->ng[k] = (float)(l > 0 ? sg * ng[k] / l : 0);
    hit->backface = hit->ng[0] * d[0] + hit->ng[1] * d[1] + hit->ng[2] * d[2] > 0;
    return 1;
}
