/*
 * The sky (see sky.h). An equirectangular map of W x H pixels, piecewise constant: pixel
 * (i, j) covers phi in [2 pi i / W, 2 pi (i + 1) / W) - pi and theta in [pi j / H, pi (j + 1) / H),
 * a solid angle of (2 pi / W) (cos theta_j - cos theta_j+1). A uniform sky is a 1 x 2 map (sky
 * above the horizon, ground below).
 *
 * Sampling (pbrt-v4's piecewise-constant 2D distribution, in solid angle): a pixel is drawn
 * with probability proportional to luminance x solid angle, then a direction uniformly in its
 * solid angle (uniform in phi and in cos theta), so pdf(w) = P(pixel) / solid angle(pixel).
 * Irradiance: E = integral L(w) V(w) max(0, n.w) dw, estimated with n_m map samples and n_c
 * cosine samples and the balance heuristic (Veach 1997, eq. 9.12 with the balance weights):
 *   E ~ sum over all samples of L(w) V(w) (n.w) / (n_m pdf_map(w) + n_c (n.w) / pi).
 * Under a uniform sky cosine samples alone are exact up to visibility (L cos / (cos / pi) =
 * pi L), so no map samples are drawn there. Each distribution's samples are stratified along
 * their first dimension.
 */
#include "sky.h"

#include "util/sampling.h"
#include "load/gltf_adapter.h"
#include "load/config_file.h"
#include "util/frame.h"
#include "util/lmb_math.h"
#include "util/sh.h"
#include "image/image_adapter.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct lmb_sky {
    uint32_t w, h;
    float *radiance;    /* 3 per pixel, nits */
    double *row_cdf;    /* h + 1: marginal over rows */
    double *col_cdf;    /* h x (w + 1): conditional over columns in each row */
    double *row_weight; /* h: each row's total weight (luminance x solid angle) */
    double east[3], up[3], south[3];
    double rotation;    /* radians */
    int has_map;
};

void lmb_sky_free(lmb_sky *s)
{
    if (!s)
        return;
    free(s->radiance);
    free(s->row_cdf);
    free(s->col_cdf);
    free(s->row_weight);
    free(s);
}

int lmb_sky_has_map(const lmb_sky *s)
{
    return s->has_map;
}

/* cos theta at the top of row j */
static double row_cos(const lmb_sky *s, uint32_t j)
{
    return cos(LMB_PI * (double)j / (double)s->h);
}

static double pixel_solid_angle(const lmb_sky *s, uint32_t j)
{
    return 2 * LMB_PI / (double)s->w * (row_cos(s, j) - row_cos(s, j + 1));
}

/* The pixel a world direction looks at. */
static void pixel_of(const lmb_sky *s, const double w[3], uint32_t *i, uint32_t *j)
{
    double x = lmb_dot3(w, s->east), y = lmb_dot3(w, s->up), z = lmb_dot3(w, s->south);
    double phi = atan2(x, -z) - s->rotation; /* 0 looking along -south */
    phi -= 2 * LMB_PI * floor((phi + LMB_PI) / (2 * LMB_PI)); /* into [-pi, pi) */
    double u = 0.5 + phi / (2 * LMB_PI), v = acos(y < -1 ? -1 : y > 1 ? 1 : y) / LMB_PI;
    uint32_t col = (uint32_t)(u * s->w), row = (uint32_t)(v * s->h);
    *i = col < s->w ? col : s->w - 1;
    *j = row < s->h ? row : s->h - 1;
}

void lmb_sky_radiance(const lmb_sky *s, const double w[3], double out[3])
{
    uint32_t i, j;
    pixel_of(s, w, &i, &j);
    const float *p = s->radiance + 3 * ((size_t)j * s->w + i);
    for (int k = 0; k < 3; k++)
        out[k] = p[k];
}

double lmb_sky_pdf(const lmb_sky *s, const double w[3])
{
    uint32_t i, j;
    pixel_of(s, w, &i, &j);
    const double *cc = s->col_cdf + (size_t)j * (s->w + 1);
    double total = s->row_cdf[s->h];
    if (!(total > 0) || !(cc[s->w] > 0))
        return 0;
    double p_row = s->row_weight[j] / total, p_col = (cc[i + 1] - cc[i]) / cc[s->w];
    return p_row * p_col / pixel_solid_angle(s, j);
}

double lmb_sky_sample(const lmb_sky *s, double u1, double u2, double w[3])
{
    double total = s->row_cdf[s->h];
    uint32_t j = lmb_cdf_segment(s->row_cdf, s->h, u1 * total);
    const double *cc = s->col_cdf + (size_t)j * (s->w + 1);
    uint32_t i = lmb_cdf_segment(cc, s->w, u2 * cc[s->w]);
    /* where u fell inside the chosen segments: uniform in them */
    double f1 = (u1 * total - s->row_cdf[j]) / (s->row_cdf[j + 1] - s->row_cdf[j]);
    double f2 = (u2 * cc[s->w] - cc[i]) / (cc[i + 1] - cc[i]);
    f1 = f1 < 0 ? 0 : f1 > 1 ? 1 : f1;
    f2 = f2 < 0 ? 0 : f2 > 1 ? 1 : f2;
    double c0 = row_cos(s, j), c1 = row_cos(s, j + 1);
    double cos_t = c0 - f1 * (c0 - c1), sin_t = sqrt(fmax(0.0, 1 - cos_t * cos_t));
    double phi = 2 * LMB_PI * (((double)i + f2) / (double)s->w - 0.5) + s->rotation;
    double x = sin_t * sin(phi), y = cos_t, z = -sin_t * cos(phi);
    for (int k = 0; k < 3; k++)
        w[k] = x * s->east[k] + y * s->up[k] + z * s->south[k];
    double p_row = s->row_weight[j] / total, p_col = (cc[i + 1] - cc[i]) / cc[s->w];
    return p_row * p_col / pixel_solid_angle(s, j);
}

/* The map's sampling tables: weight = luminance x solid angle per pixel. */
static lmb_status build_tables(lmb_sky *s, lmb_error *err)
{
    s->row_cdf = malloc(((size_t)s->h + 1) * sizeof *s->row_cdf);
    s->row_weight = malloc(((size_t)s->h + 1) * sizeof *s->row_weight);
    s->col_cdf = malloc((size_t)s->h * (s->w + 1) * sizeof *s->col_cdf + 1);
    if (!s->row_cdf || !s->row_weight || !s->col_cdf)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "sky: out of memory for a %ux%u map's tables", s->w, s->h);
    s->row_cdf[0] = 0;
    for (uint32_t j = 0; j < s->h; j++) {
        double *cc = s->col_cdf + (size_t)j * (s->w + 1), omega = pixel_solid_angle(s, j);
        cc[0] = 0;
        for (uint32_t i = 0; i < s->w; i++) {
            const float *p = s->radiance + 3 * ((size_t)j * s->w + i);
            double rgb[3] = {p[0], p[1], p[2]};
            cc[i + 1] = cc[i] + lmb_luminance(rgb) * omega;
        }
        s->row_weight[j] = cc[s->w];
        s->row_cdf[j + 1] = s->row_cdf[j] + cc[s->w];
    }
    return LMB_OK;
}

/* The image at opt->image, inside the config's folder, as radiance times colour x intensity. */
static lmb_status read_image(const lmb_sky_options *opt, const lmb_log *log, lmb_sky *s, lmb_error *err)
{
    char real[4096];
    const char *cfg_name = opt->config_path[0] ? opt->config_path : "config";
    lmb_status st = lmb_config_file(opt->config_path, "sky.image", opt->image, real, sizeof real, err);
    if (st != LMB_OK)
        return st;
    float *rgb = NULL;
    lmb_error read_err = {LMB_OK, ""};
    if (lmb_image_read_rgb(real, NULL, 0, &s->w, &s->h, &rgb, &read_err) != LMB_OK)
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: key 'sky.image': %s", cfg_name, read_err.message);
    if (s->w != 2 * s->h) {
        free(rgb);
        return lmb_error_set(err, LMB_ERR_INPUT, "%s: key 'sky.image': '%s' is %ux%u: an equirectangular map is twice "
                             "as wide as it is high", cfg_name, opt->image, s->w, s->h);
    }
    uint64_t replaced = 0;
    for (size_t k = 0; k < 3 * (size_t)s->w * s->h; k++) {
        if (!(isfinite(rgb[k]) && rgb[k] >= 0)) {
            rgb[k] = 0;
            replaced++;
        }
        rgb[k] = (float)(rgb[k] * opt->color[k % 3] * opt->intensity);
    }
    if (replaced)
        lmb_warn(log, "sky.image '%s': %llu texel value(s) that were not finite or were negative replaced by 0",
                 opt->image, (unsigned long long)replaced);
    s->radiance = rgb;
    s->has_map = !opt->cosine_only;
    return LMB_OK;
}

/* east, up, south: up = sky.up; for up = +Y exactly +X, +Y, +Z. */
static void sky_frame(const lmb_sky_options *opt, lmb_sky *s)
{
    double len = sqrt(lmb_dot3(opt->up, opt->up)), ref[3] = {0, 0, 1};
    for (int k = 0; k < 3; k++)
        s->up[k] = opt->up[k] / len;
    if (fabs(lmb_dot3(ref, s->up)) > 0.99) {
        ref[0] = 1;
        ref[2] = 0;
    }
    double d = lmb_dot3(ref, s->up);
    for (int k = 0; k < 3; k++)
        s->south[k] = ref[k] - d * s->up[k];
    double sl = sqrt(lmb_dot3(s->south, s->south));
    for (int k = 0; k < 3; k++)
        s->south[k] /= sl;
    lmb_cross3(s->up, s->south, s->east);
}

/* v rotated by the inverse of unit quaternion q (x, y, z, w). */
static void rotate_inverse(const float q[4], const double v[3], double out[3])
{
    double x = -q[0], y = -q[1], z = -q[2], w = q[3];
    double t[3] = {2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])};
    out[0] = v[0] + w * t[0] + (y * t[2] - z * t[1]);
    out[1] = v[1] + w * t[1] + (z * t[0] - x * t[2]);
    out[2] = v[2] + w * t[2] + (x * t[1] - y * t[0]);
}

/*
 * EXT_lights_image_based's irradiance as a sky: its coefficients are the irradiance
 * E(n) = sum E_lm Y_lm(n); radiance is L_lm = E_lm / A_l with the cosine lobe's A_0 = pi,
 * A_1 = 2 pi / 3, A_2 = pi / 4 (Ramamoorthi and Hanrahan 2001, eq. 8), evaluated at each pixel
 * of a 64 x 32 map (after the light's rotation, times its intensity) and clamped at 0 (nine
 * coefficients can ring below zero).
 */
static lmb_status sky_from_ibl(const lmb_gltf_ibl *ibl, lmb_sky *s, lmb_error *err)
{
    s->w = 64;
    s->h = 32;
    s->radiance = malloc(3 * (size_t)s->w * s->h * sizeof *s->radiance);
    if (!s->radiance)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "sky: out of memory");
    for (uint32_t j = 0; j < s->h; j++)
        for (uint32_t i = 0; i < s->w; i++) {
            double theta = LMB_PI * (j + 0.5) / s->h, phi = 2 * LMB_PI * ((i + 0.5) / s->w - 0.5);
            double world[3] = {sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi)}, d[3], y[9];
            rotate_inverse(ibl->rotation, world, d);
            lmb_sh9(d[0], d[1], d[2], y);
            for (int c = 0; c < 3; c++) {
                double l = 0;
                for (int k = 0; k < 9; k++)
                    l += ibl->sh[k][c] / lmb_sh_cosine_band(k) * y[k];
                s->radiance[3 * ((size_t)j * s->w + i) + (size_t)c] = (float)(l > 0 ? l * ibl->intensity : 0);
            }
        }
    s->has_map = 1;
    return LMB_OK;
}

lmb_status lmb_sky_create(const lmb_sky_options *opt, const lmb_scene *scene, const lmb_log *log, lmb_sky **out,
                          lmb_error *err)
{
    *out = NULL;
    const lmb_gltf_ibl *ibl = scene && scene->doc ? &lmb_gltf_get_view(scene->doc)->ibl : NULL;
    if (!(opt->intensity > 0) && ibl && ibl->present) {
        if (!ibl->usable)
            return lmb_error_set(err, LMB_ERR_INPUT, "%s: EXT_lights_image_based: %s", scene->path, ibl->problem);
        lmb_sky *s = calloc(1, sizeof *s);
        if (!s)
            return lmb_error_set(err, LMB_ERR_INTERNAL, "sky: out of memory");
        s->east[0] = s->up[1] = s->south[2] = 1; /* the file's own axes */
        lmb_status st = sky_from_ibl(ibl, s, err);
        if (st == LMB_OK)
            st = build_tables(s, err);
        if (st != LMB_OK || !(s->row_cdf[s->h] > 0)) {
            lmb_sky_free(s);
            if (st == LMB_OK)
                lmb_warn(log, "%s: EXT_lights_image_based light '%s' is black: no sky light", scene->path, ibl->name);
            return st;
        }
        lmb_info(log, "sky: the file's EXT_lights_image_based light '%s': its irradiance (9 spherical-harmonic "
                 "coefficients) as a 64x32 radiance map x intensity %g; its specular images are not read", ibl->name,
                 ibl->intensity);
        *out = s;
        return LMB_OK;
    }
    if (!(opt->intensity > 0))
        return LMB_OK;
    if (ibl && ibl->present)
        lmb_info(log, "sky: from the config (sky.intensity %g); the file's EXT_lights_image_based light '%s' is not "
                 "used", opt->intensity, ibl->name);
    lmb_sky *s = calloc(1, sizeof *s);
    if (!s)
        return lmb_error_set(err, LMB_ERR_INTERNAL, "sky: out of memory");
    sky_frame(opt, s);
    s->rotation = opt->rotation * LMB_PI / 180.0;
    lmb_status st = LMB_OK;
    int ground = opt->ground[0] >= 0;
    if (opt->image[0]) {
        st = read_image(opt, log, s, err);
    } else {
        s->w = 1;
        s->h = 2;
        s->radiance = calloc(6, sizeof *s->radiance);
        if (!s->radiance)
            st = lmb_error_set(err, LMB_ERR_INTERNAL, "sky: out of memory");
        for (int k = 0; k < 3 && st == LMB_OK; k++)
            s->radiance[k] = (float)(opt->color[k] * opt->intensity);
    }
    /* the ground colour replaces the rows whose centre is below the horizon */
    for (uint32_t j = s->h / 2; ground && st == LMB_OK && j < s->h; j++)
        for (uint32_t i = 0; i < s->w; i++)
            for (int k = 0; k < 3; k++)
                s->radiance[3 * ((size_t)j * s->w + i) + (size_t)k] = (float)(opt->ground[k] * opt->intensity);
    if (st == LMB_OK)
        st = build_tables(s, err);
    if (st == LMB_OK && !(s->row_cdf[s->h] > 0)) {
        lmb_warn(log, "sky: intensity %g, but its colour%s is black everywhere: no sky light", opt->intensity,
                 opt->image[0] ? " times the image" : "");
        lmb_sky_free(s);
        return LMB_OK;
    }
    if (st != LMB_OK) {
        lmb_sky_free(s);
        return st;
    }
    if (opt->image[0])
        lmb_info(log, "sky: image '%s' (%ux%u, importance-sampled at full resolution) x colour x intensity %g nits%s",
                 opt->image, s->w, s->h, opt->intensity, ground ? ", ground colour below the horizon" : "");
    else
        lmb_info(log, "sky: uniform, colour [%g, %g, %g] x intensity %g nits, %s below the horizon", opt->color[0],
                 opt->color[1], opt->color[2], opt->intensity, ground ? "ground colour" : "black");
    *out = s;
    return LMB_OK;
}

uint32_t lmb_sky_irradiance(const lmb_sky *s, const lmb_rt *rt, const double o[3], const double n[3],
                            const double ng[3], double eps, uint32_t samples, lmb_rng *rng, double e[3], double dir[3])
{
    uint32_t n_map = s->has_map ? samples / 2 : 0, n_cos = samples - n_map, rays = 0;
    lmb_lobe cosine = {{n[0], n[1], n[2]}, 1.0};
    double t[3], b[3];
    lmb_frame(n, t, b);
    for (uint32_t k = 0; k < samples; k++) {
        /* stratified along u1 within each distribution: the map's rows are drawn through their
         * CDF, so a sun that holds a third of the map's weight gets a third of the map samples,
         * not a binomial share of them */
        double w[3], u1 = lmb_rng_next(rng), u2 = lmb_rng_next(rng);
        if (k < n_map) {
            lmb_sky_sample(s, ((double)k + u1) / n_map, u2, w);
        } else {
            u1 = ((double)(k - n_map) + u1) / n_cos;
            lmb_lobe_sample_in_frame(&cosine, t, b, u1, u2, w);
        }
        double c = lmb_dot3(n, w);
        if (c <= 0 || lmb_dot3(ng, w) <= 0)
            continue;
        double denom = (n_map ? n_map * lmb_sky_pdf(s, w) : 0) + n_cos * c / LMB_PI;
        if (!(denom > 0))
            continue;
        rays++;
        double pass[3];
        if (lmb_rt_transmittance(rt, o, w, eps, 1e300, pass))
            continue;
        double l[3];
        lmb_sky_radiance(s, w, l);
        double lum = 0;
        for (int ch = 0; ch < 3; ch++) {
            double v = l[ch] * c / denom * pass[ch];
            e[ch] += v;
            lum += v * (ch == 0 ? 0.2126 : ch == 1 ? 0.7152 : 0.0722);
        }
        for (int ch = 0; dir && ch < 3; ch++)
            dir[ch] += lum * w[ch];
    }
    return rays;
}
