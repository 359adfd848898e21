#!/usr/bin/env python3
"""Hostile URIs (issue 15): file access stays inside the input's folder, and the output folder
holds only what the bake writes.

usage: check_hostile_uris.py LMBAKE WORKDIR

A textured plane (external .bin buffer, external .png image) is written into WORKDIR/in/,
with files beside the folder (WORKDIR/outside.png, outside.bin) and a symbolic link inside it
pointing out. Each case rewrites the image's or the buffer's uri and bakes under strace:
  - an image uri that leaves the folder (.., an absolute path, file:, http:, %-escaped ..,
    a link out, a shell-looking name with '/' in it): exit 0, a warning naming the image and
    the uri, the texture skipped;
  - a buffer uri that does: exit 2, an error naming the buffer and the uri, no output folder;
  - every case: strace shows none of the files the URIs aim at opened (outside.png,
    outside.bin, /etc/passwd, /etc/hostname) nor any other file of WORKDIR outside the input
    and output folders, and the output folder holds no directory (a URI never makes one).
"""
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import make_scenes  # noqa: E402

IMAGE_CASES = [
    ("../outside.png", "leaves the input's folder through '..'"),
    ("../../../../etc/passwd", "leaves the input's folder through '..'"),
    ("sub/../../outside.png", "leaves the input's folder through '..'"),
    ("%2e%2e/outside.png", "leaves the input's folder through '..'"),
    ("/etc/hostname", "is an absolute path"),
    ("file:///etc/passwd", "uses a URI scheme"),
    ("http://example.com/a.png", "uses a URI scheme"),
    ("link-out.png", "is not a file inside the input's folder"),
    ("$(touch a/b).png", "is not a file inside the input's folder"),
]
BUFFER_CASES = [
    ("../outside.bin", "leaves the input's folder through '..'"),
    ("/etc/passwd", "is an absolute path"),
    ("http://example.com/a.bin", "uses a URI scheme"),
    ("file:///etc/passwd", "uses a URI scheme"),
    ("link-out.bin", "is not a file inside the input's folder"),
]
TARGETS = ("/etc/passwd", "/etc/hostname")  # besides WORKDIR/outside.*


def png(path):
    raw = b"".join(b"\0" + bytes([200, 120, 40]) * 2 for _ in range(2))
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def scene(work):
    """WORKDIR/in/plane.gltf with plane.bin and tex.png beside it; returns the JSON doc."""
    s = make_scenes.Scene()
    mat = s.material("textured", (1, 1, 1))
    s.doc["materials"][mat]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    s.doc["images"] = [{"uri": "tex.png"}]
    s.doc["textures"] = [{"source": 0}]
    s.mesh("plane", make_scenes.plane(2), mat, uv=True)
    s.light("lamp", "point", 10.0, translation=(0, 1, 0))
    indir = os.path.join(work, "in")
    os.makedirs(indir, exist_ok=True)
    with open(os.path.join(indir, "plane.bin"), "wb") as f:
        f.write(bytes(s.blob))
    s.doc["buffers"] = [{"byteLength": len(s.blob), "uri": "plane.bin"}]
    png(os.path.join(indir, "tex.png"))
    png(os.path.join(work, "outside.png"))
    shutil.copy(os.path.join(indir, "plane.bin"), os.path.join(work, "outside.bin"))
    for name, target in (("link-out.png", "../outside.png"), ("link-out.bin", "../outside.bin")):
        if not os.path.lexists(os.path.join(indir, name)):
            os.symlink(target, os.path.join(indir, name))
    return s.doc


def opened_outside(trace, cwd, work, indir, out):
    """Paths strace saw opened (successfully or not) that the bake must not touch: what the
    hostile URIs aim at, and anything of WORKDIR outside the input, output and config folders
    and the bake's own staging folder beside the output (.OUT.lmbake-staging-HOST-PID)."""
    staging = os.path.join(os.path.dirname(out), "." + os.path.basename(out) + ".lmbake-staging-")
    bad = []
    for line in open(trace, errors="replace"):
        m = re.search(r'open(?:at)?\((?:AT_FDCWD, )?"([^"]*)"', line)
        if not m:
            continue
        p = os.path.normpath(os.path.join(cwd, m.group(1)))
        real = os.path.realpath(p)
        inside = any(x == d or x.startswith(d + "/") for x in (p, real) for d in (indir, out, work + "/config"))
        inside = inside or any(x.startswith(staging) for x in (p, real))
        if real in TARGETS or p in TARGETS or ((p.startswith(work + "/") or real.startswith(work + "/")) and not inside):
            bad.append(p)
    return sorted(set(bad))


def run(lmbake, work, doc, label, what, uri, exit_code, message):
    indir = os.path.realpath(os.path.join(work, "in"))
    d = json.loads(json.dumps(doc))
    d["images" if what == "image" else "buffers"][0]["uri"] = uri
    gltf = os.path.join(indir, "plane.gltf")
    with open(gltf, "w") as f:
        json.dump(d, f)
    out = os.path.realpath(os.path.join(work, "out-" + label))
    shutil.rmtree(out, ignore_errors=True)
    trace = os.path.join(work, "trace-%s.txt" % label)
    os.makedirs(os.path.join(work, "config"), exist_ok=True)
    cfg = os.path.join(work, "config", "small.yaml")  # read on purpose: the command line names it
    with open(cfg, "w") as f:
        f.write("texel_density: 8\n")
    cmd = ["strace", "-f", "-qq", "-e", "trace=open,openat", "-o", trace, lmbake, "bake", gltf, "-c", cfg, "-o", out,
           "--threads", "2"]
    # LeakSanitizer cannot run under ptrace (the sanitizer build aborts at exit): leaks are
    # checked by every other test of that build, not this one
    env = dict(os.environ)
    env["ASAN_OPTIONS"] = (env.get("ASAN_OPTIONS", "") + ":detect_leaks=0").lstrip(":")
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=indir, env=env)
    ok = p.returncode == exit_code
    named = "%s 0" % what
    ok &= named in p.stderr and uri in p.stderr and message in p.stderr
    dirs = [os.path.join(r, x) for r, ds, _ in os.walk(out) for x in ds] if os.path.isdir(out) else []
    ok &= not dirs and (exit_code == 0 or not os.path.exists(out))
    bad = opened_outside(trace, indir, os.path.realpath(work), indir, out)
    ok &= not bad
    print("%s %s uri %-28r exit %d (want %d); %s; directories in the output: %s; opened outside: %s" % (
        "PASS" if ok else "FAIL", what, uri, p.returncode, exit_code,
        "message names it" if named in p.stderr and message in p.stderr else "MESSAGE: " + p.stderr.strip()[:300],
        dirs or "none", bad or "none"))
    return ok


def main():
    lmbake, work = os.path.realpath(sys.argv[1]), os.path.realpath(sys.argv[2])
    if not shutil.which("strace"):
        sys.exit("strace is missing: tools/setup.sh installs it")
    os.makedirs(work, exist_ok=True)
    doc = scene(work)
    ok = True
    for k, (uri, msg) in enumerate(IMAGE_CASES):
        ok &= run(lmbake, work, doc, "image%d" % k, "image", uri, 0, msg)
    for k, (uri, msg) in enumerate(BUFFER_CASES):
        ok &= run(lmbake, work, doc, "buffer%d" % k, "buffer", uri, 2, msg)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
