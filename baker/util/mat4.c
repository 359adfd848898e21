/* 4x4 column-major matrix helpers (see mat4.h). */
#include "mat4.h"

#include <math.h>
#include <string.h>

void lmb_mat4_identity(double m[16])
{
    memset(m, 0, 16 * sizeof m[0]);
    m[0] = m[5] = m[10] = m[15] = 1.0;
}

void lmb_mat4_mul(const double a[16], const double b[16], double out[16])
{
    for (int c = 0; c < 4; c++)
        for (int r = 0; r < 4; r++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++)
                s += a[k * 4 + r] * b[c * 4 + k];
            out[c * 4 + r] = s;
        }
}

void lmb_mat4_from_trs(const double t[3], const double q[4], const double s[3], double out[16])
{
    double x = q[0], y = q[1], z = q[2], w = q[3];
    double n = sqrt(x * x + y * y + z * z + w * w);
    if (n > 0.0) {
        x /= n; y /= n; z /= n; w /= n;
    } else {
        x = y = z = 0.0; w = 1.0;
    }
    /* rotation matrix columns of the unit quaternion, each scaled by s */
    double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
                   2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                   2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
    lmb_mat4_identity(out);
    for (int c = 0; c < 3; c++)
        for (int row = 0; row < 3; row++)
            out[c * 4 + row] = r[c * 3 + row] * s[c];
    out[12] = t[0]; out[13] = t[1]; out[14] = t[2];
}

double lmb_mat4_det3(const double m[16])
{
    return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
           m[8] * (m[1] * m[6] - m[5] * m[2]);
}

void lmb_mat4_point(const double m[16], const double p[3], double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
}

void lmb_mat4_vector(const double m[16], const double v[3], double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = m[r] * v[0] + m[4 + r] * v[1] + m[8 + r] * v[2];
}

int lmb_mat4_is_finite(const double m[16])
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(m[i]))
            return 0;
    return 1;
}
