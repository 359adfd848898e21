#!/usr/bin/env python3
"""A surface without a lightmap bounces its direct light once, whatever the bounce passes.

A 10 x 10 ground (albedo 0.8) and a 10 x 3 wall beside it (albedo 0.8, `lightmap.exclude`d, so
it has no lightmap), a 50 cd point light between them. The ground is flat: it sees only the
wall and the open sky, so its indirect light is the wall's direct light bounced once, the same
with one bounce (the final gather alone) as with `bounces: auto` (bounce passes, then the final
gather). A bounce pass after the first gathers what the last pass added; a wall without a
lightmap adds nothing then (its only light is its direct light, the first pass's). Asserted:
  - the ground's indirect light (its mean minus the mean of `bounces: 0`) is over 2% of its
    direct light, so the check can see it;
  - `bounces: auto` gives that indirect light within 3% of `bounces: 1`, and so does
    `bounces: 4` (three passes);
  - the auto log's second pass adds under 0.1% (it stops there).

usage: check_unmapped_bounce.py LMBAKE WORKDIR
"""
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import make_scenes  # noqa: E402

ok = True


def check(cond, what):
    global ok
    ok &= bool(cond)
    print("%s %s" % ("ok  " if cond else "FAIL", what))


def ground_mean(out):
    import numpy as np
    import OpenImageIO as oiio
    exrs = sorted(n for n in os.listdir(out) if n.endswith(".exr") and not n.endswith("-dir.exr"))
    masks = sorted(n for n in os.listdir(out) if n.endswith("-mask.png"))
    if len(exrs) != 1 or len(masks) != 1:
        sys.exit("expected one atlas with its mask in %s: %s" % (out, sorted(os.listdir(out))))
    px = np.array(oiio.ImageBuf(os.path.join(out, exrs[0])).get_pixels(oiio.FLOAT))[..., :3]
    mask = np.array(oiio.ImageBuf(os.path.join(out, masks[0])).get_pixels(oiio.UINT8))[..., 0]
    lit = mask == 255
    return float(px[lit].mean())


def bake(lmbake, scene, work, name, bounces):
    config = os.path.join(work, name + ".yaml")
    with open(config, "w") as f:
        f.write("atlas:\n  texels: 20000\nbounces: %s\nlightmap:\n  exclude: [wall]\nprobes:\n  auto: false\n"
                "output:\n  formats: [exr, mask]\n" % bounces)
    out = os.path.join(work, name)
    p = subprocess.run([lmbake, "bake", scene, "-c", config, "-o", out], capture_output=True, text=True, timeout=600)
    if p.returncode != 0:
        sys.exit("bake %s failed:\n%s" % (name, p.stderr[-2000:]))
    return ground_mean(out), p.stdout + p.stderr


def main():
    lmbake, work = sys.argv[1:3]
    os.makedirs(work, exist_ok=True)
    s = make_scenes.Scene()
    white = s.material("white", (0.8, 0.8, 0.8))
    s.mesh("ground", make_scenes.plane(10), white)
    s.mesh("wall", make_scenes.quad((-5, 0, -1.5), (5, 0, -1.5), (5, 3, -1.5), (-5, 3, -1.5)), white)  # faces +z
    s.light("lamp", "point", 50.0, translation=(0, 1.5, 0))
    scene = os.path.join(work, "ground-wall.gltf")
    s.write(scene)

    direct, _ = bake(lmbake, scene, work, "bounces-0", 0)
    one, _ = bake(lmbake, scene, work, "bounces-1", 1)
    auto, log = bake(lmbake, scene, work, "bounces-auto", "auto")
    four, _ = bake(lmbake, scene, work, "bounces-4", 4)
    ind_one, ind_auto, ind_four = one - direct, auto - direct, four - direct
    check(ind_one > 0.02 * direct, "the wall's bounce on the ground: %.5g, %.2f%% of the direct light %.5g"
          % (ind_one, 100 * ind_one / direct, direct))
    check(abs(ind_auto / ind_one - 1) < 0.03, "bounces auto: indirect %.5g = %.4f x bounces 1's" % (ind_auto, ind_auto / ind_one))
    check(abs(ind_four / ind_one - 1) < 0.03, "bounces 4: indirect %.5g = %.4f x bounces 1's" % (ind_four, ind_four / ind_one))
    m = re.search(r"bounces: auto, ([0-9]+) pass\(es\) \+ final gather; each pass added \(share of the direct light\): ([^;]*);", log)
    shares = [float(x.rstrip("%")) for x in m.group(2).split()] if m else []
    check(len(shares) >= 2 and shares[1] < 0.1, "bounces auto: the passes added %s%% of the direct light"
          % (" ".join(map(str, shares)) if m else "?"))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
