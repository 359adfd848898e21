#!/usr/bin/env python3
"""An open level as artists bring them: no materials, a sun, and a sky from the config.

usage: check_outdoor.py LMBAKE WORKDIR

The level is tools/make_levels.py's level-single:4 (16 rooms open to the sky, walls with door
gaps, pillars, stairs and crates, a sun and point lights) with its materials removed, so every
primitive has glTF's default material (metallic, albedo 0). Three bakes at the defaults but for a
sixth of the default texel budget and fixed sample counts (what is checked here is which texels
see the sky, not noise; this keeps the test short), with:
  1. no config: the warning about the default material, and the share of black texels (below
     1/1000 of the mean) printed; this is what an outdoor level got before the sky;
  2. only the sky (sky.intensity 3000, lights.intensity_scale 0, bounces 0):
     which texels see the sky, and the sky's own share of their light;
  3. sun + sky + materials.default.albedo 0.7: no texel that sees the sky is black, every one
     holds at least half the sky's share measured in 2 (noise of two estimates), and the bounce
     passes add light (the first pass adds over 5% of the direct light).
"""
import json
import os
import re
import struct
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def strip_materials(src, dst):
    data = open(src, "rb").read()
    length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + length])
    doc.pop("materials", None)
    for m in doc["meshes"]:
        for p in m["primitives"]:
            p.pop("material", None)
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * ((4 - len(text) % 4) % 4)
    rest = data[20 + length:]
    out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + len(rest)) + struct.pack("<II", len(text), 0x4E4F534A)
    open(dst, "wb").write(out + text + rest)


def read(out, suffix):
    path = [os.path.join(out, f) for f in sorted(os.listdir(out)) if f.endswith("-lightmap-0" + suffix)][0]
    return oiio.ImageBuf(path).get_pixels(oiio.FLOAT)


def bake(lmbake, work, scene, name, config):
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write("output: {formats: [exr, mask], directional: false}\natlas: {texels: 100000}\n"
                "samples: {adaptive: false}\n" + config)
    out = os.path.join(work, name)
    p = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake %s failed (%d): %s" % (name, p.returncode, p.stderr))
    lum = read(out, ".exr")[..., :3] @ np.array([0.2126, 0.7152, 0.0722])
    valid = read(out, "-mask.png")[..., 0] > 0.99
    return lum, valid, p.stdout + p.stderr


def main():
    lmbake, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_levels.py"), work, "single:4"], check=True,
                   stdout=subprocess.DEVNULL)
    scene = os.path.join(work, "level-bare.glb")
    strip_materials(os.path.join(work, "level-single-4.glb"), scene)

    plain, valid, log = bake(lmbake, work, scene, "plain", "")
    warned = "have no material, so they get glTF's default material" in log
    black_before = np.mean(plain[valid] < 1e-3 * plain[valid].mean())
    added = re.search(r"each pass added \(share of the direct light\): ([0-9.]+)%", log)
    print("no config: %.1f%% of %d valid texels below 1/1000 of the mean; first bounce pass added %s; default-material "
          "warning: %s" % (100 * black_before, valid.sum(), added.group(1) + "%" if added else "nothing", warned))

    sky, valid2, _ = bake(lmbake, work, scene, "sky-only",
                          "bounces: 0\nsky: {intensity: 3000}\nlights: {intensity_scale: 0}\n")
    full, valid3, log = bake(lmbake, work, scene, "outdoor", "sky: {intensity: 3000, color: [0.75, 0.85, 1]}\n"
                             "materials: {default: {albedo: [0.7, 0.7, 0.7]}}\n")
    same = (valid == valid2).all() and (valid == valid3).all()
    sees_sky = valid & (sky > 0)
    sky_share = sky * (0.2126 * 0.75 + 0.7152 * 0.85 + 0.0722 * 1.0)  # the coloured sky's luminance
    black = np.mean(full[sees_sky] < 1e-3 * full[valid].mean())
    below = np.mean(full[sees_sky] < 0.5 * sky_share[sees_sky])
    added = re.search(r"each pass added \(share of the direct light\): ([0-9.]+)%", log)
    first = float(added.group(1)) if added else 0.0
    good = same and warned and sees_sky.sum() > 0.5 * valid.sum() and black == 0 and below <= 1e-3 and first > 5
    print("sun + sky + albedo 0.7: %d of %d valid texels see the sky; %.3f%% of them below 1/1000 of the mean (bound 0), "
          "%.3f%% below half the sky's share (bound 0.1%%); black overall %.2f%% (was %.1f%%); first bounce pass added "
          "%.1f%% of the direct light (bound > 5%%); layouts equal: %s  %s"
          % (sees_sky.sum(), valid.sum(), 100 * black, 100 * below, 100 * np.mean(full[valid] < 1e-3 * full[valid].mean()),
             100 * black_before, first, same, "ok" if good else "FAIL"))
    sys.exit(0 if good else 1)


if __name__ == "__main__":
    main()
