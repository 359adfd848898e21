#!/usr/bin/env python3
"""The staged bake's plan stage (issue 13; docs/farm.md): `lmbake plan` then
`lmbake bake --plan` writes the same files as `lmbake bake`, byte for byte (here at another
thread count as well); a plan is refused, exit 2 with no output folder, when it was made with
another config (the message names the key and both values), from another input, or is damaged
or truncated (each named), or when a texture file it references changed after the plan.

usage: check_plan_stage.py LMBAKE WORKDIR SCENE...
"""
import filecmp
import os
import shutil
import subprocess
import sys


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def run(args, want=0):
    r = subprocess.run(args, capture_output=True, text=True, timeout=900)
    if r.returncode != want:
        fail("%s: exit %d (want %d): %s" % (" ".join(args), r.returncode, want, r.stderr[-800:]))
    return r


def main():
    lmbake, work = sys.argv[1:3]
    scenes = sys.argv[3:]
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    cfg = os.path.join(work, "a.yaml")
    with open(cfg, "w") as f:
        f.write("atlas: {texels: 40000}\nbounces: 2\nsamples: {gather: 64, bounce: 16}\n")
    other_cfg = os.path.join(work, "b.yaml")
    with open(other_cfg, "w") as f:
        f.write("atlas: {texels: 40000}\nbounces: 2\nsamples: {gather: 64, bounce: 32}\n")
    for k, scene in enumerate(scenes):
        name = os.path.splitext(os.path.basename(scene))[0]
        plan = os.path.join(work, name + ".plan")
        direct, planned = os.path.join(work, name + "-direct"), os.path.join(work, name + "-planned")
        run([lmbake, "plan", scene, "-c", cfg, "-o", plan, "-q", "--threads", "2"])
        run([lmbake, "bake", scene, "-c", cfg, "-o", direct, "-q", "--threads", "2"])
        run([lmbake, "bake", scene, "-c", cfg, "--plan", plan, "-o", planned, "-q", "--threads", "1"])
        names = sorted(os.listdir(direct))
        if sorted(os.listdir(planned)) != names:
            fail("%s: file lists differ: %s vs %s" % (name, names, sorted(os.listdir(planned))))
        differ = [n for n in names if not filecmp.cmp(os.path.join(direct, n), os.path.join(planned, n), shallow=False)]
        if differ:
            fail("%s: bake --plan differs from bake in %s" % (name, differ))
        print("%s: plan %d bytes; bake --plan = bake in all %d files, byte for byte" %
              (name, os.path.getsize(plan), len(names)))

        # refusals: exit 2, the reason named, no output folder
        refused = os.path.join(work, name + "-refused")
        cases = [
            ([lmbake, "bake", scene, "-c", other_cfg, "--plan", plan, "-o", refused],
             "made with another config: config key 'samples.bounce' is 16 there, 32 here"),
        ]
        if k + 1 < len(scenes):  # another level's plan
            cases.append(([lmbake, "bake", scenes[k + 1], "-c", cfg, "--plan", plan, "-o", refused],
                          "made from another input"))
        data = open(plan, "rb").read()
        damaged = os.path.join(work, name + "-damaged.plan")
        with open(damaged, "wb") as f:
            f.write(data[:len(data) // 2] + bytes([data[len(data) // 2] ^ 1]) + data[len(data) // 2 + 1:])
        cases.append(([lmbake, "bake", scene, "-c", cfg, "--plan", damaged, "-o", refused],
                      "damaged: its SHA-256 does not match"))
        cut = os.path.join(work, name + "-cut.plan")
        with open(cut, "wb") as f:
            f.write(data[:-100])
        cases.append(([lmbake, "bake", scene, "-c", cfg, "--plan", cut, "-o", refused], "truncated"))
        for args, want in cases:
            r = run(args, want=2)
            if want not in r.stderr or os.path.basename(args[args.index("--plan") + 1]) not in r.stderr:
                fail("%s: no %r naming the plan in: %s" % (" ".join(args), want, r.stderr[-500:]))
            if os.path.exists(refused):
                fail("a refused plan left the output folder %s" % refused)
            print("  refused (exit 2): %s" % want)
        # a texture the glTF references changed after the plan: another input
        folder = os.path.dirname(os.path.abspath(scene))
        images = sorted(n for n in os.listdir(folder) if n.lower().endswith((".png", ".jpg", ".jpeg")))
        if images:
            copy = os.path.join(work, name + "-copy")
            shutil.copytree(folder, copy)
            copied = os.path.join(copy, os.path.basename(scene))
            copy_plan = os.path.join(work, name + "-copy.plan")
            run([lmbake, "plan", copied, "-c", cfg, "-o", copy_plan, "-q"])
            with open(os.path.join(copy, images[0]), "ab") as f:
                f.write(b"\0")
            r = run([lmbake, "bake", copied, "-c", cfg, "--plan", copy_plan, "-o", refused], want=2)
            if "made from another input" not in r.stderr or os.path.exists(refused):
                fail("%s: a changed texture (%s) not refused: %s" % (name, images[0], r.stderr[-300:]))
            print("  refused (exit 2): texture %s changed after the plan: made from another input" % images[0])
    print("ok: %d level(s): bake --plan identical to bake; foreign, damaged and truncated plans refused, named" %
          len(scenes))


if __name__ == "__main__":
    main()
