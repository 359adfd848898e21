#!/usr/bin/env python3
"""`lmbake preview --watch` without a browser (docs/watch.md), through /status and the files:

1. identical   the watch bakes a copy of tools/make_scenes.py's cornell-point.gltf (quick, then
               final); the light's intensity is changed in the file: bake 2 is a change of
               "lights", lighting only; its final files in OUTDIR equal `lmbake bake` of the
               changed level byte for byte, its layout read back (--layout-cache); the quick bake
               never wrote into OUTDIR; no light moved (/status placesKept); then the light
               is moved (a node's translation: "lights" again, placesKept false) and a config sampling key changed
               ("config samples.gather", lighting only), then an atlas key ("layout and lighting":
               laid out again).
2. errors      a half-written level (JSON cut short) and a config with an unknown key: state
               "error", the message names the file (and the key), the last good bake stays shown,
               nothing new in OUTDIR; the next good save bakes. The level removed: "waiting", then
               put back: baked. OUTDIR inside the level's folder: its bakes never trigger another.
3. cancel      a save during a bake stops it (the log says "stopped") and only the newest state is
               baked: no final bake of the stopped generation (the time to the stop is printed).
4. groups      light groups under the watch (docs/light-groups.md): make_scenes.py's sun-lamps.gltf
               with the sun alone in its group and the lamps in another; the sun x 2 in the file:
               both groups read back (/status shown.groups {read 2, lit 0}), the terminal line says
               "relit: sun x 2", no quick look before it (`--relight-only` first), the final
               files those of `lmbake bake` of the changed level byte for byte; a lamp dimmed:
               a quick look then the final, "lit again: lamps", one read back; the sun tinted:
               "sun tinted".

usage: check_watch.py LMBAKE WORKDIR CHECK
"""
import filecmp
import json
import os
import re
import shutil
import subprocess
import sys
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CONFIG = "texel_density: 12\n"


def make_level(work):
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True,
                   stdout=subprocess.DEVNULL)
    level_dir = os.path.join(work, "level")
    shutil.rmtree(level_dir, ignore_errors=True)
    os.makedirs(level_dir)
    level = os.path.join(level_dir, "cornell-point.gltf")
    doc = json.load(open(os.path.join(scenes, "cornell-point.gltf")))
    for b in doc.get("buffers", []):  # external buffers travel with it
        if "uri" in b and not b["uri"].startswith("data:"):
            shutil.copy(os.path.join(scenes, b["uri"]), level_dir)
    save_json(level, doc)
    cfg = os.path.join(level_dir, "bake.yaml")
    save_text(cfg, CONFIG)
    return level, cfg, doc


def save_text(path, text):
    with open(path, "w") as f:
        f.write(text)


def save_json(path, doc):
    save_text(path, json.dumps(doc, indent=1))


class Watch:
    def __init__(self, lmbake, level, cfg, outdir):
        self.p = subprocess.Popen([lmbake, "preview", "--watch", level, "-c", cfg, "-o", outdir], stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, text=True)
        self.lines = []
        line = self.p.stdout.readline()
        m = re.search(r"preview: (http://127\.0\.0\.1:\d+/)", line)
        if not m:
            self.p.kill()
            sys.exit("the watch did not start: " + line + self.p.stdout.read())
        self.url = m.group(1)
        os.set_blocking(self.p.stdout.fileno(), False)

    def log(self):
        try:
            while True:
                line = self.p.stdout.readline()
                if not line:
                    break
                self.lines.append(line.rstrip())
        except (BlockingIOError, TypeError):
            pass
        return self.lines

    def status(self):
        return json.load(urllib.request.urlopen(self.url + "status", timeout=10))

    def wait(self, what, test, timeout=180):
        end = time.time() + timeout
        while time.time() < end:
            s = self.status()
            if test(s):
                return s
            time.sleep(0.1)
        self.stop()
        sys.exit("FAIL: timed out waiting for %s; status %s\nlog:\n%s" % (what, json.dumps(self.status() if self.p.poll() is None else {}),
                                                                       "\n".join(self.log())))

    def shown(self, generation, kind, timeout=180):
        return self.wait("%s bake %d" % (kind, generation), lambda s: s["shown"] and s["shown"]["generation"] == generation
                         and s["shown"]["kind"] == kind, timeout)

    def stop(self):
        if self.p.poll() is None:
            self.p.terminate()
            try:
                self.p.wait(10)
            except subprocess.TimeoutExpired:
                self.p.kill()
        self.log()


def check(ok, message):
    print(("ok: " if ok else "FAIL: ") + message)
    return ok


def same_tree(a, b):
    """[] when every file of a and b is the same bytes, else the differing names."""
    diff = []
    names = sorted(set(os.listdir(a)) | set(os.listdir(b)))
    for n in names:
        pa, pb = os.path.join(a, n), os.path.join(b, n)
        if not (os.path.isfile(pa) and os.path.isfile(pb) and filecmp.cmp(pa, pb, shallow=False)):
            diff.append(n)
    return diff


def identical(lmbake, work):
    level, cfg, doc = make_level(work)
    out = os.path.join(work, "out")
    shutil.rmtree(out, ignore_errors=True)
    w = Watch(lmbake, level, cfg, out)
    ok = True
    try:
        w.shown(1, "quick")
        w.shown(1, "final")
        doc["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] *= 3
        save_json(level, doc)
        s = w.shown(2, "quick")
        ok &= check(s["changed"] == ["lights"] and not s["layout"] and s["placesKept"] is True,
                    "intensity changed: bake 2 is %s, layout %s, no light moved (placesKept %s)"
                    % (s["changed"], s["layout"], s["placesKept"]))
        s = w.shown(2, "final")
        ok &= check(s["shown"].get("layoutKept") is True, "intensity changed: bake 2's final read its layout back (layoutKept "
                    "%s)" % s["shown"].get("layoutKept"))
        plain = os.path.join(work, "plain")
        shutil.rmtree(plain, ignore_errors=True)
        subprocess.run([lmbake, "bake", level, "-c", cfg, "-o", plain, "-q"], check=True)
        diff = same_tree(out, plain)
        ok &= check(not diff, "final files after the watched change equal `lmbake bake` of the changed level, byte for "
                    "byte (%d files)%s" % (len(os.listdir(plain)), ": differ " + ", ".join(diff) if diff else ""))
        light_node = next(n for n in doc["nodes"] if "KHR_lights_punctual" in n.get("extensions", {}))
        light_node["translation"][0] -= 0.2
        save_json(level, doc)
        s = w.shown(3, "final")
        ok &= check(s["changed"] == ["lights"] and not s["layout"] and s["placesKept"] is False,
                    "light moved: bake 3 is %s, layout %s, a light moved (placesKept %s)"
                    % (s["changed"], s["layout"], s["placesKept"]))
        save_text(cfg, CONFIG + "samples: {gather: 128}\n")
        s = w.shown(4, "final")
        ok &= check(s["changed"] == ["config samples.gather"] and not s["layout"], "samples.gather: bake 4 is %s, "
                    "layout %s" % (s["changed"], s["layout"]))
        save_text(cfg, CONFIG + "samples: {gather: 128}\natlas: {padding: 3}\n")
        s = w.shown(5, "final")
        ok &= check(s["changed"] == ["config atlas.padding"] and s["layout"], "atlas.padding: bake 5 is %s, layout %s"
                    % (s["changed"], s["layout"]))
        ok &= check(s["shown"].get("layoutKept") is False, "atlas.padding: bake 5 laid the level out again (layoutKept %s)"
                    % s["shown"].get("layoutKept"))
        lines = [l for l in w.log() if re.match(r"watch: (quick|final) bake \d+ ready in [0-9.]+ s \(", l)]
        ok &= check(len(lines) == 10, "one line per bake ready (%d): %s" % (len(lines), lines[-1] if lines else ""))
    finally:
        w.stop()
    return ok


def errors(lmbake, work):
    level, cfg, doc = make_level(work)
    out = os.path.join(os.path.dirname(level), "out")  # inside the watched folder
    w = Watch(lmbake, level, cfg, out)
    ok = True
    try:
        w.shown(1, "final")
        time.sleep(1.5)
        s = w.status()
        ok &= check(s["generation"] == 1 and s["state"] == "idle", "OUTDIR inside the level's folder: no bake triggers "
                    "another (generation %d, %s)" % (s["generation"], s["state"]))
        before = {n: os.path.getmtime(os.path.join(out, n)) for n in os.listdir(out)}
        text = json.dumps(doc, indent=1)
        save_text(level, text[: len(text) // 2])
        s = w.wait("the error", lambda s: s["state"] == "error")
        ok &= check("cornell-point.gltf" in s["error"] and s["shown"]["generation"] == 1,
                    "half-written level: error %r, bake %d stays shown" % (s["error"][:120], s["shown"]["generation"]))
        doc["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] *= 2
        save_json(level, doc)
        s = w.shown(2, "final")
        ok &= check(s["error"] is None, "the next good save bakes (bake 2) and clears the error")
        save_text(cfg, CONFIG + "samples: {gathr: 64}\n")
        s = w.wait("the config error", lambda s: s["state"] == "error")
        ok &= check("bake.yaml" in s["error"] and "gathr" in s["error"] and s["shown"]["generation"] == 2,
                    "unknown config key: error %r names the file and key; bake 2 stays" % s["error"][:160])
        save_text(cfg, CONFIG)
        w.shown(3, "final")
        os.rename(level, level + ".away")
        s = w.wait("waiting", lambda s: s["state"] == "waiting")
        ok &= check("missing" in s["error"], "level removed: %r" % s["error"])
        os.rename(level + ".away", level)
        s = w.shown(4, "final")
        ok &= check(s["error"] is None and s["state"] == "idle", "level back: bake 4, no error")
        ok &= check(set(os.listdir(out)) >= set(before), "OUTDIR holds the final bake's files")
    finally:
        w.stop()
    return ok


def cancel(lmbake, work):
    level, cfg, doc = make_level(work)
    save_text(cfg, "texel_density: 48\n")  # a bake of a few seconds: long enough to be caught running
    out = os.path.join(work, "out")
    w = Watch(lmbake, level, cfg, out)
    ok = True
    try:
        w.shown(1, "final")
        light = doc["extensions"]["KHR_lights_punctual"]["lights"][0]
        light["intensity"] *= 2
        save_json(level, doc)
        w.wait("bake 2 running", lambda s: s["baking"] and s["baking"]["generation"] == 2)
        time.sleep(0.3)
        light["color"] = [1, 0.8, 0.6]
        save_json(level, doc)
        t = time.time()
        s = w.wait("bake 2 stopped", lambda s: s["cancelled"] >= 1)
        print("note: the save to bake 2's stop took %.2f s (a figure, not a bound: a busy machine is slower)"
              % (time.time() - t))
        s = w.shown(3, "final")
        finals = [h["generation"] for h in s["history"] if h["kind"] == "final"]
        ok &= check(finals == [1, 3], "only the newest state was baked to the end: final bakes %s" % finals)
        ok &= check(any(re.match(r"watch: (quick|correction|final) bake 2 stopped", l) for l in w.log()), "the log says bake 2 "
                    "was stopped")
    finally:
        w.stop()
    return ok


def groups(lmbake, work):
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True,
                   stdout=subprocess.DEVNULL)
    level_dir = os.path.join(work, "level")
    shutil.rmtree(level_dir, ignore_errors=True)
    os.makedirs(level_dir)
    level, cfg = os.path.join(level_dir, "sun-lamps.gltf"), os.path.join(level_dir, "bake.yaml")
    doc = json.load(open(os.path.join(scenes, "sun-lamps.gltf")))
    save_json(level, doc)
    save_text(cfg, "texel_density: 6\noutput:\n  light_groups:\n    - {name: sun, match: sun}\n"
                   "    - {name: lamps, match: \"lamp_*\"}\n")
    lights = doc["extensions"]["KHR_lights_punctual"]["lights"]
    sun = next(l for l in lights if l["name"] == "sun")
    out = os.path.join(work, "out")
    shutil.rmtree(out, ignore_errors=True)
    w = Watch(lmbake, level, cfg, out)
    ok = True

    def line(generation):
        for _ in range(50):
            found = [l for l in w.log() if l.startswith("watch: final bake %d ready" % generation)]
            if found:
                return found[0]
            time.sleep(0.1)
        return ""
    try:
        w.shown(1, "final")
        sun["intensity"] *= 2
        save_json(level, doc)
        s = w.shown(2, "final")
        said = line(2)
        ok &= check(s["shown"].get("groups", {}).get("read") == 2 and s["shown"]["groups"]["lit"] == 0
                    and "relit: sun x 2;" in said and "light groups: 2 read back, none lit" in said,
                    "the sun x 2: both groups read back (%s); %r" % (s["shown"].get("groups", {}).get("relit"), said))
        plain = os.path.join(work, "plain")
        shutil.rmtree(plain, ignore_errors=True)
        subprocess.run([lmbake, "bake", level, "-c", cfg, "-o", plain, "-q"], check=True)
        diff = same_tree(out, plain)
        ok &= check(not diff, "the sun x 2: the final files equal `lmbake bake` of the changed level, byte for byte (%d "
                    "files)%s" % (len(os.listdir(plain)), ": differ " + ", ".join(diff) if diff else ""))
        kinds = [h["kind"] for h in s["history"] if h["generation"] == 2]
        ok &= check(kinds == ["final"], "the sun x 2: relit first (--relight-only), no quick look before it: %s" % kinds)
        next(l for l in lights if l["name"] == "lamp_a")["intensity"] *= 0.5
        save_json(level, doc)
        s = w.shown(3, "final")
        said = line(3)
        kinds = [h["kind"] for h in s["history"] if h["generation"] == 3]
        ok &= check(kinds == ["quick", "final"], "lamp_a dimmed: not a relight (--relight-only exit 4): a quick look, "
                    "then the final: %s" % kinds)
        ok &= check("relit: lit again: lamps;" in said and "light groups: 1 read back, 1 lit" in said,
                    "lamp_a dimmed: its group lit again, the sun's read back: %r" % said)
        sun["color"] = [1.0, 0.8, 0.6]
        save_json(level, doc)
        w.shown(4, "final")
        said = line(4)
        ok &= check("relit: sun tinted;" in said, "the sun tinted: %r" % said)
    finally:
        w.stop()
    return ok


def main():
    lmbake, work, name = sys.argv[1], sys.argv[2], sys.argv[3]
    os.makedirs(work, exist_ok=True)
    ok = {"identical": identical, "errors": errors, "cancel": cancel, "groups": groups}[name](lmbake, work)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
