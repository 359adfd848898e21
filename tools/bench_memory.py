"""Peak RSS of a small and a large bake of the same scene, and bytes per texel between them.

usage: bench_memory.py LMBAKE OUTDIR TEXELS
Bakes assets/scenes/cornell-box-bevy/CornellBox.glb with `atlas.texels: 2000` (the base: the
libraries, the scene, the ray tracer) and with `atlas.texels: TEXELS`, both `bounces: 1`, under
/usr/bin/time -v; the bake's own log gives the texels it listed. Writes OUTDIR/memory.csv.
"""
import csv
import os
import re
import subprocess
import sys
import tempfile

SCENE = "assets/scenes/cornell-box-bevy/CornellBox.glb"


def bake(lmbake, texels, work):
    cfg = os.path.join(work, f"m{texels}.yaml")
    with open(cfg, "w") as f:
        f.write(f"atlas: {{texels: {texels}}}\nbounces: 1\n")
    out = os.path.join(work, f"out{texels}")
    r = subprocess.run(["/usr/bin/time", "-v", lmbake, "bake", SCENE, "-c", cfg, "-o", out],
                       capture_output=True, text=True)
    if r.returncode:
        sys.exit(f"bake at {texels} texels failed:\n{r.stderr[-2000:]}")
    log = r.stdout + r.stderr
    rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", log).group(1))
    listed = int(re.search(r"1 atlas\(es\), (\d+) texels", log).group(1))
    secs = float(re.search(r"bake: ([\d.]+) s", log).group(1))
    return rss_kb * 1024, listed, secs


def main():
    lmbake, outdir, texels = sys.argv[1], sys.argv[2], int(sys.argv[3])
    with tempfile.TemporaryDirectory() as work:
        base = bake(lmbake, 2000, work)
        big = bake(lmbake, texels, work)
    per_texel = (big[0] - base[0]) / (big[1] - base[1])
    path = os.path.join(outdir, "memory.csv")
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["budget", "texels", "peak_rss_mb", "bake_s"])
        for budget, (rss, listed, secs) in ((2000, base), (texels, big)):
            w.writerow([budget, listed, round(rss / 2**20, 1), secs])
        w.writerow(["bytes_per_texel_above_base", round(per_texel, 1), "", ""])
    print(f"base: {base[1]} texels, {base[0] / 2**20:.0f} MiB; {big[1]} texels: {big[0] / 2**20:.0f} MiB; "
          f"{per_texel:.1f} bytes per texel above the base ({path})")


if __name__ == "__main__":
    main()
