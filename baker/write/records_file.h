/*
 * The irradiance cache's records of the final gather as a file beside the lightmaps, for the
 * preview's records view: <stem>-records.bin, per record 4 little-endian float32: x, y, z (world
 * position of its gather point, the glTF's units) and its reach (world units). The glTF names it
 * in asset.extras.lmbake.irradianceCacheRecords {uri, count, layout} (gltf_write.h).
 */
#ifndef LMBAKE_RECORDS_FILE_H
#define LMBAKE_RECORDS_FILE_H

#include <lmbake/lmbake.h>

#include "irradiance_cache/ic_pass.h"

/* Writes dir/name (name: lmb_records_file_name). */
lmb_status lmb_write_records(const char *dir, const char *name, const lmb_ic_points *points, lmb_error *err);

/* "<stem>-records.bin" into buf. */
void lmb_records_file_name(const char *stem, char *buf, size_t size);

#endif
