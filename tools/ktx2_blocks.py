#!/usr/bin/env python3
"""Block-compressed KTX2 lightmaps decoded by decoders lmbake did not write, and their error
against the EXR of the same bake (the compression tests and tools/bench_compression.sh).

  read(path)            level 0's blocks and the header, through tests/ktx2/read_ktx2.mjs (npm
                        ktx-parse and three.js's Zstandard decoder)
  decode(path, work)    level 0 as float RGB, (h, w, 3): the packed formats as the reader decodes
                        them (from the Vulkan formats' definitions), BC6H through OpenImageIO's DDS reader
                        (the blocks wrapped in a DDS file with a DX10 header, DXGI_FORMAT_BC6H_UF16),
                        ASTC through Arm's astcenc command-line decompressor (`astcenc -dh`, the
                        blocks wrapped in a .astc file)
  errors(ref, got, mask) mean and 99th-percentile relative error per texel (sum over channels of
                        |got - ref| over the sum of ref) and the same over 9 x 9 box averages, over
                        the texels `mask` marks (the chart texels) whose reference is not black
"""
import json
import os
import struct
import subprocess
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BC6H, ASTC = 143, 1000066000


def read(path, work):
    raw = os.path.join(work, os.path.basename(path) + ".blocks")
    p = subprocess.run(["node", os.path.join(ROOT, "tests", "ktx2", "read_ktx2.mjs"), path, raw], capture_output=True,
                       text=True, env=dict(os.environ, NODE_PATH=os.path.join(ROOT, "node_modules")))
    if p.returncode != 0:
        raise RuntimeError("%s: the KTX2 reader failed: %s" % (path, p.stderr))
    with open(raw, "rb") as f:
        return json.loads(p.stdout), f.read()


def decode_bc6h(blocks, w, h, work):
    import OpenImageIO as oiio
    dds = os.path.join(work, "level.dds")
    flags = 0x1 | 0x2 | 0x4 | 0x1000 | 0x80000  # caps, height, width, pixel format, linear size
    pixel_format = struct.pack("<II4sIIIII", 32, 0x4, b"DX10", 0, 0, 0, 0, 0)
    header = struct.pack("<IIIIIII", 124, flags, h, w, len(blocks), 0, 1) + b"\0" * 44 + pixel_format + \
        struct.pack("<IIIII", 0x1000, 0, 0, 0, 0)
    dx10 = struct.pack("<IIIII", 95, 3, 0, 1, 0)  # DXGI_FORMAT_BC6H_UF16, 2D, no flags, 1 array element
    with open(dds, "wb") as f:
        f.write(b"DDS " + header + dx10 + blocks)
    inp = oiio.ImageInput.open(dds)
    if inp is None:
        raise RuntimeError("OpenImageIO cannot open the DDS: %s" % oiio.geterror())
    img = inp.read_image("float")
    inp.close()
    return np.asarray(img, dtype=np.float64).reshape(h, w, -1)[..., :3]


def decode_astc(blocks, w, h, work):
    import OpenImageIO as oiio
    astc = os.path.join(work, "level.astc")
    exr = os.path.join(work, "level-astc.exr")
    dims = b"".join(struct.pack("<I", v)[:3] for v in (w, h, 1))
    with open(astc, "wb") as f:
        f.write(struct.pack("<I", 0x5CA1AB13) + bytes([4, 4, 1]) + dims + blocks)
    p = subprocess.run(["astcenc", "-dh", astc, exr], capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError("astcenc -dh failed: %s%s" % (p.stdout, p.stderr))
    img = oiio.ImageBuf(exr).get_pixels(oiio.FLOAT)
    return np.asarray(img, dtype=np.float64)[..., :3]


def decode(path, work=None):
    work = work or tempfile.mkdtemp(prefix="ktx2-blocks-")
    info, blocks = read(path, work)
    w, h = info["pixelWidth"], info["pixelHeight"]
    if info["vkFormat"] == BC6H:
        return info, decode_bc6h(blocks, w, h, work)
    if info["vkFormat"] == ASTC:
        return info, decode_astc(blocks, w, h, work)
    # a packed format: the reader decoded the texels itself (float32 RGB)
    return info, np.frombuffer(blocks, dtype=np.float32).reshape(h, w, 3).astype(np.float64)


def box9(img):
    """9 x 9 box sums (valid region only) of an (h, w, c) array."""
    c = np.cumsum(np.cumsum(np.pad(img, ((1, 0), (1, 0), (0, 0))), axis=0), axis=1)
    return c[9:, 9:] - c[:-9, 9:] - c[9:, :-9] + c[:-9, :-9]


def errors(ref, got, mask):
    """(mean, p99) relative error per texel and (mean, p99) on 9 x 9 averages of the masked texels."""
    s = ref.sum(axis=2)
    keep = mask & (s > 0)
    rel = np.abs(got - ref).sum(axis=2)[keep] / s[keep]
    m = mask.astype(np.float64)[..., None]
    # averages over the mask's texels in each 9 x 9 window that lies wholly on chart texels
    full = box9(m)[..., 0] == 81
    rs, gs = box9(ref * m), box9(got * m)
    ss = rs.sum(axis=2)
    keep9 = full & (ss > 0)
    rel9 = np.abs(gs - rs).sum(axis=2)[keep9] / ss[keep9]
    return (float(rel.mean()), float(np.percentile(rel, 99)), float(rel9.mean()) if rel9.size else 0.0,
            float(np.percentile(rel9, 99)) if rel9.size else 0.0, int(keep.sum()), int(keep9.sum()))
