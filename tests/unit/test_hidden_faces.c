/*
 * Hidden faces (baker/unwrap/hidden_faces.h) on small hand-built meshes whose answer is known:
 * two crates touching on a slab hide exactly the faces they press together and their bottoms; a
 * box's bottom on a one-sided plane is hidden, and so is a plane smaller than a box's bottom under
 * it (but not that bottom); a two-sided card (alone or in a closed room), a box above a plane and
 * skipped triangles are not; the same flags at 1 and 4 threads and with the mesh 10 km from the
 * origin.
 */
#include "check.h"

#include "unwrap/hidden_faces.h"

#include <stdlib.h>
#include <string.h>

typedef struct soup {
    float pos[3 * 256];
    uint32_t idx[3 * 256];
    uint32_t nv, nt;
} soup;

static void quad(soup *s, const float a[3], const float b[3], const float c[3], const float d[3])
{
    const float *p[4] = {a, b, c, d};
    uint32_t v = s->nv;
    for (int k = 0; k < 4; k++)
        memcpy(s->pos + 3 * s->nv++, p[k], 3 * sizeof(float));
    uint32_t t[6] = {v, v + 1, v + 2, v, v + 2, v + 3};
    memcpy(s->idx + 3 * s->nt, t, sizeof t);
    s->nt += 2;
}

/* An axis-aligned box, faces outward (counter-clockwise seen from outside); returns its first
 * triangle. Triangles in order: -y, +y, -z, +z, -x, +x (two each). */
static uint32_t box(soup *s, float x0, float y0, float z0, float x1, float y1, float z1)
{
    uint32_t first = s->nt;
    float p[8][3] = {{x0, y0, z0}, {x1, y0, z0}, {x1, y1, z0}, {x0, y1, z0},
                     {x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}};
    quad(s, p[0], p[1], p[5], p[4]); /* -y */
    quad(s, p[3], p[7], p[6], p[2]); /* +y */
    quad(s, p[0], p[3], p[2], p[1]); /* -z */
    quad(s, p[4], p[5], p[6], p[7]); /* +z */
    quad(s, p[0], p[4], p[7], p[3]); /* -x */
    quad(s, p[1], p[2], p[6], p[5]); /* +x */
    return first;
}

/* A one-sided square at height y, facing +y. */
static uint32_t plane_up(soup *s, float x0, float z0, float x1, float z1, float y)
{
    uint32_t first = s->nt;
    float a[3] = {x0, y, z0}, b[3] = {x0, y, z1}, c[3] = {x1, y, z1}, d[3] = {x1, y, z0};
    quad(s, a, b, c, d);
    return first;
}

static uint32_t find(const soup *s, const uint8_t *skip, int threads, uint8_t *hidden)
{
    lmb_unwrap_input in = {s->nv, s->pos, s->nt, s->idx, skip};
    uint32_t count = 12345;
    lmb_error err;
    CHECK(lmb_find_hidden_faces(&in, threads, hidden, &count, &err) == LMB_OK);
    uint32_t n = 0;
    for (uint32_t f = 0; f < s->nt; f++)
        n += hidden[f];
    CHECK_INT(count, n);
    return count;
}

static void crates_on_a_slab(void)
{
    soup s = {0};
    uint32_t slab = box(&s, 0, -0.2f, 0, 4, 0, 2);
    uint32_t a = box(&s, 0.5f, 0, 0.5f, 1.5f, 1, 1.5f);
    uint32_t b = box(&s, 1.5f, 0, 0.5f, 2.5f, 1, 1.5f);
    uint8_t hidden[256], again[256], first[256];
    CHECK_INT(find(&s, NULL, 1, hidden), 8);
    memcpy(first, hidden, s.nt);
    for (uint32_t f = 0; f < s.nt; f++) {
        int expect = f == a || f == a + 1 || f == b || f == b + 1 /* bottoms on the slab */
                     || f == a + 10 || f == a + 11 /* a's +x side against b */
                     || f == b + 8 || f == b + 9;  /* b's -x side against a */
        CHECK_INT(hidden[f], expect);
    }
    CHECK_INT(hidden[slab + 2] + hidden[slab + 3], 0); /* the slab's top is larger than what covers it */
    CHECK_INT(find(&s, NULL, 4, again), 8);
    CHECK(memcmp(hidden, again, s.nt) == 0);

    /* skipped triangles are neither hidden nor count as covering: b's side left out leaves a's seen */
    uint8_t skip[256] = {0};
    skip[b + 8] = skip[b + 9] = 1;
    CHECK_INT(find(&s, skip, 2, hidden), 4);
    CHECK_INT(hidden[a + 10] + hidden[a + 11] + hidden[b + 8] + hidden[b + 9], 0);

    /* far from the origin (a level's corner at 10 km, its float positions 1 mm apart): the same
     * faces */
    for (uint32_t v = 0; v < s.nv; v++) {
        s.pos[3 * v] += 10000.0f;
        s.pos[3 * v + 2] -= 10000.0f;
    }
    CHECK_INT(find(&s, NULL, 2, again), 8);
    CHECK(memcmp(first, again, s.nt) == 0);
}

static void box_on_a_plane(void)
{
    soup s = {0};
    plane_up(&s, -2, -2, 2, 2, 0);
    uint32_t cube = box(&s, 0, 0, 0, 1, 1, 1);
    uint8_t hidden[256];
    /* the box's bottom bounds its solid and rests on the plane: hidden; the plane is larger */
    CHECK_INT(find(&s, NULL, 2, hidden), 2);
    CHECK_INT(hidden[cube] + hidden[cube + 1], 2);

    soup up = {0}; /* the same box half a unit above the plane: nothing touches */
    plane_up(&up, -2, -2, 2, 2, 0);
    box(&up, 0, 0.5f, 0, 1, 1.5f, 1);
    CHECK_INT(find(&up, NULL, 2, hidden), 0);

    /* on a plane smaller than its bottom: part of the bottom can be seen from below; the plane,
     * pressed into the box, cannot */
    soup small = {0};
    uint32_t under = plane_up(&small, 0.25f, 0.25f, 0.75f, 0.75f, 0);
    cube = box(&small, 0, 0, 0, 1, 1, 1);
    CHECK_INT(find(&small, NULL, 2, hidden), 2);
    CHECK_INT(hidden[under] + hidden[under + 1], 2);
    CHECK_INT(hidden[cube] + hidden[cube + 1], 0);
}

static void two_sided_card(void)
{
    soup s = {0};
    float a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {1, 1, 0}, d[3] = {0, 1, 0};
    quad(&s, a, b, c, d); /* facing +z */
    quad(&s, a, d, c, b); /* the same square facing -z */
    uint8_t hidden[256];
    CHECK_INT(find(&s, NULL, 2, hidden), 0);
    /* in a closed room (walls facing in, 10 units across) the card is still seen from both sides */
    soup room = s;
    uint32_t walls = box(&room, -5, -5, -5, 5, 5, 5);
    for (uint32_t f = walls; f < room.nt; f++) { /* turn the box's faces inward */
        uint32_t t = room.idx[3 * f + 1];
        room.idx[3 * f + 1] = room.idx[3 * f + 2];
        room.idx[3 * f + 2] = t;
    }
    CHECK_INT(find(&room, NULL, 2, hidden), 0);
}

int main(void)
{
    crates_on_a_slab();
    box_on_a_plane();
    two_sided_card();
    return check_failures();
}
