#!/usr/bin/env python3
"""Plots bench/unwrap.csv: coverage and charting time of lmbake next to xatlas."""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

rows = list(csv.DictReader(open(sys.argv[1])))
names = [r["mesh"] for r in rows]
fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
x = range(len(rows))
a.bar([i - 0.2 for i in x], [float(r["coverage"]) for r in rows], 0.4, label="lmbake")
a.bar([i + 0.2 for i in x], [max(0.0, float(r["xatlas_coverage"])) for r in rows], 0.4, label="xatlas (NOTES.md)")
a.set_xticks(list(x), names, rotation=15)
a.set_ylabel("coverage (texel centres in triangles / atlas)")
a.legend()
b.bar([i - 0.2 for i in x], [float(r["charting_s"]) for r in rows], 0.4, label="lmbake")
b.bar([i + 0.2 for i in x], [max(0.0, float(r["xatlas_charting_s"])) for r in rows], 0.4, label="xatlas (NOTES.md)")
b.set_xticks(list(x), names, rotation=15)
b.set_ylabel("charting time (s)")
b.set_yscale("log")
b.legend()
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=110)
