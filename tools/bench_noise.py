#!/usr/bin/env python3
"""Noise and error against time: three scenes baked with fixed sample counts (samples.adaptive:
false, 1x and 2x the default counts), with adaptive sampling (samples.noise 0.01, on 1x and 2x
the default counts: its budget is the direct step's rays, its records' cap twice their base),
all four without the denoiser, and at the defaults (adaptive sampling and the denoiser), each
at seeds 1 and 2. Noise is measured from outside, as an artist sees it:
per valid texel (the -mask.png), the luminance of the two seeds' lightmaps, their difference
over sqrt 2, relative to their mean; the rms over texels, its 95th percentile, and the same
after averaging 9 x 9 texels (the low-frequency part: irradiance-cache records' blotches).
Time is the bake's own wall time ("bake: X s"), the mean of the two seeds.
Error is against a converged reference of the same layout (a gather at every texel, no cache,
4096 rays, 256 direct samples, fixed counts, no denoiser; baked once per scene and kept in
OUT/noise-work): per valid texel whose reference is above 5% of the mean, the relative
difference of each seed's bake, rms and p95, the same at 9 x 9, and the bias of the mean. It
holds the cache's own interpolation error, which every case shares, and the reference's noise.
Scenes: bevy's Cornell box (an emissive ceiling: area-light penumbrae), the two-spots room
(tools/make_scenes.py: two spot lights, exact direct light, all noise from the gather) and bevy's
MixedLightingExample (textured, a sun disc and an emissive, real export).
Writes OUT/noise.csv, OUT/noise.md and OUT/noise.png. Not a test; tools/bench_noise.sh runs it
(about 20 minutes on 2 cores).

usage: bench_noise.py LMBAKE OUTDIR [SCENE ...]   (SCENE: cornell, two-spots, mixed)
"""
import csv
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio
from scipy.ndimage import uniform_filter

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
LUM = np.array([0.2126, 0.7152, 0.0722])

OFF = "denoise: {indirect: false, direct: false}\n"
CASES = [("fixed 1x", OFF + "samples: {adaptive: false}\n"),
         ("fixed 2x", OFF + "samples: {adaptive: false, direct: 32, gather: 512}\n"),
         ("adaptive 1%", OFF),
         ("adaptive 1%, 2x samples", OFF + "samples: {direct: 32, gather: 512}\n"),
         ("adaptive + denoiser (defaults)", "")]
REFERENCE = OFF + "irradiance_cache: {error: 0}\nsamples: {adaptive: false, direct: 256, gather: 4096}\n"


def scenes(work):
    gen = os.path.join(work, "generated")
    if not os.path.isdir(gen):
        subprocess.run([sys.executable, os.path.join(HERE, "make_scenes.py"), gen], check=True,
                       stdout=subprocess.DEVNULL)
    return {"cornell": os.path.join(ROOT, "assets/scenes/cornell-box-bevy/CornellBox.glb"),
            "two-spots": os.path.join(gen, "two-spots.gltf"),
            "mixed": os.path.join(ROOT, "assets/scenes/mixed-lighting-bevy/MixedLightingExample.gltf")}


def bake(lmbake, scene, out, config, seed):
    cfg = out + ".yaml"
    with open(cfg, "w") as f:
        f.write(config + "output: {formats: [exr, mask]}\n")
    shutil.rmtree(out, ignore_errors=True)
    r = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out, "--seed", str(seed)], capture_output=True,
                       text=True)
    if r.returncode != 0:
        raise SystemExit("bake failed (%s):\n%s" % (out, r.stderr[-3000:]))
    seconds = float(re.search(r"^bake: ([0-9.]+) s", r.stdout + r.stderr, re.M).group(1))
    exrs = sorted(f for f in os.listdir(out) if re.search(r"-lightmap-\d+\.exr$", f))
    return seconds, [os.path.join(out, f) for f in exrs], r.stderr


def luminance_and_mask(exr):
    px = oiio.ImageBuf(exr).get_pixels(oiio.FLOAT)[..., :3]
    mask = oiio.ImageBuf(exr.replace(".exr", "-mask.png")).get_pixels(oiio.FLOAT)[..., 0] > 0.5
    return (px * LUM).sum(-1), mask


def error(pairs, reference):
    """Against the reference: rms and p95 of the per-texel relative error, rms and p99 at 9 x 9,
    and the bias of the mean (both seeds)."""
    per, box, bias = [], [], []
    for (a, b), r in zip(pairs, reference):
        lr, mask = luminance_and_mask(r)
        ok = mask & (lr > 0.05 * lr[mask].mean())
        v = ok.astype(float)
        cnt = uniform_filter(v, 9, mode="constant")
        full = ok & (cnt > 0.999)
        fr = uniform_filter(lr * v, 9, mode="constant") / np.maximum(cnt, 1e-9)
        for exr in (a, b):
            l, _ = luminance_and_mask(exr)
            per.append(((l - lr) / np.where(ok, lr, 1))[ok])
            fl = uniform_filter(l * v, 9, mode="constant") / np.maximum(cnt, 1e-9)
            box.append(((fl - fr) / np.where(full, fr, 1))[full])
            bias.append(l[ok].sum() / lr[ok].sum() - 1)
    per, box = np.concatenate(per), np.concatenate(box)
    return (np.sqrt((per ** 2).mean()), np.percentile(np.abs(per), 95), np.sqrt((box ** 2).mean()),
            np.percentile(np.abs(box), 99), float(np.mean(bias)))


def noise(pairs):
    """rms and p95 of the per-texel relative noise, rms and p99 of its 9 x 9 average."""
    per, box = [], []
    for a, b in pairs:
        la, mask = luminance_and_mask(a)
        lb, _ = luminance_and_mask(b)
        m = 0.5 * (la + lb)
        ok = mask & (m > 1e-4 * max(m[mask].max(), 1e-30))
        per.append(((la - lb) / np.sqrt(2) / np.where(ok, m, 1))[ok])
        v = ok.astype(float)
        cnt = uniform_filter(v, 9, mode="constant")
        full = ok & (cnt > 0.999)
        fa = uniform_filter(la * v, 9, mode="constant") / np.maximum(cnt, 1e-9)
        fb = uniform_filter(lb * v, 9, mode="constant") / np.maximum(cnt, 1e-9)
        fm = 0.5 * (fa + fb)
        box.append(((fa - fb) / np.sqrt(2) / np.where(full, fm, 1))[full])
    per, box = np.concatenate(per), np.concatenate(box)
    return (np.sqrt((per ** 2).mean()), np.percentile(np.abs(per), 95), np.sqrt((box ** 2).mean()),
            np.percentile(np.abs(box), 99))


def main():
    lmbake, out = sys.argv[1], sys.argv[2]
    work = os.path.join(out, "noise-work")
    os.makedirs(work, exist_ok=True)
    all_scenes = scenes(work)
    wanted = sys.argv[3:] or list(all_scenes)
    rows = []
    for name in wanted:
        ref_dir = os.path.join(work, "%s-reference" % name)
        if not os.path.isdir(ref_dir):
            print("%s: baking the converged reference (minutes)" % name, flush=True)
            bake(lmbake, all_scenes[name], ref_dir + ".tmp", REFERENCE, 7)
            os.rename(ref_dir + ".tmp", ref_dir)
        reference = [os.path.join(ref_dir, f) for f in sorted(os.listdir(ref_dir))
                     if re.search(r"-lightmap-\d+\.exr$", f)]
        for label, config in CASES:
            runs = [bake(lmbake, all_scenes[name], os.path.join(work, "%s-%d-s%d" % (name, CASES.index((label, config)),
                                                                                          seed)), config, seed)
                    for seed in (1, 2)]
            pairs = list(zip(runs[0][1], runs[1][1]))
            rms, p95, rms9, p99_9 = noise(pairs)
            e_rms, e_p95, e_rms9, e_p99_9, bias = error(pairs, reference)
            seconds = 0.5 * (runs[0][0] + runs[1][0])
            rows.append({"scene": name, "case": label, "seconds": round(seconds, 2), "texel_rms": round(100 * rms, 3),
                         "texel_p95": round(100 * p95, 3), "box9_rms": round(100 * rms9, 3),
                         "box9_p99": round(100 * p99_9, 3), "error_rms": round(100 * e_rms, 3),
                         "error_p95": round(100 * e_p95, 3), "error9_rms": round(100 * e_rms9, 3),
                         "error9_p99": round(100 * e_p99_9, 3), "bias": round(100 * bias, 3)})
            print("%-10s %-31s %6.1f s  noise %.2f%% (p95 %.2f%%) 9x9 %.2f%% | error %.2f%% (p95 %.2f%%) 9x9 %.2f%% "
                  "(p99 %.2f%%) bias %+.2f%%" % (name, label, seconds, 100 * rms, 100 * p95, 100 * rms9, 100 * e_rms,
                                                 100 * e_p95, 100 * e_rms9, 100 * e_p99_9, 100 * bias), flush=True)
    with open(os.path.join(out, "noise.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(out, "noise.md"), "w") as f:
        f.write("| scene | sampling | bake (s) | noise per texel | p95 | noise 9x9 | error per texel | p95 | error 9x9 "
                "| bias |\n|---|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            f.write("| %s | %s | %.1f | %.2f%% | %.2f%% | %.2f%% | %.2f%% | %.2f%% | %.2f%% | %+.2f%% |\n" % (
                r["scene"], r["case"], r["seconds"], r["texel_rms"], r["texel_p95"], r["box9_rms"], r["error_rms"],
                r["error_p95"], r["error9_rms"], r["bias"]))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    kinds = (("fixed", "o-", lambda c: c.startswith("fixed")),
             ("adaptive", "s--", lambda c: c.startswith("adaptive 1%")),
             ("defaults (denoiser)", "*", lambda c: "denoiser" in c))
    for ax, key, title in ((axes[0], "texel_rms", "noise per texel"), (axes[1], "box9_rms", "noise, 9 x 9 texels"),
                           (axes[2], "error9_rms", "error against the reference, 9 x 9")):
        for k, name in enumerate(wanted):
            for kind, marker, pick in kinds:
                pts = [(r["seconds"], r[key]) for r in rows if r["scene"] == name and pick(r["case"])]
                if pts:
                    ax.plot(*zip(*sorted(pts)), marker, color="C%d" % k, markersize=10 if "*" in marker else 5,
                            label="%s, %s" % (name, kind))
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("bake time (s)")
        ax.set_ylabel("rms (%)")
        ax.set_title(title, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "noise.png"), dpi=110)
    print("wrote %s/noise.csv, noise.md, noise.png" % out)


if __name__ == "__main__":
    main()
