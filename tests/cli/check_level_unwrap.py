#!/usr/bin/env python3
"""The unwrap on a generated level (tools/make_levels.py single:2, 2,332 triangles of soup: quads
whose second triangle OpenMesh re-added on copied vertices, rows of touching crates, thin walls,
stairs), through `lmbake unwrap`:
  - at the defaults: the faces pressed together (crates touching, feet of walls, crates, pillars
    and stairs on the floor, a lintel on its wall) hidden: at least 400 of the 2,332 triangles (530
    now), the log saying so; at most 300 charts, 0 overlapping texels, L2 stretch at most 1.001,
    coverage at least 0.82 (0.846 now);
  - with `atlas.skip_hidden: false`: none hidden, at most 486 charts (0.6 x the 810 before coplanar
    links and gluing; 436 now), 0 overlapping texels, coverage at least 0.75 (0.776 now; 0.70
    before gluing) and below the defaults;
  - an explicit density above the fit estimate but within what the packer places (14 texels per
    unit in a 1024 atlas; the estimate is about 12.9) bakes, and says the packer decided;
  - one the packer cannot place (15) is exit 2, naming the instance and the estimate;
  - across nodes: a one-sided floor with a crate mesh placed by one node, a mirrored node's crate
    (scale -1: its winding turned) and a crate mesh two nodes share, all standing on it: the two
    crates placed once lose their bottoms (2 triangles each), the shared mesh keeps its own (what
    hides it does not move with its layout), the floor, larger than what covers it, keeps all.

usage: check_level_unwrap.py LMBAKE WORKDIR
"""
import base64
import json
import os
import re
import struct
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
ok = True


def check(cond, what):
    global ok
    ok &= bool(cond)
    print("%s %s" % ("ok  " if cond else "FAIL", what))


def unwrap(lmbake, level, work, text):
    config = os.path.join(work, "level.yaml")
    with open(config, "w") as f:
        f.write(text)
    return subprocess.run([lmbake, "unwrap", level, "-c", config], capture_output=True, text=True, timeout=600)


def atlas_line(out):
    m = re.search(r"atlas 0: ([0-9]+)x([0-9]+), ([0-9]+) charts, coverage ([0-9.]+), L2 stretch ([0-9.]+).*"
                  r"overlapping texels ([0-9]+)", out)
    if not m:
        sys.exit("no atlas line in:\n" + out[-1500:])
    return int(m.group(1)), int(m.group(2)), int(m.group(3)), float(m.group(4)), float(m.group(5)), int(m.group(6))


def hidden_count(out, mesh="Level"):
    m = re.search(r"mesh '%s': [0-9]+ triangles \([0-9]+ zero-area, ([0-9]+) hidden\)" % mesh, out)
    if not m:
        sys.exit("no mesh line for '%s' in:\n" % mesh + out[-1500:])
    return int(m.group(1))


def box(x0, y0, z0, x1, y1, z1):
    """8 corners and 12 outward triangles of an axis-aligned box."""
    p = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    quads = [(0, 1, 5, 4), (3, 7, 6, 2), (0, 3, 2, 1), (4, 5, 6, 7), (0, 4, 7, 3), (1, 2, 6, 5)]
    return p, [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]


def nodes_level(path):
    """A floor plane (8 x 8, one-sided, facing up) and crates standing on it, each a node."""
    meshes = [("Floor", [(-4, 0, -4), (-4, 0, 4), (4, 0, 4), (4, 0, -4)], [(0, 1, 2), (0, 2, 3)]),
              ("Crate", *box(-0.5, 0, -0.5, 0.5, 1, 0.5)), ("Mirrored", *box(-0.5, 0, -0.5, 0.5, 1, 0.5)),
              ("Shared", *box(-0.5, 0, -0.5, 0.5, 1, 0.5))]
    blob, views, accessors, gmeshes = b"", [], [], []
    for name, pos, tris in meshes:
        for data, target, comp, kind, count in ((struct.pack("<%df" % (3 * len(pos)), *[c for v in pos for c in v]),
                                                  34962, 5126, "VEC3", len(pos)),
                                                 (struct.pack("<%dI" % (3 * len(tris)), *[i for t in tris for i in t]),
                                                  34963, 5125, "SCALAR", 3 * len(tris))):
            views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
            acc = {"bufferView": len(views) - 1, "componentType": comp, "count": count, "type": kind}
            if kind == "VEC3":
                acc["min"] = [min(v[k] for v in pos) for k in range(3)]
                acc["max"] = [max(v[k] for v in pos) for k in range(3)]
            accessors.append(acc)
            blob += data
        gmeshes.append({"name": name, "primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                                      "indices": len(accessors) - 1}]})
    nodes = [{"name": "floor", "mesh": 0}, {"name": "crate", "mesh": 1, "translation": [-2, 0, -2]},
             {"name": "mirrored", "mesh": 2, "translation": [2, 0, -2], "scale": [-1, 1, 1]},
             {"name": "shared 1", "mesh": 3, "translation": [-2, 0, 2]},
             {"name": "shared 2", "mesh": 3, "translation": [2, 0, 2]}]
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes,
           "meshes": gmeshes, "accessors": accessors, "bufferViews": views,
           "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64,"
                        + base64.b64encode(blob).decode()}]}
    with open(path, "w") as f:
        json.dump(doc, f)


def separate_nodes(lmbake, work):
    level = os.path.join(work, "nodes.gltf")
    nodes_level(level)
    p = unwrap(lmbake, level, work, "{}\n")
    check(p.returncode == 0, "nodes: unwrap exits 0")
    if p.returncode != 0:
        print(p.stderr[-1500:])
        return
    got = {m: hidden_count(p.stdout, m) for m in ("Floor", "Crate", "Mirrored", "Shared")}
    check(got == {"Floor": 0, "Crate": 2, "Mirrored": 2, "Shared": 0},
          "nodes: hidden per mesh %s (the bottoms of the crates placed once)" % got)
    w, h, charts, coverage, stretch, overlaps = atlas_line(p.stdout)
    check(overlaps == 0, "nodes: %d overlapping texels" % overlaps)


def main():
    lmbake, work = sys.argv[1:3]
    os.makedirs(work, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_levels.py"), work, "single:2"], check=True,
                   stdout=subprocess.DEVNULL)
    level = os.path.join(work, "level-single-2.glb")
    p = unwrap(lmbake, level, work, "{}\n")
    check(p.returncode == 0, "defaults: unwrap exits 0")
    hidden = hidden_count(p.stdout)
    check(hidden >= 400, "defaults: %d triangles hidden (at least 400)" % hidden)
    check(re.search(r"layout: %d of 2332 triangles .* lie back to back with another face inside a solid" % hidden,
                    p.stdout + p.stderr), "defaults: the log says how many were hidden")
    w, h, charts, coverage, stretch, overlaps = atlas_line(p.stdout)
    check(charts <= 300, "defaults: %d charts (at most 300)" % charts)
    check(overlaps == 0, "defaults: %d overlapping texels" % overlaps)
    check(stretch <= 1.001, "defaults: L2 stretch %.4f (at most 1.001)" % stretch)
    check(coverage >= 0.82, "defaults: coverage %.4f (at least 0.82)" % coverage)
    p = unwrap(lmbake, level, work, "atlas: {skip_hidden: false}\n")
    w, h, all_charts, all_coverage, stretch, overlaps = atlas_line(p.stdout)
    check(p.returncode == 0 and hidden_count(p.stdout) == 0, "skip_hidden false: none hidden")
    check(all_charts <= 486 and all_charts > charts, "skip_hidden false: %d charts (at most 486, more than %d)"
          % (all_charts, charts))
    check(overlaps == 0, "skip_hidden false: %d overlapping texels" % overlaps)
    check(0.75 <= all_coverage < coverage, "skip_hidden false: coverage %.4f (at least 0.75, below %.4f)"
          % (all_coverage, coverage))
    p = unwrap(lmbake, level, work, "texel_density: 14\natlas: {max_size: 1024}\n")
    check(p.returncode == 0 and "the packer decides" in p.stderr + p.stdout,
          "14 texels per unit in a 1024 atlas: above the estimate, packed (exit %d)" % p.returncode)
    if p.returncode == 0:
        w, h, charts, coverage, stretch, overlaps = atlas_line(p.stdout)
        check(w <= 1024 and h <= 1024 and overlaps == 0, "  atlas %dx%d, %d overlapping texels" % (w, h, overlaps))
    p = unwrap(lmbake, level, work, "texel_density: 15\natlas: {max_size: 1024}\n")
    check(p.returncode == 2 and "instance 'Level'" in p.stderr and "is estimated to fit" in p.stderr
          and "atlas 0:" not in p.stdout,
          "15 texels per unit: exit %d, the packer's error names the instance and the estimate" % p.returncode)
    separate_nodes(lmbake, work)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
