#!/usr/bin/env python3
"""Level-scale unwrap + pack benchmark (issue 10; not a test: it measures time).

Generates (tools/make_levels.py) single-mesh levels of 2x2 .. 10x10 rooms (2k-58k triangles,
zero-area and non-manifold faces) and instanced levels of 250 .. 2,000 props (up to 1.3M
triangles), runs `lmbake unwrap` on each as a whole process under /usr/bin/time -v, and
records charting and packing time, wall time, peak RSS, charts, atlases and covered texels.
  - single-mesh levels at atlas.max_size 4096 and atlas.texels 8,000,000 (the issue's "about
    8M texels"), and the full 58k level also at the defaults;
  - instanced levels at the defaults (one 1024^2 atlas of texels) and the full one at 8M.
Writes CSV and a plot (time against triangles and against charts).

usage: bench_levels.py LMBAKE WORKDIR OUT_CSV OUT_PNG
"""
import csv
import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def run(lmbake, scene, cfg):
    lock = ["flock", "/tmp/lmbake-build.lock"] if shutil.which("flock") else []
    # the lock is taken outside /usr/bin/time: waiting for it is not timed
    args = lock + ["/usr/bin/time", "-v", lmbake, "unwrap", scene, "-q"] + (["-c", cfg] if cfg else [])
    p = subprocess.run(args, capture_output=True, text=True, timeout=3600)
    if p.returncode != 0:
        return {"error": p.stderr.strip().splitlines()[-1][:200]}
    m = re.search(r"total: charting ([0-9.]+) s, packing ([0-9.]+) s, (\d+) charts in (\d+) atlas", p.stdout)
    t = re.search(r"texels: (\d+) covered", p.stdout)
    d = re.search(r"texel density: (?:auto, )?([0-9.eE+-]+)", p.stdout)
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr)
    el = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (?:(\d+):)?(\d+):([0-9.]+)", p.stderr)
    wall = (int(el.group(1) or 0) * 3600 + int(el.group(2)) * 60 + float(el.group(3))) if el else -1
    cov = [float(c) for c in re.findall(r"coverage ([0-9.]+)", p.stdout)]
    return {"charting_s": float(m.group(1)), "packing_s": float(m.group(2)), "charts": int(m.group(3)),
            "atlases": int(m.group(4)), "texels": int(t.group(1)), "density": float(d.group(1)),
            "wall_s": round(wall, 2), "peak_mb": round(int(rss.group(1)) / 1024), "coverage_atlas0": cov[0] if cov else 0}


def triangles(scene, lmbake):
    p = subprocess.run([lmbake, "inspect", scene], capture_output=True, text=True)
    m = re.search(r"triangles: \d+ unique, (\d+) in nodes", p.stdout)
    return int(m.group(1)) if m else 0


def main():
    lmbake, work, out_csv, out_png = sys.argv[1:5]
    os.makedirs(work, exist_ok=True)
    big = os.path.join(work, "8m.yaml")
    with open(big, "w") as f:
        f.write("atlas: {max_size: 4096, texels: 8000000}\n")
    cases = []
    for rooms in (2, 4, 7, 10):
        cases.append(("single", "single:%d" % rooms, "level-single-%d.glb" % rooms, "8M/4096", big))
    cases.append(("single", "single:10", "level-single-10.glb", "defaults", None))
    for count in (250, 500, 1000, 2000):
        cases.append(("instances", "instances:%d" % count, "level-instances-%d.glb" % count, "defaults", None))
    cases.append(("instances", "instances:2000", "level-instances-2000.glb", "8M/4096", big))
    rows = []
    for kind, spec, name, cfg_name, cfg in cases:
        scene = os.path.join(work, name)
        if not os.path.exists(scene):
            subprocess.run([sys.executable, os.path.join(HERE, "make_levels.py"), work, spec], check=True,
                           stdout=subprocess.DEVNULL)
        r = run(lmbake, scene, cfg)
        r.update({"level": name, "kind": kind, "config": cfg_name, "triangles": triangles(scene, lmbake)})
        rows.append(r)
        print(", ".join("%s=%s" % (k, v) for k, v in r.items()), flush=True)
    keys = ["level", "kind", "config", "triangles", "charts", "atlases", "texels", "density", "charting_s",
            "packing_s", "wall_s", "peak_mb", "coverage_atlas0", "error"]
    with open(out_csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in keys})
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    for kind, cfg_name, mark in (("single", "8M/4096", "o-"), ("instances", "defaults", "s-"),
                                 ("single", "defaults", "o"), ("instances", "8M/4096", "s")):
        sel = [r for r in rows if r["kind"] == kind and r["config"] == cfg_name and "error" not in r]
        if not sel:
            continue
        label = "%s, %s" % ("single mesh" if kind == "single" else "instanced", cfg_name)
        ax[0].plot([r["triangles"] for r in sel], [r["wall_s"] for r in sel], mark, label=label)
        ax[1].plot([r["charts"] for r in sel], [r["wall_s"] for r in sel], mark, label=label)
    for a, xl in zip(ax, ("triangles (in nodes)", "charts placed")):
        a.set_xscale("log")
        a.set_yscale("log")
        a.set_xlabel(xl)
        a.set_ylabel("lmbake unwrap wall time, s (unwrap + pack)")
        a.grid(True, which="both", alpha=0.3)
        a.legend(fontsize=8)
    fig.suptitle("Unwrap + pack at level scale (targets: 58k single mesh at 8M texels < 10 s; 1M triangles < 60 s)")
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
    print("wrote %s and %s" % (out_csv, out_png))


if __name__ == "__main__":
    main()
