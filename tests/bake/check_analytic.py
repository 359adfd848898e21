#!/usr/bin/env python3
"""Bakes the generated analytic scenes (tools/make_scenes.py) and compares every texel of the
EXR lightmaps with the formulas of ../shared/DESIGN.md section 3.

usage: check_analytic.py LMBAKE WORKDIR CASE
  CASE: point-plane | many-lights | many-lights-drawn | sun-box | sun-bright | disk | disk-textured | disk-transform | sealed-room | box-floor | alpha-cards

For each texel the expected value is computed at the same points the baker uses: the
stratum centres of the texel (samples.texel), each clamped onto the closest triangle of
its chart within one texel, exactly as baker/texels/texels.c does, mapped to world space
through the output glTF's TEXCOORD_1 and POSITION. Needs Debian's python3-openimageio.
"""
import json
import math
import os
import struct
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SAMPLES = 4  # samples.texel in the configs below

CONFIG = """texel_density: 8
bounces: 0        # direct light only: the formulas are direct irradiance
samples:
  texel: %d
  direct: %d
"""
# area-light samples per point: 256, more where a third of the emitter is black (per-texel bounds)
# many-lights: 128 samples a round against 20 lights, every light is evaluated; many-lights-drawn:
# 8 a round, the lights are drawn by their unshadowed irradiance at the point
DIRECT = {"disk-transform": 1024, "many-lights-drawn": 16}
# cases that bake another case's scene with more config: sun-bright is sun-box at 100,000 lux,
# irradiance past half float's 65504 (the EXR must hold it, not Inf)
SCENE = {"sun-bright": "sun-box", "many-lights-drawn": "many-lights"}
# the sun here is the hard one of the formula (lights.sun_angle 0); sun-penumbra checks the disc
EXTRA = {"sun-box": "lights: {sun_angle: 0}\n", "alpha-cards": "lights: {sun_angle: 0}\n", "sun-bright": "lights: {intensity_scale: 100, sun_angle: 0}\n"}


def bake(lmbake, work, case):
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True)
    cfg = os.path.join(work, "analytic.yaml")
    with open(cfg, "w") as f:
        f.write(CONFIG % (SAMPLES, DIRECT.get(case, 256)) + EXTRA.get(case, ""))
    out = os.path.join(work, "out-" + case)
    p = subprocess.run([lmbake, "bake", os.path.join(scenes, SCENE.get(case, case) + ".gltf"), "-c", cfg, "-o", out, "-q",
                        "--threads", "2"], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake failed (%d): %s" % (p.returncode, p.stderr))
    return out


def read_accessor(doc, bins, index):
    a = doc["accessors"][index]
    v = doc["bufferViews"][a["bufferView"]]
    data = bins[v["buffer"]]
    comps = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[a["type"]]
    fmt = {5126: "f", 5125: "I", 5123: "H"}[a["componentType"]]
    size = struct.calcsize(fmt)
    stride = v.get("byteStride", size * comps)
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    out = []
    for i in range(a["count"]):
        out.append(struct.unpack_from("<%d%s" % (comps, fmt), data, start + i * stride))
    return out


def load_output(out):
    name = [f for f in os.listdir(out) if f.endswith(".gltf")][0]
    doc = json.load(open(os.path.join(out, name)))
    bins = [open(os.path.join(out, b["uri"]), "rb").read() for b in doc["buffers"]]
    charts = []  # (node name, atlas texture, [(world tri, uv tri)])
    for node in doc["nodes"]:
        if "mesh" not in node:
            continue
        t = node.get("translation", [0, 0, 0])
        for prim in doc["meshes"][node["mesh"]]["primitives"]:
            if "TEXCOORD_1" not in prim["attributes"]:
                continue
            mat = doc["materials"][prim["material"]]
            tex = mat["extensions"]["MOZ_lightmap"]["index"]
            pos = read_accessor(doc, bins, prim["attributes"]["POSITION"])
            uv = read_accessor(doc, bins, prim["attributes"]["TEXCOORD_1"])
            idx = [i[0] for i in read_accessor(doc, bins, prim["indices"])]
            tris = []
            for k in range(0, len(idx), 3):
                w = [tuple(pos[idx[k + j]][c] + t[c] for c in range(3)) for j in range(3)]
                u = [uv[idx[k + j]] for j in range(3)]
                tris.append((w, u))
            charts.append((node["name"], tex, tris))
    images = {}
    for ti in sorted({c[1] for c in charts}):
        png = doc["images"][doc["textures"][ti]["source"]]["uri"]
        exr = os.path.join(out, png[:-4] + ".exr")
        inp = oiio.ImageInput.open(exr)
        images[ti] = inp.read_image("float")
        inp.close()
    return charts, images


def closest_on_triangle(u, p):
    """(distance, barycentrics) of the closest point of 2D triangle u to p; as texels.c."""
    ax, ay = u[0]
    e1 = (u[1][0] - ax, u[1][1] - ay)
    e2 = (u[2][0] - ax, u[2][1] - ay)
    det = e1[0] * e2[1] - e2[0] * e1[1]
    if det == 0:
        return math.inf, None
    px, py = p[0] - ax, p[1] - ay
    b1 = (px * e2[1] - e2[0] * py) / det
    b2 = (e1[0] * py - px * e1[1]) / det
    if b1 >= 0 and b2 >= 0 and b1 + b2 <= 1:
        return 0.0, (1 - b1 - b2, b1, b2)
    best = (math.inf, None)
    for k in range(3):
        a, b = u[k], u[(k + 1) % 3]
        dx, dy = b[0] - a[0], b[1] - a[1]
        l2 = dx * dx + dy * dy
        t = max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2)) if l2 > 0 else 0.0
        d = math.hypot(a[0] + t * dx - p[0], a[1] + t * dy - p[1])
        if d < best[0]:
            w = [0.0, 0.0, 0.0]
            w[k] = 1 - t
            w[(k + 1) % 3] = t
            best = (d, tuple(w))
    return best


def subsample(k):
    sx = math.ceil(math.sqrt(SAMPLES))
    sy = (SAMPLES + sx - 1) // sx
    return ((k % sx) + 0.5) / sx, ((k // sx) + 0.5) / sy


def texels(charts, images):
    """Yields (node, value rgb, [world points of the texel's sub-samples], texel x, y, atlas)."""
    for tex, img in images.items():
        h, w = img.shape[0], img.shape[1]
        best = {}  # (x, y, k) -> (dist, node, world point)
        for node, t, tris in charts:
            if t != tex:
                continue
            for wt, ut in tris:
                ut = [(c[0] * w, c[1] * h) for c in ut]
                x0 = max(0, int(math.floor(min(c[0] for c in ut))) - 1)
                x1 = min(w - 1, int(math.floor(max(c[0] for c in ut))) + 1)
                y0 = max(0, int(math.floor(min(c[1] for c in ut))) - 1)
                y1 = min(h - 1, int(math.floor(max(c[1] for c in ut))) + 1)
                for y in range(y0, y1 + 1):
                    for x in range(x0, x1 + 1):
                        for k in range(SAMPLES):
                            sx, sy = subsample(k)
                            d, b = closest_on_triangle(ut, (x + sx, y + sy))
                            key = (x, y, k)
                            if d <= 1.0 and (key not in best or d < best[key][0] - 1e-6):
                                p = tuple(sum(b[j] * wt[j][c] for j in range(3)) for c in range(3))
                                best[key] = (d, node, p)
        grouped = {}
        for (x, y, k), (d, node, p) in best.items():
            grouped.setdefault((x, y), []).append((node, p))
        for (x, y), pts in grouped.items():
            yield pts[0][0], img[y, x, :3], [p for _, p in pts], x, y, tex


def point_plane(charts, images):
    worst, n = 0.0, 0
    for node, v, pts, x, y, _ in texels(charts, images):
        e = np.mean([100.0 * 2.0 / (2.0 ** 2 + p[0] ** 2 + p[2] ** 2) ** 1.5 for p in pts])
        worst = max(worst, abs(v[0] / e - 1))
        n += 1
    print("point-plane: %d texels, worst relative error %.4f%% (bound 0.5%%)" % (n, 100 * worst))
    return n > 5000 and worst <= 0.005


def many_lights(charts, images, how="all 20 evaluated (256 samples per point)"):
    sys.path.insert(0, os.path.join(ROOT, "tools"))
    from make_scenes import MANY_LIGHTS
    ratios = []
    for node, v, pts, x, y, _ in texels(charts, images):
        e = np.mean([sum(i * 2.0 / ((p[0] - lx) ** 2 + 4.0 + (p[2] - lz) ** 2) ** 1.5 for lx, lz, i in MANY_LIGHTS)
                     for p in pts])
        ratios.append(v[0] / e)
    r = np.array(ratios)
    mean, worst = float(np.mean(r)), float(np.max(np.abs(r - 1)))
    # every light evaluated, or drawn in proportion to its unshadowed irradiance at the point
    # (white lights: with nothing in the way every draw weighs the exact sum): only float rounding
    # is left (drawn by power, as before, the texels spread by up to 14%)
    print("many-lights: 20 point lights, %s: mean ratio to the exact sum %.5f over %d texels (bound 1 +- 0.1%%), "
          "worst %.4f%% off (bound 0.5%%)" % (how, mean, len(r), 100 * worst))
    return len(r) > 5000 and abs(mean - 1) < 0.001 and worst <= 0.005


def in_cube_shadow(p, d):
    """Ray from p toward the sun (-d) hits the cube [-0.5, 0.5] x [0, 1] x [-0.5, 0.5]?"""
    o, r = p, (-d[0], -d[1], -d[2])
    t0, t1 = 1e-6, 1e9
    for a, lo, hi in ((0, -0.5, 0.5), (1, 0.0, 1.0), (2, -0.5, 0.5)):
        if abs(r[a]) < 1e-12:
            if o[a] < lo or o[a] > hi:
                return False
            continue
        ta, tb = (lo - o[a]) / r[a], (hi - o[a]) / r[a]
        t0, t1 = max(t0, min(ta, tb)), min(t1, max(ta, tb))
    return t0 < t1


def sun_box(charts, images, sun=1000.0):
    ang = math.radians(30)
    d = (math.sin(ang), -math.cos(ang), 0.0)
    lit_e = sun * math.cos(ang)
    side_e = sun * 0.5
    ok, counts = True, {"lit": 0, "shadow": 0, "top": 0, "side": 0}
    for node, v, pts, x, y, _ in texels(charts, images):
        if node == "plane":
            if any(abs(p[0]) < 0.5 + 0.2 and abs(p[2]) < 0.5 + 0.2 for p in pts):
                continue  # at or under the cube: inside geometry / contact line
            shadow = [in_cube_shadow((p[0], 1e-4, p[2]), d) for p in pts]
            if all(shadow):
                counts["shadow"] += 1
                ok &= v[0] == 0.0
                if v[0] != 0.0:
                    print("  shadow texel", x, y, v[0], pts[0])
            elif not any(shadow):
                counts["lit"] += 1
                ok &= abs(v[0] / lit_e - 1) <= 0.005
                if abs(v[0] / lit_e - 1) > 0.005:
                    print("  lit texel", x, y, v[0], pts[0])
        elif node == "cube":
            inner = all(abs(p[2]) < 0.5 - 1e-6 for p in pts)  # not on an edge shared by two faces
            if inner and all(abs(p[1] - 1.0) < 1e-6 and abs(p[0]) < 0.5 - 1e-6 for p in pts):
                counts["top"] += 1
                ok &= abs(v[0] / lit_e - 1) <= 0.005
                if abs(v[0] / lit_e - 1) > 0.005:
                    print("  top texel", x, y, v[0], pts[0])
            elif inner and all(abs(p[0] + 0.5) < 1e-6 and 0.05 < p[1] < 1 - 1e-6 for p in pts):
                counts["side"] += 1  # the -x face: cos = 0.5
                ok &= abs(v[0] / side_e - 1) <= 0.005
                if abs(v[0] / side_e - 1) > 0.005:
                    print("  side texel", x, y, v[0], pts[0])
    print("sun-box: %s texels checked; lit = %.1f lux +-0.5%%, shadow exactly 0, -x face %.0f lux: %s" %
          (counts, lit_e, side_e, "ok" if ok else "FAIL"))
    return ok and min(counts.values()) > 10


def disk_e(L, R, h, r):
    """Irradiance from a uniform disk (radiance L, radius R) at height h, at distance r off its
    axis, on a plane parallel to it; r = 0 gives pi L R^2 / (h^2 + R^2)."""
    a = h * h + r * r
    return math.pi * L / 2 * (1 - (a - R * R) / math.sqrt((a + R * R) ** 2 - 4 * r * r * R * R))


def disk(charts, images, L=10.0):
    R, h = 0.5, 1.0
    centre = disk_e(L, R, h, 0.0)
    best = None
    for node, v, pts, x, y, _ in texels(charts, images):
        if node != "plane":
            continue
        c = np.mean(pts, axis=0)
        dist = math.hypot(c[0], c[2])
        if best is None or dist < best[0]:
            want = np.mean([disk_e(L, R, h, math.hypot(p[0], p[2])) for p in pts])
            best = (dist, float(v[0]), want)
    err = abs(best[1] / best[2] - 1)
    print("disk: texel under the centre (%.3f m off axis) %.4f lux, analytic %.4f at its points (%.4f at the centre, "
          "pi L R^2 / (h^2 + R^2)), error %.3f%% (bound 2%%); 256 area samples x %d points per texel; the 64-gon "
          "has 0.16%% less area than the disk" % (best[0], best[1], best[2], centre, 100 * err, SAMPLES))
    return err <= 0.02


def disk_textured(charts, images):
    srgb = 128 / 255.0
    return disk(charts, images, L=10.0 * ((srgb + 0.055) / 1.055) ** 2.4)


def polygon_e(L, poly, p):
    """Irradiance at p (normal +y) from a uniform polygon emitter of radiance L seen from its
    front: Lambert's formula, E = L/2 sum_i angle(r_i, r_i+1) (n . unit(r_i x r_i+1)), exact."""
    r = [np.subtract(v, p) for v in poly]
    total = 0.0
    for i in range(len(r)):
        a, b = r[i], r[(i + 1) % len(r)]
        c = np.cross(a, b)
        ln = np.linalg.norm(c)
        if ln > 0:
            ang = math.atan2(ln, float(np.dot(a, b)))
            total += ang * c[1] / ln
    return abs(L / 2 * total)


def clip(poly, keep):
    """Sutherland-Hodgman: the part of convex polygon poly where keep(v) = a . (x, z) + b >= 0."""
    out = []
    for i in range(len(poly)):
        a, b = poly[i], poly[(i + 1) % len(poly)]
        fa, fb = keep(a), keep(b)
        if fa >= 0:
            out.append(a)
        if (fa >= 0) != (fb >= 0):
            t = fa / (fa - fb)
            out.append(tuple(a[c] + t * (b[c] - a[c]) for c in range(3)))
    return out


def disk_transform(charts, images):
    """The 64-gon emitter lit only where KHR_texture_transform maps TEXCOORD_1 = (x, z) onto the
    white texel: u' = sx cos(r) x + sy sin(r) z + ox >= 0.5 (counter-clockwise in UV space, the
    extension's convention; textures.c). Every floor texel within 1.5 m of the axis is compared
    with the exact polygon irradiance at its points: the mean ratio within 1%, 95% of texels
    within 6% (1024 area-light samples per point, a third landing on the black part). The
    rotation's sign flipped (how the extension's GLSL listing reads) and no transform at all
    (TEXCOORD_1 read as is: u = x >= 0.5) must each move over 20% of those texels by more than
    6%, so the test tells them apart."""
    sys.path.insert(0, os.path.join(ROOT, "tools"))
    from make_scenes import DISK_TRANSFORM as T
    L, n, R, h = 10.0, 64, 0.5, 1.0
    ring = [(R * math.cos(2 * math.pi * k / n), h, R * math.sin(2 * math.pi * k / n)) for k in range(n)]
    c, sn = math.cos(T["rotation"]), math.sin(T["rotation"])
    sx, sy, ox = T["scale"][0], T["scale"][1], T["offset"][0]
    lit = {"spec": clip(ring, lambda v: sx * c * v[0] + sy * sn * v[2] + ox - 0.5),
           "flipped": clip(ring, lambda v: sx * c * v[0] - sy * sn * v[2] + ox - 0.5),
           "none": clip(ring, lambda v: v[0] - 0.5)}
    full = polygon_e(L, ring, (0, 0, 0))
    ratios, others = [], {"flipped": [], "none": []}
    for node, v, pts, x, y, _ in texels(charts, images):
        if node != "plane" or any(math.hypot(q[0], q[2]) > 1.5 for q in pts):
            continue
        want = np.mean([polygon_e(L, lit["spec"], q) for q in pts])
        ratios.append(float(v[0]) / want)
        for k in others:
            others[k].append(np.mean([polygon_e(L, lit[k], q) for q in pts]) / want)
    r = np.array(ratios)
    mean, worst, within = float(np.mean(r)), float(np.max(np.abs(r - 1))), float(np.mean(np.abs(r - 1) <= 0.06))
    # how many texels a wrong convention would move by more than the 6% tolerance
    off = {k: float(np.mean(np.abs(np.array(o) - 1) > 0.06)) for k, o in others.items()}
    print("disk-transform: %d floor texels within 1.5 m of the axis; E / exact polygon irradiance of the lit part "
          "(%.1f%% of the 64-gon's area): mean %.4f (bound 1 +- 1%%), worst %.2f%%, %.1f%% of texels within 6%% "
          "(bound 95%%); full 64-gon at the centre %.4f lux vs disk formula %.4f. Texels whose value a wrong "
          "convention moves by more than 6%%: rotation sign flipped %.0f%%, no transform %.0f%% (both must exceed "
          "20%%)" % (len(r), 100 * polygon_area(lit["spec"]) / polygon_area(ring), mean, 100 * worst, 100 * within,
                     full, disk_e(L, R, h, 0.0), 100 * off["flipped"], 100 * off["none"]))
    return (len(r) > 300 and abs(mean - 1) <= 0.01 and within >= 0.95 and off["flipped"] > 0.2
            and off["none"] > 0.2)


def polygon_area(poly):
    return 0.5 * abs(sum(a[0] * b[2] - b[0] * a[2] for a, b in zip(poly, poly[1:] + poly[:1])))


def sealed_room(charts, images):
    m = max(float(np.max(img)) for img in images.values())
    n = sum(1 for _ in texels(charts, images))
    print("sealed-room: %d texels, largest value in any atlas %g (must be 0)" % (n, m))
    return m == 0.0 and n > 1000


def box_floor(charts, images):
    under, ok, halo_checked = 0, True, 0
    values = {}
    for node, v, pts, x, y, tex in texels(charts, images):
        values[(tex, x, y)] = (node, v, pts)
        if node == "plane" and all(abs(p[0]) < 1 - 2.5 / 8 and abs(p[2]) < 1 - 2.5 / 8 for p in pts):
            under += 1
            ok &= float(v[0]) == 0.0
    # padding just outside the floor chart: close to the floor texels it borders
    for tex, img in images.items():
        h, w = img.shape[0], img.shape[1]
        for (t, x, y), (node, v, pts) in values.items():
            if t != tex or node != "plane":
                continue
            for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                xx, yy = x + dx, y + dy
                if 0 <= xx < w and 0 <= yy < h and (tex, xx, yy) not in values and v[0] > 0:
                    halo_checked += 1
                    ok &= float(img[yy, xx, 0]) >= 0.5 * float(v[0])
    print("box-floor: %d floor texels well under the cube are 0 (no leak); %d padding texels next to the floor "
          "hold at least half their neighbour (no dark halo): %s" % (under, halo_checked, "ok" if ok else "FAIL"))
    return ok and under > 10 and halo_checked > 50


def card_pass(p):
    """RGB share of the sun (straight down) that reaches ground point p through the alpha cards
    (tools/make_scenes.py ALPHA_CARDS): MASK cut where the checker's alpha is 0, BLEND 1 - alpha,
    transmission the base colour; which card it is under (None: none)."""
    sys.path.insert(0, os.path.join(ROOT, "tools"))
    from make_scenes import ALPHA_CARDS, ALPHA_CHECKER, BLEND_ALPHA, GLASS_TINT
    for name, x0 in ALPHA_CARDS.items():
        u, v = p[0] - x0, p[2] + 0.5
        if 0 <= u < 1 and 0 <= v < 1:
            if name == "mask":
                a = ALPHA_CHECKER[int(2 * v)][int(2 * u)][3] / 255.0
                return (1.0,) * 3 if a < 0.5 else (0.0,) * 3, name
            if name == "blend":
                return (1 - BLEND_ALPHA,) * 3, name
            return GLASS_TINT, name
    return (1.0,) * 3, None


def alpha_cards(charts, images, sun=1000.0):
    """Under each card the ground's direct light is the sun times what the card lets through, texel
    by texel (0.5%), and on average: the MASK card's half (1%) with its checker's cells within 2%,
    BLEND's 1 - alpha (1%), the glass's tint per channel (1%)."""
    ok, worst, n = True, 0.0, 0
    sums = {}  # card or (card, cell) -> [sum of measured rgb, sum of expected rgb, texels]
    for node, v, pts, x, y, _ in texels(charts, images):
        if node != "ground":
            continue
        passes = [card_pass(p) for p in pts]
        expected = np.mean([q for q, _ in passes], axis=0) * sun
        n += 1
        err = np.max(np.abs(v - expected)) / sun
        worst = max(worst, err)
        if err > 0.005:
            ok = False
            print("  texel", x, y, v, "expected", expected, pts[0])
        cards = {c for _, c in passes}
        if len(cards) == 1 and None not in cards:
            card = cards.pop()
            keys = [card]
            if card == "mask":
                cells = {(int(2 * (p[0] + 2.0)), int(2 * (p[2] + 0.5))) for p in pts}
                if len(cells) == 1:
                    keys.append("mask cell %d,%d" % cells.pop())
            for k in keys:
                acc = sums.setdefault(k, [np.zeros(3), np.zeros(3), 0])
                acc[0] += v
                acc[1] += expected
                acc[2] += 1
    print("alpha-cards: %d ground texels, worst error %.3f%% of the sun (bound 0.5%%)" % (n, 100 * worst))
    for k in sorted(sums):
        got, want, count = sums[k][0] / sums[k][2], sums[k][1] / sums[k][2], sums[k][2]
        if want.max() > 0:
            rel = np.max(np.abs(got - want) / np.maximum(want, 1e-3 * sun))
        else:
            rel = got.max() / sun
        bound = 0.01 if k in ("mask", "blend", "glass") else 0.02
        good = rel <= bound
        ok &= good
        print("  %-16s %4d texels, mean %s lux, expected %s: %.3f%% (bound %.0f%%)  %s" %
              (k, count, np.round(got, 1), np.round(want, 1), 100 * rel, 100 * bound, "ok" if good else "FAIL"))
    return ok and n > 500 and {"mask", "blend", "glass"} <= set(sums)


def main():
    lmbake, work, case = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    out = bake(lmbake, work, case)
    charts, images = load_output(out)
    check = {"point-plane": point_plane, "many-lights": many_lights,
             "many-lights-drawn": lambda c, i: many_lights(c, i, "drawn by their unshadowed irradiance (16 samples per point, 8 a round)"), "sun-box": sun_box, "sun-bright": lambda c, i: sun_box(c, i, 100000.0), "disk": disk, "disk-textured": disk_textured, "disk-transform": disk_transform, "sealed-room": sealed_room,
             "box-floor": box_floor, "alpha-cards": alpha_cards}[case]
    return 0 if check(charts, images) else 1


if __name__ == "__main__":
    sys.exit(main())
