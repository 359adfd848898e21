/*
 * libFuzzer target: decoding of base colour and emissive textures (issue 15), through the
 * bake's own path: a one-triangle glTF (loaded once) whose material names texture.png as its
 * base colour and emissive texture; each input is written as that file and lmb_textures_load
 * reads it (header size check, then OpenImageIO's decoder, which falls back to every format it
 * knows when the bytes are not PNG). OpenImageIO itself is not instrumented: the fuzzer's
 * coverage guidance sees lmbake's side only, while ASan still checks what lmbake does with the
 * decoder's results.
 */
#include "fuzz_common.h"
#include "load/textures.h"

#include <lmbake/lmbake.h>

#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* One triangle (positions and normals in a data URI) with a textured, emissive material. */
static const char scene_json[] =
    "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
    "\"nodes\":[{\"mesh\":0}],"
    "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0}]}],"
    "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0},\"metallicFactor\":0},"
    "\"emissiveTexture\":{\"index\":0},\"emissiveFactor\":[1,1,1]}],"
    "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"texture.png\"}],"
    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
    "\"min\":[0,0,0],\"max\":[1,1,0]},"
    "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}],"
    "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36},"
    "{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24}],"
    "\"buffers\":[{\"byteLength\":60,\"uri\":\"data:application/octet-stream;base64,"
    /* positions (0,0,0) (1,0,0) (0,1,0); uvs (0,0) (1,0) (0,1) as little-endian floats */
    "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAIA/AAAAAAAAAAAAAIA/\"}]}";

/* The scene, loaded on the first input and kept for the process (harness state). */
static lmb_scene *scene;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[4096];
    lmb_error err;
    const lmb_log *log = (const lmb_log *)lmb_fuzz_quiet_log();
    if (!scene) {
        if (!lmb_fuzz_write("scene.gltf", (const uint8_t *)scene_json, sizeof scene_json - 1, path) ||
            lmb_scene_load(path, NULL, &scene, log, &err) != LMB_OK)
            abort(); /* the harness itself is broken: stop at once */
    }
    if (!lmb_fuzz_write("texture.png", data, size, path))
        return 0;
    lmb_textures textures;
    (void)lmb_textures_load(scene, &textures, log, &err);
    lmb_textures_free(&textures);
    return 0;
}
