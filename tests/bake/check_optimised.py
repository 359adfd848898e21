#!/usr/bin/env python3
"""A level as glTF optimisers leave it bakes as its source does.

usage: check_optimised.py LMBAKE WORKDIR

tools/make_scenes.py alpha-cards (a MASK card whose cut-outs are in its texture's alpha, a BLEND
card, a glass pane, a sunlit ground) and two-sided-card (a double-sided card over a sunlit
ground: bounced light), each run through
  - `gltf-transform optimize --compress meshopt --texture-compress webp --simplify false`
    (EXT_meshopt_compression with its filters, KHR_mesh_quantization, EXT_texture_webp with no
    PNG fallback; meshes joined and nodes flattened where it can),
  - `gltfpack -cc` (meshopt with its higher compression, quantization),
  - `gltf-transform draco` (KHR_draco_mesh_compression),
and baked at one texel density: the mean irradiance of every material's texels within 0.5% of
the source's bake (the optimisers quantize positions and may join meshes, so texel sets differ a
little; the light is the same). The log must say what was decoded. npm's @gltf-transform/cli
and gltfpack (package.json) make the inputs.
"""
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import bake_cli  # noqa: E402
from object_means import luminance, object_means  # noqa: E402

BIN = os.path.join(ROOT, "node_modules", ".bin")
TOOLS = {
    "optimize": lambda i, o: [os.path.join(BIN, "gltf-transform"), "optimize", i, o, "--compress", "meshopt",
                              "--texture-compress", "webp", "--simplify", "false"],
    "gltfpack": lambda i, o: [os.path.join(BIN, "gltfpack"), "-cc", "-i", i, "-o", o],
    "draco": lambda i, o: [os.path.join(BIN, "gltf-transform"), "draco", i, o],
}
DECODED = {"optimize": "EXT_meshopt_compression buffer views", "gltfpack": "EXT_meshopt_compression buffer views",
           "draco": "KHR_draco_mesh_compression primitives"}
CONFIG = "texel_density: 12\nlights: {sun_angle: 0}\noutput: {formats: [exr, mask]}\nseed: 3\n"


def bake(lmbake, work, scene, name):
    out = os.path.join(work, "out-" + name)
    p = subprocess.run([lmbake, "bake", scene, "-c", os.path.join(work, "bake.yaml"), "-o", out], capture_output=True,
                       text=True)
    if p.returncode != 0:
        sys.exit("bake %s failed (%d): %s" % (name, p.returncode, p.stderr[-2000:]))
    return object_means(out, by="material"), p.stdout + p.stderr


def main():
    lmbake, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    scenes = bake_cli.scenes(work)
    with open(os.path.join(work, "bake.yaml"), "w") as f:
        f.write(CONFIG)
    ok = True
    for scene in ("alpha-cards", "two-sided-card"):
        src = os.path.join(scenes, scene + ".gltf")
        ref, _ = bake(lmbake, work, src, scene)
        for tool, cmd in TOOLS.items():
            dst = os.path.join(work, "%s-%s.glb" % (scene, tool))
            p = subprocess.run(cmd(src, dst), capture_output=True, text=True)
            if p.returncode != 0:
                sys.exit("%s failed (%d): %s" % (tool, p.returncode, (p.stdout + p.stderr)[-2000:]))
            got, log = bake(lmbake, work, dst, "%s-%s" % (scene, tool))
            decoded = "compressed geometry decoded" in log and DECODED[tool] in log
            ok &= decoded
            for mat in sorted(k for k in ref if k != "all"):
                if ref[mat][1] < 50:
                    continue
                a, b = luminance(ref[mat][0]), luminance(got[mat][0]) if mat in got else float("nan")
                rel = b / a - 1 if a > 0 else (0.0 if b == 0 else float("inf"))
                good = abs(rel) <= 0.005
                ok &= good
                print("%-15s %-9s %-11s %6d -> %6d texels, mean E %9.3f -> %9.3f lux: %+.3f%% (bound 0.5%%)  %s" %
                      (scene, tool, mat, ref[mat][1], got.get(mat, (0, 0))[1], a, b, 100 * rel,
                       "ok" if good else "FAIL"))
            if not decoded:
                print("%s %s: the log does not say the compressed geometry was decoded  FAIL" % (scene, tool))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
