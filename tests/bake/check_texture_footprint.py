#!/usr/bin/env python3
"""Bounced light off a fine texture: its albedo is averaged over each ray's footprint.

usage: check_texture_footprint.py LMBAKE WORKDIR

tools/make_scenes.py checker-bounce: a floor whose base colour is a black and white checker of
1 cm cells (mean albedo 0.5), a black ceiling 2 m above it and a point light between them; the
ceiling's indirect light is what the floor bounces. Three bakes at the same rays, gathered per
texel and not denoised (what is measured is the estimator's own noise): the checker floor, the
same floor of flat albedo 0.5, and a black one (the ceiling's direct light alone, taken off the
other two). Over the ceiling's texels: the checker's mean indirect light within 1% of the flat
floor's, and its per-texel noise (rms of the difference from a 5 x 5 box average, relative to
the mean) at most 1.1x the flat floor's. Read at points, the checker's 0 / 1 albedo made every
bounce ray a coin toss.
"""
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import bake_cli  # noqa: E402
from object_means import _image  # noqa: E402

CONFIG = ("texel_density: 16\nbounces: 1\nirradiance_cache: {error: 0}\ndenoise: {indirect: false, direct: false}\n"
          "samples: {gather: 256, adaptive: false}\noutput: {formats: [exr, mask]}\natlas: {max_size: 4096}\n")


def ceiling(lmbake, work, scenes, name):
    out = os.path.join(work, name)
    p = subprocess.run([lmbake, "bake", os.path.join(scenes, name + "-bounce.gltf"), "-c",
                        os.path.join(work, "c.yaml"), "-o", out, "-q"], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake %s failed (%d): %s" % (name, p.returncode, p.stderr[-2000:]))
    exr = [f for f in os.listdir(out) if f.endswith("-lightmap-0.exr")][0]
    img = _image(os.path.join(out, exr))[..., :3] @ np.array([0.2126, 0.7152, 0.0722])
    mask = _image(os.path.join(out, exr[:-4] + "-mask.png"))[..., 0] > 0.99
    return img, mask


def noise(e, valid):
    """rms of e minus its 5 x 5 box mean over fully valid windows, relative to e's mean there."""
    h, w = e.shape
    diffs, vals = [], []
    for y in range(2, h - 2):
        for x in range(2, w - 2):
            win = valid[y - 2:y + 3, x - 2:x + 3]
            if win.all():
                diffs.append(e[y, x] - e[y - 2:y + 3, x - 2:x + 3].mean())
                vals.append(e[y, x])
    return float(np.sqrt(np.mean(np.square(diffs))) / np.mean(vals)), len(vals)


def main():
    lmbake, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    scenes = bake_cli.scenes(work)
    with open(os.path.join(work, "c.yaml"), "w") as f:
        f.write(CONFIG)
    dark, mask = ceiling(lmbake, work, scenes, "dark")
    # the same geometry and density: the same layout and the same direct light in every bake; the
    # floor's indirect light is exactly 0 (the ceiling is black), the ceiling's is not
    ind = {}
    for name in ("checker", "flat"):
        e, m = ceiling(lmbake, work, scenes, name)
        ind[name] = np.where(mask & m, e - dark, 0.0)
    ceil = ind["flat"] > 0
    res = {name: (ind[name][ceil].mean(), *noise(np.where(ceil, ind[name], 0.0), ceil)) for name in ind}
    rel = res["checker"][0] / res["flat"][0] - 1
    ratio = res["checker"][1] / res["flat"][1]
    ok = abs(rel) <= 0.01 and ratio <= 1.1
    print("ceiling's indirect light: checker floor %.4f lux (%d texels), flat albedo 0.5 %.4f lux: %+.2f%% (bound 1%%); "
          "per-texel noise %.2f%% against %.2f%%: %.2fx (bound 1.1x)  %s" %
          (res["checker"][0], res["checker"][2], res["flat"][0], 100 * rel, 100 * res["checker"][1],
           100 * res["flat"][1], ratio, "ok" if ok else "FAIL"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
