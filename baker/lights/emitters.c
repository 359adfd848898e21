/* Emissive triangles as area lights (see direct.h, lmb_emitters_build): every emissive
 * triangle of every instance in world space, with its radiance (texture included) and a CDF
 * by power for sampling. */
#include "direct_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

uint32_t lmb_emitters_count(const lmb_emitters *e)
{
    return e ? e->count : 0;
}

/* The power CDF's total is sum of area x luminance x sides: times pi, the flux a Lambertian
 * emitter of that radiance sends out (pbrt-v4's DiffuseAreaLight::Phi). */
double lmb_emitters_power(const lmb_emitters *e)
{
    return e && e->count ? LMB_PI * e->cdf[e->count] : 0.0;
}

void lmb_emitters_free(lmb_emitters *e)
{
    if (!e)
        return;
    free(e->e);
    free(e->cdf);
    free(e);
}

static lmb_status add_emitter(lmb_emitters *es, uint32_t *cap, const emitter *x, lmb_error *err)
{
    if (es->count == *cap) {
        uint32_t c = *cap ? 2 * *cap : 64;
        emitter *n = realloc(es->e, (size_t)c * sizeof *n);
        if (!n)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "emitters: out of memory");
        es->e = n;
        *cap = c;
    }
    es->e[es->count++] = *x;
    return LMB_OK;
}

static void world_point(const double m[16], const float *p, double *out)
{
    for (int r = 0; r < 3; r++)
        out[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
}

/* The emissive texture of material `mat` on primitive pr, and its corner UVs for face f with
 * the slot's KHR_texture_transform applied (an affine map commutes with barycentric interpolation). */
static const lmb_texture *emitter_texture(const lmb_textures *tx, const lmb_material *mat, const lmb_primitive *pr,
                                          uint32_t f, double uv[6])
{
    const lmb_texture *t = lmb_textures_get(tx, &mat->emissive_texture, LMB_TEX_COLOUR);
    const float *set = mat->emissive_texture.texcoord == 1 ? pr->uv1 : mat->emissive_texture.texcoord == 0 ? pr->uv0 : NULL;
    if (!t || !set)
        return NULL;
    for (int k = 0; k < 3; k++) {
        lmb_texture_ref_apply(&mat->emissive_texture, set[2 * pr->indices[3 * f + k]],
                              set[2 * pr->indices[3 * f + k] + 1], &uv[2 * k], &uv[2 * k + 1]);
    }
    return t;
}

lmb_status lmb_emitters_build(const lmb_scene *s, const lmb_emitter_options *opt, const lmb_textures *tx, lmb_emitters **out,
                              lmb_error *err)
{
    lmb_emitters *es = calloc(1, sizeof *es);
    uint32_t cap = 0;
    lmb_status st = es ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "emitters: out of memory");
    /* lights.emissive_scale 0 (or bake --direct-of): no surface emits */
    for (uint32_t i = 0; st == LMB_OK && opt->scale > 0 && i < s->instance_count; i++) {
        const lmb_instance *in = &s->instances[i];
        const lmb_mesh *m = &s->meshes[in->mesh];
        for (uint32_t p = 0; st == LMB_OK && p < m->primitive_count; p++) {
            const lmb_primitive *pr = &s->primitives[m->first_primitive + p];
            if (pr->material < 0 || !lmb_material_is_emissive(&s->materials[pr->material]))
                continue;
            const lmb_material *mat = &s->materials[pr->material];
            for (uint32_t f = 0; st == LMB_OK && f < pr->triangle_count; f++) {
                if (pr->degenerate[f])
                    continue;
                emitter x;
                for (int k = 0; k < 3; k++)
                    world_point(in->world, pr->positions + 3 * pr->indices[3 * f + k], x.p + 3 * k);
                double e1[3] = {x.p[3] - x.p[0], x.p[4] - x.p[1], x.p[5] - x.p[2]};
                double e2[3] = {x.p[6] - x.p[0], x.p[7] - x.p[1], x.p[8] - x.p[2]};
                double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
                double len = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
                if (!(len > 0))
                    continue;
                for (int k = 0; k < 3; k++)
                    x.n[k] = (in->flips_winding ? -c[k] : c[k]) / len;
                x.area = 0.5 * len;
                for (int k = 0; k < 3; k++)
                    x.le[k] = opt->unit ? 1.0f : (float)(mat->emissive[k] * opt->scale);
                x.two_sided = opt->emission_sides == LMB_EMIT_MATERIAL && mat->double_sided;
                x.tex = emitter_texture(tx, mat, pr, f, x.uv);
                x.instance = i;
                x.primitive = m->first_primitive + p;
                x.triangle = f;
                st = add_emitter(es, &cap, &x, err);
            }
        }
    }
    if (st == LMB_OK) {
        es->cdf = malloc(((size_t)es->count + 1) * sizeof *es->cdf);
        if (!es->cdf)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "emitters: out of memory");
    }
    if (st != LMB_OK) {
        lmb_emitters_free(es);
        return st;
    }
    double acc = 0;
    es->cdf[0] = 0;
    for (uint32_t k = 0; k < es->count; k++) {
        const emitter *x = &es->e[k];
        const double *m = x->tex ? x->tex->mean : NULL;
        double lum = 0.2126 * x->le[0] * (m ? m[0] : 1) + 0.7152 * x->le[1] * (m ? m[1] : 1) +
                     0.0722 * x->le[2] * (m ? m[2] : 1);
        acc += x->area * (lum > 0 ? lum : 1e-12) * (x->two_sided ? 2 : 1);
        es->cdf[k + 1] = acc;
    }
    *out = es;
    return LMB_OK;
}

uint32_t lmb_emitter_pick(const lmb_emitters *es, double u, double *prob)
{
    return lmb_cdf_pick(es->cdf, es->count, u, prob);
}

