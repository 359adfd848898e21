#!/usr/bin/env python3
"""What light groups cost and what they save (docs/light-groups.md), side by side in one run.

usage: bench_light_groups.py LMBAKE OUTDIR [TAG ...]   (TAG: a row of DEFAULTS below, to run only those;
       their CSV and plot are OUTDIR/light-groups-TAG....csv/.png)
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
one group, its emissive ceiling (what the groups cost by themselves): about 6 minutes on 2 cores;
then the cost alone (plain and groups, no edit): level-single-10 in the most groups a bake takes (8:
the sun, Lamp 0 to Lamp 5 each alone, the other four lamps in `rest`), and bench/levels/level-gpu-10000.glb
(10,000 copies of a prop under a sun: tools/make_levels.py bench/levels gpu:10000) with its sun in
a group: about 12 minutes more.
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
DEFAULTS = [  # (tag, level, its groups, whether to edit the scales and bake the edit fresh too)
    ("single-10", "bench/levels/level-single-10.glb", [("sun", "match: Sun"), ("lamps", 'match: "Lamp*"')], True),
    ("cornell", "assets/scenes/cornell-box-bevy/CornellBox.glb", [("ceiling", "emissive: true")], True),
    ("single-10-8", "bench/levels/level-single-10.glb",
     [("sun", "match: Sun")] + [("lamp%d" % k, 'match: "Lamp %d"' % k) for k in range(6)], False),
    ("gpu-10000", "bench/levels/level-gpu-10000.glb", [("sun", 'match: "*"')], False),
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
    lmbake, outdir, only = sys.argv[1], sys.argv[2], sys.argv[3:]
    unknown = [t for t in only if t not in [d[0] for d in DEFAULTS]]
    if unknown:
        sys.exit("bench_light_groups.py: no level %s (one of %s)" % (unknown, ", ".join(d[0] for d in DEFAULTS)))
    stem = "light-groups" + "".join("-" + t for t in only)
    os.makedirs(outdir, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for tag, level, groups, edit in DEFAULTS:
            if only and tag not in only:
                continue
            level = os.path.join(ROOT, level)
            if not os.path.exists(level):
                print("skipping %s: missing (tools/make_levels.py bench/levels single:10 gpu:10000 makes it)" % level)
                continue
            name = os.path.splitext(os.path.basename(level))[0]
            cache = os.path.join(work, tag + "-cache")
            ones = [1.0] * len(groups)
            edited = [0.5] * (len(groups) - 1) + [3.0]
            plain = run(lmbake, level, "{}\n", os.path.join(work, "plain"), work, tag + "-plain", "-q")
            grouped = run(lmbake, level, config(groups, ones), os.path.join(work, "groups"), work, tag + "-groups",
                          "--layout-cache", cache)
            lit = len(re.findall(r"^light group '[^']*' \(\d+ of (\d+)\): lighting", grouped[2], re.M))
            runs = [("plain", plain), ("groups", grouped)]
            same, read_back = None, ""
            if edit:
                rescaled = run(lmbake, level, config(groups, edited), os.path.join(work, "rescaled"), work,
                               tag + "-rescaled", "--layout-cache", cache)
                fresh = run(lmbake, level, config(groups, edited), os.path.join(work, "fresh"), work, tag + "-fresh",
                            "-q")
                a, b = os.path.join(work, "rescaled"), os.path.join(work, "fresh")
                same = sorted(os.listdir(a)) == sorted(os.listdir(b)) and all(
                    filecmp.cmp(os.path.join(a, f), os.path.join(b, f), shallow=False) for f in os.listdir(b))
                read_back = rescaled[2].count("read back from the cache")
                runs += [("rescaled", rescaled), ("fresh", fresh)]
            print("%s: %d group(s) lit, plain %.1f s / %.0f MB, groups %.1f s / %.0f MB (%.2fx, %.2fx)"
                  % (tag, lit, plain[0], plain[1], grouped[0], grouped[1], grouped[0] / plain[0],
                     grouped[1] / plain[1]), flush=True)
            for run_name, r in runs:
                rows.append({"level": tag, "groups": lit, "run": run_name, "seconds": "%.2f" % r[0],
                             "peak_mb": "%.0f" % r[1], "vs_plain_time": "%.3f" % (r[0] / plain[0]),
                             "vs_plain_memory": "%.3f" % (r[1] / plain[1]),
                             "identical": ("yes" if same else "NO") if run_name == "rescaled" else "",
                             "groups_read_back": read_back if run_name == "rescaled" else ""})
    path = os.path.join(outdir, stem + ".csv")
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
        ys = [float(next((r["seconds"] for r in rows if r["level"] == n and r["run"] == run_name), 0)) for n in names]
        ax.bar(xs, ys, width=0.2, label=run_name)
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels(names)
    ax.set_ylabel("seconds (2 cores)")
    ax.set_title("light groups: a bake, with groups, a scale edit read back, and fresh")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, stem + ".png"), dpi=100)
    return 0


if __name__ == "__main__":
    sys.exit(main())
