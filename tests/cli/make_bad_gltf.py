#!/usr/bin/env python3
"""Writes small broken (and borderline) glTF files, one defect each, into OUTDIR.

Each file is a single triangle-list primitive in an embedded (data URI) buffer, then
edited to carry exactly one problem. tests/CMakeLists.txt pairs each with the exit code
and the message lmbake must give.
"""
import base64
import copy
import json
import math
import os
import struct
import sys
import zlib


def base_doc(positions, indices, normals=None):
    """A valid one-mesh glTF: POSITION (+NORMAL) floats, uint16 indices."""
    blob = b"".join(struct.pack("<3f", *p) for p in positions)
    pos_len = len(blob)
    nrm_off = len(blob)
    if normals is not None:
        blob += b"".join(struct.pack("<3f", *n) for n in normals)
    idx_off = len(blob)
    blob += b"".join(struct.pack("<H", i) for i in indices)
    while len(blob) % 4:
        blob += b"\0"
    finite = [p for p in positions if all(math.isfinite(c) for c in p)] or [(0, 0, 0)]
    doc = {
        "asset": {"version": "2.0", "generator": "lmbake tests/cli/make_bad_gltf.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "Floor", "mesh": 0}],
        "meshes": [{"name": "FloorMesh", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": pos_len},
            {"buffer": 0, "byteOffset": idx_off, "byteLength": 2 * len(indices)},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
             "min": [min(p[i] for p in finite) for i in range(3)],
             "max": [max(p[i] for p in finite) for i in range(3)]},
            {"bufferView": 1, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
        ],
    }
    if normals is not None:
        doc["bufferViews"].append({"buffer": 0, "byteOffset": nrm_off, "byteLength": 12 * len(normals)})
        doc["accessors"].append({"bufferView": 2, "componentType": 5126, "count": len(normals), "type": "VEC3"})
        doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 2
    return doc


QUAD = [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)]


def grey_png(value=128):
    """A 1 x 1 8-bit grey PNG."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 0, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(bytes([0, value]))) + chunk(b"IEND", b""))
QUAD_IDX = [0, 2, 1, 0, 3, 2]


def cases():
    ok = base_doc(QUAD, QUAD_IDX)
    yield "ok-quad", ok

    yield "index-out-of-range", base_doc(QUAD, [0, 2, 1, 0, 3, 7])
    yield "nan-position", base_doc([(0, 0, 0), (1, 0, 0), (float("nan"), 0, 1), (0, 0, 1)], QUAD_IDX)
    yield "inf-position", base_doc([(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, float("inf"), 1)], QUAD_IDX)
    yield "normal-count-mismatch", base_doc(QUAD, QUAD_IDX, normals=[(0, 1, 0)] * 3)

    d = copy.deepcopy(ok)
    d["accessors"][0]["count"] = 40  # runs past its buffer view
    yield "accessor-past-view", d

    d = copy.deepcopy(ok)
    d["bufferViews"][0]["byteLength"] = 4096  # runs past its buffer
    yield "view-past-buffer", d

    d = copy.deepcopy(ok)
    d["buffers"][0]["uri"] = "missing-level-data.bin"
    yield "missing-bin", d

    d = copy.deepcopy(ok)
    d["nodes"] = [{"name": "A", "children": [1]}, {"name": "B", "children": [0], "mesh": 0}]
    d["scenes"] = [{"nodes": []}]
    yield "node-cycle", d

    d = copy.deepcopy(ok)
    d["nodes"][0]["children"] = [5]
    yield "child-out-of-range", d

    d = copy.deepcopy(ok)
    d["meshes"][0]["primitives"][0]["material"] = 3
    yield "material-out-of-range", d

    d = copy.deepcopy(ok)
    d["extensionsUsed"] = ["KHR_lights_punctual"]
    d["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "BadSpot", "type": "spot", "intensity": 10, "spot": {"innerConeAngle": 1.0, "outerConeAngle": 0.5}}]}}
    d["nodes"].append({"name": "Lamp", "extensions": {"KHR_lights_punctual": {"light": 0}}})
    d["scenes"][0]["nodes"].append(1)
    yield "spot-cone-inverted", d

    d = copy.deepcopy(ok)
    d["extensionsUsed"] = ["KHR_lights_punctual"]
    d["extensions"] = {"KHR_lights_punctual": {"lights": [{"name": "Dark", "type": "point", "intensity": -5}]}}
    d["nodes"].append({"name": "Lamp", "extensions": {"KHR_lights_punctual": {"light": 0}}})
    d["scenes"][0]["nodes"].append(1)
    yield "negative-intensity", d

    d = copy.deepcopy(ok)
    d["extensionsUsed"] = ["KHR_lights_punctual"]
    d["extensions"] = {"KHR_lights_punctual": {"lights": [{"name": "Odd", "type": "point", "intensity": 5,
                                                           "color": [1, -0.3, 0]}]}}
    d["nodes"].append({"name": "Lamp", "extensions": {"KHR_lights_punctual": {"light": 0}}})
    d["scenes"][0]["nodes"].append(1)
    yield "negative-colour", d

    # borderline but valid: half the triangles have zero area (warning, exit 0)
    yield "degenerate-triangles", base_doc(QUAD + [(2, 0, 0)], QUAD_IDX + [1, 4, 1, 0, 1, 4])

    # not JSON at all
    yield "not-json", "{ this is not json"

    # required extensions (docs/input.md): ones that change only what a diffuse
    # bake ignores load with a warning naming them; geometry compression stays an error
    d = copy.deepcopy(ok)
    d["materials"] = [{"name": "Velvet", "pbrMetallicRoughness": {"metallicFactor": 0},
                       "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1, 0.3, 0.1]},
                                      "KHR_materials_clearcoat": {"clearcoatFactor": 1}}}]
    d["meshes"][0]["primitives"][0]["material"] = 0
    d["extensionsUsed"] = d["extensionsRequired"] = ["KHR_materials_sheen", "KHR_materials_clearcoat"]
    yield "required-sheen", d
    d = copy.deepcopy(d)
    d["extensionsUsed"] = d["extensionsRequired"] = ["KHR_materials_sheen", "ADOBE_materials_thin_transparency"]
    yield "required-sheen-unsupported", d
    # a required extension that changes the diffuse colour in a way lmbake does not model: refused
    d = copy.deepcopy(ok)
    d["extensionsUsed"] = d["extensionsRequired"] = ["ADOBE_materials_thin_transparency"]
    yield "required-unknown", d
    # KHR_materials_diffuse_transmission required: implemented, it loads
    d = copy.deepcopy(ok)
    d["extensionsUsed"] = d["extensionsRequired"] = ["KHR_materials_diffuse_transmission"]
    yield "required-diffuse-transmission", d

    # alpha that cannot mean anything (glTF 2.0 section 5.19): a cutoff outside [0, 1] or not a
    # number, an alphaMode that is not one of the three; a MASK material whose base colour
    # texture names an image that cannot be decoded (its cut-outs are unknown)
    for name, mat in (("alpha-cutoff-range", {"alphaMode": "MASK", "alphaCutoff": 1.5}),
                      ("alpha-cutoff-string", {"alphaMode": "MASK", "alphaCutoff": "half"}),
                      ("alpha-mode-unknown", {"alphaMode": "CUTOUT"})):
        d = copy.deepcopy(ok)
        d["materials"] = [dict({"name": "Leaves", "pbrMetallicRoughness": {"metallicFactor": 0}}, **mat)]
        d["meshes"][0]["primitives"][0]["material"] = 0
        yield name, d
    d = copy.deepcopy(ok)
    d["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(b"\x89PNG not an image").decode()}]
    d["textures"] = [{"source": 0}]
    d["materials"] = [{"name": "Leaves", "alphaMode": "MASK",
                       "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}}]
    d["meshes"][0]["primitives"][0]["material"] = 0
    yield "alpha-mask-texture-broken", d

    # KHR_texture_basisu required: the base colour texture has only a KTX2 image (error), or
    # also a PNG fallback `source` (loads with a warning). The KTX2 bytes are never decoded.
    d = copy.deepcopy(ok)
    blob = base64.b64decode(d["buffers"][0]["uri"].split(",", 1)[1])
    ktx = b"\xabKTX 20\xbb\r\n\x1a\n" + b"\0" * 8
    d["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(ktx)})
    blob += ktx
    d["buffers"][0] = {"byteLength": len(blob),
                       "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}
    d["images"] = [{"bufferView": len(d["bufferViews"]) - 1, "mimeType": "image/ktx2"}]
    d["textures"] = [{"extensions": {"KHR_texture_basisu": {"source": 0}}}]
    d["materials"] = [{"name": "Wood", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}}]
    d["meshes"][0]["primitives"][0]["material"] = 0
    d["extensionsUsed"] = d["extensionsRequired"] = ["KHR_texture_basisu"]
    yield "required-basisu-no-fallback", d
    d = copy.deepcopy(d)
    png = grey_png()
    d["images"].append({"uri": "data:image/png;base64," + base64.b64encode(png).decode(), "mimeType": "image/png"})
    d["textures"][0]["source"] = 1
    yield "required-basisu-fallback", d


def gpu_instanced(ok, translations, scales):
    """ok's mesh drawn through EXT_mesh_gpu_instancing with these TRANSLATION and SCALE lists."""
    d = copy.deepcopy(ok)
    blob = base64.b64decode(d["buffers"][0]["uri"].split(",", 1)[1])
    attrs = {}
    for name, vals in (("TRANSLATION", translations), ("SCALE", scales)):
        data = b"".join(struct.pack("<3f", *v) for v in vals)
        d["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        blob += data
        d["accessors"].append({"bufferView": len(d["bufferViews"]) - 1, "componentType": 5126, "count": len(vals),
                               "type": "VEC3"})
        attrs[name] = len(d["accessors"]) - 1
    d["buffers"][0] = {"byteLength": len(blob),
                       "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}
    d["nodes"][0]["extensions"] = {"EXT_mesh_gpu_instancing": {"attributes": attrs}}
    d["extensionsUsed"] = ["EXT_mesh_gpu_instancing"]
    return d


def gpu_cases(ok):
    # the instancing extension's accessors disagree in count; a copy with a zero scale
    yield "gpu-count-mismatch", gpu_instanced(ok, [(0, 0, 0), (2, 0, 0), (4, 0, 0)], [(1, 1, 1), (1, 1, 1)])
    yield "gpu-zero-scale", gpu_instanced(ok, [(0, 0, 0), (2, 0, 0), (4, 0, 0)], [(1, 1, 1), (0, 0, 0), (1, 1, 1)])


def compressed_cases():
    """glTF-Transform's compressed boxes (tests/data) with their compressed streams broken: each
    stream's first byte (meshopt's codec header, Draco's magic) zeroed; buffers as data URIs."""
    folder = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data",
                          "compressed-meshopt-draco-gltf-transform")
    for name, gltf in (("meshopt-corrupt", "BoxMeshopt.gltf"), ("draco-corrupt", "BoxDraco.gltf")):
        d = json.load(open(os.path.join(folder, gltf)))
        blob = bytearray(open(os.path.join(folder, d["buffers"][0]["uri"]), "rb").read())
        for v in d["bufferViews"]:
            ext = v.get("extensions", {}).get("EXT_meshopt_compression")
            if ext:
                blob[ext.get("byteOffset", 0)] = 0
        for m in d["meshes"]:
            for p in m["primitives"]:
                ext = p.get("extensions", {}).get("KHR_draco_mesh_compression")
                if ext:
                    at = d["bufferViews"][ext["bufferView"]].get("byteOffset", 0)
                    blob[at:at + 8] = bytes(8)
        d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()
        yield name, d


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    ok = base_doc(QUAD, QUAD_IDX)
    for name, doc in list(cases()) + list(gpu_cases(ok)) + list(compressed_cases()):
        with open(os.path.join(out, name + ".gltf"), "w") as f:
            f.write(doc if isinstance(doc, str) else json.dumps(doc, indent=1))


if __name__ == "__main__":
    main()
