/*
 * image_adapter.h's functions when the adapter is a module (image_module.h): each forwards to
 * liblmbake-images.so, loaded on the first call. Looked for beside the running binary first
 * (an installed or copied lmbake with its module), then where this build put it
 * (LMB_IMAGES_MODULE_PATH: tests, tools and fuzz replays run from other folders of the build).
 * A module that is missing, or from another build, makes every image call fail with a message
 * that names the file looked for; nothing else in a run needs it (`inspect`, farm steps).
 */
#define _GNU_SOURCE
#include "image_module.h"
#include "image_native.h"

#include <dlfcn.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#ifndef LMB_IMAGES_MODULE_PATH
#error "LMB_IMAGES_MODULE_PATH: the build's liblmbake-images.so (CMakeLists.txt sets it)"
#endif
#define MODULE_NAME "liblmbake-images.so"

/* Process-wide and written once: the loaded module's table, or why it could not be loaded.
 * pthread_once makes the first image call from any thread load it; after that both are only
 * read (dlopen's own handle table is process state of the same kind). */
static pthread_once_t module_once = PTHREAD_ONCE_INIT;
static const lmb_image_api *module_api;
static char module_failure[768];

/* Opens `path` and checks its table: NULL and a reason in why (appended) when it cannot. */
static const lmb_image_api *open_module(const char *path, char *why, size_t why_size)
{
    size_t used = strlen(why);
    void *handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        snprintf(why + used, why_size - used, "%s%s", used ? "; " : "", dlerror());
        return NULL;
    }
    const lmb_image_api *(*get)(void) = NULL;
    *(void **)&get = dlsym(handle, LMB_IMAGE_API_SYMBOL);
    const lmb_image_api *api = get ? get() : NULL;
    if (!api || api->version != LMB_IMAGE_API_VERSION) {
        snprintf(why + used, why_size - used, "%s%s: %s", used ? "; " : "", path,
                 api ? "made by another build of lmbake (image API version differs)" : "not lmbake's image module");
        dlclose(handle);
        return NULL;
    }
    return api; /* kept open for the process's life */
}

static void load_module(void)
{
    char why[sizeof module_failure] = "";
    char beside[PATH_MAX + sizeof MODULE_NAME] = "";
    ssize_t n = readlink("/proc/self/exe", beside, PATH_MAX - 1);
    char *slash = n > 0 ? (beside[n] = '\0', strrchr(beside, '/')) : NULL;
    if (slash)
        strcpy(slash + 1, MODULE_NAME);
    else
        beside[0] = '\0';
    if (beside[0] && access(beside, F_OK) == 0)
        module_api = open_module(beside, why, sizeof why);
    if (!module_api && strcmp(beside, LMB_IMAGES_MODULE_PATH) != 0)
        module_api = open_module(LMB_IMAGES_MODULE_PATH, why, sizeof why);
    if (!module_api)
        snprintf(module_failure, sizeof module_failure,
                 "images: cannot load lmbake's image module (OpenImageIO adapter), looked for beside the lmbake "
                 "binary and at %s: %s",
                 LMB_IMAGES_MODULE_PATH, why);
}

/* The table, or NULL with err set. */
static const lmb_image_api *api_or_error(lmb_error *err)
{
    pthread_once(&module_once, load_module);
    if (!module_api)
        lmb_error_set(err, LMB_ERR_INTERNAL, "%s", module_failure);
    return module_api;
}

/* .exr, .hdr and .png are written without the module (image_native.c): a bake that reads no
 * texture or sky image never loads it. */
lmb_status lmb_image_write_u8(const char *path, uint32_t width, uint32_t height, uint32_t channels,
                              const uint8_t *pixels, lmb_error *err)
{
    if (lmb_image_native_writes(path, 0))
        return lmb_image_native_write_u8(path, width, height, channels, pixels, err);
    const lmb_image_api *api = api_or_error(err);
    return api ? api->write_u8(path, width, height, channels, pixels, err) : LMB_ERR_INTERNAL;
}

lmb_status lmb_image_write_f32(const char *path, uint32_t width, uint32_t height, uint32_t channels,
                               const float *pixels, lmb_error *err)
{
    if (lmb_image_native_writes(path, 1))
        return lmb_image_native_write_f32(path, width, height, channels, pixels, err);
    const lmb_image_api *api = api_or_error(err);
    return api ? api->write_f32(path, width, height, channels, pixels, err) : LMB_ERR_INTERNAL;
}

lmb_status lmb_image_size(const char *name, const uint8_t *bytes, size_t size, uint32_t *w, uint32_t *h, lmb_error *err)
{
    const lmb_image_api *api = api_or_error(err);
    return api ? api->size(name, bytes, size, w, h, err) : LMB_ERR_INTERNAL;
}

lmb_status lmb_image_read_rgb(const char *name, const uint8_t *bytes, size_t size, uint32_t *width, uint32_t *height,
                              float **rgb, lmb_error *err)
{
    const lmb_image_api *api = api_or_error(err);
    return api ? api->read_rgb(name, bytes, size, width, height, rgb, err) : LMB_ERR_INTERNAL;
}

lmb_status lmb_image_read_alpha(const char *name, const uint8_t *bytes, size_t size, uint32_t factor, uint32_t *width,
                                uint32_t *height, float **alpha, lmb_error *err)
{
    const lmb_image_api *api = api_or_error(err);
    return api ? api->read_alpha(name, bytes, size, factor, width, height, alpha, err) : LMB_ERR_INTERNAL;
}

lmb_status lmb_image_rows_open(const char *name, const uint8_t *bytes, size_t size, lmb_image_rows **out,
                               uint32_t *width, uint32_t *height, lmb_error *err)
{
    const lmb_image_api *api = api_or_error(err);
    return api ? api->rows_open(name, bytes, size, out, width, height, err) : LMB_ERR_INTERNAL;
}

/* A reader exists only once the module is loaded: the functions below read the table directly. */
lmb_status lmb_image_rows_read(lmb_image_rows *r, uint32_t y0, uint32_t y1, float *rgb, lmb_error *err)
{
    return module_api->rows_read(r, y0, y1, rgb, err);
}

int lmb_image_rows_is_u8(const lmb_image_rows *r)
{
    return module_api->rows_is_u8(r);
}

lmb_status lmb_image_rows_read_u8(lmb_image_rows *r, uint32_t y0, uint32_t y1, uint8_t *rgb, lmb_error *err)
{
    return module_api->rows_read_u8(r, y0, y1, rgb, err);
}

void lmb_image_rows_close(lmb_image_rows *r)
{
    if (r)
        module_api->rows_close(r);
}
