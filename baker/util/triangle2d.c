/* Texel sub-samples and the closest point on a 2D triangle (see triangle2d.h). */
#include "triangle2d.h"

#include <float.h>
#include <math.h>

void lmb_texel_subsample(uint32_t k, uint32_t samples, double out[2])
{
    uint32_t sx = (uint32_t)ceil(sqrt((double)samples)), sy = (samples + sx - 1) / sx;
    out[0] = ((k % sx) + 0.5) / sx;
    out[1] = ((k / sx) + 0.5) / sy;
}

void lmb_triangle_box_2d(const double *uv, double box[4])
{
    box[0] = fmin(uv[0], fmin(uv[2], uv[4]));
    box[1] = fmin(uv[1], fmin(uv[3], uv[5]));
    box[2] = fmax(uv[0], fmax(uv[2], uv[4]));
    box[3] = fmax(uv[1], fmax(uv[3], uv[5]));
}

double lmb_closest_on_triangle_2d(const double *uv, const double p[2], double *b1, double *b2)
{
    double ax = uv[0], ay = uv[1];
    double e1x = uv[2] - ax, e1y = uv[3] - ay, e2x = uv[4] - ax, e2y = uv[5] - ay;
    double det = e1x * e2y - e2x * e1y;
    *b1 = *b2 = 0;
    if (!(fabs(det) > 0))
        return DBL_MAX; /* zero UV area: never a gather point */
    double px = p[0] - ax, py = p[1] - ay;
    double u = (px * e2y - e2x * py) / det, v = (e1x * py - px * e1y) / det;
    if (u >= 0 && v >= 0 && u + v <= 1) {
        *b1 = u;
        *b2 = v;
        return 0;
    }
    /* closest over the three edges, each as a parameter t along it */
    const double c[3][2] = {{uv[0], uv[1]}, {uv[2], uv[3]}, {uv[4], uv[5]}};
    double bestd = DBL_MAX;
    for (int k = 0; k < 3; k++) {
        const double *a = c[k], *b = c[(k + 1) % 3];
        double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
        double t = l2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2 : 0;
        t = t < 0 ? 0 : (t > 1 ? 1 : t);
        double qx = a[0] + t * dx - p[0], qy = a[1] + t * dy - p[1], d = sqrt(qx * qx + qy * qy);
        if (d < bestd) {
            bestd = d;
            double w[3] = {0, 0, 0};
            w[k] = 1 - t;
            w[(k + 1) % 3] = t;
            *b1 = w[1];
            *b2 = w[2];
        }
    }
    return bestd;
}
