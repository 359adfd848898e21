#!/usr/bin/env python3
"""Final-gather benchmark (issues 5 and 12): error against time for classic gathering, the
default gather (guided AMIS: defensive AMIS whose texels start from a mixture learned at pilot
texels), unguided defensive AMIS (every texel adapts alone) and the paper's AMIS (balance
weights, biased), at 64, 256 and 1024 rays per texel, a gather at every texel
(irradiance_cache.error 0: the estimators alone), on five generated scenes (tools/make_scenes.py):
  cornell-point  the paper's Figure 1: Cornell box, point light 3 cm under the ceiling
  two-spots      two bright spots on opposite walls (one lobe cannot fit both)
  furnace        light from everywhere alike (nothing to adapt to)
  grazing        a spot on a corridor floor, seen at grazing angles from the floor
  gap            a room lit through a 4 cm slit only (the failure case: pilots rarely see it)
Errors: relative RMSE over valid texels (the mask output) against
  - the reference: `lmbake bake --reference` (path tracing, no cache, BENCH_REF_PATHS paths),
    whose own noise is reported too (a second reference with another seed);
  - the converged gather: classic gathering with BENCH_CONVERGED_RAYS rays through the same
    cache, so the difference is the estimator's noise alone.
gather.direct_at_hits: the converged gather with direct light computed at every hit differs
from the converged gather through the cache by the cache's resolution error for direct light;
reported at the benchmark's density and at 8 texels/m, with the time it costs the default
gather at 1024 rays.
Time: the final gather's wall time as lmbake prints it (2 threads), the fastest of BENCH_REPEAT
(3) runs: the machine is shared and single runs move by tens of percent.
usage: bench_gather.py LMBAKE OUTDIR   (writes gather.csv, gather.md, gather.png, gather-<scene>.png)
"""
import csv
import math
import os
import re
import subprocess
import sys

import matplotlib
import numpy as np
import OpenImageIO as oiio

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = [("cornell-point", 32, ""), ("two-spots", 32, ""), ("furnace", 16, ""), ("grazing", 24, ""),
          ("gap", 32, "lightmap: {exclude: [lit_room]}\n")]
DEFAULT = "default (guided)"
METHODS = [("classic", ["--method", "cosine"], ""),
           (DEFAULT, ["--method", "amis_defensive"], ""),
           ("unguided defensive", ["--method", "amis_defensive"], "  guide_stride: 0\n"),
           ("AMIS paper", ["--method", "amis"], "  amis_weights: balance\n")]
PER_TEXEL = "irradiance_cache: {error: 0}\n"
DIRECT_AT_HITS = "  direct_at_hits: true\n"
RAYS = [64, 256, 1024]
REF_PATHS = int(os.environ.get("BENCH_REF_PATHS", "8192"))
CONVERGED = int(os.environ.get("BENCH_CONVERGED_RAYS", "16384"))
THREADS = os.environ.get("BENCH_THREADS", "2")
REPEAT = int(os.environ.get("BENCH_REPEAT", "3"))  # timed runs per setting; the fastest counts


def bake(lmbake, out, scene, density, extra_cfg, args, repeat=1, scene_cfg=""):
    """extra_cfg: lines under gather:; scene_cfg: top-level lines (a gather at every texel unless it
    sets irradiance_cache)."""
    cfg = out + ".yaml"
    with open(cfg, "w") as f:
        f.write("texel_density: %d\nbounces: 1\nsamples: {texel: 4, direct: 16, amis_iterations: 4}\n"
                "output: {formats: [exr, mask]}\ngather:\n  defensive: 0.1\n%s%s%s"
                % (density, extra_cfg, "" if "irradiance_cache" in scene_cfg else PER_TEXEL, scene_cfg))
    secs = []
    for _ in range(repeat):  # same seed, same files: only the time differs (this machine is shared)
        p = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out, "--threads", THREADS] + args,
                           capture_output=True, text=True)
        if p.returncode:
            sys.exit("bake failed: %s" % p.stderr)
        m = re.search(r"(final gather|reference): ([0-9.]+) s, ([0-9]+) rays", p.stdout)
        secs.append(float(m.group(2)))
    stem = os.path.splitext(os.path.basename(scene))[0]
    img = oiio.ImageBuf(os.path.join(out, stem + "-lightmap-0.exr")).get_pixels(oiio.FLOAT)[..., :3]
    mask = oiio.ImageBuf(os.path.join(out, stem + "-lightmap-0-mask.png")).get_pixels(oiio.FLOAT)[..., 0] > 0.9
    return img.astype(np.float64), mask, min(secs), int(m.group(3))


def rel_rmse(x, ref, mask):
    d = (x - ref)[mask]
    return math.sqrt((d ** 2).mean()) / ref[mask].mean()


def tonemap(img, scale):
    x = img * scale
    y = x / (1 + x)
    return np.where(y <= 0.0031308, 12.92 * y, 1.055 * np.power(np.maximum(y, 0), 1 / 2.4) - 0.055).clip(0, 1)


def loglog_at(ts, es, t):
    """Error of a method at time t by log-log interpolation over its (time, error) points."""
    lt, le = np.log(ts), np.log(es)
    if t <= ts[0]:
        return float(np.exp(le[0] + (np.log(t) - lt[0]) * (le[1] - le[0]) / (lt[1] - lt[0])))
    if t >= ts[-1]:
        return float(np.exp(le[-1] + (np.log(t) - lt[-1]) * (le[-1] - le[-2]) / (lt[-1] - lt[-2])))
    return float(np.exp(np.interp(np.log(t), lt, le)))


def main():
    lmbake, outdir = sys.argv[1], os.path.abspath(sys.argv[2])
    work = os.path.join(outdir, "gather-work")
    os.makedirs(work, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), os.path.join(work, "scenes")],
                   check=True, stdout=subprocess.DEVNULL)
    rows, hits_rows, summary = [], [], []
    md = ["# Final gather benchmark", "",
          "Relative RMSE over valid texels, a gather at every texel; `vs ref` against the path-traced reference "
          "(%d paths), `noise` against the converged gather (classic, %d rays, same cache). One bounce, 4 AMIS "
          "iterations, defensive share 0.1, %s threads, fastest of %d timed runs. \"noise at classic's time\": "
          "log-log interpolation of the method's noise to classic's time at the same rays."
          % (REF_PATHS, CONVERGED, THREADS, REPEAT), ""]
    fig, axes = plt.subplots(2, len(SCENES), figsize=(4.5 * len(SCENES), 8))
    for col, (name, density, scene_cfg) in enumerate(SCENES):
        scene = os.path.join(work, "scenes", name + ".gltf")
        path = lambda tag: os.path.join(work, "%s-%s" % (name, tag))  # noqa: E731
        print("bench: %s: references (%d paths, two seeds)" % (name, REF_PATHS), flush=True)
        ref, mask, _, _ = bake(lmbake, path("ref"), scene, density, "", ["--reference", "--rays", str(REF_PATHS)],
                               scene_cfg=scene_cfg)
        ref2, _, _, _ = bake(lmbake, path("ref2"), scene, density, "", ["--reference", "--rays", str(REF_PATHS)],
                             scene_cfg=scene_cfg + "seed: 2\n")
        ref_noise = rel_rmse(ref, ref2, mask) / math.sqrt(2)
        conv, _, _, _ = bake(lmbake, path("conv"), scene, density, "", ["--method", "cosine", "--rays", str(CONVERGED)],
                             scene_cfg=scene_cfg)
        cache_err = rel_rmse(conv, ref, mask)
        results, images = {}, {}
        for label, args, extra in METHODS:
            for rays in RAYS:
                img, _, secs, nrays = bake(lmbake, path("%s-%d" % (label.replace(" ", "_").replace("(", "").replace(")", ""), rays)),
                                           scene, density, extra, args + ["--rays", str(rays)], REPEAT, scene_cfg)
                e_ref, e_noise = rel_rmse(img, ref, mask), rel_rmse(img, conv, mask)
                results[(label, rays)] = (secs, e_ref, e_noise, nrays)
                if rays == 1024:
                    images[label] = img
                rows.append({"scene": name, "method": label, "rays_per_texel": rays, "gather_s": "%.4f" % secs,
                             "rays": nrays, "rays_per_s": "%.4g" % (nrays / secs if secs > 0 else 0),
                             "rmse_vs_reference": "%.5f" % e_ref, "rmse_noise": "%.5f" % e_noise,
                             "reference_noise": "%.5f" % ref_noise, "converged_vs_reference": "%.5f" % cache_err,
                             "valid_texels": int(mask.sum())})
                print("bench: %-14s %-20s %5d rays: %.3f s, %.3g rays/s, RMSE vs ref %.4f, noise %.4f"
                      % (name, label, rays, secs, nrays / max(secs, 1e-9), e_ref, e_noise), flush=True)
        # direct light at gather hits: the cache's resolution error and what computing it costs
        for dens in (density, 8):
            c0 = conv if dens == density else bake(lmbake, path("conv-d8"), scene, dens, "",
                                                   ["--method", "cosine", "--rays", str(CONVERGED)],
                                                   scene_cfg=scene_cfg)[0]
            c1, m1, _, _ = bake(lmbake, path("conv-hits-d%d" % dens), scene, dens, DIRECT_AT_HITS,
                                ["--method", "cosine", "--rays", str(CONVERGED)], scene_cfg=scene_cfg)
            off = bake(lmbake, path("default-d%d" % dens), scene, dens, "", ["--method", "amis_defensive", "--rays", "1024"],
                       REPEAT, scene_cfg)
            on = bake(lmbake, path("default-hits-d%d" % dens), scene, dens, DIRECT_AT_HITS,
                      ["--method", "amis_defensive", "--rays", "1024"], REPEAT, scene_cfg)
            hits_rows.append({"scene": name, "texel_density": dens, "cache_resolution_error": "%.5f" % rel_rmse(c0, c1, m1),
                              "default_1024_s": "%.4f" % off[2], "default_1024_direct_at_hits_s": "%.4f" % on[2],
                              "noise_off": "%.5f" % rel_rmse(off[0], c0, m1), "noise_on": "%.5f" % rel_rmse(on[0], c1, m1)})
            print("bench: %-14s direct at hits, %d texels/m: cache resolution error %.4f, default 1024 rays %.3f s -> %.3f s"
                  % (name, dens, rel_rmse(c0, c1, m1), off[2], on[2]), flush=True)
        # tables
        md += ["## %s (%d valid texels; reference noise %.4f, converged gather vs reference %.4f)"
               % (name, int(mask.sum()), ref_noise, cache_err), "",
               "| method | rays | gather s | rays/s | time vs classic | RMSE vs ref | noise RMSE | noise at classic's time |",
               "|---|---|---|---|---|---|---|---|"]
        for label, _, _ in METHODS:
            ts = np.array([results[(label, r)][0] for r in RAYS])
            ns = np.array([results[(label, r)][2] for r in RAYS])
            for k, r in enumerate(RAYS):
                secs, e_ref, e_noise, nrays = results[(label, r)]
                tc = results[("classic", r)][0]
                md.append("| %s | %d | %.3f | %.3g | %+.0f%% | %.4f | %.4f | %.4f |"
                          % (label, r, secs, nrays / max(secs, 1e-9), 100 * (secs / tc - 1), e_ref, e_noise,
                             loglog_at(ts, ns, tc)))
        md.append("")
        # the summary at 1024 rays: equal-time noise over classic's, efficiency, overhead
        tc, _, nc, _ = results[("classic", 1024)]
        line = {"scene": name}
        for label, _, _ in METHODS[1:]:
            ts = np.array([results[(label, r)][0] for r in RAYS])
            ns = np.array([results[(label, r)][2] for r in RAYS])
            t, _, n, _ = results[(label, 1024)]
            line[label] = (loglog_at(ts, ns, tc) / nc, (nc * nc * tc) / (n * n * t) if n > 0 else float("inf"))
        line["overheads"] = [results[(DEFAULT, r)][0] / results[("classic", r)][0] - 1 for r in RAYS]
        summary.append(line)
        for row, key, title in ((0, 2, "noise RMSE (vs converged gather)"), (1, 1, "RMSE vs path-traced reference")):
            ax = axes[row][col]
            for label, _, _ in METHODS:
                ax.plot([results[(label, r)][0] for r in RAYS], [results[(label, r)][key] for r in RAYS], "o-",
                        label=label)
                for r in RAYS:
                    ax.annotate(str(r), (results[(label, r)][0], results[(label, r)][key]), fontsize=6)
            if row == 1:
                ax.axhline(ref_noise, color="grey", ls="--", lw=0.8, label="reference's own noise")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title("%s: %s" % (name, title), fontsize=9)
            ax.set_xlabel("final gather wall time (s)")
            ax.set_ylabel("relative RMSE")
            ax.grid(True, which="both", lw=0.3)
            if col == 0:
                ax.legend(fontsize=7)
        # side-by-side images at 1024 rays, one exposure (the reference's 95th percentile at 0.8)
        lum = ref[mask].mean(axis=1)
        scale = 0.8 / max(np.percentile(lum, 95), 1e-9)
        panels = [("reference", ref)] + [(l, images[l]) for l, _, _ in METHODS]
        f2, ax2 = plt.subplots(1, len(panels), figsize=(4 * len(panels), 4 * ref.shape[0] / ref.shape[1] + 0.6))
        for a, (label, img) in zip(ax2, panels):
            a.imshow(tonemap(img, scale), interpolation="nearest")
            a.set_title("%s%s" % (label, "" if label == "reference" else ", 1024 rays, noise %.3f"
                                  % results[(label, 1024)][2]), fontsize=9)
            a.axis("off")
        f2.tight_layout()
        f2.savefig(os.path.join(outdir, "gather-%s.png" % name), dpi=100)
        plt.close(f2)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "gather.png"), dpi=100)
    overheads = sorted(o for line in summary for o in line["overheads"])
    head = ["## Summary at 1024 rays", "",
            "Noise at classic's time over classic's noise (below 1: better at equal time) and efficiency "
            "(classic noise^2 x time over the method's). Median time the default adds over classic at equal rays, "
            "over the %d settings (5 scenes x %s rays): %+.0f%% (range %+.0f%% to %+.0f%%)."
            % (len(overheads), "/".join(str(r) for r in RAYS), 100 * float(np.median(overheads)),
               100 * overheads[0], 100 * overheads[-1]), "",
            "| scene | " + " | ".join("%s: equal-time ratio / efficiency" % l for l, _, _ in METHODS[1:]) + " |",
            "|---|" + "---|" * (len(METHODS) - 1)]
    for line in summary:
        head.append("| %s | " % line["scene"] + " | ".join("%.2f / %.2f" % line[l] for l, _, _ in METHODS[1:]) + " |")
    head += ["", "## gather.direct_at_hits", "",
             "Cache resolution error: the converged gather with direct light computed at every hit against the "
             "converged gather through the cache. Time and noise: the default gather at 1024 rays without and with it.",
             "", "| scene | texels/m | cache resolution error | default 1024 s: off / on | noise off / on |",
             "|---|---|---|---|---|"]
    for h in hits_rows:
        head.append("| %s | %d | %s | %s / %s | %s / %s |" % (h["scene"], h["texel_density"], h["cache_resolution_error"],
                                                           h["default_1024_s"], h["default_1024_direct_at_hits_s"],
                                                           h["noise_off"], h["noise_on"]))
    md = md[:3] + head + [""] + md[3:]
    with open(os.path.join(outdir, "gather.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(outdir, "gather-direct-at-hits.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(hits_rows[0].keys()))
        w.writeheader()
        w.writerows(hits_rows)
    with open(os.path.join(outdir, "gather.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print("bench: wrote %s/gather.csv, gather-direct-at-hits.csv, gather.md, gather.png and gather-<scene>.png" % outdir)


if __name__ == "__main__":
    main()
