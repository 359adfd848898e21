#!/usr/bin/env python3
"""texel_density: auto (issue 10) through `lmbake unwrap`, which reports the density chosen and
the texels covered:
  - the generated 1 m Cornell box (tools/make_scenes.py cornell-point) scaled by 0.001, 1 and
    1000 (a root node with that scale): the covered texels agree within 5% and the density
    scales as 1/s (within 0.1%);
  - that 1-unit scene and bevy's Cornell box (millimetres, ~560 units across) both get
    100k-1M texels with no config file.

usage: check_auto_density.py LMBAKE WORKDIR BEVY_CORNELL_GLB
"""
import json
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def unwrap(lmbake, scene):
    p = subprocess.run([lmbake, "unwrap", scene, "-q"], capture_output=True, text=True, timeout=600)
    if p.returncode != 0:
        sys.exit("unwrap %s failed (%d): %s" % (scene, p.returncode, p.stderr))
    d = re.search(r"texel density: auto, ([0-9.eE+-]+) texels per unit", p.stdout)
    t = re.search(r"texels: ([0-9]+) covered", p.stdout)
    if not d or not t:
        sys.exit("unwrap %s: no density/texels line in:\n%s" % (scene, p.stdout[-800:]))
    return float(d.group(1)), int(t.group(1))


def scaled(src, dst, s):
    doc = json.load(open(src))
    roots = doc["scenes"][doc.get("scene", 0)]["nodes"]
    doc["nodes"].append({"name": "scale", "scale": [s, s, s], "children": roots})
    doc["scenes"][doc.get("scene", 0)]["nodes"] = [len(doc["nodes"]) - 1]
    with open(dst, "w") as f:
        json.dump(doc, f)


def main():
    lmbake, work, bevy = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), work], check=True,
                   stdout=subprocess.DEVNULL)
    base = os.path.join(work, "cornell-point.gltf")
    ok = True
    results = {}
    for s in (0.001, 1.0, 1000.0):
        path = os.path.join(work, "cornell-x%g.gltf" % s)
        scaled(base, path, s)
        results[s] = unwrap(lmbake, path)
        print("scale %-6g: density %.6g texels per unit, %d texels covered" % (s, results[s][0], results[s][1]))
    d1, t1 = results[1.0]
    for s, (d, t) in results.items():
        if abs(t / t1 - 1) > 0.05:
            print("FAIL: scale %g covers %d texels, scale 1 %d (more than 5%% apart)" % (s, t, t1))
            ok = False
        if abs(d * s / d1 - 1) > 1e-3:
            print("FAIL: scale %g: density %g, expected %g (1/s)" % (s, d, d1 / s))
            ok = False
    for name, path in (("1-unit Cornell box", base), ("bevy Cornell box (mm)", bevy)):
        d, t = unwrap(lmbake, path)
        good = 100000 <= t <= 1000000
        ok &= good
        print("%s: density %.4g, %d texels covered (100k-1M)  %s" % (name, d, t, "ok" if good else "FAIL"))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
