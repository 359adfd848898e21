#!/usr/bin/env python3
"""Absurd sizes are refused before any large allocation (issue 15), under `ulimit -v 4000000`
(about 3.8 GiB of address space): each file gets a named error, exit 2, and no output folder.

usage: check_oversized.py LMBAKE WORKDIR

  buffer-4g        an external buffer declared at 4 GiB (the file holds 216 bytes)
  buffer-4g-data   a data-URI buffer declared at 4 GiB
  accessor-2g      POSITION with count 2^31 in a 72-byte bufferView
  image-64k        a base colour PNG whose header says 65536 x 65536 (74 bytes on disk)
  nodes-1e9        nine levels of ten children each: 10^9 instances of one plane (a DAG: the
                   glTF node graph must be a tree)
Not run in the sanitizer build: AddressSanitizer reserves terabytes of address space.
"""
import json
import os
import struct
import subprocess
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "tools"))
import make_scenes  # noqa: E402

LIMIT_KB = 4000000


def base():
    s = make_scenes.Scene()
    s.mesh("plane", make_scenes.plane(2), s.material("grey", (0.5, 0.5, 0.5)), uv=True)
    s.light("lamp", "point", 10.0, translation=(0, 1, 0))
    return s


def png_header(w, h):
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(b"\0" * 1000)) + chunk(b"IEND", b""))


def make(work):
    cases = []
    s = base()
    with open(os.path.join(work, "small.bin"), "wb") as f:
        f.write(bytes(s.blob))
    s.doc["buffers"] = [{"byteLength": 4294967296, "uri": "small.bin"}]
    json.dump(s.doc, open(os.path.join(work, "buffer-4g.gltf"), "w"))
    cases.append(("buffer-4g", r"buffer 0 declares 4294967296 bytes but 'small.bin' holds 216"))

    s = base()
    s.write(os.path.join(work, "buffer-4g-data.gltf"))
    d = json.load(open(os.path.join(work, "buffer-4g-data.gltf")))
    d["buffers"][0]["byteLength"] = 4294967296
    json.dump(d, open(os.path.join(work, "buffer-4g-data.gltf"), "w"))
    cases.append(("buffer-4g-data", r"buffer 0 declares 4294967296 bytes but its data uri holds at most"))

    s = base()
    s.write(os.path.join(work, "accessor-2g.gltf"))
    d = json.load(open(os.path.join(work, "accessor-2g.gltf")))
    d["accessors"][0]["count"] = 2 ** 31
    json.dump(d, open(os.path.join(work, "accessor-2g.gltf"), "w"))
    cases.append(("accessor-2g", r"mesh 'plane' primitive 0 POSITION: 2147483648 elements of 12 bytes .* do not fit in bufferView 0"))

    with open(os.path.join(work, "huge.png"), "wb") as f:
        f.write(png_header(65536, 65536))
    s = base()
    s.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    s.doc["images"] = [{"uri": "huge.png"}]
    s.doc["textures"] = [{"source": 0}]
    s.write(os.path.join(work, "image-64k.gltf"))
    cases.append(("image-64k", r"image 0 is 65536x65536: over lmbake's limit"))

    s = base()
    prev = 0
    for k in range(9):
        s.doc["nodes"].append({"name": "level%d" % k, "children": [prev] * 10})
        prev = len(s.doc["nodes"]) - 1
    s.doc["scenes"][0]["nodes"] = [prev, 1]
    s.write(os.path.join(work, "nodes-1e9.gltf"))
    cases.append(("nodes-1e9", r"node 'plane' has two parents .*: the node graph must be a tree"))
    return cases


def main():
    import re
    lmbake, work = os.path.realpath(sys.argv[1]), os.path.realpath(sys.argv[2])
    os.makedirs(work, exist_ok=True)
    ok = True
    for name, pattern in make(work):
        out = os.path.join(work, "out-" + name)
        p = subprocess.run(["bash", "-c", 'ulimit -v %d && exec "$0" "$@"' % LIMIT_KB, lmbake, "bake",
                            os.path.join(work, name + ".gltf"), "-o", out, "-q"], capture_output=True, text=True,
                           timeout=120)
        good = p.returncode == 2 and re.search(pattern, p.stderr) is not None and not os.path.exists(out)
        print("%s %s: exit %d (want 2), %s; output folder %s" % (
            "PASS" if good else "FAIL", name, p.returncode,
            "message names it" if re.search(pattern, p.stderr) else "MESSAGE: " + p.stderr.strip()[:300],
            "absent" if not os.path.exists(out) else "PRESENT"))
        ok &= good
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
