#!/usr/bin/env python3
"""Outdoor benchmark: a generated open level (tools/make_levels.py level-single:ROOMS, rooms open
to the sky, a sun and point lights) with its materials removed, as real levels arrive, baked at
the defaults (1) with no config, (2) with a sky, (3) with a sky and materials.default.albedo 0.7.
Per bake: wall time, rays, rays/s, texels, the share of valid texels below 1/1000 of the mean,
and what the first bounce pass added; then preview screenshots of bake 3 from inside the level
(the start view: lit and lightmap). Writes OUT/sky.csv, OUT/sky.md and OUT/sky-<view>.png.
Not a test; tools/bench_sky.sh runs it (a few minutes on 2 cores).

usage: bench_sky.py LMBAKE OUTDIR [ROOMS]
"""
import csv
import os
import re
import shutil
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "bake"))
from check_outdoor import read, strip_materials  # noqa: E402

SKY = "sky: {intensity: 3000, color: [0.75, 0.85, 1]}\n"
CASES = [("no config", ""), ("sky", SKY), ("sky + albedo 0.7", SKY + "materials: {default: {albedo: [0.7, 0.7, 0.7]}}\n")]


def main():
    lmbake, out = sys.argv[1], sys.argv[2]
    rooms = int(sys.argv[3]) if len(sys.argv) > 3 else 10
    work = os.path.join(out, "sky-work")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    subprocess.run([sys.executable, os.path.join(HERE, "make_levels.py"), work, "single:%d" % rooms], check=True,
                   stdout=subprocess.DEVNULL)
    scene = os.path.join(work, "level-bare.glb")
    strip_materials(os.path.join(work, "level-single-%d.glb" % rooms), scene)
    rows = []
    for k, (label, config) in enumerate(CASES):
        cfg = os.path.join(work, "case%d.yaml" % k)
        with open(cfg, "w") as f:
            f.write("output: {formats: [exr, hdr, png, mask]}\n" + config)
        dst = os.path.join(work, "case%d" % k)
        t0 = time.time()
        p = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", dst], capture_output=True, text=True)
        wall = time.time() - t0
        if p.returncode != 0:
            sys.exit("bake %s failed: %s" % (label, p.stderr))
        lum = read(dst, ".exr")[..., :3] @ np.array([0.2126, 0.7152, 0.0722])
        valid = read(dst, "-mask.png")[..., 0] > 0.99
        bake = re.search(r"bake: [0-9.]+ s .*?, (\d+) texels \((\d+) valid\), (\d+) rays, ([0-9.e+]+) rays/s", p.stdout)
        added = re.search(r"each pass added \(share of the direct light\): ([0-9.]+)%", p.stdout)
        rows.append({"case": label, "wall_s": "%.1f" % wall, "texels": bake.group(1), "valid": bake.group(2),
                     "rays": bake.group(3), "rays_per_s": "%.3g" % float(bake.group(4)),
                     "black_share": "%.4f" % np.mean(lum[valid] < 1e-3 * lum[valid].mean()),
                     "first_bounce_added": (added.group(1) + "%") if added else "none"})
        print(rows[-1])
    with open(os.path.join(out, "sky.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(out, "sky.md"), "w") as f:
        f.write("| case | wall | texels (valid) | rays | rays/s | texels below 1/1000 of the mean | first bounce pass added |\n")
        f.write("|---|---|---|---|---|---|---|\n")
        for r in rows:
            f.write("| %s | %s s | %s (%s) | %s | %s | %.1f%% | %s |\n" % (
                r["case"], r["wall_s"], r["texels"], r["valid"], r["rays"], r["rays_per_s"],
                100 * float(r["black_share"]), r["first_bounce_added"]))
    gltf = os.path.join(work, "case2", "level-bare.gltf")
    subprocess.run(["node", os.path.join(HERE, "preview", "render.mjs"), gltf, work, "--modes", "lit,lightmap",
                    "--view", "start"], check=True)
    for view in ("lit", "lightmap"):
        shutil.copy(os.path.join(work, "preview-%s.png" % view), os.path.join(out, "sky-%s.png" % view))
    print("wrote %s/sky.csv, sky.md, sky-lit.png, sky-lightmap.png" % out)


if __name__ == "__main__":
    main()
