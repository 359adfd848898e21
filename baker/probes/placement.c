/* Probe placement (see probes.h): the grid, its refinement near surfaces, and the probes
 * dropped inside geometry or outside the level. */
#include "probes.h"
#include "sphere.h"

#include "util/mat4.h"

#include <omp.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TEST_RAYS 64          /* rays that decide whether a probe is inside geometry or outside the level */
#define AUTO_PROBES 256       /* auto spacing: the level's lightmapped surface area / spacing^2 */
#define AUTO_MAX_CELLS 4096   /* auto spacing: widened until the grid has at most this many cells (32,768 probes at most) */
#define FAR_CELLS 3           /* a probe with no surface within this many cells is outside the level */
#define PROBE_CLEARANCE 0.05  /* cells: a probe nearer a surface than this moves away from it (virtual offset) */

/* Calls fn for every lightmapped triangle, in world space. */
typedef void (*triangle_fn)(void *user, const double q[9]);

static void each_lightmapped_triangle(const lmb_scene *s, const lmb_layout *l, triangle_fn fn, void *user)
{
    for (uint32_t i = 0; i < s->instance_count; i++) {
        if (!l->instances[i].lightmapped)
            continue;
        uint32_t nt = s->meshes[s->instances[i].mesh].triangle_count;
        for (uint32_t f = 0; f < nt; f++) {
            double q[9];
            lmb_layout_world_triangle(s, l, i, f, q);
            fn(user, q);
        }
    }
}

typedef struct extent {
    double lo[3], hi[3], area;
} extent;

static void grow_extent(void *user, const double q[9])
{
    extent *e = user;
    for (int c = 0; c < 3; c++)
        for (int k = 0; k < 3; k++) {
            e->lo[k] = fmin(e->lo[k], q[3 * c + k]);
            e->hi[k] = fmax(e->hi[k], q[3 * c + k]);
        }
    e->area += lmb_triangle_area(q);
}

/* The lightmapped geometry's bounds and surface area. */
static void bounds_and_area(const lmb_scene *s, const lmb_layout *l, double lo[3], double hi[3], double *area)
{
    extent e = {{HUGE_VAL, HUGE_VAL, HUGE_VAL}, {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, 0};
    each_lightmapped_triangle(s, l, grow_extent, &e);
    for (int k = 0; k < 3; k++) {
        lo[k] = e.lo[k];
        hi[k] = e.hi[k];
    }
    *area = e.area;
}

/* The world boxes of the probe-lit instances (layout.h: props whose charts the texel budget could
 * not hold, lit by the probes instead): their mesh's object-space box through their transform.
 * Returns how many (boxes: 6 doubles each, lo then hi; caller frees), or -1 when out of memory. */
static long probe_lit_boxes(const lmb_scene *s, const lmb_layout *l, double **boxes)
{
    *boxes = NULL;
    size_t n = 0;
    for (uint32_t i = 0; i < s->instance_count; i++)
        n += l->instances[i].probe_lit != 0;
    if (!n)
        return 0;
    double *mesh_box = malloc(6 * ((size_t)s->mesh_count + 1) * sizeof *mesh_box);
    double *out = malloc(6 * n * sizeof *out);
    if (!mesh_box || !out) {
        free(mesh_box);
        free(out);
        return -1;
    }
    for (uint32_t m = 0; m < s->mesh_count; m++) {
        double *b = mesh_box + 6 * (size_t)m;
        b[0] = b[1] = b[2] = HUGE_VAL;
        b[3] = b[4] = b[5] = -HUGE_VAL;
    }
    for (uint32_t i = 0; i < s->instance_count; i++) { /* only the meshes that need it, once each */
        uint32_t m = s->instances[i].mesh;
        double *b = mesh_box + 6 * (size_t)m;
        if (!l->instances[i].probe_lit || b[3] >= b[0])
            continue;
        const lmb_mesh *me = &s->meshes[m];
        for (uint32_t p = me->first_primitive; p < me->first_primitive + me->primitive_count; p++)
            for (uint32_t v = 0; v < s->primitives[p].vertex_count; v++)
                for (int k = 0; k < 3; k++) {
                    b[k] = fmin(b[k], s->primitives[p].positions[3 * (size_t)v + k]);
                    b[3 + k] = fmax(b[3 + k], s->primitives[p].positions[3 * (size_t)v + k]);
                }
    }
    size_t j = 0;
    for (uint32_t i = 0; i < s->instance_count; i++) {
        const double *b = mesh_box + 6 * (size_t)s->instances[i].mesh;
        if (!l->instances[i].probe_lit || !(b[3] >= b[0]))
            continue;
        double *o = out + 6 * j++;
        o[0] = o[1] = o[2] = HUGE_VAL;
        o[3] = o[4] = o[5] = -HUGE_VAL;
        for (int c = 0; c < 8; c++) {
            double p[3] = {b[c & 1 ? 3 : 0], b[c & 2 ? 4 : 1], b[c & 4 ? 5 : 2]}, w[3];
            lmb_mat4_point(s->instances[i].world, p, w);
            for (int k = 0; k < 3; k++) {
                o[k] = fmin(o[k], w[k]);
                o[3 + k] = fmax(o[3 + k], w[k]);
            }
        }
    }
    free(mesh_box);
    *boxes = out;
    return (long)j;
}

/* Does triangle q touch the box centre c, half-size h? Its bounding box overlaps (the caller
 * visits only those cells) and its plane passes within the box (a conservative test: a cell
 * near a triangle's edge may count, which only refines it). */
static int plane_meets_box(const double q[9], const double c[3], const double h[3])
{
    double e1[3], e2[3], n[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = q[3 + k] - q[k];
        e2[k] = q[6 + k] - q[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double dist = n[0] * (c[0] - q[0]) + n[1] * (c[1] - q[1]) + n[2] * (c[2] - q[2]);
    double reach = h[0] * fabs(n[0]) + h[1] * fabs(n[1]) + h[2] * fabs(n[2]);
    return fabs(dist) <= reach;
}

typedef struct grid {
    double lo[3], cell[3];
    uint32_t n[3];
} grid;

static size_t cell_index(const grid *g, uint32_t x, uint32_t y, uint32_t z)
{
    return ((size_t)z * g->n[1] + y) * g->n[0] + x;
}

/* The cells box (lo, hi: 6 doubles) overlaps, clamped to the grid: a[k]..b[k] per axis. */
static void cells_of_box(const grid *g, const double box[6], uint32_t a[3], uint32_t b[3])
{
    for (int k = 0; k < 3; k++) {
        double u0 = floor((box[k] - g->lo[k]) / g->cell[k]), u1 = floor((box[3 + k] - g->lo[k]) / g->cell[k]);
        a[k] = u0 < 0 ? 0 : u0 >= g->n[k] ? g->n[k] - 1 : (uint32_t)u0;
        b[k] = u1 < 0 ? 0 : u1 >= g->n[k] ? g->n[k] - 1 : (uint32_t)u1;
    }
}

typedef struct marking {
    const grid *g;
    uint8_t *marked;
} marking;

/* Marks the cells triangle q passes through. */
static void mark_triangle(void *user, const double q[9])
{
    const marking *m = user;
    const grid *g = m->g;
    double h[3] = {0.5 * g->cell[0], 0.5 * g->cell[1], 0.5 * g->cell[2]};
    double box[6];
    for (int k = 0; k < 3; k++) {
        box[k] = fmin(q[k], fmin(q[3 + k], q[6 + k]));
        box[3 + k] = fmax(q[k], fmax(q[3 + k], q[6 + k]));
    }
    uint32_t a[3], b[3];
    cells_of_box(g, box, a, b);
    for (uint32_t z = a[2]; z <= b[2]; z++)
        for (uint32_t y = a[1]; y <= b[1]; y++)
            for (uint32_t x = a[0]; x <= b[0]; x++) {
                size_t c = cell_index(g, x, y, z);
                if (m->marked[c])
                    continue;
                double centre[3] = {g->lo[0] + (x + 0.5) * g->cell[0], g->lo[1] + (y + 0.5) * g->cell[1],
                                    g->lo[2] + (z + 0.5) * g->cell[2]};
                m->marked[c] = (uint8_t)plane_meets_box(q, centre, h);
            }
}

/* Marks the cells box (lo, hi: 6 doubles) overlaps. */
static void mark_box(const grid *g, const double box[6], uint8_t *marked)
{
    uint32_t a[3], b[3];
    cells_of_box(g, box, a, b);
    for (uint32_t z = a[2]; z <= b[2]; z++)
        for (uint32_t y = a[1]; y <= b[1]; y++)
            for (uint32_t x = a[0]; x <= b[0]; x++)
                marked[cell_index(g, x, y, z)] = 1;
}

/* Marks every cell some lightmapped triangle passes through. */
static void mark_surface_cells(const lmb_scene *s, const lmb_layout *l, const grid *g, uint8_t *marked)
{
    marking m = {g, marked};
    each_lightmapped_triangle(s, l, mark_triangle, &m);
}

/* 0 keep, 1 inside geometry (most rays that hit something hit a back face), 2 outside the level
 * (no surface within FAR_CELLS cells in any direction). *nearest: the nearest hit (t 0: none),
 * *nearest_back: the nearest back-face hit (t 0: none). */
static int probe_fate(const lmb_rt *rt, const double p[3], double far, lmb_rt_hit *nearest, lmb_rt_hit *nearest_back)
{
    uint32_t hits = 0, back = 0;
    nearest->t = nearest_back->t = 0;
    for (uint32_t j = 0; j < TEST_RAYS; j++) {
        double w[3];
        lmb_sphere_direction(j, TEST_RAYS, w);
        lmb_rt_hit h;
        if (!lmb_rt_intersect(rt, p, w, rt->eps, 1e300, &h))
            continue;
        hits++;
        back += h.backface != 0;
        if (!(nearest->t > 0) || h.t < nearest->t)
            *nearest = h;
        if (h.backface && (!(nearest_back->t > 0) || h.t < nearest_back->t))
            *nearest_back = h;
    }
    if (hits && 2 * back > hits)
        return 1;
    return !hits || nearest->t > far ? 2 : 0;
}

/*
 * Virtual offset (Unity's name): a probe inside geometry, or nearer a surface than `clearance`,
 * moves to free space instead of being dropped or reading the light of a point on the surface:
 * through the nearest back face it sees (out of a wall, to the side nearer it; also a probe that
 * sees a back face within 2 x clearance: one on a wall's face, whose test rays start past that
 * face, which a grid aligned with the level puts on every wall) or away from the nearest front
 * face, to `clearance` in front of that face. The moved probe is tested again;
 * still inside: 1 (dropped). Returns the fate at the final position; *moved: 1 when it moved.
 */
static int place_probe(const lmb_rt *rt, double p[3], double far, double clearance, int auto_grid, int *moved)
{
    lmb_rt_hit near, back;
    *moved = 0;
    int f = probe_fate(rt, p, far, &near, &back);
    /* inside; or a back face close by (a probe on a wall's outer face, whose rays into the wall
     * start past that face and meet the wall's far side); or a front face close by. An artist's
     * volume moves only out of geometry: its grid is where it was asked for */
    const lmb_rt_hit *h = f == 1 ? (back.t > 0 ? &back : NULL)
                          : f != 0 || !auto_grid ? NULL
                          : back.t > 0 && back.t < 2 * clearance ? &back
                          : near.t > 0 && near.t < clearance ? &near : NULL;
    if (!h)
        return f;
    double q[3];
    for (int k = 0; k < 3; k++) /* the face's front side is where free space is */
        q[k] = h->p[k] + clearance * h->ng[k];
    int g = probe_fate(rt, q, far, &near, &back);
    if (g == 1)
        return f == 1 ? 1 : f;
    memcpy(p, q, sizeof q);
    *moved = 1;
    return g;
}

/* lmb_probes_line_walls's test for a probe it would add. */
static int inside_geometry(const lmb_rt *rt, const double p[3])
{
    lmb_rt_hit near, back;
    return probe_fate(rt, p, HUGE_VAL, &near, &back) == 1;
}

uint32_t lmb_probe_voxel_of(const lmb_probe_set *set, const double q[3])
{
    if (!set->grid_count || set->grids[0].volume != 0 || set->grids[0].from_node)
        return UINT32_MAX;
    const lmb_probe_grid *g = &set->grids[0];
    uint32_t v[3];
    for (int k = 0; k < 3; k++) {
        double x = floor((q[k] - g->lo[k]) / g->cell[k]);
        if (!(x >= -1) || x > g->res[k]) /* more than a cell outside the grid */
            return UINT32_MAX;
        v[k] = x < 0 ? 0 : x >= g->res[k] ? g->res[k] - 1 : (uint32_t)x; /* just outside: the edge voxel */
    }
    return g->first_voxel + (v[2] * g->res[1] + v[1]) * g->res[0] + v[0];
}

/* The grid: auto spacing from the surface area (a probe per AUTO_PROBES-th of it), widened to
 * AUTO_MAX_CELLS cells. An axis thinner than the spacing gets one cell: the bounds' own extent
 * when that is at least an eighth of the spacing (a ground with props on it: the probes at a
 * quarter and three quarters of their height, where things move, not half of them under the
 * ground), else one cell of the spacing, centred (a flat level). */
static void make_grid(const lmb_config *cfg, const double lo[3], const double hi[3], double area, grid *g,
                      double *spacing)
{
    double s = cfg->probe_spacing > 0 ? cfg->probe_spacing : sqrt(area / AUTO_PROBES);
    for (;;) {
        size_t cells = 1;
        for (int k = 0; k < 3; k++) {
            double ext = hi[k] - lo[k];
            int thin = !(ext > s), flat = thin && !(ext >= 0.125 * s);
            g->n[k] = thin ? 1 : (uint32_t)fmin(ceil(ext / s), 1e6);
            g->cell[k] = flat ? s : ext / g->n[k];
            g->lo[k] = flat ? 0.5 * (lo[k] + hi[k]) - 0.5 * s : lo[k];
            cells *= g->n[k];
        }
        if (cfg->probe_spacing > 0 || cells <= AUTO_MAX_CELLS)
            break;
        s *= 1.25;
    }
    *spacing = s;
}

/* Probes before the inside/outside test: position, voxel, and whether the outside test applies
 * (the auto grid's; an artist's volume keeps the probes it asked for). */
typedef struct candidates {
    double *p;
    uint32_t *voxel;
    uint8_t *auto_grid;
    size_t count, cap;
} candidates;

static int add_candidate(candidates *c, const double p[3], uint32_t voxel, int auto_grid)
{
    if (c->count == c->cap) {
        size_t cap = c->cap ? 2 * c->cap : 4096;
        double *np = realloc(c->p, 3 * cap * sizeof *np);
        if (np)
            c->p = np;
        uint32_t *nv = realloc(c->voxel, cap * sizeof *nv);
        if (nv)
            c->voxel = nv;
        uint8_t *na = realloc(c->auto_grid, cap);
        if (na)
            c->auto_grid = na;
        if (!np || !nv || !na)
            return 0;
        c->cap = cap;
    }
    memcpy(c->p + 3 * c->count, p, 3 * sizeof *p);
    c->voxel[c->count] = voxel;
    c->auto_grid[c->count++] = (uint8_t)auto_grid;
    return 1;
}

static const char *config_name(const lmb_config *cfg)
{
    return cfg->config_path[0] ? cfg->config_path : "config";
}

/* The auto grid's candidates: a probe per empty cell, eight per cell with surface. */
static lmb_status auto_grid(const lmb_scene *s, const lmb_layout *l, const lmb_config *cfg, lmb_probe_set *out,
                            candidates *c, lmb_error *err)
{
    double lo[3], hi[3], area, *boxes;
    bounds_and_area(s, l, lo, hi, &area);
    long nbox = probe_lit_boxes(s, l, &boxes);
    if (nbox < 0)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for the probe-lit instances' boxes");
    for (long b = 0; b < nbox; b++) /* the grid covers the probe-lit props too */
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], boxes[6 * b + k]);
            hi[k] = fmax(hi[k], boxes[6 * b + 3 + k]);
        }
    if (!(area > 0) || !(hi[0] >= lo[0])) {
        free(boxes);
        return LMB_OK;
    }
    grid g;
    make_grid(cfg, lo, hi, area, &g, &out->spacing);
    size_t cells = (size_t)g.n[0] * g.n[1] * g.n[2];
    if (cells > LMB_PROBES_MAX)
        free(boxes);
    if (cells > LMB_PROBES_MAX)
        return lmb_error_set(err, LMB_ERR_INPUT,
                             "%s: probes.spacing %g makes a grid of %ux%ux%u = %zu cells over the level's %g x %g x %g "
                             "bounds: more than the %u probes a bake holds (%d floats each, 200 MB of output); raise "
                             "probes.spacing", config_name(cfg), cfg->probe_spacing, g.n[0], g.n[1], g.n[2], cells,
                             hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], LMB_PROBES_MAX, LMB_PROBE_SH + LMB_PROBE_CUBE);
    uint8_t *marked = calloc(cells + 1, 1);
    if (!marked) {
        free(boxes);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for %zu cells", cells);
    }
    mark_surface_cells(s, l, &g, marked);
    for (long b = 0; b < nbox; b++) /* and refines the cells their boxes overlap */
        mark_box(&g, boxes + 6 * b, marked);
    free(boxes);
    size_t want = 0;
    for (size_t k = 0; k < cells; k++) {
        want += marked[k] ? 8 : 1;
        out->refined += marked[k];
    }
    if (want > LMB_PROBES_MAX) {
        free(marked);
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: probes.spacing %g places %zu probes near the level's surfaces: "
                             "more than the %u a bake holds; raise probes.spacing", config_name(cfg), out->spacing,
                             want, LMB_PROBES_MAX);
    }
    int ok = 1;
    for (uint32_t z = 0; z < g.n[2]; z++)
        for (uint32_t y = 0; y < g.n[1]; y++)
            for (uint32_t x = 0; x < g.n[0]; x++) {
                uint32_t cell[3] = {x, y, z}, index = (uint32_t)cell_index(&g, x, y, z);
                int split = marked[index];
                for (int child = 0; ok && child < (split ? 8 : 1); child++) {
                    double p[3];
                    for (int k = 0; k < 3; k++)
                        p[k] = g.lo[k] + (cell[k] + (split ? 0.25 + 0.5 * ((child >> k) & 1) : 0.5)) * g.cell[k];
                    ok = add_candidate(c, p, index, 1);
                }
            }
    free(marked);
    if (!ok)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for %zu probes", want);
    lmb_probe_grid *pg = &out->grids[out->grid_count++];
    memcpy(pg->lo, g.lo, sizeof g.lo);
    memcpy(pg->cell, g.cell, sizeof g.cell);
    memcpy(pg->res, g.n, sizeof g.n);
    pg->first_voxel = 0;
    pg->volume = 0;
    return LMB_OK;
}

/* probes.volumes entry k's candidates: one at each cell's centre. */
static lmb_status volume_grid(const lmb_config *cfg, uint32_t k, uint32_t first_voxel, lmb_probe_set *out,
                              candidates *c, lmb_error *err)
{
    const lmb_probe_volume_spec *v = &cfg->probe_volumes[k];
    size_t cells = (size_t)v->resolution[0] * v->resolution[1] * v->resolution[2];
    if (c->count + cells > LMB_PROBES_MAX || first_voxel + cells > UINT32_MAX)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: probes.volumes entry %u (%ux%ux%u) brings the probes to %zu: more "
                             "than the %u a bake holds (%d floats each, 200 MB of output)", config_name(cfg), k + 1,
                             v->resolution[0], v->resolution[1], v->resolution[2], c->count + cells, LMB_PROBES_MAX,
                             LMB_PROBE_SH + LMB_PROBE_CUBE);
    lmb_probe_grid *pg = &out->grids[out->grid_count++];
    for (int a = 0; a < 3; a++) {
        pg->lo[a] = v->min[a];
        pg->res[a] = v->resolution[a];
        pg->cell[a] = (v->max[a] - v->min[a]) / v->resolution[a];
    }
    pg->first_voxel = first_voxel;
    pg->volume = k + 1;
    for (uint32_t z = 0; z < pg->res[2]; z++)
        for (uint32_t y = 0; y < pg->res[1]; y++)
            for (uint32_t x = 0; x < pg->res[0]; x++) {
                uint32_t cell[3] = {x, y, z};
                double p[3];
                for (int a = 0; a < 3; a++)
                    p[a] = pg->lo[a] + (cell[a] + 0.5) * pg->cell[a];
                if (!add_candidate(c, p, first_voxel + (uint32_t)(((size_t)z * pg->res[1] + y) * pg->res[0] + x), 0))
                    return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for %zu probes", c->count);
            }
    return LMB_OK;
}

/* A node's extras.lightmap_probes: one probe at each cell's centre of the unit cube centred on
 * the node's origin, through its world transform. */
static lmb_status node_grid(const lmb_scene *s, uint32_t k, uint32_t first_voxel, lmb_probe_set *out, candidates *c,
                            lmb_error *err)
{
    const lmb_node_probe_volume *v = &s->probe_volumes[k];
    size_t cells = (size_t)v->resolution[0] * v->resolution[1] * v->resolution[2];
    if (c->count + cells > LMB_PROBES_MAX || first_voxel + cells > UINT32_MAX)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: node '%s': extras.lightmap_probes (%ux%ux%u) brings the probes to "
                             "%zu: more than the %u a bake holds (%d floats each, 200 MB of output)", s->path, v->name,
                             v->resolution[0], v->resolution[1], v->resolution[2], c->count + cells, LMB_PROBES_MAX,
                             LMB_PROBE_SH + LMB_PROBE_CUBE);
    lmb_probe_grid *pg = &out->grids[out->grid_count++];
    for (int a = 0; a < 3; a++) {
        pg->lo[a] = -0.5;
        pg->res[a] = v->resolution[a];
        pg->cell[a] = 1.0 / v->resolution[a];
    }
    pg->first_voxel = first_voxel;
    pg->from_node = 1;
    memcpy(pg->world, v->world, sizeof pg->world);
    pg->node = v->node;
    pg->node_name = v->name;
    for (uint32_t z = 0; z < pg->res[2]; z++)
        for (uint32_t y = 0; y < pg->res[1]; y++)
            for (uint32_t x = 0; x < pg->res[0]; x++) {
                uint32_t cell[3] = {x, y, z};
                double local[3], p[3];
                for (int a = 0; a < 3; a++)
                    local[a] = pg->lo[a] + (cell[a] + 0.5) * pg->cell[a];
                lmb_mat4_point(pg->world, local, p);
                if (!add_candidate(c, p, first_voxel + (uint32_t)(((size_t)z * pg->res[1] + y) * pg->res[0] + x), 0))
                    return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for %zu probes", c->count);
            }
    return LMB_OK;
}

lmb_status lmb_probes_place(const lmb_scene *s, const lmb_layout *l, const lmb_config *cfg, const lmb_rt *rt,
                            const lmb_log *log, lmb_probe_set *out, lmb_error *err)
{
    memset(out, 0, sizeof *out);
    out->rays = cfg->probe_rays;
    candidates c = {NULL, NULL, NULL, 0, 0};
    out->grids = calloc(1 + (size_t)cfg->probe_volume_count + s->probe_volume_count, sizeof *out->grids);
    if (!out->grids)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory");
    lmb_status st = cfg->probes_auto ? auto_grid(s, l, cfg, out, &c, err) : LMB_OK;
    uint32_t voxels = 0;
    if (out->grid_count)
        voxels = out->grids[0].res[0] * out->grids[0].res[1] * out->grids[0].res[2];
    for (uint32_t k = 0; st == LMB_OK && k < cfg->probe_volume_count; k++) {
        st = volume_grid(cfg, k, voxels, out, &c, err);
        const lmb_probe_grid *pg = &out->grids[out->grid_count ? out->grid_count - 1 : 0];
        voxels += st == LMB_OK ? pg->res[0] * pg->res[1] * pg->res[2] : 0;
    }
    for (uint32_t k = 0; st == LMB_OK && k < s->probe_volume_count; k++) {
        st = node_grid(s, k, voxels, out, &c, err);
        const lmb_probe_grid *pg = &out->grids[out->grid_count ? out->grid_count - 1 : 0];
        voxels += st == LMB_OK ? pg->res[0] * pg->res[1] * pg->res[2] : 0;
    }
    uint8_t *fate = st == LMB_OK ? malloc(c.count + 1) : NULL;
    if (st == LMB_OK && !fate)
        st = lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for %zu probes", c.count);
    if (st != LMB_OK || !c.count) {
        free(c.p);
        free(c.voxel);
        free(c.auto_grid);
        free(fate);
        out->grid_count = st == LMB_OK ? out->grid_count : 0;
        return st;
    }
    const lmb_probe_grid *g0 = &out->grids[0];
    double far = FAR_CELLS * fmax(g0->cell[0], fmax(g0->cell[1], g0->cell[2]));
    double clearance = PROBE_CLEARANCE * fmin(g0->cell[0], fmin(g0->cell[1], g0->cell[2]));
    int threads = cfg->threads > 0 ? (int)cfg->threads : omp_get_max_threads();
#pragma omp parallel num_threads(threads)
    {
        lmb_rt_thread_init();
#pragma omp for schedule(dynamic, 64)
        for (size_t i = 0; i < c.count; i++) {
            int moved;
            int f = place_probe(rt, c.p + 3 * i, c.auto_grid[i] ? far : HUGE_VAL, clearance, c.auto_grid[i], &moved);
            fate[i] = (uint8_t)(f == 2 && !c.auto_grid[i] ? 0 : f); /* an artist's probe in the open stays */
            fate[i] |= (uint8_t)(moved && fate[i] == 0 ? 4 : 0);
        }
    }
    for (size_t i = 0; i < c.count; i++) {
        out->moved += fate[i] == 4;
        if (fate[i] == 4 && c.auto_grid[i]) { /* a moved probe counts in the voxel it now lies in */
            uint32_t v = lmb_probe_voxel_of(out, c.p + 3 * i);
            c.voxel[i] = v != UINT32_MAX ? v : c.voxel[i];
        }
        fate[i] &= 3;
        out->dropped_inside += fate[i] == 1;
        out->dropped_outside += fate[i] == 2;
        if (fate[i] == 0) {
            memmove(c.p + 3 * (size_t)out->count, c.p + 3 * i, 3 * sizeof *c.p);
            c.voxel[out->count] = c.voxel[i];
            out->count++;
        }
    }
    free(fate);
    free(c.auto_grid);
    out->position = c.p;
    out->cell = c.voxel;
    /* walls lined at half the probes' spacing near surfaces (a quarter cell) */
    double lining = 0.25 * fmin(g0->cell[0], fmin(g0->cell[1], g0->cell[2]));
    lmb_status walls = cfg->probes_auto ? lmb_probes_line_walls(out, l, rt, clearance, lining, LMB_PROBES_MAX, threads,
                                                                inside_geometry, err)
                                        : LMB_OK; /* an artist's volumes alone: the probes asked for */
    if (walls != LMB_OK) {
        lmb_probe_set_free(out);
        return walls;
    }
    out->sh = calloc((size_t)out->count * LMB_PROBE_SH + 1, sizeof *out->sh);
    out->cube = calloc((size_t)out->count * LMB_PROBE_CUBE + 1, sizeof *out->cube);
    if (!out->sh || !out->cube) {
        lmb_probe_set_free(out);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "probes: out of memory for %u probes", out->count);
    }
    if (cfg->probes_auto && out->grid_count && out->grids[0].volume == 0) {
        const uint32_t *n = out->grids[0].res;
        lmb_info(log, "probes: auto grid %ux%ux%u at spacing %g (%s), %u cells with surface split in 8", n[0], n[1],
                 n[2], out->spacing, cfg->probe_spacing > 0 ? "probes.spacing" : "auto: from the lightmapped surface's area",
                 out->refined);
    }
    lmb_info(log, "probes: %u (%u volume(s) from probes.volumes, %u from nodes' extras.lightmap_probes); %u moved "
             "out of geometry or off a surface (virtual offset), %u inside geometry and %u outside the level dropped; "
             "%u added on both sides of walls the tetrahedra crossed",
             out->count, cfg->probe_volume_count, s->probe_volume_count, out->moved, out->dropped_inside,
             out->dropped_outside, out->wall_probes);
    return LMB_OK;
}

void lmb_probe_set_free(lmb_probe_set *set)
{
    free(set->position);
    free(set->grids);
    free(set->cell);
    free(set->sh);
    free(set->cube);
    lmb_probe_tetrahedra_free(&set->tets);
    memset(set, 0, sizeof *set);
}
