/*
 * A light group's kept light out of memory (pipeline/group_store.h) and the groups' sum
 * (lmb_group_compose, which reads it span by span): three groups over two atlases (70,000 and 6
 * texels, so the sum's 65,536-texel spans end inside an atlas), with directions. Group 0 and 2 go
 * to their files, group 1 stays in memory; any span of any group reads back the floats put away,
 * a group brought back holds them again, and the sum equals sum_g s_g w_g E_g (and the weighted
 * direction) computed here texel by texel in double, bit for bit. With TMPDIR at a folder that
 * does not exist the light stays in memory and the sum is the same.
 */
#define _POSIX_C_SOURCE 200809L
#include "check.h"

#include "pipeline/group_lighting.h"
#include "pipeline/group_store.h"

#include <stdlib.h>

#define GROUPS 3
#define ATLASES 2

static const uint32_t width[ATLASES] = {350, 3}, height[ATLASES] = {200, 2};

static float value(uint32_t g, uint32_t a, size_t k, int dir)
{
    return (float)((dir ? -0.5 : 1.0) * (1.0 + g + 0.25 * a) * (1.0 + (double)(k % 977) / 977.0));
}

/* gl with every group's images filled (value()), as group_lighting.c allocates them. */
static void make_light(lmb_group_light *gl)
{
    memset(gl, 0, sizeof *gl);
    gl->groups = GROUPS;
    gl->atlases = ATLASES;
    gl->irradiance = calloc(GROUPS * ATLASES, sizeof *gl->irradiance);
    gl->direction = calloc(GROUPS * ATLASES, sizeof *gl->direction);
    gl->texels = calloc(ATLASES, sizeof *gl->texels);
    gl->file = malloc(GROUPS * sizeof *gl->file);
    gl->away = calloc(GROUPS, 1);
    for (uint32_t g = 0; g < GROUPS; g++)
        gl->file[g] = -1;
    for (uint32_t a = 0; a < ATLASES; a++) {
        gl->texels[a] = (uint64_t)width[a] * height[a];
        for (uint32_t g = 0; g < GROUPS; g++) {
            size_t n = 3 * (size_t)gl->texels[a], k = (size_t)g * ATLASES + a;
            gl->irradiance[k] = malloc(n * sizeof(float));
            gl->direction[k] = malloc(n * sizeof(float));
            for (size_t i = 0; i < n; i++) {
                gl->irradiance[k][i] = value(g, a, i, 0);
                gl->direction[k][i] = value(g, a, i, 1);
            }
        }
    }
}

/* Every span checked reads back value()'s floats. */
static void check_spans(const lmb_group_light *gl)
{
    const size_t spans[][3] = {{0, 0, 3}, {0, 65530, 70000}, {0, 1000, 1001}, {1, 0, 6}, {1, 2, 5}};
    for (uint32_t g = 0; g < GROUPS; g++)
        for (size_t s = 0; s < sizeof spans / sizeof *spans; s++) {
            uint32_t a = (uint32_t)spans[s][0];
            size_t i0 = spans[s][1], i1 = spans[s][2];
            float *e = malloc(3 * (i1 - i0) * sizeof *e), *d = malloc(3 * (i1 - i0) * sizeof *d);
            lmb_error err = {LMB_OK, ""};
            CHECK_INT(lmb_group_light_read_span(gl, g, a, i0, i1, e, d, &err), LMB_OK);
            int same = 1;
            for (size_t i = 0; i < 3 * (i1 - i0); i++)
                same &= e[i] == value(g, a, 3 * i0 + i, 0) && d[i] == value(g, a, 3 * i0 + i, 1);
            CHECK(same);
            free(e);
            free(d);
        }
}

/* The sum lmb_group_compose makes, against the formula texel by texel; returns whether equal. */
static int check_sum(lmb_group_light *gl)
{
    lmb_light_groups groups;
    memset(&groups, 0, sizeof groups);
    groups.count = GROUPS;
    const double scale[GROUPS] = {0.3, 2.0, 1.0}, weight[GROUPS][3] = {{1000, 900, 800}, {1, 1, 1}, {2, 3, 4}};
    for (uint32_t g = 0; g < GROUPS; g++) {
        groups.scale[g] = scale[g];
        memcpy(groups.weight[g], weight[g], sizeof weight[g]);
    }
    uint32_t w[ATLASES], h[ATLASES];
    memcpy(w, width, sizeof w);
    memcpy(h, height, sizeof h);
    lmb_layout layout;
    memset(&layout, 0, sizeof layout);
    layout.atlas_count = ATLASES;
    layout.width = w;
    layout.height = h;
    lmb_cache cache;
    memset(&cache, 0, sizeof cache);
    cache.layout = &layout;
    cache.atlas_count = ATLASES;
    cache.threads = 2;
    cache.irradiance = calloc(ATLASES, sizeof *cache.irradiance);
    lmb_error err = {LMB_OK, ""};
    CHECK_INT(lmb_group_compose(&groups, gl, &cache, NULL, &err), LMB_OK);
    int same = cache.direction != NULL;
    for (uint32_t a = 0; same && a < ATLASES; a++)
        for (size_t i = 0; i < (size_t)w[a] * h[a]; i++) {
            double sum[3] = {0, 0, 0}, v[3] = {0, 0, 0};
            for (uint32_t g = 0; g < GROUPS; g++) {
                double part[3];
                for (int c = 0; c < 3; c++) {
                    part[c] = scale[g] * weight[g][c] * (double)value(g, a, 3 * i + c, 0);
                    sum[c] += part[c];
                }
                double lum = 0.2126 * part[0] + 0.7152 * part[1] + 0.0722 * part[2];
                for (int c = 0; c < 3; c++)
                    v[c] += lum * (double)value(g, a, 3 * i + c, 1);
            }
            double lum = 0.2126 * sum[0] + 0.7152 * sum[1] + 0.0722 * sum[2], len = 0;
            for (int c = 0; c < 3; c++) {
                v[c] = lum > 0 ? v[c] / lum : 0;
                len += v[c] * v[c];
            }
            len = sqrt(len);
            for (int c = 0; c < 3; c++) {
                same &= cache.irradiance[a][3 * i + c] == (float)sum[c];
                same &= cache.direction[a][3 * i + c] == (float)(len > 1 ? v[c] / len : v[c]);
            }
        }
    for (uint32_t a = 0; a < ATLASES; a++) {
        free(cache.irradiance[a]);
        free(cache.direction ? cache.direction[a] : NULL);
    }
    free(cache.irradiance);
    free(cache.direction);
    return same;
}

int main(void)
{
    lmb_group_light gl;
    make_light(&gl);
    lmb_group_light_put_away(&gl, 0, NULL);
    lmb_group_light_put_away(&gl, 2, NULL);
    CHECK_INT(gl.in_memory, 0);
    CHECK(gl.away[0] && !gl.away[1] && gl.away[2]);
    CHECK(!gl.irradiance[0] && !gl.irradiance[1] && !gl.direction[5] && gl.irradiance[2] && gl.irradiance[3]);
    check_spans(&gl);
    CHECK(check_sum(&gl));
    lmb_error err = {LMB_OK, ""};
    CHECK_INT(lmb_group_light_bring_back(&gl, 0, &err), LMB_OK);
    CHECK(!gl.away[0] && gl.irradiance[0] && gl.irradiance[1]);
    check_spans(&gl);
    lmb_group_light_put_away(&gl, 0, NULL); /* again, over its file */
    check_spans(&gl);
    lmb_group_light_drop(&gl, 2);
    CHECK(!gl.away[2] && gl.file[2] == -1 && !gl.irradiance[4]);
    lmb_group_light_free(&gl);

    /* no folder for the files: the light stays in memory, the sum the same */
    setenv("TMPDIR", "/nonexistent-lmbake-test-folder", 1);
    make_light(&gl);
    lmb_group_light_put_away(&gl, 0, NULL);
    lmb_group_light_put_away(&gl, 1, NULL);
    CHECK_INT(gl.in_memory, 1);
    CHECK(!gl.away[0] && !gl.away[1] && gl.irradiance[0]);
    check_spans(&gl);
    CHECK(check_sum(&gl));
    lmb_group_light_free(&gl);
    printf("group store: spans and the sum read back from the files and from memory\n");
    return check_failures();
}
