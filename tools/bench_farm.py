#!/usr/bin/env python3
"""The farm benchmark (issue 13): `lmbake bake` against `lmbake farm parallel` in 1, 2 and 4
shards on this machine, side by side in one run (bake, 1, 2, 4, bake, 1, 2, 4, ...), with the
same cores for each: bake and 1 shard use 2 threads; 2 and 4 shards run 2 at a time with 1
thread each (GNU parallel -j 2). Every farm output is compared with the bake's, byte for byte.

Per farm run, from DIR/logs/times.tsv (the driver's stamps) and GNU parallel's joblogs:
  plan, shards (sum over steps of each step's wall time), merge (sum), finish: seconds;
  overhead = (plan + merge + finish) / wall;
  slowest/mean = sum over steps of the slowest shard's time / sum of the mean shard time
  (time-weighted: what the steps' imbalance costs), and the worst single step's ratio;
  critical path = plan + sum over steps of the slowest shard + merge + finish: the wall time
  if every shard had a machine of its own. It is derived from this run's shard times (shards
  of 2 and 4 ran on 1 thread each, two at a time), not measured on N machines.
Ratios (farm wall / bake wall) are taken pair by pair within a round, then their median.

usage: bench_farm.py LMBAKE LEVEL WORKDIR CSV PNG [ROUNDS] [CONFIG]
"""
import csv
import filecmp
import os
import shutil
import statistics
import subprocess
import sys
import time


def run(args):
    t0 = time.time()
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("bench_farm: %s failed: %s" % (" ".join(args), r.stderr[-800:]))
    return time.time() - t0


def stages(farm):
    """plan, shards, merge, finish seconds from the driver's stamps."""
    out = {"plan": 0.0, "shards": 0.0, "merge": 0.0, "finish": 0.0}
    prev = None
    for line in open(os.path.join(farm, "logs", "times.tsv")):
        what, t = line.rstrip("\n").split("\t")
        t = float(t)
        kind = what.split()[0]
        if prev is not None and kind in out:
            out[kind] += t - prev
        prev = t
    return out


def balance(farm, shards):
    """(sum of slowest, sum of means, worst step ratio, steps) over the steps' joblogs."""
    slow = mean = 0.0
    worst = 1.0
    steps = 0
    logs = os.path.join(farm, "logs")
    for name in sorted(os.listdir(logs)):
        if not name.endswith(".joblog"):
            continue
        times = []
        for line in open(os.path.join(logs, name)).readlines()[1:]:
            cols = line.split("\t")
            times.append(float(cols[3]))
        if len(times) != shards:
            continue
        steps += 1
        m = statistics.mean(times)
        slow += max(times)
        mean += m
        if m > 0.5:  # the worst of the steps that take time (tiny steps are all start-up)
            worst = max(worst, max(times) / m)
    return slow, mean, worst, steps


def identical(a, b):
    names = sorted(os.listdir(a))
    return names == sorted(os.listdir(b)) and all(
        filecmp.cmp(os.path.join(a, n), os.path.join(b, n), shallow=False) for n in names)


def main():
    lmbake, level, work, csv_path, png_path = sys.argv[1:6]
    rounds = int(sys.argv[6]) if len(sys.argv) > 6 else 2
    config = sys.argv[7] if len(sys.argv) > 7 else None
    cfg = ["-c", config] if config else []
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    rows = []
    for rnd in range(rounds):
        ref = os.path.join(work, "bake")
        shutil.rmtree(ref, ignore_errors=True)
        wall = run([lmbake, "bake", level] + cfg + ["-o", ref, "-q", "--threads", "2"])
        bake_wall = wall
        rows.append(dict(round=rnd, mode="bake", shards=0, wall=wall, plan="", shards_s="", merge="", finish="",
                         overhead="", slowest_over_mean="", worst_step="", steps="", vs_bake=1.0, identical="",
                         critical_path=""))
        print("round %d: bake %.1f s" % (rnd, wall), flush=True)
        for shards in (1, 2, 4):
            farm, out = os.path.join(work, "farm-%d" % shards), os.path.join(work, "out-%d" % shards)
            shutil.rmtree(farm, ignore_errors=True)
            shutil.rmtree(out, ignore_errors=True)
            jobs, threads = (1, 2) if shards == 1 else (2, 1)
            wall = run([lmbake, "farm", "parallel", level] + cfg +
                       ["--farm", farm, "-o", out, "--shards", str(shards), "--jobs", str(jobs),
                        "--threads", str(threads), "-q"])
            st = stages(farm)
            slow, mean, worst, steps = balance(farm, shards)
            same = identical(ref, out)
            rows.append(dict(round=rnd, mode="farm", shards=shards, wall=wall, plan=st["plan"], shards_s=st["shards"],
                             merge=st["merge"], finish=st["finish"],
                             overhead=(st["plan"] + st["merge"] + st["finish"]) / wall,
                             slowest_over_mean=slow / mean if mean else 1.0, worst_step=worst, steps=steps,
                             vs_bake=wall / bake_wall, identical=same,
                             critical_path=st["plan"] + slow + st["merge"] + st["finish"]))
            print("round %d: %d shard(s) %.1f s (%.2fx the bake), %d steps, plan %.1f + shards %.1f + merge %.1f + "
                  "finish %.1f s, overhead %.1f%%, slowest/mean %.2f (worst step %.2f), critical path %.1f s, identical: %s" %
                  (rnd, shards, wall, wall / bake_wall, steps, st["plan"], st["shards"], st["merge"], st["finish"],
                   100 * rows[-1]["overhead"], rows[-1]["slowest_over_mean"], worst, rows[-1]["critical_path"], same),
                  flush=True)
            if not same:
                sys.exit("bench_farm: the %d-shard output differs from lmbake bake" % shards)
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print("median over %d rounds:" % rounds)
    summary = {}
    for shards in (0, 1, 2, 4):
        sel = [r for r in rows if r["shards"] == shards]
        med = lambda k: statistics.median(float(r[k]) for r in sel)
        summary[shards] = sel
        if shards == 0:
            print("  bake: %.1f s" % med("wall"))
        else:
            print("  %d shard(s): %.1f s, %.2fx the bake (pair by pair), overhead (plan+merge+finish) %.1f%%, "
                  "slowest/mean %.2f, critical path %.1f s" % (shards, med("wall"), med("vs_bake"),
                                                              100 * med("overhead"), med("slowest_over_mean"),
                                                              med("critical_path")))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("bench_farm: no matplotlib: no plot")
        return
    fig, ax = plt.subplots(figsize=(7, 4))
    labels, bottoms = [], []
    parts = ("plan", "shards_s", "merge", "finish")
    colors = {"plan": "#888", "shards_s": "#4a7", "merge": "#d84", "finish": "#47c"}
    x = 0
    ax.bar(x, statistics.median(r["wall"] for r in summary[0]), color="#333", label="lmbake bake")
    labels.append("bake")
    for shards in (1, 2, 4):
        x += 1
        bottom = 0
        for p in parts:
            v = statistics.median(float(r[p]) for r in summary[shards])
            ax.bar(x, v, bottom=bottom, color=colors[p], label=p.replace("_s", "") if shards == 1 else None)
            bottom += v
        labels.append("%d shard%s" % (shards, "s" if shards > 1 else ""))
    ax.set_xticks(range(len(labels)))
    ax.set_xticklabels(labels)
    ax.set_ylabel("wall time (s), median of %d rounds" % rounds)
    ax.set_title("farm parallel on this machine (2 cores): %s" % os.path.basename(level))
    ax.legend()
    fig.tight_layout()
    fig.savefig(png_path, dpi=100)
    print("bench_farm: wrote %s and %s" % (csv_path, png_path))


main()
