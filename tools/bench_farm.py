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
   once, plus each step's slowest shard. A shard's time is its computing and the write of its
   part (each machine writes its own); with a binary whose log does not say the write, all N
   parts' writes fall in what does not split. Both are reported for the same run
   (farm_s_writes_serial: every part's write on the path). Against `lmbake bake --threads 1`. The worker's
   output at N shards is compared with that bake's, byte for byte. What does not split is
   reported: start (load, plan, ray-tracing scene, before the first step), between steps
   (the code between steps, merges), and the tail after the last step.

With LMB_BENCH_BEFORE=OTHER_LMBAKE (tools/bench_farm.sh's second argument) both measures run
for that binary too, side by side: in each round of 1, the four runs alternate (bake and farm
of this binary, then of the other); in 2, the two workers of each shard count run one after
the other. Rows carry binary=after|before.

Also reported, less noisy than the ratio to a bake run at another time on this shared machine:
the critical path over the same worker run's one-machine time (plan + the worker's wall, every
shard computed in turn on one thread: a one-machine bake through the farm).

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


SHARD_LINE = re.compile(r"step (\d+) \(.*\): shard (\d+) of (\d+) computed in ([0-9.]+) s.*?(?:wrote \S+ in ([0-9.]+) s)?$")


def timed_worker(args):
    """Runs a worker, stamping each line of its log: (wall, [(t, step, shard, seconds, written)]): a
    shard's seconds computing and writing its part (a binary that does not say the write: 0)."""
    t0 = time.time()
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    shards = []
    for line in p.stdout:
        m = SHARD_LINE.search(line)
        if m:
            written = float(m.group(5)) if m.group(5) else 0.0
            shards.append((time.time() - t0, int(m.group(1)), int(m.group(2)), float(m.group(4)) + written, written))
    if p.wait() != 0:
        sys.exit("bench_farm: %s failed" % " ".join(args))
    return time.time() - t0, shards


def side_by_side(binaries, scene, work, rounds, rows):
    name = os.path.splitext(os.path.basename(scene))[0]
    for rnd in range(1, rounds + 1):
        for tag, lmbake in binaries:
            ref, farm, out = (os.path.join(work, "%s-%s-%s" % (name, tag, s)) for s in ("bake", "farm", "out"))
            for d in (ref, farm, out):
                shutil.rmtree(d, ignore_errors=True)
            bake = run([lmbake, "bake", scene, "-o", ref, "-q", "--threads", "2"])
            wall = run([lmbake, "farm", "parallel", scene, "--farm", farm, "-o", out, "--shards", "2", "--workers",
                        "2", "--threads", "1", "-q"])
            same = identical(ref, out)
            rows.append(dict(measure="this machine", binary=tag, scene=name, round=rnd, shards=2, bake_s=round(bake, 2),
                             farm_s=round(wall, 2), ratio=round(wall / bake, 4), identical=same))
            print("%s %s round %d: bake --threads 2 %.1f s, farm parallel 2 workers x 1 thread %.1f s: %.3fx, "
                  "identical: %s" % (tag, name, rnd, bake, wall, wall / bake, same), flush=True)
            if not same:
                sys.exit("bench_farm: the farm's output differs from lmbake bake")


def critical_paths(binaries, scene, work, shard_counts, rows):
    name = os.path.splitext(os.path.basename(scene))[0]
    bakes = {}
    for tag, lmbake in binaries:
        ref = os.path.join(work, "%s-%s-bake-1thread" % (name, tag))
        shutil.rmtree(ref, ignore_errors=True)
        bakes[tag] = (ref, run([lmbake, "bake", scene, "-o", ref, "-q", "--threads", "1"]))
        print("%s %s: bake --threads 1 %.1f s" % (tag, name, bakes[tag][1]), flush=True)
    for n in shard_counts:
        for tag, lmbake in binaries:
            critical_path(lmbake, tag, scene, name, work, n, bakes[tag], rows)


def critical_path(lmbake, tag, scene, name, work, n, bake_run, rows):
    """One worker computes every shard of every step in turn at 1 thread (its tail too:
    --tail-threads 1, a machine of one core, where the binary has the option)."""
    ref, bake = bake_run
    farm, out = (os.path.join(work, "%s-%s-%d-%s" % (name, tag, n, s)) for s in ("farm", "out"))
    shutil.rmtree(farm, ignore_errors=True)
    shutil.rmtree(out, ignore_errors=True)
    plan = run([lmbake, "plan", scene, "--farm", farm, "--threads", "1", "-q"])
    one_core = ["--tail-threads", "1"] if "--tail-threads" in subprocess.run(
        [lmbake, "worker", "--help"], capture_output=True, text=True).stdout else []
    wall, shards = timed_worker([lmbake, "worker", scene, "--farm", farm, "--shards", str(n), "--worker", "1/1",
                                 "--threads", "1", "-o", out] + one_core)
    same = identical(ref, out)
    if not same:
        sys.exit("bench_farm: the worker's output at %d shards differs from lmbake bake" % n)
    steps = sorted({s for _, s, _, _, _ in shards})
    slowest = {s: max(t for _, st, _, t, _ in shards if st == s) for s in steps}
    total = sum(t for _, _, _, t, _ in shards)
    written = sum(w for _, _, _, _, w in shards)
    # the same run with every part's write charged to the critical path, as the model did before
    # shards said their writes (each machine writes its own part, so the slowest shard's is enough)
    slowest_computed = {s: max(t - w for _, st, _, t, w in shards if st == s) for s in steps}
    start = shards[0][0] - shards[0][3] if shards else wall
    tail = wall - shards[-1][0] if shards else 0.0
    between = wall - total - start - tail
    critical = plan + (wall - total) + sum(slowest.values())
    writes_serial = plan + (wall - total + written) + sum(slowest_computed.values())
    mean = total / n
    rows.append(dict(measure="critical path", binary=tag, scene=name, round=1, shards=n, bake_s=round(bake, 2),
                     farm_s=round(critical, 2), ratio=round(critical / bake, 4), identical=same,
                     one_machine_s=round(plan + wall, 2), ratio_same_run=round(critical / (plan + wall), 4),
                     steps=len(steps), plan_s=round(plan, 2), start_s=round(start, 2),
                     between_s=round(between, 2), tail_s=round(tail, 2),
                     shard_work_s=round(total, 2), slowest_sum_s=round(sum(slowest.values()), 2),
                     slowest_over_mean=round(sum(slowest.values()) / mean, 3) if mean else 1.0,
                     part_writes_s=round(written, 2), farm_s_writes_serial=round(writes_serial, 2),
                     ratio_same_run_writes_serial=round(writes_serial / (plan + wall), 4)))
    print("%s %s, %d shards: %d steps; critical path %.1f s = plan %.1f + start %.1f + between steps %.1f + tail "
          "%.1f + slowest shards %.1f (all shards' work %.1f s, slowest/mean %.2f): %.3fx the bake, %.3fx this "
          "run's one machine (%.1f s), identical: %s; the parts' writes %.2f s (all %d charged to the path: %.3fx "
          "the one machine)" %
          (tag, name, n, len(steps), critical, plan, start, between, tail, sum(slowest.values()), total,
           rows[-1]["slowest_over_mean"], critical / bake, critical / (plan + wall), plan + wall, same, written, n,
           writes_serial / (plan + wall)), flush=True)


def main():
    lmbake, work, csv_path, png_path, rounds, shard_list = sys.argv[1:7]
    scenes = sys.argv[7:]
    rounds = int(rounds)
    shard_counts = [int(s) for s in shard_list.split(",") if s]
    os.makedirs(work, exist_ok=True)
    binaries = [("after", lmbake)]
    if os.environ.get("LMB_BENCH_BEFORE"):
        binaries.append(("before", os.environ["LMB_BENCH_BEFORE"]))
    rows = []
    for scene in scenes:
        side_by_side(binaries, scene, work, rounds, rows)
    if shard_counts:
        critical_paths(binaries, scenes[-1], work, shard_counts, rows)
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
        for tag, _ in binaries:
            sel = [r for r in rows if r["measure"] == "this machine" and r["scene"] == name and r["binary"] == tag]
            if not sel:
                continue
            print("  %s %s: farm parallel 2 x 1 thread / bake --threads 2: median %.3fx (%s)" %
                  (tag, name, statistics.median(r["ratio"] for r in sel), ", ".join("%.3f" % r["ratio"] for r in sel)))
    for r in rows:
        if r["measure"] == "critical path":
            print("  %s %s, %d shards: critical path / bake --threads 1: %.3fx; / this run's one machine: %.3fx" %
                  (r["binary"], r["scene"], r["shards"], r["ratio"], r["ratio_same_run"]))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("bench_farm: no matplotlib: no plot")
        return
    fig, ax = plt.subplots(figsize=(7, 4))
    crit = []
    for tag, _ in binaries:
        crit = [r for r in rows if r["measure"] == "critical path" and r["binary"] == tag]
        ns = [r["shards"] for r in crit]
        ax.plot(ns, [r["ratio_same_run"] for r in crit], "o-" if tag == "after" else "s:",
                label="%s: critical path / one machine" % tag)
    ns = sorted({r["shards"] for r in rows if r["measure"] == "critical path"})
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
