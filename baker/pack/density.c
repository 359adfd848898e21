/* Texel density per instance (see density.h). */
#include "density.h"

#include "pack.h"

#include <omp.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FIT_AREA_SHARE 0.8
/* An explicit density is refused before packing only past this share of the atlas: the boxes
 * overstate what the packer needs (it interlocks non-rectangular footprints), so between the
 * estimate and this the packer is asked, and names the instance if it cannot. */
#define TRY_AREA_SHARE 1.3

double lmb_instance_world_area(const lmb_scene *s, const lmb_layout *l, uint32_t i)
{
    const lmb_charts *c = &l->meshes[s->instances[i].mesh].charts;
    double q[9], a = 0;
    for (uint32_t f = 0; f < c->triangle_count; f++)
        if (c->chart_of[f] != UINT32_MAX) {
            lmb_layout_world_triangle(s, l, i, f, q);
            a += lmb_triangle_area(q);
        }
    return a;
}

/* World area of instance i's soup triangles (before charting), and its mesh's object area. */
static void soup_areas(const lmb_scene *s, const lmb_layout *l, uint32_t i, double *world, double *object)
{
    const lmb_mesh_soup *sp = &l->meshes[s->instances[i].mesh].soup;
    double q[9], o[9];
    *world = *object = 0;
    for (uint32_t f = 0; f < sp->triangle_count; f++) {
        if (sp->skip && sp->skip[f])
            continue;
        lmb_layout_world_triangle(s, l, i, f, q);
        for (int v = 0; v < 3; v++)
            for (int d = 0; d < 3; d++)
                o[3 * v + d] = sp->positions[3 * sp->indices[3 * f + v] + d];
        *world += lmb_triangle_area(q);
        *object += lmb_triangle_area(o);
    }
}

void lmb_density_expected(const lmb_scene *s, const lmb_config *cfg, const lmb_layout *l, double *per_mesh)
{
    double total = 0;
    for (uint32_t m = 0; m < s->mesh_count; m++)
        per_mesh[m] = 0;
    double *world = malloc(sizeof(double) * s->instance_count + 1), *object = malloc(sizeof(double) * s->instance_count + 1);
    if (!world || !object) {
        free(world);
        free(object);
        return; /* no estimate: nothing is glued */
    }
    for (uint32_t i = 0; i < s->instance_count; i++) {
        world[i] = object[i] = 0;
        if (s->instances[i].lightmapped && l->meshes[s->instances[i].mesh].used) {
            soup_areas(s, l, i, &world[i], &object[i]);
            total += world[i];
        }
    }
    double automatic = total > 0 ? sqrt((double)lmb_config_atlas_texels(cfg) / total) : 0;
    for (uint32_t i = 0; i < s->instance_count; i++) {
        if (!(world[i] > 0 && object[i] > 0))
            continue;
        double o = lmb_density_override_for(s, cfg, i);
        double d = o > 0 ? o : cfg->texel_density > 0 ? cfg->texel_density : automatic;
        double per_unit = d * sqrt(world[i] / object[i]);
        uint32_t m = s->instances[i].mesh;
        per_mesh[m] = per_unit > per_mesh[m] ? per_unit : per_mesh[m];
    }
    free(world);
    free(object);
}

/* Per chart of instance i: its box sides in world units (chart box x world/uv scale) and, if
 * area is not NULL, its world area. */
static int chart_boxes(const lmb_scene *s, const lmb_layout *l, uint32_t i, double *bw, double *bh, double *area)
{
    const lmb_charts *c = &l->meshes[s->instances[i].mesh].charts;
    for (uint32_t k = 0; k < c->chart_count; k++) {
        uint32_t len = c->first[k + 1] - c->first[k];
        double *uv = malloc(sizeof(double) * 6 * len + 1), aw = 0, auv = 0, q[9];
        if (!uv)
            return 0;
        for (uint32_t t = 0; t < len; t++) {
            uint32_t f = c->order[c->first[k] + t];
            const double *u = c->uv + 6 * f;
            memcpy(uv + 6 * t, u, 6 * sizeof(double));
            lmb_layout_world_triangle(s, l, i, f, q);
            aw += lmb_triangle_area(q);
            auv += 0.5 * fabs((u[2] - u[0]) * (u[5] - u[1]) - (u[4] - u[0]) * (u[3] - u[1]));
        }
        lmb_pack_chart pc = {len, uv, 0};
        double w, h, scale = auv > 0 ? sqrt(aw / auv) : 0;
        lmb_pack_chart_box(&pc, &w, &h);
        bw[k] = w * scale;
        bh[k] = h * scale;
        if (area)
            area[k] = aw;
        free(uv);
    }
    return 1;
}

/* Charts' footprints at density d: boxes with half the padding each side (neighbours share
 * the gap) and the conservative raster's texel. */
static double footprint_area(const double *bw, const double *bh, uint32_t nc, double d, uint32_t padding)
{
    double pad = padding + 3.0, area = 0;
    for (uint32_t k = 0; k < nc; k++)
        area += (d * bw[k] + pad) * (d * bh[k] + pad);
    return area;
}

static double fit_at_share(const lmb_scene *s, const lmb_layout *l, const lmb_config *cfg, uint32_t i, double share)
{
    const lmb_layout_mesh *lm = &l->meshes[s->instances[i].mesh];
    uint32_t nc = lm->charts.chart_count;
    if (lm->kept_uv1 || nc == 0)
        return INFINITY;
    double *bw = malloc(sizeof(double) * nc + 1), *bh = malloc(sizeof(double) * nc + 1);
    if (!bw || !bh || !chart_boxes(s, l, i, bw, bh, NULL)) {
        free(bw);
        free(bh);
        return INFINITY; /* out of memory: the packer will say */
    }
    /* a chart's footprint: its box + 1 (conservative raster) + 2 x (padding + 1) per side */
    double border = 2.0 * (cfg->padding + 1) + 1 + 2 /* margin for rounding */, longest = 0;
    for (uint32_t k = 0; k < nc; k++)
        longest = fmax(longest, fmax(bw[k], bh[k]));
    double atlas = share * (double)cfg->max_atlas_size * cfg->max_atlas_size;
    double d_side = longest > 0 ? (cfg->max_atlas_size - border) / longest : INFINITY;
    double result = d_side > 0 ? d_side : 0;
    if (isfinite(d_side) && footprint_area(bw, bh, nc, d_side, cfg->padding) > atlas) {
        double lo = 0, hi = d_side; /* the footprints' area grows with d: bisect */
        for (int it = 0; it < 60 && hi - lo > 1e-6 * hi; it++) {
            double mid = 0.5 * (lo + hi);
            if (footprint_area(bw, bh, nc, mid, cfg->padding) <= atlas)
                lo = mid;
            else
                hi = mid;
        }
        result = lo;
    }
    free(bw);
    free(bh);
    return result;
}

double lmb_density_fit(const lmb_scene *s, const lmb_layout *l, const lmb_config *cfg, uint32_t i)
{
    return fit_at_share(s, l, cfg, i, FIT_AREA_SHARE);
}

typedef struct side_area {
    double side, area;
} side_area;

static int by_side(const void *a, const void *b)
{
    double x = ((const side_area *)a)->side, y = ((const side_area *)b)->side;
    return x < y ? -1 : x > y;
}

double lmb_density_floor(const lmb_scene *s, const lmb_layout *l, const lmb_config *cfg, uint32_t i)
{
    const lmb_layout_mesh *lm = &l->meshes[s->instances[i].mesh];
    uint32_t nc = lm->charts.chart_count;
    if (cfg->min_chart_texels == 0 || lm->kept_uv1 || nc == 0)
        return 0;
    double *bw = malloc(sizeof(double) * nc + 1), *bh = malloc(sizeof(double) * nc + 1),
           *ca = malloc(sizeof(double) * nc + 1);
    side_area *sa = malloc(sizeof(side_area) * nc + 1);
    double result = 0;
    if (bw && bh && ca && sa && chart_boxes(s, l, i, bw, bh, ca)) {
        double total = 0, run = 0;
        for (uint32_t k = 0; k < nc; k++) {
            sa[k] = (side_area){fmin(bw[k], bh[k]), ca[k]};
            total += ca[k];
        }
        qsort(sa, nc, sizeof *sa, by_side);
        /* the area-weighted median of the charts' shorter sides, from the largest down: the
         * charts that hold at least half the surface are at least this wide */
        uint32_t k = nc;
        while (k > 0 && run < 0.5 * total)
            run += sa[--k].area;
        if (sa[k].side > 0)
            result = cfg->min_chart_texels / sa[k].side;
    }
    free(bw);
    free(bh);
    free(ca);
    free(sa);
    return result;
}

double lmb_density_override_for(const lmb_scene *s, const lmb_config *cfg, uint32_t i)
{
    const lmb_instance *in = &s->instances[i];
    for (uint32_t k = 0; k < cfg->density_override_count; k++)
        if (lmb_glob_match(cfg->density_overrides[k].pattern, in->name) ||
            lmb_glob_match(cfg->density_overrides[k].pattern, s->meshes[in->mesh].name))
            return cfg->density_overrides[k].texel_density;
    return 0;
}

/* An explicit density that will not fit: say so now, with what would. */
static lmb_status explicit_too_high(const lmb_scene *s, const lmb_config *cfg, uint32_t i, double d, double fit,
                                    int from_override, lmb_error *err)
{
    double would = 0.97 * fit;
    return lmb_error_set(err, LMB_ERR_INPUT,
                         "instance '%s' (mesh '%s') does not fit in one %ux%u atlas at %s %g texels per unit: at most "
                         "about %.*f fits (or use texel_density: auto, or raise atlas.max_size)",
                         s->instances[i].name, s->meshes[s->instances[i].mesh].name, cfg->max_atlas_size,
                         cfg->max_atlas_size, from_override ? "its density_overrides entry's" : "texel_density", d,
                         would >= 100 ? 0 : would >= 1 ? 2 : 4, would);
}

/* Texels the free (non-fixed) instances take at scene density d, each held in [floor, fit]. */
static double free_texels(double d, uint32_t n, const uint8_t *fixed, const double *area, const double *floor_d,
                          const double *fit)
{
    double t = 0;
    for (uint32_t k = 0; k < n; k++)
        if (!fixed[k]) {
            double dk = fmin(fmax(d, floor_d[k]), fit[k]);
            t += area[k] * dk * dk;
        }
    return t;
}

/* texel_density: auto. Water filling (instances that cannot take d keep their fit, the rest
 * share what is left), then, if atlas.min_chart_texels raises some instances above d, the d
 * at which the raised and the rest together take the budget again (bisection: the texels
 * grow with d). The floors may take at most half the budget: beyond it they are scaled down. */
static double auto_density(double left, uint32_t n, const uint8_t *fixed, const double *area, double *floor_d,
                           const double *fit, double free_area, const lmb_log *log)
{
    double d = sqrt(left / free_area);
    for (int round = 0; round < 32; round++) {
        double capped_texels = 0, open_area = 0;
        for (uint32_t k = 0; k < n; k++)
            if (!fixed[k] && fit[k] < d)
                capped_texels += area[k] * fit[k] * fit[k];
            else if (!fixed[k])
                open_area += area[k];
        double next = open_area > 0 ? sqrt(fmax(left - capped_texels, 0) / open_area) : d;
        if (!(next > d * 1.001))
            break;
        d = next;
    }
    int raised = 0;
    for (uint32_t k = 0; k < n; k++)
        raised |= !fixed[k] && floor_d[k] > d && fit[k] > d;
    if (!raised)
        return d; /* the floors change nothing: the layout is the one without them */
    double floors = free_texels(0, n, fixed, area, floor_d, fit);
    if (floors > 0.5 * left) {
        double f = sqrt(0.5 * left / floors);
        for (uint32_t k = 0; k < n; k++)
            floor_d[k] *= f;
        lmb_warn(log,
                 "atlas.min_chart_texels: raising small instances would take %.0f%% of the texel budget; they get "
                 "%.0f%% of the density it asks, and the budget's half",
                 100.0 * floors / left, 100.0 * f);
    }
    double lo = 0, hi = d;
    for (int it = 0; it < 64 && hi - lo > 1e-9 * hi; it++) {
        double mid = 0.5 * (lo + hi);
        if (free_texels(mid, n, fixed, area, floor_d, fit) <= left)
            lo = mid;
        else
            hi = mid;
    }
    return lo > 0 ? lo : hi;
}

lmb_status lmb_density_measure(const lmb_scene *s, const lmb_config *cfg, const lmb_layout *l, const uint32_t *list,
                               uint32_t n, lmb_density_measures *m, lmb_error *err)
{
    m->fit = malloc(sizeof(double) * n + 1);
    m->area = malloc(sizeof(double) * n + 1);
    m->floor_d = calloc((size_t)n + 1, sizeof(double));
    if (!m->fit || !m->area || !m->floor_d) {
        lmb_density_measures_free(m);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    }
    /* each instance's charts' boxes (the work) in parallel */
    int threads = cfg->threads ? (int)cfg->threads : omp_get_max_threads();
#pragma omp parallel for num_threads(threads) schedule(dynamic, 4)
    for (uint32_t k = 0; k < n; k++) {
        uint32_t i = list[k];
        m->fit[k] = lmb_density_fit(s, l, cfg, i);
        m->area[k] = lmb_instance_world_area(s, l, i);
        m->floor_d[k] =
            lmb_density_override_for(s, cfg, i) > 0 ? 0 : fmin(lmb_density_floor(s, l, cfg, i), m->fit[k]);
    }
    return LMB_OK;
}

void lmb_density_measures_free(lmb_density_measures *m)
{
    free(m->fit);
    free(m->area);
    free(m->floor_d);
    m->fit = m->area = m->floor_d = NULL;
}

lmb_status lmb_density_choose(const lmb_scene *s, const lmb_config *cfg, lmb_layout *l, const uint32_t *list,
                              uint32_t n, const lmb_density_measures *m, uint64_t budget, const lmb_log *log,
                              lmb_density_report *rep, lmb_error *err)
{
    memset(rep, 0, sizeof *rep);
    rep->automatic = !(cfg->texel_density > 0);
    rep->budget = budget;
    const double *fit = m->fit, *area = m->area;
    double *floor_d = malloc(sizeof(double) * n + 1);
    uint8_t *fixed = calloc((size_t)n + 1, 1);
    lmb_status st = floor_d && fixed ? LMB_OK : lmb_error_set(err, LMB_ERR_INTERNAL, "layout: out of memory");
    double fixed_texels = 0, free_area = 0;
    for (uint32_t k = 0; st == LMB_OK && k < n; k++)
        floor_d[k] = m->floor_d[k];
    for (uint32_t k = 0; st == LMB_OK && k < n; k++) {
        uint32_t i = list[k];
        double o = lmb_density_override_for(s, cfg, i), d = o > 0 ? o : cfg->texel_density;
        if (!(fit[k] > 0)) {
            st = lmb_error_set(err, LMB_ERR_INPUT,
                               "instance '%s' (mesh '%s') has %u charts: their padding alone (atlas.padding %u) "
                               "covers more than one %ux%u atlas at any density; raise atlas.max_size or lower "
                               "atlas.padding",
                               s->instances[i].name, s->meshes[s->instances[i].mesh].name,
                               l->meshes[s->instances[i].mesh].charts.chart_count, cfg->padding, cfg->max_atlas_size,
                               cfg->max_atlas_size);
            break;
        }
        /* floor_d[k]: 0 where an override is the artist's word for this instance */
        if (d > 0) { /* explicit: it wins (raised to the floor), or it is refused now */
            if (d > fit[k] && d > fit_at_share(s, l, cfg, i, TRY_AREA_SHARE))
                st = explicit_too_high(s, cfg, i, d, fit[k], o > 0, err);
            else if (d > fit[k])
                lmb_info(log,
                         "instance '%s' (mesh '%s'): texel_density %g is above the %.4g estimated to fit one %ux%u "
                         "atlas; the packer decides",
                         s->instances[i].name, s->meshes[s->instances[i].mesh].name, d, fit[k], cfg->max_atlas_size,
                         cfg->max_atlas_size);
            if (floor_d[k] > d) {
                d = floor_d[k];
                rep->raised++;
            }
            l->instances[i].texel_density = d;
            fixed[k] = 1;
            fixed_texels += area[k] * d * d;
        } else {
            free_area += area[k];
        }
    }
    if (st == LMB_OK && !rep->automatic)
        rep->scene_density = cfg->texel_density;
    if (st == LMB_OK && rep->automatic && free_area > 0) {
        double left = (double)rep->budget - fixed_texels;
        if (left < 0.1 * (double)rep->budget)
            left = 0.1 * (double)rep->budget; /* overrides took the budget: the rest still gets some */
        double d = auto_density(left, n, fixed, area, floor_d, fit, free_area, log);
        rep->scene_density = d;
        for (uint32_t k = 0; k < n; k++) {
            if (fixed[k])
                continue;
            uint32_t i = list[k];
            double di = fmin(fmax(d, floor_d[k]), fit[k]);
            l->instances[i].texel_density = di > 0 ? di : d;
            if (floor_d[k] > d && di > d)
                rep->raised++;
            if (m->floor_d[k] > 0 && di < m->floor_d[k] * (1 - 1e-9)) { /* the budget won over the floor */
                rep->short_of_floor++;
                double share = di / m->floor_d[k];
                rep->floor_share_min = rep->short_of_floor == 1 || share < rep->floor_share_min ? share
                                                                                                  : rep->floor_share_min;
            }
            if (fit[k] < d) {
                rep->capped++;
                lmb_warn(log,
                         "instance '%s' (mesh '%s') gets %.4g texels per unit, less than the scene's %.4g, so that it "
                         "fits one %ux%u atlas (raise atlas.max_size for more)",
                         s->instances[i].name, s->meshes[s->instances[i].mesh].name, di, d, cfg->max_atlas_size,
                         cfg->max_atlas_size);
            }
        }
    }
    if (st == LMB_OK && rep->raised)
        lmb_info(log,
                 "%u instance(s) get more than the scene's %.4g texels per unit so that their charts span at least %u "
                 "texels (atlas.min_chart_texels)",
                 rep->raised, rep->scene_density, cfg->min_chart_texels);
    free(floor_d);
    free(fixed);
    return st;
}
