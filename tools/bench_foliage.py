#!/usr/bin/env python3
"""Foliage benchmark: what alpha-cut leaves cost. A generated level (a 40 x 40 m ground, TREES trees
of a trunk and 24 leaf cards each, double-sided, their base colour texture's alpha a leaf shape
that cuts away 55% of each card: most of the level's triangles are alpha-cut leaves) under a sun
and a sky, baked with no config but the sky (1) as it is, alphaMode MASK, and (2) with the leaves
made opaque (alphaMode removed), side by side in one run. Per bake: wall time, rays, rays/s;
and the ratio of (1) to (2). Writes OUT/foliage.csv and OUT/foliage.md. Not a test;
tools/bench_foliage.sh runs it (a few minutes on 2 cores).

usage: bench_foliage.py LMBAKE OUTDIR [TREES]
"""
import copy
import csv
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from gltf_scene import Scene, box, quad  # noqa: E402

LEAF = 16  # the leaf texture's size: alpha 255 inside an ellipse, 0 outside


def leaf_texture():
    rows = []
    for y in range(LEAF):
        row = []
        for x in range(LEAF):
            u, v = (x + 0.5) / LEAF - 0.5, (y + 0.5) / LEAF - 0.5
            inside = (u / 0.5) ** 2 + (v / 0.3) ** 2 <= 1.0
            row.append((60, 140, 50, 255 if inside else 0))
        rows.append(row)
    return rows


def level(trees, seed=7, panes=False):
    """The foliage level; panes: also a glass pane (transmission 0.9, green) and a veil (BLEND, alpha
    0.4) standing between the trees, so every kind of surface light passes is in it (the
    determinism test bakes it so)."""
    rnd = random.Random(seed)
    s = Scene()
    ground = s.material("ground", (0.4, 0.35, 0.3))
    bark = s.material("bark", (0.3, 0.2, 0.1))
    leaves = s.material("leaves", (1.0, 1.0, 1.0), double_sided=True)
    m = s.doc["materials"][leaves]
    m["alphaMode"] = "MASK"
    m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": s.texture_pixels(leaf_texture())}
    s.mesh("ground", quad((-20, 0, 20), (20, 0, 20), (20, 0, -20), (-20, 0, -20)), ground)
    side = math.ceil(math.sqrt(trees))
    for t in range(trees):
        cx, cz = -16 + 32 * ((t % side) + 0.5) / side, -16 + 32 * ((t // side) + 0.5) / side
        s.mesh("trunk%d" % t, box(cx - 0.15, 0, cz - 0.15, cx + 0.15, 3, cz + 0.15), bark)
        tris = []
        for _ in range(24):
            c = (cx + rnd.uniform(-1.2, 1.2), rnd.uniform(2.5, 4.5), cz + rnd.uniform(-1.2, 1.2))
            a, b = rnd.uniform(0, math.pi), rnd.uniform(-0.6, 0.6)
            e1 = (0.5 * math.cos(a), 0.5 * math.sin(b), 0.5 * math.sin(a))
            e2 = (-0.5 * math.sin(a) * math.cos(b), 0.5 * math.cos(b), 0.5 * math.cos(a) * math.sin(b))
            corner = lambda i, j: tuple(c[k] + i * e1[k] + j * e2[k] for k in range(3))
            tris += quad(corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1))
        # TEXCOORD_0: each card's own [0, 1]^2 (corners in quad order)
        s.mesh("leaves%d" % t, tris, leaves)
        prim = s.doc["meshes"][-1]["primitives"][0]
        uv = [(0, 0), (1, 0), (1, 1), (0, 0), (1, 1), (0, 1)] * 24
        prim["attributes"]["TEXCOORD_0"] = s._accessor(uv, 2)
    if panes:
        glass = s.material("glass", (0.3, 0.9, 0.4))
        s.doc["materials"][glass]["extensions"] = {"KHR_materials_transmission": {"transmissionFactor": 0.9}}
        s.require("KHR_materials_transmission")
        veil = s.material("veil", (0.9, 0.9, 0.9))
        s.doc["materials"][veil]["alphaMode"] = "BLEND"
        s.doc["materials"][veil]["pbrMetallicRoughness"]["baseColorFactor"][3] = 0.4
        s.mesh("glass", quad((-6, 0, 0.5), (6, 0, 0.5), (6, 3, 0.5), (-6, 3, 0.5)), glass)
        s.mesh("veil", quad((0.5, 0, -6), (0.5, 0, 6), (0.5, 3, 6), (0.5, 3, -6)), veil)
    s.light("sun", "directional", 20000.0, rotation=[-0.3535534, 0.3535534, 0.1464466, 0.8535534])
    return s


def bake(lmbake, scene, cfg, out):
    t0 = time.time()
    p = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out], capture_output=True, text=True)
    wall = time.time() - t0
    if p.returncode != 0:
        sys.exit("bake %s failed (%d): %s" % (scene, p.returncode, p.stderr[-2000:]))
    m = re.search(r"bake: ([0-9.]+) s .*?([0-9]+) rays, ([0-9.e+]+) rays/s", p.stdout + p.stderr)
    return wall, int(m.group(2)), float(m.group(3))


def main():
    lmbake, out = sys.argv[1], sys.argv[2]
    trees = int(sys.argv[3]) if len(sys.argv) > 3 else 40
    work = os.path.join(out, "foliage-work")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    s = level(trees)
    cut = os.path.join(work, "foliage.gltf")
    s.write(cut)
    doc = json.load(open(cut))
    del doc["materials"][2]["alphaMode"]
    opaque = os.path.join(work, "foliage-opaque.gltf")
    json.dump(doc, open(opaque, "w"))
    tris = {m["name"]: doc["accessors"][m["primitives"][0]["indices"]]["count"] // 3 for m in doc["meshes"]}
    leaf = sum(v for k, v in tris.items() if k.startswith("leaves"))
    cfg = os.path.join(work, "sky.yaml")
    with open(cfg, "w") as f:
        f.write("sky: {intensity: 3000, color: [0.75, 0.85, 1]}\n")
    rows = []
    for label, scene in (("leaves alpha-cut (MASK)", cut), ("leaves opaque", opaque)):
        wall, rays, rps = bake(lmbake, scene, cfg, os.path.join(work, os.path.basename(scene)[:-5]))
        rows.append({"level": label, "wall_s": round(wall, 2), "rays": rays, "rays_per_s": "%.3g" % rps})
        print("%-24s %7.2f s  %12d rays  %.3g rays/s" % (label, wall, rays, rps), flush=True)
    ratio = rows[0]["wall_s"] / rows[1]["wall_s"]
    with open(os.path.join(out, "foliage.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(out, "foliage.md"), "w") as f:
        f.write("%d trees, %d triangles, %d of them leaf cards (%.0f%%)\n\n" %
                (trees, sum(tris.values()), leaf, 100.0 * leaf / sum(tris.values())))
        f.write("| level | wall s | rays | rays/s |\n|---|---|---|---|\n")
        for r in rows:
            f.write("| %s | %s | %s | %s |\n" % (r["level"], r["wall_s"], r["rays"], r["rays_per_s"]))
        f.write("\nalpha-cut / opaque: %.2fx\n" % ratio)
    print("%d of %d triangles are leaf cards; alpha-cut / opaque wall time: %.2fx" % (leaf, sum(tris.values()), ratio))


if __name__ == "__main__":
    main()
