#!/usr/bin/env python3
"""File sizes per output format (docs/output.md): bevy's Cornell box and the generated
level-single-10 (58k triangles, 10 x 10 rooms), each baked at the defaults with every format,
then once per further KTX2 variant. Sizes only, no timings: it may share the machine.

usage: bench_output_sizes.py LMBAKE OUTDIR    (writes OUTDIR/output-sizes.csv and .md)
"""
import csv
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

FILES = [("EXR (half float, zip)", ".exr"), ("Radiance .hdr", ".hdr"), ("PNG preview", ".png"),
         ("RGBM PNG", "-rgbm.png")]
KTX2 = [("KTX2 E5B9G9R9 + zstd", "ktx2_format: e5b9g9r9, ktx2_supercompression: zstd"),
        ("KTX2 E5B9G9R9, no supercompression", "ktx2_format: e5b9g9r9, ktx2_supercompression: none"),
        ("KTX2 B10G11R11 + zstd", "ktx2_format: b10g11r11, ktx2_supercompression: zstd"),
        ("KTX2 RGBA16F + zstd", "ktx2_format: rgba16f, ktx2_supercompression: zstd")]


def bake(lmbake, work, scene, name, output):
    out = os.path.join(work, name)
    shutil.rmtree(out, ignore_errors=True)
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write("output: {formats: [exr, hdr, png, ktx2, rgbm], directional: false, %s}\n" % output)
    subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out, "-q"], check=True)
    return out


def sizes(out, suffix):
    """Total bytes of the atlases' files ending in suffix (every atlas), and the atlas count."""
    names = [f for f in os.listdir(out) if f.endswith(suffix) and "-lightmap-" in f
             and (suffix != ".png" or not f.endswith(("-rgbm.png", "-dir.png", "-mask.png")))]
    return sum(os.path.getsize(os.path.join(out, f)) for f in names), len(names)


def main():
    lmbake, outdir = sys.argv[1:3]
    work = os.path.join(outdir, "sizes-work")
    os.makedirs(work, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(HERE, "make_levels.py"), work, "single:10"], check=True,
                   stdout=subprocess.DEVNULL)
    scenes = [("bevy Cornell box", os.path.join(ROOT, "assets", "scenes", "cornell-box-bevy", "CornellBox.glb")),
              ("level-single-10", os.path.join(work, "level-single-10.glb"))]
    rows = []
    for label, scene in scenes:
        key = os.path.basename(scene).split(".")[0]
        first = None
        for k, (name, output) in enumerate(KTX2):
            out = bake(lmbake, work, scene, "%s-%d" % (key, k), output)
            if first is None:
                first = out
                for fname, suffix in FILES:
                    b, n = sizes(out, suffix)
                    rows.append((label, fname, b, n))
            b, n = sizes(out, ".ktx2")
            rows.append((label, name, b, n))
        print("%s: %d atlas(es)" % (label, rows[-1][3]))
    with open(os.path.join(outdir, "output-sizes.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "file", "bytes", "atlases"])
        w.writerows(rows)
    with open(os.path.join(outdir, "output-sizes.md"), "w") as f:
        f.write("| file | %s |\n|---|---|---|\n" % " | ".join(s[0] for s in scenes))
        for fname in [x[0] for x in FILES] + [x[0] for x in KTX2]:
            vals = ["{:,}".format(r[2]) for s in scenes for r in rows if r[0] == s[0] and r[1] == fname]
            f.write("| %s | %s |\n" % (fname, " | ".join(vals)))
    print(open(os.path.join(outdir, "output-sizes.md")).read())


if __name__ == "__main__":
    main()
