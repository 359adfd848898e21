/*
 * Packing on the 4 x 4 block grid (block-compressed lightmaps: BC6H, ASTC 4x4): charts of a
 * sphere, a torus and a grid of small quads, packed with padding 2. Checked on the placed
 * triangles, sampled densely (independent of the packer's rasterizer): every texel a chart
 * covers lies in its atlas, no 4 x 4 block holds texels two charts record (covered texels
 * and their 8 neighbours: what bilinear filtering reads), and two charts' records stay more
 * than `padding` texels apart, as without blocks. Also: the block grid's atlas area against
 * the texel grid's, within a bound measured here (small charts cost the most: a chart 3 texels
 * wide spans 2 blocks with its neighbours' reach). And instanced copies' rectangles
 * (rects.h) on the block grid: corners on it, no block shared by two rectangles, at least
 * `padding` texels apart.
 */
#include "check.h"

#include "../support/charts_at.h"
#include "../support/meshgen.h"
#include "pack/pack.h"
#include "pack/rects.h"
#include "unwrap/unwrap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NOBODY UINT32_MAX

/* Per atlas texel: the chart whose record holds it, and the chart whose record dilated by
 * padding reaches it (NOBODY: none). */
typedef struct owners {
    uint32_t w, h;
    uint32_t *chart;
    uint32_t *near;
} owners;

static void mark(owners *o, uint32_t chart, const double *uv, uint32_t triangles, const double m[6], uint32_t padding,
                 uint64_t *outside, uint64_t *clashes, uint8_t *covered)
{
    memset(covered, 0, (size_t)o->w * o->h);
    for (uint32_t t = 0; t < triangles; t++) {
        double p[3][2];
        for (int v = 0; v < 3; v++) {
            double x = uv[6 * t + 2 * v], y = uv[6 * t + 2 * v + 1];
            p[v][0] = m[0] * x + m[1] * y + m[2];
            p[v][1] = m[3] * x + m[4] * y + m[5];
        }
        const int n = 48; /* barycentric samples per edge */
        for (int a = 0; a <= n; a++)
            for (int b = 0; a + b <= n; b++) {
                /* inside the triangle by 1e-4 of a sample step: a vertex on a texel corner
                 * touches no texel beyond it (the packer's raster takes open squares) */
                double e = 1e-4, wa = (a + e) / (n + 3 * e), wb = (b + e) / (n + 3 * e), wc = 1 - wa - wb;
                double x = wa * p[0][0] + wb * p[1][0] + wc * p[2][0], y = wa * p[0][1] + wb * p[1][1] + wc * p[2][1];
                long tx = (long)floor(x), ty = (long)floor(y);
                if (tx < 0 || ty < 0 || tx >= (long)o->w || ty >= (long)o->h) {
                    (*outside)++;
                    continue;
                }
                covered[(size_t)ty * o->w + (size_t)tx] = 1;
            }
    }
    /* record: covered + 1; near: covered + 1 + padding */
    long r = 1 + (long)padding;
    for (uint32_t y = 0; y < o->h; y++)
        for (uint32_t x = 0; x < o->w; x++) {
            if (!covered[(size_t)y * o->w + x])
                continue;
            for (long dy = -r; dy <= r; dy++)
                for (long dx = -r; dx <= r; dx++) {
                    long X = (long)x + dx, Y = (long)y + dy;
                    if (X < 0 || Y < 0 || X >= (long)o->w || Y >= (long)o->h)
                        continue;
                    size_t k = (size_t)Y * o->w + (size_t)X;
                    if (labs(dx) <= 1 && labs(dy) <= 1) {
                        if (o->chart[k] != NOBODY && o->chart[k] != chart)
                            (*clashes)++;
                        o->chart[k] = chart;
                    }
                    if (o->near[k] == NOBODY)
                        o->near[k] = chart;
                }
        }
}

/* Packs the charts of g at `density` texels per unit with the given block; returns the total
 * atlas area and checks the layout. */
static uint64_t pack(const char *name, const gen_mesh *g, double density, uint32_t block)
{
    lmb_unwrap_input in = {g->vertex_count, g->positions, g->triangle_count, g->indices, NULL};
    lmb_unwrap_options uo;
    lmb_charts c;
    lmb_error err;
    lmb_unwrap_options_default(&uo);
    if (lmb_unwrap_mesh(&in, &uo, &c, &err) != LMB_OK) {
        fprintf(stderr, "%s: %s\n", name, err.message);
        check_failed_count++;
        return 0;
    }
    uint32_t padding = 2;
    charts_at at;
    if (!charts_at_density(&c, density, &at)) {
        check_failed_count++;
        lmb_charts_free(&c);
        return 0;
    }
    const lmb_pack_chart *charts = at.charts;
    lmb_pack_options po = {2048, padding, 0, 0, block};
    lmb_pack_result r;
    uint64_t area = 0;
    CHECK_INT(lmb_pack_charts(charts, c.chart_count, &po, &r, &err), LMB_OK);
    uint64_t outside = 0, clashes = 0, close = 0, shared_blocks = 0;
    for (uint32_t a = 0; a < r.atlas_count; a++) {
        owners o = {r.width[a], r.height[a], NULL, NULL};
        size_t texels = (size_t)o.w * o.h;
        area += texels;
        o.chart = malloc(texels * sizeof *o.chart + 1);
        o.near = malloc(texels * sizeof *o.near + 1);
        uint8_t *covered = malloc(texels + 1);
        for (size_t k = 0; k < texels; k++)
            o.chart[k] = o.near[k] = NOBODY;
        /* records first, then each chart's padded reach must meet no other chart's record */
        for (uint32_t k = 0; k < c.chart_count; k++)
            if (r.placements[k].atlas == a)
                mark(&o, k, charts[k].uv, charts[k].triangle_count, r.placements[k].m, padding, &outside, &clashes,
                     covered);
        for (uint32_t k = 0; k < c.chart_count; k++) {
            if (r.placements[k].atlas != a)
                continue;
            for (size_t q = 0; q < texels; q++)
                o.near[q] = NOBODY;
            uint64_t dummy = 0;
            owners only = {o.w, o.h, malloc(texels * sizeof(uint32_t) + 1), o.near};
            for (size_t q = 0; q < texels; q++)
                only.chart[q] = NOBODY;
            mark(&only, k, charts[k].uv, charts[k].triangle_count, r.placements[k].m, padding, &dummy, &dummy,
                 covered);
            for (size_t q = 0; q < texels; q++)
                close += o.near[q] == k && o.chart[q] != NOBODY && o.chart[q] != k;
            free(only.chart);
        }
        if (block > 1)
            for (uint32_t by = 0; by < o.h / block; by++)
                for (uint32_t bx = 0; bx < o.w / block; bx++) {
                    uint32_t first = NOBODY;
                    int two = 0;
                    for (uint32_t y = by * block; y < (by + 1) * block; y++)
                        for (uint32_t x = bx * block; x < (bx + 1) * block; x++) {
                            uint32_t ch = o.chart[(size_t)y * o.w + x];
                            if (ch != NOBODY && first != NOBODY && ch != first)
                                two = 1;
                            if (ch != NOBODY && first == NOBODY)
                                first = ch;
                        }
                    shared_blocks += (uint64_t)two;
                }
        free(o.chart);
        free(o.near);
        free(covered);
    }
    printf("%s, block %u: %u charts in %u atlas(es), %llu texels; samples outside %llu, texels two charts "
           "record %llu, texels within padding of another chart %llu, blocks two charts record %llu\n",
           name, block, c.chart_count, r.atlas_count, (unsigned long long)area, (unsigned long long)outside,
           (unsigned long long)clashes, (unsigned long long)close, (unsigned long long)shared_blocks);
    CHECK_INT(outside, 0);
    CHECK_INT(clashes, 0);
    CHECK_INT(close, 0);
    CHECK_INT(shared_blocks, 0);
    CHECK(block <= 1 || (r.atlas_count > 0 && r.width[0] % block == 0 && r.height[0] % block == 0));
    lmb_pack_result_free(&r);
    lmb_charts_free(&c);
    charts_at_free(&at);
    return area;
}

/* A grid of separate quads (each its own chart), side `side` units: many small charts, the
 * block grid's worst case. */
static int gen_quads(gen_mesh *m, uint32_t n, float side)
{
    memset(m, 0, sizeof *m);
    m->vertex_count = 4 * n * n;
    m->triangle_count = 2 * n * n;
    m->positions = malloc(sizeof(float) * 3 * m->vertex_count);
    m->indices = malloc(sizeof(uint32_t) * 3 * m->triangle_count);
    if (!m->positions || !m->indices)
        return -1;
    for (uint32_t q = 0; q < n * n; q++) {
        float x = (float)(q % n) * 2 * side, z = (float)(q / n) * 2 * side, tilt = 0.1f * (float)(q % 7);
        float corner[4][3] = {{x, 0, z}, {x + side, tilt, z}, {x + side, tilt, z + side}, {x, 0, z + side}};
        memcpy(m->positions + 12 * q, corner, sizeof corner);
        uint32_t b = 4 * q, idx[6] = {b, b + 1, b + 2, b, b + 2, b + 3};
        memcpy(m->indices + 6 * q, idx, sizeof idx);
    }
    return 0;
}

/* 40 rectangles of assorted sizes (whole blocks and not: copies at other scales) placed with
 * padding 2 on the 4 x 4 grid. */
static void rects_on_blocks(void)
{
    lmb_rect_item items[40];
    for (uint32_t i = 0; i < 40; i++)
        items[i] = (lmb_rect_item){8 + 4 * (i % 5) + (i % 3 == 2 ? 3 : 0), 12 + 4 * (i % 4) + (i % 7 == 3 ? 1 : 0),
                                   i / 10};
    lmb_rect_result r;
    lmb_error err;
    CHECK_INT(lmb_place_rects(items, 40, 2, 4, 256, &r, &err), LMB_OK);
    uint32_t off_grid = 0, shared = 0, close = 0;
    for (uint32_t i = 0; i < 40; i++) {
        off_grid += r.x[i] % 4 != 0 || r.y[i] % 4 != 0;
        for (uint32_t j = i + 1; j < 40; j++) {
            if (r.atlas[i] != r.atlas[j])
                continue;
            /* blocks each covers: [x / 4, ceil((x + w) / 4)) */
            int bx = r.x[i] / 4 < (r.x[j] + items[j].w + 3) / 4 && r.x[j] / 4 < (r.x[i] + items[i].w + 3) / 4;
            int by = r.y[i] / 4 < (r.y[j] + items[j].h + 3) / 4 && r.y[j] / 4 < (r.y[i] + items[i].h + 3) / 4;
            shared += bx && by;
            int gx = r.x[i] < r.x[j] + items[j].w + 2 && r.x[j] < r.x[i] + items[i].w + 2;
            int gy = r.y[i] < r.y[j] + items[j].h + 2 && r.y[j] < r.y[i] + items[i].h + 2;
            close += gx && gy;
        }
    }
    printf("rectangles on blocks: %u atlases; off the grid %u, pairs sharing a block %u, pairs closer than the "
           "padding %u\n", r.atlas_count, off_grid, shared, close);
    CHECK_INT(off_grid, 0);
    CHECK_INT(shared, 0);
    CHECK_INT(close, 0);
    lmb_rect_result_free(&r);
}

int main(void)
{
    rects_on_blocks();
    gen_mesh g;
    /* bounds: the block grid's area over the texel grid's at these densities, measured with
     * some margin (docs/unwrap.md#block-compressed-atlases) */
    struct {
        const char *name;
        int kind;
        double density, bound;
    } cases[] = {{"sphere 48x32", 0, 40.0, 1.15}, {"torus 48x24", 1, 40.0, 1.2}, {"quads 12x12", 2, 4.0, 1.5}};
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        int ok = cases[i].kind == 0   ? gen_uv_sphere(&g, 48, 32, 1.0f)
                 : cases[i].kind == 1 ? gen_torus(&g, 48, 24, 1.0f, 0.3f)
                                      : gen_quads(&g, 12, 1.0f);
        if (ok != 0) {
            check_failed_count++;
            continue;
        }
        uint64_t texels = pack(cases[i].name, &g, cases[i].density, 1);
        uint64_t blocks = pack(cases[i].name, &g, cases[i].density, 4);
        double ratio = texels ? (double)blocks / (double)texels : 0;
        printf("%s: block grid area / texel grid area = %.3f (bound %.2f)\n", cases[i].name, ratio, cases[i].bound);
        CHECK(ratio > 0 && ratio <= cases[i].bound);
        gen_mesh_free(&g);
    }
    return check_failures();
}
