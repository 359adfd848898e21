/*
 * The staged bake's file container (baker/steps/part_file.h): a part reads back as written;
 * a part made from another config, input, lmbake version or plan, or for another step or
 * shard, is refused with a message naming what differs (the config's key and both values);
 * truncated and damaged files are named as such; the thread count is not part of the identity;
 * writing leaves no temporary file.
 * usage: test_part_file SCENES_DIR WORKDIR
 */
#include "check.h"
#include "steps/part_file.h"
#include "util/file.h"

#include <dirent.h>
#include <lmbake/lmbake.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char *scenes, *work;

static lmb_scene *load(const char *rel)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", scenes, rel);
    lmb_scene *s = NULL;
    lmb_error err;
    if (lmb_scene_load(path, NULL, &s, NULL, &err) != LMB_OK) {
        fprintf(stderr, "cannot load %s: %s\n", path, err.message);
        exit(1);
    }
    return s;
}

/* Reads path against expect/want, read into memory and mapped (the merge's way): both must give
 * the same status, message and body. Returns the status and leaves the message in msg. */
static lmb_status read_as(const char *path, const lmb_part_identity *expect, const lmb_part_place *want, char *msg)
{
    lmb_part_place got, got_mapped;
    void *body = NULL;
    size_t n = 0;
    lmb_error err = {LMB_OK, ""}, err_mapped = {LMB_OK, ""};
    lmb_status st = lmb_part_read(path, expect, want, &got, &body, &n, &err);
    lmb_part_view view;
    lmb_status st_mapped = lmb_part_map(path, expect, want, &got_mapped, &view, &err_mapped);
    CHECK_INT(st_mapped, st);
    CHECK(!strcmp(err.message, err_mapped.message));
    if (st == LMB_OK && st_mapped == LMB_OK)
        CHECK(view.body_length == n && !memcmp(view.body, body, n) && !memcmp(&got, &got_mapped, sizeof got));
    lmb_part_unmap(&view);
    snprintf(msg, 512, "%s", err.message);
    free(body);
    return st;
}

/* The whole file; 1 on success. */
static int lmb_read_file_for_test(const char *path, char **out, size_t *size)
{
    lmb_error err;
    return lmb_read_file(path, "test", out, size, &err) == LMB_OK;
}

static int contains(const char *msg, const char *want)
{
    if (strstr(msg, want))
        return 1;
    fprintf(stderr, "message '%s' lacks '%s'\n", msg, want);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_part_file SCENES_DIR WORKDIR\n");
        return 2;
    }
    scenes = argv[1];
    work = argv[2];
    mkdir(work, 0777);
    lmb_scene *box = load("khr-Box/glTF-Binary/Box.glb"), *other = load("khr-Box/glTF-Embedded/Box.gltf");
    lmb_config cfg;
    lmb_config_default(&cfg);
    lmb_error err;
    lmb_part_identity id, id_threads, id_rays, id_other;
    CHECK_INT(lmb_part_identity_make(box, &cfg, &id, &err), LMB_OK);
    cfg.threads = 7;
    CHECK_INT(lmb_part_identity_make(box, &cfg, &id_threads, &err), LMB_OK);
    cfg.threads = 0;
    cfg.gather_rays = 512;
    CHECK_INT(lmb_part_identity_make(box, &cfg, &id_rays, &err), LMB_OK);
    cfg.gather_rays = 256;
    CHECK_INT(lmb_part_identity_make(other, &cfg, &id_other, &err), LMB_OK);
    /* threads never change a result: same identity */
    CHECK(!memcmp(id.config, id_threads.config, 32) && !strcmp(id.config_text, id_threads.config_text));
    CHECK(memcmp(id.config, id_rays.config, 32) != 0);
    CHECK(memcmp(id.input, id_other.input, 32) != 0); /* same mesh, other file */

    /* a part reads back as written */
    char path[4096], msg[512];
    snprintf(path, sizeof path, "%s/step3.2-of-4", work);
    const char body[] = "texels 123..456 of step 3";
    lmb_part_place place = {LMB_PART_SHARD, 3, 1, 4};
    CHECK_INT(lmb_part_write(path, &id, &place, body, sizeof body, &err), LMB_OK);
    lmb_part_place got;
    void *back = NULL;
    size_t n = 0;
    CHECK_INT(lmb_part_read(path, &id_threads, &place, &got, &back, &n, &err), LMB_OK);
    CHECK_INT(read_as(path, &id_threads, &place, msg), LMB_OK); /* mapped: the same body */
    CHECK_INT(n, sizeof body);
    CHECK(back && !memcmp(back, body, sizeof body));
    CHECK(got.kind == LMB_PART_SHARD && got.step == 3 && got.shard == 1 && got.shards == 4);
    free(back);
    /* written twice: the same bytes, and no temporary file left */
    char path2[4096];
    snprintf(path2, sizeof path2, "%s/again", work);
    CHECK_INT(lmb_part_write(path2, &id, &place, body, sizeof body, &err), LMB_OK);
    char *a, *b;
    size_t na, nb;
    CHECK_INT(lmb_read_file_for_test(path, &a, &na), 1);
    CHECK_INT(lmb_read_file_for_test(path2, &b, &nb), 1);
    CHECK(na == nb && !memcmp(a, b, na));
    free(b);
    DIR *d = opendir(work);
    struct dirent *e;
    int tmp = 0;
    while (d && (e = readdir(d)))
        tmp += strstr(e->d_name, ".tmp-") != NULL;
    if (d)
        closedir(d);
    CHECK_INT(tmp, 0);

    /* refusals, each naming what differs */
    CHECK_INT(read_as(path, &id_rays, &place, msg), LMB_ERR_INPUT);
    CHECK(contains(msg, "made with another config: config key 'samples.gather' is 256 there, 512 here"));
    CHECK(contains(msg, path));
    CHECK_INT(read_as(path, &id_other, &place, msg), LMB_ERR_INPUT);
    CHECK(contains(msg, "made from another input"));
    lmb_part_identity newer = id;
    snprintf(newer.version, sizeof newer.version, "9.9.9");
    CHECK_INT(read_as(path, &newer, &place, msg), LMB_ERR_INPUT);
    CHECK(contains(msg, "made by lmbake " LMB_VERSION_STRING "; this is lmbake 9.9.9"));
    lmb_part_identity plan = id;
    plan.plan[0] = 1;
    CHECK_INT(read_as(path, &plan, &place, msg), LMB_ERR_INPUT);
    CHECK(contains(msg, "belongs to another plan"));
    lmb_part_place step4 = {LMB_PART_SHARD, 4, 1, 4}, shard3 = {LMB_PART_SHARD, 3, 2, 4}, state = {LMB_PART_STATE, 3, 0, 0};
    CHECK_INT(read_as(path, &id, &step4, msg), LMB_ERR_INPUT);
    CHECK(contains(msg, "is of step 3, not step 4"));
    CHECK_INT(read_as(path, &id, &shard3, msg), LMB_ERR_INPUT);
    CHECK(contains(msg, "is shard 2/4, not 3/4"));
    CHECK_INT(read_as(path, &id, &state, msg), LMB_ERR_INPUT);
    CHECK(contains(msg, "is a shard file, not a state file"));

    /* truncated, damaged, not a part */
    snprintf(path2, sizeof path2, "%s/cut", work);
    FILE *f = fopen(path2, "wb");
    fwrite(a, 1, na - 5, f);
    fclose(f);
    CHECK_INT(read_as(path2, &id, &place, msg), LMB_ERR_INPUT);
    CHECK(contains(msg, "truncated or padded"));
    a[na - 40] ^= 1; /* a body byte */
    f = fopen(path2, "wb");
    fwrite(a, 1, na, f);
    fclose(f);
    CHECK_INT(read_as(path2, &id, &place, msg), LMB_ERR_INPUT);
    CHECK(contains(msg, "damaged: its SHA-256 does not match"));
    f = fopen(path2, "wb");
    fputs("{\"asset\": {}}", f);
    fclose(f);
    CHECK_INT(read_as(path2, &id, &place, msg), LMB_ERR_INPUT);
    CHECK(contains(msg, "not an lmbake plan or part file"));
    f = fopen(path2, "wb"); /* empty (a file mmap cannot map) */
    fclose(f);
    CHECK_INT(read_as(path2, &id, &place, msg), LMB_ERR_INPUT);
    CHECK(contains(msg, "not an lmbake plan or part file"));
    f = fopen(path2, "wb"); /* its magic and no more */
    fwrite(a, 1, 20, f);
    fclose(f);
    CHECK_INT(read_as(path2, &id, &place, msg), LMB_ERR_INPUT);
    CHECK(contains(msg, "truncated (shorter than its header)"));
    free(a);

    char hex[65];
    lmb_sha256_hex("abc", 3, hex); /* FIPS 180-2 example */
    CHECK(!strcmp(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"));

    lmb_part_identity_free(&id);
    lmb_part_identity_free(&id_threads);
    lmb_part_identity_free(&id_rays);
    lmb_part_identity_free(&id_other);
    lmb_scene_free(box);
    lmb_scene_free(other);
    return check_failures();
}
