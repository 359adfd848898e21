#!/usr/bin/env python3
"""The sky and the sun with a size against analytic irradiance (scenes of tools/make_scenes.py;
every texel compared at the points the baker uses, as check_analytic.py does; bounces: 0).

usage: check_sky.py LMBAKE WORKDIR CASE
  plane     an open plane under a uniform sky of L = 1000 nits: E = pi L at every texel, within
            0.3% (the EXR's half floats hold 3142 for 3141.6).
  well      a disk at the bottom of a black cylinder (R 0.5, depth 1) open to the sky: at a point
            r off the axis E = pi L F, F the view factor of the opening, a coaxial disk of radius R
            at height H: F = (1 - (H^2 + r^2 - R^2) / sqrt((H^2 + r^2 + R^2)^2 - 4 r^2 R^2)) / 2;
            at the centre pi L sin^2(alpha), alpha = atan(R / H). sky.samples 2048: the mean ratio
            over the floor and over the texels within 0.1 of the centre both within 1%.
  sealed    the sealed room under a sky of 10^4 nits (and its point light outside): every texel 0.
  patch     an environment map (EXR, written here) black but for a 4 x 4 pixel patch of 5000 at
            40 degrees from the zenith, rotated by sky.rotation: on the open plane E = the patch's
            sum of L x integral of cos over each pixel: the mean within 1%, 99% of texels within 1%.
  sun-map   a 2048 x 1024 map of a uniform sky of 1 with a sun disc of 10^5 (0.53 degrees): the
            mean within 1% of the analytic E with MIS, and the variance over texels at least 10x
            lower than with cosine sampling alone (sky.sampling: cosine) at
            the same rays (figures printed). Cosine sampling alone is unbiased too, but its mean over
            the texels is not yet near E: a few texels hold the sun's light.
  penumbra  a sun straight down (lights.sun_angle 8) and a plate 1.5 above half the ground: the
            shadow edge's penumbra, measured between the 10% and 90% crossings of the irradiance
            across it and scaled by the disc's profile, is 1.5 x tan(8 deg) wide within 10%; the
            texels across the edge follow the disc's profile: off by 0.02 of the sun's irradiance
            on average, 99% within 0.1 (64 shadow rays per point).
  materials materials.override in the furnace (albedo 0.8, 2 nits, two bounces: E = 2 pi (1 +
            0.8 + 0.64) within 1%); a wall with no material beside a plane under a sky: a warning,
            and with materials.default.albedo 0.7 the plane beside it gains over 5%.
  ibl       the file's EXT_lights_image_based irradiance coefficients for L = 500 (1 + y): the open
            plane gets 500 x 5 pi / 3 within 1% (3% per texel); a config sky wins over it, and the
            log names the source; 8 rows of coefficients are refused (exit 2).
  bad-image a sky.image that is missing, outside the config's folder, absolute, not an image or
            not 2:1: exit 2 naming the key, nothing written; with NaN, Inf and negative texels: a
            warning naming how many were replaced by 0.
"""
import math
import os
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

import check_analytic as ca

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from make_scenes import PLATE_HEIGHT, WELL  # noqa: E402

BASE = "texel_density: %d\nbounces: 0\nsamples: {texel: 4, direct: %d}\noutput: {formats: [exr], directional: false}\n"


def bake(lmbake, work, scene, name, config, density=8, direct=16):
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True,
                   stdout=subprocess.DEVNULL)
    cfg = os.path.join(work, name + ".yaml")  # the map files are written beside it
    base = BASE % (density, direct)
    if "bounces:" in config:  # the case's own
        base = base.replace("bounces: 0\n", "")
    with open(cfg, "w") as f:
        f.write(base + config)
    out = os.path.join(work, "out-" + name)
    p = subprocess.run([lmbake, "bake", os.path.join(scenes, scene + ".gltf"), "-c", cfg, "-o", out, "-q"],
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake %s failed (%d): %s" % (name, p.returncode, p.stderr))
    return ca.load_output(out)


def write_map(path, pixels):
    h, w = pixels.shape[:2]
    out = oiio.ImageOutput.create(path)
    out.open(path, oiio.ImageSpec(w, h, 3, "float"))
    out.write_image(pixels.astype(np.float32))
    out.close()


def map_irradiance(pixels, rotation=0.0):
    """E on an open upward plane under an equirectangular map (piecewise constant per pixel):
    sum over the upper rows of L x (2 pi / W) x (sin^2 theta_1 - sin^2 theta_0) / 2."""
    h, w = pixels.shape[:2]
    lum = pixels[..., 0]  # the tests' maps are grey
    total = 0.0
    for j in range(h // 2):
        t0, t1 = math.pi * j / h, math.pi * (j + 1) / h
        total += lum[j].sum() * (2 * math.pi / w) * (math.sin(t1) ** 2 - math.sin(t0) ** 2) / 2
    return total


def plane(lmbake, work):
    charts, images = bake(lmbake, work, "sky-plane", "plane", "sky: {intensity: 1000}\n")
    want = math.pi * 1000
    r = np.array([float(v[0]) / want for node, v, pts, x, y, t in ca.texels(charts, images)])
    good = r.size > 1000 and np.max(np.abs(r - 1)) <= 0.003
    print("plane: uniform sky of 1000 nits: %d texels, E / (pi L) from %.5f to %.5f (bound 1 +- 0.3%%)  %s"
          % (r.size, r.min(), r.max(), "ok" if good else "FAIL"))
    return good


def opening_view_factor(r, R, H):
    return 0.5 * (1 - (H * H + r * r - R * R) / math.sqrt((H * H + r * r + R * R) ** 2 - 4 * r * r * R * R))


def well(lmbake, work):
    L = 1000.0
    charts, images = bake(lmbake, work, "sky-well", "well", "sky: {intensity: %g, samples: 2048}\n"
                            "density_overrides: [{match: wall, texel_density: 8}]\n" % L, density=64)
    R, H = WELL
    ratios, centre = [], []
    for node, v, pts, x, y, t in ca.texels(charts, images):
        if node != "floor" or float(v[0]) <= 0:
            continue
        rs = [math.hypot(p[0], p[2]) for p in pts]
        if max(rs) > R - 0.02:
            continue  # the rim, where the wall meets the floor
        want = np.mean([math.pi * L * opening_view_factor(r, R, H) for r in rs])
        ratios.append(float(v[0]) / want)
        if max(rs) < 0.1:
            centre.append((float(v[0]), want))
    ratios = np.array(ratios)
    alpha = math.atan(R / H)
    mean = ratios.mean()
    centre_ratio = sum(c[0] for c in centre) / sum(c[1] for c in centre)
    good = ratios.size > 500 and len(centre) > 50 and abs(mean - 1) <= 0.01 and abs(centre_ratio - 1) <= 0.01
    print("well: %d floor texels, mean E / (pi L F(r)) %.4f (bound 1 +- 1%%); %d texels within 0.1 of the centre: "
          "%.4f of it (bound 1 +- 1%%); pi L sin^2(alpha) = %.1f lux, they hold %.1f  %s"
          % (ratios.size, mean, len(centre), centre_ratio, math.pi * L * math.sin(alpha) ** 2,
             np.mean([c[0] for c in centre]), "ok" if good else "FAIL"))
    return good


def sealed(lmbake, work):
    charts, images = bake(lmbake, work, "sealed-room", "sealed", "sky: {intensity: 10000, ground_color: [1, 1, 1]}\n")
    m = max(float(np.max(img)) for img in images.values())
    n = sum(1 for _ in ca.texels(charts, images))
    good = m == 0.0 and n > 1000
    print("sealed: a closed room under a sky of 10^4 nits: %d texels, largest value %g (must be 0)  %s"
          % (n, m, "ok" if good else "FAIL"))
    return good


def patch(lmbake, work):
    w, h = 512, 256
    pixels = np.zeros((h, w, 3))
    row = int(round(40 / 180 * h))
    pixels[row:row + 4, 300:304] = 5000.0
    write_map(os.path.join(work, "patch.exr"), pixels)
    charts, images = bake(lmbake, work, "sky-plane", "patch", "sky: {intensity: 1, image: patch.exr, rotation: 70}\n")
    want = map_irradiance(pixels)
    r = np.array([float(v[0]) / want for node, v, pts, x, y, t in ca.texels(charts, images)])
    within = np.mean(np.abs(r - 1) <= 0.01)
    good = r.size > 1000 and abs(r.mean() - 1) <= 0.01 and within >= 0.99
    print("patch: a 4 x 4 pixel patch of 5000 at 40 deg from the zenith: E = %.4f lux; %d texels, mean %.4f of it "
          "(bound 1 +- 1%%), %.2f%% within 1%% (bound 99%%), from %.4f to %.4f  %s"
          % (want, r.size, r.mean(), 100 * within, r.min(), r.max(), "ok" if good else "FAIL"))
    return good


def sun_map(lmbake, work):
    w, h = 2048, 1024
    pixels = np.ones((h, w, 3))
    # a disc of 0.53 degrees' diameter at 35 degrees from the zenith
    th = (np.arange(h) + 0.5) / h * math.pi
    ph = (np.arange(w) + 0.5) / w * 2 * math.pi - math.pi
    tt, pp = np.meshgrid(th, ph, indexing="ij")
    sun_t, sun_p = math.radians(35), 0.4
    dirs = np.stack([np.sin(tt) * np.sin(pp), np.cos(tt), -np.sin(tt) * np.cos(pp)], axis=-1)
    sun = np.array([math.sin(sun_t) * math.sin(sun_p), math.cos(sun_t), -math.sin(sun_t) * math.cos(sun_p)])
    disc = dirs @ sun >= math.cos(math.radians(0.53 / 2))
    pixels[disc] = 1e5
    write_map(os.path.join(work, "sun.exr"), pixels)
    want = map_irradiance(pixels)
    got = {}
    for mode in ("mis", "cosine"):
        charts, images = bake(lmbake, work, "sky-plane", "sun-" + mode,
                              "sky: {intensity: 1, image: sun.exr, sampling: %s, samples: 16}\n" % mode)
        got[mode] = np.array([float(v[0]) / want for node, v, pts, x, y, t in ca.texels(charts, images)])
    ok = abs(got["mis"].mean() - 1) <= 0.01
    for mode, r in got.items():
        print("sun-map, %-6s: %d texels, mean E / analytic %.4f%s, relative variance over texels %.3g"
              % (mode, r.size, r.mean(), " (bound 1 +- 1%%)  %s" % ("ok" if ok else "FAIL") if mode == "mis" else "",
                 r.var()))
    ratio = got["cosine"].var() / max(got["mis"].var(), 1e-30)
    good = ratio >= 10
    print("sun-map: a 10^5:1 sun disc (%d pixels) in a 2048 x 1024 map, E = %.1f lux: variance cosine / MIS = %.1f "
          "at equal rays (bound >= 10)  %s" % (int(disc.sum()), want, ratio, "ok" if good else "FAIL"))
    return ok and good


def lit_fraction(s):
    """Share of a uniform disc left of a line at signed offset s (in radii) from its centre."""
    s = max(-1.0, min(1.0, s))
    return 1 - (math.acos(s) - s * math.sqrt(1 - s * s)) / math.pi


def penumbra(lmbake, work):
    angle, sun = 8.0, 1000.0
    charts, images = bake(lmbake, work, "sun-plate", "penumbra", "lights: {sun_angle: %g}\n" % angle, density=64,
                          direct=64)
    d, rho = PLATE_HEIGHT, math.tan(math.radians(angle / 2))
    xs, es, off = [], [], []
    for node, v, pts, x, y, t in ca.texels(charts, images):
        if node != "ground" or any(abs(p[2]) > 1.5 for p in pts):
            continue
        px = float(np.mean([p[0] for p in pts]))
        if abs(px) > 2 * d * rho:
            continue
        xs.append(px)
        es.append(float(v[0]) / sun)
        want = np.mean([lit_fraction(p[0] / (d * rho)) for p in pts])
        off.append(abs(es[-1] - want))
    xs, es = np.array(xs), np.array(es)
    bins = np.arange(-2 * d * rho, 2 * d * rho, 1.0 / 64)  # a texel wide
    centres = 0.5 * (bins[1:] + bins[:-1])
    means = np.array([es[(xs >= a) & (xs < b)].mean() for a, b in zip(bins[:-1], bins[1:])])

    def crossing(level):
        k = int(np.argmax(means >= level))
        return centres[k - 1] + (level - means[k - 1]) / (means[k] - means[k - 1]) * (centres[k] - centres[k - 1])

    s10 = -1.0
    while lit_fraction(s10) < 0.1:
        s10 += 1e-5
    measured = (crossing(0.9) - crossing(0.1)) / (-2 * s10) * 2  # 10-90 width -> the full width, 2 d rho
    expected = d * math.tan(math.radians(angle))
    off = np.array(off)
    within = np.mean(off <= 0.1)
    good = abs(measured / expected - 1) <= 0.1 and within >= 0.99 and off.mean() <= 0.02
    print("penumbra: sun of %g deg, plate %.2f above: full width %.4f (from the 10-90%% width %.4f), d x tan(angle) "
          "= %.4f, ratio %.3f (bound 1 +- 10%%); %d texels across the edge off the disc's profile by %.4f of the sun "
          "on average (bound 0.02), %.2f%% within 0.1 (bound 99%%)  %s"
          % (angle, d, measured, crossing(0.9) - crossing(0.1), expected, measured / expected, off.size, off.mean(),
             100 * within, "ok" if good else "FAIL"))
    return good


def bad_image(lmbake, work):
    """Each bad sky.image: exit 2, an error naming the key and the file, no output folder."""
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True,
                   stdout=subprocess.DEVNULL)
    with open(os.path.join(work, "not-an-image.exr"), "w") as f:
        f.write("plain text\n")
    write_map(os.path.join(work, "square.exr"), np.ones((64, 64, 3)))
    nan = np.ones((32, 64, 3))
    nan[3, 5, 1], nan[7, 9, 0], nan[1, 1, 2] = np.nan, np.inf, -2.0
    write_map(os.path.join(work, "nan.exr"), nan)
    os.makedirs(os.path.join(work, "elsewhere"), exist_ok=True)
    write_map(os.path.join(work, "elsewhere", "sky.exr"), np.ones((32, 64, 3)))
    cases = [("missing.exr", 2, "sky.image"), ("../elsewhere/sky.exr", 2, "sky.image': '../elsewhere/sky.exr'"),
             ("/etc/passwd", 2, "sky.image': '/etc/passwd'"), ("not-an-image.exr", 2, "sky.image"),
             ("square.exr", 2, "is 64x64: an equirectangular map is twice as wide as it is high"),
             ("nan.exr", 0, "3 texel value(s) that were not finite or were negative replaced by 0")]
    ok = True
    sub = os.path.join(work, "configs")
    os.makedirs(sub, exist_ok=True)
    for image, code, message in cases:
        folder = work if not image.startswith("../") else sub
        cfg = os.path.join(folder, "bad.yaml")
        with open(cfg, "w") as f:
            f.write("texel_density: 2\nsky: {intensity: 10, image: \"%s\"}\n" % image)
        out = os.path.join(work, "out-bad")
        p = subprocess.run([lmbake, "bake", os.path.join(scenes, "sky-plane.gltf"), "-c", cfg, "-o", out],
                           capture_output=True, text=True)
        good = p.returncode == code and message in p.stderr and (code == 0) == os.path.exists(out)
        ok &= good
        last = [l for l in p.stderr.splitlines() if "sky" in l]
        print("sky.image %-22s exit %d (want %d): %s  %s" % (image, p.returncode, code, last[-1] if last else "",
                                                            "ok" if good else "FAIL"))
        subprocess.run(["rm", "-rf", out])
    return ok


def materials(lmbake, work):
    """materials.override and materials.default against what they must give."""
    ok = True
    # the furnace (albedo 0.5, 1 nit) overridden to albedo 0.8 and 2 nits, two bounces (default rays):
    # E = pi x 2 x (1 + 0.8 + 0.64)
    cfg = ("bounces: 2\n"
           "materials: {override: [{match: \"furn*\", albedo: [0.8, 0.8, 0.8], emissive: [2, 2, 2]}]}\n")
    charts, images = bake(lmbake, work, "furnace", "override", cfg, direct=64)
    v = np.array([float(x[1][0]) for x in ca.texels(charts, images)])
    want = math.pi * 2 * (1 + 0.8 + 0.64)
    good = abs(v.mean() / want - 1) <= 0.01
    ok &= good
    print("materials.override: furnace at albedo 0.8 and 2 nits: mean E %.4f = %.4f x pi Le (1 + rho + rho^2) "
          "(bound 1 +- 1%%)  %s" % (v.mean(), v.mean() / want, "ok" if good else "FAIL"))
    # a wall with no material beside the open plane: without materials.default the bake warns and
    # the wall reflects nothing (the plane beside it gets the sky it sees, < pi L); with albedo
    # 0.7 the wall bounces sky light onto it
    near = {}
    for label, extra in (("none", ""), ("0.7", "materials: {default: {albedo: [0.7, 0.7, 0.7]}}\n")):
        scenes = os.path.join(work, "scenes")
        cfg_path = os.path.join(work, "bare-%s.yaml" % label)
        with open(cfg_path, "w") as f:
            f.write((BASE % (8, 16)).replace("bounces: 0", "bounces: 2") + "sky: {intensity: 1000}\n" + extra)
        out = os.path.join(work, "out-bare-" + label)
        p = subprocess.run([lmbake, "bake", os.path.join(scenes, "sky-bare-wall.gltf"), "-c", cfg_path, "-o", out],
                           capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit("bake bare-%s failed (%d): %s" % (label, p.returncode, p.stderr))
        charts, images = ca.load_output(out)
        vals = [float(x[1][0]) for x in ca.texels(charts, images) if x[0] == "plane" and
                all(0.1 < p[0] < 1.0 and abs(p[2]) < 4 for p in x[2])]
        near[label] = (np.mean(vals), p.stdout + p.stderr)
    warned = "have no material, so they get glTF's default material" in near["none"][1]
    told = "bounce light with albedo [0.7, 0.7, 0.7] (materials.default.albedo)" in near["0.7"][1]
    gain = near["0.7"][0] / near["none"][0]
    good = warned and told and near["none"][0] < math.pi * 1000 and gain > 1.05
    ok &= good
    print("materials.default: the plane within 1 of a bare wall under a 1000-nit sky: %.1f lux without (< pi L = "
          "%.1f; warned: %s), %.1f with albedo 0.7 (x %.3f, bound > 1.05; said: %s)  %s"
          % (near["none"][0], math.pi * 1000, warned, near["0.7"][0], gain, told, "ok" if good else "FAIL"))
    return ok


def ibl(lmbake, work):
    """The file's EXT_lights_image_based irradiance as the sky: L(w) = L0 (1 + w.y), whose
    irradiance coefficients are E_00 = pi L0 sqrt(4 pi) and E_1,-1 = (2 pi / 3) L0 0.488603 (4 pi / 3);
    an upward plane gets E = L0 (pi + 2 pi / 3). A config sky wins over it (the log says so); a
    malformed light is refused naming the extension."""
    import json as jsonlib
    L0 = 500.0
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True,
                   stdout=subprocess.DEVNULL)
    doc = jsonlib.load(open(os.path.join(scenes, "sky-plane.gltf")))
    sh = [[0.0] * 3 for _ in range(9)]
    for c in range(3):
        sh[0][c] = math.pi * L0 * math.sqrt(4 * math.pi)
        sh[1][c] = 2 * math.pi / 3 * L0 * 0.488603 * 4 * math.pi / 3
    doc["extensionsUsed"] = doc.get("extensionsUsed", []) + ["EXT_lights_image_based"]
    doc["extensions"] = {"EXT_lights_image_based": {"lights": [{"name": "dome", "intensity": 1.0,
                                                                "irradianceCoefficients": sh,
                                                                "specularImageSize": 1, "specularImages": []}]}}
    doc["scenes"][0]["extensions"] = {"EXT_lights_image_based": {"light": 0}}
    path = os.path.join(scenes, "sky-ibl.gltf")
    with open(path, "w") as f:
        jsonlib.dump(doc, f)
    ok = True
    runs = {}
    for label, config in (("file", ""), ("config", "sky: {intensity: 1000}\n")):
        cfg = os.path.join(work, "ibl-%s.yaml" % label)
        with open(cfg, "w") as f:
            f.write(BASE % (8, 16) + config)
        out = os.path.join(work, "out-ibl-" + label)
        p = subprocess.run([lmbake, "bake", path, "-c", cfg, "-o", out], capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit("bake ibl-%s failed: %s" % (label, p.stderr))
        charts, images = ca.load_output(out)
        runs[label] = (np.array([float(x[1][0]) for x in ca.texels(charts, images)]), p.stdout + p.stderr)
    want = L0 * (math.pi + 2 * math.pi / 3)
    r = runs["file"][0] / want
    said = "sky: the file's EXT_lights_image_based light 'dome'" in runs["file"][1]
    good = said and r.size > 1000 and abs(r.mean() - 1) <= 0.01 and np.max(np.abs(r - 1)) <= 0.03
    ok &= good
    print("ibl: L = %g (1 + y) from the file's irradiance coefficients: E / (5 pi L0 / 3) mean %.4f, from %.4f to %.4f "
          "(bounds 1%% and 3%%); log names the source: %s  %s" % (L0, r.mean(), r.min(), r.max(), said,
                                                                 "ok" if good else "FAIL"))
    c = runs["config"][0] / (math.pi * 1000)
    said = "sky: from the config (sky.intensity 1000); the file's EXT_lights_image_based light 'dome' is not used" \
        in runs["config"][1]
    good = said and abs(c.mean() - 1) <= 0.003
    ok &= good
    print("ibl: a config sky of 1000 nits wins: E / (pi L) %.5f; the log says so: %s  %s"
          % (c.mean(), said, "ok" if good else "FAIL"))
    doc["extensions"]["EXT_lights_image_based"]["lights"][0]["irradianceCoefficients"] = sh[:8]
    bad = os.path.join(scenes, "sky-ibl-bad.gltf")
    with open(bad, "w") as f:
        jsonlib.dump(doc, f)
    out = os.path.join(work, "out-ibl-bad")
    p = subprocess.run([lmbake, "bake", bad, "-o", out], capture_output=True, text=True)
    good = p.returncode == 2 and "EXT_lights_image_based: light 0: irradianceCoefficients must be 9 x 3" in p.stderr \
        and not os.path.exists(out)
    ok &= good
    print("ibl: 8 rows of coefficients: exit %d, %s  %s" % (p.returncode, p.stderr.strip().splitlines()[-1][:120],
                                                           "ok" if good else "FAIL"))
    return ok


def main():
    lmbake, work, case = sys.argv[1], sys.argv[2], sys.argv[3]
    os.makedirs(work, exist_ok=True)
    checks = {"plane": plane, "well": well, "sealed": sealed, "patch": patch, "sun-map": sun_map,
              "penumbra": penumbra, "bad-image": bad_image, "materials": materials, "ibl": ibl}
    sys.exit(0 if checks[case](lmbake, work) else 1)


if __name__ == "__main__":
    main()
