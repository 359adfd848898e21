/*
 * The OpenImageIO adapter as a module (CMake option LMB_IMAGES_MODULE, on by default): the
 * adapter (image_adapter.cpp) is built into liblmbake-images.so, and image_module.c loads it
 * with dlopen the first time an image is read or written. Linking OpenImageIO into lmbake
 * loads its ~270 shared libraries (OpenCV, ffmpeg, GDAL, ... through Debian's build) at every
 * start: 0.4 s and 130 MB before main, in every process (`inspect`, each farm step, each bake
 * the watch starts), while only image reading and writing need them (docs/layout.md).
 *
 * The module exports one symbol, lmb_images_module_api, the table below; everything else in
 * it is hidden, so its functions never bind to the binary's forwarders of the same names.
 */
#ifndef LMBAKE_IMAGE_MODULE_H
#define LMBAKE_IMAGE_MODULE_H

#include "image_adapter.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Bumped whenever the table or a signature in image_adapter.h changes: a module from another
 * build is refused by name rather than called through the wrong types. */
#define LMB_IMAGE_API_VERSION 2u

typedef struct lmb_image_api {
    uint32_t version; /* LMB_IMAGE_API_VERSION of the module's build */
    lmb_status (*write_u8)(const char *, uint32_t, uint32_t, uint32_t, const uint8_t *, lmb_error *);
    lmb_status (*write_f32)(const char *, uint32_t, uint32_t, uint32_t, const float *, lmb_error *);
    lmb_status (*size)(const char *, const uint8_t *, size_t, uint32_t *, uint32_t *, lmb_error *);
    lmb_status (*read_rgb)(const char *, const uint8_t *, size_t, uint32_t *, uint32_t *, float **, lmb_error *);
    lmb_status (*rows_open)(const char *, const uint8_t *, size_t, lmb_image_rows **, uint32_t *, uint32_t *,
                            lmb_error *);
    lmb_status (*rows_read)(lmb_image_rows *, uint32_t, uint32_t, float *, lmb_error *);
    int (*rows_is_u8)(const lmb_image_rows *);
    lmb_status (*rows_read_u8)(lmb_image_rows *, uint32_t, uint32_t, uint8_t *, lmb_error *);
    void (*rows_close)(lmb_image_rows *);
    lmb_status (*read_alpha)(const char *, const uint8_t *, size_t, uint32_t, uint32_t *, uint32_t *, float **,
                             lmb_error *);
} lmb_image_api;

/* The module's one exported symbol (its name as a string for dlsym). */
#define LMB_IMAGE_API_SYMBOL "lmb_images_module_api"
const lmb_image_api *lmb_images_module_api(void);

#ifdef __cplusplus
}
#endif

#endif
