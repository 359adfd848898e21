#!/usr/bin/env python3
"""The unwrap on a generated level (tools/make_levels.py single:2, 2,332 triangles of soup: quads
whose second triangle OpenMesh re-added on copied vertices, rows of touching crates, thin walls,
stairs), through `lmbake unwrap`:
  - at the defaults: the faces pressed together (crates touching, feet of walls, crates, pillars
    and stairs on the floor, a lintel on its wall) hidden: at least 400 of the 2,332 triangles (530
    now), the log saying so; at most 300 charts, 0 overlapping texels, L2 stretch at most 1.001,
    coverage at least 0.82 (0.846 now);
  - with `atlas.skip_hidden: false`: none hidden, at most 486 charts (0.6 x the 810 before coplanar
    links and gluing; 436 now), 0 overlapping texels, coverage at least 0.75 (0.776 now; 0.70
    before gluing) and below the defaults';
  - an explicit density above the fit estimate but within what the packer places (14 texels per
    unit in a 1024 atlas; the estimate is about 12.9) bakes, and says the packer decided;
  - one the packer cannot place (15) is exit 2, naming the instance and the estimate.

usage: check_level_unwrap.py LMBAKE WORKDIR
"""
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
ok = True


def check(cond, what):
    global ok
    ok &= bool(cond)
    print("%s %s" % ("ok  " if cond else "FAIL", what))


def unwrap(lmbake, level, work, text):
    config = os.path.join(work, "level.yaml")
    with open(config, "w") as f:
        f.write(text)
    return subprocess.run([lmbake, "unwrap", level, "-c", config], capture_output=True, text=True, timeout=600)


def atlas_line(out):
    m = re.search(r"atlas 0: ([0-9]+)x([0-9]+), ([0-9]+) charts, coverage ([0-9.]+), L2 stretch ([0-9.]+).*"
                  r"overlapping texels ([0-9]+)", out)
    if not m:
        sys.exit("no atlas line in:\n" + out[-1500:])
    return int(m.group(1)), int(m.group(2)), int(m.group(3)), float(m.group(4)), float(m.group(5)), int(m.group(6))


def hidden_count(out):
    m = re.search(r"mesh 'Level': [0-9]+ triangles \([0-9]+ zero-area, ([0-9]+) hidden\)", out)
    if not m:
        sys.exit("no mesh line in:\n" + out[-1500:])
    return int(m.group(1))


def main():
    lmbake, work = sys.argv[1:3]
    os.makedirs(work, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_levels.py"), work, "single:2"], check=True,
                   stdout=subprocess.DEVNULL)
    level = os.path.join(work, "level-single-2.glb")
    p = unwrap(lmbake, level, work, "{}\n")
    check(p.returncode == 0, "defaults: unwrap exits 0")
    hidden = hidden_count(p.stdout)
    check(hidden >= 400, "defaults: %d triangles hidden (at least 400)" % hidden)
    check(re.search(r"layout: %d of 2332 triangles .* lie back to back with another face inside a solid" % hidden,
                    p.stdout + p.stderr), "defaults: the log says how many were hidden")
    w, h, charts, coverage, stretch, overlaps = atlas_line(p.stdout)
    check(charts <= 300, "defaults: %d charts (at most 300)" % charts)
    check(overlaps == 0, "defaults: %d overlapping texels" % overlaps)
    check(stretch <= 1.001, "defaults: L2 stretch %.4f (at most 1.001)" % stretch)
    check(coverage >= 0.82, "defaults: coverage %.4f (at least 0.82)" % coverage)
    p = unwrap(lmbake, level, work, "atlas: {skip_hidden: false}\n")
    w, h, all_charts, all_coverage, stretch, overlaps = atlas_line(p.stdout)
    check(p.returncode == 0 and hidden_count(p.stdout) == 0, "skip_hidden false: none hidden")
    check(all_charts <= 486 and all_charts > charts, "skip_hidden false: %d charts (at most 486, more than %d)"
          % (all_charts, charts))
    check(overlaps == 0, "skip_hidden false: %d overlapping texels" % overlaps)
    check(0.75 <= all_coverage < coverage, "skip_hidden false: coverage %.4f (at least 0.75, below %.4f)"
          % (all_coverage, coverage))
    p = unwrap(lmbake, level, work, "texel_density: 14\natlas: {max_size: 1024}\n")
    check(p.returncode == 0 and "the packer decides" in p.stderr + p.stdout,
          "14 texels per unit in a 1024 atlas: above the estimate, packed (exit %d)" % p.returncode)
    if p.returncode == 0:
        w, h, charts, coverage, stretch, overlaps = atlas_line(p.stdout)
        check(w <= 1024 and h <= 1024 and overlaps == 0, "  atlas %dx%d, %d overlapping texels" % (w, h, overlaps))
    p = unwrap(lmbake, level, work, "texel_density: 15\natlas: {max_size: 1024}\n")
    check(p.returncode == 2 and "instance 'Level'" in p.stderr and "is estimated to fit" in p.stderr
          and "atlas 0:" not in p.stdout,
          "15 texels per unit: exit %d, the packer's error names the instance and the estimate" % p.returncode)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
