#!/usr/bin/env python3
"""KTX2 lightmap formats against each other (docs/output.md#block-compressed-lightmaps-bc6h-and-astc):
bevy's Cornell box, the generated level-single-10 (58k triangles, 10 x 10 rooms, 11 lights) and a
sunlit outdoor level (level-gpu-100: 100 copies of a 4,000-triangle prop on a ground, a sun), each
baked at the defaults once per KTX2 format. Per format and scene:
  bytes per texel on the GPU (the level's size / texels) and on disk (the .ktx2 file, Zstandard);
  encode seconds (the bake's log: the block encoder's time; the packed formats' is negligible)
  and the bake's own seconds, and their ratio;
  mean and p99 relative error per chart texel and on 9 x 9 averages against the same bake's EXR
  (tools/ktx2_blocks.py; the block formats decoded by OpenImageIO's and astcenc's decoders, the
  packed ones by tests/ktx2/read_ktx2.mjs);
  the luminance jump across seams at each sample, as tests/bake/check_artists.py measures it, over
  edges between triangles that turn by less than 20 degrees (seams across one smooth surface),
  at samples whose two sides read a chart's texels (not faces nothing sees, which have none),
  on the decoded lightmap and on the EXR: the largest growth over the EXR's is what the
  compression adds (the largest jump itself can be the light's own: a shadow edge on a seam).
LMB_BENCH_REUSE=1 measures an earlier run's bakes again (their times kept in bench-times.json).
Writes OUTDIR/compression.csv, compression.md and compression.png (error against bytes).

usage: bench_compression.py LMBAKE OUTDIR
"""
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import time

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "bake"))
import ktx2_blocks as kb  # noqa: E402
import check_analytic as ca  # noqa: E402
import check_artists  # noqa: E402

# (name, output.ktx2_format, GPU bytes per texel of the level)
FORMATS = [("E5B9G9R9", "e5b9g9r9", 4), ("B10G11R11", "b10g11r11", 4), ("RGBA16F", "rgba16f", 8),
           ("BC6H", "bc6h", 1), ("ASTC 4x4 HDR", "astc_hdr", 1)]


def bake(lmbake, work, scene, name, fmt):
    out = os.path.join(work, name)
    times = os.path.join(out, "bench-times.json")
    if os.environ.get("LMB_BENCH_REUSE") == "1" and os.path.exists(times):  # measure an earlier run's bakes again
        t = json.load(open(times))
        return out, t["bake_s"], t["encode_s"]
    shutil.rmtree(out, ignore_errors=True)
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write("output: {formats: [exr, ktx2, mask], ktx2_format: %s, ktx2_supercompression: zstd}\n" % fmt)
    t0 = time.time()
    p = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out], capture_output=True, text=True)
    seconds = time.time() - t0
    if p.returncode != 0:
        sys.exit("%s: bake failed: %s" % (name, p.stderr[-2000:]))
    encode = sum(float(m) for m in re.findall(r"blocks of \d+x\d+ texels encoded in ([0-9.]+)s", p.stderr + p.stdout))
    with open(times, "w") as f:
        json.dump({"bake_s": seconds, "encode_s": encode}, f)
    return out, seconds, encode


def reads_chart(mask, u, v):
    """Whether a bilinear lookup at (u, v) reads a texel a chart covers (mask: valid or inside
    geometry). A face nothing can see (skipped: atlas.skip_hidden) has no texels of its own: its
    lookups read padding, which no one sees."""
    h, w = mask.shape
    x, y = int(np.floor(u * w - 0.5)), int(np.floor(v * h - 0.5))
    return bool(mask[np.clip([y, y, y + 1, y + 1], 0, h - 1), np.clip([x, x + 1, x, x + 1], 0, w - 1)].any())


def smooth_seam_jumps(charts, images, masks=None, max_degrees=20.0, points=8):
    """The relative luminance jump at every sample across seams, as tests/bake/check_artists.py measures
    it (bilinear lookups at 8 points along every edge two triangles share with different lightmap
    UVs), over the edges whose two triangles turn by less than max_degrees: seams across one
    smooth surface, not the corners where a wall meets the floor (a real edge of the light). With
    masks (per texture, chart texels), samples where a side reads no chart texel are left out."""
    def normal(t):
        a, b, c = (np.array(p) for p in t)
        n = np.cross(b - a, c - a)
        return n / (np.linalg.norm(n) or 1.0)
    edges = {}
    for node, tex, tris in charts:
        for wt, ut in tris:
            n = normal(wt)
            for k in range(3):
                a, b = (wt[k], ut[k]), (wt[(k + 1) % 3], ut[(k + 1) % 3])
                ka, kb_ = tuple(round(c, 5) for c in a[0]), tuple(round(c, 5) for c in b[0])
                if kb_ < ka:
                    a, b, ka, kb_ = b, a, kb_, ka
                edges.setdefault((ka, kb_), []).append((tex, a[1], b[1], n))
    jumps = []
    cos = np.cos(np.radians(max_degrees))
    for sides in edges.values():
        if len(sides) != 2:
            continue
        (ta, a0, a1, na), (tb, b0, b1, nb) = sides
        if float(np.dot(na, nb)) < cos:
            continue
        if ta == tb and max(abs(a0[i] - b0[i]) + abs(a1[i] - b1[i]) for i in range(2)) < 1e-6:
            continue  # one chart
        for k in range(points):
            t = (k + 0.5) / points
            ua, va = a0[0] + t * (a1[0] - a0[0]), a0[1] + t * (a1[1] - a0[1])
            ub, vb = b0[0] + t * (b1[0] - b0[0]), b0[1] + t * (b1[1] - b0[1])
            if masks is not None and not (reads_chart(masks[ta], ua, va) and reads_chart(masks[tb], ub, vb)):
                continue
            la = check_artists.lum(check_artists.bilinear(images[ta], ua, va))
            lb = check_artists.lum(check_artists.bilinear(images[tb], ub, vb))
            jumps.append(abs(la - lb) / (0.5 * (la + lb)) if la + lb > 0 else 0.0)
    return np.array(jumps)


def measure(out, work):
    """Per atlas decoded, errors pooled over atlases, seam jumps."""
    doc = json.load(open(os.path.join(out, [f for f in os.listdir(out) if f.endswith(".gltf")][0])))
    charts, exrs = ca.load_output(out)
    decoded, charted, refs, gpu, disk, texels = {}, {}, [], 0, 0, 0
    for ti in exrs:
        stem = os.path.join(out, doc["images"][doc["textures"][ti]["source"]]["uri"][:-4])
        info, got = kb.decode(stem + ".ktx2", work)
        decoded[ti] = got
        ref = np.asarray(exrs[ti], dtype=np.float64)[..., :3]
        states = np.asarray(oiio.ImageBuf(stem + "-mask.png").get_pixels(oiio.FLOAT))[..., 0]
        mask = states > 0.99
        charted[ti] = states > 0.25  # valid or inside geometry
        refs.append((ref, got, mask))
        gpu += sum(lv["uncompressed"] for lv in info["levels"])
        disk += os.path.getsize(stem + ".ktx2")
        texels += ref.shape[0] * ref.shape[1]
    per = [kb.errors(r, g, m) for r, g, m in refs]
    n = sum(p[4] for p in per)
    n9 = sum(p[5] for p in per)
    mean = sum(p[0] * p[4] for p in per) / n
    mean9 = sum(p[2] * p[5] for p in per) / max(n9, 1)
    p99 = max(p[1] for p in per)
    p99_9 = max(p[3] for p in per)
    jumps = smooth_seam_jumps(charts, decoded, charted)
    jumps_exr = smooth_seam_jumps(charts, exrs, charted)
    jump = float(jumps.max()) if jumps.size else 0.0
    jump_exr = float(jumps_exr.max()) if jumps_exr.size else 0.0
    # what the compression adds: the largest growth of a sample's jump over the EXR's
    jump_added = float((jumps - jumps_exr).max()) if jumps.size else 0.0
    return dict(gpu_bpt=gpu / texels, disk_bpt=disk / texels, mean=mean, p99=p99, mean9=mean9, p99_9=p99_9,
                jump=jump, jump_exr=jump_exr, jump_added=jump_added, seam_samples=int(jumps.size), texels=texels,
                atlases=len(exrs))


def main():
    lmbake, outdir = sys.argv[1:3]
    work = os.path.join(outdir, "compression-work")
    os.makedirs(work, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(HERE, "make_levels.py"), work, "single:10", "gpu:100"], check=True,
                   stdout=subprocess.DEVNULL)
    scenes = [("bevy Cornell box", os.path.join(ROOT, "assets", "scenes", "cornell-box-bevy", "CornellBox.glb")),
              ("level-single-10", os.path.join(work, "level-single-10.glb")),
              ("sunlit outdoor (level-gpu-100)", os.path.join(work, "level-gpu-100.glb"))]
    rows = []
    for label, scene in scenes:
        key = os.path.basename(scene).split(".")[0]
        for name, fmt, _ in FORMATS:
            out, seconds, encode = bake(lmbake, work, scene, "%s-%s" % (key, fmt), fmt)
            m = measure(out, work)
            row = dict(scene=label, format=name, bake_s=seconds, encode_s=encode, encode_share=encode / seconds, **m)
            rows.append(row)
            print("%-32s %-13s %5.2f B/texel GPU %5.2f disk; encode %.2fs of %.1fs (%.1f%%); error mean %.3f%% p99 "
                  "%.2f%%, 9x9 mean %.4f%% p99 %.3f%%; seam jump %.3f%% (EXR %.3f%%), added at most %.3f%% over %d "
                  "samples" % (label, name, m["gpu_bpt"], m["disk_bpt"], encode, seconds, 100 * encode / seconds,
                     100 * m["mean"], 100 * m["p99"], 100 * m["mean9"], 100 * m["p99_9"], 100 * m["jump"],
                     100 * m["jump_exr"], 100 * m["jump_added"], m["seam_samples"]), flush=True)
    keys = list(rows[0].keys())
    with open(os.path.join(outdir, "compression.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(outdir, "compression.md"), "w") as f:
        f.write("| scene | format | GPU B/texel | disk B/texel | encode s | bake s | encode / bake | mean error | "
                "p99 | 9x9 mean | 9x9 p99 | seam jump added (samples) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            f.write("| %s | %s | %.2f | %.2f | %.2f | %.1f | %.1f%% | %.3f%% | %.2f%% | %.4f%% | %.3f%% | %.3f%% (%d) |\n"
                    % (r["scene"], r["format"], r["gpu_bpt"], r["disk_bpt"], r["encode_s"], r["bake_s"],
                       100 * r["encode_share"], 100 * r["mean"], 100 * r["p99"], 100 * r["mean9"], 100 * r["p99_9"],
                       100 * r["jump_added"], r["seam_samples"]))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for label, _ in scenes:
        rs = [r for r in rows if r["scene"] == label]
        ax.plot([r["gpu_bpt"] for r in rs], [100 * r["mean"] for r in rs], "o", label=label)
        for r in rs:
            ax.annotate(r["format"], (r["gpu_bpt"], 100 * r["mean"]), fontsize=7, xytext=(4, 2),
                        textcoords="offset points")
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("bytes per texel on the GPU (level 0)")
    ax.set_ylabel("mean relative error per texel against the EXR (%)")
    ax.axhline(2.0, color="grey", lw=0.8, ls="--")
    ax.legend(fontsize=8)
    ax.set_title("KTX2 lightmap formats: error against size")
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "compression.png"), dpi=120)
    print(open(os.path.join(outdir, "compression.md")).read())


if __name__ == "__main__":
    main()
