/*
 * Bake config tests: defaults, every key parsed to its value, each kind of error naming
 * file, line and key, the shipped example equal to the defaults, glob matching.
 * usage: test_config EXAMPLE_CONFIG
 */
#include "check.h"

#include <lmbake/lmbake.h>

static lmb_status parse(const char *text, lmb_config *cfg, lmb_error *err)
{
    lmb_config_default(cfg);
    err->message[0] = '\0';
    return lmb_config_parse("level.yaml", text, strlen(text), cfg, err);
}

static void test_defaults(void)
{
    lmb_config c;
    lmb_config_default(&c);
    CHECK_NEAR(c.texel_density, 8.0, 0);
    CHECK_INT(c.max_atlas_size, 1024);
    CHECK_INT(c.padding, 2);
    CHECK_INT(c.gather_rays, 256);
    CHECK_INT(c.amis_iterations, 4);
    CHECK_INT(c.gather_method, LMB_GATHER_AMIS_DEFENSIVE);
    CHECK_INT(c.output_formats, LMB_OUTPUT_EXR | LMB_OUTPUT_HDR | LMB_OUTPUT_PNG);
    CHECK_INT(c.include_count, 1);
    CHECK(!strcmp(c.include[0], "*"));
    CHECK(!strcmp(c.extras_key, "lightmap"));
}

static void test_full(void)
{
    const char *text = "texel_density: 12.5\n"
                       "density_overrides:\n"
                       "  - match: \"Floor*\"\n"
                       "    texel_density: 32\n"
                       "atlas: {max_size: 2048, padding: 4, keep_uv1: yes}\n"
                       "samples:\n"
                       "  texel: 1\n"
                       "  direct: 64\n"
                       "  gather: 1024\n"
                       "  amis_iterations: 8\n"
                       "bounces: 0\n"
                       "gather:\n"
                       "  method: cosine\n"
                       "  defensive: 0.25\n"
                       "seed: 9000000000\n"
                       "threads: 2\n"
                       "output:\n"
                       "  formats: [exr, png]\n"
                       "lightmap:\n"
                       "  include: [\"Room*\", \"Prop?\"]\n"
                       "  exclude: Sky\n"
                       "  extras_key: bake\n"
                       "lights: {intensity_scale: 0.5, emissive_scale: 2}\n";
    lmb_config c;
    lmb_error err;
    CHECK_INT(parse(text, &c, &err), LMB_OK);
    CHECK_NEAR(c.texel_density, 12.5, 0);
    CHECK_INT(c.density_override_count, 1);
    CHECK(!strcmp(c.density_overrides[0].pattern, "Floor*"));
    CHECK_NEAR(c.density_overrides[0].texel_density, 32, 0);
    CHECK_INT(c.max_atlas_size, 2048);
    CHECK_INT(c.padding, 4);
    CHECK_INT(c.keep_uv1, 1);
    CHECK_INT(c.texel_samples, 1);
    CHECK_INT(c.direct_samples, 64);
    CHECK_INT(c.gather_rays, 1024);
    CHECK_INT(c.amis_iterations, 8);
    CHECK_INT(c.bounces, 0);
    CHECK_INT(c.gather_method, LMB_GATHER_COSINE);
    CHECK_NEAR(c.defensive_fraction, 0.25, 0);
    CHECK(c.seed == 9000000000ULL);
    CHECK_INT(c.threads, 2);
    CHECK_INT(c.output_formats, LMB_OUTPUT_EXR | LMB_OUTPUT_PNG);
    CHECK_INT(c.include_count, 2);
    CHECK(!strcmp(c.include[1], "Prop?"));
    CHECK_INT(c.exclude_count, 1);
    CHECK(!strcmp(c.exclude[0], "Sky"));
    CHECK(!strcmp(c.extras_key, "bake"));
    CHECK_NEAR(c.light_intensity_scale, 0.5, 0);
    CHECK_NEAR(c.emissive_scale, 2, 0);
}

/* Each error: LMB_ERR_INPUT and a message with file:line and the key. */
static void expect_error(const char *text, const char *where, const char *what)
{
    lmb_config c;
    lmb_error err;
    CHECK_INT(parse(text, &c, &err), LMB_ERR_INPUT);
    CHECK_CONTAINS(err.message, where);
    CHECK_CONTAINS(err.message, what);
}

static void test_errors(void)
{
    expect_error("texel_density: 8\natlas:\n  maxsize: 512\n", "level.yaml:3:", "unknown key 'atlas.maxsize'");
    expect_error("atlas:\n  maxsize: 512\n", "level.yaml:2:", "max_size, padding, keep_uv1");
    expect_error("samples:\n  gather: lots\n", "level.yaml:2:", "key 'samples.gather': expected an integer in 1..1048576, got 'lots'");
    expect_error("samples:\n  gather: -3\n", "level.yaml:2:", "got '-3'");
    expect_error("samples:\n  gather: 2.5\n", "level.yaml:2:", "got '2.5'");
    expect_error("samples:\n  gather: 0\n", "level.yaml:2:", "got '0'");
    expect_error("texel_density: 0\n", "level.yaml:1:", "key 'texel_density': expected a number > 0");
    expect_error("texel_density: .nan\n", "level.yaml:1:", "key 'texel_density'");
    expect_error("\n\ngather:\n  method: fancy\n", "level.yaml:4:", "expected one of cosine, amis, amis_defensive, got 'fancy'");
    expect_error("atlas:\n  keep_uv1: maybe\n", "level.yaml:2:", "expected true or false, got 'maybe'");
    expect_error("output:\n  formats: [exr, tiff]\n", "level.yaml:2:", "expected exr, hdr or png, got 'tiff'");
    expect_error("output:\n  formats: []\n", "level.yaml:2:", "at least one output format");
    expect_error("seed: 1\nseed: 2\n", "level.yaml:2:", "key 'seed' is given twice");
    expect_error("samples: [1, 2]\n", "level.yaml:1:", "key 'samples': expected a mapping");
    expect_error("- a\n- b\n", "level.yaml:1:", "must be a mapping");
    expect_error("atlas:\n  padding: [1\n", "level.yaml:", "YAML syntax error");
    expect_error("density_overrides:\n  - match: Floor\n", "level.yaml:2:", "needs both match and texel_density");
    expect_error("density_overrides:\n  - match: Floor\n    size: 3\n", "level.yaml:3:", "unknown key 'density_overrides.size'");
    expect_error("bouncez: 3\n", "level.yaml:1:", "unknown key 'bouncez'");
    lmb_config c;
    lmb_error err;
    lmb_config_default(&c);
    CHECK_INT(lmb_config_load("/nonexistent/level.yaml", &c, &err), LMB_ERR_INPUT);
    CHECK_CONTAINS(err.message, "cannot open config '/nonexistent/level.yaml'");
}

static void test_empty_is_defaults(void)
{
    lmb_config c, d;
    lmb_error err;
    CHECK_INT(parse("# nothing but a comment\n", &c, &err), LMB_OK);
    lmb_config_default(&d);
    CHECK(memcmp(&c, &d, sizeof c) == 0);
}

/* The shipped, commented example holds exactly the defaults. */
static void test_example(const char *path)
{
    lmb_config c, d;
    lmb_error err = {LMB_OK, ""};
    lmb_config_default(&c);
    lmb_config_default(&d);
    CHECK_INT(lmb_config_load(path, &c, &err), LMB_OK);
    if (err.message[0])
        fprintf(stderr, "%s\n", err.message);
    CHECK(memcmp(&c, &d, sizeof c) == 0);
}

static void test_glob(void)
{
    CHECK(lmb_glob_match("*", ""));
    CHECK(lmb_glob_match("*", "Floor"));
    CHECK(lmb_glob_match("Floor*", "Floor_01"));
    CHECK(!lmb_glob_match("Floor*", "MainFloor"));
    CHECK(lmb_glob_match("?all", "Wall"));
    CHECK(!lmb_glob_match("?all", "all"));
    CHECK(lmb_glob_match("a*b*c", "a__b__b__c"));
    CHECK(!lmb_glob_match("a*b*c", "a__b__b__"));
    CHECK(lmb_glob_match("", ""));
    CHECK(!lmb_glob_match("", "x"));
    CHECK(lmb_glob_match("*Minus1", "DarkMinus1"));
}

int main(int argc, char **argv)
{
    test_defaults();
    test_full();
    test_errors();
    test_empty_is_defaults();
    if (argc > 1)
        test_example(argv[1]);
    else
        check_failed_count++;
    test_glob();
    return check_failures();
}
