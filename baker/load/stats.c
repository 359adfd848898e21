/* Scene counts for `lmbake inspect` and bake reports (see lmb_scene_stats). */
#include <lmbake/lmbake.h>

#include <string.h>

int lmb_material_is_emissive(const lmb_material *m)
{
    return m->emissive[0] > 0.0f || m->emissive[1] > 0.0f || m->emissive[2] > 0.0f;
}

static uint64_t emissive_triangles_of(const lmb_scene *s, const lmb_mesh *mesh)
{
    uint64_t n = 0;
    for (uint32_t p = 0; p < mesh->primitive_count; p++) {
        const lmb_primitive *prim = &s->primitives[mesh->first_primitive + p];
        if (prim->material >= 0 && lmb_material_is_emissive(&s->materials[prim->material]))
            n += prim->triangle_count - prim->degenerate_count;
    }
    return n;
}

void lmb_scene_stats_compute(const lmb_scene *s, lmb_scene_stats *out)
{
    memset(out, 0, sizeof *out);
    for (uint32_t m = 0; m < s->mesh_count; m++) {
        out->triangles_unique += s->meshes[m].triangle_count;
        out->triangles_skipped += s->meshes[m].skipped_triangles;
        out->degenerate_unique += s->meshes[m].degenerate_count;
    }
    for (uint32_t i = 0; i < s->instance_count; i++) {
        const lmb_instance *in = &s->instances[i];
        const lmb_mesh *mesh = &s->meshes[in->mesh];
        out->triangles_instanced += mesh->triangle_count;
        if (in->gpu_instance <= 0)
            out->triangles_in_nodes += mesh->triangle_count;
        out->emissive_triangles += emissive_triangles_of(s, mesh);
        if (in->lightmapped) {
            out->lightmapped_instances++;
            out->lightmapped_triangles += mesh->triangle_count - mesh->degenerate_count;
        }
    }
    for (uint32_t m = 0; m < s->material_count; m++)
        out->emissive_materials += (uint32_t)lmb_material_is_emissive(&s->materials[m]);
}
