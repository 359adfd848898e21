#!/usr/bin/env python3
"""texel_density: auto (issue 10) through `lmbake unwrap`, which reports the density chosen and
the texels covered:
  - the generated 1 m Cornell box (tools/make_scenes.py cornell-point) scaled by 0.001, 1 and
    1000 (a root node with that scale): the covered texels agree within 5% and the density
    scales as 1/s (within 0.1%);
  - that 1-unit scene and bevy's Cornell box (millimetres, ~560 units across) both get
    100k-1M texels with no config file;
  - atlas.min_chart_texels: a 5 cm cube on a 100 m ground. At the defaults (4) each of the
    cube's faces spans at least 4 texels (about 0.4 without the floor, which the test also
    checks) and the ground keeps at least 99% of its density (the budget shrinks the rest).

usage: check_auto_density.py LMBAKE WORKDIR BEVY_CORNELL_GLB
"""
import json
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def unwrap(lmbake, scene, config=None, want_sizes=False):
    p = subprocess.run([lmbake, "unwrap", scene, "-q"] + (["-c", config] if config else []), capture_output=True,
                       text=True, timeout=600)
    if p.returncode != 0:
        sys.exit("unwrap %s failed (%d): %s" % (scene, p.returncode, p.stderr))
    d = re.search(r"texel density: auto, ([0-9.eE+-]+) texels per unit", p.stdout)
    t = re.search(r"texels: ([0-9]+) covered", p.stdout)
    if not d or not t:
        sys.exit("unwrap %s: no density/texels line in:\n%s" % (scene, p.stdout[-800:]))
    if want_sizes:
        c = re.search(r"smallest typical chart ([0-9.]+) texels across \(instance '([^']*)'\)", p.stdout)
        if not c:
            sys.exit("unwrap %s: no chart sizes line in:\n%s" % (scene, p.stdout[-800:]))
        return float(d.group(1)), int(t.group(1)), float(c.group(1)), c.group(2)
    return float(d.group(1)), int(t.group(1))


def prop_on_ground(path):
    """A 100 m square ground (two triangles) and a 5 cm cube standing on it, as glTF."""
    import base64
    import struct
    g = 50.0
    pos = [(-g, 0, -g), (g, 0, -g), (g, 0, g), (-g, 0, g)]
    idx = [0, 2, 1, 0, 3, 2]
    h = 0.025
    faces = [((1, 0, 0), (0, 1, 0)), ((-1, 0, 0), (0, 1, 0)), ((0, 1, 0), (0, 0, 1)), ((0, -1, 0), (0, 0, 1)),
             ((0, 0, 1), (1, 0, 0)), ((0, 0, -1), (1, 0, 0))]
    cube_pos, cube_idx = [], []
    for n, u in faces:
        v = (n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0])
        base = len(cube_pos)
        for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            cube_pos.append(tuple(h * (n[k] + a * u[k] + b * v[k]) + (h if k == 1 else 0) for k in range(3)))
        cube_idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    blob = b"".join(struct.pack("<3f", *p) for p in pos + cube_pos)
    nv0 = len(blob)
    blob += struct.pack("<%dI" % len(idx), *idx) + struct.pack("<%dI" % len(cube_idx), *[i for i in cube_idx])
    def box(ps):
        return [min(p[k] for p in ps) for k in range(3)], [max(p[k] for p in ps) for k in range(3)]
    (g0, g1), (c0, c1) = box(pos), box(cube_pos)
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0, "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"name": "Ground", "mesh": 0}, {"name": "Pebble", "mesh": 1, "translation": [3, 0, 2]}],
        "meshes": [{"name": "Ground", "primitives": [{"attributes": {"POSITION": 0}, "indices": 2}]},
                   {"name": "Cube", "primitives": [{"attributes": {"POSITION": 1}, "indices": 3}]}],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": nv0},
                        {"buffer": 0, "byteOffset": nv0, "byteLength": len(blob) - nv0}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": g0, "max": g1},
            {"bufferView": 0, "byteOffset": 48, "componentType": 5126, "count": 24, "type": "VEC3", "min": c0,
             "max": c1},
            {"bufferView": 1, "componentType": 5125, "count": 6, "type": "SCALAR"},
            {"bufferView": 1, "byteOffset": 24, "componentType": 5125, "count": 36, "type": "SCALAR"}],
    }
    with open(path, "w") as f:
        json.dump(doc, f)


def check_small_prop(lmbake, work):
    scene, off = os.path.join(work, "pebble.gltf"), os.path.join(work, "min-chart-0.yaml")
    prop_on_ground(scene)
    with open(off, "w") as f:
        f.write("atlas:\n  min_chart_texels: 0\n")
    d_on, t_on, c_on, who_on = unwrap(lmbake, scene, None, True)
    d_off, t_off, c_off, who_off = unwrap(lmbake, scene, off, True)
    print("5 cm cube on a 100 m ground: min_chart_texels 4: smallest typical chart %.2f texels ('%s'), ground %.4g "
          "texels per unit; min_chart_texels 0: %.2f texels ('%s'), %.4g" % (c_on, who_on, d_on, c_off, who_off, d_off))
    ok = True
    if who_on != "Pebble" or who_off != "Pebble" or not c_on >= 3.99:
        print("FAIL: the cube's faces should span at least 4 texels at the defaults")
        ok = False
    if not c_off < 1.0:
        print("FAIL: without the floor the cube's faces should span under a texel (the floor is not what lit it)")
        ok = False
    if not d_on >= 0.99 * d_off:
        print("FAIL: the ground lost more than 1% of its density to the cube")
        ok = False
    return ok


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
    ok &= check_small_prop(lmbake, work)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
