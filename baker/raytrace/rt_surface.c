/* Surfaces that let light through (see rt_surface.h). */
#include "rt_surface.h"

lmb_rt_surface lmb_rt_surface_of(const lmb_material *m, const lmb_primitive *pr, const lmb_textures *tx)
{
    lmb_rt_surface sf = {m, pr, tx, 0};
    if (!m)
        return sf;
    if (m->alpha_mode == LMB_ALPHA_MASK)
        sf.kind |= LMB_SURFACE_CUT;
    if (m->alpha_mode == LMB_ALPHA_BLEND || m->transmission > 0)
        sf.kind |= LMB_SURFACE_PARTIAL;
    return sf;
}

int lmb_rt_surface_cut(const lmb_rt_surface *sf, uint32_t tri, double b1, double b2)
{
    if (!(sf->kind & LMB_SURFACE_CUT))
        return 0;
    return lmb_material_alpha(sf->textures, sf->material, sf->primitive, tri, b1, b2) < sf->material->alpha_cutoff;
}

void lmb_rt_surface_pass(const lmb_rt_surface *sf, uint32_t tri, double b1, double b2, int backface, double pass[3],
                         double *cover)
{
    pass[0] = pass[1] = pass[2] = 0.0;
    *cover = 1.0;
    if (!(sf->kind & LMB_SURFACE_PARTIAL))
        return;
    const lmb_material *m = sf->material;
    double a = 1.0;
    if (m->alpha_mode == LMB_ALPHA_BLEND) {
        a = lmb_material_alpha(sf->textures, m, sf->primitive, tri, b1, b2);
        a = a < 0 ? 0 : a > 1 ? 1 : a;
    }
    double through[3] = {0, 0, 0};
    if (m->transmission > 0) {
        if (m->volume && backface) { /* leaving a volume: tinted when it entered */
            through[0] = through[1] = through[2] = 1.0;
        } else {
            double t = lmb_material_transmission(sf->textures, m, sf->primitive, tri, b1, b2), base[3];
            t *= 1.0 - (m->spec_gloss ? 0.0 : m->metallic);
            lmb_material_base_colour(sf->textures, m, sf->primitive, tri, b1, b2, base);
            for (int k = 0; k < 3; k++)
                through[k] = t * base[k] * (m->volume ? m->volume_tint[k] : 1.0);
        }
    }
    for (int k = 0; k < 3; k++) {
        double p = (1.0 - a) + a * through[k];
        pass[k] = p < 0 ? 0 : p > 1 ? 1 : p;
    }
    *cover = a;
}
