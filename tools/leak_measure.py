#!/usr/bin/env python3
"""Measures light where none can go in a baked leak scene (tools/leak_scenes.py): what the
lightmaps, the probes, and points lit by the probes (through the tetrahedra, as Unity and Godot
interpolate, and through the irradiance volume, as bevy does) read in the scene's dark region,
as a share of the lit region's lightmap mean. Read from the output glTF alone, as an engine would.

usage: leak_measure.py OUTDIR SCENE        prints one JSON line
   or: import leak_measure; leak_measure.measure(outdir, scene)

Texel positions: each lightmapped triangle's TEXCOORD_1 is rasterised at texel centres (those
within half a texel of the triangle, clamped onto it). "Away" texels are more than one texel from
every face of the dark box but the one they lie on (a texel clamped onto an edge lies on two: it
is at a wall). Probe-lit points: a grid over the dark box
kept 0.3 m inside it; each reads the brightest of the six ambient-cube faces.
"""
import json
import math
import os
import struct
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from leak_scenes import LEAK_SCENES  # noqa: E402

LUM = np.array([0.2126, 0.7152, 0.0722])
PROBE_MARGIN = 0.3


def accessor(doc, blobs, index):
    a = doc["accessors"][index]
    v = doc["bufferViews"][a["bufferView"]]
    comps = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[a["type"]]
    dtype = {5126: np.float32, 5125: np.uint32, 5123: np.uint16}[a["componentType"]]
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    raw = blobs[v["buffer"]][start:start + a["count"] * comps * np.dtype(dtype).itemsize]
    return np.frombuffer(raw, dtype=dtype).reshape(a["count"], comps)


def read_exr(path):
    import OpenImageIO as oiio
    inp = oiio.ImageInput.open(path)
    img = inp.read_image("float")
    inp.close()
    return np.asarray(img)[:, :, :3]


def node_matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], dtype=float).reshape(4, 4).T
    m = np.eye(4)
    t = node.get("translation", [0, 0, 0])
    m[:3, 3] = t
    return m


def texel_points(tris_w, tris_uv, w, h):
    """(atlas x, y, world point, texel size in world units) of every texel centre within half a
    texel of the triangles."""
    xs, ys, ps, sizes = [], [], [], []
    for wt, ut in zip(tris_w, tris_uv):
        u = ut * np.array([w, h])
        e1, e2 = u[1] - u[0], u[2] - u[0]
        det = e1[0] * e2[1] - e2[0] * e1[1]
        if abs(det) < 1e-12:
            continue
        size = math.sqrt(np.linalg.norm(np.cross(wt[1] - wt[0], wt[2] - wt[0])) / abs(det))  # world units a texel
        x0, x1 = int(max(0, math.floor(u[:, 0].min()) - 1)), int(min(w - 1, math.floor(u[:, 0].max()) + 1))
        y0, y1 = int(max(0, math.floor(u[:, 1].min()) - 1)), int(min(h - 1, math.floor(u[:, 1].max()) + 1))
        gx, gy = np.meshgrid(np.arange(x0, x1 + 1), np.arange(y0, y1 + 1))
        c = np.stack([gx.ravel() + 0.5, gy.ravel() + 0.5], axis=1) - u[0]
        b1 = (c[:, 0] * e2[1] - e2[0] * c[:, 1]) / det
        b2 = (e1[0] * c[:, 1] - c[:, 0] * e1[1]) / det
        b0 = 1 - b1 - b2
        # within half a texel: the barycentric margin scaled by the triangle's texel extent
        edge = [np.linalg.norm(e1), np.linalg.norm(e2), np.linalg.norm(u[2] - u[1])]
        margin = 0.5 * max(edge) / abs(det)  # half a texel over the shortest height, in barycentric units
        keep = (b0 >= -margin) & (b1 >= -margin) & (b2 >= -margin)
        if not keep.any():
            continue
        bb = np.clip(np.stack([b0, b1, b2], axis=1)[keep], 0, None)
        bb /= bb.sum(axis=1, keepdims=True)
        xs.append(gx.ravel()[keep])
        ys.append(gy.ravel()[keep])
        ps.append(bb @ wt)
        sizes.append(np.full(keep.sum(), size))
    if not xs:
        return np.zeros(0, int), np.zeros(0, int), np.zeros((0, 3)), np.zeros(0)
    return np.concatenate(xs), np.concatenate(ys), np.concatenate(ps), np.concatenate(sizes)


def lightmap_texels(out, doc, blobs):
    """Every lightmapped texel once: (luminance, world point, texel size)."""
    seen = {}
    for node in doc["nodes"]:
        if "mesh" not in node:
            continue
        m = node_matrix(node)
        for prim in doc["meshes"][node["mesh"]]["primitives"]:
            if "TEXCOORD_1" not in prim["attributes"] or "material" not in prim:
                continue
            ext = doc["materials"][prim["material"]].get("extensions", {}).get("MOZ_lightmap")
            if not ext:
                continue
            tex = ext["index"]
            pos = accessor(doc, blobs, prim["attributes"]["POSITION"]).astype(float)
            pos = pos @ m[:3, :3].T + m[:3, 3]
            uv = accessor(doc, blobs, prim["attributes"]["TEXCOORD_1"]).astype(float)
            idx = accessor(doc, blobs, prim["indices"]).ravel().astype(int).reshape(-1, 3)
            if tex not in seen:
                uri = doc["images"][doc["textures"][tex]["source"]]["uri"]
                seen[tex] = (read_exr(os.path.join(out, os.path.splitext(uri)[0] + ".exr")), [])
            img = seen[tex][0]
            h, w = img.shape[:2]
            xs, ys, ps, sizes = texel_points(pos[idx], uv[idx], w, h)
            seen[tex][1].append((xs, ys, ps, sizes))
    lum, pts, size = [], [], []
    for img, parts in seen.values():
        xs = np.concatenate([p[0] for p in parts])
        ys = np.concatenate([p[1] for p in parts])
        ps = np.concatenate([p[2] for p in parts])
        ss = np.concatenate([p[3] for p in parts])
        key = ys * img.shape[1] + xs
        _, first = np.unique(key, return_index=True)
        lum.append(img[ys[first], xs[first]] @ LUM)
        pts.append(ps[first])
        size.append(ss[first])
    return np.concatenate(lum), np.concatenate(pts), np.concatenate(size)


def inside(p, lo, hi, margin=0.0):
    lo, hi = np.asarray(lo) + margin, np.asarray(hi) - margin
    return np.all((p >= lo - 1e-6) & (p <= hi + 1e-6), axis=-1)


def away_from_faces(p, lo, hi, size):
    """Texels more than a texel from every face of the box but the one they lie on."""
    lo, hi = np.asarray(lo), np.asarray(hi)
    d = np.concatenate([p - lo, hi - p], axis=1)  # 6 distances
    on = d < 1e-4
    d = np.where(on, np.inf, d)
    return (on.sum(axis=1) <= 1) & (d.min(axis=1) > size)  # a texel on an edge (two faces) is at a wall


def probes(doc, blobs):
    pr = doc.get("asset", {}).get("extras", {}).get("lightmap", {}).get("probes")
    if not pr:
        return None
    pos = accessor(doc, blobs, pr["positions"]).astype(float)
    v = doc["bufferViews"][pr["ambientCube"]]
    cube = np.frombuffer(blobs[v["buffer"]][v.get("byteOffset", 0):v.get("byteOffset", 0) + v["byteLength"]],
                         dtype=np.float32).reshape(-1, 6, 3).astype(float)
    tets = accessor(doc, blobs, pr["tetrahedra"]).ravel().reshape(-1, 4) if "tetrahedra" in pr else None
    return pos, cube, tets


def tetra_lookup(points, pos, cube, tets):
    """Ambient cubes at points by the barycentric weights of the tetrahedron holding each (the
    preview's and Unity's way); beyond the hull: the tetrahedron the point is least outside, its
    weights clamped to >= 0 and renormalised (the preview's rule, Unity's extrapolation)."""
    out = np.zeros((len(points), 6, 3))
    a = pos[tets[:, 0]]
    m = np.stack([pos[tets[:, 1]] - a, pos[tets[:, 2]] - a, pos[tets[:, 3]] - a], axis=2)  # (T, 3, 3)
    good = np.abs(np.linalg.det(m)) > 1e-12
    inv = np.zeros_like(m)
    inv[good] = np.linalg.inv(m[good])
    for i, p in enumerate(points):
        b = np.einsum("tij,tj->ti", inv, p - a)
        w = np.concatenate([1 - b.sum(axis=1, keepdims=True), b], axis=1)
        hit = np.where(good & np.all(w >= -1e-6, axis=1))[0]
        if len(hit):
            t = hit[0]
            out[i] = np.einsum("k,kfc->fc", w[t], cube[tets[t]])
        else:  # beyond the hull: the tetrahedron it is least outside, weights clamped (the preview's rule)
            least = np.where(good, w.min(axis=1), -np.inf)
            t = int(np.argmax(least))
            c = np.maximum(w[t], 0)
            out[i] = np.einsum("k,kfc->fc", c / c.sum(), cube[tets[t]])
    return out


def read_volume(path):
    """A KTX2 E5B9G9R9 3D texture (no supercompression) as float (depth, height, width, 3)."""
    data = open(path, "rb").read()
    w, h, d = struct.unpack_from("<III", data, 20)
    offset, length = struct.unpack_from("<QQ", data, 80)
    raw = np.frombuffer(data[offset:offset + length], dtype=np.uint32).astype(np.int64)
    e = (raw >> 27) - 15 - 9
    r, g, b = raw & 511, (raw >> 9) & 511, (raw >> 18) & 511
    rgb = np.stack([r, g, b], axis=1) * np.power(2.0, e)[:, None]
    return rgb.reshape(d, h, w, 3)


def volume_lookup(points, tex, world):
    """bevy's irradiance_volume.wgsl: the point in the unit cube, clamped to voxel centres,
    sampled trilinearly in each of the six face sections; returns (N, 6, 3)."""
    d, h, w = tex.shape[:3]
    res = np.array([w, h // 2, d // 3])
    inv = np.linalg.inv(world)
    out = np.zeros((len(points), 6, 3))
    for i, p in enumerate(points):
        q = (inv @ np.append(p, 1.0))[:3] + 0.5
        stp = np.clip(np.clip(q, 0, 1) * res, 0.5, res - 0.5) - 0.5
        i0 = np.floor(stp).astype(int)
        f = stp - i0
        i1 = np.minimum(i0 + 1, res - 1)
        for face in range(6):
            axis, neg = face // 2, face % 2
            acc = np.zeros(3)
            for cx in (0, 1):
                for cy in (0, 1):
                    for cz in (0, 1):
                        x = i1[0] if cx else i0[0]
                        y = i1[1] if cy else i0[1]
                        z = i1[2] if cz else i0[2]
                        wt = (f[0] if cx else 1 - f[0]) * (f[1] if cy else 1 - f[1]) * (f[2] if cz else 1 - f[2])
                        acc += wt * tex[z + axis * res[2], y + neg * res[1], x]
            out[i, 2 * axis + neg] = acc
    return out


def probe_points(lo, hi, margin):
    lo, hi = np.asarray(lo) + margin, np.asarray(hi) - margin
    axes = [np.linspace(lo[k], hi[k], 5) if hi[k] > lo[k] else np.array([(lo[k] + hi[k]) / 2]) for k in range(3)]
    g = np.meshgrid(*axes, indexing="ij")
    return np.stack([x.ravel() for x in g], axis=1)


def measure(out, scene, margin=PROBE_MARGIN, probes_too=True):
    name = [f for f in os.listdir(out) if f.endswith(".gltf")][0]
    doc = json.load(open(os.path.join(out, name)))
    blobs = [open(os.path.join(out, b["uri"]), "rb").read() for b in doc["buffers"]]
    dark_lo, dark_hi, lit_lo, lit_hi, wall = LEAK_SCENES[scene]
    lum, pts, size = lightmap_texels(out, doc, blobs)
    lit = inside(pts, lit_lo, lit_hi)
    dark = inside(pts, dark_lo, dark_hi)
    lit_mean = float(lum[lit].mean())
    r = {"scene": scene, "texel_cm": round(100 * float(np.median(size)), 2), "lit_mean": lit_mean,
         "dark_texels": int(dark.sum()), "dark_mean": float(lum[dark].mean()) if dark.any() else 0.0}
    away = dark & away_from_faces(pts, dark_lo, dark_hi, size)
    r["dark_away_max"] = float(lum[away].max()) if away.any() else 0.0
    r["dark_max"] = float(lum[dark].max()) if dark.any() else 0.0
    if wall is not None:
        axis, at, _ = wall
        foot = dark & (np.abs(pts[:, axis] - at) < size * 1.01) | dark & (pts[:, axis] - at < size)
        r["dark_wall_max"] = float(lum[foot].max()) if foot.any() else 0.0
    pr = probes(doc, blobs) if probes_too else None
    if pr:
        pos, cube, tets = pr
        ind = inside(pos, dark_lo, dark_hi)
        r["dark_probes"] = int(ind.sum())
        r["dark_probe_max"] = float((cube[ind] @ LUM).max()) if ind.any() else 0.0
        pts3 = probe_points(dark_lo, dark_hi, margin)
        if tets is not None and len(tets):
            r["tetra_max"] = float((tetra_lookup(pts3, pos, cube, tets) @ LUM).max())
        vols = []
        for node in doc["nodes"]:
            iv = node.get("extras", {}).get("lightmap", {}).get("irradianceVolume")
            if iv:
                tex = read_volume(os.path.join(out, iv["uri"]))
                vols.append(volume_lookup(pts3, tex, node_matrix(node)) @ LUM)
        if vols:
            r["volume_max"] = float(max(v.max() for v in vols))
    for k in list(r):
        if k.endswith("_max") or k == "dark_mean":
            r[k + "_share"] = r[k] / lit_mean if lit_mean > 0 else 0.0
    return r


if __name__ == "__main__":
    print(json.dumps(measure(sys.argv[1], sys.argv[2])))
