/*
 * The files a staged bake passes between machines (docs/farm.md): the plan, each shard's part
 * of a step, each step's merged state. One container for all: a header saying what made the
 * file, the effective config's text, a body, and a SHA-256 of everything before it.
 *
 *   "LMBAKE\x01\n"   8 bytes magic
 *   u32 format, kind, step, shard, shards          (little-endian, as all numbers here)
 *   char version[32]                               lmbake's version, NUL-padded
 *   u8 input[32], config[32], plan[32]             SHA-256 of the input, the config text, the plan
 *   u64 config_length, body_length
 *   config text, body
 *   u8 sha256[32]                                  of every byte before it
 *
 * Reading checks the checksum first (a truncated or damaged file is named as such), then the
 * identity against what the reader expects, and names what differs: the lmbake version, the
 * input, the config (with the first key whose value differs), the plan, the step or the shard.
 * Writing goes to a temporary name beside the file and renames it into place, so a writer
 * killed half-way leaves no file, and two writers of the same part leave identical bytes.
 */
#ifndef LMBAKE_FARM_PART_FILE_H
#define LMBAKE_FARM_PART_FILE_H

#include <lmbake/lmbake.h>

#include <stddef.h>
#include <stdint.h>

/* 2: a step's state lists its parts by SHA-256 (format 1 copied their bytes) */
#define LMB_PART_FORMAT 2

typedef enum lmb_part_kind { LMB_PART_PLAN = 1, LMB_PART_SHARD = 2, LMB_PART_STATE = 3 } lmb_part_kind;

/* What made a file: compared field by field when it is read. */
typedef struct lmb_part_identity {
    char version[32];       /* LMB_VERSION_STRING */
    uint8_t input[32];      /* SHA-256 of the glTF file and its buffers (lmb_part_identity_make) */
    uint8_t config[32];     /* SHA-256 of config_text */
    uint8_t plan[32];       /* SHA-256 of the plan file's body; zero in the plan itself */
    char *config_text;      /* lmb_config_write of the config, threads left out; owned (free()) */
} lmb_part_identity;

typedef struct lmb_part_place {
    uint32_t kind, step, shard, shards; /* shard 0..shards-1; 0 of 1 for plans and states */
} lmb_part_place;

/* The identity of a bake of `scene` (loaded from its file) with cfg: lmbake's version, the
 * hash of the glTF file, every buffer as loaded and every image file it references, and of
 * the config's text with threads set to 0 (the thread count never changes a result). plan is
 * left zero. */
lmb_status lmb_part_identity_make(const lmb_scene *scene, const lmb_config *cfg, lmb_part_identity *id,
                                  lmb_error *err);
void lmb_part_identity_free(lmb_part_identity *id);

/* The identity's input hash with the glTF file's bytes given instead of read from scene->path
 * (then every buffer as loaded, every image file the glTF references, the config's sky image):
 * a light group's key hashes the file with the lights it does not hold taken out. */
void lmb_part_input_hash(const lmb_scene *scene, const lmb_config *cfg, const void *file, size_t size, uint8_t out[32]);

/* Writes path (via path.tmp-HOST-PID and rename). */
lmb_status lmb_part_write(const char *path, const lmb_part_identity *id, const lmb_part_place *place,
                          const void *body, size_t body_length, lmb_error *err);

/* A piece of a body written as it lies in memory (a step's header and its results). */
typedef struct lmb_part_piece {
    const void *data;
    size_t size;
} lmb_part_piece;

/* lmb_part_write of the body made of n pieces in turn, with no copy of them joined: a step's
 * results are megabytes, and a copy is as many fresh pages to fault in. */
lmb_status lmb_part_write_pieces(const char *path, const lmb_part_identity *id, const lmb_part_place *place,
                                 const lmb_part_piece *pieces, size_t n, lmb_error *err);

/* Reads path, checks its checksum, then its identity against *expect and its place against
 * *want (kind, step, shard, shards; shards 0 in want: any), naming the first difference.
 * On success *body (owned, free()) and *body_length hold the body and *got its place (the
 * body is moved to the start of the buffer the file was read into: no second buffer). */
lmb_status lmb_part_read(const char *path, const lmb_part_identity *expect, const lmb_part_place *want,
                         lmb_part_place *got, void **body, size_t *body_length, lmb_error *err);

/* A part file mapped read-only (lmb_part_map): the body lies in the page cache's own pages, with
 * no copy into a buffer of this process. */
typedef struct lmb_part_view {
    void *map;
    size_t map_length;
    const uint8_t *body;
    size_t body_length;
    const uint8_t *sum; /* the 32-byte SHA-256 that ends the file (a state lists its parts by it) */
} lmb_part_view;

/* lmb_part_read's checks, on the file mapped instead of read: what a merge reads megabytes of
 * and copies once, into the merged state. *view unmapped with lmb_part_unmap. */
lmb_status lmb_part_map(const char *path, const lmb_part_identity *expect, const lmb_part_place *want,
                        lmb_part_place *got, lmb_part_view *view, lmb_error *err);
void lmb_part_unmap(lmb_part_view *view);

/* SHA-256 of n bytes. */
void lmb_sha256(const void *data, size_t n, uint8_t out[32]);

/* SHA-256 of n bytes, as lowercase hex (65 bytes with the NUL). */
void lmb_sha256_hex(const void *data, size_t n, char hex[65]);

#endif
