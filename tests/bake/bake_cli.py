"""Shared by the bake checks (check_indirect.py, check_irradiance_cache.py): generated scenes
and one `lmbake bake` through the CLI."""
import glob
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def scenes(work):
    """tools/make_scenes.py into WORK/scenes; returns that folder."""
    d = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), d], check=True,
                   stdout=subprocess.DEVNULL)
    return d


def bake(lmbake, work, scene, name, config, *args):
    """Bakes scene with the config text into WORK/NAME; returns (atlas 0's EXR, the bake's stdout).
    A failed bake ends the check with its stderr."""
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(config)
    out = os.path.join(work, name)
    p = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out] + list(args), capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake %s failed (%d): %s" % (name, p.returncode, p.stderr))
    exr = glob.glob(os.path.join(out, "*-lightmap-0.exr"))
    assert len(exr) == 1, exr
    return exr[0], p.stdout
