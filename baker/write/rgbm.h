/*
 * RGBM lightmaps (output.formats rgbm): an 8-bit RGBA PNG for targets without HDR textures,
 * as Unity and Unreal's Lightmass ship them, with the range stated in the glTF. Per texel, v
 * the lightmap value (3 channels) and R the range:
 *   x = sqrt(min(v / R, 1)),  a = ceil(255 max(x)) / 255,  rgb = round(255 x / a) / 255
 * decoded as v = R (rgb a)^2. The square root (gamma 2) spends the 8 bits evenly over
 * relative precision: every channel decodes within 1% of the texel's largest channel for
 * texels from R / 10^5 to R (write/rgbm.c). Values above R are clamped and counted.
 */
#ifndef LMBAKE_RGBM_H
#define LMBAKE_RGBM_H

#include <lmbake/lmbake.h>

/* The formula as written into the glTF, next to the range. */
#define LMB_RGBM_DECODE "v = range * (rgb * a)^2, rgb and a in [0, 1], linear (not sRGB)"

/* The range of output.rgbm_range `range` (0 = auto): as given, or the smallest power of two
 * at or above the largest channel of a valid texel (1 when every texel is 0). */
double lmb_rgbm_range(double range, const float *rgb, const uint8_t *valid, size_t texels);

/* rgbm := 4 bytes per texel of rgb (3 floats per texel) at `range`; returns the valid texels
 * (valid[i] == LMB_TEXEL_VALID) with a channel above the range, which are clamped. */
uint64_t lmb_rgbm_encode(const float *rgb, const uint8_t *valid, size_t texels, double range, uint8_t *rgbm);

/* One texel back (for tests). */
void lmb_rgbm_decode(const uint8_t rgbm[4], double range, double out[3]);

#endif
