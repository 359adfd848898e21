/* The probes as the output holds them (write/gltf_write.h's lmb_gltf_probes): float positions,
 * the values in the lightmaps' scale (output.scale radiance: E / pi), their Delaunay tetrahedra
 * (tetrahedra.c), and each grid as bevy's irradiance volume. */
#include "probes.h"

#include "util/lmb_math.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Grid g's volume file's name (STEM-irradiance-volume.ktx2 for the auto grid,
 * STEM-irradiance-volume-K.ktx2 for probes.volumes entry K, STEM-irradiance-volume-node-N.ktx2
 * for node N's extras.lightmap_probes; light group NAME's: ...-group-NAME.ktx2). */
static void volume_name(const lmb_probe_set *set, uint32_t g, const char *stem, const char *group, char *name,
                        size_t size)
{
    char tail[160] = "";
    if (group)
        snprintf(tail, sizeof tail, "-group-%s", group);
    if (set->grids[g].from_node)
        snprintf(name, size, "%s-irradiance-volume-node-%u%s.ktx2", stem, set->grids[g].node, tail);
    else if (set->grids[g].volume)
        snprintf(name, size, "%s-irradiance-volume-%u%s.ktx2", stem, set->grids[g].volume, tail);
    else
        snprintf(name, size, "%s-irradiance-volume%s.ktx2", stem, tail);
}

/* A copy of name (NULL: out of memory). */
static char *copy_name(const char *name)
{
    char *c = malloc(strlen(name) + 1);
    if (c)
        memcpy(c, name, strlen(name) + 1);
    return c;
}

/* Each grid's volume file beside the glTF (volume_name); out->volumes owned (node names borrowed
 * from the scene). */
static lmb_status write_volumes(const lmb_probe_set *set, double scale, const char *dir, const char *stem,
                                lmb_gltf_probes *out, lmb_error *err)
{
    lmb_gltf_volume *vols = calloc((size_t)set->grid_count + 1, sizeof *vols);
    if (!vols)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory");
    out->volumes = vols;
    lmb_status st = LMB_OK;
    for (uint32_t g = 0; st == LMB_OK && g < set->grid_count; g++) {
        lmb_probe_volume v;
        st = lmb_probe_volume_make(set, g, NULL, &v, err);
        char name[512], path[4096 + 520];
        volume_name(set, g, stem, NULL, name, sizeof name);
        snprintf(path, sizeof path, "%s/%s", dir, name);
        if (st == LMB_OK)
            st = lmb_probe_volume_write_ktx2(&v, scale, path, err);
        char *uri = st == LMB_OK ? copy_name(name) : NULL;
        if (st == LMB_OK && !uri)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory");
        if (st == LMB_OK) {
            lmb_gltf_volume *o = &vols[out->volume_count++];
            o->uri = uri;
            memcpy(o->lo, v.lo, sizeof v.lo);
            memcpy(o->hi, v.hi, sizeof v.hi);
            memcpy(o->res, v.res, sizeof v.res);
            o->config_entry = set->grids[g].volume;
            o->node_name = set->grids[g].from_node ? set->grids[g].node_name : NULL;
            memcpy(o->matrix, set->grids[g].world, sizeof o->matrix);
        }
        lmb_probe_volume_free(&v);
    }
    return st;
}

lmb_status lmb_probes_output(lmb_probe_set *set, const lmb_config *cfg, const char *dir, const char *stem,
                             const lmb_log *log, lmb_gltf_probes *out, lmb_error *err)
{
    memset(out, 0, sizeof *out);
    if (!set->count)
        return LMB_OK;
    size_t n = set->count;
    float *positions = malloc(3 * n * sizeof *positions), *sh = malloc(LMB_PROBE_SH * n * sizeof *sh),
          *cube = malloc(LMB_PROBE_CUBE * n * sizeof *cube);
    if (!positions || !sh || !cube) {
        free(positions);
        free(sh);
        free(cube);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for the output of %u probes", set->count);
    }
    int radiance = cfg->output_scale == LMB_SCALE_RADIANCE;
    double scale = radiance ? 1.0 / LMB_PI : 1.0;
    for (size_t k = 0; k < 3 * n; k++)
        positions[k] = (float)set->position[k];
    for (size_t k = 0; k < LMB_PROBE_SH * n; k++)
        sh[k] = (float)(set->sh[k] * scale);
    for (size_t k = 0; k < LMB_PROBE_CUBE * n; k++)
        cube[k] = (float)(set->cube[k] * scale);
    out->count = set->count;
    out->positions = positions;
    out->sh = sh;
    out->cube = cube;
    out->spacing = set->spacing;
    out->radiance = radiance;
    lmb_status st = lmb_probe_set_tetrahedra(set, err);
    if (st != LMB_OK)
        return st;
    const lmb_probe_tetrahedra_out tets = set->tets;
    uint32_t *copy = malloc(4 * (size_t)tets.count * sizeof *copy + 1);
    if (!copy)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for %u tetrahedra", tets.count);
    if (tets.count)
        memcpy(copy, tets.tetrahedra, 4 * (size_t)tets.count * sizeof *copy);
    out->tetrahedra = copy; /* owned by out */
    out->tetrahedron_count = tets.count;
    if (tets.count)
        lmb_info(log, "probes: %u tetrahedra (Delaunay, qhull)%s", tets.count,
                 tets.flat ? "; flat ones between grid cells dropped" : "");
    else
        lmb_warn(log, "probes: no tetrahedra: the %u probes %s%s", set->count,
                 set->count < 4 ? "are fewer than 4" : "span no volume (qhull: ", set->count < 4 ? "" : tets.why);
    return write_volumes(set, scale, dir, stem, out, err);
}

lmb_status lmb_probes_output_group(lmb_gltf_probes *out, const lmb_probe_set *set, const lmb_config *cfg,
                                   const char *dir, const char *stem, uint32_t g, const char *name, double scale,
                                   const double intensity[3], const float *sh_lux, const float *cube_lux,
                                   lmb_error *err)
{
    if (!out->count || g >= LMB_MAX_LIGHT_GROUPS)
        return LMB_OK;
    size_t n = out->count;
    double k = cfg->output_scale == LMB_SCALE_RADIANCE ? 1.0 / LMB_PI : 1.0;
    float *sh = malloc(LMB_PROBE_SH * n * sizeof *sh), *cube = malloc(LMB_PROBE_CUBE * n * sizeof *cube);
    if (!sh || !cube) {
        free(sh);
        free(cube);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for light group '%s'", name);
    }
    for (size_t i = 0; i < LMB_PROBE_SH * n; i++)
        sh[i] = sh_lux ? (float)(sh_lux[i] * k) : 0.0f;
    for (size_t i = 0; i < LMB_PROBE_CUBE * n; i++)
        cube[i] = cube_lux ? (float)(cube_lux[i] * k) : 0.0f;
    out->group_name[g] = name;
    out->group_scale[g] = scale;
    for (int c = 0; c < 3; c++)
        out->group_intensity[g][c] = intensity[c];
    out->group_sh[g] = sh;
    out->group_cube[g] = cube;
    out->groups = g + 1;
    /* its own bevy volumes: the group's light in each grid, as its files hold it (a game blends
     * them with the lightmaps' weights) */
    float *dark = cube_lux ? NULL : calloc(LMB_PROBE_CUBE * n + 1, sizeof *dark);
    lmb_status st = cube_lux || dark ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory");
    lmb_gltf_volume *vols = (lmb_gltf_volume *)(uintptr_t)out->volumes; /* owned by out */
    for (uint32_t v = 0; st == LMB_OK && v < out->volume_count; v++) {
        lmb_probe_volume vol;
        char file[512], path[4096 + 520];
        volume_name(set, v, stem, name, file, sizeof file);
        snprintf(path, sizeof path, "%s/%s", dir, file);
        st = lmb_probe_volume_make(set, v, cube_lux ? cube_lux : dark, &vol, err);
        if (st == LMB_OK)
            st = lmb_probe_volume_write_ktx2(&vol, k, path, err);
        lmb_probe_volume_free(&vol);
        if (st == LMB_OK && !(vols[v].group_uri[g] = copy_name(file)))
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory");
    }
    free(dark);
    return st;
}

void lmb_probes_output_free(lmb_gltf_probes *out)
{
    for (uint32_t g = 0; g < out->groups; g++) {
        free((void *)out->group_sh[g]);
        free((void *)out->group_cube[g]);
    }
    free((void *)out->positions);
    free((void *)out->sh);
    free((void *)out->cube);
    free((void *)out->tetrahedra);
    for (uint32_t i = 0; out->volumes && i < out->volume_count; i++) {
        free((void *)out->volumes[i].uri);
        for (uint32_t g = 0; g < LMB_MAX_LIGHT_GROUPS; g++)
            free((void *)out->volumes[i].group_uri[g]);
    }
    free((void *)out->volumes);
    memset(out, 0, sizeof *out);
}
