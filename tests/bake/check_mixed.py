#!/usr/bin/env python3
"""Mixed lighting (docs/mixed-lighting.md): per-light bake modes and the shadowmask.

usage: check_mixed.py LMBAKE WORKDIR CASE   (CASE: superposition, shadowmask, errors)

superposition  two-spots.gltf (a closed 1 m room, a point light 3 cm from the left wall and one
               3 cm from the right wall), 4 bounces, bakes that differ only in lights.modes:
                 A  left baked, right indirect        B  left baked, right realtime
                 C  left realtime, right indirect     D  left realtime, right baked
                 E  D with bounces: 0 (the right light's direct light alone)
               A = B + C (the lightmap of one baked and one indirect light is the bake of the
               first alone plus the indirect part of the second's), and C = D - E (the indirect
               part is a full bake minus its direct light): per object within 1%, and per
               texel over 5 x 5 blocks within 4% rms (the bakes' own noise: the same comparison
               between two seeds of D is printed beside it). The right wall's hot spot, 3 cm
               from its light, is absent from C (its 95th percentile there is under 20% of D's).
shadowmask     sun-plate.gltf (4 x 4 ground, a sun straight down, a plate 1.5 above the x < 0
               half) with the sun `indirect` and output.shadowmask, bounces 0: the lightmap is
               0 everywhere (the sun's direct light is the engine's), and the shadowmask's R
               channel is the sun's visibility. A point sun (lights.sun_angle 0): per texel the
               share of its gather points with x >= 0 (the plate's shadow edge is at x = 0),
               exactly, 8-bit; every texel fully in or out agrees. A sun of 8 degrees: texels
               farther than the penumbra's half width (1.5 tan 4 deg) from the edge are exactly
               0 or 255, those inside follow the disc's profile within 0.1 for 99%. The glTF
               names the sun's channel on the light and on the lightmap texture.
errors         an unknown mode in the config or in a light's extras, more than 4 shadowmask
               lights (a warning naming the extra ones, baked instead), a glob that matches
               nothing (a warning).
"""
import json
import math
import os
import re
import shutil
import subprocess
import sys

import numpy as np
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "tools"))
import check_analytic as ca  # noqa: E402
from make_scenes import PLATE_HEIGHT  # noqa: E402
from object_means import object_means  # noqa: E402

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def scenes(work):
    out = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), out], check=True,
                   stdout=subprocess.DEVNULL)
    return out


def bake(lmbake, work, scene, name, config, expect_ok=True):
    out = os.path.join(work, "out-" + name)
    shutil.rmtree(out, ignore_errors=True)
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(config)
    p = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out], capture_output=True, text=True)
    if expect_ok and p.returncode != 0:
        sys.exit("bake %s failed (%d): %s" % (name, p.returncode, p.stderr[-3000:]))
    return out, p


def exr(out):
    return ca.load_output(out)[1]


def modes(left, right):
    return "lights:\n  modes:\n    - {match: left_spot, mode: %s}\n    - {match: right_spot, mode: %s}\n" % (left, right)


def blocks(img, n=5):
    h, w = img.shape[0] // n * n, img.shape[1] // n * n
    return img[:h, :w].reshape(h // n, n, w // n, n, -1).mean(axis=(1, 3))


def lum(x):
    return 0.2126 * x[..., 0] + 0.7152 * x[..., 1] + 0.0722 * x[..., 2]


def superposition(lmbake, work):
    scene = os.path.join(scenes(work), "two-spots.gltf")
    base = "texel_density: 48\nbounces: 4\noutput: {formats: [exr, mask], directional: false}\n"
    outs = {}
    for key, left, right, extra in (("A", "baked", "indirect", ""), ("B", "baked", "realtime", ""),
                                    ("C", "realtime", "indirect", ""), ("D", "realtime", "baked", ""),
                                    ("D2", "realtime", "baked", "seed: 2\n"),
                                    ("E", "realtime", "baked", "")):
        cfg = base + modes(left, right) + extra
        if key == "E":
            cfg = cfg.replace("bounces: 4", "bounces: 0")
        outs[key], p = bake(lmbake, work, scene, "mixed-" + key, cfg)
        if key == "A":
            log = p.stdout + p.stderr
            check("light 'right_spot': indirect" in log and "light 'left_spot': baked" in log,
                  "the log names each light's mode")
    means = {k: object_means(o) for k, o in outs.items()}
    imgs = {k: list(exr(o).values())[0][..., :3].astype(np.float64) for k, o in outs.items()}
    mask = np.asarray(Image.open(os.path.join(outs["A"], [f for f in os.listdir(outs["A"]) if f.endswith("-mask.png")][0])))
    valid = (mask if mask.ndim == 2 else mask[..., 0]) == 255

    def compare(label, got, want, names):
        worst = max(abs(lum(got[n][0]) / lum(want[n][0]) - 1) for n in names if n != "all" and want[n][1] > 50)
        check(worst <= 0.01, "%s per object: worst %.3f%% (bound 1%%)" % (label, 100 * worst))

    names = list(means["A"])
    sum_bc = {n: (means["B"][n][0] + means["C"][n][0], means["B"][n][1]) for n in names}
    compare("A = B + C", means["A"], sum_bc, names)
    diff_de = {n: (means["D"][n][0] - means["E"][n][0], means["D"][n][1]) for n in names}
    compare("C = D - E", means["C"], diff_de, names)
    wmask = blocks(valid[..., None].astype(float))[..., 0] == 1

    def block_rms(a, b):
        a, b = lum(blocks(a)), lum(blocks(b))
        sel = wmask & (b > 0.05 * np.median(b[wmask]))
        return float(np.sqrt(np.mean(((a - b) / b)[sel] ** 2)))

    noise = block_rms(imgs["D2"], imgs["D"])
    r1 = block_rms(imgs["A"], imgs["B"] + imgs["C"])
    r2 = block_rms(imgs["C"], imgs["D"] - imgs["E"])
    check(r1 <= 0.04 and r2 <= 0.04, "per 5x5 texels: A vs B + C %.2f%% rms, C vs D - E %.2f%% rms (bound 4%%; two seeds "
          "of D differ by %.2f%%)" % (100 * r1, 100 * r2, 100 * noise))
    # the right light's direct hot spot is not in C: compare the brightest texels of D and C
    d, c = lum(imgs["D"])[valid], lum(imgs["C"])[valid]
    check(np.percentile(c, 99.9) < 0.2 * np.percentile(d, 99.9),
          "the indirect light's hot spot is not in its lightmap: 99.9th percentile %.3g vs %.3g baked"
          % (np.percentile(c, 99.9), np.percentile(d, 99.9)))


def shadowmask(lmbake, work):
    scene = os.path.join(scenes(work), "sun-plate.gltf")
    base = ("texel_density: 40\nbounces: 0\nsamples: {texel: 4, direct: 64}\noutput: {formats: [exr], directional: false, "
            "shadowmask: true}\nlights: {sun_angle: %g, modes: [{match: sun, mode: indirect}]}\n")
    d = PLATE_HEIGHT
    for angle in (0.0, 8.0):
        out, _ = bake(lmbake, work, scene, "shadowmask-%g" % angle, base % angle)
        doc = json.load(open(os.path.join(out, "sun-plate.gltf")))
        tex = [t for t in doc["textures"] if "lightmap" in t.get("extras", {})][0]["extras"]["lightmap"]
        charts, images = ca.load_output(out)
        check(max(float(np.abs(i).max()) for i in images.values()) == 0.0,
              "sun %g deg: the lightmap holds none of the indirect sun's direct light (all 0)" % angle)
        light = doc["extensions"]["KHR_lights_punctual"]["lights"][0]
        check(light.get("extras", {}).get("lightmap", {}).get("shadowmaskChannel") == "R" and
              tex.get("shadowmask", {}).get("lights") == {"R": "sun"},
              "the glTF names the sun's channel R on the light and the texture")
        sm = np.asarray(Image.open(os.path.join(out, tex["files"]["shadowmask"]))).astype(np.float64)
        key = list(images)[0]
        rho = math.tan(math.radians(angle / 2))
        full, agree, pen, near = 0, 0, 0, 0
        for node, v, pts, x, y, t in ca.texels(charts, {key: sm}):
            if node != "ground" or any(abs(p[2]) > 1.5 or abs(p[0]) > 1.5 for p in pts):
                continue
            xs = [p[0] for p in pts]
            if angle == 0:
                want = 255 * np.mean([px >= 0 for px in xs])
                full += 1
                agree += abs(v[0] - want) <= 0.5 + 1e-9 if 0 < want < 255 else v[0] == want
                continue
            half = d * rho
            if min(xs) > half + 1e-6 or max(xs) < -half - 1e-6:  # fully lit or fully shadowed
                full += 1
                agree += v[0] == (255 if min(xs) > 0 else 0)
            else:
                want = 255 * np.mean([ca_lit(px / half) for px in xs])
                pen += 1
                near += abs(v[0] - want) <= 0.1 * 255
        if angle == 0:
            check(full > 1000 and agree == full, "point sun: %d/%d ground texels equal the share of their points with "
                  "x >= 0, 8-bit" % (agree, full))
        else:
            check(full > 1000 and agree == full and pen > 20 and near >= 0.99 * pen,
                  "8 deg sun: %d/%d texels fully in or out agree; %d/%d penumbra texels within 0.1 of the disc's "
                  "profile" % (agree, full, near, pen))


def ca_lit(s):
    """Share of a uniform disc left of a line at signed offset s (in radii) from its centre."""
    s = max(-1.0, min(1.0, s))
    return 1 - (math.acos(s) - s * math.sqrt(1 - s * s)) / math.pi


def errors(lmbake, work):
    sc = scenes(work)
    scene = os.path.join(sc, "two-spots.gltf")
    out, p = bake(lmbake, work, scene, "bad-mode", "lights:\n  modes:\n    - {match: left_spot, mode: dynamic}\n", False)
    check(p.returncode == 2 and re.search(r"bad-mode.yaml:3: .*'lights.modes.mode': expected one of baked, indirect, "
                                          r"realtime, got 'dynamic'", p.stderr) and not os.path.exists(out),
          "an unknown mode in the config: exit 2, the line named, no output (%s)" % p.stderr.strip().splitlines()[-1])
    doc = json.load(open(scene))
    doc["extensions"]["KHR_lights_punctual"]["lights"][1]["extras"] = {"lightmap_mode": "stationary"}
    bad = os.path.join(sc, "bad-extras.gltf")
    json.dump(doc, open(bad, "w"))
    out, p = bake(lmbake, work, bad, "bad-extras", "texel_density: 8\n", False)
    check(p.returncode == 2 and "bad-extras.gltf: light 'right_spot'" in p.stderr and "'stationary'" in p.stderr
          and not os.path.exists(out), "an unknown mode in a light's extras: exit 2, file and light named (%s)"
          % p.stderr.strip().splitlines()[-1])
    many = os.path.join(sc, "many-lights.gltf")
    out, p = bake(lmbake, work, many, "five-masks",
                  "texel_density: 2\nbounces: 0\noutput: {shadowmask: true}\nlights:\n  modes:\n"
                  "    - {match: \"lamp*\", mode: indirect}\n    - {match: nothing_here, mode: realtime}\n")
    m = re.search(r"output.shadowmask holds 4 lights; (\d+) more indirect light\(s\) are baked instead: (.*)", p.stderr)
    check(p.returncode == 0 and m is not None and m.group(1) == "16" and "'lamp4'" in m.group(2)
          and "lamp0" not in m.group(2), "20 indirect lights and a shadowmask: the 16 past 4 listed and baked (%s)"
          % (m.group(0)[:90] if m else None))
    check("lights.modes 'nothing_here' matches no light" in p.stderr, "a glob that matches no light: a warning")


def main():
    lmbake, work, case = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    {"superposition": superposition, "shadowmask": shadowmask, "errors": errors}[case](lmbake, work)
    if failures:
        sys.exit("%d check(s) failed" % len(failures))


if __name__ == "__main__":
    main()
