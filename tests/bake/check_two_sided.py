#!/usr/bin/env python3
"""The back of a doubleSided surface reflects (glTF: both sides are front).

usage: check_two_sided.py LMBAKE WORKDIR

tools/make_scenes.py two-sided-card: a sunlit ground (albedo 0.5, sun straight down, 1000 lux)
under a 2 x 2 card (albedo 0.8, doubleSided, facing up) 1 m above it. The ground under the card
is in the card's shadow and sees no other ground (a plane): its light is what the card's
underside reflects, and the underside is lit by the sunlit ground around the shadow. The
ground's mean irradiance within 0.5 m of the point under the card's centre, in three bakes with
6 bounces (near convergence: the back's light is estimated from the cache's, which holds one
bounce more than a front's, so the two count bounces alike only in the limit):
  - the defaults (auto texel density, the irradiance cache, the denoiser),
  - the path-traced --reference (2048 paths per texel at 8 texels per unit: the mean over the
    region does not depend on the texel size),
  - materials.reflect_sides: front (backs dark, as before): under 1 lux.
The defaults must be within 3% of the reference and above 50 lux.
"""
import json
import os
import struct
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import bake_cli  # noqa: E402


def accessor(doc, bins, index):
    a = doc["accessors"][index]
    v = doc["bufferViews"][a["bufferView"]]
    comps = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[a["type"]]
    fmt = {5126: "f", 5125: "I", 5123: "H"}[a["componentType"]]
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    stride = v.get("byteStride", struct.calcsize(fmt) * comps)
    return np.array([struct.unpack_from("<%d%s" % (comps, fmt), bins[v["buffer"]], start + i * stride)
                     for i in range(a["count"])])


def ground_mean(out, half=0.5):
    """Mean irradiance (luminance) of the ground's texels whose centres lie within `half` of (0, 0)
    in x and z, found through the output's TEXCOORD_1 (texel centres, barycentric in numpy)."""
    name = [f for f in os.listdir(out) if f.endswith(".gltf")][0]
    doc = json.load(open(os.path.join(out, name)))
    bins = [open(os.path.join(out, b["uri"]), "rb").read() for b in doc["buffers"]]
    node = [n for n in doc["nodes"] if n.get("name") == "ground"][0]
    prim = doc["meshes"][node["mesh"]]["primitives"][0]
    tex = doc["materials"][prim["material"]]["extensions"]["MOZ_lightmap"]["index"]
    img = oiio.ImageBuf(os.path.join(out, doc["images"][doc["textures"][tex]["source"]]["uri"][:-4] + ".exr"))
    rgb = img.get_pixels(oiio.FLOAT)[..., :3]
    h, w = rgb.shape[:2]
    pos = accessor(doc, bins, prim["attributes"]["POSITION"])
    uv = accessor(doc, bins, prim["attributes"]["TEXCOORD_1"]) * [w, h]
    idx = accessor(doc, bins, prim["indices"]).reshape(-1, 3)
    ys, xs = np.mgrid[0:h, 0:w]
    cx, cy = xs.ravel() + 0.5, ys.ravel() + 0.5
    picked = np.zeros(h * w, bool)
    for tri in idx:
        (ax, ay), (bx, by), (qx, qy) = uv[tri]
        det = (bx - ax) * (qy - ay) - (qx - ax) * (by - ay)
        b1 = ((cx - ax) * (qy - ay) - (qx - ax) * (cy - ay)) / det
        b2 = ((bx - ax) * (cy - ay) - (cx - ax) * (by - ay)) / det
        inside = (b1 >= 0) & (b2 >= 0) & (b1 + b2 <= 1)
        p = (1 - b1 - b2)[:, None] * pos[tri[0]] + b1[:, None] * pos[tri[1]] + b2[:, None] * pos[tri[2]]
        picked |= inside & (np.abs(p[:, 0]) < half) & (np.abs(p[:, 2]) < half)
    lum = rgb.reshape(-1, 3)[picked] @ np.array([0.2126, 0.7152, 0.0722])
    return float(lum.mean()), int(picked.sum())


def bake(lmbake, work, scene, name, config, args=()):
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write("bounces: 6\nlights: {sun_angle: 0}\noutput: {formats: [exr]}\n" + config)
    out = os.path.join(work, name)
    p = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out, "-q"] + list(args), capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake %s failed (%d): %s" % (name, p.returncode, p.stderr))
    return ground_mean(out)


def main():
    lmbake, work = sys.argv[1], sys.argv[2]
    scenes = bake_cli.scenes(work)
    scene = os.path.join(scenes, "two-sided-card.gltf")
    got, n = bake(lmbake, work, scene, "defaults", "")
    ref, m = bake(lmbake, work, scene, "reference", "texel_density: 8\n", ("--reference", "--rays", "2048"))
    front, _ = bake(lmbake, work, scene, "front", "texel_density: 8\nmaterials: {reflect_sides: front}\n")
    rel = got / ref - 1
    ok = abs(rel) <= 0.03 and got > 50 and front < 1
    print("two-sided card: ground under it, mean E: defaults %.2f lux (%d texels), path-traced reference %.2f lux "
          "(%d texels): %+.2f%% (bound 3%%); with backs that reflect nothing (materials.reflect_sides: front) "
          "%.2f lux  %s" % (got, n, ref, m, 100 * rel, front, "ok" if ok else "FAIL"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
