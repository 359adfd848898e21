/*
 * The unwrapper's half-edge topology (OpenMesh behind baker/unwrap/halfedge_adapter.h) on
 * input OpenMesh's add_face refuses or accepts only as a non-manifold vertex: a complex
 * edge (3 triangles on one edge), a winding flip, a bowtie vertex and a triangle touching a
 * closed fan at its centre. Checks that every triangle is kept (and charted), which
 * neighbours become seams, which stay, which seams link coplanar triangles, the counts
 * reported, that OpenMesh printed nothing, and that two builds agree.
 */
#define _POSIX_C_SOURCE 200809L
#include "check.h"

#include "unwrap/unwrap_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const float pos[] = {
    0, 0, 0,   1, 0, 0,   0.5f, 1, 0,  0.5f, -1, 0, 0.5f, 0, 1, -0.5f, 0, 0.5f, /* 0-5: complex edge 0-1 */
    3, 0, 0,   4, 0, 0,   3.5f, 1, 0,  3.5f, -1, 0,                           /* 6-9: winding flip on 6-7 */
    6, 0, 0,   7, 0, 0,   7, 1, 0,     5, 0, 0,      5, -1, 0,                /* 10-14: bowtie at 10 */
    10, 0, 0,  11, 0, 0,  10, 1, 0,    9, 0, 0,      10, -1, 0,               /* 15-19: closed fan around 15 */
    10, 0, 1,  10.5f, 0.5f, 1,                                                 /* 20-21: touches 15 */
};

static const uint32_t idx[] = {
    0, 1, 2,                                  /* T0 */
    1, 0, 3,                                  /* T1: T0's neighbour across 0-1 */
    1, 0, 4,                                  /* T2: a third triangle on 0-1 (refused: complex edge) */
    4, 0, 5,                                  /* T3: T2's neighbour across 0-4, in T2's plane */
    6, 7, 8,                                  /* T4 */
    6, 7, 9,                                  /* T5: runs 6 -> 7 as T4 does (refused: flipped) */
    10, 11, 12,                               /* T6 */
    10, 13, 14,                               /* T7: shares only vertex 10 with T6 (bowtie) */
    15, 16, 17, 15, 17, 18, 15, 18, 19, 15, 19, 16, /* T8-T11: a closed fan around 15 */
    15, 20, 21,                               /* T12: touches the closed fan (refused: complex vertex) */
};

enum { NT = sizeof idx / sizeof idx[0] / 3 };

#define N LMB_NONE

/* Expected triangle across each corner's edge (corner k: from vertex k to k + 1). */
static const uint32_t expect[NT][3] = {
    {N, N, N}, /* T0: 0-1 is a seam (three triangles), its other edges are boundaries */
    {N, N, N}, /* T1 */
    {N, 3, N}, /* T2: keeps T3 across 0-4 (vertex 1 duplicated, not 0) */
    {2, N, N}, /* T3 */
    {N, N, N}, /* T4: 6-7 is a seam (flip) */
    {N, N, N}, /* T5 */
    {N, N, N}, /* T6 */
    {N, N, N}, /* T7 */
    {11, N, 9}, {8, N, 10}, {9, N, 11}, {10, N, 8}, /* the fan keeps its spokes */
    {N, N, N}, /* T12 */
};

/* Runs lmb_topology_build with stderr sent to a temporary file; returns the bytes that
 * reached stderr, or -1. */
static long build_quietly(const lmb_unwrap_input *in, lmb_topology *t, lmb_status *st, lmb_error *err)
{
    FILE *tmp = tmpfile();
    if (!tmp)
        return -1;
    fflush(stderr);
    int saved = dup(2);
    dup2(fileno(tmp), 2);
    *st = lmb_topology_build(in, "test", t, err);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    long n = (long)lseek(fileno(tmp), 0, SEEK_END);
    fclose(tmp);
    return n;
}

static void test_topology(void)
{
    lmb_unwrap_input in = {sizeof pos / sizeof pos[0] / 3, pos, NT, idx, NULL};
    lmb_topology t, again;
    lmb_error err;
    lmb_status st;
    CHECK_INT(build_quietly(&in, &t, &st, &err), 0); /* OpenMesh's messages were counted, not printed */
    CHECK_INT(st, LMB_OK);
    if (st != LMB_OK)
        return;
    for (uint32_t f = 0; f < NT; f++)
        for (int k = 0; k < 3; k++) {
            if (t.neighbor[3 * f + k] != expect[f][k])
                printf("T%u corner %d: neighbour %d, expected %d\n", f, k, (int)t.neighbor[3 * f + k],
                       (int)expect[f][k]);
            CHECK(t.neighbor[3 * f + k] == expect[f][k]);
        }
    /* coplanar links across seams: only T0 and T1 (same plane, edge 0-1 run both ways); T4/T5
     * run 6-7 the same way (a flip), T2 stands across the others' plane */
    for (uint32_t f = 0; f < NT; f++)
        for (int k = 0; k < 3; k++) {
            uint32_t want = f == 0 && k == 0 ? 1 : f == 1 && k == 0 ? 0 : LMB_NONE;
            if (t.link[3 * f + k] != want)
                printf("T%u corner %d: link %d, expected %d\n", f, k, (int)t.link[3 * f + k], (int)want);
            CHECK(t.link[3 * f + k] == want);
        }
    /* 22 distinct positions; three duplicates: vertex 1 for T2, vertex 6 for T5, 15 for T12 */
    CHECK_INT(t.counts.duplicated_vertices, 3);
    CHECK_INT(t.vertex_count, 22 + 3);
    CHECK(t.corner[3 * 2 + 0] >= 22 && t.corner[3 * 2 + 1] == t.corner[3 * 3 + 1]);   /* T2: 1', then 0 shared with T3 */
    CHECK(t.corner[3 * 5 + 0] >= 22 && t.corner[3 * 5 + 1] == t.corner[3 * 4 + 1]);   /* T5: 6', 7 */
    CHECK(t.corner[3 * 12 + 0] >= 22 && t.corner[3 * 12 + 0] != t.corner[3 * 8 + 0]); /* T12: 15' */
    CHECK_INT(t.counts.complex_edge_faces, 1);
    CHECK_INT(t.counts.flipped_faces, 1);
    CHECK_INT(t.counts.vertex_faces, 1);
    CHECK_INT(t.counts.nonmanifold_edges, 1);
    /* vertex 10; vertex 0, where the fin's fan meets T0/T1's; vertex 7, which T5's copy still
     * shares with T4 (only 6 was duplicated) */
    CHECK_INT(t.counts.bowtie_vertices, 3);
    CHECK_INT(t.counts.om_complex_edge, 2);   /* T2 and T5 */
    CHECK_INT(t.counts.om_complex_vertex, 1); /* T12 */
    CHECK_INT(t.counts.om_relink_failed + t.counts.om_other, 0);
    /* deterministic */
    CHECK_INT(build_quietly(&in, &again, &st, &err), 0);
    CHECK(st == LMB_OK && again.vertex_count == t.vertex_count &&
          !memcmp(again.neighbor, t.neighbor, sizeof(uint32_t) * 3 * NT) &&
          !memcmp(again.corner, t.corner, sizeof(uint32_t) * 3 * NT));
    if (st == LMB_OK)
        lmb_topology_free(&again);
    lmb_topology_free(&t);
}

/* The whole unwrap keeps and charts every triangle and reports the same counts. */
static void test_unwrap_keeps_all(void)
{
    lmb_unwrap_input in = {sizeof pos / sizeof pos[0] / 3, pos, NT, idx, NULL};
    lmb_unwrap_options o;
    lmb_charts c;
    lmb_error err;
    lmb_unwrap_options_default(&o);
    o.name = "test";
    CHECK_INT(lmb_unwrap_mesh(&in, &o, &c, &err), LMB_OK);
    for (uint32_t f = 0; f < NT; f++)
        CHECK(c.chart_of[f] != UINT32_MAX);
    CHECK(c.chart_of[2] == c.chart_of[3]);          /* neighbours in one plane: one chart */
    CHECK(c.chart_of[0] == c.chart_of[1]);          /* coplanar across the complex edge: linked */
    CHECK(c.chart_of[2] != c.chart_of[0]);          /* the fin on that edge: a seam */
    CHECK(c.chart_of[4] != c.chart_of[5]);          /* across the winding flip: a seam */
    CHECK(c.chart_of[8] == c.chart_of[10]);         /* the flat fan is one chart */
    CHECK_INT(c.topology.complex_edge_faces, 1);
    CHECK_INT(c.topology.flipped_faces, 1);
    CHECK_INT(c.topology.vertex_faces, 1);
    CHECK_INT(c.topology.nonmanifold_edges, 1);
    CHECK_INT(c.topology.bowtie_vertices, 3);
    lmb_charts_free(&c);
}

int main(void)
{
    test_topology();
    test_unwrap_keeps_all();
    return check_failures();
}
