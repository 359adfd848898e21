/* The probes as the output holds them (write/gltf_write.h's lmb_gltf_probes): float positions,
 * the values in the lightmaps' scale (output.scale radiance: E / pi), and the grid as bevy's
 * irradiance volume, DIR/STEM-irradiance-volume.ktx2. */
#include "probes.h"

#include "util/lmb_math.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The volume's file beside the glTF; its name into out->volume_uri (owned). */
static lmb_status write_volume(const lmb_probe_set *set, double scale, const char *dir, const char *stem,
                               lmb_gltf_probes *out, lmb_error *err)
{
    lmb_probe_volume v;
    lmb_status st = lmb_probe_volume_make(set, &v, err);
    char name[512], path[4096 + 520];
    snprintf(name, sizeof name, "%s-irradiance-volume.ktx2", stem);
    snprintf(path, sizeof path, "%s/%s", dir, name);
    if (st == LMB_OK)
        st = lmb_probe_volume_write_ktx2(&v, scale, path, err);
    char *uri = st == LMB_OK ? malloc(strlen(name) + 1) : NULL;
    if (st == LMB_OK && !uri)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory");
    if (st == LMB_OK) {
        memcpy(uri, name, strlen(name) + 1);
        out->volume_uri = uri;
        memcpy(out->volume_lo, v.lo, sizeof v.lo);
        memcpy(out->volume_hi, v.hi, sizeof v.hi);
        memcpy(out->volume_res, v.res, sizeof v.res);
    }
    lmb_probe_volume_free(&v);
    return st;
}

lmb_status lmb_probes_output(const lmb_probe_set *set, const lmb_config *cfg, const char *dir, const char *stem,
                             lmb_gltf_probes *out, lmb_error *err)
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
    return write_volume(set, scale, dir, stem, out, err);
}

void lmb_probes_output_free(lmb_gltf_probes *out)
{
    free((void *)out->positions);
    free((void *)out->sh);
    free((void *)out->cube);
    free((void *)out->volume_uri);
    memset(out, 0, sizeof *out);
}
