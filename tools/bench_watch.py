#!/usr/bin/env python3
"""The artist's loop, timed (docs/watch.md#cost): `lmbake preview --watch` of a level; once bake 1
is final, the level is saved with its light brighter (x 2), then with the light moved; for each
save, the seconds from the save to the quick picture, to its refinement with the changed lights'
direct light (a change of punctual lights alone) and to the final one (the watch's /status: the
moment each was shown), then a plain `lmbake bake` of the same file, one after the other in one
run. Each quick picture's error against the final: both atlases box-averaged over 9 x 9 texels
(valid texels only), rms of the difference over the final's mean, luminance.

level-single-10: its lamp 'Lamp 1' (KHR_lights_punctual: a change of lights; LEVEL:NAME picks a
point light by name, the first by default: level-single-10's 'Lamp 0', like every even lamp of
tools/make_levels.py's single level, sits between two wall pieces and lights nothing). bevy's Cornell
box: its light is an emissive quad: emissiveFactor x 2 (materials), then the node moved
(geometry: the layout is made again). A level with no point light and no emissive material
(tools/make_levels.py's gpu levels): its sun x 2, then turned 10 degrees about the vertical.

usage: bench_watch.py LMBAKE OUT_CSV LEVEL[:LIGHT]...
"""
import json
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import urllib.request

import numpy as np
import OpenImageIO as oiio


def read_level(path):
    b = open(path, "rb").read()
    if path.endswith(".glb"):
        n = struct.unpack("<I", b[12:16])[0]
        return json.loads(b[20:20 + n]), b[20 + n:]
    return json.loads(b), None


def write_level(path, doc, rest):
    """Saved as an editor would: the new file written beside, then renamed over."""
    text = json.dumps(doc).encode()
    if rest is not None:
        text += b" " * (-len(text) % 4)
        body = struct.pack("<I4s", len(text), b"JSON") + text + rest
        data = b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body
    else:
        data = text
    with open(path + ".tmp", "wb") as f:
        f.write(data)
    os.replace(path + ".tmp", path)


def light_edits(doc, light=None):
    """[(what, edit(doc))]: the light brighter, then moved (the point light named `light`, else the first)."""
    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    point = [i for i, l in enumerate(lights) if l.get("type") == "point" and light in (None, l.get("name"))]
    if light and not point:
        sys.exit("bench_watch: no point light named '%s'" % light)
    if point:
        k = point[0]
        node = next(n for n in doc["nodes"] if n.get("extensions", {}).get("KHR_lights_punctual", {}).get("light") == k)

        def brighter(d):
            d["extensions"]["KHR_lights_punctual"]["lights"][k]["intensity"] *= 2

        def moved(d):
            n = next(n for n in d["nodes"] if n.get("extensions", {}).get("KHR_lights_punctual", {}).get("light") == k)
            n["translation"] = [n.get("translation", [0, 0, 0])[0] + 2.0] + n.get("translation", [0, 0, 0])[1:]
        return [("light %s x 2" % lights[k].get("name", k), brighter), ("light %s moved" % lights[k].get("name", k), moved)], node
    if lights:  # a sun: brighter, then turned 10 degrees about the vertical
        node = next(n for n in doc["nodes"] if "KHR_lights_punctual" in n.get("extensions", {}))

        def sun_brighter(d):
            d["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] *= 2

        def sun_turned(d):
            n = next(n for n in d["nodes"] if "KHR_lights_punctual" in n.get("extensions", {}))
            x, y, z, w = n.get("rotation", [0, 0, 0, 1])
            c, s = math.cos(math.radians(5)), math.sin(math.radians(5))  # q_y(10 deg) * q
            n["rotation"] = [c * x + s * z, c * y + s * w, c * z - s * x, c * w - s * y]
        name = lights[0].get("name", 0)
        return [("light %s x 2" % name, sun_brighter), ("light %s turned 10 deg" % name, sun_turned)], node
    m = next(i for i, mat in enumerate(doc["materials"]) if any(mat.get("emissiveFactor", [0, 0, 0])))
    node_index = next(i for i, n in enumerate(doc["nodes"]) if "mesh" in n and any(
        p.get("material") == m for p in doc["meshes"][n["mesh"]]["primitives"]))

    def brighter(d):
        d["materials"][m]["emissiveFactor"] = [2 * c for c in d["materials"][m]["emissiveFactor"]]

    def moved(d):
        n = d["nodes"][node_index]
        t = n.get("translation", [0, 0, 0])
        n["translation"] = [t[0] + 0.05 * abs(t[1] or 1), t[1], t[2]]
    return [("emissive '%s' x 2" % doc["materials"][m].get("name", m), brighter),
            ("emissive node '%s' moved" % doc["nodes"][node_index].get("name", node_index), moved)], None


def box9(img, valid):
    """9 x 9 box average of img over valid texels (an integral image)."""
    w = valid.astype(np.float64)

    def boxsum(a):
        c = np.pad(a, ((5, 4), (5, 4)) + ((0, 0),) * (a.ndim - 2)).cumsum(0).cumsum(1)
        return c[9:, 9:] - c[:-9, 9:] - c[9:, :-9] + c[:-9, :-9]
    n = boxsum(w)
    s = boxsum(img * w[..., None])
    return np.where(n[..., None] > 0, s / np.maximum(n, 1)[..., None], 0)


def accessor(doc, folder, index):
    """An accessor's values as a numpy array (float VEC2/VEC3, unsigned indices; no sparse)."""
    a = doc["accessors"][index]
    v = doc["bufferViews"][a["bufferView"]]
    data = open(os.path.join(folder, doc["buffers"][v["buffer"]]["uri"]), "rb").read()
    dtype = {5126: np.float32, 5125: np.uint32, 5123: np.uint16, 5121: np.uint8}[a["componentType"]]
    n = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[a["type"]]
    size = np.dtype(dtype).itemsize * n
    stride = v.get("byteStride", size)
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    raw = np.frombuffer(data, np.uint8, count=stride * (a["count"] - 1) + size, offset=start)
    rows = np.lib.stride_tricks.as_strided(raw, (a["count"], size), (stride, 1))
    return np.ascontiguousarray(rows).view(dtype).reshape(a["count"], n)


def uv1_triangles(gltf):
    """Each lightmapped primitive's triangles as TEXCOORD_1 (T x 3 x 2), in the file's order."""
    doc, folder = json.load(open(gltf)), os.path.dirname(gltf)
    out = []
    for m in doc["meshes"]:
        for p in m["primitives"]:
            if "TEXCOORD_1" not in p["attributes"]:
                continue
            uv = accessor(doc, folder, p["attributes"]["TEXCOORD_1"])
            idx = accessor(doc, folder, p["indices"]).reshape(-1) if "indices" in p else np.arange(len(uv))
            out.append(uv[idx].reshape(-1, 3, 2).astype(np.float64))
    return np.concatenate(out)


def bilinear(img, u, v):
    h, w = img.shape[:2]
    x, y = np.clip(u * w - 0.5, 0, w - 1), np.clip(v * h - 0.5, 0, h - 1)
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    x1, y1 = np.minimum(x0 + 1, w - 1), np.minimum(y0 + 1, h - 1)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    return ((img[y0, x0] * (1 - fx) + img[y0, x1] * fx) * (1 - fy) + (img[y1, x0] * (1 - fx) + img[y1, x1] * fx) * fy)


def quick_in_final_atlas(quick_gltf, quick_img, final_gltf, shape):
    """The quick bake's light at each final texel: the texel centre's barycentric coordinates in
    its final UV1 triangle, the same point in the quick bake's triangle (both bakes keep the
    input's triangles in order; their charts and atlases differ), read bilinearly."""
    tf, tq = uv1_triangles(final_gltf), uv1_triangles(quick_gltf)
    assert len(tf) == len(tq), "the two bakes' triangles differ (%d, %d)" % (len(tf), len(tq))
    h, w = shape
    out = np.zeros((h, w, 3))
    hit = np.zeros((h, w), bool)
    for f, q in zip(tf, tq):
        px = f * [w, h]
        x0, y0 = np.floor(px.min(0) - 0.5).astype(int)
        x1, y1 = np.ceil(px.max(0) - 0.5).astype(int)
        xs, ys = np.meshgrid(np.arange(max(x0, 0), min(x1, w - 1) + 1), np.arange(max(y0, 0), min(y1, h - 1) + 1))
        c = np.stack([xs.ravel() + 0.5, ys.ravel() + 0.5], 1)
        a, b, d = px
        m = np.array([b - a, d - a]).T
        if abs(np.linalg.det(m)) < 1e-12:
            continue
        l12 = np.linalg.solve(m, (c - a).T).T
        inside = (l12 >= -1e-9).all(1) & (l12.sum(1) <= 1 + 1e-9)
        if not inside.any():
            continue
        l12 = l12[inside]
        uvq = q[0] + l12[:, :1] * (q[1] - q[0]) + l12[:, 1:] * (q[2] - q[0])
        xi, yi = xs.ravel()[inside], ys.ravel()[inside]
        out[yi, xi] = bilinear(quick_img, uvq[:, 0], uvq[:, 1])
        hit[yi, xi] = True
    return out, hit


def quick_error(quick_gltf, quick_img, final_gltf, final_exr):
    """rms over the final's valid texels of (quick - final), both 9 x 9-averaged in the final's
    atlas, luminance, over the final's mean."""
    f = oiio.ImageBuf(final_exr).get_pixels(oiio.FLOAT)[..., :3].astype(np.float64)
    q = oiio.ImageBuf(quick_img).get_pixels(oiio.FLOAT)[..., :3].astype(np.float64)
    qf, hit = quick_in_final_atlas(quick_gltf, q, final_gltf, f.shape[:2])
    valid = (f.max(axis=2) > 0) & hit
    lum = lambda a: a @ np.array([0.2126, 0.7152, 0.0722])
    lq, lf = lum(box9(qf, valid)), lum(box9(f, valid))
    return float(np.sqrt(np.mean((lq[valid] - lf[valid]) ** 2)) / np.mean(lf[valid]))


def status(url):
    return json.load(urllib.request.urlopen(url + "status", timeout=10))


def wait_shown(url, generation, kind, timeout=1800, revision=None):
    """/status once bake `generation` of `kind` is shown (at `revision` or later, when given)."""
    end = time.time() + timeout
    while time.time() < end:
        s = status(url)
        sh = s.get("shown")
        if sh and sh["generation"] == generation and sh["kind"] == kind and sh.get("revision", 0) >= (revision or 0):
            return s
        if sh and revision and sh["generation"] == generation and sh["kind"] == "final":
            return None  # no refined quick picture came before the final
        if s["state"] == "error":
            sys.exit("watch error: " + s["error"])
        time.sleep(0.05)
    sys.exit("timed out waiting for %s bake %d" % (kind, generation))


def fetch_quick(url, generation, revision, stem, dest):
    """The quick picture of bake `generation` at `revision` (the files scene.json names) into
    dest; returns (its glTF, its lightmap)."""
    shutil.rmtree(dest, ignore_errors=True)
    os.makedirs(dest)
    shown = json.load(urllib.request.urlopen("%sscene.json?kind=quick&gen=%d&rev=%d" % (url, generation, revision),
                                             timeout=10))["gltf"]
    base = url + shown.lstrip("/").rsplit("/", 1)[0] + "/"
    get = lambda f: urllib.request.urlretrieve(base + f, os.path.join(dest, f))
    get("%s.gltf" % stem)
    for f in ["%s-lightmap-0.hdr" % stem] + [b["uri"] for b in json.load(open(os.path.join(dest, "%s.gltf" % stem)))["buffers"]]:
        get(f)
    return os.path.join(dest, "%s.gltf" % stem), os.path.join(dest, "%s-lightmap-0.hdr" % stem)


def bench(lmbake, level_src, rows, light=None):
    work = tempfile.mkdtemp(prefix="bench-watch-")
    level = os.path.join(work, os.path.basename(level_src))
    shutil.copy(level_src, level)
    doc, rest = read_level(level)
    edits, _ = light_edits(doc, light)
    out = os.path.join(work, "out")
    p = subprocess.Popen([lmbake, "preview", "--watch", level, "-o", out], stdout=subprocess.PIPE, text=True)
    url = re.search(r"(http://127\.0\.0\.1:\d+/)", p.stdout.readline()).group(1)
    name = os.path.basename(level_src).rsplit(".", 1)[0]
    try:
        wait_shown(url, 1, "final")
        for g, (what, edit) in enumerate(edits, start=2):
            edit(doc)
            saved = time.time()
            write_level(level, doc, rest)
            stem = os.path.basename(level).rsplit(".", 1)[0]
            s = wait_shown(url, g, "quick")
            first_at = s["shown"]["readyAt"] / 1000
            composed = s["shown"].get("composedOn")
            first = fetch_quick(url, g, 0, stem, os.path.join(work, "quick0"))
            s = wait_shown(url, g, "quick", revision=1)  # refined with the direct light of the final bake
            refined = bounced = None
            if s:
                refined = (s["shown"]["readyAt"] / 1000, fetch_quick(url, g, 1, stem, os.path.join(work, "quick1")))
                s = wait_shown(url, g, "quick", revision=2)  # and with the light of its bounce passes
                if s:
                    bounced = (s["shown"]["readyAt"] / 1000, fetch_quick(url, g, 2, stem, os.path.join(work, "quick2")))
            s = wait_shown(url, g, "final")
            final_at = s["shown"]["readyAt"] / 1000
            final = (os.path.join(out, "%s.gltf" % stem), os.path.join(out, "%s-lightmap-0.exr" % stem))
            err0 = quick_error(*first, *final)
            err1 = quick_error(*refined[1], *final) if refined else None
            err2 = quick_error(*bounced[1], *final) if bounced else None
            t0 = time.time()
            subprocess.run([lmbake, "bake", level, "-o", os.path.join(work, "plain"), "-q"], check=True)
            plain = time.time() - t0
            row = (name, what, ",".join(s["changed"]), "layout" if s["layout"] else "lighting",
                   "composed" if composed else "quick", first_at - saved, err0,
                   refined[0] - saved if refined else None, err1, bounced[0] - saved if bounced else None, err2,
                   final_at - saved, plain)
            rows.append(row)
            print("%s: %s (%s; %s): %s picture %.1f s (9x9 error %.2f%%)%s%s, final %.1f s, plain bake %.1f s"
                  % (name, what, row[2], row[3], row[4], row[5], 100 * err0,
                     "; refined with the direct light %.1f s (%.2f%%)" % (row[7], 100 * err1) if refined else "",
                     "; with the bounced light %.1f s (%.2f%%)" % (row[9], 100 * err2) if bounced else "",
                     row[11], row[12]), flush=True)
    finally:
        p.terminate()
        p.wait()
        shutil.rmtree(work, ignore_errors=True)


def main():
    lmbake, csv = sys.argv[1], sys.argv[2]
    rows = []
    for arg in sys.argv[3:]:
        m = re.match(r"(.*\.gl(?:b|tf)):(.+)$", arg)  # LEVEL:LIGHT
        bench(lmbake, m.group(1) if m else arg, rows, m.group(2) if m else None)
    with open(csv, "w") as f:
        f.write("level,edit,changed,redone,quick_shown,save_to_quick_s,quick_error_9x9_rms,save_to_refined_s,"
                "refined_error_9x9_rms,save_to_bounced_s,bounced_error_9x9_rms,save_to_final_s,plain_bake_s\n")
        for r in rows:
            cells = [("%.4f" if k in (6, 8, 10) else "%.2f") % v if isinstance(v, float) else "" if v is None else str(v)
                     for k, v in enumerate(r)]
            f.write(",".join(cells) + "\n")


if __name__ == "__main__":
    main()
