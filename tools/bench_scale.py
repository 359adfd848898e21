#!/usr/bin/env python3
"""Scale benchmark (driven by tools/bench_scale.sh; docs/benchmarks.md#scale): bakes each level
with the BEFORE and AFTER binaries, one after the other (never two at once), at defaults, under
a time limit (peak RSS read from /proc while the bake runs), and records per bake: the exit (ok, timeout, error), wall
seconds, peak RSS, texels, BVH build seconds, seams seconds. Bevy's Cornell box is baked the same
way as the yardstick for time. Writes a CSV and a plot of peak memory against copies.

usage: bench_scale.py BEFORE AFTER WORKDIR CSV PNG TIMEOUT_S LEVEL[=COPIES] ...
  BEFORE may be '-' to bake with AFTER only.
"""
import csv
import os
import re
import subprocess
import sys
import time


def bake(lmbake, scene, out, timeout):
    """One bake, its peak RSS read from /proc (VmHWM) while it runs, so that a bake stopped at
    the time limit still has one; returns a dict of what it measured."""
    timings = out + ".timings.csv"
    log = open(out + ".log", "w")
    t0 = time.time()
    p = subprocess.Popen([lmbake, "bake", scene, "-o", out, "--timings=" + timings], stdout=log,
                         stderr=subprocess.STDOUT)
    peak_kb, killed = 0, False
    while p.poll() is None:
        try:
            with open("/proc/%d/status" % p.pid) as f:
                for line in f:
                    if line.startswith("VmHWM:"):
                        peak_kb = max(peak_kb, int(line.split()[1]))
        except OSError:
            pass
        if time.time() - t0 > timeout:
            p.kill()
            killed = True
        time.sleep(0.2)
    wall = time.time() - t0
    log.close()
    with open(out + ".log") as f:
        text = f.read()
    texels = re.search(r"bake: .* ([0-9]+) texels \(([0-9]+) valid\)", text)
    bvh = re.search(r"ray tracing: .* built in ([0-9.]+) s", text)
    seams = None
    if os.path.exists(timings):
        with open(timings) as f:
            for row in csv.DictReader(f):
                if row["stage"] == "seams":
                    seams = float(row["wall_s"])
    status = "timeout" if killed else ("ok" if p.returncode == 0 else "error %d" % p.returncode)
    if status.startswith("error"):
        sys.stderr.write(text[-2000:])
    return {"status": status, "wall_s": round(wall, 2), "peak_mb": round(peak_kb / 1024.0, 1) if peak_kb else "",
            "texels": int(texels.group(1)) if texels else "", "bvh_s": float(bvh.group(1)) if bvh else "",
            "seams_s": seams if seams is not None else ""}


def main():
    before, after, work, csv_path, png, timeout = sys.argv[1:7]
    timeout = int(timeout)
    levels = []
    for arg in sys.argv[7:]:
        path, _, copies = arg.partition("=")
        levels.append((path, int(copies) if copies else 0))
    binaries = [("after", after)] if before == "-" else [("before", before), ("after", after)]
    rows = []
    for path, copies in levels:
        for label, lmbake in binaries:
            name = os.path.splitext(os.path.basename(path))[0]
            out = os.path.join(work, "%s-%s" % (name, label))
            subprocess.run(["rm", "-rf", out])
            r = bake(lmbake, path, out, timeout)
            r.update({"level": name, "copies": copies, "binary": label})
            rows.append(r)
            print("%-28s %-6s %-8s %8s s %9s MB %9s texels  BVH %6s s  seams %7s s" % (
                name, label, r["status"], r["wall_s"], r["peak_mb"], r["texels"], r["bvh_s"], r["seams_s"]), flush=True)
            subprocess.run(["rm", "-rf", out])
    fields = ["level", "copies", "binary", "status", "wall_s", "peak_mb", "texels", "bvh_s", "seams_s"]
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow({k: r[k] for k in fields})
    cornell = {r["binary"]: r for r in rows if "Cornell" in r["level"]}
    for r in rows:
        c = cornell.get(r["binary"])
        if r["copies"] and c and c["status"] == "ok" and r["status"] == "ok":
            print("%s %s: %.2fx the Cornell box's time (%s s / %s s)" % (r["level"], r["binary"],
                                                                       r["wall_s"] / c["wall_s"], r["wall_s"], c["wall_s"]))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("bench_scale: no matplotlib, no plot")
        return
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for label, _ in binaries:
        pts = sorted((r["copies"], r["peak_mb"], r["status"]) for r in rows
                     if r["binary"] == label and r["copies"] and r["peak_mb"] != "")
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", label=label)
            for x, y, s in pts:
                if s != "ok":
                    ax.annotate(s, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
    ax.set_xscale("log")
    ax.set_xlabel("instanced copies (tools/make_levels.py gpu:N)")
    ax.set_ylabel("peak RSS, MB")
    ax.set_title("lmbake bake at defaults: peak memory against copies")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print("bench_scale: wrote %s and %s" % (csv_path, png))


if __name__ == "__main__":
    main()
