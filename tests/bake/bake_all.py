#!/usr/bin/env python3
"""`lmbake bake` on every .gltf/.glb under the given folders: each exits 0 (and its output
passes the Khronos validator with 0 errors) or 2 with an "error:" line naming the reason.
A low-resolution config keeps it quick (few probe rays too: a lamp's 4,000 probes took most of
the run); quality is tested elsewhere.

usage: bake_all.py LMBAKE WORKDIR VALIDATOR_JS|none DIR...   (none: the sanitizer pass: no validator,
       whose node process checks nothing the sanitizers see, and one bake per scene folder: its other
       encodings (.gltf / .glb / embedded) of the same level are loaded by 'lmbake inspect', the part
       of a bake where they differ; one level is one file name in one scene folder)
"""
import glob
import os
import subprocess
import sys

CONFIG = "texel_density: 4\natlas: {max_size: 2048}\nbounces: 2\nsamples: {texel: 1, direct: 2, gather: 16, bounce: 8, max_rays: 256}\nprobes: {rays: 32}\n"


def main():
    lmbake, work, validator, dirs = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
    os.makedirs(work, exist_ok=True)
    cfg = os.path.join(work, "low.yaml")
    with open(cfg, "w") as f:
        f.write(CONFIG)
    bad, n, baked = [], 0, 0
    seen = set()
    for d in dirs:
        for path in sorted(glob.glob(os.path.join(d, "**", "*.gl*"), recursive=True)):
            if not path.endswith((".gltf", ".glb")):
                continue
            n += 1
            out = os.path.join(work, "out-%d" % n)
            rel = os.path.relpath(path, d)
            # one level: the same file name in one scene folder (khr-Box/glTF/Box.gltf, khr-Box/glTF-Binary/Box.glb)
            level = (d, rel.split(os.sep)[0], os.path.splitext(os.path.basename(rel))[0])
            if validator == "none" and level in seen:
                p = subprocess.run([lmbake, "inspect", path, "-c", cfg], capture_output=True, text=True, timeout=900)
                status = "loaded (inspect; the scene's other encoding was baked)"
                if p.returncode == 2 and "error:" in p.stderr:
                    status = "rejected (inspect): " + p.stderr.strip().splitlines()[-1][:160]
                elif p.returncode != 0:
                    status = "inspect exit %d" % p.returncode
                    bad.append("%s: inspect exit %d\n%s" % (rel, p.returncode, p.stderr[-2000:]))
                print("%-70s %s" % (rel, status))
                continue
            seen.add(level)
            p = subprocess.run([lmbake, "bake", path, "-c", cfg, "-o", out, "-q"], capture_output=True, text=True,
                               timeout=900)
            if p.returncode == 0 and validator == "none":
                status = "ok (not validated)"
                baked += 1
            elif p.returncode == 0:
                gl = [f for f in os.listdir(out) if f.endswith(".gltf")]
                v = subprocess.run(["node", validator, os.path.join(out, gl[0])], capture_output=True, text=True)
                status = "ok, validator: " + v.stdout.splitlines()[0].split(": ", 1)[1] if v.stdout else "no report"
                if v.returncode != 0:
                    bad.append("%s: output fails the validator:\n%s" % (rel, v.stdout[:2000]))
                baked += 1
            elif p.returncode == 2 and "error:" in p.stderr:
                status = "rejected: " + p.stderr.strip().splitlines()[-1][:160]
                if os.path.exists(out):
                    bad.append("%s: exit 2 but %s exists" % (rel, out))
            else:
                status = "exit %d" % p.returncode
                bad.append("%s: exit %d\n%s" % (rel, p.returncode, p.stderr[-2000:]))
            print("%-70s %s" % (rel, status))
    print("%d files, %d baked, %d problems" % (n, baked, len(bad)))
    for b in bad:
        print("FAIL", b)
    return 1 if bad or n < 30 else 0


if __name__ == "__main__":
    sys.exit(main())
