#!/usr/bin/env python3
"""What moves is not scenery: skinned meshes, morph targets and lower levels of detail.

usage: check_moving.py LMBAKE WORKDIR

tools/make_scenes.py moving.gltf: a ground under a 1000-lux sun straight down and six 1 m boxes
floating 0.5 m above it (MOVING): a skinned Character, a Blob with a morph target, Crate_LOD0 and
its sibling Crate_LOD1, a Rock whose MSFT_lod names RockFar. Checked, texel by texel (bounces 0,
the sun's disc 0, so the ground's light is exactly 1000 lux or 0):
  - the ground under each static box (Crate_LOD0, Rock) is in shadow (0), under each moving or
    lower-LOD one lit (1000): they cast no baked shadow;
  - the moving ones have no lightmap in the output (no TEXCOORD_1), the static ones have one;
  - the light probes cover them: a probe within 1 m of each one's centre;
  - the log names them (1 skinned, 1 morphing, 2 lower-LOD);
and moving-static.gltf (the Character's extras.lightmap: true): the Character is lightmapped and
the ground under it is in shadow.
"""
import json
import os
import struct
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import bake_cli  # noqa: E402
sys.path.insert(0, os.path.join(ROOT, "tools"))
from check_analytic import load_output, texels  # noqa: E402
from make_scenes import MOVING  # noqa: E402

CONFIG = "texel_density: 8\nbounces: 0\nlights: {sun_angle: 0}\nsamples: {texel: 4}\n"


def bake(lmbake, work, scenes, name):
    out = os.path.join(work, name)
    p = subprocess.run([lmbake, "bake", os.path.join(scenes, name + ".gltf"), "-c", os.path.join(work, "c.yaml"), "-o",
                        out], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake %s failed (%d): %s" % (name, p.returncode, p.stderr[-2000:]))
    return out, p.stdout + p.stderr


def under(charts, images):
    """{box name: [ground texel values (luminance) whose points all lie within 0.4 of its centre]}"""
    vals = {k: [] for k in MOVING}
    for node, v, pts, x, y, _ in texels(charts, images):
        if node != "ground":
            continue
        for name, ((cx, cz), _) in MOVING.items():
            if all(abs(p[0] - cx) < 0.4 and abs(p[2] - cz) < 0.4 for p in pts):
                vals[name].append(float(np.mean(v)))
    return vals


def probes(out):
    name = [f for f in os.listdir(out) if f.endswith(".gltf")][0]
    doc = json.load(open(os.path.join(out, name)))
    info = doc["asset"]["extras"]["lightmap"]["probes"]
    a = doc["accessors"][info["positions"]]
    v = doc["bufferViews"][a["bufferView"]]
    data = open(os.path.join(out, doc["buffers"][v["buffer"]]["uri"]), "rb").read()
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    pos = np.array(struct.unpack_from("<%df" % (3 * a["count"]), data, start)).reshape(-1, 3)
    mapped = {n["name"]: "TEXCOORD_1" in doc["meshes"][n["mesh"]]["primitives"][0]["attributes"]
              for n in doc["nodes"] if "mesh" in n}
    return pos, mapped


def main():
    lmbake, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    scenes = bake_cli.scenes(work)
    with open(os.path.join(work, "c.yaml"), "w") as f:
        f.write(CONFIG)
    ok = True
    out, log = bake(lmbake, work, scenes, "moving")
    said = "what moves: 1 skinned, 1 morphing and 2 lower-LOD instance(s)" in log
    print("log names them: %s" % ("ok" if said else "FAIL"))
    ok &= said
    vals = under(*load_output(out))
    pos, mapped = probes(out)
    for name, ((cx, cz), static) in MOVING.items():
        v = np.array(vals[name])
        want = 0.0 if static else 1000.0
        near = np.min(np.linalg.norm(pos - np.array([cx, 1.0, cz]), axis=1))
        good = v.size >= 9 and np.all(np.abs(v - want) <= 1e-3 * 1000) and mapped.get(name) == static and near <= 1.0
        ok &= bool(good)
        print("%-10s %-7s ground under it: %d texels, %.1f..%.1f lux (want %.0f); lightmapped %s; nearest probe %.2f m  "
              "%s" % (name, "static" if static else "moves", v.size, v.min() if v.size else -1, v.max() if v.size else -1,
                      want, mapped.get(name), near, "ok" if good else "FAIL"))
    out, log = bake(lmbake, work, scenes, "moving-static")
    v = np.array(under(*load_output(out))["Character"])
    _, mapped = probes(out)
    good = v.size >= 9 and np.all(v <= 1.0) and mapped.get("Character") is True
    ok &= bool(good)
    print("extras.lightmap: true on the Character: lightmapped %s, ground under it %.1f..%.1f lux (want 0)  %s" %
          (mapped.get("Character"), v.min() if v.size else -1, v.max() if v.size else -1, "ok" if good else "FAIL"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
