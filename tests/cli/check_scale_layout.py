#!/usr/bin/env python3
"""Layouts at game scale, through `lmbake unwrap` and one `lmbake bake` (tools/make_levels.py
levels: gpu:300, 300 copies of a 3,968-triangle prop through one EXT_mesh_gpu_instancing node
over a ground, and single:2, the soup level):
  - the texel budget kept: at the defaults, and with atlas.texels 60,000, where the props'
    atlas.min_chart_texels floors cannot all be met, the layout makes at most 110% of
    atlas.texels; the second says how many props fall short and by how much;
  - with atlas.texels 20,000 the props' 18 charts each (5,401 in all) take more than the budget
    at any density (edges and padding): the props are lit by the light probes instead, a
    warning names the mesh, its 300 copies and what the charts take whatever the density (over
    the budget), and the ground's layout keeps the budget; with atlas.max_size 128 the copies
    (one atlas for all) fit no atlas at any density: they go to the probes too, not an error;
  - 0 overlapping texels in every atlas of both levels at 1x and 4x the default budget;
  - a bake where nothing emits light (the sun made `realtime`) stops after the layout: the
    warning, no light stage, black lightmaps, and the same texels as the layout counted.

usage: check_scale_layout.py LMBAKE WORKDIR
"""
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DEFAULT_BUDGET = 629145
ok = True


def check(cond, what):
    global ok
    ok &= bool(cond)
    print("%s %s" % ("ok  " if cond else "FAIL", what))


def run(cmd):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=900)


def unwrap(lmbake, level, work, name, text):
    config = os.path.join(work, name + ".yaml")
    with open(config, "w") as f:
        f.write(text)
    return run([lmbake, "unwrap", level, "-c", config])


def budget_line(out):
    m = re.search(r"texel density: auto, ([0-9.e+-]+) texels per unit \(budget ([0-9]+) texels; ([0-9]+) made", out)
    if not m:
        sys.exit("no texel density line in:\n" + out[-1500:])
    return float(m.group(1)), int(m.group(2)), int(m.group(3))


def overlapping(out):
    atlases = re.findall(r"atlas [0-9]+: .*overlapping texels ([0-9]+)", out)
    return len(atlases), sum(int(a) for a in atlases)


def check_layout(lmbake, level, work, label, budget, expect_short=False):
    p = unwrap(lmbake, level, work, label, "atlas:\n  texels: %d\n" % budget)
    check(p.returncode == 0, "%s: unwrap exits 0" % label)
    if p.returncode != 0:
        print(p.stderr[-1500:])
        return
    density, said_budget, made = budget_line(p.stdout)
    check(said_budget == budget and made <= 1.10 * budget,
          "%s: %d texels made for atlas.texels %d (%.0f%%, at most 110%%) at %.4g texels per unit"
          % (label, made, budget, 100.0 * made / budget, density))
    n, overlaps = overlapping(p.stdout)
    check(n > 0 and overlaps == 0, "%s: %d overlapping texels over %d atlas(es)" % (label, overlaps, n))
    if expect_short:
        m = re.search(r"atlas.min_chart_texels: ([0-9]+) small instance\(s\) fall short of charts ([0-9]+) texels "
                      r"wide to keep the texel budget: they get ([0-9]+)% of that density", p.stderr)
        check(m and int(m.group(1)) > 0 and 0 < int(m.group(3)) < 100,
              "%s: the log names the props short of their floor (%s)" % (label, m.group(0) if m else p.stderr[-400:]))


def main():
    lmbake, work = sys.argv[1:3]
    os.makedirs(work, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_levels.py"), work, "gpu:300", "single:2"],
                   check=True, stdout=subprocess.DEVNULL)
    gpu = os.path.join(work, "level-gpu-300.glb")
    single = os.path.join(work, "level-single-2.glb")
    check_layout(lmbake, gpu, work, "gpu:300 defaults", DEFAULT_BUDGET)
    check_layout(lmbake, gpu, work, "gpu:300 atlas.texels 60000", 60000, expect_short=True)
    p = unwrap(lmbake, gpu, work, "gpu:300 atlas.texels 20000", "atlas:\n  texels: 20000\n")
    m = re.search(r"texel budget: ([0-9]+) instance\(s\) of 1 mesh\(es\) drawn many times are lit by the light "
                  r"probes, not the lightmap: 'Prop' \(300\)\. With them every chart together takes about ([0-9]+) "
                  r"texels whatever the density", p.stderr)
    _, _, made = budget_line(p.stdout) if p.returncode == 0 else (0, 0, -1)
    check(p.returncode == 0 and m and int(m.group(1)) == 300 and int(m.group(2)) > 20000 and 0 < made <= 22000,
          "gpu:300 atlas.texels 20000: the props go to the probes, said with the numbers (%s); %d texels made"
          % (m.group(0) if m else p.stderr[-600:], made))
    check("no density keeps it" not in p.stderr, "gpu:300 atlas.texels 20000: no 'no density keeps it' warning")
    # atlas.max_size 128: the 300 copies, which share one atlas, fit none at any density
    p = unwrap(lmbake, gpu, work, "gpu:300 atlas.max_size 128", "atlas:\n  max_size: 128\n")
    m = re.search(r"texel budget: 300 instance\(s\) of 1 mesh\(es\) drawn many times are lit by the light probes, "
                  r"not the lightmap: 'Prop' \(300\)\. The copies of a node share one atlas, and theirs fit no "
                  r"128x128 atlas at any density", p.stderr)
    _, budget, made = budget_line(p.stdout) if p.returncode == 0 else (0, 1, -1)
    check(p.returncode == 0 and m and 0 < made <= 1.10 * budget,
          "gpu:300 atlas.max_size 128: the copies go to the probes instead of an error (%s); %d texels for %d"
          % (m.group(0) if m else p.stderr[-600:], made, budget))
    n, overlaps = overlapping(p.stdout)
    check(n > 0 and overlaps == 0, "gpu:300 atlas.texels 20000: %d overlapping texels" % overlaps)
    check_layout(lmbake, gpu, work, "gpu:300 4x budget", 4 * DEFAULT_BUDGET)
    check_layout(lmbake, single, work, "single:2 defaults", DEFAULT_BUDGET)
    check_layout(lmbake, single, work, "single:2 4x budget", 4 * DEFAULT_BUDGET)

    # nothing emits: the layout, black lightmaps, no light computed
    config = os.path.join(work, "dark.yaml")
    with open(config, "w") as f:
        f.write("atlas:\n  texels: 20000\nlights:\n  modes:\n    - {match: '*', mode: realtime}\n")
    out = os.path.join(work, "dark-out")
    p = run([lmbake, "bake", gpu, "-c", config, "-o", out])
    check(p.returncode == 0, "dark bake exits 0")
    check("nothing emits light" in p.stderr and "no light is computed" in p.stderr, "dark bake: the warning")
    check(not re.search(r"^(direct|bounce pass|final gather|seams):", p.stderr + p.stdout, re.M),
          "dark bake: no light stage and no seams ran")
    texels = re.search(r"bake: .* ([0-9]+) texels \(([0-9]+) valid\)", p.stdout)
    layout = unwrap(lmbake, gpu, work, "dark-layout", "atlas:\n  texels: 20000\n")
    _, _, made = budget_line(layout.stdout)
    check(texels and int(texels.group(1)) == made, "dark bake: %s texels, the layout's %d"
          % (texels.group(1) if texels else "?", made))
    try:
        import OpenImageIO as oiio
        import numpy as np
        for name in sorted(os.listdir(out)):
            if name.endswith(".exr"):
                img = oiio.ImageBuf(os.path.join(out, name))
                px = np.array(img.get_pixels(oiio.FLOAT))
                check(px.size > 0 and float(np.abs(px).max()) == 0.0, "dark bake: %s is black" % name)
    except ImportError:
        check(False, "OpenImageIO's Python module (python3-openimageio) to read the EXR")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
