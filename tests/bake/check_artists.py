#!/usr/bin/env python3
"""What artists see (issue 14): no bright rim around a light fixture flush under a ceiling,
sealed double-sided rooms stay dark, under both emission policies (docs/artists.md).

usage: check_artists.py LMBAKE WORKDIR CASE
  rim-front            a one-sided emitter quad 1 mm under the ceiling, turned 20 degrees so its
                       outline crosses texels at every offset: no ceiling texel brighter than 2x
                       the median of the ceiling texels 5-10 texels from the outline
  rim-double           the same quad and room doubleSided, default policy (emission: front only)
  rim-double-material  the same under lights.emission_sides: material (the quad's back emits
                       into the 1 mm gap too): the same bound
  sealed-double        a sealed room of doubleSided walls, a point light, a sun and a
                       double-sided emitter outside, both policies: every texel inside is 0
  seams                a UV sphere and a smooth-normal cube whose faces are separate charts, lit
                       smoothly (a sun and a dim emissive room): the largest luminance jump across
                       seams, sampled bilinearly from both sides at 8 points along every edge
                       that two triangles share with different lightmap UVs (and along the edge
                       two instances of one floor tile share), falls at least 10x
                       against seams.stitch: false and is under 1% of the local value
  directional          output.directional: on a plane lit from one side by a sun, every texel's
                       direction (the -dir.exr) points at the sun within 2 degrees, and the decode
                       from the -dir.png the glTF names, at the surface normal, gives back the
                       analytic E within 1%; in a furnace (uniform light over each hemisphere)
                       the mean D.n is 2/3 within 0.02; byte-identical at 1 and 2 threads
"""
import json
import math
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "tools"))
import check_analytic as ca  # noqa: E402  (texel points exactly as the baker places them)
import make_scenes  # noqa: E402

DENSITY = 20  # texels per metre: 5 cm texels, the 60 cm fixture spans 12
CONFIG = "texel_density: %d\nsamples:\n  texel: %d\n" % (DENSITY, ca.SAMPLES)


def bake(lmbake, work, scene, name, extra="", config=None):
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True)
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write((CONFIG if config is None else config) + extra)
    out = os.path.join(work, "out-" + name)
    p = subprocess.run([lmbake, "bake", os.path.join(scenes, scene + ".gltf"), "-c", cfg, "-o", out, "-q",
                        "--threads", "2"], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake failed (%d): %s" % (p.returncode, p.stderr))
    return ca.load_output(out)


def outline_distance(p):
    """Distance (m) in the ceiling plane from p to the fixture's square outline, 0 inside."""
    t = -make_scenes.RIM_TURN
    x = p[0] * math.cos(t) - p[2] * math.sin(t)
    z = p[0] * math.sin(t) + p[2] * math.cos(t)
    h = make_scenes.RIM_HALF
    return math.hypot(max(abs(x) - h, 0.0), max(abs(z) - h, 0.0))


def rim(charts, images, label):
    ceiling = []  # (distance to the outline in texels, luminance)
    for node, v, pts, x, y, tex in ca.texels(charts, images):
        if node == "room" and all(abs(p[1] - 2.0) < 1e-6 for p in pts):
            d = outline_distance(np.mean(pts, axis=0)) * DENSITY
            ceiling.append((d, float(0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2])))
    ring = [l for d, l in ceiling if 5 <= d <= 10]
    median = float(np.median(ring))
    worst = max(ceiling, key=lambda c: c[1])
    print("%s: %d ceiling texels; median 5-10 texels from the outline %.4g (%d texels); brightest %.4g "
          "(%.2fx, %.1f texels from the outline); bound 2x" % (label, len(ceiling), median, len(ring), worst[1],
                                                               worst[1] / median, worst[0]))
    return len(ring) > 100 and median > 0 and worst[1] <= 2 * median


def sealed(charts, images, label):
    """Every texel of the room is 0. (The emitter panel outside is lightmapped too: edge-on to
    the sun, it gets the grazing part of the sun's disc, lights.sun_angle.)"""
    room = [float(np.max(v)) for node, v, pts, x, y, t in ca.texels(charts, images) if node == "room"]
    m = max(room) if room else -1.0
    print("%s: %d texels inside, largest value of any %g (must be 0)" % (label, len(room), m))
    return m == 0.0 and len(room) > 1000


def bilinear(img, u, v):
    """The EXR's bilinear lookup at normalised (u, v), texel centres at half integers, clamped."""
    h, w = img.shape[0], img.shape[1]
    x, y = u * w - 0.5, v * h - 0.5
    x0, y0 = math.floor(x), math.floor(y)
    ax, ay = x - x0, y - y0
    out = np.zeros(3)
    for j, wy in ((0, 1 - ay), (1, ay)):
        for i, wx in ((0, 1 - ax), (1, ax)):
            xx, yy = min(max(x0 + i, 0), w - 1), min(max(y0 + j, 0), h - 1)
            out += wx * wy * img[yy, xx, :3]
    return out


def seam_edge_jumps(charts, images, points=8):
    """{node: [largest relative luminance jump along each seam edge]} over edges two triangles
    share in world space with different lightmap UVs (found here from the output glTF, not by
    the baker)."""
    edges = {}
    for node, tex, tris in charts:
        node = "tiles" if node.startswith("tile") else node  # two instances of one mesh: one surface
        for wt, ut in tris:
            for k in range(3):
                a, b = (wt[k], ut[k]), (wt[(k + 1) % 3], ut[(k + 1) % 3])
                ka, kb = tuple(round(c, 5) for c in a[0]), tuple(round(c, 5) for c in b[0])
                if kb < ka:
                    a, b, ka, kb = b, a, kb, ka
                edges.setdefault((ka, kb), []).append((node, tex, a[1], b[1]))
    result = {}
    for sides in edges.values():
        if len(sides) != 2 or sides[0][0] != sides[1][0]:
            continue
        (node, ta, a0, a1), (_, tb, b0, b1) = sides
        if ta == tb and max(abs(a0[i] - b0[i]) + abs(a1[i] - b1[i]) for i in range(2)) < 1e-6:
            continue  # one chart
        worst = 0.0
        for k in range(points):
            t = (k + 0.5) / points
            la = lum(bilinear(images[ta], a0[0] + t * (a1[0] - a0[0]), a0[1] + t * (a1[1] - a0[1])))
            lb = lum(bilinear(images[tb], b0[0] + t * (b1[0] - b0[0]), b0[1] + t * (b1[1] - b0[1])))
            worst = max(worst, abs(la - lb) / (0.5 * (la + lb)))
        result.setdefault(node, []).append(worst)
    return result


def seam_jumps(charts, images, points=8):
    """{node: (seam edges, largest relative luminance jump)} (seam_edge_jumps)."""
    return {node: (len(j), max(j)) for node, j in seam_edge_jumps(charts, images, points).items()}


def lum(c):
    return float(0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2])


def seams(lmbake, work):
    cfg = "texel_density: 40\nlightmap:\n  exclude: [room]\n"
    off = seam_jumps(*bake(lmbake, work, "seams", "seams-off", "seams:\n  stitch: false\n", cfg))
    on = seam_jumps(*bake(lmbake, work, "seams", "seams-on", "", cfg))
    ok = True
    for node in ("sphere", "cube", "tiles"):
        (n, before), (_, after) = off.get(node, (0, 0.0)), on.get(node, (0, 0.0))
        good = n >= (1 if node == "tiles" else 4) and after * 10 <= before and after < 0.01
        print("seams, %s: %d seam edges; largest luminance jump %.3f%% unstitched, %.4f%% stitched (%.0fx): %s"
              % (node, n, 100 * before, 100 * after, before / after if after > 0 else float("inf"),
                 "ok" if good else "FAIL (need >= 10x and < 1%)"))
        ok &= good
    return ok


def read_image(path):
    import OpenImageIO as oiio
    inp = oiio.ImageInput.open(path)
    img = inp.read_image("float")
    inp.close()
    return img


def directional_texture(out):
    """(-dir.exr, -dir.png as D) of atlas 0, found through the glTF's extras.lightmap_directional."""
    name = [f for f in os.listdir(out) if f.endswith(".gltf")][0]
    doc = json.load(open(os.path.join(out, name)))
    refs = {m["extras"]["lightmap_directional"]["index"] for m in doc["materials"]
            if "lightmap_directional" in m.get("extras", {})}
    uri = doc["images"][doc["textures"][sorted(refs)[0]]["source"]]["uri"]
    png = read_image(os.path.join(out, uri))[..., :3] * 2.0 - 1.0  # 8-bit (D + 1) / 2, read as [0, 1]
    return read_image(os.path.join(out, uri[:-4] + ".exr"))[..., :3], png


def decode(e, d, n, m):
    """The documented decode: E(m) = E max(0, 1 + 1.5 D.m) / (1 + 1.5 D.n)."""
    return e * max(0.0, 1 + 1.5 * float(np.dot(d, m))) / (1 + 1.5 * float(np.dot(d, n)))


def directional(lmbake, work):
    cfg = "texel_density: 8\noutput:\n  directional: true\n"
    charts, images = bake(lmbake, work, "dir-plane", "dir-plane", "", cfg)
    exr, png = directional_texture(os.path.join(work, "out-dir-plane"))
    to_sun = -np.array(make_scenes.DIR_SUN)
    e_sun = make_scenes.DIR_SUN_LUX * float(to_sun[1])
    worst_angle, worst_e, n = 0.0, 0.0, 0
    up = np.array([0.0, 1.0, 0.0])
    for node, v, pts, x, y, tex in ca.texels(charts, images):
        d = exr[y, x]
        cosang = float(np.dot(d, to_sun) / max(np.linalg.norm(d), 1e-30))
        worst_angle = max(worst_angle, math.degrees(math.acos(min(1.0, cosang))))
        worst_e = max(worst_e, abs(decode(lum(v), png[y, x], up, up) / e_sun - 1))
        n += 1
    ok = n > 500 and worst_angle <= 2.0 and worst_e <= 0.01
    print("directional, plane under a sun: %d texels; largest angle between D and the sun %.4f deg (bound 2); "
          "decode at the normal vs analytic E: largest error %.4f%% (bound 1%%)" % (n, worst_angle, 100 * worst_e))
    charts, images = bake(lmbake, work, "furnace", "dir-furnace", "", cfg)
    exr, _ = directional_texture(os.path.join(work, "out-dir-furnace"))
    dots = []
    for node, v, pts, x, y, tex in ca.texels(charts, images):
        c = np.mean(pts, axis=0)
        normal = np.zeros(3)  # the furnace room: [-1, 1] x [0, 2] x [-1, 1], faces inward
        for k, (lo, hi) in enumerate(((-1, 1), (0, 2), (-1, 1))):
            normal[k] = 1 if abs(c[k] - lo) < 1e-4 else -1 if abs(c[k] - hi) < 1e-4 else 0
        if np.abs(normal).sum() == 1:
            dots.append(float(np.dot(exr[y, x], normal)))
    mean = float(np.mean(dots))
    good = len(dots) > 500 and abs(mean - 2 / 3) <= 0.02
    print("directional, furnace: mean D.n %.4f over %d texels (2/3 within 0.02), per-texel spread %.4f: %s"
          % (mean, len(dots), float(np.std(dots)), "ok" if good else "FAIL"))
    ok &= good
    out1 = os.path.join(work, "out-dir-furnace")
    out2 = os.path.join(work, "out-dir-furnace-1thread")
    cfgf = os.path.join(work, "dir-furnace.yaml")
    subprocess.run([lmbake, "bake", os.path.join(work, "scenes", "furnace.gltf"), "-c", cfgf, "-o", out2, "-q",
                    "--threads", "1"], check=True)
    same = all(open(os.path.join(out1, f), "rb").read() == open(os.path.join(out2, f), "rb").read()
               for f in ("furnace-lightmap-0-dir.exr", "furnace-lightmap-0.exr"))
    print("directional, furnace at 1 and 2 threads: %s" % ("byte-identical" if same else "DIFFERENT"))
    return ok and same


def main():
    lmbake, work, case = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    material = "lights:\n  emission_sides: material\n"
    if case == "rim-front":
        ok = rim(*bake(lmbake, work, "rim-front", case), case)
    elif case == "rim-double":
        ok = rim(*bake(lmbake, work, "rim-double", case), case + " (emission: front)")
    elif case == "rim-double-material":
        ok = rim(*bake(lmbake, work, "rim-double", case, material), case)
    elif case == "directional":
        ok = directional(lmbake, work)
    elif case == "seams":
        ok = seams(lmbake, work)
    elif case == "sealed-double":
        ok = sealed(*bake(lmbake, work, "sealed-room-double", "sealed-front"), "sealed, emission front")
        ok &= sealed(*bake(lmbake, work, "sealed-room-double", "sealed-material", material), "sealed, emission material")
    else:
        sys.exit("unknown case " + case)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
