#!/usr/bin/env python3
"""KTX2 lightmaps read back by an independent reader (tests/ktx2/read_ktx2.mjs: npm ktx-parse,
three.js's zstd decoder, texels decoded from the Vulkan formats there) against the EXR of the
same bake, field by field and texel by texel.

usage: check_ktx2.py LMBAKE WORKDIR

The demo Cornell box at 64 texels per unit (one bounce, few rays), baked once per variant with output.formats
[exr, ktx2]: e5b9g9r9 with and without zstd, b10g11r11 with zstd, rgba16f without. For each:
  header   vkFormat 123 / 122 / 97, typeSize 4 / 4 / 2, the EXR's size, depth 0, layers 0,
           1 face, 1 level, supercompressionScheme 2 (zstd) or 0, the uncompressed level size;
  DFD      version 2, colour model RGBSDA, BT.709, linear, straight alpha, 1x1 blocks,
           bytesPlane0 = the texel size, and the samples of KTX-Software's dfdutils (E5B9G9R9:
           per channel a 9-bit mantissa, upper 8448, and the 5-bit exponent at bit 27 with the
           exponent qualifier, lower 15 upper 31; B10G11R11: unsigned floats 11/11/10 bits;
           RGBA16F: signed floats, alpha channel 15);
  key/value KTXorientation "rd", KTXwriter "lmbake <version>";
  texels   every texel within the format's precision of the EXR (which holds half floats):
           E5B9G9R9 2^-9 of the texel's largest channel, B10G11R11 2^-7 (R, G) and 2^-6 (B)
           relative, RGBA16F equal.
"""
import json
import os
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
F = 0x80  # float qualifier
S = 0x40  # signed qualifier
X = 0x20  # exponent qualifier
ONE, MINUS_ONE = 0x3F800000, 0xBF800000
VARIANTS = {
    ("e5b9g9r9", "zstd"): (123, 4, [(0, 9, 0, 0, 8448), (27, 5, X | 0, 15, 31), (9, 9, 1, 0, 8448),
                                    (27, 5, X | 1, 15, 31), (18, 9, 2, 0, 8448), (27, 5, X | 2, 15, 31)]),
    ("e5b9g9r9", "none"): None,
    ("b10g11r11", "zstd"): (122, 4, [(0, 11, F | 0, 0, ONE), (11, 11, F | 1, 0, ONE), (22, 10, F | 2, 0, ONE)]),
    ("rgba16f", "none"): (97, 2, [(0, 16, F | S | 0, MINUS_ONE, ONE), (16, 16, F | S | 1, MINUS_ONE, ONE),
                                  (32, 16, F | S | 2, MINUS_ONE, ONE), (48, 16, F | S | 15, MINUS_ONE, ONE)]),
}
VARIANTS[("e5b9g9r9", "none")] = VARIANTS[("e5b9g9r9", "zstd")]


def main():
    lmbake, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True,
                   stdout=subprocess.DEVNULL)
    version = subprocess.run([lmbake, "--version"], capture_output=True, text=True).stdout.split()[-1]
    ok = True
    for (fmt, sc), (vk, type_size, samples) in VARIANTS.items():
        name = "%s-%s" % (fmt, sc)
        cfg = os.path.join(work, name + ".yaml")
        with open(cfg, "w") as f:
            # the light is checked elsewhere: one bounce and few rays (the texels are compared
            # with the same bake's EXR, noise and all)
            f.write("texel_density: 64\nbounces: 1\nsamples: {gather: 32, adaptive: false}\n"
                    "output: {formats: [exr, ktx2], directional: false, ktx2_format: %s, "
                    "ktx2_supercompression: %s}\n" % (fmt, sc))
        out = os.path.join(work, name)
        subprocess.run([lmbake, "bake", os.path.join(scenes, "cornell-point.gltf"), "-c", cfg, "-o", out, "-q"],
                       check=True)
        exr = oiio.ImageBuf(os.path.join(out, "cornell-point-lightmap-0.exr")).get_pixels(oiio.FLOAT)[..., :3]
        h, w = exr.shape[:2]
        raw = os.path.join(work, name + ".f32")
        p = subprocess.run(["node", os.path.join(HERE, "read_ktx2.mjs"), os.path.join(out, "cornell-point-lightmap-0.ktx2"),
                            raw], capture_output=True, text=True, env=dict(os.environ, NODE_PATH=os.path.join(ROOT, "node_modules")))
        if p.returncode != 0:
            print("%s: the reader failed: %s" % (name, p.stderr))
            ok = False
            continue
        k = json.loads(p.stdout)
        texel = 8 if vk == 97 else 4
        problems = []
        want = {"vkFormat": vk, "typeSize": type_size, "pixelWidth": w, "pixelHeight": h, "pixelDepth": 0,
                "layerCount": 0, "faceCount": 1, "levelCount": 1, "supercompressionScheme": 2 if sc == "zstd" else 0,
                "uncompressedByteLength": w * h * texel}
        problems += ["%s %s, want %s" % (f, k[f], v) for f, v in want.items() if k[f] != v]
        if sc == "none" and k["levelBytes"] != w * h * texel:
            problems.append("levelBytes %d, want %d" % (k["levelBytes"], w * h * texel))
        d = k["dfd"]
        want_dfd = {"vendorId": 0, "descriptorType": 0, "versionNumber": 2, "colorModel": 1, "colorPrimaries": 1,
                    "transferFunction": 1, "flags": 0, "texelBlockDimension": [0, 0, 0, 0],
                    "bytesPlane": [texel, 0, 0, 0, 0, 0, 0, 0]}
        problems += ["dfd %s %s, want %s" % (f, d[f], v) for f, v in want_dfd.items() if d[f] != v]
        got = [(s["bitOffset"], s["bitLength"] + 1, s["channelType"], s["sampleLower"] & 0xFFFFFFFF,
                s["sampleUpper"] & 0xFFFFFFFF) for s in d["samples"]]
        if got != samples:
            problems.append("dfd samples %s, want %s" % (got, samples))
        if k["keyValue"].get("KTXorientation") != "rd" or k["keyValue"].get("KTXwriter") != "lmbake " + version:
            problems.append("key/value %s" % k["keyValue"])
        texels = np.fromfile(raw, dtype=np.float32).reshape(h, w, 3).astype(np.float64)
        e = exr.astype(np.float64)
        if vk == 123:
            bound = 2.0 ** -9 * e.max(axis=2, keepdims=True) + 2.0 ** -11 * e + 1e-30
        elif vk == 122:
            bound = np.concatenate([2.0 ** -7 * e[..., :2], 2.0 ** -6 * e[..., 2:]], axis=2) * 1.01 + 2.0 ** -11 * e + 1e-12
        else:
            bound = np.zeros_like(e)
        off = np.abs(texels - e) > bound
        if off.any():
            problems.append("%d of %d texel values beyond the format's precision" % (off.sum(), off.size))
        good = not problems
        ok &= good
        print("%-16s %dx%d, %d bytes in the level (%d uncompressed): header, DFD (%d samples), key/value and %d "
              "texels %s%s" % (name, w, h, k["levelBytes"], w * h * texel, len(samples), w * h,
                               "ok" if good else "FAIL: ", "; ".join(problems)))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
