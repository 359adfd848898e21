/*
 * Embree 3 scene of the whole level (see rt_scene.h). One triangle geometry per
 * (instance, primitive) of a mesh used once, vertices transformed to world space at build
 * time; a mesh several instances use gets one object-space scene (a geometry per primitive)
 * and an Embree instance per placement (rtcSetGeometryTransform). Built with
 * RTC_SCENE_FLAG_ROBUST so rays along shared edges do not slip through.
 */
#include "rt_scene.h"

#include "../util/clock.h"
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
    for (uint32_t m = 0; rt->mesh_scenes && m < rt->mesh_count; m++)
        if (rt->mesh_scenes[m])
            rtcReleaseScene(rt->mesh_scenes[m]);
    free(rt->mesh_scenes);
    if (rt->device)
        rtcReleaseDevice(rt->device);
    free(rt->geoms);
    free(rt->filters);
    memset(rt, 0, sizeof *rt);
}

static void intersect_filter(const struct RTCFilterFunctionNArguments *a);
static void occluded_filter(const struct RTCFilterFunctionNArguments *a);

/* A triangle geometry of primitive p, its vertices through `world` (NULL: object space), attached
 * to `scene` with id `id`; the world bounds grow by its vertices. fd: its filter data, whose
 * surface decides whether it gets filter functions (only where light passes it in part or all). */
static lmb_status attach_triangles(lmb_rt *rt, RTCScene scene, unsigned id, const lmb_primitive *pr,
                                   const double *world, double lo[3], double hi[3], lmb_rt_filter_data *fd,
                                   lmb_error *err)
{
    RTCGeometry g = rtcNewGeometry(rt->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), pr->vertex_count);
    unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                           pr->triangle_count);
    if (!v || !ix) {
        rtcReleaseGeometry(g);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "ray tracing: out of memory");
    }
    for (uint32_t k = 0; k < pr->vertex_count; k++) {
        double q[3] = {pr->positions[3 * k], pr->positions[3 * k + 1], pr->positions[3 * k + 2]}, w[3];
        if (world)
            lmb_mat4_point(world, q, w);
        else
            memcpy(w, q, sizeof w);
        for (int d = 0; d < 3; d++) {
            v[3 * k + d] = (float)w[d];
            if (world) {
                lo[d] = fmin(lo[d], w[d]);
                hi[d] = fmax(hi[d], w[d]);
            }
        }
    }
    memcpy(ix, pr->indices, (size_t)pr->triangle_count * 3 * sizeof(unsigned));
    if (fd->surface.kind) {
        rtcSetGeometryUserData(g, fd);
        rtcSetGeometryIntersectFilterFunction(g, intersect_filter);
        rtcSetGeometryOccludedFilterFunction(g, occluded_filter);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(scene, g, id);
    rtcReleaseGeometry(g);
    return LMB_OK;
}

/* Mesh m's object-space scene: a geometry per primitive with triangles, ids 0, 1, ... */
static lmb_status mesh_scene(lmb_rt *rt, const lmb_scene *s, uint32_t m, lmb_error *err)
{
    const lmb_mesh *mesh = &s->meshes[m];
    RTCScene sc = rtcNewScene(rt->device);
    rtcSetSceneFlags(sc, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(sc, RTC_BUILD_QUALITY_MEDIUM);
    lmb_status st = LMB_OK;
    unsigned id = 0;
    for (uint32_t p = 0; p < mesh->primitive_count && st == LMB_OK; p++) {
        const lmb_primitive *pr = &s->primitives[mesh->first_primitive + p];
        if (pr->triangle_count) {
            st = attach_triangles(rt, sc, id++, pr, NULL, NULL, NULL, &rt->filters[rt->geom_count + mesh->first_primitive + p],
                                  err);
            rt->stored_triangles += pr->triangle_count;
        }
    }
    rtcCommitScene(sc);
    rt->mesh_scenes[m] = sc;
    return st;
}

/* Instance i as an Embree instance of its mesh's scene, with id `slot` (its first slot); the
 * world bounds grow by its mesh's transformed bounding box. */
static lmb_status attach_instance(lmb_rt *rt, const lmb_scene *s, uint32_t i, unsigned slot, double lo[3], double hi[3])
{
    const lmb_instance *in = &s->instances[i];
    const lmb_mesh *mesh = &s->meshes[in->mesh];
    RTCGeometry g = rtcNewGeometry(rt->device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(g, rt->mesh_scenes[in->mesh]);
    float m[16];
    for (int k = 0; k < 16; k++)
        m[k] = (float)in->world[k];
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, m);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(rt->scene, g, slot);
    rtcReleaseGeometry(g);
    double blo[3] = {1e300, 1e300, 1e300}, bhi[3] = {-1e300, -1e300, -1e300};
    for (uint32_t p = 0; p < mesh->primitive_count; p++) {
        const lmb_primitive *pr = &s->primitives[mesh->first_primitive + p];
        for (uint32_t k = 0; k < pr->vertex_count; k++)
            for (int d = 0; d < 3; d++) {
                blo[d] = fmin(blo[d], pr->positions[3 * k + d]);
                bhi[d] = fmax(bhi[d], pr->positions[3 * k + d]);
            }
    }
    for (int c = 0; c < 8 && blo[0] <= bhi[0]; c++) {
        double q[3] = {c & 1 ? bhi[0] : blo[0], c & 2 ? bhi[1] : blo[1], c & 4 ? bhi[2] : blo[2]}, w[3];
        lmb_mat4_point(in->world, q, w);
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], w[d]);
            hi[d] = fmax(hi[d], w[d]);
        }
    }
    return LMB_OK;
}

/* The inverse transpose of world's upper 3 x 3, row-major (the cofactor matrix over the
 * determinant); normals through it are then normalized. */
static void normal_matrix(const double w[16], float out[9])
{
    double a[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            a[r][c] = w[4 * c + r];
    double cof[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            cof[r][c] = a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1];
        }
    double det = a[0][0] * cof[0][0] + a[0][1] * cof[0][1] + a[0][2] * cof[0][2];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            out[3 * r + c] = (float)(det != 0 ? cof[r][c] / det : 0);
}

lmb_status lmb_rt_build(const lmb_scene *s, const lmb_textures *tx, lmb_rt *rt, lmb_error *err)
{
    double t0 = lmb_seconds();
    memset(rt, 0, sizeof *rt);
    uint32_t n = 0;
    for (uint32_t i = 0; i < s->instance_count; i++) /* what moves is not in it (lmb_instance.occludes) */
        n += s->instances[i].occludes ? s->meshes[s->instances[i].mesh].primitive_count : 0;
    uint32_t *uses = calloc((size_t)s->mesh_count + 1, sizeof *uses);
    rt->geoms = calloc((size_t)n + 1, sizeof *rt->geoms);
    rt->mesh_scenes = calloc((size_t)s->mesh_count + 1, sizeof *rt->mesh_scenes);
    rt->mesh_count = s->mesh_count;
    rt->geom_count = n; /* the filters' world part; set again when built */
    rt->filters = calloc((size_t)n + s->primitive_count + 1, sizeof *rt->filters);
    for (uint32_t p = 0; rt->filters && p < s->primitive_count; p++) {
        const lmb_primitive *pr = &s->primitives[p];
        rt->filters[n + p].surface = lmb_rt_surface_of(pr->material >= 0 ? &s->materials[pr->material] : NULL, pr, tx);
    }
    rt->device = rtcNewDevice(NULL);
    if (!uses || !rt->geoms || !rt->mesh_scenes || !rt->device || !rt->filters) {
        free(uses);
        lmb_rt_free(rt);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "ray tracing: cannot create the Embree device");
    }
    rt->scene = rtcNewScene(rt->device);
    rtcSetSceneFlags(rt->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(rt->scene, RTC_BUILD_QUALITY_MEDIUM);
    for (uint32_t i = 0; i < s->instance_count; i++)
        uses[s->instances[i].mesh] += s->instances[i].occludes != 0;
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    lmb_status st = LMB_OK;
    uint32_t slot = 0;
    for (uint32_t i = 0; i < s->instance_count && st == LMB_OK; i++) {
        const lmb_instance *in = &s->instances[i];
        const lmb_mesh *m = &s->meshes[in->mesh];
        if (!in->occludes)
            continue;
        int instanced = uses[in->mesh] >= 2;
        if (instanced && !rt->mesh_scenes[in->mesh])
            st = mesh_scene(rt, s, in->mesh, err);
        if (instanced && st == LMB_OK && m->triangle_count)
            st = attach_instance(rt, s, i, slot, lo, hi);
        uint32_t first = 0;
        for (uint32_t p = 0; p < m->primitive_count && st == LMB_OK; p++) {
            const lmb_primitive *pr = &s->primitives[m->first_primitive + p];
            if (pr->triangle_count) {
                lmb_rt_geom *g = &rt->geoms[slot];
                lmb_rt_filter_data *fd = &rt->filters[n + m->first_primitive + p];
                if (!instanced) {
                    rt->filters[slot].surface = fd->surface;
                    rt->filters[slot].flips_winding = in->flips_winding;
                    st = attach_triangles(rt, rt->scene, slot, pr, in->world, lo, hi, &rt->filters[slot], err);
                    rt->stored_triangles += pr->triangle_count;
                }
                rt->cut_geoms += (fd->surface.kind & LMB_SURFACE_CUT) != 0;
                rt->partial_geoms += (fd->surface.kind & LMB_SURFACE_PARTIAL) != 0;
                rt->cut_triangles += fd->surface.kind & LMB_SURFACE_CUT ? pr->triangle_count : 0;
                rt->partial_triangles += fd->surface.kind & LMB_SURFACE_PARTIAL ? pr->triangle_count : 0;
                g->instance = i;
                g->primitive = m->first_primitive + p;
                g->first_triangle = first;
                g->flips_winding = in->flips_winding;
                g->instanced = instanced;
                if (instanced)
                    normal_matrix(in->world, g->normal_matrix);
                rt->placed_triangles += pr->triangle_count;
                slot++;
            }
            first += pr->triangle_count;
        }
    }
    free(uses);
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
    rt->build_seconds = lmb_seconds() - t0;
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

/* What a query asks of the surfaces light partly passes (the filters read it). */
enum { QUERY_PLAIN = 0, QUERY_TRANSMIT = 1, QUERY_LAYERS = 2 };

/* A query's Embree context with what the filters keep: the partly passing surfaces met. */
typedef struct rt_query {
    struct RTCIntersectContext ctx; /* first: Embree hands it to the filters */
    const lmb_rt *rt;
    int mode;
    double o[3], d[3]; /* the ray's world origin and direction */
    uint32_t count;
    lmb_rt_layer layer[LMB_RT_MAX_LAYERS];
} rt_query;

static void query_init(rt_query *q, const lmb_rt *rt, int mode, const double o[3], const double d[3])
{
    rtcInitIntersectContext(&q->ctx);
    q->rt = rt;
    q->mode = mode;
    q->count = 0;
    if (mode != QUERY_PLAIN) { /* only the filters of such queries read them */
        memcpy(q->o, o, sizeof q->o);
        memcpy(q->d, d, sizeof q->d);
    }
}

/* A hit's slot, world geometric normal (front side, unit) and side, from what Embree reports: the
 * slot's normal matrix turns an instanced hit's object-space Ng. */
static inline void fill_hit(const lmb_rt *rt, unsigned inst, unsigned geom, unsigned prim, float u, float v, const float ngo[3],
                     double t, const double o[3], const double d[3], lmb_rt_hit *hit)
{
    int instanced = inst != RTC_INVALID_GEOMETRY_ID;
    hit->t = t;
    for (int k = 0; k < 3; k++)
        hit->p[k] = o[k] + t * d[k];
    hit->geom = instanced ? inst + geom : geom; /* the slot */
    hit->prim = prim;
    hit->u = u;
    hit->v = v;
    const lmb_rt_geom *g = &rt->geoms[hit->geom];
    double ng[3] = {ngo[0], ngo[1], ngo[2]}, sg = 1.0;
    if (instanced) { /* Ng in object space: world = M^-T Ng, which also follows a mirrored instance's winding */
        const float *nm = g->normal_matrix;
        double o[3] = {ng[0], ng[1], ng[2]};
        for (int r = 0; r < 3; r++)
            ng[r] = nm[3 * r] * o[0] + nm[3 * r + 1] * o[1] + nm[3 * r + 2] * o[2];
    } else { /* Embree's Ng = (v1 - v0) x (v2 - v0) over the stored (world) winding */
        sg = g->flips_winding ? -1.0 : 1.0;
    }
    double l = sqrt(ng[0] * ng[0] + ng[1] * ng[1] + ng[2] * ng[2]);
    for (int k = 0; k < 3; k++)
        hit->ng[k] = (float)(l > 0 ? sg * ng[k] / l : 0);
    hit->backface = hit->ng[0] * d[0] + hit->ng[1] * d[1] + hit->ng[2] * d[2] > 0;
}

/*
 * The filters (Embree calls them for every candidate hit on a geometry that has them, in no set
 * order). A MASK surface's cut-away part is rejected in every query. A surface light partly passes
 * is a hit in a plain query; otherwise its hit is kept in the query and rejected, so the ray goes
 * on: a transmittance query keeps what it lets through (and stops, as occluded, where it lets
 * nothing through or the list is full), a layers query the nearest LMB_RT_MAX_LAYERS such surfaces
 * (one that lets nothing through is a hit). Embree may report one triangle more than once, and a
 * ray through an edge meets both triangles that share it (the scene is built robust, watertight):
 * a triangle already kept, or another of the same geometry met within the ray offset of it, is
 * not kept again. What the query returns depends only on the set of
 * surfaces met, never on the order they came in.
 */
/* Embree's RTCHitN / RTCRayN accessors are C++ only: the same structure-of-arrays layout read in C
 * (rtcore_ray.h: hit Ng_x, Ng_y, Ng_z, u, v as float[N], then primID, geomID, instID[0] as
 * unsigned[N]; ray org_x .. time as float[N] each, then tfar). */
#define HIT_F(h, n, field) (((const float *)(h))[(field) * (n)])
#define HIT_U(h, n, field) (((const unsigned *)(h))[(field) * (n)])
#define RAY_TFAR(r, n) (((const float *)(r))[8 * (n)])

static void filter(const struct RTCFilterFunctionNArguments *a, int occlusion)
{
    if (!a->valid[0])
        return;
    const lmb_rt_filter_data *fd = a->geometryUserPtr;
    rt_query *q = (rt_query *)a->context;
    unsigned prim = HIT_U(a->hit, a->N, 5);
    float u = HIT_F(a->hit, a->N, 3), v = HIT_F(a->hit, a->N, 4);
    if (lmb_rt_surface_cut(&fd->surface, prim, u, v)) {
        a->valid[0] = 0;
        return;
    }
    if (!(fd->surface.kind & LMB_SURFACE_PARTIAL) || q->mode == QUERY_PLAIN)
        return;
    lmb_rt_hit h;
    const float ng[3] = {HIT_F(a->hit, a->N, 0), HIT_F(a->hit, a->N, 1), HIT_F(a->hit, a->N, 2)};
    fill_hit(q->rt, HIT_U(a->hit, a->N, 7), HIT_U(a->hit, a->N, 6), prim, u, v, ng, RAY_TFAR(a->ray, a->N), q->o, q->d, &h);
    for (uint32_t k = 0; k < q->count; k++)
        if (q->layer[k].hit.geom == h.geom &&
            (q->layer[k].hit.prim == h.prim || fabs(q->layer[k].hit.t - h.t) <= q->rt->eps)) {
            a->valid[0] = 0; /* met again, or the same crossing on the edge two triangles share */
            return;
        }
    double pass[3], cover;
    lmb_rt_surface_pass(&fd->surface, prim, u, v, h.backface, pass, &cover);
    if (!(pass[0] > 0 || pass[1] > 0 || pass[2] > 0))
        return; /* lets nothing through: a hit */
    uint32_t at = q->count;
    if (q->count == LMB_RT_MAX_LAYERS) {
        if (occlusion || q->mode == QUERY_TRANSMIT)
            return; /* too many: occluded */
        at = 0; /* layers: the farthest kept goes, if this one is nearer */
        for (uint32_t k = 1; k < q->count; k++)
            if (q->layer[k].hit.t > q->layer[at].hit.t ||
                (q->layer[k].hit.t == q->layer[at].hit.t && q->layer[k].hit.geom > q->layer[at].hit.geom))
                at = k;
        if (!(h.t < q->layer[at].hit.t)) {
            a->valid[0] = 0;
            return;
        }
    } else {
        q->count++;
    }
    q->layer[at].hit = h;
    memcpy(q->layer[at].pass, pass, sizeof pass);
    q->layer[at].cover = cover;
    a->valid[0] = 0;
}

static void intersect_filter(const struct RTCFilterFunctionNArguments *a)
{
    filter(a, 0);
}

static void occluded_filter(const struct RTCFilterFunctionNArguments *a)
{
    filter(a, 1);
}

int lmb_rt_occluded(const lmb_rt *rt, const double o[3], const double d[3], double tmin, double tmax)
{
    rt_query q;
    struct RTCRay r;
    query_init(&q, rt, QUERY_PLAIN, o, d);
    make_ray(&r, o, d, tmin, tmax);
    rtcOccluded1(rt->scene, &q.ctx, &r);
    return r.tfar < 0; /* Embree sets tfar to -inf on a hit */
}

/* Layers in a fixed order (distance, then slot and triangle), whatever order they were met in. */
static int layer_order(const void *pa, const void *pb)
{
    const lmb_rt_hit *a = &((const lmb_rt_layer *)pa)->hit, *b = &((const lmb_rt_layer *)pb)->hit;
    if (a->t != b->t)
        return a->t < b->t ? -1 : 1;
    if (a->geom != b->geom)
        return a->geom < b->geom ? -1 : 1;
    return (a->prim > b->prim) - (a->prim < b->prim);
}

int lmb_rt_transmittance(const lmb_rt *rt, const double o[3], const double d[3], double tmin, double tmax,
                         double pass[3])
{
    rt_query q;
    struct RTCRay r;
    query_init(&q, rt, rt->partial_geoms ? QUERY_TRANSMIT : QUERY_PLAIN, o, d);
    make_ray(&r, o, d, tmin, tmax);
    rtcOccluded1(rt->scene, &q.ctx, &r);
    pass[0] = pass[1] = pass[2] = r.tfar < 0 ? 0.0 : 1.0;
    if (r.tfar < 0 || !q.count)
        return r.tfar < 0;
    qsort(q.layer, q.count, sizeof *q.layer, layer_order);
    for (uint32_t k = 0; k < q.count; k++)
        for (int c = 0; c < 3; c++)
            pass[c] *= q.layer[k].pass[c];
    return 0;
}

/* Closest hit of a query in mode `mode`; q keeps the layers met. */
static int intersect(const lmb_rt *rt, rt_query *q, const double o[3], const double d[3], double tmin, double tmax,
                     lmb_rt_hit *hit)
{
    struct RTCRayHit rh;
    make_ray(&rh.ray, o, d, tmin, tmax);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(rt->scene, &q->ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    const float ng[3] = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
    fill_hit(rt, rh.hit.instID[0], rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, ng, rh.ray.tfar, o, d, hit);
    return 1;
}

int lmb_rt_intersect(const lmb_rt *rt, const double o[3], const double d[3], double tmin, double tmax, lmb_rt_hit *hit)
{
    rt_query q;
    query_init(&q, rt, QUERY_PLAIN, o, d);
    return intersect(rt, &q, o, d, tmin, tmax, hit);
}

int lmb_rt_intersect_layers(const lmb_rt *rt, const double o[3], const double d[3], double tmin, double tmax,
                            lmb_rt_hit *hit, lmb_rt_layer *layers, uint32_t *count)
{
    rt_query q;
    query_init(&q, rt, rt->partial_geoms ? QUERY_LAYERS : QUERY_PLAIN, o, d);
    int found = intersect(rt, &q, o, d, tmin, tmax, hit);
    *count = 0;
    for (uint32_t k = 0; k < q.count; k++)
        if (!found || q.layer[k].hit.t < hit->t)
            layers[(*count)++] = q.layer[k];
    if (*count > 1)
        qsort(layers, *count, sizeof *layers, layer_order);
    return found;
}

int lmb_rt_triangle_cut(const lmb_rt *rt, const lmb_scene *s, uint32_t instance, uint32_t tri, double b1, double b2)
{
    if (!rt->cut_geoms)
        return 0;
    const lmb_mesh *m = &s->meshes[s->instances[instance].mesh];
    for (uint32_t p = 0; p < m->primitive_count; p++) {
        const lmb_primitive *pr = &s->primitives[m->first_primitive + p];
        if (tri < pr->triangle_count)
            return lmb_rt_surface_cut(&rt->filters[rt->geom_count + m->first_primitive + p].surface, tri, b1, b2);
        tri -= pr->triangle_count;
    }
    return 0;
}
