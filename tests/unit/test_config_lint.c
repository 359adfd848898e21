/*
 * Config lint tests: a key another key switches off is warned of with both names; sky.image
 * alone means intensity 1 (the map's own radiance); the image's path is checked even when the
 * sky is off.
 */
#include "check.h"
#include "config_parse.h"

#include <lmbake/lmbake.h>

#include <stdio.h>

/* Warnings collected by a test's log. */
typedef struct collected {
    char text[4096];
    int count;
} collected;

static void collect(void *user, const char *message)
{
    collected *c = user;
    size_t n = strlen(c->text);
    snprintf(c->text + n, sizeof c->text - n, "%s\n", message);
    c->count++;
}

/* Keys another key switches off are warned of with both names; sky.image alone means
 * intensity 1 (the map's own radiance); its path is checked even when the sky is off. */
static void test_lint(void)
{
    lmb_config c;
    lmb_error err;
    collected got = {"", 0};
    lmb_log log = {collect, &got, NULL};
    CHECK_INT(parse("sky: {image: sky.hdr}\n", &c, &err), LMB_OK);
    CHECK_NEAR(c.sky_intensity, 1, 0);
    CHECK_INT(parse("sky: {image: sky.hdr, intensity: 300}\n", &c, &err), LMB_OK);
    CHECK_NEAR(c.sky_intensity, 300, 0);
    CHECK_INT(parse("sky: {color: [1, 0.5, 0.5]}\n", &c, &err), LMB_OK);
    CHECK_NEAR(c.sky_intensity, 0, 0); /* a colour alone is no sky */

    /* defaults: nothing to say */
    lmb_config_default(&c);
    CHECK_INT(lmb_config_lint(&c, &log, &err), LMB_OK);
    CHECK_INT(got.count, 0);

    CHECK_INT(parse("sky: {color: [1, 0.5, 0.5], rotation: 90, ground_color: [0.1, 0.1, 0.1]}\n"
                    "output: {ktx2_format: rgba16f, rgbm_range: 8, directional: false}\n"
                    "bounces: 3\nbounces_auto: {tail: 0.1}\n"
                    "samples: {adaptive: false, noise: 0.02, directional: 64}\n"
                    "gather: {method: cosine, amis_weights: balance, guide_stride: 0, lobes: 3}\n",
                    &c, &err), LMB_OK);
    CHECK_INT(lmb_config_lint(&c, &log, &err), LMB_OK);
    CHECK_CONTAINS(got.text, "config: key 'sky.color' has no effect: there is no sky (sky.intensity is 0");
    CHECK_CONTAINS(got.text, "key 'sky.rotation' has no effect: there is no sky");
    CHECK_CONTAINS(got.text, "key 'sky.ground_color' has no effect");
    CHECK_CONTAINS(got.text, "key 'output.ktx2_format' has no effect: output.formats has no ktx2");
    CHECK_CONTAINS(got.text, "key 'output.rgbm_range' has no effect: output.formats has no rgbm");
    CHECK_CONTAINS(got.text, "key 'bounces_auto.tail' has no effect: bounces is a number, not auto");
    CHECK_CONTAINS(got.text, "key 'samples.noise' has no effect: samples.adaptive is false");
    CHECK_CONTAINS(got.text, "key 'samples.directional' has no effect: output.directional is false");
    CHECK_CONTAINS(got.text, "key 'gather.amis_weights' has no effect: gather.method is cosine");
    CHECK_CONTAINS(got.text, "key 'gather.lobes' has no effect: gather.guide_stride is 0");
    CHECK_INT(got.count, 10);

    /* a uniform sky: rotation turns nothing */
    got.text[0] = '\0';
    got.count = 0;
    CHECK_INT(parse("sky: {intensity: 1000, rotation: 45}\n", &c, &err), LMB_OK);
    CHECK_INT(lmb_config_lint(&c, &log, &err), LMB_OK);
    CHECK_CONTAINS(got.text, "key 'sky.rotation' has no effect: the sky is uniform (no sky.image to turn)");
    CHECK_INT(got.count, 1);

    /* an image the sky does not use is still checked, and its being unused is said */
    CHECK_INT(parse("sky: {image: /etc/passwd, intensity: 0}\n", &c, &err), LMB_OK);
    CHECK_INT(lmb_config_lint(&c, &log, &err), LMB_ERR_INPUT);
    CHECK_CONTAINS(err.message, "config: key 'sky.image': '/etc/passwd'");
    CHECK_INT(parse("sky: {image: missing.hdr, intensity: 0}\n", &c, &err), LMB_OK);
    CHECK_INT(lmb_config_lint(&c, &log, &err), LMB_ERR_INPUT);
    CHECK_CONTAINS(err.message, "key 'sky.image': 'missing.hdr' is not a file inside the config's folder");
}

int main(void)
{
    test_lint();
    return check_failures();
}
