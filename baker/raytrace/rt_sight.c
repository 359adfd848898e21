/* Two surface points in sight of each other (rt_sight.h). */
#include "rt_sight.h"

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
