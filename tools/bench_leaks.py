#!/usr/bin/env python3
"""Leak benchmark: every scene of the leak suite (tools/leak_scenes.py) baked with no config but
the texel budget, by one or two lmbake binaries side by side, and what the dark region reads
(tools/leak_measure.py): the lightmap's mean, its brightest texel more than a texel from the
wall, its brightest texel anywhere, its brightest probe, and probe-lit points 0.3 m and more
inside it through the tetrahedra and through the irradiance volume; each also as a share of the
lit region's lightmap mean. The two-room scenes run at wall thicknesses 1, 2, 5 and 20 cm and
at 0.25x, 1x and 4x the default texel budget (atlas.texels 157286, auto = 629145, 2516582).
Writes OUT/leaks.csv and OUT/leaks.md. Not a test; tools/bench_leaks.sh runs it.

usage: bench_leaks.py OUTDIR LMBAKE [LMBAKE_BEFORE] [--quick]
  --quick: the 2 cm wall at the three densities and the other scenes at 1x only
"""
import csv
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import leak_measure  # noqa: E402
from leak_scenes import WALLS_CM  # noqa: E402

DENSITIES = {"0.25x": 157286, "1x": None, "4x": 2516582}
OTHER = ["box-floor-T", "slab", "courtyard"]
SOLID = {"box-floor-T"}  # the dark region is inside a solid: no probe-lit object can be there
COLUMNS = ["dark_mean", "dark_away_max", "dark_max", "dark_probe_max", "tetra_max", "volume_max"]


def cases(quick):
    out = []
    for t in WALLS_CM:
        for d in DENSITIES:
            if not quick or t == 2:
                out.append(("two-rooms-%d" % t, d))
    out += [(s, "1x") for s in OTHER]
    return out


def bake(lmbake, scenes, work, scene, density, tag):
    cfg = os.path.join(work, "%s-%s.yaml" % (scene, density))
    with open(cfg, "w") as f:
        f.write("atlas:\n  texels: %d\n" % DENSITIES[density] if DENSITIES[density] else "{}\n")
    out = os.path.join(work, "%s-%s-%s" % (scene, density, tag))
    t0 = time.time()
    p = subprocess.run([lmbake, "bake", os.path.join(scenes, scene + ".gltf"), "-c", cfg, "-o", out, "-q"],
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake %s failed: %s" % (out, p.stderr))
    r = leak_measure.measure(out, scene, probes_too=scene not in SOLID)
    r["seconds"] = time.time() - t0
    return r


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    quick = "--quick" in sys.argv
    work, binaries = args[0], args[1:]
    tags = ["after", "before"][:len(binaries)]
    os.makedirs(work, exist_ok=True)
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(HERE, "leak_scenes.py"), scenes], check=True)
    rows = []
    for scene, density in cases(quick):
        for tag, lmbake in reversed(list(zip(tags, binaries))):
            r = bake(lmbake, scenes, work, scene, density, tag)
            r.update({"density": density, "binary": tag})
            rows.append(r)
            print("%-14s %-5s %-6s texel %.2f cm, lit %.1f lux: " % (scene, density, tag, r["texel_cm"], r["lit_mean"]) +
                  ", ".join("%s %.3g (%.3f%%)" % (c, r.get(c, 0), 100 * r.get(c + "_share", 0)) for c in COLUMNS) +
                  ", %.1f s" % r["seconds"], flush=True)
    keys = ["scene", "density", "binary", "texel_cm", "lit_mean", "seconds"] + \
        [k for c in COLUMNS for k in (c, c + "_share")]
    with open(os.path.join(work, "leaks.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, keys, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)
    with open(os.path.join(work, "leaks.md"), "w") as f:
        f.write("| scene | density | binary | texel | lit mean | dark mean | dark texel > 1 texel from wall | dark texel, any |"
                " dark probe | tetrahedra, 0.3 m in | volume, 0.3 m in | bake |\n")
        f.write("|---|---|---|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            cells = ["%.3g lux (%.3f%%)" % (r.get(c, 0), 100 * r.get(c + "_share", 0)) for c in COLUMNS]
            f.write("| %s | %s | %s | %.2f cm | %.1f lux | %s | %.1f s |\n" %
                    (r["scene"], r["density"], r["binary"], r["texel_cm"], r["lit_mean"], " | ".join(cells), r["seconds"]))
    print("wrote %s and %s" % (os.path.join(work, "leaks.csv"), os.path.join(work, "leaks.md")))


if __name__ == "__main__":
    main()
