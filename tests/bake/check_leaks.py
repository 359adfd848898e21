#!/usr/bin/env python3
"""No light where no light can go (docs/leaks.md): the leak suite's scenes (tools/leak_scenes.py),
baked with no config but the texel density, read back from the output glTF alone
(tools/leak_measure.py) as an engine would.

usage: check_leaks.py LMBAKE WORKDIR CASE
  CASE  walls:    two sealed rooms split by a wall, one lit: walls 1, 2, 5 and 20 cm thick at
                  0.25x, 1x and 4x the default texel budget's texels (half, once and twice the
                  default density of 62.65 texels per metre: 3.2, 1.6 and 0.8 cm texels; the rooms
                  scaled down so that a bake stays small, the wall and the texels not)
        others:   the crate on a floor, the thin ceiling slab under a sunlit roof, the closed hut
                  in a sunlit courtyard
        lit-side: the lit room's floor along the wall, defaults against the path-traced
                  --reference at the same 5 cm texels (no darkening bought by killing light),
                  stored in data/two-rooms-lit-side-reference.json
        lit-side-reference: makes that file (8192 paths per texel, about 4 minutes)

Asserted in every dark region, as a share of the lit region's lightmap mean: the lightmap's mean,
every texel more than a texel from the region's faces, every probe in it, and probe-lit points a
quarter of the region (at most 0.3 m) inside it through the tetrahedra and through the
irradiance volume: at most 0.1% (the crate: its lightmap only; the slab's room and the hut: not
yet the volume, nor the slab room's tetrahedra, which are printed: docs/leaks.md#limits). lit-side: the mean of the lit floor's texels within 15 cm of the
wall within 2% of the reference's.
"""
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import leak_measure  # noqa: E402
import leak_scenes  # noqa: E402

DEFAULT_DENSITY = 62.65  # texels per metre the defaults pick for the full-size two rooms
BOUND = 0.001
ok = True

# (wall cm, texel budget factor, room scale, extra config): every thickness and every budget at
# least once; the rooms shrink as the texels do so that each bake is a few tens of thousands
WALL_CASES = [(1, 0.25, 0.5, ""), (2, 1, 0.25, ""), (5, 0.25, 0.5, ""), (20, 1, 0.25, ""),
              (1, 4, 0.125, "samples: {gather: 64, direct: 16}\n")]
# scene, texel density, what is asserted in its dark region (inside the crate there is nothing to
# light: no probes there). Measured and printed but not yet met, so not asserted (docs/leaks.md,
# limits): the irradiance volume inside the slab's room and the hut (a voxel grid whose cells
# straddle their walls), the slab room's tetrahedra (one reaches a probe outside its wall)
LIGHTMAP = ("dark_mean", "dark_away_max")
OTHERS = [("box-floor-T", 24, LIGHTMAP), ("slab", 6, LIGHTMAP + ("dark_probe_max",)),
          ("courtyard", 10, LIGHTMAP + ("dark_probe_max", "tetra_max"))]


def check(cond, what):
    global ok
    ok &= bool(cond)
    print("%s %s" % ("ok  " if cond else "FAIL", what), flush=True)


def bake(lmbake, work, scene_path, name, config, *args):
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(config)
    out = os.path.join(work, name)
    p = subprocess.run([lmbake, "bake", scene_path, "-c", cfg, "-o", out, "--threads", "2"] + list(args),
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake %s failed (%d): %s" % (name, p.returncode, p.stderr))
    return out, p.stdout + p.stderr


def scaled_boxes(scene, scale, t_cm):
    """The scene's boxes for rooms scaled by `scale` (the wall keeps its thickness)."""
    w, h, d = (c * scale for c in leak_scenes.ROOM)
    t = t_cm / 100.0
    return ((t / 2, 0, -d / 2), (w + t / 2, h, d / 2), (-w - t / 2, 0, -d / 2), (-t / 2, h, d / 2), (0, t / 2, 1))


def assert_dark(r, label, asserted=None):
    for key, what in (("dark_mean", "lightmap mean"), ("dark_away_max", "brightest texel over a texel from its faces"),
                      ("dark_probe_max", "brightest probe"), ("tetra_max", "probe-lit points, tetrahedra"),
                      ("volume_max", "probe-lit points, irradiance volume")):
        if key not in r:
            if asserted is None or key in asserted:
                check(False, "%s: no %s to read" % (label, what))
            continue
        share = r[key + "_share"]
        if asserted is not None and key not in asserted:
            print("     %s: dark side's %s %.4g lux = %.4f%% of the lit side's (not asserted: docs/leaks.md#limits)" %
                  (label, what, r[key], 100 * share))
            continue
        check(share <= BOUND, "%s: dark side's %s %.4g lux = %.4f%% of the lit side's %.1f lux (bound %.1f%%)" %
              (label, what, r[key], 100 * share, r["lit_mean"], 100 * BOUND))


def walls(lmbake, work):
    for t_cm, factor, scale, extra in WALL_CASES:
        scenes = os.path.join(work, "scenes-%g" % scale)
        os.makedirs(scenes, exist_ok=True)
        leak_scenes.two_rooms(scenes, t_cm, scale)
        name = "two-rooms-%d-%gx" % (t_cm, factor)
        density = DEFAULT_DENSITY * factor ** 0.5
        out, log = bake(lmbake, work, os.path.join(scenes, "two-rooms-%d.gltf" % t_cm), name,
                        "texel_density: %g\n%s" % (density, extra))
        boxes = scaled_boxes("two-rooms", scale, t_cm)
        leak_scenes.LEAK_SCENES[name] = boxes
        margin = min(leak_measure.PROBE_MARGIN, 0.25 * leak_scenes.ROOM[0] * scale)
        r = leak_measure.measure(out, name, margin)
        label = "%d cm wall, %.2f cm texels (%gx)" % (t_cm, 100.0 / density, factor)
        check(r["lit_mean"] > 10, "%s: the lit room is lit (%.1f lux)" % (label, r["lit_mean"]))
        assert_dark(r, label)


def others(lmbake, work):
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "leak_scenes.py"), scenes], check=True)
    for scene, density, asserted in OTHERS:
        out, log = bake(lmbake, work, os.path.join(scenes, scene + ".gltf"), scene,
                        "texel_density: %g\nsamples: {gather: 128}\n" % density)
        r = leak_measure.measure(out, scene, probes_too=len(asserted) > len(LIGHTMAP))
        check(r["lit_mean"] > 10, "%s: the lit region is lit (%.1f lux)" % (scene, r["lit_mean"]))
        assert_dark(r, scene, asserted)


REFERENCE = os.path.join(HERE, "data", "two-rooms-lit-side-reference.json")
REFERENCE_RAYS = 8192


def lit_strip(lmbake, work, name, args):
    """The lit room's floor within 15 cm of the 2 cm wall, at 5 cm texels (2.5 times the wall; the
    same texels in every bake: a mean over texel centres near a wall depends on where they fall):
    (mean lux, texel count) of a bake with `args`."""
    scenes = os.path.join(work, "scenes-lit")
    os.makedirs(scenes, exist_ok=True)
    scale, t_cm = 0.25, 2
    leak_scenes.two_rooms(scenes, t_cm, scale)
    scene = os.path.join(scenes, "two-rooms-%d.gltf" % t_cm)
    out, _ = bake(lmbake, work, scene, "lit-" + name, "texel_density: 20\n", *args)
    doc = json.load(open(os.path.join(out, [f for f in os.listdir(out) if f.endswith(".gltf")][0])))
    blobs = [open(os.path.join(out, b["uri"]), "rb").read() for b in doc["buffers"]]
    lum, pts, size = leak_measure.lightmap_texels(out, doc, blobs)
    t = t_cm / 100.0
    d = leak_scenes.ROOM[2] * scale
    strip = (np.abs(pts[:, 1]) < 1e-4) & (pts[:, 0] < -t / 2) & (pts[:, 0] > -t / 2 - 0.15) & \
        (np.abs(pts[:, 2]) < d / 2 - 0.05)
    return float(lum[strip].mean()), int(strip.sum())


def lit_side_reference(lmbake, work):
    """Writes the stored reference lit_side compares with: lmbake bake --reference at
    REFERENCE_RAYS paths per texel (about 4 minutes on 2 cores)."""
    mean, count = lit_strip(lmbake, work, "reference", ("--reference", "--rays", str(REFERENCE_RAYS)))
    with open(REFERENCE, "w") as f:
        json.dump({"scene": "tools/leak_scenes.py two_rooms(wall 2 cm, scale 0.25), texel_density 20",
                   "made_by": "tests/bake/check_leaks.py LMBAKE WORKDIR lit-side-reference",
                   "rays": REFERENCE_RAYS, "strip_texels": count, "strip_mean_lux": mean}, f, indent=1)
        f.write("\n")
    print("reference: %d floor texels within 15 cm of the wall, mean %.2f lux (%d paths): %s" %
          (count, mean, REFERENCE_RAYS, REFERENCE))


def lit_side(lmbake, work):
    """The lit room's floor within 15 cm of the wall: the defaults against a stored path-traced
    reference of the same texels (tests/bake/data/two-rooms-lit-side-reference.json)."""
    ref = json.load(open(REFERENCE))
    mean, count = lit_strip(lmbake, work, "defaults", ())
    if count != ref["strip_texels"]:
        sys.exit("lit-side: %d strip texels, the reference has %d: the layout changed; remake it with "
                 "'%s'" % (count, ref["strip_texels"], ref["made_by"]))
    means = {"defaults": mean, "reference": ref["strip_mean_lux"]}
    print("defaults: %d floor texels within 15 cm of the wall, mean %.2f lux; reference (%d paths, stored) %.2f lux" %
          (count, mean, ref["rays"], ref["strip_mean_lux"]))
    rel = means["defaults"] / means["reference"] - 1
    check(abs(rel) <= 0.02, "lit floor along the wall: defaults %.2f lux vs reference %.2f lux (%+.2f%%, bound 2%%)" %
          (means["defaults"], means["reference"], 100 * rel))


def main():
    lmbake, work, case = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    {"walls": walls, "others": others, "lit-side": lit_side,
     "lit-side-reference": lit_side_reference}[case](lmbake, work)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
