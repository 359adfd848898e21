#!/usr/bin/env python3
"""The farm benchmark (docs/farm.md, docs/benchmarks.md#farm). Two measures:

1. This machine, side by side: `lmbake bake --threads 2` against `lmbake farm parallel
   --shards 2 --workers 2 --threads 1` (two workers on the same 2 cores), alternated
   (bake, farm, bake, farm, ...) for ROUNDS rounds per scene; the ratio farm / bake is taken
   pair by pair within a round, then the median. Every farm output is compared with the
   bake's, byte for byte.
2. Many machines, derived: the critical path of a bake whose N workers each have a machine of
   their own. One worker (`lmbake worker --worker 1/1 --shards N --threads 1`) computes every
   shard of every step one after the other and logs each shard's time; then
      critical path = plan + (worker wall - all shard times) + sum over steps of the slowest shard
   i.e. what does not split (start, between-step work, merges, the tail that writes the bake)
   once, plus each step's slowest shard. Against `lmbake bake --threads 1`. The worker's
   output at N shards is compared with that bake's, byte for byte. What does not split is
   reported: start (load, plan, ray-tracing scene, before the first step), between steps
   (the code between steps, merges), and the tail after the last step.

usage: bench_farm.py LMBAKE WORKDIR CSV PNG ROUNDS SHARDS_LIST SCENE [SCENE ...]
       (SHARDS_LIST e.g. "1,4,16"; critical paths are measured on the last scene)
"""
import csv
import filecmp
import os
import re
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


def identical(a, b):
    names = sorted(os.listdir(a))
    return names == sorted(os.listdir(b)) and all(
        filecmp.cmp(os.path.join(a, n), os.path.join(b, n), shallow=False) for n in names)


SHARD_LINE = re.compile(r"step (\d+) \(.*\): shard (\d+) of (\d+) computed in ([0-9.]+) s")


def timed_worker(args):
    """Runs a worker, stamping each line of its log: (wall, [(t, step, shard, seconds)])."""
    t0 = time.time()
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    shards = []
    for line in p.stdout:
        m = SHARD_LINE.search(line)
        if m:
            shards.append((time.time() - t0, int(m.group(1)), int(m.group(2)), float(m.group(4))))
    if p.wait() != 0:
        sys.exit("bench_farm: %s failed" % " ".join(args))
    return time.time() - t0, shards


def side_by_side(lmbake, scene, work, rounds, rows):
    name = os.path.splitext(os.path.basename(scene))[0]
    for rnd in range(1, rounds + 1):
        ref, farm, out = (os.path.join(work, "%s-%s" % (name, s)) for s in ("bake", "farm", "out"))
        for d in (ref, farm, out):
            shutil.rmtree(d, ignore_errors=True)
        bake = run([lmbake, "bake", scene, "-o", ref, "-q", "--threads", "2"])
        wall = run([lmbake, "farm", "parallel", scene, "--farm", farm, "-o", out, "--shards", "2", "--workers", "2",
                    "--threads", "1", "-q"])
        same = identical(ref, out)
        rows.append(dict(measure="this machine", scene=name, round=rnd, shards=2, bake_s=round(bake, 2),
                         farm_s=round(wall, 2), ratio=round(wall / bake, 4), identical=same))
        print("%s round %d: bake --threads 2 %.1f s, farm parallel 2 workers x 1 thread %.1f s: %.3fx, identical: %s"
              % (name, rnd, bake, wall, wall / bake, same), flush=True)
        if not same:
            sys.exit("bench_farm: the farm's output differs from lmbake bake")


def critical_paths(lmbake, scene, work, shard_counts, rows):
    name = os.path.splitext(os.path.basename(scene))[0]
    ref = os.path.join(work, name + "-bake-1thread")
    shutil.rmtree(ref, ignore_errors=True)
    bake = run([lmbake, "bake", scene, "-o", ref, "-q", "--threads", "1"])
    print("%s: bake --threads 1 %.1f s" % (name, bake), flush=True)
    for n in shard_counts:
        farm, out = (os.path.join(work, "%s-%d-%s" % (name, n, s)) for s in ("farm", "out"))
        shutil.rmtree(farm, ignore_errors=True)
        shutil.rmtree(out, ignore_errors=True)
        plan = run([lmbake, "plan", scene, "--farm", farm, "--threads", "1", "-q"])
        wall, shards = timed_worker([lmbake, "worker", scene, "--farm", farm, "--shards", str(n), "--worker", "1/1",
                                     "--threads", "1", "-o", out])
        same = identical(ref, out)
        if not same:
            sys.exit("bench_farm: the worker's output at %d shards differs from lmbake bake" % n)
        steps = sorted({s for _, s, _, _ in shards})
        slowest = {s: max(t for _, st, _, t in shards if st == s) for s in steps}
        total = sum(t for _, _, _, t in shards)
        start = shards[0][0] - shards[0][3] if shards else wall
        tail = wall - shards[-1][0] if shards else 0.0
        between = wall - total - start - tail
        critical = plan + (wall - total) + sum(slowest.values())
        mean = total / n
        rows.append(dict(measure="critical path", scene=name, round=1, shards=n, bake_s=round(bake, 2),
                         farm_s=round(critical, 2), ratio=round(critical / bake, 4), identical=same,
                         steps=len(steps), plan_s=round(plan, 2), start_s=round(start, 2),
                         between_s=round(between, 2), tail_s=round(tail, 2),
                         shard_work_s=round(total, 2), slowest_sum_s=round(sum(slowest.values()), 2),
                         slowest_over_mean=round(sum(slowest.values()) / mean, 3) if mean else 1.0))
        print("%s, %d shards: %d steps; critical path %.1f s = plan %.1f + start %.1f + between steps %.1f + tail %.1f "
              "+ slowest shards %.1f (all shards' work %.1f s, slowest/mean %.2f): %.3fx the bake, identical: %s" %
              (name, n, len(steps), critical, plan, start, between, tail, sum(slowest.values()), total,
               rows[-1]["slowest_over_mean"], critical / bake, same), flush=True)


def main():
    lmbake, work, csv_path, png_path, rounds, shard_list = sys.argv[1:7]
    scenes = sys.argv[7:]
    rounds = int(rounds)
    shard_counts = [int(s) for s in shard_list.split(",") if s]
    os.makedirs(work, exist_ok=True)
    rows = []
    for scene in scenes:
        side_by_side(lmbake, scene, work, rounds, rows)
    critical_paths(lmbake, scenes[-1], work, shard_counts, rows)
    keys = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    print("summary:")
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        sel = [r for r in rows if r["measure"] == "this machine" and r["scene"] == name]
        if not sel:
            continue
        print("  %s: farm parallel 2 x 1 thread / bake --threads 2: median %.3fx (%s)" %
              (name, statistics.median(r["ratio"] for r in sel), ", ".join("%.3f" % r["ratio"] for r in sel)))
    for r in rows:
        if r["measure"] == "critical path":
            print("  %s, %d shards: critical path / bake --threads 1: %.3fx" % (r["scene"], r["shards"], r["ratio"]))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("bench_farm: no matplotlib: no plot")
        return
    crit = [r for r in rows if r["measure"] == "critical path"]
    fig, ax = plt.subplots(figsize=(7, 4))
    ns = [r["shards"] for r in crit]
    ax.plot(ns, [r["ratio"] for r in crit], "o-", label="critical path / bake --threads 1")
    ax.plot(ns, [1.0 / n for n in ns], "k--", label="ideal 1/N")
    ax.set_xscale("log", base=2)
    ax.set_yscale("log", base=2)
    ax.set_xlabel("machines (one worker each, 1 thread)")
    ax.set_ylabel("time / one machine")
    ax.set_title("farm: %s" % crit[0]["scene"] if crit else "farm")
    ax.legend()
    fig.tight_layout()
    fig.savefig(png_path, dpi=100)
    print("bench_farm: wrote %s and %s" % (csv_path, png_path))


main()
