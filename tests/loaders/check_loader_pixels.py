#!/usr/bin/env python3
"""lmbake's engine loaders in Chromium (loaders/three, loaders/babylon) against the lightmap files:
every pixel an example page renders (tests/loaders/loader_pixels.mjs: the lightmap value in lux
and the lightmap coordinates, as the loader set the materials up) against the bilinear lookup
of the file the loader used at those coordinates, decoded by a decoder lmbake did not write
(tools/ktx2_blocks.py; the .hdr through OpenImageIO), and against the EXR.

usage: check_loader_pixels.py LMBAKE WORKDIR LOADER[,LOADER...]

bevy's Cornell box (one bounce, few rays, 60,000 texels: the loaders are checked, not the light;
the 160 x 120 probe: about four texels per pixel, each pixel checked at its own coordinates), once per KTX2
format: E5B9G9R9 with Zstandard, BC6H without, ASTC HDR with; each loader's page on each bake.
Which file a loader must read: the KTX2 when it reads that format and the GPU samples it, else
the .hdr, and the page must say why (EXPECT below; Chromium's SwiftShader has BC6H and no ASTC
hdr profile). Bounds per
pixel, relative: against the file the page read, mean 0.1% (the .hdr: 0.5%, RGBE decoders
differ by half a mantissa step) and 99th percentile 1% (the GPU's bilinear weights are 8-bit
fixed point); against the EXR, the file's own precision on top
(E5B9G9R9 0.4%, .hdr 1%, BC6H and ASTC their mean error, docs/output.md): mean within 2%.
Then level-single-10 and 16 copies of a prop through EXT_mesh_gpu_instancing (per-copy
rectangles), BC6H: each page against its files, and the two pages against each other (the same
view: the same lightmap coordinates at every pixel, cross_check()); and Babylon's probe-lit
sphere (probe_light()); and Babylon's light groups (light_groups(): make_scenes.py's sun-lamps
with the sun and the lamps in two groups, at weights (0.3, 2): each pixel against the sum of the
groups' .hdr files at its coordinates, each times its weight and the intensity the glTF names;
then again with every group read from its BC6H .ktx2, against the decoded blocks).
Every page runs in one browser.
"""
import json
import os
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import ktx2_blocks as kb  # noqa: E402

SCENE = os.path.join(ROOT, "assets", "scenes", "cornell-box-bevy", "CornellBox.glb")
FORMATS = {"e5b9g9r9": "zstd", "bc6h": "none", "astc_hdr": "zstd"}
# (loader, format) -> the file it must read, or None: the KTX2 unless the page says the GPU
# cannot sample the format
EXPECT = {("three", "e5b9g9r9"): "ktx2", ("three", "bc6h"): "ktx2", ("three", "astc_hdr"): None,
          ("babylon", "e5b9g9r9"): "hdr", ("babylon", "bc6h"): "ktx2", ("babylon", "astc_hdr"): "hdr"}
# Babylon reads both E5B9G9R9 and ASTC through the .hdr: the ASTC bake's page covers that path
SKIP = {("babylon", "e5b9g9r9")}


def bilinear(img, u, v):
    """Bilinear lookups of img (h, w, 3) at arrays u, v (texel centres at half integers, clamped)."""
    h, w = img.shape[:2]
    x, y = u * w - 0.5, v * h - 0.5
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    ax, ay = (x - x0)[:, None], (y - y0)[:, None]
    def at(xx, yy):
        return img[np.clip(yy, 0, h - 1), np.clip(xx, 0, w - 1)]
    return ((1 - ay) * ((1 - ax) * at(x0, y0) + ax * at(x0 + 1, y0)) +
            ay * ((1 - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1)))


def read_image(path):
    return np.asarray(oiio.ImageBuf(path).get_pixels(oiio.FLOAT), dtype=np.float64)[..., :3]


def relative(got, want):
    s = want.sum(axis=1)
    keep = s > 1e-3 * max(float(np.median(s)), 1e-30)
    return np.abs(got - want).sum(axis=1)[keep] / s[keep]


def page_file(work, loader, tag):
    return os.path.join(work, "%s-%s.json" % (loader, tag))


def run_pages(work, jobs):
    """Every page in one browser (tests/loaders/loader_pixels.mjs --jobs)."""
    jobs_file = os.path.join(work, "jobs.json")
    with open(jobs_file, "w") as f:
        json.dump(jobs, f)
    subprocess.run(["node", os.path.join(HERE, "loader_pixels.mjs"), "--jobs", jobs_file], check=True,
                   env=dict(os.environ, NODE_PATH=os.path.join(ROOT, "node_modules")))


def page_job(work, gltf, loader, tag, probe_light=False):
    return {"loader": loader, "gltf": gltf, "out": page_file(work, loader, tag), "source": "ktx2",
            "probeLight": probe_light}


def check(work, out, stem_name, loader, fmt, tag, min_pixels=10000):
    """One page on one bake against the file it read and the EXR; returns (ok, uv, lit)."""
    p = json.load(open(page_file(work, loader, tag)))
    value = np.array(p["value"], dtype=np.float64).reshape(-1, 4)
    uv = np.array(p["uv"], dtype=np.float64).reshape(-1, 4)
    lit = (uv[:, 3] > 0.5) & (value[:, 3] > 0.5)
    report = " ".join(p["logs"])
    atlas = np.rint(uv[:, 2]).astype(int)  # the page writes each pixel's atlas beside its coordinates
    used_ktx2 = ("from %s-lightmap-0.ktx2" % stem_name) in report
    want_file, want_exr = np.zeros((len(uv), 3)), np.zeros((len(uv), 3))
    for a in np.unique(atlas[lit]):
        stem = os.path.join(out, "%s-lightmap-%d" % (stem_name, a))
        if used_ktx2 != (("from %s-lightmap-%d.ktx2" % (stem_name, a)) in report):
            used_ktx2 = None  # atlases read from different kinds of file: reported below
        ref_file = kb.decode(stem + ".ktx2", work)[1] if used_ktx2 else read_image(stem + ".hdr")
        at = lit & (atlas == a)
        want_file[at] = bilinear(ref_file, uv[at, 0], uv[at, 1])
        want_exr[at] = bilinear(read_image(stem + ".exr"), uv[at, 0], uv[at, 1])
    got = value[lit, :3]
    rel_file = relative(got, want_file[lit])
    rel_exr = relative(got, want_exr[lit])
    want = EXPECT[(loader, fmt)] or ("hdr" if "cannot sample" in report else "ktx2")
    problems = []
    if used_ktx2 is None:
        problems.append("atlases read from different kinds of file")
    elif used_ktx2 != (want == "ktx2"):
        problems.append("read %s, expected the %s" % ("the KTX2" if used_ktx2 else "the .hdr", want))
    if not lit.sum() > min_pixels:
        problems.append("only %d lightmapped pixels" % lit.sum())
    # RGBE decoders differ by half a mantissa step (three adds 0.5 before scaling, OIIO does
    # not): up to 0.4% at the smallest mantissa, so the .hdr's mean bound is 0.5%
    mean_bound = 0.001 if used_ktx2 else 0.005
    if not (rel_file.size and rel_file.mean() <= mean_bound and np.percentile(rel_file, 99) <= 0.01):
        problems.append("pixels off the file they read")
    if not (rel_exr.size and rel_exr.mean() <= 0.02):
        problems.append("pixels off the EXR")
    print("%s, %-9s %s: %d pixels from %s; against it mean %.4f%% p99 %.3f%% (bounds %g%%, 1%%); against the EXR "
          "mean %.3f%% p99 %.2f%% (bound 2%%): %s" % (loader, fmt, stem_name, lit.sum(),
                                                       "the KTX2" if used_ktx2 else "the .hdr",
                                                       100 * rel_file.mean(), 100 * np.percentile(rel_file, 99),
                                                       100 * mean_bound, 100 * rel_exr.mean(),
                                                       100 * np.percentile(rel_exr, 99),
                                                       "ok" if not problems else "FAIL: " + "; ".join(problems)), flush=True)
    return not problems, uv, lit


def bake(lmbake, scene, out, cfg, text):
    with open(cfg, "w") as f:
        f.write(text)
    subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out, "-q"], check=True)


# the loaders are checked, not the light: one bounce, few rays, 60,000 texels
CHEAP = "bounces: 1\nsamples: {gather: 32, adaptive: false}\natlas: {texels: 60000}\n"


def cross_check(work, out, name, loaders, uvs):
    """The two pages against each other: the same camera on the same level, so each pixel lit in
    both has the same lightmap coordinates (for instanced copies: in the copy's own rectangle; a
    page that gave every copy the first copy's rectangle, or none, would differ by whole
    rectangles)."""
    (ua, la), (ub, lb) = (uvs[k] for k in loaders)
    h, w = read_image(os.path.join(out, name + "-lightmap-0.exr")).shape[:2]
    both = la & lb
    texels = np.hypot((ua[both, 0] - ub[both, 0]) * w, (ua[both, 1] - ub[both, 1]) * h)
    agree = both.sum() / max(1, (la | lb).sum())
    good = agree >= 0.9 and texels.size > 0 and np.median(texels) <= 0.5 and np.percentile(texels, 90) <= 1.0
    print("%s, %s: %d pixels lit in both pages (%.1f%% of those lit in either; bound 90%%); lightmap "
          "coordinates apart by median %.3f texels, p90 %.3f, p99 %.2f (bounds 0.5, 1): %s"
          % (name, " vs ".join(loaders), both.sum(), 100 * agree, np.median(texels) if texels.size else -1,
             np.percentile(texels, 90) if texels.size else -1, np.percentile(texels, 99) if texels.size else -1,
             "ok" if good else "FAIL"), flush=True)
    return good


def probe_light(work):
    """Babylon's probe-lit sphere (lmbake-babylon-probes: a spherical polynomial on the sphere's
    reflection texture) against lmbake-probes' irradiance at each pixel's normal, at the probes'
    centroid, halfway to the farthest probe and at that probe: within 0.1% per pixel, 0.01% mean
    (32-bit floats on the GPU; 2e-6 seen)."""
    p = json.load(open(page_file(work, "babylon", "probe-light")))
    ok = True
    for s in p["spheres"]:
        good = s["pixels"] > 1000 and s["worst"] <= 1e-3 and s["mean"] <= 1e-4
        ok &= good
        print("babylon probe light at (%.3f, %.3f, %.3f): %d pixels, irradiance against lmbake-probes' worst %.4f%% "
              "mean %.5f%% (bounds 0.1%%, 0.01%%): %s" % (tuple(s["point"]) + (s["pixels"], 100 * s["worst"],
                                                         100 * s["mean"], "ok" if good else "FAIL")), flush=True)
    return ok


GROUP_WEIGHTS = (0.3, 2.0)


def light_groups(work, out, source):
    """Babylon's page at GROUP_WEIGHTS against sum_g w_g x intensity_g x group g's file (bilinear at
    each pixel's coordinates): its .hdr (source hdr), or its BC6H .ktx2 as decoded by
    tools/ktx2_blocks.py (source ktx2: the page must say it read every group from its .ktx2); the
    bake's own lightmap (the sum at scales 1, 1) is not that sum, so a page that ignored the groups
    fails."""
    p = json.load(open(page_file(work, "babylon", "groups-" + source)))
    value = np.array(p["value"], dtype=np.float64).reshape(-1, 4)
    uv = np.array(p["uv"], dtype=np.float64).reshape(-1, 4)
    lit = (uv[:, 3] > 0.5) & (value[:, 3] > 0.5)
    with open(os.path.join(out, "sun-lamps.gltf")) as f:
        doc = json.load(f)
    groups = next(t["extras"]["lightmap"]["groups"] for t in doc["textures"]
                  if t.get("extras", {}).get("lightmap", {}).get("groups"))
    want, plain = np.zeros((lit.sum(), 3)), bilinear(read_image(os.path.join(out, "sun-lamps-lightmap-0.hdr")),
                                                    uv[lit, 0], uv[lit, 1])
    for w, g in zip(GROUP_WEIGHTS, groups):
        img = kb.decode(os.path.join(out, g["files"]["ktx2"]), work)[1] if source == "ktx2" else \
            read_image(os.path.join(out, g["files"]["hdr"]))
        want += w * np.array(g["intensity"]) * bilinear(img, uv[lit, 0], uv[lit, 1])
    rel, off_plain = relative(value[lit, :3], want), relative(plain, want)
    said = any("at weights %s" % ", ".join("%g" % w for w in GROUP_WEIGHTS) in l for l in p["logs"])
    read = "light groups from %s" % ", ".join("%s %s" % (g["name"], source) for g in groups)
    from_files = any(read in l for l in p["logs"])
    # as the level's lightmap: the KTX2's texels are exact in the page (0.1%), the .hdr's differ by
    # the RGBE decoders' half step (0.5%)
    mean_bound = 0.001 if source == "ktx2" else 0.005
    good = (lit.sum() > 500 and said and from_files and rel.size and rel.mean() <= mean_bound and
            np.percentile(rel, 99) <= 0.01 and off_plain.mean() > 0.05)
    print("babylon light groups %s at weights %s, read from their %s: %d pixels against sum_g w_g x intensity_g x "
          "group g's file: mean %.4f%% p99 %.3f%% (bounds %g%%, 1%%; the bake's own lightmap is %.1f%% off that sum); "
          "the page said the weights: %s, and '%s': %s: %s"
          % ([g["name"] for g in groups], GROUP_WEIGHTS, source, lit.sum(), 100 * rel.mean(),
             100 * np.percentile(rel, 99) if rel.size else -1, 100 * mean_bound, 100 * off_plain.mean(), said, read,
             from_files, "ok" if good else "FAIL"), flush=True)
    return good


def main():
    lmbake, work, loaders = sys.argv[1], sys.argv[2], sys.argv[3].split(",")
    os.makedirs(work, exist_ok=True)
    jobs, checks = [], []  # checks: (out, stem, loader, format, tag, min pixels)
    for fmt, sc in FORMATS.items():
        out = os.path.join(work, "out-" + fmt)
        # the E5B9G9R9 bake (which Babylon reads as the .hdr, covered by the ASTC bake) carries
        # the probes for Babylon's probe-lit sphere
        probes = "{auto: true}" if fmt == "e5b9g9r9" and "babylon" in loaders else "{auto: false}"
        bake(lmbake, SCENE, out, os.path.join(work, fmt + ".yaml"),
             CHEAP + "probes: %s\noutput: {formats: [exr, ktx2], directional: false, ktx2_format: %s, "
             "ktx2_supercompression: %s}\n" % (probes, fmt, sc))
        for loader in loaders:
            if (loader, fmt) not in SKIP:
                jobs.append(page_job(work, os.path.join(out, "CornellBox.gltf"), loader, fmt))
                checks.append((out, "CornellBox", loader, fmt, fmt, 10000))
        if probes != "{auto: false}":
            jobs.append(page_job(work, os.path.join(out, "CornellBox.gltf"), "babylon", "probe-light", True))
    # level-single-10 (58k triangles, 100 rooms, 11 lamps) and 16 copies of a prop through
    # EXT_mesh_gpu_instancing on a ground (two atlases: the ground's, the copies'), BC6H without
    # supercompression (both modules read it); each page against its files, and the pages
    # against each other
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_levels.py"), work, "single:10", "gpu:16"],
                   check=True, stdout=subprocess.DEVNULL)
    levels = [("level-single-10", 300), ("level-gpu-16", 1500)]  # level-single-10 seen from outside: ~480 lightmapped pixels
    for name, min_pixels in levels:
        out = os.path.join(work, "out-" + name)
        bake(lmbake, os.path.join(work, name + ".glb"), out, os.path.join(work, name + ".yaml"),
             CHEAP + "probes: {auto: false}\noutput: {formats: [exr, ktx2], directional: false, ktx2_format: bc6h, "
             "ktx2_supercompression: none}\n")
        for loader in loaders:
            jobs.append(page_job(work, os.path.join(out, name + ".gltf"), loader, name))
            checks.append((out, name, loader, "bc6h", name, min_pixels))
    groups_out = os.path.join(work, "out-groups")
    if "babylon" in loaders:
        subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), os.path.join(work, "scenes")],
                       check=True, stdout=subprocess.DEVNULL)
        bake(lmbake, os.path.join(work, "scenes", "sun-lamps.gltf"), groups_out, os.path.join(work, "groups.yaml"),
             CHEAP + "probes: {auto: false}\noutput:\n  directional: false\n  formats: [exr, hdr, png, ktx2]\n"
             "  ktx2_format: bc6h\n  ktx2_supercompression: none\n  light_groups:\n"
             "    - {name: sun, match: sun}\n    - {name: lamps, match: \"lamp_*\"}\n")
        for source in ("hdr", "ktx2"):
            jobs.append(dict(page_job(work, os.path.join(groups_out, "sun-lamps.gltf"), "babylon", "groups-" + source),
                             source=source, groups=",".join("%g" % w for w in GROUP_WEIGHTS)))
    run_pages(work, jobs)
    ok, uvs = True, {}
    for out, stem, loader, fmt, tag, min_pixels in checks:
        good, uv, lit = check(work, out, stem, loader, fmt, tag, min_pixels)
        ok &= good
        uvs[(stem, loader)] = (uv, lit)
    if "babylon" in loaders:
        ok &= probe_light(work)
        ok &= light_groups(work, groups_out, "hdr")
        ok &= light_groups(work, groups_out, "ktx2")
    for name, _ in levels:
        if len(loaders) == 2:
            ok &= cross_check(work, os.path.join(work, "out-" + name), name, loaders,
                              {k: uvs[(name, k)] for k in loaders})
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
