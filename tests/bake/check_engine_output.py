#!/usr/bin/env python3
"""Lightmaps as engines load them (docs/output.md): per-node rectangles, output.scale, RGBM.

usage: check_engine_output.py LMBAKE WORKDIR CASE   (CASE: rects, scale, rgbm)

rects  bevy's MixedLightingExample (its meshes carry their own TEXCOORD_1, as bevy's example
       places them in one atlas with a uv_rect) baked with atlas.keep_uv1 and KTX2 B10G11R11:
       - one atlas; every lightmapped node names in extras.lightmap its atlas, scaleOffset and
         files, and every file named exists; the KTX2 has the vkFormat (122) and the
         supercompression (2, zstd) of the lightmaps bevy ships (its Cornell box's, here);
       - the output TEXCOORD_1 is the input's, untouched; Khronos' validator finds 0 errors;
       - the rectangles lie in [0, 1] and do not overlap; each node's TEXCOORD_1 through its
         rectangle covers texels no other node covers (sampled at every triangle's centroid:
         the texel there is valid and the node's own);
       - the light on each node (the lightmap at every triangle's centroid, area-weighted) agrees
         with an unwrapped bake of the same scene within 3% (the rectangle maps each node onto its
         own light, not a neighbour's) for the nodes over 5% of the area (floor, sphere, fabric);
         the chair's small parts get few texels from their own UVs and differ more (printed).
scale  bevy's Cornell box with output.scale radiance: every EXR texel times pi equals the
       irradiance bake's (same seed) within half-float rounding; MOZ_lightmap.intensity is pi
       and extras.lightmap.scale says radiance.
rgbm   the same scene with output.formats rgbm: decoded by the formula the glTF states, every
       channel within 1% of the texel's largest channel over [range 1e-5, range]; with a range
       below the brightest texels, the valid texels above it are clamped, and the log's count
       equals the count from the EXR.
"""
import json
import os
import re
import shutil
import struct
import subprocess
import sys

import numpy as np
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
from object_means import _accessor, _image, claim_texels, cover_pairs, lightmap_uv  # noqa: E402

MIXED = os.path.join(ROOT, "assets", "scenes", "mixed-lighting-bevy", "MixedLightingExample.gltf")
CORNELL = os.path.join(ROOT, "assets", "scenes", "cornell-box-bevy", "CornellBox.glb")
BEVY_KTX2 = os.path.join(ROOT, "assets", "scenes", "cornell-box-bevy", "reference-lightmaps", "CornellBox-Small.zstd.ktx2")

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def bake(lmbake, work, scene, name, config):
    out = os.path.join(work, name)
    shutil.rmtree(out, ignore_errors=True)
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(config)
    r = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("bake %s failed:\n%s" % (name, r.stderr[-3000:]))
    gltf = [f for f in os.listdir(out) if f.endswith(".gltf")][0]
    return out, json.load(open(os.path.join(out, gltf))), r.stderr


def ktx2_header(path):
    b = open(path, "rb").read(48)
    vk, _, w, h = struct.unpack_from("<4I", b, 12)
    scheme = struct.unpack_from("<I", b, 44)[0]
    return vk, w, h, scheme


def bins_of(out, doc):
    return [open(os.path.join(out, b["uri"]), "rb").read() for b in doc["buffers"]]


def lightmapped_nodes(doc):
    return [n for n in doc["nodes"] if "mesh" in n and isinstance(n.get("extras", {}).get("lightmap"), dict)]


def rects(lmbake, work):
    # one bounce, 32 gather rays: rectangles and formats are logic; the light per node compared
    # between the two layouts is a mean over thousands of texels
    common = ("atlas: {texels: 65536, keep_uv1: %s}\nbounces: 1\nsamples: {gather: 32}\n"
              "output: {formats: [exr, hdr, png, mask, ktx2], ktx2_format: b10g11r11}\n")
    out, doc, _ = bake(lmbake, work, MIXED, "rects", common % "true")
    src = json.load(open(MIXED))
    src_bins = [open(os.path.join(os.path.dirname(MIXED), b["uri"]), "rb").read() for b in src["buffers"]]
    bins = bins_of(out, doc)
    nodes = lightmapped_nodes(doc)
    atlases = {n["extras"]["lightmap"]["atlas"] for n in nodes}
    check(len(nodes) == 6 and atlases == {0}, "6 lightmapped nodes, one atlas (%d nodes, atlases %s)" % (len(nodes), sorted(atlases)))
    files = nodes[0]["extras"]["lightmap"]["files"]
    missing = [f for n in nodes for f in n["extras"]["lightmap"]["files"].values() if not os.path.exists(os.path.join(out, f))]
    check(not missing and {"exr", "hdr", "png", "ktx2"} <= set(files), "every named file exists (%s)" % sorted(files))
    vk, w, h, scheme = ktx2_header(os.path.join(out, files["ktx2"]))
    bvk, _, _, bscheme = ktx2_header(BEVY_KTX2)
    check((vk, scheme) == (bvk, bscheme) == (122, 2), "KTX2 vkFormat %d, supercompression %d; bevy ships %d, %d" % (vk, scheme, bvk, bscheme))
    exr = _image(os.path.join(out, files["exr"]))[..., :3]
    valid = _image(os.path.join(out, files["exr"][:-4] + "-mask.png"))[..., 0] > 0.99
    H, W = valid.shape
    check((W, H) == (w, h), "the KTX2 is the EXR's size (%dx%d)" % (w, h))
    # untouched TEXCOORD_1 and rectangles
    boxes = []
    same_uv = True
    all_tris, all_labels = [], []
    centroids = {}
    for label, node in enumerate(nodes, 1):
        sx, sy, ox, oy = node["extras"]["lightmap"]["scaleOffset"]
        boxes.append((ox, oy, ox + sx, oy + sy, node.get("name")))
        in_node = next(n for n in src["nodes"] if n.get("name") == node.get("name"))
        for prim, in_prim in zip(doc["meshes"][node["mesh"]]["primitives"], src["meshes"][in_node["mesh"]]["primitives"]):
            uv = _accessor(doc, bins, prim["attributes"]["TEXCOORD_1"])
            idx = _accessor(doc, bins, prim["indices"]).reshape(-1).astype(int)
            in_uv = _accessor(src, src_bins, in_prim["attributes"]["TEXCOORD_1"])
            in_idx = _accessor(src, src_bins, in_prim["indices"]).reshape(-1).astype(int)
            same_uv &= np.array_equal(uv[idx].astype(np.float32), in_uv[in_idx].astype(np.float32))
            atlas_uv = lightmap_uv(node, uv)
            tri = atlas_uv[idx].reshape(-1, 3, 2)
            all_tris.append(tri)
            all_labels.append(np.full(len(tri), label))
            c = tri.mean(axis=1)
            centroids[label] = np.minimum((c * [W, H]).astype(int), [W - 1, H - 1])
    check(same_uv, "TEXCOORD_1 is the input's, untouched (each node's rectangle places it)")
    # each texel to the first node whose triangles cover it, in node order
    tri_of, texel = cover_pairs(np.concatenate(all_tris), W, H)
    labels = np.concatenate(all_labels)[tri_of]
    owner, clash = claim_texels(labels, texel, W * H)
    owner = owner.reshape(H, W)
    gltf = os.path.join(out, [f for f in os.listdir(out) if f.endswith(".gltf")][0])
    v = subprocess.run(["node", os.path.join(HERE, "validate_gltf.js"), gltf], capture_output=True, text=True)
    check(v.returncode == 0 and "KHR_texture_transform" in doc["extensionsUsed"],
          "Khronos' validator: %s (KHR_texture_transform on MOZ_lightmap listed)" % v.stdout.splitlines()[0].split(": ", 1)[-1])
    inside = all(0 <= b[0] < b[2] <= 1 + 1e-9 and 0 <= b[1] < b[3] <= 1 + 1e-9 for b in boxes)
    overlap = [(a[4], b[4]) for i, a in enumerate(boxes) for b in boxes[i + 1:]
               if a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]]
    check(inside and not overlap, "rectangles inside [0, 1] and disjoint (overlapping: %s)" % overlap)
    check(clash == 0, "no texel is covered by two nodes (%d)" % clash)
    own, total, lit = 0, 0, 0
    for label, c in centroids.items():
        x, y = c[:, 0], c[:, 1]
        own += int((owner[y, x] == label).sum())
        lit += int(valid[y, x].sum())
        total += len(x)
    check(own == total, "triangle centroids through their node's rectangle: %d/%d on the node's own texels (%d valid)" % (own, total, lit))
    # the same scene unwrapped: the light at the same surface points agrees
    out2, doc2, _ = bake(lmbake, work, MIXED, "rects-unwrapped", common % "false")
    a, b = surface_means(out, doc), surface_means(out2, doc2)
    worst, all_area = 0, sum(area for _, area in a.values())
    for name in a:
        (ea, area), (eb, _) = a[name], b[name]
        big = area >= 0.05 * all_area
        print("     %-24s %5.1f%% of the area  kept %8.2f  unwrapped %8.2f  ratio %.4f%s" %
              (name, 100 * area / all_area, ea, eb, ea / eb, "" if big else "  (small: its own UVs give it few texels)"))
        worst = max(worst, abs(ea / eb - 1) if big else 0)
    check(worst <= 0.03, "area-weighted light per node over 5%% of the area, kept TEXCOORD_1 vs unwrapped: worst %.2f%% "
          "(bound 3%%)" % (100 * worst))


def bilinear(img, u, v):
    h, w = img.shape[:2]
    x, y = np.clip(u * w - 0.5, 0, w - 1), np.clip(v * h - 0.5, 0, h - 1)
    x0, y0 = np.minimum(x.astype(int), w - 2), np.minimum(y.astype(int), h - 2)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    return ((1 - fx) * (1 - fy) * img[y0, x0] + fx * (1 - fy) * img[y0, x0 + 1] +
            (1 - fx) * fy * img[y0 + 1, x0] + fx * fy * img[y0 + 1, x0 + 1])


def surface_means(out, doc):
    """{node: (luminance of the lightmap at every triangle's centroid (through the node's
    rectangle), weighted by the triangle's area; the area)}: the light on the surface, whatever
    the layout."""
    bins = bins_of(out, doc)
    means = {}
    for node in lightmapped_nodes(doc):
        exr = _image(os.path.join(out, node["extras"]["lightmap"]["files"]["exr"]))[..., :3]
        total, area = 0.0, 0.0
        for prim in doc["meshes"][node["mesh"]]["primitives"]:
            idx = _accessor(doc, bins, prim["indices"]).reshape(-1).astype(int)
            p = _accessor(doc, bins, prim["attributes"]["POSITION"])[idx].reshape(-1, 3, 3)
            uv = lightmap_uv(node, _accessor(doc, bins, prim["attributes"]["TEXCOORD_1"]))[idx].reshape(-1, 3, 2).mean(axis=1)
            a = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
            e = bilinear(exr, uv[:, 0], uv[:, 1]) @ np.array([0.2126, 0.7152, 0.0722])
            total += float((e * a).sum())
            area += float(a.sum())
        means[node["name"]] = (total / max(area, 1e-30), area)
    return means


def scale(lmbake, work):
    cfg = "texel_density: 0.1\noutput: {formats: [exr, hdr, png], scale: %s}\n"
    o1, d1, _ = bake(lmbake, work, CORNELL, "irradiance", cfg % "irradiance")
    o2, d2, _ = bake(lmbake, work, CORNELL, "radiance", cfg % "radiance")
    e1 = _image(os.path.join(o1, "CornellBox-lightmap-0.exr"))
    e2 = _image(os.path.join(o2, "CornellBox-lightmap-0.exr"))
    rel = np.abs(e2 * np.pi - e1) / np.maximum(e1, 1e-3)
    check(e1.shape == e2.shape and rel.max() < 2 ** -10, "radiance x pi = irradiance, every texel (worst %.2e, half float 9.8e-04)" % rel.max())
    mats = [m["extensions"]["MOZ_lightmap"] for m in d2["materials"] if "MOZ_lightmap" in m.get("extensions", {})]
    check(mats and all(abs(m["intensity"] - np.pi) < 1e-12 for m in mats), "MOZ_lightmap.intensity is pi (texel x intensity = E)")
    tex = d2["textures"][mats[0]["index"]]["extras"]["lightmap"]
    nodes = lightmapped_nodes(d2)
    check(tex["scale"] == "radiance" and all(n["extras"]["lightmap"]["scale"] == "radiance" for n in nodes),
          "extras.lightmap.scale is radiance on the texture and every node")


def rgbm(lmbake, work):
    cfg = "texel_density: 0.1\noutput: {formats: [exr, hdr, png, mask, rgbm]%s}\n"
    out, doc, _ = bake(lmbake, work, CORNELL, "rgbm", cfg % "")
    tex = [t for t in doc["textures"] if "lightmap" in t.get("extras", {})][0]["extras"]["lightmap"]
    R = tex["rgbm"]["range"]
    check(tex["rgbm"]["decode"].startswith("v = range * (rgb * a)^2"), "the glTF states the decode: %s" % tex["rgbm"]["decode"])
    exr = _image(os.path.join(out, tex["files"]["exr"]))[..., :3]
    valid = _image(os.path.join(out, tex["files"]["exr"][:-4] + "-mask.png"))[..., 0] > 0.99
    px = np.asarray(Image.open(os.path.join(out, tex["files"]["rgbm"]))).astype(np.float64) / 255
    check(px.shape[2] == 4 and px.shape[:2] == exr.shape[:2], "RGBM is 8-bit RGBA at the atlas size")
    dec = R * (px[..., :3] * px[..., 3:4]) ** 2
    top = exr.max(axis=2)
    sel = (top >= R * 1e-5) & (top <= R)
    err = np.abs(dec - exr).max(axis=2)[sel] / top[sel]
    check(exr.max() <= R and R / 2 < exr.max(), "auto range %g: the power of two above the brightest texel %g" % (R, exr.max()))
    check(err.max() <= 0.01, "decoded within 1%% over [range 1e-5, range]: worst %.3f%%, p99 %.3f%% (%d texels)" % (100 * err.max(), 100 * np.percentile(err, 99), sel.sum()))
    # a range below the brightest texels: clamped and counted
    small = float(np.percentile(top[valid], 99))
    out2, doc2, log = bake(lmbake, work, CORNELL, "rgbm-clamped", cfg % (", rgbm_range: %r" % small))
    tex2 = [t for t in doc2["textures"] if "lightmap" in t.get("extras", {})][0]["extras"]["lightmap"]
    exr2 = _image(os.path.join(out2, tex2["files"]["exr"]))[..., :3]
    over = int(((exr2.max(axis=2) > small) & valid).sum())
    m = re.search(r"atlas 0: (\d+) texels brighter than RGBM's range", log)
    check(m is not None and abs(int(m.group(1)) - over) <= max(2, over // 200),
          "clamped texels counted in the log: %s, from the EXR %d (half-float rounding at the edge)" % (m.group(1) if m else None, over))
    px2 = np.asarray(Image.open(os.path.join(out2, tex2["files"]["rgbm"]))).astype(np.float64) / 255
    dec2 = tex2["rgbm"]["range"] * (px2[..., :3] * px2[..., 3:4]) ** 2
    check(tex2["rgbm"]["range"] == small and dec2.max() <= small * 1.0001, "values above the range decode to at most the range")


def main():
    lmbake, work, case = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    {"rects": rects, "scale": scale, "rgbm": rgbm}[case](lmbake, work)
    if failures:
        sys.exit("%d check(s) failed" % len(failures))


if __name__ == "__main__":
    main()
