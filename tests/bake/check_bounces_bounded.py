#!/usr/bin/env python3
"""`bounces: auto` stops once the tail is known well enough, even where the ratio never settles.

An open yard under a noon sun: a 16 x 16 ground (albedo 0.5) and eight 2 x 4 x 2 blocks (albedo
0.9). Light bounces between the ground and the blocks' sides and escapes to the open sky, so what
a pass adds falls fast, and the passes' ratios (0.37, 0.30) differ by more than the settling
test allows (0.02 + 5%). The third rule of `bounces: auto` (docs/defaults.md "Bounces auto") stops
when every ratio the last two passes allow gives the same total within a tenth of
`bounces_auto.tail` (0.5% at the default) of the light.
Asserted:
  - the log gives that rule as the reason, after fewer passes than `bounces_auto.max`;
  - with `bounces_auto.tail: 0.005` (a bound of 0.05%) the passes go on longer;
  - the yard's mean light is within 0.5% (the rule's bound) + 0.3% (the two bakes' noise) of
    `bounces: 16`, fifteen passes and no extrapolation;
  - the indirect light (the mean minus `bounces: 0`'s) is over 5% of the direct light, so the
    comparison can see a missing bounce.

usage: check_bounces_bounded.py LMBAKE WORKDIR
"""
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "tools"))
import bake_cli  # noqa: E402
import make_scenes  # noqa: E402

ok = True


def check(cond, what):
    global ok
    ok &= bool(cond)
    print("%s %s" % ("ok  " if cond else "FAIL", what))


def mean_light(exr):
    """Mean of the lit texels (the bake's mask) over every atlas of the bake EXR is atlas 0 of."""
    import numpy as np
    import OpenImageIO as oiio
    total, count = 0.0, 0
    out = os.path.dirname(exr)
    for n in sorted(os.listdir(out)):
        if n.endswith(".exr") and not n.endswith("-dir.exr"):
            px = np.array(oiio.ImageBuf(os.path.join(out, n)).get_pixels(oiio.FLOAT))[..., :3]
            mask = np.array(oiio.ImageBuf(os.path.join(out, n[:-4] + "-mask.png")).get_pixels(oiio.UINT8))[..., 0]
            lit = mask == 255
            total += float(px[lit].sum())
            count += int(lit.sum()) * 3
    return total / count


def bake(lmbake, scene, work, name, bounces, more=""):
    """(mean light, stdout) of a bake at 20,000 texels with `bounces` and more config text."""
    exr, log = bake_cli.bake(lmbake, work, scene, name, "atlas:\n  texels: 20000\nbounces: %s\nprobes:\n  auto: false\n"
                             "output:\n  formats: [exr, mask]\n%s" % (bounces, more))
    return mean_light(exr), log


def main():
    lmbake, work = sys.argv[1:3]
    os.makedirs(work, exist_ok=True)
    s = make_scenes.Scene()
    grey, white = s.material("grey", (0.5, 0.5, 0.5)), s.material("white", (0.9, 0.9, 0.9))
    s.mesh("ground", make_scenes.plane(16), grey)
    for i, (x, z) in enumerate([(-5, -5), (0, -5), (5, -5), (-5, 0), (5, 0), (-5, 5), (0, 5), (5, 5)]):
        s.mesh("block%d" % i, make_scenes.box(x - 1, 0, z - 1, x + 1, 4, z + 1, bottom=False), white)
    s.light("sun", "directional", 3.0, rotation=(-0.7071068, 0.0, 0.0, 0.7071068))  # straight down
    scene = os.path.join(work, "yard.gltf")
    s.write(scene)

    direct, _ = bake(lmbake, scene, work, "bounces-0", 0)
    auto, log = bake(lmbake, scene, work, "bounces-auto", "auto")
    _, log_tight = bake(lmbake, scene, work, "bounces-auto-tight", "auto", "bounces_auto:\n  tail: 0.005\n")
    many, _ = bake(lmbake, scene, work, "bounces-16", 16)
    m = re.search(r"bounces: auto, ([0-9]+) pass\(es\).*", log)
    print(m.group(0) if m else "no bounces line in the log")
    check(m and "any ratio the last two passes allow" in m.group(0) and int(m.group(1)) < 31,
          "bounces auto stopped by the tail's bound after %s pass(es)" % (m.group(1) if m else "?"))
    t = re.search(r"bounces: auto, ([0-9]+) pass\(es\).*", log_tight)
    print(t.group(0) if t else "no bounces line in the tight bake's log")
    check(m and t and int(t.group(1)) > int(m.group(1)),
          "bounces_auto.tail 0.005: %s pass(es), more than the default's" % (t.group(1) if t else "?"))
    check(many - direct > 0.05 * direct, "indirect light %.4g, %.1f%% of the direct light %.4g"
          % (many - direct, 100 * (many - direct) / direct, direct))
    check(abs(auto / many - 1) < 0.008, "bounces auto: mean %.5g = %.4f x bounces 16's %.5g (within 0.8%%)"
          % (auto, auto / many, many))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
