#!/usr/bin/env python3
"""Killed at any moment, nothing lost (issue 15): kill -9 at random times during a bake into a
folder that holds an earlier bake leaves either the earlier bake or the new one, complete.

Reference runs first: bake A (seed 1, no directional lightmaps) into an empty folder, then bake
B (seed 2, directional lightmaps: more files, other contents) over a copy of it; a user's own file
sits in the folder throughout. Then KILLS times: copy A's folder, start bake B into it, SIGKILL
it after a random delay (uniform over 0 .. 1.15 x B's time, fixed random seed), and compare every
file in the folder (names, sizes, SHA-256) with A's and with B's: it must equal one of them
exactly, never a mix, never a truncated file, and hold no staging folder. The next bake (or the
end of the test) removes what a killed bake left beside the folder.

A kill at a random moment rarely lands while the outputs move into place (milliseconds of a
bake), so half the kills run the bake under strace with every link, rename and unlink delayed
by 0.1 s and strike inside that commit window: after the staged glTF appears (the last file a
bake writes), at moments spread evenly over the span the traced reference run took from there
to its last call. Moving files in one by one, as lmbake did before, fails there.

usage: check_kill_safety.py LMBAKE SCENE WORKDIR [KILLS]
"""
import hashlib
import os
import random
import shutil
import signal
import subprocess
import sys
import time


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def snapshot(folder):
    """{relative path: (size, sha256)} of every file under folder; folders as entries too."""
    files = {}
    for root, dirs, names in os.walk(folder):
        for d in dirs:
            files[os.path.relpath(os.path.join(root, d), folder) + "/"] = ("dir", "")
        for n in names:
            p = os.path.join(root, n)
            with open(p, "rb") as f:
                data = f.read()
            files[os.path.relpath(p, folder)] = (len(data), hashlib.sha256(data).hexdigest())
    return files


def bake(lmbake, scene, cfg, out):
    t = time.monotonic()
    r = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out], capture_output=True, text=True, timeout=900)
    if r.returncode != 0:
        fail("bake into %s: exit %d: %s" % (out, r.returncode, r.stderr[-800:]))
    return time.monotonic() - t


DELAYED = "rename,renameat,renameat2,link,linkat,unlink,unlinkat,rmdir"


def traced(cmd, log=None):
    """cmd under strace, each call in DELAYED held for 0.1 s before it runs."""
    return ["strace", "-f", "-qq", "-ttt", "-o", log or os.devnull, "-e", "trace=" + DELAYED,
            "-e", "inject=%s:delay_enter=100000" % DELAYED] + cmd


def commit_span(log):
    """Seconds from the last staged image's rename (the glTF is written next) to the last call
    on a staging folder in a traced run: the window in which the outputs move into place."""
    staged, last = None, None
    with open(log) as f:
        for line in f:
            parts = line.split(None, 2)
            if len(parts) == 3 and ".lmbake-staging-" in parts[2]:
                last = float(parts[1])
                if ".part." in parts[2]:
                    staged = last
    if staged is None:
        fail("the traced reference run staged no image")
    return last - staged


def staged_gltf_appears(work, stem, proc, limit):
    """Waits until a staging folder beside the output holds the glTF and returns the pid in
    that folder's name (the bake's, not strace's); None if the bake ended first."""
    end = time.monotonic() + limit
    while time.monotonic() < end and proc.poll() is None:
        for d in os.listdir(work):
            if ".lmbake-staging-" in d and os.path.exists(os.path.join(work, d, stem + ".gltf")):
                return int(d.rsplit("-", 1)[1])
        time.sleep(0.005)
    return None


def describe(got, ref):
    diff = sorted(k for k in set(got) | set(ref) if got.get(k) != ref.get(k))
    return ", ".join(diff[:6]) + (" ..." if len(diff) > 6 else "")


def main():
    lmbake, scene, work = sys.argv[1:4]
    kills = int(sys.argv[4]) if len(sys.argv) > 4 else 20
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    # the texels are few: what is checked is how files move into place, not the light
    base = "atlas: {texels: 10000}\nbounces: 2\nsamples: {gather: 64, bounce: 16, adaptive: false}\n"
    cfg_a, cfg_b = os.path.join(work, "a.yaml"), os.path.join(work, "b.yaml")
    with open(cfg_a, "w") as f:
        f.write(base + "seed: 1\noutput: {directional: false}\n")
    with open(cfg_b, "w") as f:
        f.write(base + "seed: 2\noutput: {directional: true}\n")

    ref_a, ref_b = os.path.join(work, "ref-a"), os.path.join(work, "ref-b")
    os.makedirs(ref_a)
    with open(os.path.join(ref_a, "my-notes.txt"), "w") as f:  # a user's file: kept by every bake
        f.write("not lmbake's\n")
    bake(lmbake, scene, cfg_a, ref_a)
    shutil.copytree(ref_a, ref_b, symlinks=True)
    seconds = bake(lmbake, scene, cfg_b, ref_b)
    old, new = snapshot(ref_a), snapshot(ref_b)
    if old == new:
        fail("bakes A and B wrote the same files: the test could not tell them apart")
    print("reference: A %d files, B %d files (%d differ), B takes %.2f s" %
          (len(old), len(new), len([k for k in set(old) | set(new) if old.get(k) != new.get(k)]), seconds))

    # the commit window of a traced bake
    out = os.path.join(work, "out")
    shutil.copytree(ref_a, out, symlinks=True)
    log = os.path.join(work, "trace.log")
    r = subprocess.run(traced([lmbake, "bake", scene, "-c", cfg_b, "-o", out], log), capture_output=True, timeout=900)
    if r.returncode != 0 or snapshot(out) != new:
        fail("the traced reference bake failed or differs from B (exit %d)" % r.returncode)
    span = commit_span(log)
    stem = os.path.splitext(os.path.basename(scene))[0]
    print("traced bake: the outputs move into place over %.2f s after the glTF is staged" % span)

    rng = random.Random(15)
    outcomes = {"earlier": 0, "new": 0}
    for trial in range(kills):
        shutil.rmtree(out, ignore_errors=True)
        shutil.copytree(ref_a, out, symlinks=True)
        for d in os.listdir(work):  # a killed bake's leftovers (their removal is tested at the end)
            if ".lmbake-staging-" in d:
                shutil.rmtree(os.path.join(work, d))
        at_commit = trial >= kills // 2
        cmd = [lmbake, "bake", scene, "-c", cfg_b, "-o", out]
        if at_commit:
            k, n = trial - kills // 2, kills - kills // 2
            delay = span * (k + 0.5) / n
            cmd = traced(cmd)
        else:
            delay = rng.uniform(0, 1.15 * seconds)
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        victim = proc.pid
        if at_commit:
            victim = staged_gltf_appears(work, stem, proc, 20 * seconds + 60)
            if victim is None:
                fail("kill %d: the traced bake ended before its glTF was staged" % (trial + 1))
        try:
            proc.wait(timeout=delay)
        except subprocess.TimeoutExpired:
            try:
                os.kill(victim, signal.SIGKILL)
            except ProcessLookupError:
                pass
            proc.wait()
        got = snapshot(out)
        if got == old:
            state = "earlier"
        elif got == new:
            state = "new"
        else:
            fail("kill %d after %.2f s: the folder holds neither bake; differs from the earlier in %s; from the new "
                 "in %s" % (trial + 1, delay, describe(got, old), describe(got, new)))
        outcomes[state] += 1
        finished = proc.returncode == 0
        print("kill %2d at %5.2f s%s (%s): %s bake, complete" %
              (trial + 1, delay, " after the glTF was staged (traced)" if at_commit else "",
               "had finished" if finished else "killed", state))

    # what killed bakes left beside the folder goes with the next bake, which completes
    bake(lmbake, scene, cfg_b, out)
    if snapshot(out) != new:
        fail("the bake after the kills differs from bake B: %s" % describe(snapshot(out), new))
    left = [d for d in os.listdir(work) if ".lmbake-staging-" in d]
    if left:
        fail("staging folders left after a completed bake: %s" % left)
    print("ok: %d kills: %d left the earlier bake, %d the new one, each complete (%d files compared by SHA-256); "
          "never a mix" % (kills, outcomes["earlier"], outcomes["new"], len(new)))


if __name__ == "__main__":
    main()
