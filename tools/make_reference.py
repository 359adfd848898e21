#!/usr/bin/env python3
"""Path-traced reference for the defaults' accuracy test (tests/bake/check_defaults.py): the
per-object mean irradiance of the closed Cornell box (tools/make_scenes.py cornell-closed.gltf)
at 64, 128 and 256 texels per unit, written as JSON (tests/bake/data/cornell-closed-reference.json).

Each density is baked with `lmbake bake --reference` (cosine paths with direct light at every
hit, bounces_max = 32 bounces: at the scene's bounce ratio of ~0.71 the cut leaves < 0.0002% of
the light out) on the same texel layout the test's bakes get. An object's mean converges with the
paths over all its texels, not per texel, so the paths per texel fall as the texels grow (the
same ~8M paths per density). Two seeds at half the paths each: their mean is stored, and half
their difference is each object's standard error estimate, stored beside it.

usage: make_reference.py LMBAKE OUT.json [WORKDIR]    (about 4 minutes on 2 cores)
"""
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "bake"))
import object_means  # noqa: E402

DENSITIES = {64: 256, 128: 64, 256: 16}  # texels per unit -> paths per texel (both seeds together)
CONFIG = "texel_density: %d\noutput:\n  formats: [exr, mask]\n  directional: false\n"


def main():
    lmbake, out_json = sys.argv[1], sys.argv[2]
    work = sys.argv[3] if len(sys.argv) > 3 else tempfile.mkdtemp(prefix="lmbake-reference-")
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(HERE, "make_scenes.py"), scenes], check=True,
                   stdout=subprocess.DEVNULL)
    result = {"scene": "tools/make_scenes.py cornell-closed.gltf",
              "made_by": "tools/make_reference.py (lmbake bake --reference, 2 seeds)", "densities": {}}
    for density, paths in DENSITIES.items():
        cfg = os.path.join(work, "ref-%d.yaml" % density)
        with open(cfg, "w") as f:
            f.write(CONFIG % density)
        runs = []
        for seed in (1, 2):
            out = os.path.join(work, "ref-%d-%d" % (density, seed))
            subprocess.run([lmbake, "bake", os.path.join(scenes, "cornell-closed.gltf"), "-c", cfg, "-o", out,
                            "--reference", "--rays", str(paths // 2), "--seed", str(seed), "-q"], check=True)
            runs.append(object_means.object_means(out))
        objects = {}
        for name in runs[0]:
            a, b = runs[0][name][0], runs[1][name][0]
            objects[name] = {"mean": [round(float(x), 6) for x in (a + b) / 2],
                             "stderr": [round(float(x), 6) for x in abs(a - b) / 2],
                             "texels": runs[0][name][1]}
        result["densities"][str(density)] = {"paths_per_texel": paths, "objects": objects}
        print("%d texels/unit, %d paths: all %s, stderr %s" % (density, paths, objects["all"]["mean"],
                                                               objects["all"]["stderr"]))
    with open(out_json, "w") as f:
        json.dump(result, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
