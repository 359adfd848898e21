/*
 * Vector helpers shared by the samplers: dot and cross products and an orthonormal tangent frame
 * around a unit normal (Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 2017:
 * branch-free, continuous except at n.z = -1).
 */
#ifndef LMBAKE_FRAME_H
#define LMBAKE_FRAME_H

static inline double lmb_dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void lmb_cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Two unit tangents t, b with (t, b, n) right-handed and orthonormal. */
static inline void lmb_frame(const double n[3], double t[3], double b[3])
{
    double s = n[2] >= 0 ? 1.0 : -1.0, a = -1.0 / (s + n[2]), c = n[0] * n[1] * a;
    t[0] = 1.0 + s * n[0] * n[0] * a;
    t[1] = s * c;
    t[2] = -s * n[0];
    b[0] = c;
    b[1] = s + n[1] * n[1] * a;
    b[2] = -n[1];
}

#endif
