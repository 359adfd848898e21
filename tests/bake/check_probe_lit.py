#!/usr/bin/env python3
"""Props the texel budget cannot hold are lit by the light probes (docs/unwrap.md#props-lit-by-the-probes).

tools/make_levels.py gpu:60: a ground and 60 copies of an 18-chart prop through one
EXT_mesh_gpu_instancing node, under a sun, baked with atlas.texels 4,000: the copies' charts
alone take about 7,000 texels at any density. Asserted:
  - the warning names the mesh and its 60 copies and what their charts take (over the budget);
  - the bake makes at most 110% of the budget (the ground's texels);
  - the output: the prop's mesh has no TEXCOORD_1 and its instancing node no per-copy lightmap
    rectangle; the ground's has both TEXCOORD_1 and its lightmap;
  - the probes cover the props: every copy's position has a probe within 1.5 cells (probes
    spacing) and the probes' heights span the props' (some probe below the tallest prop top,
    some above the ground);
  - the props still cast shadows: over 5% of the ground's texels get under half its median
    light;
  - `lmbake farm parallel` in 2 shards writes the same files, byte for byte;
  - `lmbake inspect` (before any layout) says that the mesh drawn 60 times may go to the probes.

usage: check_probe_lit.py LMBAKE WORKDIR
"""
import filecmp
import json
import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
ok = True


def check(cond, what):
    global ok
    ok &= bool(cond)
    print("%s %s" % ("ok  " if cond else "FAIL", what))


def accessor(doc, blobs, index):
    import numpy as np
    a = doc["accessors"][index]
    v = doc["bufferViews"][a["bufferView"]]
    comps = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[a["type"]]
    dtype = {5126: np.float32, 5125: np.uint32}[a["componentType"]]
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    raw = blobs[v["buffer"]][start:start + a["count"] * comps * np.dtype(dtype).itemsize]
    return np.frombuffer(raw, dtype=dtype).reshape(a["count"], comps)


def main():
    import numpy as np
    lmbake, work = sys.argv[1:3]
    os.makedirs(work, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_levels.py"), work, "gpu:60"], check=True,
                   stdout=subprocess.DEVNULL)
    level = os.path.join(work, "level-gpu-60.glb")
    config = os.path.join(work, "budget.yaml")
    with open(config, "w") as f:
        f.write("atlas:\n  texels: 4000\noutput:\n  formats: [exr, mask]\n")
    p = subprocess.run([lmbake, "inspect", level, "-c", config], capture_output=True, text=True, timeout=120)
    check(p.returncode == 0
          and "1 lightmapped mesh(es) drawn more than once, 60 copies: if the texel budget cannot hold their charts, "
              "the bake lights them by the light probes" in p.stdout,
          "inspect says the prop's 60 copies may be lit by the probes")
    out = os.path.join(work, "out")
    shutil.rmtree(out, ignore_errors=True)
    p = subprocess.run([lmbake, "bake", level, "-c", config, "-o", out], capture_output=True, text=True, timeout=600)
    check(p.returncode == 0, "bake exits 0")
    if p.returncode != 0:
        print(p.stderr[-2000:])
        sys.exit(1)
    m = re.search(r"texel budget: 60 instance\(s\) of 1 mesh\(es\) drawn many times are lit by the light probes, not "
                  r"the lightmap: 'Prop' \(60\)\. With them every chart together takes about ([0-9]+) texels", p.stderr)
    check(m and int(m.group(1)) > 4000, "the warning names 'Prop' and its 60 copies, their charts' %s texels"
          % (m.group(1) if m else "?"))
    texels = re.search(r"bake: .* ([0-9]+) texels \(([0-9]+) valid\)", p.stdout)
    check(texels and 0 < int(texels.group(1)) <= 4400, "texels made: %s (at most 4,400)" % (texels.group(1) if texels else "?"))

    gltf = os.path.join(out, "level-gpu-60.gltf")
    doc = json.load(open(gltf))
    blobs = [open(os.path.join(out, b["uri"]), "rb").read() for b in doc["buffers"]]
    nodes = {n.get("name"): n for n in doc["nodes"]}
    props, ground = nodes["Props"], nodes["Ground"]
    prop_prims = doc["meshes"][props["mesh"]]["primitives"]
    ground_prims = doc["meshes"][ground["mesh"]]["primitives"]
    inst = props["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]
    check(all("TEXCOORD_1" not in q["attributes"] for q in prop_prims) and not any(k.startswith("_LIGHTMAP") for k in inst),
          "the prop's mesh has no TEXCOORD_1, its copies no lightmap rectangle (attributes: %s)" % sorted(inst))
    check(all("TEXCOORD_1" in q["attributes"] for q in ground_prims), "the ground keeps its TEXCOORD_1")

    probes = doc["asset"]["extras"]["lightmap"]["probes"]
    pos = accessor(doc, blobs, probes["positions"])
    spacing = probes["spacing"]
    copies = accessor(doc, blobs, inst["TRANSLATION"])
    scale = accessor(doc, blobs, inst["SCALE"])[:, 0]
    d = np.sqrt(((copies[:, None, :] - pos[None, :, :]) ** 2).sum(-1)).min(1)
    check(float(d.max()) <= 1.5 * spacing, "every copy has a probe within %.3g (1.5 cells of %.3g): farthest %.3g"
          % (1.5 * spacing, spacing, float(d.max())))
    top = float((copies[:, 1] + 1.15 * scale).max())  # the prop's radius is at most 1.15 (bumps)
    check(float(pos[:, 1].min()) < top and float(pos[:, 1].max()) > 0,
          "probe heights %.3g..%.3g reach the props (ground 0, tops up to %.3g)" % (pos[:, 1].min(), pos[:, 1].max(), top))
    import OpenImageIO as oiio
    exr = [n for n in os.listdir(out) if n.endswith(".exr") and not n.endswith("-dir.exr")]
    mask = [n for n in os.listdir(out) if n.endswith("-mask.png")]
    e = np.array(oiio.ImageBuf(os.path.join(out, exr[0])).get_pixels(oiio.FLOAT))[..., :3].mean(-1)
    lit = np.array(oiio.ImageBuf(os.path.join(out, mask[0])).get_pixels(oiio.UINT8))[..., 0] == 255
    open_ground = float(np.median(e[lit]))
    shadowed = float((e[lit] < 0.5 * open_ground).mean())
    check(len(exr) == 1 and shadowed > 0.05, "the props' shadows: %.1f%% of the ground's texels under half the median "
          "light %.4g" % (100 * shadowed, open_ground))

    farm = os.path.join(work, "farm")
    farm_out = os.path.join(work, "farm-out")
    for d_ in (farm, farm_out):
        shutil.rmtree(d_, ignore_errors=True)
    p = subprocess.run([lmbake, "farm", "parallel", level, "-c", config, "--farm", farm, "-o", farm_out, "--shards", "2",
                        "--threads", "1"], capture_output=True, text=True, timeout=900)
    check(p.returncode == 0, "farm parallel exits 0")
    names = sorted(os.listdir(out))
    same = p.returncode == 0 and names == sorted(os.listdir(farm_out)) and \
        all(filecmp.cmp(os.path.join(out, n), os.path.join(farm_out, n), shallow=False) for n in names)
    check(same, "farm parallel (2 shards) = bake, %d files byte for byte" % len(names))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
