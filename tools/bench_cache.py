#!/usr/bin/env python3
"""Irradiance cache benchmark (issue 11): error against time for a gather at every texel
(irradiance_cache.error 0) and for the cache at several error settings, on five generated
scenes (tools/make_scenes.py): cornell-point, two-spots, furnace, grazing and contact (blocks
and a thin-legged chair on a floor). Two bounces everywhere, default gather (defensive AMIS).

Error: relative RMSE over lit texels (valid in the mask, reference > 0) against the path-traced
reference (`lmbake bake --reference`, BENCH_REF_PATHS paths, depth 2).
Time: the lighting stages' wall time as lmbake prints it (direct light, the bounce pass and the
final gather: the cache serves both gathers), 2 threads, the fastest of BENCH_REPEAT runs.
Speed-up at equal RMSE: per-texel gathering's time at the cache's RMSE (log-log interpolation
over its three ray counts) over the cache's time. At equal time: per-texel's RMSE at the
cache's time over the cache's RMSE.

At the defaults it also bakes with irradiance_cache.records: per_pass (every pass places its
own records) beside the default shared (one record set refined pass by pass).
Then the path tracer: the Cornell box with all bounces (bounces: auto against a 32-bounce
reference of BENCH_PT_REF paths): the RMSE and time of `--reference` with 1024 paths per texel,
and of lmbake's default bake (the cache on).

usage: bench_cache.py LMBAKE OUTDIR   (writes cache.csv, cache.md, cache.png, cache-<scene>.png)
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
SCENES = [("cornell-point", 48), ("two-spots", 48), ("furnace", 16), ("grazing", 24), ("contact", 24)]
PER_TEXEL_RAYS = [64, 256, 1024]
CACHE = [(0.15, 256), (0.3, 256), (0.6, 256), (0.3, 64)]  # (irradiance_cache.error, samples.gather)
REF_PATHS = int(os.environ.get("BENCH_REF_PATHS", "4096"))
PT_REF = int(os.environ.get("BENCH_PT_REF", "8192"))
THREADS = os.environ.get("BENCH_THREADS", "2")
REPEAT = int(os.environ.get("BENCH_REPEAT", "2"))


def bake(lmbake, out, scene, cfg_text, args, repeat=1):
    cfg = out + ".yaml"
    with open(cfg, "w") as f:
        f.write(cfg_text)
    secs, log = [], ""
    for _ in range(repeat):
        p = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out, "--threads", THREADS] + args,
                           capture_output=True, text=True)
        if p.returncode:
            sys.exit("bake failed: %s" % p.stderr)
        log = p.stdout
        secs.append(float(re.search(r"\(lighting ([0-9.]+) s\)", log).group(1)))
    stem = os.path.splitext(os.path.basename(scene))[0]
    img = oiio.ImageBuf(os.path.join(out, stem + "-lightmap-0.exr")).get_pixels(oiio.FLOAT)[..., :3]
    mask = oiio.ImageBuf(os.path.join(out, stem + "-lightmap-0-mask.png")).get_pixels(oiio.FLOAT)[..., 0] > 0.9
    records = sum(int(m) for m in re.findall(r"final gather, atlas \d+: (\d+) records", log))
    return img.astype(np.float64), mask, min(secs), records


def rel_rmse(x, ref, mask):
    d = (x - ref)[mask]
    return math.sqrt((d ** 2).mean()) / ref[mask].mean()


def loglog(xs, ys, x):
    """y at x by log-log interpolation (linear extrapolation in log-log beyond the ends)."""
    lx, ly = np.log(xs), np.log(ys)
    order = np.argsort(lx)
    lx, ly = lx[order], ly[order]
    if np.log(x) <= lx[0]:
        k = 0
    elif np.log(x) >= lx[-1]:
        k = len(lx) - 2
    else:
        return float(np.exp(np.interp(np.log(x), lx, ly)))
    return float(np.exp(ly[k] + (np.log(x) - lx[k]) * (ly[k + 1] - ly[k]) / (lx[k + 1] - lx[k])))


def base_cfg(density, bounces=2):
    return ("texel_density: %d\nbounces: %s\noutput: {formats: [exr, mask]}\n" % (density, bounces))


def main():
    lmbake, outdir = sys.argv[1], os.path.abspath(sys.argv[2])
    work = os.path.join(outdir, "cache-work")
    os.makedirs(work, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), os.path.join(work, "scenes")],
                   check=True, stdout=subprocess.DEVNULL)
    rows = []
    md = ["# Irradiance cache benchmark", "",
          "Relative RMSE over lit texels against the path-traced reference (%d paths, depth 2); time = lmbake's "
          "lighting wall time (direct + bounce pass + final gather), %s threads, fastest of %d runs. Two bounces, "
          "defensive AMIS. `records` = final gather records." % (REF_PATHS, THREADS, REPEAT), ""]
    fig, axes = plt.subplots(1, len(SCENES), figsize=(5 * len(SCENES), 4.5))
    summary, modes = [], []
    for col, (name, density) in enumerate(SCENES):
        scene = os.path.join(work, "scenes", name + ".gltf")
        print("bench: %s: reference (%d paths)" % (name, REF_PATHS), flush=True)
        ref, mask, ref_s, _ = bake(lmbake, os.path.join(work, name + "-ref"), scene, base_cfg(density),
                                   ["--reference", "--rays", str(REF_PATHS)])
        lit = mask & (ref.mean(axis=2) > 0)
        per_texel = []
        for rays in PER_TEXEL_RAYS:
            img, _, secs, _ = bake(lmbake, os.path.join(work, "%s-pt-%d" % (name, rays)), scene,
                                   base_cfg(density) + "irradiance_cache: {error: 0}\n", ["--rays", str(rays)], REPEAT)
            e = rel_rmse(img, ref, lit)
            per_texel.append((secs, e))
            rows.append({"scene": name, "method": "per-texel", "error": 0, "rays": rays, "records": "",
                         "lighting_s": "%.3f" % secs, "rmse": "%.5f" % e, "speedup_equal_rmse": "",
                         "rmse_ratio_equal_time": ""})
            print("bench: %-14s per-texel %5d rays: %.3f s, RMSE %.4f" % (name, rays, secs, e), flush=True)
        ts, es = np.array([p[0] for p in per_texel]), np.array([p[1] for p in per_texel])
        md += ["## %s (%d lit texels)" % (name, lit.sum()), "",
               "| method | error | rays | records | lighting s | RMSE | speed-up at equal RMSE | per-texel RMSE / cache RMSE at equal time |",
               "|---|---|---|---|---|---|---|---|"]
        for (t, e), rays in zip(per_texel, PER_TEXEL_RAYS):
            md.append("| per-texel | 0 | %d | | %.3f | %.4f | | |" % (rays, t, e))
        cache_pts = []
        for err, rays in CACHE:
            img, _, secs, records = bake(lmbake, os.path.join(work, "%s-ic-%g-%d" % (name, err, rays)), scene,
                                         base_cfg(density) + "irradiance_cache: {error: %g}\n" % err,
                                         ["--rays", str(rays)], REPEAT)
            e = rel_rmse(img, ref, lit)
            speedup = loglog(es, ts, e) / secs  # per-texel time at this RMSE / cache time
            at_time = loglog(ts, es, secs) / e   # per-texel RMSE at this time / cache RMSE
            cache_pts.append((secs, e, err, rays))
            rows.append({"scene": name, "method": "cache", "error": err, "rays": rays, "records": records,
                         "lighting_s": "%.3f" % secs, "rmse": "%.5f" % e, "speedup_equal_rmse": "%.2f" % speedup,
                         "rmse_ratio_equal_time": "%.3f" % at_time})
            md.append("| cache | %g | %d | %d | %.3f | %.4f | %.1fx | %.2f |" % (err, rays, records, secs, e, speedup,
                                                                                   at_time))
            print("bench: %-14s cache %.2f %4d rays: %.3f s, RMSE %.4f, %d records, %.1fx at equal RMSE, "
                  "per-texel/cache RMSE at equal time %.2f" % (name, err, rays, secs, e, records, speedup, at_time),
                  flush=True)
            if (err, rays) == (0.3, 256):
                summary.append((name, speedup, at_time, e, secs))
                # the other record mode at the defaults: every pass places its own records
                img2, _, secs2, rec2 = bake(lmbake, os.path.join(work, "%s-ic-per-pass" % name), scene,
                                            base_cfg(density) + "irradiance_cache: {error: 0.3, records: per_pass}\n",
                                            ["--rays", str(rays)], REPEAT)
                e2 = rel_rmse(img2, ref, lit)
                modes.append((name, secs2, e2, rec2, secs, e, records))
                rows.append({"scene": name, "method": "cache per_pass", "error": err, "rays": rays, "records": rec2,
                             "lighting_s": "%.3f" % secs2, "rmse": "%.5f" % e2, "speedup_equal_rmse": "",
                             "rmse_ratio_equal_time": ""})
                print("bench: %-14s cache per_pass: %.3f s, RMSE %.4f (shared: %.3f s, RMSE %.4f)"
                      % (name, secs2, e2, secs, e), flush=True)
        md.append("")
        ax = axes[col]
        ax.plot(ts, es, "o-", label="per-texel (64/256/1024 rays)")
        for secs, e, err, rays in cache_pts:
            ax.plot([secs], [e], "s", label="cache error %g, %d rays" % (err, rays))
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("lighting wall time (s)")
        ax.set_ylabel("relative RMSE vs path-traced reference")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "cache.png"), dpi=100)

    md += ["## Default settings (error 0.3, 256 rays x ray_scale 4)", "",
           "| scene | speed-up at equal RMSE | per-texel RMSE / cache RMSE at equal time |", "|---|---|---|"]
    md += ["| %s | %.1fx | %.2f |" % (n, s, a) for n, s, a, _, _ in summary]
    md.append("")
    md += ["## irradiance_cache.records: per_pass vs shared (the default), error 0.3, 256 rays", "",
           "| scene | per_pass s | per_pass RMSE | shared s | shared RMSE | time per_pass / shared |", "|---|---|---|---|---|---|"]
    md += ["| %s | %.3f | %.4f | %.3f | %.4f | %.2f |" % (n, t2, e2, t1, e1, t2 / t1) for n, t2, e2, _, t1, e1, _ in modes]
    md.append("")

    # against the path tracer, all bounces
    name, density = "cornell-point", 32
    scene = os.path.join(work, "scenes", name + ".gltf")
    print("bench: path tracer: %d-path reference, 32 bounces" % PT_REF, flush=True)
    cfg = base_cfg(density, "auto")
    truth, mask, _, _ = bake(lmbake, os.path.join(work, "pt-truth"), scene, cfg, ["--reference", "--rays", str(PT_REF)])
    lit = mask & (truth.mean(axis=2) > 0)
    pt, _, pt_s, _ = bake(lmbake, os.path.join(work, "pt-1024"), scene, cfg, ["--reference", "--rays", "1024"])
    lm, _, lm_s, records = bake(lmbake, os.path.join(work, "pt-lmbake"), scene, cfg, [], REPEAT)
    lmp, _, lmp_s, _ = bake(lmbake, os.path.join(work, "pt-lmbake-per-pass"), scene,
                            cfg + "irradiance_cache: {records: per_pass}\n", [], REPEAT)
    lm0, _, lm0_s, _ = bake(lmbake, os.path.join(work, "pt-lmbake-per-texel"), scene,
                            cfg + "irradiance_cache: {error: 0}\n", [], REPEAT)
    e_pt, e_lm, e_lm0 = rel_rmse(pt, truth, lit), rel_rmse(lm, truth, lit), rel_rmse(lm0, truth, lit)
    e_lmp = rel_rmse(lmp, truth, lit)
    md += ["## Against the path tracer (cornell-point, density %d, all bounces)" % density, "",
           "| bake | lighting s | RMSE vs %d-path reference | time vs path tracer |" % PT_REF, "|---|---|---|---|",
           "| `--reference --rays 1024` | %.2f | %.4f | 1 |" % (pt_s, e_pt),
           "| lmbake defaults (cache) | %.2f | %.4f | 1/%.1f |" % (lm_s, e_lm, pt_s / lm_s),
           "| lmbake defaults, `irradiance_cache.records: per_pass` | %.2f | %.4f | 1/%.1f |" % (lmp_s, e_lmp, pt_s / lmp_s),
           "| lmbake defaults, `irradiance_cache.error: 0` | %.2f | %.4f | 1/%.1f |" % (lm0_s, e_lm0, pt_s / lm0_s), ""]
    for label, secs, e in (("reference-1024", pt_s, e_pt), ("defaults-cache", lm_s, e_lm), ("defaults-per-texel", lm0_s, e_lm0)):
        rows.append({"scene": "cornell-point all bounces", "method": label, "error": "", "rays": "", "records": "",
                     "lighting_s": "%.3f" % secs, "rmse": "%.5f" % e, "speedup_equal_rmse": "",
                     "rmse_ratio_equal_time": ""})
    print("bench: path tracer 1024 paths %.2f s RMSE %.4f; lmbake cache %.2f s RMSE %.4f (1/%.1f of the time); "
          "per-texel %.2f s RMSE %.4f" % (pt_s, e_pt, lm_s, e_lm, pt_s / lm_s, lm0_s, e_lm0), flush=True)

    with open(os.path.join(outdir, "cache.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(outdir, "cache.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print("bench: wrote %s/cache.csv, cache.md, cache.png" % outdir)


if __name__ == "__main__":
    main()
