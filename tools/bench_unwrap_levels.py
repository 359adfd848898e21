#!/usr/bin/env python3
"""Level unwrap benchmark: lmbake against xatlas (npm xatlasjs) on the generated single-mesh
level (tools/make_levels.py: 58,300 triangles, a soup with re-added triangles, touching
crates, thin walls), at the default density (what texel_density: auto picks) and at 4x it,
same padding. Per run: charts, atlas size, coverage (texel centres inside a triangle over the
atlas area), charting and packing seconds, and for lmbake the overlapping texels. The two
tools run alternately (A B A B ...); the packing ratio is taken round by round, then the
median.

usage: bench_unwrap_levels.py LMBAKE WORKDIR OUT.csv OUT.png [ROUNDS]
"""
import csv
import json
import os
import re
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PADDING = 2


def lmbake_unwrap(lmbake, level, config):
    p = subprocess.run([lmbake, "unwrap", level, "-q"] + (["-c", config] if config else []), capture_output=True,
                       text=True, timeout=1200)
    if p.returncode != 0:
        sys.exit("lmbake unwrap failed: " + p.stderr[-1500:])
    out = p.stdout
    total = re.search(r"total: charting ([0-9.]+) s, packing ([0-9.]+) s, ([0-9]+) charts in ([0-9]+) atlas", out)
    atlas = re.search(r"atlas 0: ([0-9]+)x([0-9]+), [0-9]+ charts, coverage ([0-9.]+), L2 stretch ([0-9.]+).*"
                      r"overlapping texels ([0-9]+)", out)
    density = re.search(r"texel density: (?:auto, )?([0-9.eE+-]+) texels per unit", out)
    if not total or not atlas or not density or int(total.group(4)) != 1:
        sys.exit("lmbake unwrap: unexpected report:\n" + out[-1500:])
    return {"tool": "lmbake", "texels_per_unit": float(density.group(1)), "charts": int(total.group(3)),
            "width": int(atlas.group(1)), "height": int(atlas.group(2)), "coverage": float(atlas.group(3)),
            "l2_stretch": float(atlas.group(4)), "overlapping_texels": int(atlas.group(5)),
            "charting_s": float(total.group(1)), "packing_s": float(total.group(2))}


def xatlas_unwrap(level, tpu):
    p = subprocess.run(["node", os.path.join(HERE, "xatlas_unwrap.mjs"), level, repr(tpu), str(PADDING)],
                       capture_output=True, text=True, timeout=1200)
    if p.returncode != 0:
        sys.exit("xatlas failed: " + p.stderr[-1500:])
    r = json.loads(p.stdout.strip().splitlines()[-1])
    r.update({"l2_stretch": "", "overlapping_texels": ""})
    return r


def main():
    lmbake, work, out_csv, out_png = sys.argv[1:5]
    rounds = int(sys.argv[5]) if len(sys.argv) > 5 else 3
    os.makedirs(work, exist_ok=True)
    level = os.path.join(work, "level-single.glb")
    if not os.path.exists(level):
        subprocess.run([sys.executable, os.path.join(HERE, "make_levels.py"), work, "single"], check=True,
                       stdout=subprocess.DEVNULL)
    auto = lmbake_unwrap(lmbake, level, None)["texels_per_unit"]
    rows = []
    for scale in (1, 4):
        tpu = round(auto * scale, 4)
        config = os.path.join(work, "density-%dx.yaml" % scale)
        with open(config, "w") as f:
            f.write("texel_density: %r\natlas: {padding: %d}\n" % (tpu, PADDING))
        lmbake_unwrap(lmbake, level, config)  # warm-up (page cache)
        for r in range(rounds):
            for row in (lmbake_unwrap(lmbake, level, config), xatlas_unwrap(level, tpu)):
                row.update({"scale": scale, "round": r + 1, "texels_per_unit": tpu})
                rows.append(row)
                print("%-6s %dx round %d: %6d charts, %4dx%-4d coverage %.3f, charting %.2f s, packing %.2f s" %
                      (row["tool"], scale, r + 1, row["charts"], row["width"], row["height"], row["coverage"],
                       row["charting_s"], row["packing_s"]), flush=True)
    keys = ["tool", "scale", "round", "texels_per_unit", "charts", "width", "height", "coverage", "l2_stretch",
            "overlapping_texels", "charting_s", "packing_s"]
    with open(out_csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    summary = {}
    for scale in (1, 4):
        pick = lambda tool, k: [r[k] for r in rows if r["tool"] == tool and r["scale"] == scale]
        ratios = [a / b for a, b in zip(pick("lmbake", "packing_s"), pick("xatlas", "packing_s"))]
        summary[scale] = {t: {k: statistics.median(pick(t, k)) for k in ("charts", "coverage", "charting_s",
                                                                        "packing_s")} for t in ("lmbake", "xatlas")}
        summary[scale]["packing_ratio"] = statistics.median(ratios)
        s = summary[scale]
        print("%dx (%.4g texels per unit): charts %d vs %d, coverage %.3f vs %.3f, charting %.2f vs %.2f s, packing "
              "%.2f vs %.2f s, lmbake/xatlas packing %.2f (median of %d rounds)" %
              (scale, auto * scale, s["lmbake"]["charts"], s["xatlas"]["charts"], s["lmbake"]["coverage"],
               s["xatlas"]["coverage"], s["lmbake"]["charting_s"], s["xatlas"]["charting_s"],
               s["lmbake"]["packing_s"], s["xatlas"]["packing_s"], s["packing_ratio"],
               rounds))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(12, 3.6))
    labels = ["1x", "4x"]
    for j, (k, title) in enumerate((("charts", "charts"), ("coverage", "coverage"), ("packing_s", "packing (s)"))):
        for o, tool in ((-0.2, "lmbake"), (0.2, "xatlas")):
            ax[j].bar([i + o for i in range(2)], [summary[s][tool][k] for s in (1, 4)], 0.4, label=tool)
        ax[j].set_xticks(range(2))
        ax[j].set_xticklabels(["%s (%.3g/unit)" % (l, auto * s) for l, s in zip(labels, (1, 4))])
        ax[j].set_title(title)
    ax[0].legend()
    fig.suptitle("level-single (58,300 triangles): lmbake and xatlas, padding %d, medians of %d rounds" %
                 (PADDING, rounds))
    fig.tight_layout()
    fig.savefig(out_png, dpi=110)
    print("wrote %s and %s" % (out_csv, out_png))


if __name__ == "__main__":
    main()
