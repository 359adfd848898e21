#!/usr/bin/env python3
"""The output folder and the output glTF hold what a user expects, and nothing else.

usage: check_output_tidy.py LMBAKE SCENES_DIR WORKDIR

- `-o a/b/out` where a/b does not exist: the bake makes the missing parents (as mkdir -p) and
  writes there.
- `-o file/x/out` where `file` is a regular file: exit 2, the error names the output folder and
  the file in the way; nothing is created.
- a bad input with `-o new/deep/out`: exit 2, and the parents the bake made are gone again.
- Khronos SimpleMeshes (one mesh drawn by two nodes): each node gets its lightmapped copy and
  the original mesh, now unused, is dropped with its accessors and buffer views: every mesh is
  drawn by a node, every accessor read by a mesh, every buffer view read by an accessor or an
  image, and the counts are what the copies need (2 meshes).
"""
import json
import os
import shutil
import subprocess
import sys


def run(lmbake, *args, cwd=None):
    return subprocess.run([lmbake] + list(args), capture_output=True, text=True, cwd=cwd, timeout=600)


def main():
    lmbake, scenes, work = os.path.abspath(sys.argv[1]), sys.argv[2], sys.argv[3]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    scene = os.path.abspath(os.path.join(scenes, "khr-SimpleMeshes", "glTF", "SimpleMeshes.gltf"))
    failures = []

    p = run(lmbake, "bake", scene, "-o", "a/b/out", "-q", cwd=work)
    if p.returncode != 0 or not os.path.isfile(os.path.join(work, "a", "b", "out", "SimpleMeshes.gltf")):
        failures.append("missing parents: exit %d, %s" % (p.returncode, p.stderr.strip()))
    else:
        print("ok: -o a/b/out made a/b and wrote a/b/out/SimpleMeshes.gltf")

    with open(os.path.join(work, "file"), "w") as f:
        f.write("not a folder\n")
    p = run(lmbake, "bake", scene, "-o", "file/x/out", "-q", cwd=work)
    want = "cannot create output folder 'file/x/out': 'file' exists and is not a folder"
    if p.returncode != 2 or want not in p.stderr or os.path.exists(os.path.join(work, "file", "x")):
        failures.append("file in the way: exit %d, stderr %r (wanted exit 2 and %r)" % (p.returncode, p.stderr, want))
    else:
        print("ok: a file in the way is named: " + p.stderr.strip().splitlines()[-1])

    bad = os.path.join(work, "bad.gltf")
    with open(bad, "w") as f:
        f.write('{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 7}}]}],'
                ' "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]}')
    p = run(lmbake, "bake", bad, "-o", "new/deep/out", "-q", cwd=work)
    if p.returncode != 2 or os.path.exists(os.path.join(work, "new")):
        failures.append("bad input: exit %d, new/ %s" % (p.returncode, "left behind" if os.path.exists(
            os.path.join(work, "new")) else "gone"))
    else:
        print("ok: a refused bake leaves no folder it made (exit 2: %s)" % p.stderr.strip().splitlines()[-1][:100])

    out = os.path.join(work, "a", "b", "out")
    doc = json.load(open(os.path.join(out, "SimpleMeshes.gltf")))
    drawn = {n["mesh"] for n in doc["nodes"] if "mesh" in n}
    read = set()
    for m in doc["meshes"]:
        for prim in m["primitives"]:
            read |= set(prim["attributes"].values())
            if "indices" in prim:
                read.add(prim["indices"])
            for t in prim.get("targets", []):
                read |= set(t.values())
    views = {a["bufferView"] for a in doc["accessors"] if "bufferView" in a}
    views |= {i["bufferView"] for i in doc.get("images", []) if "bufferView" in i}
    # the light probes (docs/probes.md) are read through asset.extras.lightmap.probes
    probes = doc["asset"].get("extras", {}).get("lightmap", {}).get("probes")
    if probes:
        read.add(probes["positions"])
        if "tetrahedra" in probes:
            read.add(probes["tetrahedra"])
        views |= {probes["sh"], probes["ambientCube"]}
    problems = []
    if drawn != set(range(len(doc["meshes"]))):
        problems.append("meshes no node draws: %s" % sorted(set(range(len(doc["meshes"]))) - drawn))
    if read != set(range(len(doc["accessors"]))):
        problems.append("accessors no mesh reads: %s" % sorted(set(range(len(doc["accessors"]))) - read))
    if views != set(range(len(doc["bufferViews"]))):
        problems.append("buffer views nothing reads: %s" % sorted(set(range(len(doc["bufferViews"]))) - views))
    if len(doc["meshes"]) != 2:
        problems.append("%d meshes, expected 2 (one lightmapped copy per node)" % len(doc["meshes"]))
    if problems:
        failures.append("SimpleMeshes output: " + "; ".join(problems))
    else:
        print("ok: SimpleMeshes output: %d meshes, %d accessors, %d buffer views, all in use"
              % (len(doc["meshes"]), len(doc["accessors"]), len(doc["bufferViews"])))

    for f in failures:
        print("FAIL: " + f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
