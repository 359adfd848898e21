#!/usr/bin/env python3
"""How probe faces see a lamp's hot spot against the lightmap texels (docs/probes.md#not-yet-built):
a measurement, not a test (the bound is not met yet).

usage: probe_hotspot.py LMBAKE WORKDIR

tools/make_scenes.py's closed Cornell box (1 m, walls of albedo 0.8, a 10 cd point light 5 cm
under the ceiling: a hot spot on the ceiling), no config but the texel density:
  - with POINTS as probes.volumes of one probe each;
  - with a 2 cm cube at each point instead (lightmapped at 1,000 texels per metre): what the
    texels' own estimator (the final gather, AMIS) makes of each face.
Per point and face, the probe's ambient cube against the mean of the cube face's texels (their
centres, through the output's TEXCOORD_1): the faces looking up at the hot spot (+Y) within 2%
each; every face within 3% (the cube's own faces shade each other's surroundings a little).
"""
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import leak_measure  # noqa: E402
from gltf_scene import Scene, box, quad  # noqa: E402

POINTS = [(0.3, 0.15, 0.85), (0.7, 0.15, 0.7), (0.9, 0.12, 0.9), (0.1, 0.15, 0.15), (0.9, 0.35, 0.6)]
HALF = 0.01  # the cubes' half size
FACES = ["+X", "-X", "+Y", "-Y", "+Z", "-Z"]
ok = True


def check(cond, what):
    global ok
    ok &= bool(cond)
    print("%s %s" % ("ok  " if cond else "FAIL", what), flush=True)


def cornell(path, cubes):
    s = Scene()
    white, red, green = (s.material(n, c) for n, c in
                         zip(("white", "red", "green"), ((0.8, 0.8, 0.8), (0.8, 0.1, 0.1), (0.1, 0.8, 0.1))))
    c = [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1), (0, 1, 0), (1, 1, 0), (1, 1, 1), (0, 1, 1)]
    s.mesh("floor", quad(c[0], c[3], c[2], c[1]), white)
    s.mesh("ceiling", quad(c[4], c[5], c[6], c[7]), white)
    s.mesh("back", quad(c[0], c[1], c[5], c[4]), white)
    s.mesh("front", quad(c[3], c[7], c[6], c[2]), white)
    s.mesh("left", quad(c[0], c[4], c[7], c[3]), red)
    s.mesh("right", quad(c[1], c[2], c[6], c[5]), green)
    s.mesh("tall_block", box(0.13, 0, 0.37, 0.43, 0.6, 0.67, bottom=False), white)
    s.mesh("short_block", box(0.55, 0, 0.15, 0.85, 0.3, 0.45, bottom=False), white)
    s.light("ceiling_point", "point", 10.0, translation=(0.5, 0.95, 0.5))
    if cubes:
        grey = s.material("probe_cube", (0.8, 0.8, 0.8))
        for k, p in enumerate(POINTS):
            s.mesh("probe_cube_%d" % k, box(p[0] - HALF, p[1] - HALF, p[2] - HALF, p[0] + HALF, p[1] + HALF, p[2] + HALF),
                   grey)
    s.write(path)


def bake(lmbake, work, name, scene, config):
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(config)
    out = os.path.join(work, name)
    p = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out, "--threads", "2", "-q"], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake %s failed (%d): %s" % (name, p.returncode, p.stderr))
    doc = json.load(open(os.path.join(out, [f for f in os.listdir(out) if f.endswith(".gltf")][0])))
    blobs = [open(os.path.join(out, b["uri"]), "rb").read() for b in doc["buffers"]]
    return out, doc, blobs


def main():
    lmbake, work = sys.argv[1:3]
    os.makedirs(work, exist_ok=True)
    plain, with_cubes = os.path.join(work, "cornell.gltf"), os.path.join(work, "cornell-cubes.gltf")
    cornell(plain, False)
    cornell(with_cubes, True)
    volumes = "".join("    - {min: [%g, %g, %g], max: [%g, %g, %g], resolution: [1, 1, 1]}\n" %
                      (p[0] - HALF, p[1] - HALF, p[2] - HALF, p[0] + HALF, p[1] + HALF, p[2] + HALF) for p in POINTS)
    _, doc, blobs = bake(lmbake, work, "probes", plain,
                         "atlas:\n  texels: 150000\nprobes:\n  auto: false\n  volumes:\n" + volumes)
    pos, cube, _ = leak_measure.probes(doc, blobs)
    out, doc, blobs = bake(lmbake, work, "cubes", with_cubes,
                           "atlas:\n  texels: 150000\ndensity_overrides:\n  - {match: 'probe_cube_*', texel_density: 1000}\n"
                           "probes:\n  auto: false\n")
    lum, pts, _ = leak_measure.lightmap_texels(out, doc, blobs)
    worst_up = worst = 0.0
    for k, p in enumerate(POINTS):
        j = int(np.argmin(((pos - np.array(p)) ** 2).sum(axis=1)))
        check(np.linalg.norm(pos[j] - p) < 1e-4, "probe %d at %s" % (k, np.round(pos[j], 4)))
        for f, name in enumerate(FACES):
            axis, sign = f // 2, 1 - 2 * (f % 2)
            on = np.all(np.abs(pts - p) <= HALF + 1e-6, axis=1) & (np.abs(pts[:, axis] - (p[axis] + sign * HALF)) < 1e-6)
            # the face's own texels only: not on its edges (those are shared with the neighbouring faces)
            for a in range(3):
                if a != axis:
                    on &= np.abs(pts[:, a] - p[a]) < HALF - 1e-6
            face = float(lum[on].mean())
            probe = float(cube[j, f] @ leak_measure.LUM)
            rel = probe / face - 1
            worst = max(worst, abs(rel))
            if name == "+Y":
                worst_up = max(worst_up, abs(rel))
            print("point %d %s: probe %.2f lux, cube face %.2f lux (%d texels): %+.2f%%" %
                  (k, name, probe, face, on.sum(), 100 * rel))
    check(worst_up <= 0.02, "faces looking up at the hot spot: worst %.2f%% (bound 2%%)" % (100 * worst_up))
    check(worst <= 0.03, "every face: worst %.2f%% (bound 3%%)" % (100 * worst))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
