#!/usr/bin/env python3
"""lmbake's engine loaders in Chromium (loaders/three, loaders/babylon) against the lightmap files:
every pixel an example page renders (tests/loaders/loader_pixels.mjs: the lightmap value in lux
and the lightmap coordinates, as the loader set the materials up) against the bilinear lookup
of the file the loader used at those coordinates, decoded by a decoder lmbake did not write
(tools/ktx2_blocks.py; the .hdr through OpenImageIO), and against the EXR.

usage: check_loader_pixels.py LMBAKE WORKDIR LOADER[,LOADER...]

bevy's Cornell box (one bounce, few rays, 60,000 texels: the loaders are checked, not the light;
a texel still covers about one pixel of the 320 x 240 probe), once per KTX2
format: E5B9G9R9 with Zstandard, BC6H without, ASTC HDR with; each loader's page on each bake.
Which file a loader must read: the KTX2 when it reads that format and the GPU samples it, else
the .hdr, and the page must say why (EXPECT below; Chromium's SwiftShader has BC6H and no ASTC
hdr profile). Bounds per
pixel, relative: against the file the page read, mean 0.1% (the .hdr: 0.5%, RGBE decoders
differ by half a mantissa step) and 99th percentile 1% (the GPU's bilinear weights are 8-bit
fixed point); against the EXR, the file's own precision on top
(E5B9G9R9 0.4%, .hdr 1%, BC6H and ASTC their mean error, docs/output.md): mean within 2%.
"""
import json
import os
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import ktx2_blocks as kb  # noqa: E402

SCENE = os.path.join(ROOT, "assets", "scenes", "cornell-box-bevy", "CornellBox.glb")
FORMATS = {"e5b9g9r9": "zstd", "bc6h": "none", "astc_hdr": "zstd"}
# (loader, format) -> the file it must read, or None: the KTX2 unless the page says the GPU
# cannot sample the format
EXPECT = {("three", "e5b9g9r9"): "ktx2", ("three", "bc6h"): "ktx2", ("three", "astc_hdr"): None,
          ("babylon", "e5b9g9r9"): "hdr", ("babylon", "bc6h"): "ktx2", ("babylon", "astc_hdr"): "hdr"}
# Babylon reads both E5B9G9R9 and ASTC through the .hdr: the ASTC bake's page covers that path
SKIP = {("babylon", "e5b9g9r9")}


def bilinear(img, u, v):
    """Bilinear lookups of img (h, w, 3) at arrays u, v (texel centres at half integers, clamped)."""
    h, w = img.shape[:2]
    x, y = u * w - 0.5, v * h - 0.5
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    ax, ay = (x - x0)[:, None], (y - y0)[:, None]
    def at(xx, yy):
        return img[np.clip(yy, 0, h - 1), np.clip(xx, 0, w - 1)]
    return ((1 - ay) * ((1 - ax) * at(x0, y0) + ax * at(x0 + 1, y0)) +
            ay * ((1 - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1)))


def read_image(path):
    return np.asarray(oiio.ImageBuf(path).get_pixels(oiio.FLOAT), dtype=np.float64)[..., :3]


def relative(got, want):
    s = want.sum(axis=1)
    keep = s > 1e-3 * max(float(np.median(s)), 1e-30)
    return np.abs(got - want).sum(axis=1)[keep] / s[keep]


def check(work, out, loader, fmt):
    probe_file = os.path.join(work, "%s-%s.json" % (loader, fmt))
    subprocess.run(["node", os.path.join(HERE, "loader_pixels.mjs"), loader, os.path.join(out, "CornellBox.gltf"),
                    probe_file], check=True, env=dict(os.environ, NODE_PATH=os.path.join(ROOT, "node_modules")))
    p = json.load(open(probe_file))
    value = np.array(p["value"], dtype=np.float64).reshape(-1, 4)
    uv = np.array(p["uv"], dtype=np.float64).reshape(-1, 4)
    lit = (uv[:, 3] > 0.5) & (value[:, 3] > 0.5)
    report = " ".join(p["logs"])
    used_ktx2 = "from CornellBox-lightmap-0.ktx2" in report
    stem = os.path.join(out, "CornellBox-lightmap-0")
    ref_file = kb.decode(stem + ".ktx2", work)[1] if used_ktx2 else read_image(stem + ".hdr")
    exr = read_image(stem + ".exr")
    u, v = uv[lit, 0], uv[lit, 1]
    got = value[lit, :3]
    rel_file = relative(got, bilinear(ref_file, u, v))
    rel_exr = relative(got, bilinear(exr, u, v))
    want = EXPECT[(loader, fmt)] or ("hdr" if "cannot sample" in report else "ktx2")
    problems = []
    if used_ktx2 != (want == "ktx2"):
        problems.append("read %s, expected the %s" % ("the KTX2" if used_ktx2 else "the .hdr", want))
    if not lit.sum() > 20000:
        problems.append("only %d lightmapped pixels" % lit.sum())
    # RGBE decoders differ by half a mantissa step (three adds 0.5 before scaling, OIIO does
    # not): up to 0.4% at the smallest mantissa, so the .hdr's mean bound is 0.5%
    mean_bound = 0.001 if used_ktx2 else 0.005
    if not (rel_file.mean() <= mean_bound and np.percentile(rel_file, 99) <= 0.01):
        problems.append("pixels off the file they read")
    if not rel_exr.mean() <= 0.02:
        problems.append("pixels off the EXR")
    print("%s, %-9s: %d pixels from %s; against it mean %.4f%% p99 %.3f%% (bounds %g%%, 1%%); against the EXR "
          "mean %.3f%% p99 %.2f%% (bound 2%%): %s" % (loader, fmt, lit.sum(), "the KTX2" if used_ktx2 else "the .hdr",
                                                       100 * rel_file.mean(), 100 * np.percentile(rel_file, 99),
                                                       100 * mean_bound, 100 * rel_exr.mean(),
                                                       100 * np.percentile(rel_exr, 99),
                                                       "ok" if not problems else "FAIL: " + "; ".join(problems)), flush=True)
    return not problems


def main():
    lmbake, work, loaders = sys.argv[1], sys.argv[2], sys.argv[3].split(",")
    os.makedirs(work, exist_ok=True)
    ok = True
    for fmt, sc in FORMATS.items():
        out = os.path.join(work, "out-" + fmt)
        cfg = os.path.join(work, fmt + ".yaml")
        with open(cfg, "w") as f:
            # the loaders are checked, not the light: one bounce, few rays
            f.write("bounces: 1\nsamples: {gather: 32, adaptive: false}\nprobes: {auto: false}\natlas: {texels: 60000}\n"
                    "output: {formats: [exr, ktx2], directional: "
                    "false, ktx2_format: %s, ktx2_supercompression: %s}\n" % (fmt, sc))
        subprocess.run([lmbake, "bake", SCENE, "-c", cfg, "-o", out, "-q"], check=True)
        for loader in loaders:
            if (loader, fmt) in SKIP:
                continue
            ok &= check(work, out, loader, fmt)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
