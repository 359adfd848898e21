#!/usr/bin/env python3
"""Robustness smoke test: truncated and byte-mutated copies of real glTF files never crash
lmbake. Every run must exit 0 (still loadable) or 2 (bad input, with an "error:" line),
never 3 or a signal, and print no sanitizer report (the ASan build runs this too).

usage: mutation_smoke.py LMBAKE SCENES_DIR WORKDIR [PER_SOURCE]   (mutants per source file, default 40)
"""
import os
import random
import subprocess
import sys

SOURCES = [
    "khr-Box/glTF-Binary/Box.glb",
    "khr-SimpleSparseAccessor/glTF-Embedded/SimpleSparseAccessor.gltf",
    "khr-MeshPrimitiveModes/glTF-Embedded/MeshPrimitiveModes.gltf",
    "cornell-box-bevy/CornellBox.glb",
]


def main():
    lmbake, scenes, work = sys.argv[1:4]
    per_source = int(sys.argv[4]) if len(sys.argv) > 4 else 40
    os.makedirs(work, exist_ok=True)
    rng = random.Random(20261122)  # fixed: the same files every run
    failures, runs = [], 0
    for rel in SOURCES:
        data = open(os.path.join(scenes, rel), "rb").read()
        ext = os.path.splitext(rel)[1]
        for i in range(per_source):
            d = bytearray(data)
            if i < per_source // 3:
                d = d[: rng.randrange(len(d))]
            else:
                for _ in range(rng.randint(1, 8)):
                    d[rng.randrange(len(d))] = rng.choice(b'0123456789-.eE"{}[],:ab\x00\xff')
            path = os.path.join(work, f"mutant-{runs}{ext}")
            open(path, "wb").write(d)
            p = subprocess.run([lmbake, "inspect", "-q", path], capture_output=True, text=True, errors="replace")
            runs += 1
            bad = p.returncode not in (0, 2) or "Sanitizer" in p.stderr or "runtime error" in p.stderr
            if p.returncode == 2 and "error:" not in p.stderr:
                bad = True
            if bad:
                failures.append(f"{path} (from {rel}): exit {p.returncode}\n{p.stderr[-1500:]}")
            else:
                os.remove(path)
    print(f"{runs} mutated files, {len(failures)} failures")
    for f in failures:
        print("FAIL", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
