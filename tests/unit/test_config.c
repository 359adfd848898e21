/*
 * Bake config tests: defaults, every key parsed to its value, range edges, each kind of
 * error naming file, line and key, the shipped example equal to the defaults, glob matching.
 * (The warnings about keys other keys switch off: test_config_lint.c.)
 * usage: test_config EXAMPLE_CONFIG
 */
#define _POSIX_C_SOURCE 200809L /* mkstemp, for one test through a real file */

#include "check.h"
#include "config_parse.h"

#include <lmbake/lmbake.h>

#include <stdlib.h>
#include <unistd.h>

static int same_as_defaults(const lmb_config *c)
{
    lmb_config d;
    lmb_config_default(&d);
    return memcmp(c, &d, sizeof d) == 0;
}

static void test_defaults(void)
{
    lmb_config c;
    lmb_config_default(&c);
    CHECK_NEAR(c.texel_density, 0, 0); /* auto */
    CHECK(c.atlas_texels == 0);        /* auto: 0.6 x max_size^2 */
    CHECK(lmb_config_atlas_texels(&c) == 629145);
    CHECK_INT(c.density_override_count, 0);
    CHECK_INT(c.max_atlas_size, 4096);
    CHECK_INT(c.padding, 2);
    CHECK_INT(c.min_chart_texels, 4);
    CHECK_INT(c.keep_uv1, 0);
    CHECK_INT(c.texel_samples, 4);
    CHECK_INT(c.direct_samples, 16);
    CHECK_INT(c.gather_rays, 256);
    CHECK_INT(c.amis_iterations, 4);
    CHECK(c.bounces == LMB_AUTO);
    CHECK_INT(c.bounces_max, 32);
    CHECK_NEAR(c.bounces_tail, 0.05, 0);
    CHECK_INT(c.gather_method, LMB_GATHER_AMIS_DEFENSIVE);
    CHECK_NEAR(c.defensive_fraction, 0.1, 0);
    CHECK(c.seed == 1);
    CHECK_INT(c.threads, 0);
    CHECK_INT(c.output_formats, LMB_OUTPUT_EXR | LMB_OUTPUT_HDR | LMB_OUTPUT_PNG);
    CHECK_INT(c.include_count, 1);
    CHECK(!strcmp(c.include[0], "*"));
    CHECK_INT(c.exclude_count, 0);
    CHECK(!strcmp(c.extras_key, "lightmap"));
    CHECK_NEAR(c.light_intensity_scale, 1.0, 0);
    CHECK_NEAR(c.emissive_scale, 1.0, 0);
    CHECK(c.emission_sides == LMB_EMIT_FRONT);
    CHECK(c.directional == 1 && c.directional_rays == 32);
    CHECK(c.seam_stitch == 1 && c.firefly_spread == 1);
}

/* Every key set away from its default, in block and flow style. */
static void test_full(void)
{
    const char *text = "texel_density: 12.5\n"
                       "density_overrides:\n"
                       "  - match: \"Floor*\"\n"
                       "    texel_density: 32\n"
                       "  - {match: Prop?, texel_density: 0.5}\n"
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
                       "lights: {intensity_scale: 0.5, emissive_scale: 2, emission_sides: material}\n";
    lmb_config c;
    lmb_error err;
    CHECK_INT(parse(text, &c, &err), LMB_OK);
    CHECK_NEAR(c.texel_density, 12.5, 0);
    CHECK_INT(c.density_override_count, 2);
    CHECK(!strcmp(c.density_overrides[0].pattern, "Floor*"));
    CHECK_NEAR(c.density_overrides[0].texel_density, 32, 0);
    CHECK(!strcmp(c.density_overrides[1].pattern, "Prop?"));
    CHECK_NEAR(c.density_overrides[1].texel_density, 0.5, 0);
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
    CHECK(!strcmp(c.include[0], "Room*"));
    CHECK(!strcmp(c.include[1], "Prop?"));
    CHECK_INT(c.exclude_count, 1);
    CHECK(!strcmp(c.exclude[0], "Sky"));
    CHECK(!strcmp(c.extras_key, "bake"));
    CHECK_NEAR(c.light_intensity_scale, 0.5, 0);
    CHECK_NEAR(c.emissive_scale, 2, 0);
    CHECK(c.emission_sides == LMB_EMIT_MATERIAL);
}

/* Keys not named keep what cfg held; values at the edges of their ranges are accepted. */
static void expect_error(const char *text, const char *where, const char *what);

static void test_partial_and_edges(void)
{
    lmb_config c;
    lmb_error err;
    CHECK_INT(parse("atlas:\n  padding: 0\n", &c, &err), LMB_OK);
    CHECK_INT(c.padding, 0);
    CHECK_INT(c.max_atlas_size, 4096);
    CHECK(c.bounces == LMB_AUTO);

    /* auto and explicit values of the keys that take both */
    CHECK_INT(parse("texel_density: auto\nbounces: auto\natlas: {texels: auto}\n", &c, &err), LMB_OK);
    CHECK_NEAR(c.texel_density, 0, 0);
    CHECK(c.bounces == LMB_AUTO);
    CHECK(c.atlas_texels == 0);
    CHECK_INT(parse("texel_density: 12\nbounces: 3\natlas: {texels: 2000000, max_size: 2048}\n"
                    "bounces_auto: {max: 8, tail: 0.1}\n", &c, &err), LMB_OK);
    CHECK_NEAR(c.texel_density, 12, 0);
    CHECK_INT(c.bounces, 3);
    CHECK(c.atlas_texels == 2000000 && lmb_config_atlas_texels(&c) == 2000000);
    CHECK_INT(c.bounces_max, 8);
    CHECK_NEAR(c.bounces_tail, 0.1, 0);
    CHECK_INT(parse("atlas: {max_size: 2048}\n", &c, &err), LMB_OK);
    CHECK(lmb_config_atlas_texels(&c) == 629145);
    CHECK_INT(parse("atlas: {max_size: 512}\n", &c, &err), LMB_OK);
    CHECK(lmb_config_atlas_texels(&c) == (uint64_t)(0.6 * 512 * 512));
    expect_error("texel_density: 'auto'\n", "level.yaml:1: ",
                 "key 'texel_density': expected auto or a number > 0 and <= 100000, got 'auto'");
    expect_error("bounces: Auto\n", "level.yaml:1: ", "key 'bounces': expected auto or an integer in 0..64, got 'Auto'");
    expect_error("bounces: 65\n", "level.yaml:1: ", "expected auto or an integer in 0..64, got '65'");
    expect_error("atlas:\n  texels: 10\n", "level.yaml:2: ", "key 'atlas.texels': expected auto or an integer in 256..");
    expect_error("bounces_auto:\n  tail: 0\n", "level.yaml:2: ", "key 'bounces_auto.tail': expected a number > 0 and < 1");
    expect_error("bounces_auto:\n  max: 0\n", "level.yaml:2: ", "key 'bounces_auto.max': expected an integer in 1..64");

    CHECK_INT(parse("seed: 9223372036854775807\nthreads: 1024\ntexel_density: 100000\n", &c, &err), LMB_OK);
    CHECK(c.seed == 9223372036854775807ULL);
    CHECK_INT(c.threads, 1024);
    CHECK_NEAR(c.texel_density, 100000, 0);

    CHECK_INT(parse("gather: {method: amis, defensive: 0.9995}\nlights: {intensity_scale: 0}\n", &c, &err), LMB_OK);
    CHECK_INT(c.gather_method, LMB_GATHER_AMIS);
    CHECK_NEAR(c.defensive_fraction, 0.9995, 0);
    CHECK_NEAR(c.light_intensity_scale, 0, 0);

    CHECK_INT(c.amis_weights, LMB_AMIS_UNBIASED);
    CHECK_INT(c.bounce_rays, 64);
    CHECK_INT(c.bounce_rays_high, 16);
    CHECK_INT(parse("gather: {amis_weights: balance}\nsamples: {bounce: 7}\noutput: {formats: [exr, mask]}\n", &c, &err),
              LMB_OK);
    CHECK_INT(c.amis_weights, LMB_AMIS_BALANCE);
    CHECK_INT(c.bounce_rays, 7);
    CHECK_INT(c.output_formats, LMB_OUTPUT_EXR | LMB_OUTPUT_MASK);
    expect_error("gather:\n  amis_weights: paper\n", "level.yaml:2: ",
                 "key 'gather.amis_weights': expected one of unbiased, balance, got 'paper'");
    /* guided gathering (issue 12) */
    CHECK_INT(c.guide_stride, 8);
    CHECK_INT(c.guide_lobes, 2);
    CHECK_INT(c.direct_at_hits, 0);
    CHECK_INT(parse("gather: {guide_stride: 0, lobes: 3, direct_at_hits: true}\n", &c, &err), LMB_OK);
    CHECK_INT(c.guide_stride, 0);
    CHECK_INT(c.guide_lobes, 3);
    CHECK_INT(c.direct_at_hits, 1);
    expect_error("gather:\n  lobes: 4\n", "level.yaml:2: ", "key 'gather.lobes'");
    expect_error("gather: {guide_stride: 65}\n", "level.yaml:1: ", "key 'gather.guide_stride'");

    CHECK_INT(parse("atlas: {keep_uv1: On}\noutput: {formats: hdr}\nlightmap: {include: []}\n", &c, &err), LMB_OK);
    CHECK_INT(c.keep_uv1, 1);
    CHECK_INT(c.output_formats, LMB_OUTPUT_HDR);
    CHECK_INT(c.include_count, 0);

    CHECK_INT(parse("atlas: {keep_uv1: off}\nsamples: {gather: 1048576}\n", &c, &err), LMB_OK);
    CHECK_INT(c.keep_uv1, 0);
    CHECK_INT(c.gather_rays, 1048576);
}

/* Each error: LMB_ERR_INPUT, "level.yaml:LINE:" and the key and problem. */
static void expect_error(const char *text, const char *where, const char *what)
{
    lmb_config c;
    lmb_error err;
    CHECK_INT(parse(text, &c, &err), LMB_ERR_INPUT);
    CHECK_INT(err.status, LMB_ERR_INPUT);
    CHECK_CONTAINS(err.message, where);
    CHECK_CONTAINS(err.message, what);
}

static void test_value_errors(void)
{
    expect_error("samples:\n  gather: lots\n", "level.yaml:2: ",
                 "key 'samples.gather': expected an integer in 1..1048576, got 'lots'");
    expect_error("samples:\n  direct: 4\n  gather: -3\n", "level.yaml:3: ",
                 "key 'samples.gather': expected an integer in 1..1048576, got '-3'");
    expect_error("samples:\n  gather: 2.5\n", "level.yaml:2: ", "key 'samples.gather': expected an integer");
    expect_error("samples:\n  gather: 12abc\n", "level.yaml:2: ", "got '12abc'");
    expect_error("samples:\n  gather: 0\n", "level.yaml:2: ", "got '0'");
    expect_error("samples:\n  gather: 1048577\n", "level.yaml:2: ", "got '1048577'");
    expect_error("seed: 9223372036854775808\n", "level.yaml:1: ",
                 "key 'seed': expected an integer in 0..9223372036854775807, got '9223372036854775808'");
    expect_error("atlas:\n  max_size: 8\n", "level.yaml:2: ", "key 'atlas.max_size': expected an integer in 16..16384");
    expect_error("threads: [1]\n", "level.yaml:1: ", "key 'threads': expected an integer in 0..1024, got a list");
    expect_error("texel_density: 0\n", "level.yaml:1: ",
                 "key 'texel_density': expected auto or a number > 0 and <= 100000, got '0'");
    expect_error("texel_density: .nan\n", "level.yaml:1: ", "key 'texel_density': expected auto or a number");
    expect_error("texel_density: .inf\n", "level.yaml:1: ", "got '.inf'");
    expect_error("texel_density: 0x10\n", "level.yaml:1: ", "got '0x10'");
    expect_error("texel_density:\n", "level.yaml:1: ", "got an empty value");
    expect_error("gather:\n  defensive: 1\n", "level.yaml:2: ",
                 "key 'gather.defensive': expected a number >= 0 and < 1, got '1'");
    expect_error("lights:\n  emissive_scale: -0.5\n", "level.yaml:2: ", "key 'lights.emissive_scale'");
    expect_error("lights:\n  emission_sides: both\n", "level.yaml:2: ", "one of front, material");
    expect_error("\n\ngather:\n  method: fancy\n", "level.yaml:4: ",
                 "key 'gather.method': expected one of cosine, amis, amis_defensive, got 'fancy'");
    expect_error("atlas:\n  keep_uv1: maybe\n", "level.yaml:2: ",
                 "key 'atlas.keep_uv1': expected true or false, got 'maybe'");
    expect_error("output:\n  formats:\n    - exr\n    - tiff\n", "level.yaml:4: ",
                 "key 'output.formats': expected one of exr, hdr, png, mask, ktx2, rgbm, got 'tiff'");
    expect_error("output:\n  ktx2_format: bc7\n", "level.yaml:2: ",
                 "key 'output.ktx2_format': expected one of e5b9g9r9, b10g11r11, rgba16f, bc6h, astc_hdr, got 'bc7'");
    expect_error("output:\n  ktx2_supercompression: lz4\n", "level.yaml:2: ",
                 "key 'output.ktx2_supercompression': expected one of none, zstd, got 'lz4'");
    expect_error("output:\n  scale: lux\n", "level.yaml:2: ",
                 "key 'output.scale': expected one of irradiance, radiance, got 'lux'");
    expect_error("output:\n  rgbm_range: 0\n", "level.yaml:2: ",
                 "key 'output.rgbm_range': expected auto or a number > 0");
    expect_error("output: {rgbm_range: -8}\n", "level.yaml:1: ", "key 'output.rgbm_range'");
    expect_error("output:\n  formats: []\n", "level.yaml:2: ", "key 'output.formats': expected at least one of exr");
    expect_error("lightmap:\n  extras_key: \"\"\n", "level.yaml:2: ",
                 "key 'lightmap.extras_key': expected a non-empty string");
}

static void test_structure_errors(void)
{
    expect_error("texel_density: 8\natlas:\n  maxsize: 512\n", "level.yaml:3: ",
                 "unknown key 'atlas.maxsize' (known keys under 'atlas': texels, max_size, padding, keep_uv1, share_meshes, skip_hidden, min_chart_texels)");
    expect_error("bouncez: 3\n", "level.yaml:1: ",
                 "unknown key 'bouncez' (known keys: texel_density, density_overrides, atlas");
    expect_error("seed: 1\nthreads: 2\nseed: 2\n", "level.yaml:3: ", "key 'seed' is given twice (first on line 1)");
    expect_error("atlas:\n  padding: 1\n  padding: 2\n", "level.yaml:3: ", "key 'atlas.padding' is given twice");
    expect_error("atlas: {padding: 1}\natlas: {max_size: 64}\n", "level.yaml:2: ", "key 'atlas' is given twice");
    expect_error("samples: [1, 2]\n", "level.yaml:1: ", "key 'samples': expected a mapping of keys, got a list");
    expect_error("- a\n- b\n", "level.yaml:1: ", "the config must be a mapping of keys");
    expect_error("just words\n", "level.yaml:1: ", "must be a mapping of keys (key: value), got 'just words'");
    expect_error("a: 1\n---\nb: 2\n", "level.yaml:2: ", "a second YAML document");
    expect_error("density_overrides:\n  - match: Floor\n", "level.yaml:2: ",
                 "key 'density_overrides': each entry needs both match and texel_density");
    expect_error("density_overrides:\n  - match: Floor\n    size: 3\n", "level.yaml:3: ",
                 "unknown key 'density_overrides.size' (known keys under 'density_overrides': match, texel_density)");
    expect_error("density_overrides:\n  - {match: A, match: B, texel_density: 2}\n", "level.yaml:2: ",
                 "key 'density_overrides.match' is given twice");
    expect_error("density_overrides:\n  - match: A\n    texel_density: -1\n", "level.yaml:3: ",
                 "key 'density_overrides.texel_density': expected a number > 0");
}

static void test_yaml_errors(void)
{
    /* libyaml's own problem text, at the line where it found it */
    expect_error("atlas:\n  padding: [1\n  max_size: 2\n", "level.yaml:3: ",
                 "YAML syntax error: did not find expected ',' or ']'");
    expect_error("atlas:\n\tpadding: 1\n", "level.yaml:2: ", "YAML syntax error: found character that cannot start");
    expect_error("seed: 1\nbad: \xff\n", "level.yaml:2: ", "YAML syntax error: invalid leading UTF-8 octet");
    /* the two ways an unquoted glob goes wrong, with a hint */
    expect_error("lightmap:\n  include: *Floor\n", "level.yaml:2: ",
                 "undefined alias (put a glob that starts with * in quotes)");
    expect_error("lightmap:\n  exclude: [Sky, ?all]\n", "level.yaml:2: ",
                 "key 'lightmap.exclude': expected a glob, got a mapping (put a glob that starts with ? in quotes)");
}

/* More than LMB_MAX_PATTERNS globs: an error at the first entry too many. */
static void test_too_many_patterns(void)
{
    char text[LMB_MAX_PATTERNS * 16 + 64], *p = text;
    p += sprintf(p, "lightmap:\n  exclude:\n");
    for (int i = 0; i <= LMB_MAX_PATTERNS; i++)
        p += sprintf(p, "    - N%d\n", i);
    char where[32];
    snprintf(where, sizeof where, "level.yaml:%d: ", 3 + LMB_MAX_PATTERNS);
    expect_error(text, where, "key 'lightmap.exclude': expected at most 64 entries, got 65");

    char longname[LMB_PATTERN_LEN + 32];
    snprintf(longname, sizeof longname, "lightmap:\n  include: [%0*d]\n", LMB_PATTERN_LEN, 7);
    expect_error(longname, "level.yaml:2: ", "at most 127 characters, got '0000");
}

static void test_empty_is_defaults(void)
{
    static const char *const texts[] = {"", "# nothing but a comment\n\n# and another\n", "---\n", "~\n",
                                        "atlas:\nsamples: ~\n", "density_overrides:\nlightmap: {exclude: null}\n"};
    for (size_t i = 0; i < sizeof texts / sizeof *texts; i++) {
        lmb_config c;
        lmb_error err;
        CHECK_INT(parse(texts[i], &c, &err), LMB_OK);
        CHECK(same_as_defaults(&c));
    }
}

static void test_files(void)
{
    lmb_config c;
    lmb_error err;
    lmb_config_default(&c);
    CHECK_INT(lmb_config_load("/nonexistent/level.yaml", &c, &err), LMB_ERR_INPUT);
    CHECK_CONTAINS(err.message, "cannot open config '/nonexistent/level.yaml': No such file or directory");

    char path[] = "/tmp/lmbake-test-config-XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    if (fd < 0)
        return;
    const char *text = "# a level\nsamples:\n  texel: 300\n";
    CHECK(write(fd, text, strlen(text)) == (ssize_t)strlen(text));
    close(fd);
    CHECK_INT(lmb_config_load(path, &c, &err), LMB_ERR_INPUT);
    char where[160];
    snprintf(where, sizeof where, "%s:3: key 'samples.texel': expected an integer in 1..256, got '300'", path);
    CHECK_CONTAINS(err.message, where);
    unlink(path);
}

/* The shipped, commented example holds exactly the defaults. */
static void test_example(const char *path)
{
    lmb_config c;
    lmb_error err = {LMB_OK, ""};
    lmb_config_default(&c);
    CHECK_INT(lmb_config_load(path, &c, &err), LMB_OK);
    if (err.message[0])
        fprintf(stderr, "%s\n", err.message);
    CHECK(strcmp(c.config_path, path) == 0);
    memset(c.config_path, 0, sizeof c.config_path); /* where it was read from (sky.image is read beside it), not a key */
    CHECK(same_as_defaults(&c));
}

/* The written config reads back to the same struct (memcmp: defaults zero the padding), and
 * two configs that differ in one key differ in that key's line. */
static void round_trip(const char *text)
{
    lmb_config a, b;
    lmb_error err = {LMB_OK, ""};
    lmb_config_default(&a);
    CHECK_INT(lmb_config_parse("rt.yaml", text, strlen(text), &a, &err), LMB_OK);
    char written[16384];
    size_t n = lmb_config_write(&a, written, sizeof written);
    CHECK(n > 0 && n < sizeof written);
    CHECK_INT(strlen(written), n);
    lmb_config_default(&b);
    b.seed = 77; /* overwritten by the text: every key is there */
    b.gather_rays = 3;
    err.message[0] = 0;
    CHECK_INT(lmb_config_parse("written.yaml", written, n, &b, &err), LMB_OK);
    if (err.message[0])
        fprintf(stderr, "%s\n%s\n", err.message, written);
    CHECK(memcmp(&a, &b, sizeof a) == 0);
    char small[8];
    CHECK_INT(lmb_config_write(&a, small, sizeof small), n); /* the length it needs, truncated */
    CHECK_INT(strlen(small), 7);
}

static void test_write(void)
{
    round_trip("");
    round_trip("texel_density: 12.5\n"
               "density_overrides: [{match: \"Floor \\\"*\", texel_density: 32}, {match: P?, texel_density: 0.1}]\n"
               "atlas: {texels: 70000, max_size: 2048, padding: 4, keep_uv1: yes}\n"
               "samples: {gather: 1024, bounce_high: 0}\n"
               "bounces: 3\n"
               "gather: {method: amis, amis_weights: balance, defensive: 0.3333333333333333}\n"
               "irradiance_cache: {error: 0, records: per_pass}\n"
               "seed: 9000000000\n"
               "output: {formats: [png, exr, mask], directional: false}\n"
               "lightmap: {include: [\"Room*\", \"Prop?\"], exclude: [], extras_key: bake}\n"
               "lights: {intensity_scale: 0.1, emission_sides: material}\n"
               "seams: {stitch: false}\n");
    lmb_config a, b;
    lmb_config_default(&a);
    lmb_config_default(&b);
    b.gather_rays = 512;
    char ta[16384], tb[16384];
    lmb_config_write(&a, ta, sizeof ta);
    lmb_config_write(&b, tb, sizeof tb);
    CHECK(strstr(ta, "\n  gather: 256\n") && strstr(tb, "\n  gather: 512\n"));
}

static void test_glob(void)
{
    CHECK(lmb_glob_match("*", ""));
    CHECK(lmb_glob_match("*", "Floor"));
    CHECK(lmb_glob_match("Floor*", "Floor"));
    CHECK(lmb_glob_match("Floor*", "Floor_01"));
    CHECK(!lmb_glob_match("Floor*", "MainFloor"));
    CHECK(!lmb_glob_match("Floor*", "floor_01")); /* case-sensitive */
    CHECK(lmb_glob_match("?all", "Wall"));
    CHECK(lmb_glob_match("?all", "Hall"));
    CHECK(!lmb_glob_match("?all", "all"));
    CHECK(!lmb_glob_match("?all", "Walls"));
    CHECK(lmb_glob_match("a*b*c", "abc"));
    CHECK(lmb_glob_match("a*b*c", "a__b__b__c"));
    CHECK(!lmb_glob_match("a*b*c", "a__b__b__"));
    CHECK(!lmb_glob_match("a*b*c", "a__c__b"));
    CHECK(!lmb_glob_match("Door", "Window"));
    CHECK(lmb_glob_match("", ""));
    CHECK(!lmb_glob_match("", "x"));
    CHECK(lmb_glob_match("*Minus1", "DarkMinus1"));
    CHECK(lmb_glob_match("**?", "x"));
    CHECK(!lmb_glob_match("**?", ""));
    /* backtracking is linear per star: a pattern that is exponential for naive recursion */
    static char many_a[20001];
    memset(many_a, 'a', sizeof many_a - 1);
    CHECK(!lmb_glob_match("*a*a*a*a*a*a*a*a*a*a*a*a*b", many_a));
    CHECK(lmb_glob_match("*a*a*a*a*a*a*a*a*a*a*a*a*", many_a));
}

/* The engine-output keys: formats, KTX2 format, scale, RGBM range. */
static void test_output_keys(void)
{
    lmb_config c;
    lmb_error err;
    CHECK_INT(parse("output:\n  formats: [exr, ktx2, rgbm]\n  ktx2_format: b10g11r11\n  ktx2_supercompression: none\n"
                    "  scale: radiance\n  rgbm_range: 6\n", &c, &err), LMB_OK);
    CHECK_INT(c.output_formats, LMB_OUTPUT_EXR | LMB_OUTPUT_KTX2 | LMB_OUTPUT_RGBM);
    CHECK_INT(c.ktx2_format, 1);
    CHECK_INT(c.ktx2_zstd, 0);
    CHECK_INT(c.output_scale, LMB_SCALE_RADIANCE);
    CHECK_NEAR(c.rgbm_range, 6, 0);
    CHECK_INT(parse("output: {rgbm_range: auto}\n", &c, &err), LMB_OK);
    CHECK_NEAR(c.rgbm_range, 0, 0);
    CHECK_INT(c.output_scale, LMB_SCALE_IRRADIANCE); /* the default */
    CHECK_INT(c.shadowmask, 0);
    CHECK_INT(c.share_meshes, 0);
    CHECK_INT(parse("atlas: {share_meshes: true}\n", &c, &err), LMB_OK);
    CHECK_INT(c.share_meshes, 1);
    CHECK_INT(parse("output: {shadowmask: true}\nlights:\n  modes:\n    - {match: \"Sun*\", mode: indirect}\n"
                    "    - {match: Lamp, mode: realtime}\n", &c, &err), LMB_OK);
    CHECK_INT(c.shadowmask, 1);
    CHECK_INT(c.light_mode_count, 2);
    CHECK(strcmp(c.light_modes[0].pattern, "Sun*") == 0);
    CHECK_INT(c.light_modes[0].mode, LMB_LIGHT_INDIRECT);
    CHECK_INT(c.light_modes[1].mode, LMB_LIGHT_REALTIME);
    expect_error("lights:\n  modes:\n    - {match: Sun, mode: stationary}\n", "level.yaml:3: ",
                 "key 'lights.modes.mode': expected one of baked, indirect, realtime, got 'stationary'");
    expect_error("lights:\n  modes:\n    - {match: Sun}\n", "level.yaml:3: ",
                 "key 'lights.modes': each entry needs both match and mode");
    expect_error("lights: {modes: [indirect]}\n", "level.yaml:1: ", "key 'lights.modes': expected a mapping {match: GLOB");
    expect_error("output: {shadowmask: 4}\n", "level.yaml:1: ", "key 'output.shadowmask': expected true or false");
    lmb_light_mode m;
    CHECK_INT(lmb_light_mode_parse("indirect", &m), 0);
    CHECK_INT(m, LMB_LIGHT_INDIRECT);
    CHECK_INT(lmb_light_mode_parse("Indirect", &m), -1);
    CHECK(strcmp(lmb_light_mode_name(LMB_LIGHT_REALTIME), "realtime") == 0);
}

/* The sky, sun and materials keys: values, and the usual named errors for unknown keys and bad values. */
static void test_outdoor_keys(void)
{
    lmb_config c;
    lmb_error err;
    CHECK_INT(parse("sky:\n  intensity: 2000\n  color: [0.5, 0.6, 1]\n  ground_color: [0.2, 0.2, 0.1]\n"
                    "  image: maps/sky.exr\n  rotation: -90\n  up: [0, 0, 1]\n  samples: 32\n  sampling: cosine\n"
                    "lights: {sun_angle: 2}\n"
                    "materials:\n  default: {albedo: [0.7, 0.6, 0.5]}\n"
                    "  override: [{match: \"Wood*\", albedo: [0.4, 0.3, 0.2]}, {match: Lamp, emissive: [5, 4, 3]}]\n",
                    &c, &err), LMB_OK);
    CHECK_NEAR(c.sky_intensity, 2000, 0);
    CHECK_NEAR(c.sky_color[1], 0.6, 0);
    CHECK_NEAR(c.sky_ground[2], 0.1, 0);
    CHECK(strcmp(c.sky_image, "maps/sky.exr") == 0);
    CHECK_NEAR(c.sky_rotation, -90, 0);
    CHECK_NEAR(c.sky_up[2], 1, 0);
    CHECK_INT(c.sky_samples, 32);
    CHECK_INT(c.sky_cosine_only, 1);
    CHECK_NEAR(c.sun_angle, 2, 0);
    CHECK_NEAR(c.default_albedo[0], 0.7, 0);
    CHECK_INT(c.material_override_count, 2);
    CHECK(strcmp(c.material_overrides[0].pattern, "Wood*") == 0);
    CHECK_NEAR(c.material_overrides[0].albedo[2], 0.2, 0);
    CHECK(c.material_overrides[0].emissive[0] < 0); /* not given: keep the file's */
    CHECK(c.material_overrides[1].albedo[0] < 0);
    CHECK_NEAR(c.material_overrides[1].emissive[0], 5, 0);
    expect_error("sky:\n  colour: [1, 1, 1]\n", "level.yaml:2: ", "unknown key 'sky.colour'");
    expect_error("materials:\n  defaults: {albedo: [1, 1, 1]}\n", "level.yaml:2: ", "unknown key 'materials.defaults'");
    expect_error("lights:\n  sun_size: 1\n", "level.yaml:2: ", "unknown key 'lights.sun_size'");
    expect_error("sky: {color: [1, 1]}\n", "level.yaml:1: ", "key 'sky.color': expected [r, g, b]");
    expect_error("sky: {up: [0, 0, 0]}\n", "level.yaml:1: ", "key 'sky.up': expected [x, y, z], finite and not all 0");
    expect_error("materials: {default: {albedo: [2, 0, 0]}}\n", "level.yaml:1: ", "key 'materials.default.albedo'");
    expect_error("materials: {override: [{match: Wood}]}\n", "level.yaml:1: ",
                 "each entry needs match and at least one of albedo and emissive");
    expect_error("lights: {sun_angle: 45}\n", "level.yaml:1: ", "key 'lights.sun_angle': expected a number >= 0 and <= 30");
}

/* probes.*: values, volumes, and the named errors for a bad volume. */
static void test_probe_keys(void)
{
    lmb_config c;
    lmb_error err;
    lmb_config_default(&c);
    CHECK_INT(c.probes_auto, 1);
    CHECK_NEAR(c.probe_spacing, 0, 0);
    CHECK_INT(c.probe_rays, 512);
    CHECK_INT(c.probe_volume_count, 0);
    CHECK_INT(parse("probes:\n  auto: false\n  spacing: 2.5\n  rays: 256\n  volumes:\n"
                    "    - {min: [-1, 0, -2], max: [1, 2.5, 2], resolution: [4, 2, 8]}\n"
                    "    - {min: [0, 0, 0], max: [1, 1, 1], resolution: [1, 1, 1]}\n", &c, &err), LMB_OK);
    CHECK_INT(c.probes_auto, 0);
    CHECK_NEAR(c.probe_spacing, 2.5, 0);
    CHECK_INT(c.probe_rays, 256);
    CHECK_INT(c.probe_volume_count, 2);
    CHECK_NEAR(c.probe_volumes[0].min[2], -2, 0);
    CHECK_NEAR(c.probe_volumes[0].max[1], 2.5, 0);
    CHECK_INT(c.probe_volumes[0].resolution[2], 8);
    CHECK_INT(c.probe_volumes[1].resolution[0], 1);
    expect_error("probes: {spacing: 0}\n", "level.yaml:1: ", "key 'probes.spacing'");
    expect_error("probes: {spacing: -1}\n", "level.yaml:1: ", "key 'probes.spacing'");
    expect_error("probes:\n  volumes:\n    - {min: [0, 2, 0], max: [1, 1, 1], resolution: [2, 2, 2]}\n",
                 "level.yaml:3: ", "min 2 is not below max 1 on the y axis");
    expect_error("probes:\n  volumes:\n    - {min: [0, 0, 0], max: [1, 1, 1], resolution: [2, 0, 2]}\n",
                 "level.yaml:3: ", "key 'probes.volumes.resolution': expected [x, y, z], integers in 1..256");
    expect_error("probes:\n  volumes:\n    - {min: [0, 0, 0], max: [1, 1, 1], resolution: [2, 257, 2]}\n",
                 "level.yaml:3: ", "integers in 1..256");
    expect_error("probes:\n  volumes:\n    - {min: [0, 0, 0], max: [1, 1, 1]}\n", "level.yaml:3: ",
                 "each entry needs min, max and resolution");
    expect_error("probes:\n  volumes:\n    - {min: [0, .nan, 0], max: [1, 1, 1], resolution: [1, 1, 1]}\n",
                 "level.yaml:3: ", "key 'probes.volumes.min'");
}

int main(int argc, char **argv)
{
    test_defaults();
    test_full();
    test_partial_and_edges();
    test_value_errors();
    test_structure_errors();
    test_yaml_errors();
    test_too_many_patterns();
    test_empty_is_defaults();
    test_files();
    if (argc > 1) {
        test_example(argv[1]);
    } else {
        fprintf(stderr, "usage: test_config EXAMPLE_CONFIG\n");
        check_failed_count++;
    }
    test_glob();
    test_write();
    test_outdoor_keys();
    test_output_keys();
    test_probe_keys();
    return check_failures();
}
