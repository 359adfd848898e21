#!/usr/bin/env python3
"""What light groups cost and what they save (docs/light-groups.md), side by side in one run.

usage: bench_light_groups.py LMBAKE OUTDIR [LEVEL:CONFIG ...]
Per level, one after the other on this machine, each under /usr/bin/time -v (wall seconds, peak
resident memory):
  plain      lmbake bake without groups;
  groups     the same level with output.light_groups (the config named), with --layout-cache:
             every group lit on its own and kept;
  rescaled   the groups' scales edited (each x 0.5, the last x 3), with the same --layout-cache:
             every group read back, only the sum and the files written;
  fresh      that rescaled config without the cache (what the rescaled files must equal, byte
             for byte: the `identical` column).
Writes OUTDIR/light-groups.csv and OUTDIR/light-groups.png (seconds per level and run).
Defaults: bench/levels/level-single-10.glb in groups {Sun} and {Lamp*}, and bevy's Cornell box in
one group, its emissive ceiling (what the groups cost by themselves): about 6 minutes on 2 cores.
"""
import csv
import filecmp
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULTS = [
    ("bench/levels/level-single-10.glb", [("sun", "match: Sun"), ("lamps", 'match: "Lamp*"')]),
    ("assets/scenes/cornell-box-bevy/CornellBox.glb", [("ceiling", "emissive: true")]),
]


def config(groups, scales):
    lines = ["output:", "  light_groups:"]
    for (name, holds), s in zip(groups, scales):
        lines.append('    - {name: %s, %s, scale: %r}' % (name, holds, s))
    return "\n".join(lines) + "\n"


def run(lmbake, level, cfg_text, out, work, name, *extra):
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(cfg_text)
    shutil.rmtree(out, ignore_errors=True)
    r = subprocess.run(["/usr/bin/time", "-v", lmbake, "bake", level, "-c", cfg, "-o", out] + list(extra),
                       capture_output=True, text=True)
    if r.returncode:
        sys.exit("%s: %s failed:\n%s" % (level, name, r.stderr[-2000:]))
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (?:(\d+):)?(\d+):([\d.]+)", r.stderr)
    secs = (int(wall.group(1) or 0) * 3600 + int(wall.group(2)) * 60 + float(wall.group(3)))
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", r.stderr).group(1)) / 1024.0
    return secs, rss, r.stdout + r.stderr


def main():
    lmbake, outdir = sys.argv[1], sys.argv[2]
    levels = DEFAULTS
    if len(sys.argv) > 3:
        sys.exit("bench_light_groups.py: the levels and their groups are the defaults above")
    os.makedirs(outdir, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for level, groups in levels:
            level = os.path.join(ROOT, level)
            if not os.path.exists(level):
                print("skipping %s: missing (tools/make_levels.py bench/levels single:10 makes it)" % level)
                continue
            name = os.path.splitext(os.path.basename(level))[0]
            cache = os.path.join(work, name + "-cache")
            ones = [1.0] * len(groups)
            edited = [0.5] * (len(groups) - 1) + [3.0]
            plain = run(lmbake, level, "{}\n", os.path.join(work, "plain"), work, name + "-plain", "-q")
            grouped = run(lmbake, level, config(groups, ones), os.path.join(work, "groups"), work, name + "-groups",
                          "--layout-cache", cache, "-q")
            rescaled = run(lmbake, level, config(groups, edited), os.path.join(work, "rescaled"), work,
                           name + "-rescaled", "--layout-cache", cache)
            fresh = run(lmbake, level, config(groups, edited), os.path.join(work, "fresh"), work, name + "-fresh", "-q")
            a, b = os.path.join(work, "rescaled"), os.path.join(work, "fresh")
            same = sorted(os.listdir(a)) == sorted(os.listdir(b)) and all(
                filecmp.cmp(os.path.join(a, f), os.path.join(b, f), shallow=False) for f in os.listdir(b))
            read_back = rescaled[2].count("read back from the cache")
            for run_name, r in (("plain", plain), ("groups", grouped), ("rescaled", rescaled), ("fresh", fresh)):
                rows.append({"level": name, "groups": len(groups), "run": run_name, "seconds": "%.2f" % r[0],
                             "peak_mb": "%.0f" % r[1], "vs_plain_time": "%.3f" % (r[0] / plain[0]),
                             "vs_plain_memory": "%.3f" % (r[1] / plain[1]),
                             "identical": ("yes" if same else "NO") if run_name == "rescaled" else "",
                             "groups_read_back": read_back if run_name == "rescaled" else ""})
    path = os.path.join(outdir, "light-groups.csv")
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    for r in rows:
        print(" ".join("%s=%s" % kv for kv in r.items()))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("bench_light_groups: no matplotlib: no plot")
        return 0
    names = sorted({r["level"] for r in rows}, key=[r["level"] for r in rows].index)
    runs = ["plain", "groups", "rescaled", "fresh"]
    fig, ax = plt.subplots(figsize=(7, 3.5))
    for k, run_name in enumerate(runs):
        xs = [i + 0.2 * (k - 1.5) for i in range(len(names))]
        ys = [float(next(r["seconds"] for r in rows if r["level"] == n and r["run"] == run_name)) for n in names]
        ax.bar(xs, ys, width=0.2, label=run_name)
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels(names)
    ax.set_ylabel("seconds (2 cores)")
    ax.set_title("light groups: a bake, with groups, a scale edit read back, and fresh")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "light-groups.png"), dpi=100)
    return 0


if __name__ == "__main__":
    sys.exit(main())
