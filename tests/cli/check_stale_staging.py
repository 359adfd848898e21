#!/usr/bin/env python3
"""Stale staging folders (issues 10, 15): a bake killed with SIGKILL leaves its staging folder
.out.lmbake-staging-HOST-PID beside the output folder `out` and never touches `out`; the next
bake into that folder removes it (its process is gone) with a warning that names it, as well as
an older-style staging folder inside `out`, keeps staging folders whose process still runs or
that belong to another host, and writes its own outputs next to the files already there.

usage: check_stale_staging.py LMBAKE SCENE WORKDIR
"""
import os
import shutil
import signal
import socket
import subprocess
import sys
import time


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def staging_dirs(folder, prefix):
    return sorted(d for d in os.listdir(folder) if d.startswith(prefix))


def main():
    lmbake, scene, work = sys.argv[1:4]
    shutil.rmtree(work, ignore_errors=True)
    out = os.path.join(os.path.realpath(os.path.dirname(work)), os.path.basename(work), "out")
    os.makedirs(out)
    work = os.path.dirname(out)
    sibling = ".out.lmbake-staging-"
    # an earlier, complete bake's output: it must survive the killed bake byte for byte
    marker = os.path.join(out, "earlier-output.txt")
    with open(marker, "w") as f:
        f.write("an earlier bake\n")
    host = socket.gethostname().replace("-", "_").replace("/", "_")
    cfg = os.path.join(work, "small.yaml")  # a few seconds of baking: time to kill it, quick to redo
    with open(cfg, "w") as f:
        f.write("atlas: {texels: 60000}\nbounces: 2\nsamples: {gather: 64, bounce: 16}\n")

    # 1. a bake killed mid-way leaves its staging folder beside `out`, and `out` as it was
    proc = subprocess.Popen([lmbake, "bake", scene, "-c", cfg, "-o", out, "--threads", "1"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    mine = sibling + "%s-%d" % (host, proc.pid)
    for _ in range(600):  # until its staging folder exists (the bake has started)
        if os.path.isdir(os.path.join(work, mine)) or proc.poll() is not None:
            break
        time.sleep(0.01)
    time.sleep(0.3)
    if proc.poll() is not None:
        fail("the bake finished before it could be killed; use a slower scene")
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    left = staging_dirs(work, sibling)
    if left != [mine]:
        fail("after kill -9 expected exactly %s, found %s" % (mine, left))
    if sorted(os.listdir(out)) != ["earlier-output.txt"]:
        fail("the killed bake wrote outside its staging folder: %s" % os.listdir(out))
    if open(marker).read() != "an earlier bake\n":
        fail("the earlier output changed")

    # 2. a staging folder of a process that still runs (this script) is not touched
    alive = sibling + "%s-%d" % (host, os.getpid())
    os.makedirs(os.path.join(work, alive))
    # and one of another host is not ours to judge
    other = sibling + "otherhost-1"
    os.makedirs(os.path.join(work, other))
    # an older-style staging folder inside `out`, of a process that is gone, goes too
    inside = ".lmbake-staging-%s-%d" % (host, proc.pid)
    os.makedirs(os.path.join(out, inside))

    # 3. the next bake removes the stale one, says so, and completes
    r = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out, "--threads", "2"], capture_output=True, text=True,
                       timeout=600)
    if r.returncode != 0:
        fail("second bake exit %d: %s" % (r.returncode, r.stderr[-500:]))
    for gone in (os.path.join(work, mine), os.path.join(out, inside)):
        want = "removed '%s', left by a bake that was stopped (process %d is gone)" % (gone, proc.pid)
        if want not in r.stderr:
            fail("no warning %r in stderr:\n%s" % (want, r.stderr[-1500:]))
    left = staging_dirs(work, sibling)
    if left != sorted([alive, other]):
        fail("expected only the live and the other host's staging folders, found %s" % left)
    if staging_dirs(out, ".lmbake-staging-"):
        fail("the stale staging folder inside out was kept: %s" % os.listdir(out))
    stem = os.path.splitext(os.path.basename(scene))[0]
    for name in (stem + ".gltf", stem + "-lightmap-0.exr", "earlier-output.txt"):
        if not os.path.isfile(os.path.join(out, name)):
            fail("missing %s after the second bake" % name)
    print("ok: killed bake left %s only (out untouched); the next bake removed it and %s with warnings, kept %s "
          "and %s" % (mine, inside, alive, other))


if __name__ == "__main__":
    main()
