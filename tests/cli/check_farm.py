#!/usr/bin/env python3
"""The farm (issue 13; docs/farm.md).

1. Identity: `lmbake farm parallel` in 4 shards (GNU parallel runs 2 workers of 1 thread)
   writes the same files as `lmbake bake` (2 threads), byte for byte: EXR, .hdr, PNG, glTF,
   buffers, records. Configs: the irradiance cache on with AMIS (guided, the default method)
   and directional maps; the cache off (per-texel gathers; guided AMIS shards by atlas); and
   the default farm.min_step_rays (cheap steps computed in every process).
2. Workers by hand (lmbake worker): one killed mid-bake while the other waits, started
   again: the same bytes; one left alone times out naming the part and the worker it waits
   for; one with another config refuses to start, naming the key.
3. Faults, driving the stages by hand (plan, step, merge, finish): at the first step of each
   kind (direct, records placed, ..., denoise level) one shard is killed (SIGKILL) half-way
   through its run and leaves no part, then is rerun; another shard runs twice and writes the
   same bytes; finish refuses while a step is not merged and
   nothing appears in the output folder before it; the output equals `lmbake bake`.
4. Refusals by merge: a part from a farm with another config (named: the part file and the
   config key with both values), a damaged part, a missing part (the shard to rerun named).

usage: check_farm.py LMBAKE WORKDIR SCENE [quick]
"""
import filecmp
import os
import re
import shutil
import signal
import subprocess
import sys
import time

SHARDS = 4


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def run(args, want=0, timeout=900):
    r = subprocess.run(args, capture_output=True, text=True, timeout=timeout)
    if r.returncode != want:
        fail("%s: exit %d (want %d): %s %s" % (" ".join(args), r.returncode, want, r.stdout[-400:], r.stderr[-800:]))
    return r


def same_files(a, b, what):
    names = sorted(os.listdir(a))
    if sorted(os.listdir(b)) != names:
        fail("%s: file lists differ: %s vs %s" % (what, names, sorted(os.listdir(b))))
    differ = [n for n in names if not filecmp.cmp(os.path.join(a, n), os.path.join(b, n), shallow=False)]
    if differ:
        fail("%s: differs from lmbake bake in %s" % (what, differ))
    return names


def write(path, text):
    with open(path, "w") as f:
        f.write(text)
    return path


def steps_of(farm):
    return int(open(os.path.join(farm, "end")).read())


def part(farm, step, k):
    return os.path.join(farm, "parts", "%04d.%d-of-%d.part" % (step, k, SHARDS))


def identity(lmbake, work, scene, name, cfg):
    ref, farm, out = (os.path.join(work, name + s) for s in ("-bake", "-farm", "-out"))
    run([lmbake, "bake", scene, "-c", cfg, "-o", ref, "-q", "--threads", "2"])
    t0 = time.time()
    run([lmbake, "farm", "parallel", scene, "-c", cfg, "--farm", farm, "-o", out, "--shards", str(SHARDS),
         "--jobs", "2", "--threads", "1", "-q"])
    names = same_files(ref, out, name)
    print("%s: farm parallel, %d shards x %d steps (%.1f s) = lmbake bake in all %d files, byte for byte: %s" %
          (name, SHARDS, steps_of(farm), time.time() - t0, len(names), " ".join(names)))
    if steps_of(farm) > 1:
        # resume: step 1's state and one of its parts lost, the output gone; the script run
        # again replays the merged steps, computes that one part, merges and finishes: the same
        # files, and no other part rewritten
        parts = {n: os.stat(os.path.join(farm, "parts", n)).st_mtime_ns for n in os.listdir(os.path.join(farm, "parts"))}
        os.remove(os.path.join(farm, "steps", "0001.state"))
        os.remove(part(farm, 1, 2))
        shutil.rmtree(out)
        time.sleep(0.05)
        run(["bash", os.path.join(farm, "parallel.sh")])
        rewritten = sorted(n for n, t in parts.items() if os.stat(os.path.join(farm, "parts", n)).st_mtime_ns != t)
        if rewritten != [os.path.basename(part(farm, 1, 2))]:
            fail("%s: the resumed script rewrote %s, not step 1's part 2 alone" % (name, rewritten))
        same_files(ref, out, name + " resumed")
        print("%s: parallel.sh run again after losing step 1's state and part 2: wrote that part alone, "
              "output identical" % name)


def workers(lmbake, work, scene, cfg):
    """Workers by hand: 2 workers of 4 shards; worker 2 killed mid-bake while worker 1 waits
    for its parts, then started again: the same bytes as lmbake bake. A worker late beyond
    --wait-timeout fails naming the part and the worker; a worker with another config refuses."""
    ref, farm, out = (os.path.join(work, "workers" + s) for s in ("-bake", "-farm", "-out"))
    run([lmbake, "bake", scene, "-c", cfg, "-o", ref, "-q", "--threads", "2"])
    common = [scene, "-c", cfg, "--farm", farm, "--shards", str(SHARDS), "--threads", "1", "-q"]
    run([lmbake, "plan", scene, "-c", cfg, "--farm", farm, "-q"])
    # alone, worker 1 computes its shards of step 0 and then waits for worker 2's: timed out
    r = run([lmbake, "worker"] + common + ["--worker", "1/2", "--wait-timeout", "1"], want=3)
    if "0000.2-of-4.part" not in r.stderr or "worker 2 of 2" not in r.stderr:
        fail("a worker that timed out did not name the part and the worker: %r" % r.stderr)
    print("worker timed out:", r.stderr.strip().splitlines()[-1])
    w1 = subprocess.Popen([lmbake, "worker"] + common + ["--worker", "1/2", "-o", out], stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True)
    w2 = subprocess.Popen([lmbake, "worker"] + common + ["--worker", "2/2"], stdout=subprocess.DEVNULL,
                          stderr=subprocess.DEVNULL)
    deadline = time.time() + 600
    while not os.path.exists(part(farm, 1, 2)) and w2.poll() is None and time.time() < deadline:
        time.sleep(0.02)
    if w2.poll() is not None:
        fail("worker 2 ended (exit %s) before step 1's part 2 appeared" % w2.returncode)
    w2.send_signal(signal.SIGKILL)
    w2.wait()
    time.sleep(1.0)
    if w1.poll() is not None:
        fail("worker 1 did not wait for the killed worker's parts (exit %s): %s" % (w1.returncode, w1.stderr.read()))
    killed_at = max(int(n[:4]) for n in os.listdir(os.path.join(farm, "parts")) if n.endswith(".part"))
    run([lmbake, "worker"] + common + ["--worker", "2/2"])
    if w1.wait(timeout=900) != 0:
        fail("worker 1 failed: %s" % w1.stderr.read())
    names = same_files(ref, out, "workers")
    print("workers: worker 2 of 2 killed at step %d of %d while worker 1 waited, started again: output = lmbake "
          "bake in all %d files" % (killed_at, steps_of(farm), len(names)))
    # a worker against this farm folder with another config refuses, naming the difference
    other = write(os.path.join(work, "other-worker.yaml"), open(cfg).read().replace("bounce: 16", "bounce: 32"))
    r = run([lmbake, "worker", scene, "-c", other, "--farm", farm, "--shards", str(SHARDS), "-q"], want=2)
    if "samples.bounce" not in r.stderr:
        fail("a worker with another config: the key is not named in %r" % r.stderr)
    print("worker with another config refused:", r.stderr.strip().splitlines()[-1])


def faults(lmbake, work, scene, cfg):
    ref, farm, out = (os.path.join(work, "faults" + s) for s in ("-bake", "-farm", "-out"))
    run([lmbake, "bake", scene, "-c", cfg, "-o", ref, "-q", "--threads", "2"])
    common = [scene, "-c", cfg, "--farm", farm]
    run([lmbake, "plan"] + common + ["-q"])
    killed = late = twice = 0
    step = 0
    kinds = set()
    while not os.path.exists(os.path.join(farm, "end")):
        # shard 1 as it should run, timed: the kill of shard 2 comes at half that time
        t0 = time.time()
        r = run([lmbake, "step"] + common + ["--step", str(step), "--shard", "1/%d" % SHARDS, "--threads", "1"])
        took = time.time() - t0
        # the drill (a kill half-way, a shard run twice) on the first step of each kind (direct,
        # records placed, gathered again, gradients, interpolation, refinement, denoise level,
        # directions; a pass's or a level's number aside): later steps of a kind run the same code
        # on other items, and are only run
        said = r.stdout + r.stderr
        m = re.search(r"^step %d \((.*?)\): shard" % step, said, re.M)
        if not m and not re.search(r"^step %d: the bake has %d steps: nothing to do" % (step, step), said, re.M):
            fail("step %d: shard 1 said neither the step's kind nor the end: %r" % (step, said[-300:]))
        kind = re.sub(r"[0-9]+", "#", m.group(1)) if m else "the end"
        if kind in kinds:
            for k in range(2, SHARDS + 1):
                run([lmbake, "step"] + common + ["--step", str(step), "--shard", "%d/%d" % (k, SHARDS), "-q",
                                                 "--threads", "1"])
            run([lmbake, "merge"] + common + ["--step", str(step), "--shards", str(SHARDS), "-q"])
            step += 1
            continue
        kinds.add(kind)
        p = subprocess.Popen([lmbake, "step"] + common + ["--step", str(step), "--shard", "2/%d" % SHARDS, "-q",
                              "--threads", "1"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(took / 2)
        left = None
        if p.poll() is None:
            p.send_signal(signal.SIGKILL)
            p.wait()
            # killed before its part was renamed into place: no part; killed after (while it
            # exits): a whole part, the same bytes as its rerun writes
            if os.path.exists(part(farm, step, 2)):
                left = open(part(farm, step, 2), "rb").read()
                late += 1
            else:
                killed += 1
        else:
            p.wait()
        run([lmbake, "step"] + common + ["--step", str(step), "--shard", "2/%d" % SHARDS, "-q", "--threads", "1"])
        if left is not None and open(part(farm, step, 2), "rb").read() != left:
            fail("step %d: shard 2 killed after writing its part left other bytes than its rerun" % step)
        # shard 3 twice: the same bytes
        run([lmbake, "step"] + common + ["--step", str(step), "--shard", "3/%d" % SHARDS, "-q", "--threads", "2"])
        first = open(part(farm, step, 3), "rb").read()
        run([lmbake, "step"] + common + ["--step", str(step), "--shard", "3/%d" % SHARDS, "-q", "--threads", "1"])
        if open(part(farm, step, 3), "rb").read() != first:
            fail("step %d: shard 3 run twice wrote different bytes" % step)
        twice += 1
        run([lmbake, "step"] + common + ["--step", str(step), "--shard", "4/%d" % SHARDS, "-q", "--threads", "1"])
        if step == 0 and not os.path.exists(os.path.join(farm, "end")):
            # before the last merge: finish refuses (the next step is not merged), writes nothing
            r = run([lmbake, "finish"] + common + ["-o", out], want=2)
            if "has not been merged" not in r.stderr or os.path.exists(out):
                fail("finish before every step was merged: %r, output folder exists: %s" %
                     (r.stderr[-300:], os.path.exists(out)))
        run([lmbake, "merge"] + common + ["--step", str(step), "--shards", str(SHARDS), "-q"])
        if os.path.exists(out):
            fail("the output folder appeared before the finish stage")
        step += 1
    if killed == 0:
        fail("no shard was still running at half its time: the kill test did not kill")
    run([lmbake, "finish"] + common + ["-o", out, "-q"])
    names = same_files(ref, out, "faults")
    print("faults: %d steps of %d kinds (%s); on the first of each kind: %d shards killed half-way (no part left) "
          "and rerun, %d killed while exiting (whole part, = rerun), %d shards run twice (same bytes); finish "
          "before the last merge refused; output = lmbake bake in all %d files" %
          (steps_of(farm), len(kinds), "; ".join(sorted(kinds)), killed, late, twice, len(names)))
    return farm


def refusals(lmbake, work, scene, cfg, farm):
    # a farm of the same level with another config: its part in our farm is refused by name
    other_cfg = write(os.path.join(work, "other.yaml"), open(cfg).read().replace("bounce: 16", "bounce: 32"))
    other = os.path.join(work, "other-farm")
    run([lmbake, "plan", scene, "-c", other_cfg, "--farm", other, "-q"])
    run([lmbake, "step", scene, "-c", other_cfg, "--farm", other, "--step", "0", "--shard", "1/%d" % SHARDS, "-q"])
    mixed = os.path.join(work, "mixed-farm")
    shutil.copytree(farm, mixed)
    for n in ("end",):
        os.remove(os.path.join(mixed, n))
    shutil.copy(part(other, 0, 1), part(mixed, 0, 1))
    common = [scene, "-c", cfg, "--farm", mixed]
    r = run([lmbake, "merge"] + common + ["--step", "0", "--shards", str(SHARDS)], want=2)
    want = "config key 'samples.bounce' is 32 there, 16 here"
    if want not in r.stderr or "0000.1-of-4.part" not in r.stderr:
        fail("a part from another config: no %r naming the part in %r" % (want, r.stderr))
    print("refused, another config:", r.stderr.strip().splitlines()[-1])
    # damaged
    data = bytearray(open(part(farm, 0, 2), "rb").read())
    data[len(data) // 2] ^= 1
    open(part(mixed, 0, 1), "wb").write(open(part(farm, 0, 1), "rb").read())
    open(part(mixed, 0, 2), "wb").write(bytes(data))
    r = run([lmbake, "merge"] + common + ["--step", "0", "--shards", str(SHARDS)], want=2)
    if "0000.2-of-4.part" not in r.stderr or "damaged" not in r.stderr:
        fail("a damaged part: not named in %r" % r.stderr)
    print("refused, damaged part:", r.stderr.strip().splitlines()[-1])
    # missing
    os.remove(part(mixed, 0, 2))
    r = run([lmbake, "merge"] + common + ["--step", "0", "--shards", str(SHARDS)], want=2)
    if "0000.2-of-4.part" not in r.stderr or "--shard 2/4" not in r.stderr:
        fail("a missing part: the shard to rerun not named in %r" % r.stderr)
    print("refused, missing part:", r.stderr.strip().splitlines()[-1])


def main():
    lmbake, work, scene = sys.argv[1:4]
    quick = len(sys.argv) > 4 and sys.argv[4] == "quick"
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    # 10,000 texels in both passes: the farm's mechanics do not depend on the texel count, and at
    # 20,000 this was the Release pass's second-longest test
    base = "atlas: {texels: 10000}\nbounces: 2\nsamples: {gather: 64, bounce: 16}\n"
    cache_amis = write(os.path.join(work, "cache-amis.yaml"),
                       base + "gather: {method: amis_defensive}\nirradiance_cache: {error: 0.3}\n"
                       "output: {directional: true}\nfarm: {min_step_rays: 0}\n")
    identity(lmbake, work, scene, "cache-amis", cache_amis)
    if not quick:
        no_cache = write(os.path.join(work, "no-cache.yaml"),
                         base.replace("bounces: 2", "bounces: 3") + "irradiance_cache: {error: 0}\n"
                         "farm: {min_step_rays: 0}\n")
        identity(lmbake, work, scene, "no-cache", no_cache)
        defaults = write(os.path.join(work, "default-min.yaml"), base)
        identity(lmbake, work, scene, "default-min-step-rays", defaults)
    # quick (sanitizer builds): fewer, larger steps in the fault drill; the drill is of the farm's
    # mechanics, which the identities above check with probes: none here (a step fewer to kill)
    faults_cfg = write(os.path.join(work, "faults.yaml"),
                       base + "farm: {min_step_rays: %d}\nprobes: {auto: false}\n" % (300000 if quick else 0))
    if not quick:  # the workers' restarts are process drills: the sanitizer pass reads and writes parts in the others
        workers(lmbake, work, scene, faults_cfg)
    farm = faults(lmbake, work, scene, faults_cfg)
    refusals(lmbake, work, scene, faults_cfg, farm)
    print("ok: farm identical, %sfaults survived, foreign parts refused" % ("" if quick else "workers restarted, "))


main()
