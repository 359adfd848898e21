#!/usr/bin/env python3
"""Thread scaling per stage, before and after, side by side (docs/benchmarks.md#threads).

For every scene and thread count, the `before` binary and the `after` binary bake one after
the other (before, after, before, after, ...: a load on the machine hits both alike). Each
output line is time-stamped as it is printed and the bake is cut into stages by the first
line of each, the same lines for both binaries (a stage runs from its first line to the next
stage's first line, as ../shared/tools/portable/scaling.sh cuts a log):

  set-up             start -> the first `direct:` line (load, unwrap, pack, ray-tracing scene)
  direct             -> the first `bounce pass` line
  bounce passes      -> the first `final gather` line
  final gather       -> `final gather, atlas 0: N records` (records, gradients, interpolation)
  denoise 1          -> `denoise: the final gather's light ...`
  direct refinement  -> `direct light: estimated noise ...`
  rest               -> exit (second denoiser pass, directions, fireflies, seams, images, glTF)

A stage whose lines a bake does not print (no bounce pass, no refinement) is left out of it.
Then T copies of the after binary's 1-thread bake run at once (T the largest thread count):
what T farm workers of one thread each do on this machine. Each copy's time against the
1-thread bake alone is the machine's own scaling (shared caches, memory, a busy host); the
T-thread bake's time against theirs divided by T says whether threads keep up with processes.
The after binary also runs once more at each T > 1 with --timings=CSV (a run of its own: its
sampling thread stays out of the times compared): per stage the CPU time over all threads and
the serial share; the serial seconds summed over the stages, S, at T
threads with wall time W give the serial fraction of the work, f = S / (S + T (W - S)).
From the wall times alone, Amdahl's f = (T / speed-up - 1) / (T - 1) for each T > 1.
The same serial share is also sampled from outside the process for both binaries
(SerialSampler: /proc/PID/task/*/stat every 0.1 s), so before and after are measured alike.
Every output of every bake is compared with the after binary's at the first thread count,
byte for byte (before and after must agree too: the work changes the speed, not the bits).

With ROUNDS > 1 the whole sequence repeats and every figure printed is the rounds' median (the
CSV keeps each round): on a machine others share, one round's times move by 10% or more.

usage: bench_threads.py BEFORE AFTER WORKDIR CSV PNG THREADS(e.g. 1,2) ROUNDS SCENE[=CONFIG] ...
"""
import csv
import filecmp
import os
import re
import shutil
import subprocess
import statistics
import sys
import threading
import time

STAGES = [("set-up", None), ("direct", r"direct:"), ("bounce passes", r"bounce pass \d"),
          ("final gather", r"final gather"), ("denoise 1", r"final gather, atlas \d+: \d+ records"),
          ("direct refinement", r"denoise: the final gather's light"),
          ("rest", r"direct light: estimated noise")]


TICK = os.sysconf("SC_CLK_TCK")


class SerialSampler(threading.Thread):
    """Samples a process's threads' CPU ticks (/proc/PID/task/*/stat, utime + stime) every
    INTERVAL s from outside, so that any binary (before or after) is measured alike; an
    interval in which at most one thread ran more than half of it counts as serial. Coarser
    than --timings (the kernel counts in 1/TICK s) but the same rule."""
    INTERVAL = 0.1

    def __init__(self, pid):
        super().__init__(daemon=True)
        self.pid, self.serial, self.sampled, self.done = pid, 0.0, 0.0, threading.Event()

    def ticks(self):
        out = {}
        try:
            for tid in os.listdir("/proc/%d/task" % self.pid):
                try:
                    with open("/proc/%d/task/%s/stat" % (self.pid, tid)) as f:
                        fields = f.read().rsplit(")", 1)[1].split()
                    out[tid] = int(fields[11]) + int(fields[12])
                except (OSError, IndexError, ValueError):
                    pass
        except OSError:
            pass
        return out

    def run(self):
        last, t_last = self.ticks(), time.time()
        while not self.done.wait(self.INTERVAL):
            now, t_now = self.ticks(), time.time()
            if not now:
                break
            dt = t_now - t_last
            busy = sum(1 for tid, v in now.items() if (v - last.get(tid, 0)) / TICK > 0.5 * dt)
            self.sampled += dt
            self.serial += dt if busy <= 1 else 0.0
            last, t_last = now, t_now


def timed(args, log_path, serial=None):
    """Runs args, time-stamping each line of its output; returns (wall seconds, [(t, line)]).
    serial: a list that gets the seconds sampled as serial and the seconds sampled."""
    t0 = time.time()
    lines, buf = [], b""
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    sampler = SerialSampler(proc.pid)
    sampler.start()
    while True:
        chunk = proc.stdout.read1(65536)
        if not chunk:
            break
        buf += chunk
        parts = re.split(rb"[\r\n]", buf)
        buf = parts.pop()
        now = time.time() - t0
        lines += [(now, p.decode(errors="replace")) for p in parts if p.strip()]
    if buf.strip():
        lines.append((time.time() - t0, buf.decode(errors="replace")))
    rc = proc.wait()
    wall = time.time() - t0
    sampler.done.set()
    sampler.join()
    if serial is not None:
        serial[:] = [sampler.serial, sampler.sampled]
    with open(log_path, "w") as f:
        f.writelines("%8.3f %s\n" % (t, l) for t, l in lines)
    if rc != 0:
        sys.exit("bench_threads: %s failed (exit %d); log: %s" % (" ".join(args), rc, log_path))
    return wall, lines


def stage_times(lines, wall):
    """{stage: seconds} by the first line of each stage (STAGES), in order."""
    starts, k = [("set-up", 0.0)], 1
    for t, text in lines:
        while k < len(STAGES):
            name, pattern = STAGES[k]
            if re.match(pattern, text):
                starts.append((name, t))
                k += 1
                continue
            break
        else:
            break
    times = {}
    for i, (name, t) in enumerate(starts):
        end = starts[i + 1][1] if i + 1 < len(starts) else wall
        times[name] = end - t
    return times


def timings_csv(path):
    """(serial seconds summed over the stages, whole bake wall, whole bake CPU) from --timings=CSV."""
    serial, wall, cpu = 0.0, 0.0, 0.0
    with open(path) as f:
        for row in csv.DictReader(f):
            if row["stage"] == "whole bake":
                wall, cpu = float(row["wall_s"]), float(row["cpu_s"])
            else:
                serial += float(row["serial_s"])
    return serial, wall, cpu


def identical(a, b):
    names = sorted(os.listdir(a))
    return names == sorted(os.listdir(b)) and all(
        filecmp.cmp(os.path.join(a, n), os.path.join(b, n), shallow=False) for n in names)


def measure_round(name, scene, cfg, before, after, threads, work, reference, rows, r):
    """One round on one scene: each thread count with both binaries, alternating, then T 1-thread
    processes at once. Returns (walls, stages, serial) dicts for this round."""
    walls, stages, serial = {}, {}, {}
    for t in threads:
        for which, binary in (("before", before), ("after", after)):
            out = os.path.join(work, "%s-%s-t%d" % (name, which, t))
            shutil.rmtree(out, ignore_errors=True)
            args = [binary, "bake", scene, *cfg, "-o", out, "--threads", str(t)]
            outside = []
            wall, lines = timed(args, out + ".log", outside)
            walls[which, t] = wall
            sec, sampled = outside
            walls[which, t, "outside"] = sec * wall / sampled if sampled else 0.0  # over the whole wall time
            stages[which, t] = stage_times(lines, wall)
            if reference[0] is None:
                reference[0] = out + "-reference"
                shutil.rmtree(reference[0], ignore_errors=True)
                shutil.copytree(out, reference[0])
            same = identical(reference[0], out)
            print("%-22s round %d %-6s %2d thread(s): %7.2f s%s" % (name, r + 1, which, t, wall,
                  "" if same else "  OUTPUT DIFFERS from " + reference[0]), flush=True)
            if not same:
                sys.exit("bench_threads: %s differs from %s" % (out, reference[0]))
            for stage, sec in stages[which, t].items():
                rows.append([name, r + 1, which, t, stage, "%.3f" % sec])
            rows.append([name, r + 1, which, t, "whole bake", "%.3f" % wall])
    # --timings in a run of its own, so that its sampling thread does not touch the times above
    for t in threads[1:]:
        tcsv = os.path.join(work, "%s-timings-t%d.csv" % (name, t))
        out = os.path.join(work, "%s-timings-t%d" % (name, t))
        shutil.rmtree(out, ignore_errors=True)
        timed([after, "bake", scene, *cfg, "-o", out, "--threads", str(t), "--timings=" + tcsv], out + ".log")
        serial[t] = timings_csv(tcsv)
    # threads against processes: T copies of the 1-thread bake at once on the same machine
    # (what a farm of T workers does), against the T-thread bake
    tn = threads[-1]
    if threads[0] != 1:
        return walls, stages, serial
    procs, outs = [], []
    t0 = time.time()
    for k in range(tn):
        out = os.path.join(work, "%s-process-%d" % (name, k))
        shutil.rmtree(out, ignore_errors=True)
        outs.append(out)
        procs.append(subprocess.Popen([after, "bake", scene, *cfg, "-o", out, "--threads", "1", "-q"]))
    ends = []
    for p in procs:
        if p.wait() != 0:
            sys.exit("bench_threads: a 1-thread copy of %s failed" % name)
        ends.append(time.time() - t0)
    for out in outs:
        if not identical(reference[0], out):
            sys.exit("bench_threads: %s differs from %s" % (out, reference[0]))
    walls["processes", tn] = max(ends)
    print("%-22s round %d %d processes x 1 thread at once: %7.2f s (each %s)" % (name, r + 1, tn, max(ends),
          ", ".join("%.2f s" % e for e in ends)), flush=True)
    rows.append([name, r + 1, "processes", tn, "whole bake", "%.3f" % max(ends)])
    return walls, stages, serial


def medians(runs):
    """The rounds' medians, key by key: (walls, stages, serial)."""
    walls = {k: statistics.median(w[k] for w, _, _ in runs) for k in runs[0][0]}
    stages = {k: {s: statistics.median(st[k][s] for _, st, _ in runs if s in st[k]) for s in runs[0][1][k]}
              for k in runs[0][1]}
    serial = {t: tuple(statistics.median(se[t][i] for _, _, se in runs) for i in range(3)) for t in runs[0][2]}
    return walls, stages, serial


def main():
    if len(sys.argv) < 9:
        sys.exit(__doc__)
    before, after, work, csv_path, png_path, threads_arg, rounds_arg = sys.argv[1:8]
    threads = [int(t) for t in threads_arg.split(",")]
    rounds = int(rounds_arg)
    scenes = sys.argv[8:]
    os.makedirs(work, exist_ok=True)
    rows, summary = [], []
    for spec in scenes:
        scene, _, config = spec.partition("=")
        name = os.path.splitext(os.path.basename(scene))[0]
        cfg = ["-c", config] if config else []
        runs = []  # per round: (walls, stages, serial) as measure_round gives them
        reference = [None]
        for r in range(rounds):
            runs.append(measure_round(name, scene, cfg, before, after, threads, work, reference, rows, r))
        summary.append((name,) + medians(runs))
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "round", "binary", "threads", "stage", "wall_s"])
        w.writerows(rows)
    t1, tn = threads[0], threads[-1]
    for name, walls, stages, serial in summary:
        print("\n%s (median of %d round(s)): seconds per stage, %d and %d thread(s); speed-up = %d-thread time / "
              "%d-thread time" % (name, rounds, t1, tn, t1, tn))
        print("%-20s %9s %9s %8s   %9s %9s %8s" % ("stage", "before t%d" % t1, "t%d" % tn, "speed-up",
                                                  "after t%d" % t1, "t%d" % tn, "speed-up"))
        for stage, _ in STAGES + [("whole bake", None)]:
            get = (lambda which, t: walls[which, t]) if stage == "whole bake" else \
                  (lambda which, t: stages[which, t].get(stage))
            vals = [get(w, t) for w in ("before", "after") for t in (t1, tn)]
            if all(v is None for v in vals):
                continue
            cell = lambda v: "%9.2f" % v if v is not None else "%9s" % "-"
            sp = lambda a, b: "%7.2fx" % (a / b) if a and b else "%8s" % "-"
            print("%-20s %s %s %s   %s %s %s" % (stage, cell(vals[0]), cell(vals[1]), sp(vals[0], vals[1]),
                                              cell(vals[2]), cell(vals[3]), sp(vals[2], vals[3])))
        for t in threads[1:]:
            for which in ("before", "after"):
                s = walls[which, t1] / walls[which, t] * t1
                f = (t / s - 1) / (t - 1)
                sec = walls[which, t, "outside"]
                w = walls[which, t]
                fo = sec / (sec + t * (w - sec)) if w > sec else 1.0
                print("%s: %-6s at %d threads: speed-up %.2fx over %d thread(s); Amdahl serial fraction from the "
                      "wall times %.1f%%; sampled from outside: %.2f s of %.2f s with at most one thread running, "
                      "serial fraction of the work %.2f%%" % (name, which, t, walls[which, t1] / walls[which, t], t1,
                                                             100 * f, sec, w, 100 * fo))
            if t == tn and ("processes", tn) in walls:
                solo, together = walls["after", t1] * t1, walls["processes", tn]
                print("%s: %d 1-thread bakes at once took %.2f s against %.2f s alone: each core does %.1f%% of the "
                      "work it does alone (the machine's own scaling); %d threads take %.2f s per bake, %d processes "
                      "%.2f s per bake: threads / processes = %.3f" % (
                          name, tn, together, solo, 100 * solo / together, tn, walls["after", tn], tn,
                          together / tn, walls["after", tn] / (together / tn)))
            sec, wall, cpu = serial[t]
            f = sec / (sec + t * (wall - sec)) if wall > sec else 1.0
            print("%s: after  at %d threads: %.2f s of %.2f s wall with at most one thread running (--timings); "
                  "serial fraction of the work %.2f%%; CPU/wall %.2f" % (name, t, sec, wall, 100 * f, cpu / wall))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, len(summary), figsize=(6 * len(summary), 4.5), squeeze=False)
        for ax, (name, walls, stages, serial) in zip(axes[0], summary):
            names = [s for s, _ in STAGES if stages["after", t1].get(s) and stages["before", t1].get(s)] + ["whole bake"]
            for k, which in enumerate(("before", "after")):
                ups = [(walls[which, t1] / walls[which, tn]) if s == "whole bake" else
                       stages[which, t1][s] / stages[which, tn][s] if stages[which, tn].get(s) else 0 for s in names]
                ax.bar([i + 0.4 * k for i in range(len(names))], ups, width=0.4, label=which)
            ax.axhline(tn / t1, color="grey", linestyle="--", linewidth=1, label="ideal %gx" % (tn / t1))
            ax.set_xticks([i + 0.2 for i in range(len(names))])
            ax.set_xticklabels(names, rotation=35, ha="right", fontsize=8)
            ax.set_ylabel("speed-up, %d -> %d threads" % (t1, tn))
            ax.set_title(name)
            ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(png_path, dpi=110)
        print("\nbench_threads: %s, %s" % (csv_path, png_path))
    except ImportError:
        print("\nbench_threads: %s (no matplotlib: no plot)" % csv_path)


if __name__ == "__main__":
    main()
