/* Real spherical harmonics up to l = 2 (Sloan, "Stupid Spherical Harmonics Tricks", with glTF's
 * axes) and the clamped cosine's band factors A_l (Ramamoorthi and Hanrahan 2001, eq. 8: the
 * irradiance's coefficients are A_l times the radiance's). Order: (0,0) (1,-1) (1,0) (1,1)
 * (2,-2) (2,-1) (2,0) (2,1) (2,2). Shared by the sky (EXT_lights_image_based) and the probes. */
#ifndef LMBAKE_SH_H
#define LMBAKE_SH_H

static inline void lmb_sh9(double x, double y, double z, double out[9])
{
    out[0] = 0.282095;
    out[1] = 0.488603 * y;
    out[2] = 0.488603 * z;
    out[3] = 0.488603 * x;
    out[4] = 1.092548 * x * y;
    out[5] = 1.092548 * y * z;
    out[6] = 0.315392 * (3 * z * z - 1);
    out[7] = 1.092548 * x * z;
    out[8] = 0.546274 * (x * x - y * y);
}

/* A_l of coefficient k: pi, 2 pi / 3 (l = 1), pi / 4 (l = 2). */
static inline double lmb_sh_cosine_band(int k)
{
    const double pi = 3.14159265358979323846;
    return k == 0 ? pi : k < 4 ? 2 * pi / 3 : pi / 4;
}

#endif
