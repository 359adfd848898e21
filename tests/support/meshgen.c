/* Generated meshes for tests and benchmarks (see meshgen.h). */
#include "meshgen.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static int alloc(gen_mesh *m, uint32_t nv, uint32_t nt)
{
    memset(m, 0, sizeof *m);
    m->positions = malloc(sizeof(float) * 3 * nv);
    m->indices = malloc(sizeof(uint32_t) * 3 * nt);
    if (!m->positions || !m->indices) {
        gen_mesh_free(m);
        return -1;
    }
    return 0;
}

void gen_mesh_free(gen_mesh *m)
{
    free(m->positions);
    free(m->indices);
    memset(m, 0, sizeof *m);
}

static void vert(gen_mesh *m, double x, double y, double z)
{
    float *p = m->positions + 3 * m->vertex_count++;
    p[0] = (float)x; p[1] = (float)y; p[2] = (float)z;
}

static void tri(gen_mesh *m, uint32_t a, uint32_t b, uint32_t c)
{
    uint32_t *t = m->indices + 3 * m->triangle_count++;
    t[0] = a; t[1] = b; t[2] = c;
}

/* Quad a,b,c,d counter-clockwise as seen from the side it faces. */
static void quad(gen_mesh *m, const double a[3], const double b[3], const double c[3], const double d[3])
{
    uint32_t base = m->vertex_count;
    vert(m, a[0], a[1], a[2]); vert(m, b[0], b[1], b[2]); vert(m, c[0], c[1], c[2]); vert(m, d[0], d[1], d[2]);
    tri(m, base, base + 1, base + 2);
    tri(m, base, base + 2, base + 3);
}

/* Axis-aligned block on the floor (y = 0): 4 sides and a top, facing out (10 triangles). */
static void block(gen_mesh *m, double x0, double z0, double x1, double z1, double h)
{
    const double p[8][3] = {{x0, 0, z0}, {x1, 0, z0}, {x1, 0, z1}, {x0, 0, z1},
                            {x0, h, z0}, {x1, h, z0}, {x1, h, z1}, {x0, h, z1}};
    quad(m, p[4], p[7], p[6], p[5]); /* top, +y */
    quad(m, p[0], p[4], p[5], p[1]); /* -z */
    quad(m, p[1], p[5], p[6], p[2]); /* +x */
    quad(m, p[2], p[6], p[7], p[3]); /* +z */
    quad(m, p[3], p[7], p[4], p[0]); /* -x */
}

int gen_cornell_box(gen_mesh *m)
{
    if (alloc(m, 60, 30))
        return -1;
    const double c[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}, {0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}};
    /* walls face into the room; the box is open at z = 1 */
    quad(m, c[0], c[3], c[2], c[1]); /* floor, +y */
    quad(m, c[4], c[5], c[6], c[7]); /* ceiling, -y */
    quad(m, c[0], c[1], c[5], c[4]); /* back wall z = 0, +z */
    quad(m, c[0], c[4], c[7], c[3]); /* left wall x = 0, +x */
    quad(m, c[1], c[2], c[6], c[5]); /* right wall x = 1, -x */
    block(m, 0.13, 0.37, 0.43, 0.67, 0.6); /* tall block */
    block(m, 0.55, 0.15, 0.85, 0.45, 0.3); /* short block */
    return 0;
}

int gen_uv_sphere(gen_mesh *m, uint32_t seg, uint32_t rings, float r)
{
    /* poles shared; rings-1 latitude circles of seg vertices each */
    if (seg < 3 || rings < 2 || alloc(m, 2 + seg * (rings - 1), 2 * seg * (rings - 1)))
        return -1;
    vert(m, 0, r, 0);
    for (uint32_t i = 1; i < rings; i++) {
        double th = PI * i / rings;
        for (uint32_t j = 0; j < seg; j++) {
            double ph = 2 * PI * j / seg;
            vert(m, r * sin(th) * cos(ph), r * cos(th), -r * sin(th) * sin(ph));
        }
    }
    vert(m, 0, -r, 0);
    uint32_t south = m->vertex_count - 1;
    for (uint32_t j = 0; j < seg; j++)
        tri(m, 0, 1 + j, 1 + (j + 1) % seg);
    for (uint32_t i = 0; i + 2 < rings; i++)
        for (uint32_t j = 0; j < seg; j++) {
            uint32_t a = 1 + i * seg + j, b = 1 + i * seg + (j + 1) % seg;
            uint32_t c = a + seg, d = b + seg;
            tri(m, a, c, d);
            tri(m, a, d, b);
        }
    for (uint32_t j = 0; j < seg; j++) {
        uint32_t base = 1 + (rings - 2) * seg;
        tri(m, base + j, south, base + (j + 1) % seg);
    }
    return 0;
}

int gen_torus(gen_mesh *m, uint32_t seg, uint32_t sides, float major, float minor)
{
    if (seg < 3 || sides < 3 || alloc(m, seg * sides, 2 * seg * sides))
        return -1;
    for (uint32_t i = 0; i < seg; i++) {
        double u = 2 * PI * i / seg;
        for (uint32_t j = 0; j < sides; j++) {
            double v = 2 * PI * j / sides, rr = major + minor * cos(v);
            vert(m, rr * cos(u), minor * sin(v), -rr * sin(u));
        }
    }
    for (uint32_t i = 0; i < seg; i++)
        for (uint32_t j = 0; j < sides; j++) {
            uint32_t a = i * sides + j, b = i * sides + (j + 1) % sides;
            uint32_t c = ((i + 1) % seg) * sides + j, d = ((i + 1) % seg) * sides + (j + 1) % sides;
            tri(m, a, c, d);
            tri(m, a, d, b);
        }
    return 0;
}

int gen_bumpy_sphere(gen_mesh *m, uint32_t seg, uint32_t rings, float r, float bump)
{
    if (gen_uv_sphere(m, seg, rings, r))
        return -1;
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        float *p = m->positions + 3 * v;
        double th = acos(fmax(-1.0, fmin(1.0, p[1] / r))), ph = atan2(-p[2], p[0]);
        double k = 1.0 + bump * (sin(5 * th) * sin(7 * ph) + 0.5 * sin(11 * th + 3 * ph) + 0.25 * cos(17 * ph - 13 * th));
        for (int c = 0; c < 3; c++)
            p[c] = (float)(p[c] * k);
    }
    return 0;
}
