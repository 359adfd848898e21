#!/usr/bin/env python3
"""Lightmaps for EXT_mesh_gpu_instancing copies (docs/unwrap.md "Instanced copies").

usage: check_instancing.py LMBAKE WORKDIR CASE   (CASE: copies, shared)

copies:
instanced-boxes.gltf (tools/make_scenes.py): a 30 x 30 ground, 576 boxes drawn through one
EXT_mesh_gpu_instancing node (every other one 1.5 x larger), a roof 3 above the x < 0 half, a sun
30 degrees off vertical. Baked with no config but a smaller texel budget:
  - every copy is lightmapped: the node's _LIGHTMAP_SCALE and _LIGHTMAP_OFFSET hold 576 non-empty
    rectangles, one mesh and one TEXCOORD_1 for all of them (no copy of the mesh per instance);
  - the rectangles lie in [0, 1], do not overlap, and the 1.5 x copies' are 1.5 x larger (within a
    texel); every triangle's centroid, through its copy's rectangle, lands on a texel no other copy
    covers, valid for 99% of them;
  - the light is right: the tops of copies in the open get the sun's 866 lux (1000 lux at 30
    degrees) plus what bounces, within [866, 1.3 x 866]; copies under the roof are darker than a
    third of that;
  - Khronos' validator finds 0 errors.
shared: seams.gltf (two floor tiles, nodes tile and tile_b, one mesh; a point light) with
atlas.share_meshes: one lightmapped mesh in the output used by both nodes, two disjoint
rectangles in extras.lightmap.scaleOffset, and the light at 400 points of each tile (the
lightmap through the node's rectangle) equal to a bake with a copy per node within the two
bakes' noise: the rms difference at most 1.5 x that between two seeds of the copies' bake.
"""
import json
import math
import os
import shutil
import struct
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from object_means import _accessor, _image, claim_texels, cover_pairs  # noqa: E402

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def bilinear(img, u, v):
    h, w = img.shape[:2]
    x, y = np.clip(u * w - 0.5, 0, w - 1.001), np.clip(v * h - 0.5, 0, h - 1.001)
    x0, y0 = x.astype(int), y.astype(int)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    return ((1 - fx) * (1 - fy) * img[y0, x0] + fx * (1 - fy) * img[y0, x0 + 1] +
            (1 - fx) * fy * img[y0 + 1, x0] + fx * fy * img[y0 + 1, x0 + 1])


def bake(lmbake, work, scene, name, config):
    out = os.path.join(work, name)
    shutil.rmtree(out, ignore_errors=True)
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(config)
    p = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake %s failed: %s" % (name, p.stderr[-2000:]))
    gltf = [f for f in os.listdir(out) if f.endswith(".gltf")][0]
    doc = json.load(open(os.path.join(out, gltf)))
    return out, doc, [open(os.path.join(out, b["uri"]), "rb").read() for b in doc["buffers"]]


def tile_light(out, doc, bins, name, grid=20):
    """Luminance of the lightmap at grid x grid points of node `name`'s surface, through its rectangle."""
    node = next(n for n in doc["nodes"] if n.get("name") == name)
    so = node["extras"]["lightmap"]["scaleOffset"]
    prim = doc["meshes"][node["mesh"]]["primitives"][0]
    uv = _accessor(doc, bins, prim["attributes"]["TEXCOORD_1"])
    idx = _accessor(doc, bins, prim["indices"]).reshape(-1).astype(int)
    tex = doc["materials"][prim["material"]]["extensions"]["MOZ_lightmap"]["index"]
    exr = _image(os.path.join(out, doc["textures"][tex]["extras"]["lightmap"]["files"]["exr"]))[..., :3]
    vals = []
    for t in uv[idx].reshape(-1, 3, 2):
        for a in range(grid):
            for b in range(grid - a):
                w = np.array([(a + 1 / 3) / grid, (b + 1 / 3) / grid])
                p = t[0] + w[0] * (t[1] - t[0]) + w[1] * (t[2] - t[0])
                vals.append(p * so[:2] + so[2:])
    vals = np.array(vals)
    return bilinear(exr, vals[:, 0], vals[:, 1]) @ np.array([0.2126, 0.7152, 0.0722])


def shared(lmbake, work):
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True,
                   stdout=subprocess.DEVNULL)
    scene = os.path.join(scenes, "seams.gltf")
    base = "texel_density: 20\noutput: {formats: [exr], directional: false}\n"
    o1, d1, b1 = bake(lmbake, work, scene, "shared", base + "atlas: {share_meshes: true}\n")
    o2, d2, b2 = bake(lmbake, work, scene, "copies", base)
    o3, d3, b3 = bake(lmbake, work, scene, "copies-seed2", base + "seed: 2\n")
    tiles = [n for n in d1["nodes"] if n.get("name") in ("tile", "tile_b")]
    check(len(tiles) == 2 and tiles[0]["mesh"] == tiles[1]["mesh"] and
          sum(1 for m in d1["meshes"] if m["name"].startswith("tile")) == 1,
          "one lightmapped mesh for both nodes (%s)" % [m["name"] for m in d1["meshes"]])
    r = [n["extras"]["lightmap"]["scaleOffset"] for n in tiles]
    apart = (r[0][2] + r[0][0] <= r[1][2] + 1e-9 or r[1][2] + r[1][0] <= r[0][2] + 1e-9 or
             r[0][3] + r[0][1] <= r[1][3] + 1e-9 or r[1][3] + r[1][1] <= r[0][3] + 1e-9)
    check(apart and all(0 <= x <= 1 for q in r for x in q), "two disjoint rectangles: %s" % r)
    for name in ("tile", "tile_b"):
        a, b, c = tile_light(o1, d1, b1, name), tile_light(o2, d2, b2, name), tile_light(o3, d3, b3, name)
        diff = np.sqrt(np.mean(((a - b) / b) ** 2))
        noise = np.sqrt(np.mean(((c - b) / b) ** 2))
        check(diff <= 1.5 * noise + 0.002 and abs(a.mean() / b.mean() - 1) <= 0.01,
              "%s: shared vs copies %.2f%% rms, mean ratio %.4f (two seeds of the copies: %.2f%% rms)"
              % (name, 100 * diff, a.mean() / b.mean(), 100 * noise))
    v = subprocess.run(["node", os.path.join(HERE, "validate_gltf.js"), os.path.join(o1, "seams.gltf")],
                       capture_output=True, text=True)
    check(v.returncode == 0, "Khronos' validator: %s" % v.stdout.splitlines()[0].split(": ", 1)[-1])


def copies(lmbake, work):
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True,
                   stdout=subprocess.DEVNULL)
    out = os.path.join(work, "out")
    shutil.rmtree(out, ignore_errors=True)
    cfg = os.path.join(work, "instanced.yaml")
    with open(cfg, "w") as f:
        # min_chart_texels 0: one density for every copy, so rectangles scale with the copies (the
        # floor would raise the small copies' boxes more than the large ones')
        f.write("atlas: {texels: 131072, min_chart_texels: 0}\noutput: {formats: [exr, mask], directional: false}\n")
    p = subprocess.run([lmbake, "bake", os.path.join(scenes, "instanced-boxes.gltf"), "-c", cfg, "-o", out],
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake failed: " + p.stderr[-2000:])
    doc = json.load(open(os.path.join(out, "instanced-boxes.gltf")))
    bins = [open(os.path.join(out, b["uri"]), "rb").read() for b in doc["buffers"]]
    node = next(n for n in doc["nodes"] if n.get("name") == "boxes")
    attrs = node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]
    scale = _accessor(doc, bins, attrs["_LIGHTMAP_SCALE"])
    offset = _accessor(doc, bins, attrs["_LIGHTMAP_OFFSET"])
    trans = _accessor(doc, bins, attrs["TRANSLATION"])
    size = _accessor(doc, bins, attrs["SCALE"])[:, 0]
    n = len(trans)
    check(n == 576 and len(scale) == n and len(offset) == n and (scale > 0).all(),
          "every one of the %d copies has a rectangle (_LIGHTMAP_SCALE, _LIGHTMAP_OFFSET)" % n)
    box_meshes = {n2["mesh"] for n2 in doc["nodes"] if "mesh" in n2 and n2.get("name") == "boxes"}
    check(len(box_meshes) == 1 and sum(1 for m in doc["meshes"] if m["name"].startswith("box")) == 1,
          "one mesh for all copies (%s)" % [m["name"] for m in doc["meshes"]])
    prim = doc["meshes"][node["mesh"]]["primitives"][0]
    tex = doc["materials"][prim["material"]]["extensions"]["MOZ_lightmap"]["index"]
    lm = doc["textures"][tex]["extras"]["lightmap"]
    exr = _image(os.path.join(out, lm["files"]["exr"]))[..., :3]
    valid = _image(os.path.join(out, lm["files"]["exr"][:-4] + "-mask.png"))[..., 0] > 0.99
    H, W = valid.shape
    uv = _accessor(doc, bins, prim["attributes"]["TEXCOORD_1"])
    pos = _accessor(doc, bins, prim["attributes"]["POSITION"])
    idx = _accessor(doc, bins, prim["indices"]).reshape(-1).astype(int)
    tri_uv, tri_p = uv[idx].reshape(-1, 3, 2), pos[idx].reshape(-1, 3, 3)
    # rectangles
    lo, hi = offset, offset + scale
    inside = (lo >= -1e-6).all() and (hi <= 1 + 1e-6).all()
    order = np.argsort(lo[:, 0])
    overlaps = 0
    for a in range(n):  # sweep on x
        i = order[a]
        for b in range(a + 1, n):
            j = order[b]
            if lo[j, 0] >= hi[i, 0] - 1e-9:
                break
            overlaps += lo[j, 1] < hi[i, 1] - 1e-9 and lo[i, 1] < hi[j, 1] - 1e-9
    check(inside and overlaps == 0, "rectangles inside [0, 1] and disjoint (%d overlapping pairs)" % overlaps)
    big, small = scale[size > 1.2, 0] * W, scale[size < 1.2, 0] * W
    ratio = big.mean() / small.mean()
    check(abs(big.mean() - 1.5 * small.mean()) <= 1.0, "1.5 x copies get 1.5 x rectangles: %.2f and %.2f texels wide "
          "(ratio %.3f)" % (big.mean(), small.mean(), ratio))
    # each texel to the first copy whose triangles cover it, in copy order
    tris = (tri_uv[None] * scale[:, None, None, :] + offset[:, None, None, :]).reshape(-1, 3, 2)
    tri_of, texel = cover_pairs(tris, W, H)
    owner, clash = claim_texels(tri_of // len(tri_uv) + 1, texel, W * H)
    owner = owner.reshape(H, W)
    own, lit, total = 0, 0, 0
    for k in range(n):
        c = (tri_uv * scale[k] + offset[k]).mean(axis=1)
        x = np.minimum((c[:, 0] * W).astype(int), W - 1)
        y = np.minimum((c[:, 1] * H).astype(int), H - 1)
        own += int((owner[y, x] == k + 1).sum())
        lit += int(valid[y, x].sum())
        total += len(x)
    check(clash == 0 and own == total and lit >= 0.99 * total,
          "centroids through their copy's rectangle: %d/%d on the copy's own texels, %d valid; %d texels claimed "
          "twice" % (own, total, lit, clash))
    # light on the copies' tops
    normal = np.cross(tri_p[:, 1] - tri_p[:, 0], tri_p[:, 2] - tri_p[:, 0])
    top = normal[:, 1] > 0.5 * np.linalg.norm(normal, axis=1)
    open_lux, roofed_lux = [], []
    for k in range(n):
        c = (tri_uv[top] * scale[k] + offset[k]).mean(axis=1)
        e = bilinear(exr, c[:, 0], c[:, 1]) @ np.array([0.2126, 0.7152, 0.0722])
        x, z = trans[k, 0], trans[k, 2]
        if abs(z) < 9 and x > 1.5:
            open_lux.append(e.mean())
        elif abs(z) < 9 and x < -1.5:
            roofed_lux.append(e.mean())
    o, r = float(np.median(open_lux)), float(np.median(roofed_lux))
    check(866 <= o <= 1.3 * 866, "tops of copies in the open: median %.0f lux (sun 866 + bounced; bound 866..1126, "
          "%d copies)" % (o, len(open_lux)))
    check(r < o / 3, "tops of copies under the roof: median %.0f lux, darker than a third of the open ones (%d copies)"
          % (r, len(roofed_lux)))
    v = subprocess.run(["node", os.path.join(HERE, "validate_gltf.js"), os.path.join(out, "instanced-boxes.gltf")],
                       capture_output=True, text=True)
    check(v.returncode == 0, "Khronos' validator: %s" % v.stdout.splitlines()[0].split(": ", 1)[-1])


def main():
    lmbake, work, case = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    {"copies": copies, "shared": shared}[case](lmbake, work)
    if failures:
        sys.exit("%d check(s) failed" % len(failures))


if __name__ == "__main__":
    main()
