"""Per-object means of a bake's lightmap: which valid texel belongs to which lightmapped node,
and the mean irradiance over each node's texels. Shared by the defaults' accuracy check
(check_defaults.py) and the tool that makes its stored reference (tools/make_reference.py).

A texel belongs to the node whose lightmap-UV triangle covers its centre or, for the
conservatively rasterized edge texels, lies within 0.75 texel of it; texels are valid where the
bake's mask (output.formats: mask) says 255. Two bakes with the same layout (same scene, same
density) get the same texel sets, so their per-object means compare texel set by texel set.
"""
import json
import os
import struct

import numpy as np
import OpenImageIO as oiio


def _accessor(doc, bins, index):
    a = doc["accessors"][index]
    v = doc["bufferViews"][a["bufferView"]]
    comps = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[a["type"]]
    fmt = {5126: "f", 5125: "I", 5123: "H", 5121: "B"}[a["componentType"]]
    size = struct.calcsize(fmt)
    stride = v.get("byteStride", size * comps)
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    data = bins[v["buffer"]]
    return np.array([struct.unpack_from("<%d%s" % (comps, fmt), data, start + i * stride) for i in range(a["count"])])


def _image(path):
    buf = oiio.ImageBuf(path)
    px = buf.get_pixels(oiio.FLOAT)
    if px is None or px.size == 0:
        raise RuntimeError("cannot read %s: %s" % (path, buf.geterror()))
    return px.astype(np.float64)


def cover_pairs(tris, w, h, reach=0.75, window_max=16):
    """(triangle index, texel index y * w + x) of every texel whose centre lies in a UV triangle
    or within reach texels of it (the conservatively rasterized edge texels), for all the
    triangles tris (T x 3 x 2, atlas UV) at once: windows of like size side by side in arrays (a
    triangle whose window is wider than window_max texels alone). On a level's 40k triangles one
    numpy call per triangle cost most of a test's time (20 of 40 s)."""
    tris = np.asarray(tris, np.float64)
    p = tris * np.array([w, h])
    lo = np.maximum(np.floor(p.min(axis=1) - 1).astype(int), 0)
    hi = np.minimum(np.ceil(p.max(axis=1) + 1).astype(int), [w - 1, h - 1])
    size = hi - lo + 1
    on = (size > 0).all(axis=1)
    small = on & (size <= window_max).all(axis=1)
    tri_out, texel_out = [], []
    for t in np.nonzero(on & ~small)[0]:  # wide windows one at a time
        _, texel = _cover_windows(p[t:t + 1], lo[t:t + 1], hi[t:t + 1], size[t:t + 1], reach, w)
        tri_out.append(np.full(len(texel), t))
        texel_out.append(texel)
    # windows of like size together (at most 4, 8, 16 texels wide), about 2M texels at a time
    side = size.max(axis=1)
    for lo_side, hi_side in ((0, 4), (4, 8), (8, window_max)):
        group = np.nonzero(small & (side > lo_side) & (side <= hi_side))[0]
        step = max(1, 2_000_000 // (hi_side * hi_side))
        for start in range(0, len(group), step):
            ts = group[start:start + step]
            i, texel = _cover_windows(p[ts], lo[ts], hi[ts], size[ts], reach, w)
            tri_out.append(ts[i])
            texel_out.append(texel)
    if not tri_out:
        return np.zeros(0, int), np.zeros(0, int)
    return np.concatenate(tri_out), np.concatenate(texel_out)


def _cover_windows(P, lo, hi, size, reach, w):
    """cover_pairs for triangles P (T x 3 x 2, in texels) whose windows [lo, hi] are at most
    size.max() texels wide: (index into P, texel index) of every covered texel."""
    kx, ky = size[:, 0].max(), size[:, 1].max()
    xs = np.broadcast_to(lo[:, 0, None, None] + np.arange(kx)[None, None, :], (len(P), ky, kx))
    ys = np.broadcast_to(lo[:, 1, None, None] + np.arange(ky)[None, :, None], (len(P), ky, kx))
    in_win = (xs <= hi[:, 0, None, None]) & (ys <= hi[:, 1, None, None])
    cx, cy = xs + 0.5, ys + 0.5
    area = (P[:, 1, 0] - P[:, 0, 0]) * (P[:, 2, 1] - P[:, 0, 1]) - (P[:, 2, 0] - P[:, 0, 0]) * (P[:, 1, 1] - P[:, 0, 1])
    sign = np.sign(area)[:, None, None]
    inside = np.ones(xs.shape, bool)
    dist = np.full(xs.shape, np.inf)
    for k in range(3):
        a, b = P[:, k], P[:, (k + 1) % 3]
        ex, ey = (b[:, 0] - a[:, 0])[:, None, None], (b[:, 1] - a[:, 1])[:, None, None]
        ax, ay = a[:, 0, None, None], a[:, 1, None, None]
        inside &= (ex * (cy - ay) - ey * (cx - ax)) * sign >= 0
        l2 = ex * ex + ey * ey
        t = np.where(l2 > 0, np.clip(((cx - ax) * ex + (cy - ay) * ey) / np.where(l2 > 0, l2, 1), 0, 1), 0)
        dist = np.minimum(dist, np.hypot(cx - (ax + t * ex), cy - (ay + t * ey)))
    i, y, x = np.nonzero(in_win & (inside | (dist <= reach)))
    return i, ys[i, y, x] * w + xs[i, y, x]


def claim_texels(labels, texels, n):
    """Texels claimed in label order, as a loop over labels 1, 2, ... that gives each covered
    texel to the first label covering it: (owner (n, 0: none), clash: covered (triangle, texel)
    pairs whose texel a lower label already holds). labels, texels: one pair per triangle and
    texel (cover_pairs)."""
    first = np.full(n, np.iinfo(np.int64).max)
    np.minimum.at(first, texels, labels)
    owner = np.where(first == np.iinfo(np.int64).max, 0, first)
    return owner, int((owner[texels] < labels).sum())


def lightmap_uv(node, uv):
    """TEXCOORD_1 placed in its atlas by the node's extras.lightmap.scaleOffset (sx, sy, ox, oy):
    (1, 1, 0, 0) for unwrapped meshes, a rectangle for meshes that kept their own TEXCOORD_1."""
    so = node.get("extras", {}).get("lightmap", {}).get("scaleOffset", [1, 1, 0, 0])
    return uv * np.array(so[:2]) + np.array(so[2:])


def object_means(out, by="node"):
    """{node name: (mean rgb over its valid texels, texel count)} for the bake in folder out,
    plus its "all" entry (every valid texel of every node). Needs output.formats exr and mask.
    by="material": keyed by the primitives' material names instead (what survives a glTF
    optimiser that joins or renames nodes)."""
    name = [f for f in os.listdir(out) if f.endswith(".gltf")][0]
    doc = json.load(open(os.path.join(out, name)))
    bins = [open(os.path.join(out, b["uri"]), "rb").read() for b in doc["buffers"]]
    atlases = {}
    tris = {}  # atlas -> [(UV triangles, node index + 1)] in the document's order
    nodes = []
    for node in doc["nodes"]:
        if "mesh" not in node:
            continue
        for prim in doc["meshes"][node["mesh"]]["primitives"]:
            if "TEXCOORD_1" not in prim["attributes"]:
                continue
            tex = doc["materials"][prim["material"]]["extensions"]["MOZ_lightmap"]["index"]
            if tex not in atlases:
                png = doc["images"][doc["textures"][tex]["source"]]["uri"]
                exr = _image(os.path.join(out, png[:-4] + ".exr"))[..., :3]
                mask = _image(os.path.join(out, png[:-4] + "-mask.png"))[..., 0]
                atlases[tex] = (exr, mask > 0.99)
                tris[tex] = []
            key = node["name"] if by == "node" else doc["materials"][prim["material"]].get("name", "")
            if key not in nodes:
                nodes.append(key)
            label = nodes.index(key) + 1
            uv = lightmap_uv(node, _accessor(doc, bins, prim["attributes"]["TEXCOORD_1"]))
            idx = _accessor(doc, bins, prim["indices"]).reshape(-1).astype(int)
            tris[tex].append((uv[idx].reshape(-1, 3, 2), label))
    # each valid texel to the node of the first triangle (in the document's order) covering it
    owner = {}
    for tex, (exr, valid) in atlases.items():
        h, w = valid.shape
        t = np.concatenate([a for a, _ in tris[tex]])
        label_of = np.concatenate([np.full(len(a), label) for a, label in tris[tex]])
        tri_of, texel = cover_pairs(t, w, h)
        keep = valid.reshape(-1)[texel]
        first, _ = claim_texels(tri_of[keep] + 1, texel[keep], w * h)
        owner[tex] = np.where(first > 0, label_of[np.maximum(first - 1, 0)], 0).reshape(h, w)
    sums = {n: [np.zeros(3), 0] for n in nodes + ["all"]}
    for tex, (exr, valid) in atlases.items():
        for label, n in enumerate(nodes, 1):
            sel = owner[tex] == label
            for key in (n, "all"):
                sums[key][0] += exr[sel].sum(axis=0)
                sums[key][1] += int(sel.sum())
    return {n: (s / max(c, 1), c) for n, (s, c) in sums.items()}


def luminance(rgb):
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
