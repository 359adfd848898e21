/*
 * Texture lookups (baker/load/textures.c): sampler wrap modes REPEAT, MIRRORED_REPEAT and
 * CLAMP_TO_EDGE per axis at coordinates outside [0, 1], nearest and bilinear filtering,
 * KHR_texture_transform's matrix against the extension's own worked examples, and the
 * diffuse albedo a material gives (metalness from the blue channel, spec-gloss, unlit, a
 * missing UV set). Textures are built in memory: no file is read.
 */
#include "check.h"

#include "load/textures.h"
#include "raytrace/rt_surface.h"

#include <math.h>
#include <stdlib.h>

#define PI 3.14159265358979323846

/* A 4 x 4 data texture whose texel (x, y) holds (x, y, 10 x + y). */
static float grid[4 * 4 * 3];

static lmb_texture grid_texture(int wrap_s, int wrap_t, int nearest)
{
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++) {
            grid[3 * (4 * y + x)] = (float)x;
            grid[3 * (4 * y + x) + 1] = (float)y;
            grid[3 * (4 * y + x) + 2] = (float)(10 * x + y);
        }
    lmb_texture t = {4, 4, {NULL, grid}, {0, 0, 0}, wrap_s, wrap_t, nearest, NULL, 0, 0, {NULL}, {0}, {0}};
    return t;
}

/* The texel column (x) nearest sampling reads at u, and the row at v. */
static void nearest_at(const lmb_texture *t, double u, double v, float *x, float *y)
{
    float out[3];
    lmb_texture_sample(t, LMB_TEX_DATA, u, v, out);
    *x = out[0];
    *y = out[1];
}

static void test_wrap_nearest(void)
{
    /* u -> texel index floor(4 u): -0.1 -> -1, 1.3 -> 5, -1.1 -> -5, 2.1 -> 8, 0.99 -> 3 */
    const double u[] = {-0.1, 1.3, -1.1, 2.1, 0.99, 0.0};
    const int repeat[] = {3, 1, 3, 0, 3, 0};
    const int mirror[] = {0, 2, 3, 0, 3, 0}; /* period 8: 0 1 2 3 3 2 1 0 */
    const int clamp[] = {0, 3, 0, 3, 3, 0};
    for (int k = 0; k < 6; k++) {
        float x, y;
        lmb_texture t = grid_texture(LMB_WRAP_REPEAT, LMB_WRAP_CLAMP_TO_EDGE, 1);
        nearest_at(&t, u[k], u[k], &x, &y);
        CHECK_INT((int)x, repeat[k]);
        CHECK_INT((int)y, clamp[k]);
        t = grid_texture(LMB_WRAP_MIRRORED_REPEAT, LMB_WRAP_REPEAT, 1);
        nearest_at(&t, u[k], u[k], &x, &y);
        CHECK_INT((int)x, mirror[k]);
        CHECK_INT((int)y, repeat[k]);
        t = grid_texture(LMB_WRAP_CLAMP_TO_EDGE, LMB_WRAP_MIRRORED_REPEAT, 1);
        nearest_at(&t, u[k], u[k], &x, &y);
        CHECK_INT((int)x, clamp[k]);
        CHECK_INT((int)y, mirror[k]);
    }
    /* far outside: no overflow, the same answer as one period away */
    float x, y;
    lmb_texture t = grid_texture(LMB_WRAP_REPEAT, LMB_WRAP_MIRRORED_REPEAT, 1);
    nearest_at(&t, 1e15 + 0.3, -1e15 - 0.3, &x, &y);
    CHECK(x >= 0 && x <= 3 && y >= 0 && y <= 3);
    /* whole periods away: as u = 0.3 (index 1) and v = -0.3 (index -2, mirrored to 1) */
    nearest_at(&t, 1e6 + 0.3, -1e6 - 0.3, &x, &y);
    CHECK_INT((int)x, 1);
    CHECK_INT((int)y, 1);
    t = grid_texture(LMB_WRAP_CLAMP_TO_EDGE, LMB_WRAP_CLAMP_TO_EDGE, 1);
    nearest_at(&t, -INFINITY, NAN, &x, &y); /* broken UVs read texel (0, 0) */
    CHECK_INT((int)x, 0);
    CHECK_INT((int)y, 0);
}

static void test_wrap_bilinear(void)
{
    /* u = 0: texel centres -0.5 and 0.5 -> columns -1 and 0 at half weight each */
    float out[3];
    lmb_texture t = grid_texture(LMB_WRAP_REPEAT, LMB_WRAP_REPEAT, 0);
    lmb_texture_sample(&t, LMB_TEX_DATA, 0.0, 0.375, out); /* v = 0.375: exactly row 1 */
    CHECK_NEAR(out[0], 1.5, 1e-6);                          /* (3 + 0) / 2 */
    CHECK_NEAR(out[1], 1.0, 1e-6);
    t = grid_texture(LMB_WRAP_CLAMP_TO_EDGE, LMB_WRAP_REPEAT, 0);
    lmb_texture_sample(&t, LMB_TEX_DATA, 0.0, 0.375, out);
    CHECK_NEAR(out[0], 0.0, 1e-6);
    lmb_texture_sample(&t, LMB_TEX_DATA, 1.0, 0.375, out); /* columns 3 and 4 -> 3, 3 */
    CHECK_NEAR(out[0], 3.0, 1e-6);
    t = grid_texture(LMB_WRAP_MIRRORED_REPEAT, LMB_WRAP_REPEAT, 0);
    lmb_texture_sample(&t, LMB_TEX_DATA, 0.0, 0.375, out); /* columns -1 -> 0 and 0 */
    CHECK_NEAR(out[0], 0.0, 1e-6);
    lmb_texture_sample(&t, LMB_TEX_DATA, -0.25, 0.375, out); /* x = -1.5: columns -2 -> 1 and -1 -> 0 */
    CHECK_NEAR(out[0], 0.5, 1e-6);
    lmb_texture_sample(&t, LMB_TEX_DATA, 1.25, 0.375, out); /* x = 4.5: columns 4 -> 3 and 5 -> 2 */
    CHECK_NEAR(out[0], 2.5, 1e-6);
    t = grid_texture(LMB_WRAP_REPEAT, LMB_WRAP_REPEAT, 0);
    lmb_texture_sample(&t, LMB_TEX_DATA, 1.25, 0.375, out); /* columns 4 -> 0 and 5 -> 1 */
    CHECK_NEAR(out[0], 0.5, 1e-6);
    lmb_texture_sample(&t, LMB_TEX_DATA, 0.3, 0.6, out); /* inside: plain bilinear, x = 0.7, y = 1.9 */
    CHECK_NEAR(out[0], 0.7, 1e-6);
    CHECK_NEAR(out[1], 1.9, 1e-6);
}

static void apply(const double m[6], double u, double v, double *tu, double *tv)
{
    lmb_texture_ref r = {0, 0, {m[0], m[1], m[2], m[3], m[4], m[5]}};
    lmb_texture_ref_apply(&r, u, v, tu, tv);
}

/* The extension's examples: "only the lower left quadrant of the source image, rotated
 * clockwise 90 degrees" and "inverts the T axis"; then T x R x S's order. */
static void test_transform(void)
{
    double m[6], u, v;
    const double off1[2] = {0, 1}, half[2] = {0.5, 0.5};
    lmb_texture_transform_matrix(off1, PI / 2, half, m);
    const double corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const double want[4][2] = {{0, 1}, {0, 0.5}, {0.5, 0.5}, {0.5, 1}};
    for (int k = 0; k < 4; k++) {
        apply(m, corners[k][0], corners[k][1], &u, &v);
        CHECK_NEAR(u, want[k][0], 1e-12);
        CHECK_NEAR(v, want[k][1], 1e-12);
    }
    const double flip[2] = {1, -1};
    lmb_texture_transform_matrix(off1, 0, flip, m);
    apply(m, 0.25, 0.1, &u, &v);
    CHECK_NEAR(u, 0.25, 1e-12);
    CHECK_NEAR(v, 0.9, 1e-12);
    /* scale first, then rotate (counter-clockwise in u-right, v-down space), then offset */
    const double off[2] = {0.6, 0.25}, sc[2] = {2, 0.5};
    lmb_texture_transform_matrix(off, PI / 3, sc, m);
    apply(m, 1, 0, &u, &v);
    CHECK_NEAR(u, 2 * cos(PI / 3) + 0.6, 1e-12);
    CHECK_NEAR(v, -2 * sin(PI / 3) + 0.25, 1e-12);
    apply(m, 0, 1, &u, &v);
    CHECK_NEAR(u, 0.5 * sin(PI / 3) + 0.6, 1e-12);
    CHECK_NEAR(v, 0.5 * cos(PI / 3) + 0.25, 1e-12);
}

/* One triangle with TEXCOORD_0 = (0.1, 0.1) at every corner and no TEXCOORD_1. */
static lmb_primitive one_triangle(float *uv0, uint32_t *idx)
{
    lmb_primitive p;
    memset(&p, 0, sizeof p);
    for (int k = 0; k < 6; k++)
        uv0[k] = 0.1f;
    idx[0] = 0;
    idx[1] = 1;
    idx[2] = 2;
    p.vertex_count = 3;
    p.uv0 = uv0;
    p.triangle_count = 1;
    p.indices = idx;
    return p;
}

static lmb_texture_ref ref(int32_t texture, int32_t texcoord)
{
    lmb_texture_ref r = {texture, texcoord, {1, 0, 0, 0, 1, 0}};
    return r;
}

static void test_albedo(void)
{
    float uv0[6], mr[3] = {0.9f, 0.8f, 0.25f}, colour[3] = {0.5f, 0.25f, 1.0f}, spec[3] = {0.2f, 0.5f, 0.1f};
    uint32_t idx[3];
    lmb_primitive pr = one_triangle(uv0, idx);
    lmb_texture tex[3] = {
        {1, 1, {NULL, mr}, {0, 0, 0}, LMB_WRAP_REPEAT, LMB_WRAP_REPEAT, 0, NULL, 0, 0, {NULL}, {0}, {0}},     /* metallicRoughness (data) */
        {1, 1, {colour, NULL}, {0, 0, 0}, LMB_WRAP_REPEAT, LMB_WRAP_REPEAT, 0, NULL, 0, 0, {NULL}, {0}, {0}}, /* base colour */
        {1, 1, {spec, NULL}, {0, 0, 0}, LMB_WRAP_REPEAT, LMB_WRAP_REPEAT, 0, NULL, 0, 0, {NULL}, {0}, {0}},   /* specular */
    };
    lmb_textures tx = {3, tex};
    lmb_material m;
    memset(&m, 0, sizeof m);
    m.base_color[0] = m.base_color[1] = m.base_color[2] = 0.8f;
    m.base_color_texture = ref(1, 0);
    m.metallic = 1.0f;
    m.metallic_texture = ref(0, 0);
    m.specular_texture = ref(-1, 0);
    m.emissive_texture = ref(-1, 0);
    double a[3];
    /* metalness = 1 x blue 0.25 (not red, not sRGB-decoded): diffuse share 0.75 */
    lmb_material_albedo(&tx, &m, &pr, 0, 0.2, 0.3, a);
    CHECK_NEAR(a[0], 0.8 * 0.5 * 0.75, 1e-6);
    CHECK_NEAR(a[1], 0.8 * 0.25 * 0.75, 1e-6);
    CHECK_NEAR(a[2], 0.8 * 1.0 * 0.75, 1e-6);
    /* the metallic texture read through TEXCOORD_1, which the primitive lacks: it counts as 1 */
    m.metallic_texture.texcoord = 1;
    lmb_material_albedo(&tx, &m, &pr, 0, 0.2, 0.3, a);
    CHECK_NEAR(a[0], 0.0, 1e-9);
    m.metallic = 0.5f;
    lmb_material_albedo(&tx, &m, &pr, 0, 0.2, 0.3, a);
    CHECK_NEAR(a[0], 0.8 * 0.5 * 0.5, 1e-6);
    /* spec-gloss: diffuse x (1 - max specular factor x texture) = (1 - max(0.2 x 1, 0.5 x 0.5, 0.1 x 1)) */
    m.spec_gloss = 1;
    m.specular[0] = 1.0f;
    m.specular[1] = 0.5f;
    m.specular[2] = 1.0f;
    m.specular_texture = ref(2, 0);
    lmb_material_albedo(&tx, &m, &pr, 0, 0.2, 0.3, a);
    CHECK_NEAR(a[0], 0.8 * 0.5 * 0.75, 1e-6);
    CHECK_NEAR(a[2], 0.8 * 1.0 * 0.75, 1e-6);
    /* unlit: no reflection at all */
    m.unlit = 1;
    lmb_material_albedo(&tx, &m, &pr, 0, 0.2, 0.3, a);
    CHECK(a[0] == 0 && a[1] == 0 && a[2] == 0);
}

/* COLOR_0 multiplies the base colour and its alpha (interpolated over the triangle); alpha is
 * factor x texture alpha x COLOR_0 alpha; transmission takes its share of the diffuse colour and
 * passes factor x texture red of the light, tinted by the base colour (raytrace/rt_surface.h). */
static void test_alpha_colour_transmission(void)
{
    float uv0[6], colour[3] = {0.5f, 0.25f, 1.0f}, alpha[1] = {0.4f}, red[3] = {0.5f, 0.0f, 0.0f};
    float rgba[12] = {1, 0.5f, 0, 1, 1, 0.5f, 0, 0.5f, 0, 0.5f, 1, 0};
    uint32_t idx[3];
    lmb_primitive pr = one_triangle(uv0, idx);
    pr.colors = rgba;
    lmb_texture tex[2] = {
        {1, 1, {colour, NULL}, {0, 0, 0}, LMB_WRAP_REPEAT, LMB_WRAP_REPEAT, 0, alpha, 1, 0, {NULL}, {0}, {0}}, /* base colour + alpha */
        {1, 1, {NULL, red}, {0, 0, 0}, LMB_WRAP_REPEAT, LMB_WRAP_REPEAT, 0, NULL, 0, 0, {NULL}, {0}, {0}},     /* transmission (data) */
    };
    lmb_textures tx = {2, tex};
    lmb_material m;
    memset(&m, 0, sizeof m);
    for (int k = 0; k < 4; k++)
        m.base_color[k] = 0.8f;
    m.base_color_texture = ref(0, 0);
    m.metallic_texture = ref(-1, 0);
    m.specular_texture = ref(-1, 0);
    m.emissive_texture = ref(-1, 0);
    m.transmission_texture = ref(-1, 0);
    /* barycentrics (0.5, 0.25, 0.25) of the corners: COLOR_0 = (0.75, 0.5, 0.25, 0.625) */
    double a[3], b0 = 0.5, b1 = 0.25, b2 = 0.25;
    lmb_material_albedo(&tx, &m, &pr, 0, b1, b2, a);
    CHECK_NEAR(a[0], 0.8 * 0.5 * (b0 * 1 + b1 * 1 + b2 * 0), 1e-6);
    CHECK_NEAR(a[1], 0.8 * 0.25 * 0.5, 1e-6);
    CHECK_NEAR(a[2], 0.8 * 1.0 * (b1 * 0 + b2 * 1), 1e-6);
    CHECK_NEAR(lmb_material_alpha(&tx, &m, &pr, 0, b1, b2), 0.8 * 0.4 * (b0 * 1 + b1 * 0.5 + b2 * 0), 1e-6);
    /* BLEND: coverage alpha, 1 - alpha passes */
    m.alpha_mode = LMB_ALPHA_BLEND;
    lmb_rt_surface sf = lmb_rt_surface_of(&m, &pr, &tx);
    double pass[3], cover, al = 0.8 * 0.4 * 0.625;
    lmb_rt_surface_pass(&sf, 0, b1, b2, 0, pass, &cover);
    CHECK_NEAR(cover, al, 1e-6);
    CHECK_NEAR(pass[1], 1 - al, 1e-6);
    /* MASK: cut below the cutoff (alpha 0.2 here), whole above it */
    m.alpha_mode = LMB_ALPHA_MASK;
    m.alpha_cutoff = 0.19f;
    sf = lmb_rt_surface_of(&m, &pr, &tx);
    CHECK(!lmb_rt_surface_cut(&sf, 0, b1, b2));
    m.alpha_cutoff = 0.21f;
    CHECK(lmb_rt_surface_cut(&sf, 0, b1, b2));
    /* transmission 0.5 x texture red 0.5: a quarter of the light passes, tinted by the base colour
     * (factor x texture x COLOR_0), and three quarters of the diffuse colour is left */
    m.alpha_mode = LMB_ALPHA_OPAQUE;
    m.transmission = 0.5f;
    m.transmission_texture = ref(1, 0);
    sf = lmb_rt_surface_of(&m, &pr, &tx);
    lmb_rt_surface_pass(&sf, 0, b1, b2, 0, pass, &cover);
    CHECK_NEAR(cover, 1.0, 1e-12);
    CHECK_NEAR(pass[0], 0.25 * 0.8 * 0.5 * 0.75, 1e-6);
    CHECK_NEAR(pass[1], 0.25 * 0.8 * 0.25 * 0.5, 1e-6);
    lmb_material_albedo(&tx, &m, &pr, 0, b1, b2, a);
    CHECK_NEAR(a[1], 0.75 * 0.8 * 0.25 * 0.5, 1e-6);
    /* a volume tints once, entering; leaving through a back face passes all */
    m.volume = 1;
    m.volume_tint[0] = m.volume_tint[1] = m.volume_tint[2] = 0.5f;
    lmb_rt_surface_pass(&sf, 0, b1, b2, 0, pass, &cover);
    CHECK_NEAR(pass[1], 0.5 * 0.25 * 0.8 * 0.25 * 0.5, 1e-6);
    lmb_rt_surface_pass(&sf, 0, b1, b2, 1, pass, &cover);
    CHECK_NEAR(pass[1], 1.0, 1e-12);
}

int main(void)
{
    test_alpha_colour_transmission();
    test_wrap_nearest();
    test_wrap_bilinear();
    test_transform();
    test_albedo();
    return check_failures();
}
