/*
 * The step runner's files (runner.h): the body of a part or a state, where they live in the
 * farm folder, how a step's items are cut into chunks, and the merge of a step's parts.
 * Internal to baker/steps/.
 */
#ifndef LMBAKE_STEPS_STEP_PARTS_H
#define LMBAKE_STEPS_STEP_PARTS_H

#include "runner.h"

/* The body of a part:
 *   u32 end, u32 name_length, u64 items, u64 chunks, counters[LMB_STEP_COUNTERS], u64 bytes,
 *   name, chunks x (u64 first, u64 last, u64 size), bytes     (little-endian hosts only, as
 * part_file.h). A part holds its shard's chunks of items (in item order, their bytes one after
 * the other). A step's state lists its parts by the SHA-256 that ends each part file: u32
 * shards, u32 0, shards x 32 bytes; reading a state merges the parts it lists. */
#define BODY_HEADER (2 * 4 + (3 + LMB_STEP_COUNTERS) * 8)

typedef struct step_chunk {
    uint64_t first, last, size;
} step_chunk;

typedef struct step_body {
    uint32_t end;
    uint64_t items, counters[LMB_STEP_COUNTERS];
    char name[96];
    uint64_t chunk_count;
    step_chunk *chunks;   /* encode: given; decode: malloc'd (free it) */
    const uint8_t *bytes;
    uint64_t size;
} step_body;

/* A step's items are cut into chunks of equal estimated cost, LMB_STEP_CHUNKS_PER_SHARD per
 * shard, dealt to the shards in turn (chunk c to shard c mod N): a shard's items are spread over
 * the whole step, so what the cost estimate misses (empty atlas rows, shadowed regions, records
 * that gather more) evens out across the shards. 32, not 8: at 8, the direct step of bevy's
 * Cornell box (149 bands) left one of 2 workers 1.6 s of 16 behind the other; at 32, 0.2 s. A
 * chunk costs a call and 24 bytes in the part. */
#define LMB_STEP_CHUNKS_PER_SHARD 32

/* Writes b as the body of a part file at path: its head (everything before the
 * results) and b->bytes as they lie, not joined into one copy first. */
lmb_status lmb_step_body_write(const char *path, const lmb_part_identity *id, const lmb_part_place *place,
                               const step_body *b, lmb_error *err);
/* b->chunks is malloc'd on success (free it); b->bytes points into body. */
lmb_status lmb_step_body_decode(const char *path, const uint8_t *body, size_t size, step_body *b, lmb_error *err);
void lmb_step_part_path(const char *dir, uint32_t step, uint32_t shard, uint32_t shards, char *out, size_t n);
void lmb_step_state_path(const char *dir, uint32_t step, char *out, size_t n);
uint64_t *lmb_step_chunk_cuts(const lmb_step_desc *d, uint32_t shards, uint64_t *count);
lmb_status lmb_step_write_end_marker(const char *dir, uint32_t step, lmb_error *err);
lmb_status lmb_step_merge_parts(const char *dir, const lmb_part_identity *id, uint32_t step, uint32_t shards,
                                int write_state, const uint8_t *sums, lmb_buf *out, uint64_t *counters,
                                lmb_merge_report *report, lmb_error *err);
/* Step `step`'s state: its shard count and the parts' SHA-256s (*sums: malloc'd, shards x 32). */
lmb_status lmb_step_state_read(const char *dir, const lmb_part_identity *id, uint32_t step, uint32_t *shards,
                               uint8_t **sums, lmb_error *err);

#endif
