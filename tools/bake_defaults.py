#!/usr/bin/env python3
"""Bakes every .gltf/.glb under the given folders with NO config file (issue 10: "defaults bake
real levels") and records, per file: exit code, the density auto chose, texels, bounces run,
wall time, peak memory, NaN texels in the EXR and the Khronos validator's error count.
Files meant to be refused (Draco, broken) must exit 2 with an error line; everything else
must exit 0 with 0 validator errors and no NaN. Writes CSV + a Markdown table. Not a test (it
takes tens of minutes); tools/bake_defaults.sh runs it.

usage: bake_defaults.py LMBAKE WORKDIR OUT_CSV DIR...
Each bake holds /tmp/lmbake-build.lock (if flock exists) so no build runs beside it.
"""
import csv
import glob
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def field(rx, text, cast=str, default=""):
    m = re.search(rx, text)
    return cast(m.group(1)) if m else default


def main():
    lmbake, work, out_csv, dirs = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
    os.makedirs(work, exist_ok=True)
    validator = os.path.join(ROOT, "tests", "bake", "validate_gltf.js")
    env = dict(os.environ, NODE_PATH=os.path.join(ROOT, "node_modules"))
    lock = ["flock", "/tmp/lmbake-build.lock"] if shutil.which("flock") else []
    rows, problems = [], []
    files = []
    for d in dirs:
        files += sorted(p for p in glob.glob(os.path.join(d, "**", "*.gl*"), recursive=True)
                        if p.endswith((".gltf", ".glb")))
    for n, path in enumerate(files):
        out = os.path.join(work, "out-%d" % n)
        shutil.rmtree(out, ignore_errors=True)
        # the lock is taken outside /usr/bin/time: waiting for it is not timed
        p = subprocess.run(lock + ["/usr/bin/time", "-v", lmbake, "bake", path, "-o", out], capture_output=True,
                           text=True, timeout=3600)
        el = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (?:(\d+):)?(\d+):([0-9.]+)", p.stderr)
        secs = (int(el.group(1) or 0) * 3600 + int(el.group(2)) * 60 + float(el.group(3))) if el else -1
        rel = os.path.relpath(path, os.path.dirname(os.path.dirname(path)))
        row = {"file": rel, "exit": p.returncode, "seconds": "%.1f" % secs,
               "peak_mb": "%.0f" % (field(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr, int, 0) / 1024)}
        if p.returncode == 0:
            row["density"] = field(r"texel density: (?:auto, )?([0-9.eE+-]+) texels per unit", p.stdout)
            row["texels"] = field(r"(\d+) texels \(\d+ valid\)", p.stdout)
            row["atlases"] = field(r"(\d+) atlas\(es\)", p.stdout)
            row["bounces"] = field(r"(\d+) bounce\(s\)", p.stdout)
            row["tail"] = field(r"geometric tail of ([0-9.]+%)", p.stdout)
            nan = 0
            for exr in glob.glob(os.path.join(out, "*.exr")):
                px = oiio.ImageBuf(exr).get_pixels(oiio.FLOAT)
                nan += int(np.count_nonzero(~np.isfinite(px)))
            row["nan_texels"] = nan
            gl = [f for f in os.listdir(out) if f.endswith(".gltf")]
            v = subprocess.run(["node", validator, os.path.join(out, gl[0])], capture_output=True, text=True, env=env)
            row["validator_errors"] = field(r": (\d+) errors", v.stdout, int, -1)
            if nan or row["validator_errors"] != 0:
                problems.append("%s: %d NaN texels, validator errors %s" % (rel, nan, row["validator_errors"]))
        elif p.returncode == 2 and "error:" in p.stderr:
            row["refused"] = [l for l in p.stderr.splitlines() if "error:" in l][-1][:200]
        else:
            problems.append("%s: exit %d: %s" % (rel, p.returncode, p.stderr[-600:]))
        rows.append(row)
        print("%-60s exit %d %6ss density %-8s texels %-8s bounces %-3s %s" % (
            rel, p.returncode, row["seconds"], row.get("density", ""), row.get("texels", ""), row.get("bounces", ""),
            row.get("refused", "")), flush=True)
        shutil.rmtree(out, ignore_errors=True)
    keys = ["file", "exit", "density", "texels", "atlases", "bounces", "tail", "seconds", "peak_mb", "nan_texels",
            "validator_errors", "refused"]
    with open(out_csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in keys})
    md = os.path.splitext(out_csv)[0] + ".md"
    with open(md, "w") as f:
        f.write("| file | exit | density (texels/unit) | texels | bounces | tail added | time s | peak MB |\n")
        f.write("|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            f.write("| %s | %s | %s | %s | %s | %s | %s | %s |\n" % (
                r["file"], r["exit"], r.get("density", ""), r.get("texels", ""), r.get("bounces", ""),
                r.get("tail", ""), r["seconds"], r["peak_mb"]))
    print("%d files, %d baked, %d refused, %d problems; wrote %s and %s" % (
        len(rows), sum(r["exit"] == 0 for r in rows), sum(r["exit"] == 2 for r in rows), len(problems), out_csv, md))
    for pr in problems:
        print("PROBLEM", pr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
