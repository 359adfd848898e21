/*
 * Light groups' light kept between bakes (docs/light-groups.md#kept-between-bakes): with
 * `--layout-cache DIR` (what `lmbake preview --watch` passes), each light group's finished light
 * (its dilated, post-processed images, directions, probes' light, irradiance-cache records and
 * the texels' states) is written to DIR, under a key of everything that decides it: lmbake's
 * version, the glTF file with every buffer and image it reads (lmb_part_identity_make), the sky
 * image when the group holds the sky, the config's text with every group's scale set to 1 and
 * threads to 0, and the group's place and name. A later bake whose group has the same key reads
 * it back instead of lighting it: a change of the groups' scales relights at once, and the files
 * are those a bake without the cache writes, byte for byte (the same composition runs on the
 * same floats). The key holds of the glTF everything but the punctual lights the group does not
 * hold (group_key.c): another group's light edited or moved, or the intensity or colour of the
 * light a unit group holds, keeps it; any other change of the glTF or of a config key lights the
 * group again.
 */
#ifndef LMBAKE_GROUP_CACHE_H
#define LMBAKE_GROUP_CACHE_H

#include "pipeline/group_lighting.h"
#include "write/atlas_images.h"

/* Every group's key into keys[g] (the level's files hashed once for all). */
lmb_status lmb_group_cache_keys(const lmb_scene *scene, const lmb_config *cfg, const lmb_light_groups *groups,
                                uint8_t (*keys)[32], lmb_error *err);

/* Whether DIR holds a group's light under key (not read: lmb_group_cache_read checks it whole). */
int lmb_group_cache_has(const char *dir, const uint8_t key[32]);

/* Group g's light from DIR into gl (its images, directions, probes' light and records) and the
 * cache's texel states, texels and valid_texels: 1 when the file was there and whole, 0 when not
 * (a damaged one is said on the log). */
int lmb_group_cache_read(const char *dir, const uint8_t key[32], uint32_t g, lmb_group_light *gl, lmb_cache *cache,
                         uint32_t probes, uint64_t *texels, uint64_t *valid_texels, const lmb_log *log);

/* Group g's light (gl, after the post stage) and the cache's texel states into DIR; a file that
 * cannot be written is said on the log (the bake goes on). */
void lmb_group_cache_write(const char *dir, const uint8_t key[32], uint32_t g, const lmb_group_light *gl,
                           const lmb_cache *cache, uint32_t probes, uint64_t texels, uint64_t valid_texels,
                           const lmb_log *log);

/* Group g's own files of atlas a (paths[0..count): its .exr, .hdr and .ktx2 as
 * lmb_group_image_paths names them and lmb_write_group_images wrote them into the output's
 * staging folder) kept in DIR beside its
 * light: they are the same bytes at any scales and, for a group of one source, at any intensity
 * and colour of it (they hold its light at 1), and a later bake that reads the group back copies
 * them instead of encoding them again. A file that cannot be kept is said on the log. */
void lmb_group_cache_keep_files(const char *dir, const uint8_t key[32], uint32_t a, const char *const *paths,
                                uint32_t count, const lmb_log *log);

/* The files kept for that group and atlas written to paths: 1 when they were kept whole, 0 when
 * not (then they are to be encoded; a damaged file is said on the log). */
int lmb_group_cache_copy_files(const char *dir, const uint8_t key[32], uint32_t a, const char *const *paths,
                               uint32_t count, const lmb_log *log);

#endif
