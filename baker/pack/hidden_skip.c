/*
 * atlas.skip_hidden for a whole level (hidden_skip.h): which triangles of the lightmapped meshes
 * face into a solid, back to back with another face (baker/unwrap/hidden_faces.h), and so get no
 * chart.
 *
 * A mesh used by one node only is tested in world space against every other mesh used by one node
 * only: a crate placed by its own node on the level's floor, a wall against its neighbour. A mesh
 * several nodes or EXT_mesh_gpu_instancing copies share is tested against its own faces only:
 * its layout is shared by every placement, so what hides a face must move with it. Meshes with a
 * kept TEXCOORD_1 are left whole.
 */
#include "hidden_skip.h"

#include "../util/clock.h"
#include "../util/mat4.h"
#include "keep_uv1.h"
#include "unwrap/hidden_faces.h"

#include <omp.h>

#include <stdlib.h>
#include <string.h>

/* Marks a mesh's hidden triangles skipped: no chart, no texels, TEXCOORD_1 (0, 0) as a zero-area
 * triangle's. */
static void skip(lmb_mesh_soup *soup, const uint8_t *hidden, uint32_t *count)
{
    for (uint32_t f = 0; f < soup->triangle_count; f++) {
        *count += hidden[f] && !soup->skip[f];
        soup->skip[f] |= hidden[f];
    }
}

static lmb_status own_faces(lmb_layout_mesh *lm, int threads, lmb_error *err)
{
    uint8_t *hidden = malloc((size_t)lm->soup.triangle_count + 1);
    if (!hidden)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "hidden faces: out of memory");
    lmb_unwrap_input in = {lm->soup.vertex_count, lm->soup.positions, lm->soup.triangle_count, lm->soup.indices,
                           lm->soup.skip};
    uint32_t found = 0;
    lmb_status st = lmb_find_hidden_faces(&in, threads, hidden, &found, err);
    if (st == LMB_OK)
        skip(&lm->soup, hidden, &lm->hidden_count);
    free(hidden);
    return st;
}

/* The level's meshes used by one node only, as one soup in world space (each instance's winding
 * kept front-facing: a mirrored node's triangles are turned). first[m]: mesh m's first triangle
 * in it, UINT32_MAX for a mesh not in it. */
typedef struct world_soup {
    float *positions;
    uint32_t *indices;
    uint8_t *degenerate;
    uint32_t vertex_count, triangle_count;
    uint32_t *first;
} world_soup;

static void world_soup_free(world_soup *w)
{
    free(w->positions);
    free(w->indices);
    free(w->degenerate);
    free(w->first);
    memset(w, 0, sizeof *w);
}

static lmb_status build_world_soup(const lmb_scene *s, const uint32_t *uses, const uint32_t *instance_of,
                                   world_soup *w, lmb_error *err)
{
    memset(w, 0, sizeof *w);
    uint64_t nv = 0, nt = 0;
    for (uint32_t m = 0; m < s->mesh_count; m++)
        if (uses[m] == 1)
            for (uint32_t p = 0; p < s->meshes[m].primitive_count; p++) {
                nv += s->primitives[s->meshes[m].first_primitive + p].vertex_count;
                nt += s->primitives[s->meshes[m].first_primitive + p].triangle_count;
            }
    if (nv > UINT32_MAX || nt > UINT32_MAX / 3)
        return LMB_OK; /* beyond one soup's indices: each mesh keeps its own test */
    w->positions = malloc((nv * 3 + 1) * sizeof *w->positions);
    w->indices = malloc((nt * 3 + 1) * sizeof *w->indices);
    w->degenerate = malloc(nt + 1);
    w->first = malloc(((size_t)s->mesh_count + 1) * sizeof *w->first);
    if (!w->positions || !w->indices || !w->degenerate || !w->first) {
        world_soup_free(w);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "hidden faces: out of memory");
    }
    for (uint32_t m = 0; m < s->mesh_count; m++) {
        w->first[m] = UINT32_MAX;
        if (uses[m] != 1)
            continue;
        const lmb_instance *in = &s->instances[instance_of[m]];
        w->first[m] = w->triangle_count;
        for (uint32_t p = 0; p < s->meshes[m].primitive_count; p++) {
            const lmb_primitive *pr = &s->primitives[s->meshes[m].first_primitive + p];
            for (uint32_t v = 0; v < pr->vertex_count; v++) {
                double q[3] = {pr->positions[3 * (size_t)v], pr->positions[3 * (size_t)v + 1],
                               pr->positions[3 * (size_t)v + 2]}, o[3];
                lmb_mat4_point(in->world, q, o);
                for (int k = 0; k < 3; k++)
                    w->positions[3 * ((size_t)w->vertex_count + v) + k] = (float)o[k];
            }
            for (uint32_t t = 0; t < pr->triangle_count; t++) {
                uint32_t *dst = w->indices + 3 * ((size_t)w->triangle_count + t);
                const uint32_t *src = pr->indices + 3 * (size_t)t;
                dst[0] = src[0] + w->vertex_count;
                dst[1] = (in->flips_winding ? src[2] : src[1]) + w->vertex_count;
                dst[2] = (in->flips_winding ? src[1] : src[2]) + w->vertex_count;
                w->degenerate[w->triangle_count + t] = pr->degenerate[t];
            }
            w->vertex_count += pr->vertex_count;
            w->triangle_count += pr->triangle_count;
        }
    }
    return LMB_OK;
}

lmb_status lmb_layout_skip_hidden(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, lmb_error *err)
{
    int threads = cfg->threads ? (int)cfg->threads : omp_get_max_threads();
    uint32_t *uses = calloc((size_t)s->mesh_count + 1, sizeof *uses);
    uint32_t *instance_of = calloc((size_t)s->mesh_count + 1, sizeof *instance_of);
    if (!uses || !instance_of) {
        free(uses);
        free(instance_of);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "hidden faces: out of memory");
    }
    for (uint32_t i = 0; i < s->instance_count; i++) {
        uses[s->instances[i].mesh]++;
        instance_of[s->instances[i].mesh] = i;
    }
    int *tested = calloc((size_t)s->mesh_count + 1, sizeof *tested); /* 1: unwrapped, wants the test */
    lmb_status st = tested ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "hidden faces: out of memory");
    for (uint32_t m = 0; st == LMB_OK && m < s->mesh_count; m++)
        tested[m] = l->meshes[m].used && !(cfg->keep_uv1 && lmb_mesh_has_uv1(s, m));

    /* meshes used once: one test over their world triangles */
    world_soup w;
    memset(&w, 0, sizeof w);
    int world = 0;
    for (uint32_t m = 0; st == LMB_OK && m < s->mesh_count; m++)
        world |= tested[m] && uses[m] == 1;
    if (st == LMB_OK && world)
        st = build_world_soup(s, uses, instance_of, &w, err);
    if (st == LMB_OK && w.triangle_count > 0) {
        double t0 = lmb_seconds();
        uint8_t *hidden = malloc((size_t)w.triangle_count + 1);
        uint32_t found = 0;
        lmb_unwrap_input in = {w.vertex_count, w.positions, w.triangle_count, w.indices, w.degenerate};
        st = hidden ? lmb_find_hidden_faces(&in, threads, hidden, &found, err)
                    : lmb_error_set(err, LMB_ERR_INTERNAL, "hidden faces: out of memory");
        uint32_t world_meshes = 0;
        for (uint32_t m = 0; m < s->mesh_count; m++)
            world_meshes += tested[m] && w.first[m] != UINT32_MAX;
        double share = (lmb_seconds() - t0) / (world_meshes ? world_meshes : 1); /* part of deciding the charts */
        for (uint32_t m = 0; st == LMB_OK && m < s->mesh_count; m++)
            if (tested[m] && w.first[m] != UINT32_MAX) {
                skip(&l->meshes[m].soup, hidden + w.first[m], &l->meshes[m].hidden_count);
                l->meshes[m].chart_seconds += share;
                tested[m] = 0;
            }
        free(hidden);
    }
    world_soup_free(&w);

    /* the rest (shared meshes, or a level too big for one soup): each against its own faces */
    for (uint32_t m = 0; st == LMB_OK && m < s->mesh_count; m++)
        if (tested[m]) {
            double t0 = lmb_seconds();
            st = own_faces(&l->meshes[m], threads, err);
            l->meshes[m].chart_seconds += lmb_seconds() - t0;
        }
    free(tested);
    free(uses);
    free(instance_of);
    return st;
}

void lmb_layout_report_hidden(const lmb_scene *s, const lmb_layout *l, const lmb_log *log)
{
    uint64_t total = 0, all = 0;
    uint32_t most = UINT32_MAX, meshes = 0;
    for (uint32_t m = 0; m < s->mesh_count; m++) {
        if (!l->meshes[m].used)
            continue;
        all += l->meshes[m].soup.triangle_count;
        if (l->meshes[m].hidden_count == 0)
            continue;
        total += l->meshes[m].hidden_count;
        meshes++;
        if (most == UINT32_MAX || l->meshes[m].hidden_count > l->meshes[most].hidden_count)
            most = m;
    }
    if (total > 0)
        lmb_info(log, "layout: %llu of %llu triangles (%.1f%%) lie back to back with another face inside a solid "
                 "(crates touching, a wall's foot on the floor) and get no texels, in %u mesh(es), most in '%s' (%u); "
                 "atlas.skip_hidden: false keeps them",
                 (unsigned long long)total, (unsigned long long)all, 100.0 * (double)total / (double)(all ? all : 1),
                 meshes, s->meshes[most].name, l->meshes[most].hidden_count);
}
