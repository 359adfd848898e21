#!/usr/bin/env python3
"""`lmbake bake --layout-cache DIR` (docs/watch.md#what-is-redone), on tools/make_scenes.py's
cornell-point.gltf at a small density:

1. the first bake builds the layout and keeps it in DIR ("layout: built ... kept");
2. a lighting-only change (the lamp 3x brighter in the file, and a config sampling key) reads it
   back ("layout: read back") with the gather points' validity the first bake tested (none of
   their rays traced again: fewer rays) and the probes it placed, and the files equal a plain `lmbake bake` of the
   changed level and config, byte for byte;
3. a layout change (a mesh node moved; then atlas.padding) builds it again;
4. damaged cache files (the layout, the validity) are said in a warning, the layout is built and
   the points tested again, and the files are still those of a plain bake;
5. --direct-of (the watch's correction of a changed light) reads the layout back and its
   lightmaps equal a plain bake's with no bounces, byte for byte; a name no light has gives black lightmaps, said;
   on `lmbake plan` it is a usage error;
6. --layout-cache with --plan is a usage error.

usage: check_layout_cache.py LMBAKE WORKDIR
"""
import filecmp
import json
import os
import re
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CONFIG = "texel_density: 8\nsamples: {gather: 64, bounce: 16, direct: 4}\n"


def run(args):
    r = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return r.returncode, r.stdout + r.stderr


def check(ok, message):
    print(("ok: " if ok else "FAIL: ") + message)
    return ok


def rays(log):
    m = re.search(r"\d+ texels \(\d+ valid\), (\d+) rays", log)
    return int(m.group(1)) if m else -1


def differing(a, b):
    names = sorted(os.listdir(b))
    if sorted(os.listdir(a)) != names:
        return ["(file lists)"]
    return [n for n in names if not filecmp.cmp(os.path.join(a, n), os.path.join(b, n), shallow=False)]


def main():
    lmbake, work = sys.argv[1], sys.argv[2]
    shutil.rmtree(work, ignore_errors=True)
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True,
                   stdout=subprocess.DEVNULL)
    level = os.path.join(scenes, "cornell-point.gltf")
    doc = json.load(open(level))
    cfg = os.path.join(work, "bake.yaml")
    cache = os.path.join(work, "layouts")

    def bake(name, config_text, *extra):
        with open(cfg, "w") as f:
            f.write(config_text)
        return run([lmbake, "bake", level, "-c", cfg, "-o", os.path.join(work, name), *extra])

    ok = True
    code, log = bake("first", CONFIG, "--layout-cache", cache)
    ok &= check(code == 0 and "layout: built" in log and "kept in" in log,
                "first bake: layout built and kept (exit %d)" % code)
    kept = [f for f in os.listdir(cache) if f.endswith(".lmbp")] if os.path.isdir(cache) else []
    ok &= check(len(kept) == 1, "one layout file in the cache: %s" % kept)
    memo = [f for f in os.listdir(cache) if f.endswith("-seed1.lmbv")] if os.path.isdir(cache) else []
    ok &= check(len(memo) == 1 and memo[0].startswith(kept[0][:-5] if kept else "?"),
                "the gather points' validity kept beside it: %s" % memo)
    rays_first = rays(log)

    doc["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] *= 3
    json.dump(doc, open(level, "w"), indent=1)
    lighting = CONFIG.replace("gather: 64", "gather: 48")
    code, log = bake("cached", lighting, "--layout-cache", cache)
    ok &= check(code == 0 and "layout: read back" in log, "lamp x 3 and samples.gather: layout read back (exit %d)"
                % code)
    m = re.search(r"gather points: the validity of (\d+) read back", log)
    ok &= check(m is not None and int(m.group(1)) > 1000 and rays(log) < rays_first,
                "and the gather points' validity: %s points, %s rays against %s in the first bake"
                % (m.group(1) if m else None, rays(log), rays_first))
    m = re.search(r"probes: (\d+) read back with the layout", log)
    probe_files = [f for f in os.listdir(cache) if f.endswith("-probes.lmbq")]
    ok &= check(m is not None and int(m.group(1)) > 8 and "auto grid" not in log and len(probe_files) == 1 and
                probe_files[0].startswith(kept[0][:-5] if kept else "?"),
                "and the probes' placement and tetrahedra, kept beside it (%s): %s probes" %
                (probe_files, m.group(1) if m else None))
    code, _ = bake("plain", lighting)
    diff = differing(os.path.join(work, "cached"), os.path.join(work, "plain"))
    ok &= check(code == 0 and not diff, "files from the layout read back equal a plain bake's, byte for byte%s"
                % (": differ " + ", ".join(diff) if diff else ""))

    mesh_node = next(n for n in doc["nodes"] if "mesh" in n)
    mesh_node["translation"] = [t + d for t, d in zip(mesh_node.get("translation", [0, 0, 0]), [0.1, 0, 0])]
    json.dump(doc, open(level, "w"), indent=1)
    code, log = bake("moved", lighting, "--layout-cache", cache)
    ok &= check(code == 0 and "layout: built" in log, "a mesh node moved: layout built again (exit %d)" % code)
    code, log = bake("padded", lighting + "atlas: {padding: 3}\n", "--layout-cache", cache)
    ok &= check(code == 0 and "layout: built" in log, "atlas.padding: layout built again (exit %d)" % code)

    for f in os.listdir(cache):  # damage every kept layout: the bake builds it and says so
        path = os.path.join(cache, f)
        data = bytearray(open(path, "rb").read())
        data[len(data) // 2] ^= 0xFF
        open(path, "wb").write(data)
    code, log = bake("damaged", lighting, "--layout-cache", cache)
    ok &= check(code == 0 and "layout cache:" in log and "layout: built" in log and "is damaged" in log and
                "validity of" not in log and "read back with the layout" not in log,
                "damaged cache files: warned, layout built, points tested and probes placed again (exit %d)" % code)
    code, _ = bake("plain2", lighting)
    diff = differing(os.path.join(work, "damaged"), os.path.join(work, "plain2"))
    ok &= check(not diff, "and the files equal a plain bake's%s" % (": differ " + ", ".join(diff) if diff else ""))

    # --direct-of (the watch's correction of a changed light): the named light's direct light
    # alone, in the layout kept: the files of a plain bake with no bounces, byte for byte
    code, log = bake("direct-of", lighting, "--layout-cache", cache, "--direct-of", "ceiling_*")
    ok &= check(code == 0 and "layout: read back" in log, "--direct-of reads the layout back (exit %d)" % code)
    code, _ = bake("direct-plain", lighting + "bounces: 0\nseams: {stitch: false}\noutput: {formats: [hdr], directional: false}\n")
    # its lightmaps (it places no probes: the watch reads only those)
    lightmaps = [n for n in sorted(os.listdir(os.path.join(work, "direct-plain"))) if n.endswith((".hdr", ".png"))]
    diff = [n for n in lightmaps if not filecmp.cmp(os.path.join(work, "direct-of", n),
                                                    os.path.join(work, "direct-plain", n), shallow=False)]
    ok &= check(code == 0 and lightmaps and not diff, "--direct-of 'ceiling_*': its lightmaps %s equal a plain bake's "
                "with bounces: 0, byte for byte%s" % (lightmaps, ": differ " + ", ".join(diff) if diff else ""))
    code, log = bake("direct-none", lighting, "--direct-of", "no such light")
    ok &= check(code == 0 and "nothing emits light" in log, "--direct-of a name no light has: black lightmaps, said "
                "(exit %d)" % code)
    code, log = run([lmbake, "plan", level, "--direct-of", "x", "-o", os.path.join(work, "x")])
    ok &= check(code == 1 and "--direct-of" in log, "--direct-of with plan: usage error (exit %d)" % code)

    code, log = run([lmbake, "bake", level, "--plan", "x.lmbp", "--layout-cache", cache, "-o", os.path.join(work, "x")])
    ok &= check(code == 1 and "--layout-cache" in log, "--plan with --layout-cache: usage error (exit %d)" % code)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
