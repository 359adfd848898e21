/*
 * `lmbake unwrap SCENE [-c CONFIG] [--report] [--png DIR]`: the lightmap UV layout alone
 * (unwrap + pack), with the quality report of issue 3: per mesh triangles, charts, L2
 * stretch and charting time; per atlas size, charts, coverage, L2 stretch, density
 * p1/p50/p99, overlapping texels; packing time. --png writes one chart image per atlas.
 */
#include "cli_common.h"
#include "commands.h"
#include "progress.h"

#include "pack/layout.h"
#include "write/output_dir.h"
#include "unwrap/metrics.h"
#include "image/image_adapter.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char help[] =
    "usage: lmbake unwrap SCENE [-c CONFIG] [--report] [--png DIR] [-q]\n"
    "\n"
    "Computes the lightmap UV layout (charts and atlases) of SCENE without baking.\n"
    "\n"
    "  -c, --config FILE   bake config: texel_density, density_overrides, atlas.*\n"
    "      --report        per mesh and per atlas quality figures (the default output)\n"
    "      --png DIR       write DIR/atlas-N-charts.png, one colour per chart\n"
    "  -q, --quiet         no progress or warnings\n"
    "  -h, --help          this help\n"
    "\n"
    "Metrics (docs/unwrap.md): coverage = texel centres inside a triangle /\n"
    "atlas area; L2 stretch (Sander 2001, 1 = ideal); density = UV/3D area per triangle over\n"
    "the mean, area-weighted percentiles; overlapping texels = centres covered twice.\n";

/* Mesh-level metrics: chart-local UVs against object-space positions. */
static void mesh_stretch(const lmb_layout_mesh *lm, lmb_uv_metrics *m)
{
    const lmb_mesh_soup *s = &lm->soup;
    uint32_t n = 0;
    double *pos = malloc(sizeof(double) * 9 * s->triangle_count + 1), *uv = malloc(sizeof(double) * 6 * s->triangle_count + 1);
    memset(m, 0, sizeof *m);
    for (uint32_t f = 0; pos && uv && f < s->triangle_count; f++) {
        if (lm->charts.chart_of[f] == UINT32_MAX)
            continue;
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++)
                pos[9 * n + 3 * k + d] = s->positions[3 * s->indices[3 * f + k] + d];
        memcpy(uv + 6 * n, lm->charts.uv + 6 * f, 6 * sizeof(double));
        n++;
    }
    lmb_uv_layout l = {n, pos, uv, 0, 0};
    lmb_error err;
    if (pos && uv)
        lmb_uv_metrics_compute(&l, m, &err);
    free(pos);
    free(uv);
}

/* Triangles of every instance placed in atlas a, world positions and atlas UVs. */
static lmb_status atlas_metrics(const lmb_scene *s, const lmb_layout *l, uint32_t a, lmb_uv_metrics *m, uint32_t *charts,
                                lmb_error *err)
{
    uint32_t n = 0, cap = 0;
    *charts = 0;
    for (uint32_t i = 0; i < l->instance_count; i++)
        if (l->instances[i].lightmapped && l->instances[i].atlas == a) {
            cap += l->meshes[s->instances[i].mesh].soup.triangle_count;
            *charts += l->meshes[s->instances[i].mesh].charts.chart_count;
        }
    double *pos = malloc(sizeof(double) * 9 * cap + 1), *uv = malloc(sizeof(double) * 6 * cap + 1);
    if (!pos || !uv) {
        free(pos);
        free(uv);
        return lmb_error_set(err, LMB_ERR_INTERNAL, "report: out of memory");
    }
    for (uint32_t i = 0; i < l->instance_count; i++) {
        const lmb_layout_instance *li = &l->instances[i];
        if (!li->lightmapped || li->atlas != a)
            continue;
        const lmb_layout_mesh *lm = &l->meshes[s->instances[i].mesh];
        for (uint32_t f = 0; f < lm->soup.triangle_count; f++) {
            if (lm->charts.chart_of[f] == UINT32_MAX)
                continue;
            lmb_layout_world_triangle(s, l, i, f, pos + 9 * n);
            lmb_layout_uv(l, i, f, uv + 6 * n);
            n++;
        }
    }
    lmb_uv_layout lay = {n, pos, uv, l->width[a], l->height[a]};
    lmb_status st = lmb_uv_metrics_compute(&lay, m, err);
    free(pos);
    free(uv);
    return st;
}

typedef struct paint {
    uint8_t *rgb;
    uint32_t width;
    uint8_t colour[3];
} paint;

static void paint_texel(void *user, uint32_t x, uint32_t y)
{
    paint *p = user;
    memcpy(p->rgb + 3 * ((size_t)y * p->width + x), p->colour, 3);
}

/* A bright colour per (instance, chart), from an integer hash. */
static void chart_colour(uint32_t instance, uint32_t chart, uint8_t out[3])
{
    uint32_t h = instance * 0x9E3779B1u ^ (chart + 1) * 0x85EBCA77u;
    h ^= h >> 15;
    h *= 0x2C1B3C6Du;
    h ^= h >> 12;
    for (int c = 0; c < 3; c++)
        out[c] = (uint8_t)(64 + ((h >> (8 * c)) & 0xFF) * 191 / 255);
}

static lmb_status write_png(const lmb_scene *s, const lmb_layout *l, uint32_t a, const char *dir, lmb_error *err)
{
    paint p = {calloc((size_t)l->width[a] * l->height[a] * 3 + 1, 1), l->width[a], {0, 0, 0}};
    if (!p.rgb)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "png: out of memory");
    for (uint32_t i = 0; i < l->instance_count; i++) {
        const lmb_layout_instance *li = &l->instances[i];
        if (!li->lightmapped || li->atlas != a)
            continue;
        const lmb_charts *c = &l->meshes[s->instances[i].mesh].charts;
        for (uint32_t f = 0; f < c->triangle_count; f++)
            if (c->chart_of[f] != UINT32_MAX) {
                chart_colour(i, c->chart_of[f], p.colour);
                double uv[6];
                lmb_layout_uv(l, i, f, uv);
                lmb_raster_triangle_centres(uv, l->width[a], l->height[a], paint_texel, &p);
            }
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/atlas-%u-charts.png", dir, a);
    lmb_status st = lmb_image_write_u8(path, l->width[a], l->height[a], 3, p.rgb, err);
    free(p.rgb);
    if (st == LMB_OK)
        printf("wrote %s\n", path);
    return st;
}

/* What the half-edge mesh refused and made seams of (nothing when the mesh is manifold and
 * consistently wound). */
static void print_topology(const lmb_topology_counts *t)
{
    uint32_t refused = t->complex_edge_faces + t->flipped_faces + t->vertex_faces;
    if (refused || t->nonmanifold_edges || t->bowtie_vertices)
        printf("  topology: %u non-manifold edges, %u bowtie vertices; %u triangles re-added on %u duplicated "
               "vertices (%u on a complex edge, %u flipped, %u at a vertex); OpenMesh warnings: %u complex edge, "
               "%u complex vertex, %u re-linking, %u other\n",
               t->nonmanifold_edges, t->bowtie_vertices, refused, t->duplicated_vertices, t->complex_edge_faces,
               t->flipped_faces, t->vertex_faces, t->om_complex_edge, t->om_complex_vertex, t->om_relink_failed,
               t->om_other);
}

typedef struct chart_box {
    double x0, y0, x1, y1, area; /* texel units; area: the chart's UV area */
    uint64_t centres;            /* texel centres its triangles cover */
} chart_box;

static void count_centre(void *user, uint32_t x, uint32_t y)
{
    (void)x;
    (void)y;
    ++*(uint64_t *)user;
}

static int by_short_side(const void *a, const void *b)
{
    const chart_box *p = a, *q = b;
    double x = fmin(p->x1 - p->x0, p->y1 - p->y0), y = fmin(q->x1 - q->x0, q->y1 - q->y0);
    return x < y ? -1 : x > y;
}

/* Chart sizes in texels, what atlas.min_chart_texels is about: the smallest chart, the
 * smallest instance's typical chart (the area-weighted median of its charts' shorter sides,
 * the measure the floor uses), and the charts that cover no texel centre (lit only by
 * dilation). */
static void print_chart_sizes(const lmb_scene *s, const lmb_layout *l)
{
    uint64_t charts = 0, empty = 0;
    double smallest = INFINITY, typical_min = INFINITY;
    uint32_t smallest_at = 0, typical_at = 0;
    for (uint32_t i = 0; i < l->instance_count; i++) {
        const lmb_layout_instance *li = &l->instances[i];
        const lmb_charts *c = &l->meshes[s->instances[i].mesh].charts;
        if (!li->lightmapped || c->chart_count == 0)
            continue;
        chart_box *b = malloc(sizeof(chart_box) * c->chart_count);
        if (!b)
            return;
        for (uint32_t k = 0; k < c->chart_count; k++)
            b[k] = (chart_box){INFINITY, INFINITY, -INFINITY, -INFINITY, 0, 0};
        for (uint32_t f = 0; f < c->triangle_count; f++) {
            uint32_t k = c->chart_of[f];
            if (k == UINT32_MAX)
                continue;
            double u[6];
            lmb_layout_uv(l, i, f, u);
            for (int v = 0; v < 3; v++) {
                b[k].x0 = fmin(b[k].x0, u[2 * v]);
                b[k].x1 = fmax(b[k].x1, u[2 * v]);
                b[k].y0 = fmin(b[k].y0, u[2 * v + 1]);
                b[k].y1 = fmax(b[k].y1, u[2 * v + 1]);
            }
            b[k].area += 0.5 * fabs((u[2] - u[0]) * (u[5] - u[1]) - (u[4] - u[0]) * (u[3] - u[1]));
            lmb_raster_triangle_centres(u, l->width[li->atlas], l->height[li->atlas], count_centre, &b[k].centres);
        }
        double total = 0, run = 0;
        for (uint32_t k = 0; k < c->chart_count; k++) {
            double side = fmin(b[k].x1 - b[k].x0, b[k].y1 - b[k].y0);
            charts++;
            empty += b[k].centres == 0;
            total += b[k].area;
            if (side < smallest) {
                smallest = side;
                smallest_at = i;
            }
        }
        qsort(b, c->chart_count, sizeof *b, by_short_side);
        uint32_t k = c->chart_count;
        while (k > 0 && run < 0.5 * total)
            run += b[--k].area;
        double typical = fmin(b[k].x1 - b[k].x0, b[k].y1 - b[k].y0);
        if (typical < typical_min) {
            typical_min = typical;
            typical_at = i;
        }
        free(b);
    }
    if (charts)
        printf("chart sizes: smallest %.2f texels across (instance '%s'); smallest typical chart %.2f texels across "
               "(instance '%s'); %llu of %llu charts (%.1f%%) cover no texel centre\n",
               smallest, s->instances[smallest_at].name, typical_min, s->instances[typical_at].name,
               (unsigned long long)empty, (unsigned long long)charts, 100.0 * (double)empty / (double)charts);
}

static void print_report(const lmb_scene *s, const lmb_layout *l)
{
    double chart_total = 0;
    for (uint32_t m = 0; m < l->mesh_count; m++) {
        const lmb_layout_mesh *lm = &l->meshes[m];
        if (!lm->used)
            continue;
        lmb_uv_metrics um;
        mesh_stretch(lm, &um);
        chart_total += lm->chart_seconds;
        printf("mesh '%s': %u triangles (%u zero-area, %u hidden), %u charts (%u planar, %u split, %u glued), "
               "L2 stretch %.4f, charting %.3f s\n",
               s->meshes[m].name, lm->soup.triangle_count, s->meshes[m].degenerate_count, lm->hidden_count,
               lm->charts.chart_count,
               lm->charts.planar_charts, lm->charts.splits, lm->charts.glued, um.l2_stretch, lm->chart_seconds);
        print_topology(&lm->charts.topology);
    }
    printf("total: charting %.3f s, packing %.3f s, %u charts in %u atlas(es)\n", chart_total, l->pack_seconds,
           l->chart_total, l->atlas_count);
    if (l->density.automatic)
        printf("texel density: auto, %.4g texels per unit (budget %llu texels; %llu made, %.0f%%)",
               l->density.scene_density, (unsigned long long)l->density.budget, (unsigned long long)l->density.texels,
               l->density.budget ? 100.0 * (double)l->density.texels / (double)l->density.budget : 0.0);
    else
        printf("texel density: %.4g texels per unit", l->density.scene_density);
    if (l->density.capped)
        printf("; %u instance(s) lowered to fit one atlas", l->density.capped);
    if (l->density.raised)
        printf("; %u small instance(s) raised (atlas.min_chart_texels)", l->density.raised);
    printf("\n");
    print_chart_sizes(s, l);
}

int cmd_unwrap(int argc, char **argv)
{
    const char *scene_path = NULL, *config_path = NULL, *png_dir = NULL;
    int quiet = 0;
    for (int i = 1; i < argc; i++) {
        const char *v;
        int r;
        if (cli_is_flag(argv[i], "--help", "-h")) {
            fputs(help, stdout);
            return LMB_OK;
        } else if ((r = cli_opt_value(argc, argv, &i, "--config", "-c", &v)) != 0) {
            if (r < 0)
                return cli_usage_error("unwrap", "%s needs a file", argv[i]);
            config_path = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--png", NULL, &v)) != 0) {
            if (r < 0)
                return cli_usage_error("unwrap", "--png needs a folder");
            png_dir = v;
        } else if (cli_is_flag(argv[i], "--report", NULL)) {
            /* the report is always printed */
        } else if (cli_is_flag(argv[i], "--quiet", "-q")) {
            quiet = 1;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            return cli_usage_error("unwrap", "unknown option '%s'", argv[i]);
        } else if (scene_path) {
            return cli_usage_error("unwrap", "one scene at a time ('%s' and '%s')", scene_path, argv[i]);
        } else {
            scene_path = argv[i];
        }
    }
    if (!scene_path)
        return cli_usage_error("unwrap", "no SCENE given");
    lmb_config cfg;
    lmb_error err = {LMB_OK, ""};
    lmb_config_default(&cfg);
    if (config_path && lmb_config_load(config_path, &cfg, &err) != LMB_OK)
        return cli_fail(&err);
    cli_warnings warnings = {0, quiet};
    lmb_log log = cli_log(&warnings);
    if (lmb_config_lint(&cfg, &log, &err) != LMB_OK)
        return cli_fail(&err);
    lmb_scene *scene;
    if (lmb_scene_load(scene_path, &cfg, &scene, &log, &err) != LMB_OK)
        return cli_fail(&err);
    lmb_scene_select_lightmapped(scene, &cfg);
    cli_progress progress;
    cli_progress_init(&progress, stderr, quiet);
    lmb_layout layout;
    int made = 0;
    lmb_status st = png_dir ? lmb_make_folders(png_dir, &made, &err) : LMB_OK;
    if (st == LMB_OK)
        st = lmb_layout_build(scene, &cfg, cli_progress_update, &progress, &log, &layout, &err);
    double texels = 0;
    if (st == LMB_OK) {
        print_report(scene, &layout);
        for (uint32_t a = 0; a < layout.atlas_count && st == LMB_OK; a++) {
            lmb_uv_metrics m;
            uint32_t charts;
            st = atlas_metrics(scene, &layout, a, &m, &charts, &err);
            if (st == LMB_OK)
                printf("atlas %u: %ux%u, %u charts, coverage %.4f, L2 stretch %.4f, density p1/p50/p99 "
                       "%.3f/%.3f/%.3f, overlapping texels %llu\n",
                       a, layout.width[a], layout.height[a], charts, m.coverage, m.l2_stretch, m.density_p1,
                       m.density_p50, m.density_p99, (unsigned long long)m.overlapping_texels);
            texels += m.coverage * layout.width[a] * layout.height[a];
            if (st == LMB_OK && png_dir)
                st = write_png(scene, &layout, a, png_dir, &err);
        }
        if (st == LMB_OK)
            printf("texels: %.0f covered (texel centres inside a triangle) in %u atlas(es)\n", texels,
                   layout.atlas_count);
    }
    lmb_layout_free(&layout);
    lmb_scene_free(scene);
    return st == LMB_OK ? LMB_OK : cli_fail(&err);
}
