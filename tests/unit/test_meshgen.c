/*
 * The generated reference meshes are what issue 3 says they are: triangle counts
 * (30, 20,224, 20,000), closed and consistently oriented (every edge used twice, in
 * opposite directions), outward (signed volume near the analytic one), and the Cornell
 * box's areas and inward-facing walls.
 */
#include "check.h"

#include "../support/meshgen.h"

#include <stdlib.h>

#define PI 3.14159265358979323846

static double signed_volume(const gen_mesh *m)
{
    double v = 0;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const float *a = m->positions + 3 * m->indices[3 * t], *b = m->positions + 3 * m->indices[3 * t + 1],
                    *c = m->positions + 3 * m->indices[3 * t + 2];
        v += (a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) - a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
              a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) / 6.0;
    }
    return v;
}

/* Closed and consistently wound: each directed edge appears once and its reverse once. */
static int closed_oriented(const gen_mesh *m)
{
    uint32_t nv = m->vertex_count;
    int *count = calloc((size_t)nv * nv, sizeof *count); /* small meshes only */
    if (!count)
        return 0;
    for (uint32_t t = 0; t < m->triangle_count; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = m->indices[3 * t + k], b = m->indices[3 * t + (k + 1) % 3];
            count[(size_t)a * nv + b]++;
        }
    int ok = 1;
    for (uint32_t a = 0; a < nv && ok; a++)
        for (uint32_t b = 0; b < nv && ok; b++)
            if (count[(size_t)a * nv + b] > 1 || (count[(size_t)a * nv + b] == 1 && count[(size_t)b * nv + a] != 1))
                ok = 0;
    free(count);
    return ok;
}

static double total_area(const gen_mesh *m)
{
    double s = 0;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const float *a = m->positions + 3 * m->indices[3 * t], *b = m->positions + 3 * m->indices[3 * t + 1],
                    *c = m->positions + 3 * m->indices[3 * t + 2];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2], z = e1[0] * e2[1] - e1[1] * e2[0];
        s += 0.5 * sqrt(x * x + y * y + z * z);
    }
    return s;
}

int main(void)
{
    gen_mesh m;
    CHECK_INT(gen_uv_sphere(&m, 128, 80, 1.0f), 0);
    CHECK_INT(m.triangle_count, 20224);
    CHECK(closed_oriented(&m));
    CHECK_NEAR(signed_volume(&m), 4.0 / 3.0 * PI, 0.01 * 4.0 / 3.0 * PI);
    gen_mesh_free(&m);

    CHECK_INT(gen_torus(&m, 125, 80, 1.0f, 0.3f), 0);
    CHECK_INT(m.triangle_count, 20000);
    CHECK(closed_oriented(&m));
    CHECK_NEAR(signed_volume(&m), 2 * PI * PI * 1.0 * 0.09, 0.01 * 2 * PI * PI * 0.09);
    gen_mesh_free(&m);

    CHECK_INT(gen_cornell_box(&m), 0);
    CHECK_INT(m.triangle_count, 30);
    /* 5 unit walls + tall block (0.09 top + 4 x 0.3 x 0.6) + short block (0.09 + 4 x 0.3 x 0.3) */
    CHECK_NEAR(total_area(&m), 5 + 0.81 + 0.45, 1e-5);
    /* floor (first quad) faces up into the room */
    const float *a = m.positions, *b = m.positions + 3, *c = m.positions + 6;
    /* ((b-a) x (c-a)).y = (b-a).z (c-a).x - (b-a).x (c-a).z */
    double ny = (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]);
    CHECK(ny > 0);
    gen_mesh_free(&m);
    return check_failures();
}
