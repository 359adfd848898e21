#!/usr/bin/env python3
"""`lmbake unwrap` on every .gltf/.glb under the given folders (degenerate and non-manifold
scenes included): every atlas reports 0 overlapping texels, or the file is rejected with
exit 2 and an error line. Prints each file's atlases for the record.

usage: check_unwrap_all.py LMBAKE DIR...
"""
import glob
import os
import re
import subprocess
import sys

ATLAS = re.compile(r"^atlas (\d+): (\d+)x(\d+), (\d+) charts, coverage ([\d.]+), L2 stretch ([\d.]+).*overlapping texels (\d+)")


def main():
    lmbake, dirs = sys.argv[1], sys.argv[2:]
    bad, n, atlases = [], 0, 0
    cfg = os.path.join(os.environ.get("TMPDIR", "/tmp"), "lmbake-unwrap-all-%d.yaml" % os.getpid())
    with open(cfg, "w") as f:
        f.write("texel_density: 8\natlas: {max_size: 2048}\n")
    for d in dirs:
        for path in sorted(glob.glob(os.path.join(d, "**", "*.gl*"), recursive=True)):
            if not path.endswith((".gltf", ".glb")):
                continue
            n += 1
            p = subprocess.run([lmbake, "unwrap", path, "-c", cfg, "-q"], capture_output=True, text=True, timeout=900)
            rel = os.path.relpath(path, d)
            if p.returncode == 2 and "error:" in p.stderr:
                print("%-60s rejected: %s" % (rel, p.stderr.strip().splitlines()[-1][:120]))
                continue
            if p.returncode != 0:
                bad.append("%s: exit %d %s" % (rel, p.returncode, p.stderr[-1500:]))
                continue
            for line in p.stdout.splitlines():
                m = ATLAS.match(line)
                if m:
                    atlases += 1
                    print("%-60s %s" % (rel, line))
                    if int(m.group(7)) != 0:
                        bad.append("%s: %s" % (rel, line))
    os.remove(cfg)
    print("%d files, %d atlases, %d problems" % (n, atlases, len(bad)))
    for b in bad:
        print("FAIL", b)
    return 1 if bad or atlases < 20 else 0


if __name__ == "__main__":
    sys.exit(main())
