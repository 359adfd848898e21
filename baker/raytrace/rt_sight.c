/* Two surface points in sight of each other (rt_sight.h). */
#include "rt_sight.h"

#include "util/frame.h"

#include <math.h>

int lmb_rt_in_sight(const lmb_rt *rt, const double a[3], const double ng_a[3], const double b[3], const double ng_b[3],
                    double lift)
{
    double c = ng_a[0] * ng_b[0] + ng_a[1] * ng_b[1] + ng_a[2] * ng_b[2];
    if (c < LMB_SIGHT_SAME_PLANE)
        return 1;
    double gap[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    lift = fmax(lift, LMB_SIGHT_LIFT_PER_DISTANCE * sqrt(gap[0] * gap[0] + gap[1] * gap[1] + gap[2] * gap[2]));
    double o[3], d[3];
    for (int k = 0; k < 3; k++) {
        o[k] = a[k] + lift * ng_a[k];
        d[k] = b[k] + lift * ng_b[k] - o[k];
    }
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0))
        return 1;
    for (int k = 0; k < 3; k++)
        d[k] /= len;
    lmb_rt_thread_init();
    return !lmb_rt_occluded(rt, o, d, 0.0, len);
}

uint32_t lmb_rt_sides(const lmb_rt *rt, const double p[3], const double ng[3], double lift, double reach,
                      lmb_rt_side *out, uint32_t most)
{
    double t1[3], t2[3], o[3];
    lmb_frame(ng, t1, t2);
    for (int k = 0; k < 3; k++)
        o[k] = p[k] + lift * ng[k];
    lmb_rt_hit hit[8];
    int got[8];
    for (int j = 0; j < 8; j++) {
        double w[3];
        lmb_rt_tangent_direction(t1, t2, j, w);
        got[j] = lmb_rt_intersect(rt, o, w, 0.0, reach, &hit[j]);
    }
    uint32_t n = 0;
    while (n < most) {
        int best = -1;
        for (int j = 0; j < 8; j++) {
            if (!got[j] || (best >= 0 && !(hit[j].t < hit[best].t)))
                continue;
            int same = 0; /* a face taken, or one turned less than 25 degrees from it */
            for (uint32_t q = 0; q < n; q++)
                same |= fabs(out[q].m[0] * hit[j].ng[0] + out[q].m[1] * hit[j].ng[1] + out[q].m[2] * hit[j].ng[2]) > 0.906;
            if (!same)
                best = j;
        }
        if (best < 0)
            break;
        const lmb_rt_hit *h = &hit[best];
        double side = (o[0] - h->p[0]) * h->ng[0] + (o[1] - h->p[1]) * h->ng[1] + (o[2] - h->p[2]) * h->ng[2];
        lmb_rt_side *s = &out[n++];
        for (int k = 0; k < 3; k++)
            s->m[k] = side < 0 ? -h->ng[k] : h->ng[k];
        s->d = s->m[0] * h->p[0] + s->m[1] * h->p[1] + s->m[2] * h->p[2];
        got[best] = 0;
    }
    return n;
}
