#!/usr/bin/env python3
"""Relighting a level with light groups (docs/light-groups.md#what-an-edit-costs), side by side in
one run: each edit baked with the watch's --layout-cache (what `lmbake preview --watch` runs for its
final bake) after a first bake kept the groups, then the same edited level baked without the cache
(what the files must equal, byte for byte), each under /usr/bin/time -v.

usage: bench_relight.py LMBAKE OUTDIR [LEVEL ...]   (writes OUTDIR/relight.csv and OUTDIR/relight.png;
       LEVEL: a stem of the levels below, e.g. sun-lamps, to run only those: OUTDIR/relight-sun-lamps.csv)

level-single-10 (11 lights) in three groups: the sun, Lamp 0 alone, the other ten lamps. Edits
(each of the first bake's level, not one after the other): Lamp 0 x 2, Lamp 0 tinted, Lamp 0
off, the sun x 0.5 (each alone in its group: a new weight), the lamps' group scale x 0.5 (the
config), Lamp 0 moved 2 m (its group lit again). bevy's Cornell box with its emissive ceiling in a
group: the group's scale x 3, and the ceiling's emissive strength x 3 and its colour tinted in the
glTF (alone in their group: a new weight). tools/make_scenes.py's sun-lamps (a ground and a cube
under a sky of 400 lux, a sun and two lamps; 30 texels per unit) with the sky alone in its group: sky.intensity x 0.5,
and that sky tinted (the config; each a new weight). Then each level under `lmbake preview --watch` (no browser): every
edit saved over the watched file (the level, or the config for a config edit) in turn, each timed
from the save to the final files on the watch's /status, its lightmaps compared with the fresh
bake of that edit. About 25 minutes on 2 cores.
"""
import csv
import filecmp
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(lmbake, level, cfg_text, out, work, name, *extra):
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(cfg_text)
    shutil.rmtree(out, ignore_errors=True)
    r = subprocess.run(["/usr/bin/time", "-v", lmbake, "bake", level, "-c", cfg, "-o", out] + list(extra),
                       capture_output=True, text=True)
    if r.returncode:
        sys.exit("%s: %s failed:\n%s" % (level, name, r.stderr[-2000:]))
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (?:(\d+):)?(\d+):([\d.]+)", r.stderr)
    secs = int(wall.group(1) or 0) * 3600 + int(wall.group(2)) * 60 + float(wall.group(3))
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", r.stderr).group(1)) / 1024.0
    return secs, rss, r.stdout + r.stderr


def read_gltf(path):
    """(json document, binary chunk or None)."""
    data = open(path, "rb").read()
    if data[:4] != b"glTF":
        return json.loads(data), None
    n = struct.unpack("<I", data[12:16])[0]
    doc = json.loads(data[20:20 + n])
    rest = data[20 + n:]
    return doc, rest[8:8 + struct.unpack("<I", rest[:4])[0]] if rest else None


def write_glb(path, doc, binary):
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<I4s", len(text), b"JSON") + text
    if binary is not None:
        binary += b"\0" * (-len(binary) % 4)
        chunks += struct.pack("<I4s", len(binary), b"BIN\0") + binary
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks)


def config(groups, base=""):
    """The config: base's keys, then output.light_groups."""
    lines = ["output:", "  light_groups:"] + ["    - {%s}" % g for g in groups]
    return base + "\n".join(lines) + "\n"


def edited_config(groups, base, change):
    """The config after an edit: change None (the glTF's edit), a group's line in place of the
    group of that name, or {"base": text} in place of the base keys."""
    if isinstance(change, dict):
        return config(groups, change["base"])
    return config([change if change and g.split(",")[0] == change.split(",")[0] else g for g in groups], base)


def light_index(doc, name):
    return next(i for i, l in enumerate(doc["extensions"]["KHR_lights_punctual"]["lights"]) if l["name"] == name)


def light_node(doc, name):
    k = light_index(doc, name)
    return next(n for n in doc["nodes"] if n.get("extensions", {}).get("KHR_lights_punctual", {}).get("light") == k)


def scale_light(name, k):
    def edit(doc):
        doc["extensions"]["KHR_lights_punctual"]["lights"][light_index(doc, name)]["intensity"] *= k
    return edit


def tint_light(name, color):
    def edit(doc):
        doc["extensions"]["KHR_lights_punctual"]["lights"][light_index(doc, name)]["color"] = color
    return edit


def move_light(name, d):
    def edit(doc):
        n = light_node(doc, name)
        n["translation"] = [t + dt for t, dt in zip(n.get("translation", [0, 0, 0]), d)]
    return edit


def emissive_tint(color):
    def edit(doc):
        for m in doc.get("materials", []):
            if any(m.get("emissiveFactor", [0, 0, 0])):
                m["emissiveFactor"] = color
    return edit


def emissive_x(k):
    def edit(doc):
        for m in doc.get("materials", []):
            if any(m.get("emissiveFactor", [0, 0, 0])):
                ext = m.setdefault("extensions", {}).setdefault("KHR_materials_emissive_strength", {})
                ext["emissiveStrength"] = ext.get("emissiveStrength", 1.0) * k
    return edit


def same_images(a, b, prefix_a, prefix_b):
    """Whether every image file of bake b is in a (named with a's level) with the same bytes."""
    images = [f for f in os.listdir(b) if f.endswith((".exr", ".hdr", ".png", ".ktx2"))]
    return bool(images) and all(
        filecmp.cmp(os.path.join(a, prefix_a + f[len(prefix_b):]), os.path.join(b, f), shallow=False)
        if os.path.exists(os.path.join(a, prefix_a + f[len(prefix_b):])) else False for f in images)


def watch_edits(lmbake, level, doc, binary, cfg_text, work, edits, fresh_dirs):
    """`lmbake preview --watch` of a copy of level; each edit (what, the glTF's edit or None, the
    config's text after it) of the first level and config saved over them in turn; rows of seconds
    from the save to the final bake on /status."""
    wdir = os.path.join(work, "watch-" + os.path.splitext(os.path.basename(level))[0])
    os.makedirs(wdir, exist_ok=True)
    name = os.path.splitext(os.path.basename(level))[0]
    ext = os.path.splitext(level)[1]  # .gltf: one with its buffers embedded (make_scenes.py's)
    watched, cfg, out = os.path.join(wdir, name + ext), os.path.join(wdir, "level.yaml"), os.path.join(wdir, "out")
    shutil.copy(level, watched)
    with open(cfg, "w") as f:
        f.write(cfg_text)
    p = subprocess.Popen([lmbake, "preview", "--watch", watched, "-c", cfg, "-o", out], stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True)
    rows = []
    try:
        m = re.search(r"preview: (http://127\.0\.0\.1:\d+/)", p.stdout.readline())
        if not m:
            sys.exit("the watch did not start")
        url = m.group(1)

        def final(generation, timeout=600):
            end = time.time() + timeout
            while time.time() < end:
                s = json.load(urllib.request.urlopen(url + "status", timeout=10))
                if s.get("error"):
                    sys.exit("the watch failed: %s" % s["error"])
                if s["shown"] and s["shown"]["generation"] == generation and s["shown"]["kind"] == "final":
                    return s
                time.sleep(0.05)
            sys.exit("the watch's final bake %d did not come" % generation)
        final(1)
        glb_now, cfg_now = None, cfg_text
        for k, (what, edit, cfg_after) in enumerate(edits):
            d = json.loads(json.dumps(doc))
            if edit:
                edit(d)
            glb_after = json.dumps(d)
            time.sleep(1.5)  # the file's time stamp moves on
            saved = time.time()
            if glb_after != glb_now:  # the level saved (the first edit always: the watched copy is the level's file)
                if ext == ".gltf":
                    with open(watched + ".tmp", "w") as f:
                        json.dump(d, f)
                else:
                    write_glb(watched + ".tmp", d, binary)
                os.replace(watched + ".tmp", watched)
            if cfg_after != cfg_now:
                with open(cfg + ".tmp", "w") as f:
                    f.write(cfg_after)
                os.replace(cfg + ".tmp", cfg)
            glb_now, cfg_now = glb_after, cfg_after
            s = final(k + 2)
            secs = s["shown"]["readyAt"] / 1000.0 - saved
            same = same_images(out, fresh_dirs[what][0], name, fresh_dirs[what][1])
            groups = s["shown"].get("groups") or {}
            rows.append({"level": name, "edit": what, "run": "watch", "seconds": "%.2f" % secs, "peak_mb": "",
                         "groups_lit": groups.get("lit", ""), "groups_read_back": groups.get("read", ""),
                         "identical": "yes" if same else "NO"})
            print("%s under the watch, %s: final files %.2f s after the save (%s), lightmaps identical to the "
                  "fresh bake: %s" % (name, what, secs, groups, same), flush=True)
    finally:
        p.terminate()
        try:
            p.wait(10)
        except subprocess.TimeoutExpired:
            p.kill()
    return rows


LEVELS = [  # (level, its groups, its edits (what, the glTF's edit, the config's), the config's other keys)
    ("bench/levels/level-single-10.glb",
     ["name: sun, match: Sun", 'name: lamp0, match: "Lamp 0"', 'name: lamps, match: "Lamp *"'],
     [("Lamp 0 x 2", scale_light("Lamp 0", 2.0), None),
      ("Lamp 0 tinted", tint_light("Lamp 0", [1.0, 0.6, 0.3]), None),
      ("Lamp 0 off", scale_light("Lamp 0", 0.0), None),
      ("sun x 0.5", scale_light("Sun", 0.5), None),
      ("lamps' group scale x 0.5", None, 'name: lamps, match: "Lamp *", scale: 0.5'),
      ("Lamp 0 moved 2 m", move_light("Lamp 0", [2.0, 0.0, 0.0]), None)]),
    ("assets/scenes/cornell-box-bevy/CornellBox.glb", ["name: ceiling, emissive: true"],
     [("ceiling's group scale x 3", None, "name: ceiling, emissive: true, scale: 3"),
      ("emissive strength x 3", emissive_x(3.0), None),
      ("emissive colour tinted", emissive_tint([1.0, 0.7, 0.4]), None)]),
    ("sun-lamps", ["name: sky, sky: true", 'name: lights, match: "*"'],
     [("sky.intensity x 0.5", None, {"base": "texel_density: 30\nsky: {intensity: 200}\n"}),
      ("sky tinted", None, {"base": "texel_density: 30\nsky: {intensity: 200, color: [1.0, 0.8, 0.6]}\n"})],
     "texel_density: 30\nsky: {intensity: 400}\n"),
]


def main():
    lmbake, outdir, only = sys.argv[1], sys.argv[2], sys.argv[3:]
    os.makedirs(outdir, exist_ok=True)
    stem = "relight" + "".join("-" + o for o in only)
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for level, groups, edits, *rest in LEVELS:
            if only and os.path.splitext(os.path.basename(level))[0] not in only:
                continue
            base = rest[0] if rest else ""
            if level == "sun-lamps":
                subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), os.path.join(work, "scenes")],
                               check=True, stdout=subprocess.DEVNULL)
                level = os.path.join(work, "scenes", "sun-lamps.gltf")
            level = os.path.join(ROOT, level)
            if not os.path.exists(level):
                print("skipping %s: missing (tools/make_levels.py bench/levels single:10 makes it)" % level)
                continue
            name = os.path.splitext(os.path.basename(level))[0]
            cache = os.path.join(work, name + "-cache")
            doc, binary = read_gltf(level)
            fresh_dirs = {}
            first = run(lmbake, level, config(groups, base), os.path.join(work, "first"), work, name + "-first",
                        "--layout-cache", cache, "-q")
            rows.append({"level": name, "edit": "first bake, groups kept", "run": "kept", "seconds": "%.2f" % first[0],
                         "peak_mb": "%.0f" % first[1], "groups_lit": len(groups), "groups_read_back": 0,
                         "identical": ""})
            print("%s: first bake with %d groups kept: %.1f s" % (name, len(groups), first[0]), flush=True)
            for k, (what, edit, group) in enumerate(edits):
                edited = level
                if edit:
                    d = json.loads(json.dumps(doc))
                    edit(d)
                    edited = os.path.join(work, "%s-edit%d.glb" % (name, k))
                    write_glb(edited, d, binary)
                cfg = edited_config(groups, base, group)
                relit = run(lmbake, edited, cfg, os.path.join(work, "relit"), work, "%s-relit%d" % (name, k),
                            "--layout-cache", cache)
                fresh = run(lmbake, edited, cfg, os.path.join(work, "fresh"), work, "%s-fresh%d" % (name, k), "-q")
                a, b = os.path.join(work, "relit"), os.path.join(work, "fresh")
                same = sorted(os.listdir(a)) == sorted(os.listdir(b)) and all(
                    filecmp.cmp(os.path.join(a, f), os.path.join(b, f), shallow=False) for f in os.listdir(b))
                lit, read = relit[2].count("): lighting"), relit[2].count("read back from the cache")
                for run_name, r in (("relit", relit), ("fresh", fresh)):
                    rows.append({"level": name, "edit": what, "run": run_name, "seconds": "%.2f" % r[0],
                                 "peak_mb": "%.0f" % r[1], "groups_lit": lit if run_name == "relit" else len(groups),
                                 "groups_read_back": read if run_name == "relit" else 0,
                                 "identical": ("yes" if same else "NO") if run_name == "relit" else ""})
                print("%s, %s: relit %.2f s (%d group(s) lit, %d read back), fresh bake %.1f s, identical: %s" %
                      (name, what, relit[0], lit, read, fresh[0], same), flush=True)
                kept = os.path.join(work, "fresh-%s-%d" % (name, k))
                shutil.copytree(b, kept)
                fresh_dirs[what] = (kept, "%s-edit%d" % (name, k) if edit else name)
            watched = [(w, e, edited_config(groups, base, g)) for w, e, g in edits]
            rows += watch_edits(lmbake, level, doc, binary, config(groups, base), work, watched, fresh_dirs)
    with open(os.path.join(outdir, stem + ".csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("bench_relight: no matplotlib: no plot")
        return 0
    edits = [(r["level"], r["edit"]) for r in rows if r["run"] == "relit"]
    fig, ax = plt.subplots(figsize=(9, 4))
    labels = {"relit": "read back with --layout-cache", "watch": "preview --watch: save to final files",
              "fresh": "bake without the cache"}
    for k, run_name in enumerate(("relit", "watch", "fresh")):
        ys = [float(next((r["seconds"] for r in rows if (r["level"], r["edit"]) == e and r["run"] == run_name), 0))
              for e in edits]
        ax.barh([i + 0.28 * k for i in range(len(edits))], ys, height=0.28, label=labels[run_name])
    ax.set_yticks([i + 0.28 for i in range(len(edits))])
    short = {"level-single-10": "single-10", "CornellBox": "Cornell", "sun-lamps": "sun-lamps"}
    ax.set_yticklabels(["%s: %s" % (short.get(l, l), e) for l, e in edits], fontsize=8)
    ax.set_xscale("log")
    ax.set_xlabel("seconds after the edit to the final files (2 cores, log scale)")
    ax.set_title("relighting a level with light groups")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, stem + ".png"), dpi=100)
    print("bench_relight: wrote %s/%s.csv and %s.png" % (outdir, stem, stem))
    return 0


if __name__ == "__main__":
    sys.exit(main())
