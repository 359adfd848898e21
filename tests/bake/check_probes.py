#!/usr/bin/env python3
"""Light probes against analytic irradiance (scenes of tools/make_scenes.py; the probes as the
output glTF holds them: asset.extras.lightmap.probes, docs/probes.md).

usage: check_probes.py LMBAKE WORKDIR CASE
  sky      an open plane under a uniform sky of L = 1000 nits: every probe lies above the plane
           (the ones the grid puts under it are inside geometry: dropped), and over the plane's
           middle the ambient cube's +Y irradiance is pi L within 0.5%, the SH's at +Y within 0.5%
           (a hemisphere's step has no even band above 0, whose truncation the SH would miss);
           the reflected light: the cube's -Y irradiance is pi B F, B = albedo L = 0.5 L the
           plane's radiance (its lightmap holds pi L everywhere) and F the view factor of the
           10 x 10 plane from the probe (four rectangles from the point's foot), within 1%.
  point    a black plane and a 100 cd point light: at each probe every face of the ambient cube
           is I max(0, n . w) / d^2 within 1%, and the SH at n is I / d^2 x (1/4 + c/2 +
           5 (3c^2 - 1) / 32) with c = n . w (a delta's clamped cosine truncated to L2) within 1%.
  sealed   the sealed room under a sky of 10^4 nits with a point light outside: every probe 0.
  solid    a plane with a closed 2 m cube on it: no probe inside the cube, probes around it.
  scale    output.scale radiance: the same probes' values divided by pi.
  cornell  bevy's Cornell box (atlas.texels 150,000) with probes.volumes 1 to 2 units off its floor, walls and
           ceiling: at each probe, for the axis facing a surface straight ahead (a ray along -n
           hits a triangle facing n within 8 units), the ambient cube's irradiance for n against
           the lightmap read there (bilinear, as an engine reads it): the mean ratio per surface
           within 3%; each probe's ratio and the SH's (its L2 truncation) printed.
  node     a node "Hall" with extras.lightmap_probes [4, 2, 3] (rotated 30 degrees, scaled): its 24
           probes at its world transform x the unit cube's cell centres (1e-4), the output's
           volume node with that transform as its matrix, its KTX2 of (4, 4, 9) texels; a
           resolution [0, 2, 3]: exit 2 naming the file and the node, nothing written.
  volume   the closed cube on a plane: the grid as bevy's irradiance volume, read back by an
           independent reader (tests/ktx2/read_ktx2.mjs, npm ktx-parse): vkFormat 123, (Rx, 2Ry,
           3Rz) texels for the node's resolution, every face of every voxel with probes equal to
           the mean of its probes' ambient cubes within E5B9G9R9's precision (2^-9 of the texel's
           largest channel), and the voxels inside the cube (no probe) filled from their
           neighbours, not black (two bounces: every probe outside sees some light).
  adaptive rounds of probes.rays directions to samples.noise (the sky plane): none with
           samples.adaptive false; with a target no estimate meets most probes take more rounds
           than at the default target, and the reflected light is within 1% as in `sky`.
  tetrahedra bevy's Cornell box (atlas.texels 40,000): the probes' Delaunay tetrahedra in the
           output (asset.extras.lightmap.probes.tetrahedra): every probe a vertex, every volume
           positive, no probe inside a circumsphere (deeper than 1e-5 of r^2: float32 positions),
           each face in at most two, the boundary faces enclose the tetrahedra's total volume;
           and a volume of one layer of probes: no tetrahedra, a warning that says why.
"""
import json
import math
import os
import struct
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

BASE = "texel_density: 8\nbounces: 0\noutput: {formats: [exr], directional: false}\n"


def bake(lmbake, work, scene, name, config):
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True,
                   stdout=subprocess.DEVNULL)
    cfg = os.path.join(work, name + ".yaml")
    base = "".join(line + "\n" for line in BASE.splitlines() if line.split(":")[0] + ":" not in config)
    with open(cfg, "w") as f:
        f.write(base + config)
    out = os.path.join(work, "out-" + name)
    p = subprocess.run([lmbake, "bake", os.path.join(scenes, scene + ".gltf"), "-c", cfg, "-o", out],
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("bake %s failed (%d): %s" % (name, p.returncode, p.stderr))
    return load_probes(os.path.join(out, scene + ".gltf")), p.stdout + p.stderr


def floats(doc, folder, view, count):
    v = doc["bufferViews"][view]
    with open(os.path.join(folder, doc["buffers"][v["buffer"]]["uri"]), "rb") as f:
        f.seek(v.get("byteOffset", 0))
        data = f.read(v["byteLength"])
    values = struct.unpack("<%df" % (len(data) // 4), data)
    per = len(values) // count
    return [values[i * per:(i + 1) * per] for i in range(count)]


def load_probes(path):
    with open(path) as f:
        doc = json.load(f)
    folder = os.path.dirname(path)
    p = doc["asset"]["extras"]["lightmap"]["probes"]
    n = p["count"]
    acc = doc["accessors"][p["positions"]]
    return {"count": n, "meta": p, "positions": floats(doc, folder, acc["bufferView"], n),
            "sh": floats(doc, folder, p["sh"], n), "cube": floats(doc, folder, p["ambientCube"], n)}


def sh_basis(n):
    x, y, z = n
    return [0.282095, 0.488603 * y, 0.488603 * z, 0.488603 * x, 1.092548 * x * y, 1.092548 * y * z,
            0.315392 * (3 * z * z - 1), 1.092548 * x * z, 0.546274 * (x * x - y * y)]


def sh_irradiance(sh, n, channel=0):
    return sum(sh[3 * k + channel] * b for k, b in enumerate(sh_basis(n)))


AXES = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]


def report(name, good, text):
    print("%s: %s  %s" % (name, text, "ok" if good else "FAIL"))
    return good


def corner_view_factor(a, b, h):
    """View factor from a point at height h over a corner of an a x b rectangle, facing it."""
    if a <= 0 or b <= 0:
        return 0.0
    ra, rb = math.hypot(a, h), math.hypot(b, h)
    return (a / ra * math.atan(b / ra) + b / rb * math.atan(a / rb)) / (2 * math.pi)


def plane_view_factor(p, half):
    x, h, z = p
    return sum(corner_view_factor(ax, bz, h) for ax in (half - x, half + x) for bz in (half - z, half + z))


def sky(lmbake, work):
    L = 1000.0
    probes, log = bake(lmbake, work, "sky-plane", "sky", "sky: {intensity: %g}\n" % L)
    want = math.pi * L
    mid = [i for i, p in enumerate(probes["positions"]) if abs(p[0]) < 3 and abs(p[2]) < 3]
    cube = [probes["cube"][i][3 * 2] / want for i in mid]
    sh = [sh_irradiance(probes["sh"][i], (0, 1, 0)) / want for i in mid]
    down = [probes["cube"][i][3 * 3] / (math.pi * 0.5 * L * plane_view_factor(probes["positions"][i], 5.0))
            for i in mid]
    above = all(p[1] > 0 for p in probes["positions"])
    good = probes["count"] > 100 and above and len(mid) > 50 and max(abs(r - 1) for r in cube) <= 0.005 \
        and max(abs(r - 1) for r in sh) <= 0.005 and max(abs(r - 1) for r in down) <= 0.01 and "inside geometry" in log
    return report("sky", good, "%d probes, all above the plane: %s; %d over its middle: cube +Y / (pi L) %.5f..%.5f, "
                  "SH +Y / (pi L) %.5f..%.5f (bounds 1 +- 0.5%%); reflected, cube -Y / (pi B F) %.5f..%.5f (1 +- 1%%)"
                  % (probes["count"], above, len(mid), min(cube), max(cube), min(sh), max(sh), min(down), max(down)))


def point(lmbake, work):
    I, light = 100.0, (0.3, 2.0, -0.2)
    probes, _ = bake(lmbake, work, "probe-point", "point", "")
    worst_cube = worst_sh = 0.0
    for p, sh, cube in zip(probes["positions"], probes["sh"], probes["cube"]):
        d = [light[k] - p[k] for k in range(3)]
        dist = math.sqrt(sum(v * v for v in d))
        w = [v / dist for v in d]
        e_perp = I / (dist * dist)
        for a, n in enumerate(AXES):
            c = sum(n[k] * w[k] for k in range(3))
            worst_cube = max(worst_cube, abs(cube[3 * a] - e_perp * max(0.0, c)) / e_perp)
            want = e_perp * (0.25 + c / 2 + 5 * (3 * c * c - 1) / 32)
            worst_sh = max(worst_sh, abs(sh_irradiance(sh, n) - want) / e_perp)
    good = probes["count"] > 50 and worst_cube <= 0.01 and worst_sh <= 0.01
    return report("point", good, "%d probes: largest cube error %.5f, SH error %.5f of I / d^2 (bounds 1%%)"
                  % (probes["count"], worst_cube, worst_sh))


def sealed(lmbake, work):
    probes, _ = bake(lmbake, work, "sealed-room", "sealed", "sky: {intensity: 10000}\nbounces: 2\n")
    top = max(max(abs(v) for v in sh + cube) for sh, cube in zip(probes["sh"], probes["cube"]))
    inside = all(-1 < p[0] < 1 and 0 < p[1] < 2 and -1 < p[2] < 1 for p in probes["positions"])
    good = probes["count"] > 10 and inside and top == 0.0
    return report("sealed", good, "%d probes, all in the room: %s, largest value %g (want 0)"
                  % (probes["count"], inside, top))


def solid(lmbake, work):
    probes, log = bake(lmbake, work, "box-floor", "solid", "")
    inside = [p for p in probes["positions"] if -1 < p[0] < 1 and 0 < p[1] < 2 and -1 < p[2] < 1]
    lit = sum(1 for cube in probes["cube"] if cube[3 * 2] > 0)
    good = probes["count"] > 50 and not inside and lit > probes["count"] // 2
    return report("solid", good, "%d probes, %d inside the cube (want 0), %d lit from above; log: %s"
                  % (probes["count"], len(inside), lit, [l for l in log.splitlines() if l.startswith("probes:")][:1]))


def scale(lmbake, work):
    a, _ = bake(lmbake, work, "probe-point", "scale-e", "")
    b, _ = bake(lmbake, work, "probe-point", "scale-r", "output: {formats: [exr], directional: false, scale: radiance}\n")
    worst = 0.0
    for x, y in zip(a["cube"] + a["sh"], b["cube"] + b["sh"]):
        for u, v in zip(x, y):
            worst = max(worst, abs(u / math.pi - v) / max(1e-6, abs(u / math.pi)))
    good = a["count"] == b["count"] > 0 and worst < 1e-5 and b["meta"]["scale"] == "radiance"
    return report("scale", good, "%d probes, largest relative difference from E / pi %.2g, scale %s"
                  % (b["count"], worst, b["meta"]["scale"]))


CORNELL_VOLUMES = """atlas: {texels: 150000}
probes:
  auto: false
  volumes:
    - {min: [-540, 0.5, -200], max: [-480, 1.5, -40], resolution: [3, 1, 4]}
    - {min: [-200, 0.5, -540], max: [-40, 1.5, -320], resolution: [4, 1, 3]}
    - {min: [-1.5, 100, -500], max: [-0.5, 450, -100], resolution: [1, 4, 4]}
    - {min: [-500, 100, -558.7], max: [-100, 450, -557.7], resolution: [4, 4, 1]}
    - {min: [-548.5, 100, -500], max: [-547.5, 450, -100], resolution: [1, 4, 4]}
    - {min: [-540, 547.3, -540], max: [-420, 548.3, -420], resolution: [3, 1, 3]}
"""


def ray_triangle(o, d, tri):
    """Distance along unit d from o to triangle tri, or None (Moller-Trumbore)."""
    e1 = [tri[1][k] - tri[0][k] for k in range(3)]
    e2 = [tri[2][k] - tri[0][k] for k in range(3)]
    pv = [d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]]
    det = sum(e1[k] * pv[k] for k in range(3))
    if abs(det) < 1e-12:
        return None
    tv = [o[k] - tri[0][k] for k in range(3)]
    u = sum(tv[k] * pv[k] for k in range(3)) / det
    qv = [tv[1] * e1[2] - tv[2] * e1[1], tv[2] * e1[0] - tv[0] * e1[2], tv[0] * e1[1] - tv[1] * e1[0]]
    v = sum(d[k] * qv[k] for k in range(3)) / det
    t = sum(e2[k] * qv[k] for k in range(3)) / det
    if u < 0 or v < 0 or u + v > 1 or t <= 0:
        return None
    return t, u, v


def bilinear(img, u, v):
    h, w = img.shape[0], img.shape[1]
    x, y = u * w - 0.5, v * h - 0.5
    x0, y0 = int(math.floor(x)), int(math.floor(y))
    fx, fy = x - x0, y - y0
    total = 0.0
    for j, wy in ((0, 1 - fy), (1, fy)):
        for i, wx in ((0, 1 - fx), (1, fx)):
            xx, yy = min(max(x0 + i, 0), w - 1), min(max(y0 + j, 0), h - 1)
            total += wx * wy * float(img[yy, xx, 0])
    return total


def cornell(lmbake, work):
    import check_analytic as ca  # numpy and OpenImageIO: this case only
    cfg = os.path.join(work, "cornell.yaml")
    with open(cfg, "w") as f:
        f.write(CORNELL_VOLUMES)
    out = os.path.join(work, "out-cornell")
    p = subprocess.run([lmbake, "bake", os.path.join(ROOT, "assets", "scenes", "cornell-box-bevy", "CornellBox.glb"),
                        "-c", cfg, "-o", out, "-q"], capture_output=True, text=True)
    if p.returncode != 0:
        return report("cornell", False, "bake failed (%d): %s" % (p.returncode, p.stderr))
    probes = load_probes(os.path.join(out, "CornellBox.gltf"))
    charts, images = ca.load_output(out)
    tris = [(tex, w, u) for node, tex, ts in charts for w, u in ts]
    ratios = {}  # axis -> [(cube ratio, sh ratio)]
    for pos, sh, cube in zip(probes["positions"], probes["sh"], probes["cube"]):
        for a, n in enumerate(AXES):
            back = [-c for c in n]
            best = None
            for tex, w, uv in tris:
                hit = ray_triangle(pos, back, w)
                if not hit or hit[0] > 8:
                    continue
                e1 = [w[1][k] - w[0][k] for k in range(3)]
                e2 = [w[2][k] - w[0][k] for k in range(3)]
                nn = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
                ln = math.sqrt(sum(c * c for c in nn))
                if ln == 0 or abs(sum(nn[k] * n[k] for k in range(3)) / ln) < 0.99:
                    continue
                if best is None or hit[0] < best[0]:
                    best = (hit[0], tex, uv, hit[1], hit[2])
            if best is None:
                continue
            t, tex, uv, b1, b2 = best
            u = (1 - b1 - b2) * uv[0][0] + b1 * uv[1][0] + b2 * uv[2][0]
            v = (1 - b1 - b2) * uv[0][1] + b1 * uv[1][1] + b2 * uv[2][1]
            e = bilinear(images[tex], u, v)
            if e > 0:
                ratios.setdefault(a, []).append((cube[3 * a] / e, sh_irradiance(sh, n) / e))
    names = ["+X", "-X", "+Y", "-Y", "+Z", "-Z"]
    good, lines = len(ratios) >= 4, []
    for a, rs in sorted(ratios.items()):
        mean = sum(r[0] for r in rs) / len(rs)
        ok = abs(mean - 1) <= 0.03
        good = good and ok
        lines.append("%s: %d probes, cube / lightmap mean %.4f (%.4f..%.4f), SH / lightmap %.4f..%.4f %s"
                     % (names[a], len(rs), mean, min(r[0] for r in rs), max(r[0] for r in rs),
                        min(r[1] for r in rs), max(r[1] for r in rs), "ok" if ok else "FAIL"))
    return report("cornell", good, "%d probes; per surface normal (bound: mean within 3%%):\n  %s"
                  % (probes["count"], "\n  ".join(lines)))


def quat_matrix(t, q, sc):
    """Column-major 4 x 4 of translation t, rotation quaternion q (x, y, z, w), scale sc."""
    x, y, z, w = q
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m = [0.0] * 16
    for c in range(3):
        for row in range(3):
            m[4 * c + row] = r[row][c] * sc[c]
    m[12], m[13], m[14], m[15] = t[0], t[1], t[2], 1.0
    return m


def node(lmbake, work):
    probes, log = bake(lmbake, work, "probe-node", "node", "probes: {auto: false}\n")
    out = os.path.join(work, "out-node")
    with open(os.path.join(out, "probe-node.gltf")) as f:
        doc = json.load(f)
    hall = [n for n in doc["nodes"] if n.get("name") == "Hall"][0]
    m = quat_matrix(hall["translation"], hall["rotation"], hall["scale"])
    want = []
    for z in range(3):
        for y in range(2):
            for x in range(4):
                lc = [(x + 0.5) / 4 - 0.5, (y + 0.5) / 2 - 0.5, (z + 0.5) / 3 - 0.5]
                want.append([sum(m[4 * c + r] * lc[c] for c in range(3)) + m[12 + r] for r in range(3)])
    got = probes["positions"]
    worst = max(min(max(abs(a - b) for a, b in zip(w, g)) for g in got) for w in want) if got else 1e9
    vol = [n for n in doc["nodes"] if n.get("name") == "lightmap irradiance volume of Hall"]
    matrix_ok = bool(vol) and max(abs(a - b) for a, b in zip(vol[0].get("matrix", [0] * 16), m)) < 1e-9
    head = None
    if vol:
        ktx = os.path.join(out, vol[0]["extras"]["lightmap"]["irradianceVolume"]["uri"])
        p = subprocess.run(["node", os.path.join(ROOT, "tests", "ktx2", "read_ktx2.mjs"), ktx, os.path.join(work, "node.f32")],
                           capture_output=True, text=True, cwd=ROOT)
        head = json.loads(p.stdout) if p.returncode == 0 else None
    dims_ok = head is not None and (head["pixelWidth"], head["pixelHeight"], head["pixelDepth"]) == (4, 4, 9)
    scenes = os.path.join(work, "scenes")
    bad_out = os.path.join(work, "out-node-bad")
    b = subprocess.run([lmbake, "bake", os.path.join(scenes, "probe-node-bad.gltf"), "-o", bad_out], capture_output=True,
                       text=True)
    bad_ok = b.returncode == 2 and "probe-node-bad.gltf: node 'Hall': extras.lightmap_probes" in b.stderr \
        and not os.path.exists(bad_out)
    good = probes["count"] == 24 and worst < 1e-4 and matrix_ok and dims_ok and bad_ok
    return report("node", good, "%d probes (want 24), farthest from its expected place %.2g; volume node with the Hall's "
                  "matrix: %s; KTX2 %s; bad resolution: exit %d, %s"
                  % (probes["count"], worst, matrix_ok, head and (head["pixelWidth"], head["pixelHeight"], head["pixelDepth"]),
                     b.returncode, b.stderr.strip().splitlines()[-1] if b.stderr.strip() else "no message"))


def volume(lmbake, work):
    probes, _ = bake(lmbake, work, "box-floor", "volume", "bounces: 2\n")
    out = os.path.join(work, "out-volume")
    with open(os.path.join(out, "box-floor.gltf")) as f:
        doc = json.load(f)
    node = [n for n in doc["nodes"] if "irradianceVolume" in n.get("extras", {}).get("lightmap", {})][0]
    vol = node["extras"]["lightmap"]["irradianceVolume"]
    rx, ry, rz = vol["resolution"]
    lo = [node["translation"][k] - node["scale"][k] / 2 for k in range(3)]
    cell = [node["scale"][k] / vol["resolution"][k] for k in range(3)]
    texels = os.path.join(work, "volume.f32")
    p = subprocess.run(["node", os.path.join(ROOT, "tests", "ktx2", "read_ktx2.mjs"), os.path.join(out, vol["uri"]),
                        texels], capture_output=True, text=True, cwd=ROOT)
    if p.returncode != 0:
        return report("volume", False, "the reader failed: %s" % p.stderr)
    head = json.loads(p.stdout)
    with open(texels, "rb") as f:
        data = f.read()
    rgb = struct.unpack("<%df" % (len(data) // 4), data)
    sums, counts = {}, {}
    for pos, cube in zip(probes["positions"], probes["cube"]):
        v = tuple(min(int((pos[k] - lo[k]) / cell[k]), vol["resolution"][k] - 1) for k in range(3))
        sums[v] = [a + b for a, b in zip(sums.get(v, [0.0] * 18), cube)]
        counts[v] = counts.get(v, 0) + 1
    worst, black_inside, checked = 0.0, 0, 0
    for z in range(rz):
        for y in range(ry):
            for x in range(rx):
                total = 0.0
                for face in range(6):
                    t, pz = y + (face % 2) * ry, z + (face // 2) * rz
                    i = 3 * ((pz * 2 * ry + t) * rx + x)
                    got = rgb[i:i + 3]
                    if (x, y, z) in counts:
                        want = [sums[(x, y, z)][3 * face + c] / counts[(x, y, z)] for c in range(3)]
                        tol = max(want) * 2 ** -9 + 1e-6
                        worst = max(worst, max(abs(a - b) / tol for a, b in zip(got, want)))
                        checked += 1
                    total += sum(got)
                if (x, y, z) not in counts and total <= 0:
                    black_inside += 1
    empty = rx * ry * rz - len(counts)
    good = (head["vkFormat"] == 123 and (head["pixelWidth"], head["pixelHeight"], head["pixelDepth"]) ==
            (rx, 2 * ry, 3 * rz) and checked > 0 and worst <= 1.0 and empty > 0 and black_inside == 0)
    return report("volume", good, "vkFormat %d, %dx%dx%d texels for resolution %s; %d faces checked, largest error %.3f "
                  "of the format's step; %d voxels without probes, %d of them black"
                  % (head["vkFormat"], head["pixelWidth"], head["pixelHeight"], head["pixelDepth"], vol["resolution"],
                     checked, worst, empty, black_inside))


def adaptive(lmbake, work):
    """Rounds of rays to samples.noise: none with samples.adaptive false; at a noise target no
    estimate meets (samples.max_rays 2048: at most 4 rounds of 512) more than half the probes
    take more rounds, more than at the default target; the reflected light of the sky case
    (cube -Y) then still within 1% of pi B F."""
    L = 1000.0
    rounds = lambda log: [l for l in log.splitlines() if "rays per probe on average" in l]
    _, off = bake(lmbake, work, "sky-plane", "fixed", "sky: {intensity: %g}\nsamples: {adaptive: false}\n" % L)
    probes, most = bake(lmbake, work, "sky-plane", "most", "sky: {intensity: %g}\nsamples: {noise: 1e-9, max_rays: 2048}\n" % L)
    _, default = bake(lmbake, work, "sky-plane", "default", "sky: {intensity: %g}\nsamples: {max_rays: 2048}\n" % L)
    line, line_default = rounds(most), rounds(default)
    n = probes["count"]
    took = lambda l: int(l[0].split("; ")[1].split(" of ")[0]) if l else -1
    # a probe whose two half lattices agree exactly (a step between sky and plane crossed by as
    # many directions in each) shows no error and stops: most, not all, take more rounds
    every = took(line) > n // 2 and took(line_default) < took(line)
    rays = float(line[0].split("probes: ")[1].split(" rays")[0]) if line else 0
    mid = [i for i, p in enumerate(probes["positions"]) if abs(p[0]) < 3 and abs(p[2]) < 3]
    down = [probes["cube"][i][3 * 3] / (math.pi * 0.5 * L * plane_view_factor(probes["positions"][i], 5.0))
            for i in mid]
    good = not rounds(off) and every and max(abs(r - 1) for r in down) <= 0.01
    return report("adaptive", good, "samples.adaptive false: %s; samples.noise 1e-9: %s; default noise: %d probes "
                  "(fewer); reflected light at 1e-9, cube -Y / (pi B F) %.5f..%.5f (1 +- 1%%)"
                  % ("no rounds" if not rounds(off) else rounds(off)[0], line[0].split("probes: ")[1] if line else "no line",
                     took(line_default), min(down), max(down)))


TETRA_CONFIG = "atlas: {texels: 40000}\nbounces: 1\n"
# above the blocks: no probe of the layer is inside geometry (one would move out of the layer)
FLAT_CONFIG = TETRA_CONFIG + """probes:
  auto: false
  volumes: [{min: [-500, 400, -500], max: [-100, 410, -100], resolution: [4, 1, 4]}]
"""


def tetrahedra(lmbake, work):
    import numpy as np  # this case only
    glb = os.path.join(ROOT, "assets", "scenes", "cornell-box-bevy", "CornellBox.glb")
    good = True
    for name, config in (("auto", TETRA_CONFIG), ("flat", FLAT_CONFIG)):
        cfg = os.path.join(work, name + ".yaml")
        with open(cfg, "w") as f:
            f.write(config)
        out = os.path.join(work, "out-" + name)
        p = subprocess.run([lmbake, "bake", glb, "-c", cfg, "-o", out], capture_output=True, text=True)
        if p.returncode != 0:
            return report("tetrahedra", False, "%s: bake failed (%d): %s" % (name, p.returncode, p.stderr))
        path = os.path.join(out, "CornellBox.gltf")
        doc = json.load(open(path))
        meta = doc["asset"]["extras"]["lightmap"]["probes"]
        if name == "flat":
            good &= report("tetrahedra flat", "tetrahedra" not in meta and "no tetrahedra" in p.stderr,
                           "16 probes in one layer: %s; %s" % ("no tetrahedra key" if "tetrahedra" not in meta else
                                                              "a tetrahedra key",
                                                              [l for l in p.stderr.splitlines() if "tetrahedra" in l]))
            continue
        pos = np.array(load_probes(path)["positions"], dtype=np.float64)
        acc = doc["accessors"][meta["tetrahedra"]]
        view = doc["bufferViews"][acc["bufferView"]]
        with open(os.path.join(out, doc["buffers"][view["buffer"]]["uri"]), "rb") as f:
            f.seek(view.get("byteOffset", 0) + acc.get("byteOffset", 0))
            tets = np.frombuffer(f.read(4 * acc["count"]), "<u4").reshape(-1, 4).astype(np.int64)
        a, b, c, d = (pos[tets[:, k]] for k in range(4))
        vol = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6
        # Delaunay: no probe inside a tetrahedron's circumsphere (deeper than float32 positions allow)
        m = 2 * np.stack([b - a, c - a, d - a], 1)
        rhs = np.stack([(q * q).sum(1) - (a * a).sum(1) for q in (b, c, d)], 1)
        centre = np.linalg.solve(m, rhs[..., None])[..., 0]
        r2 = ((centre - a) ** 2).sum(1)
        deepest = 0.0
        for i in range(0, len(tets), 1000):
            d2 = ((centre[i:i + 1000, None, :] - pos[None, :, :]) ** 2).sum(2)
            deepest = max(deepest, float(((r2[i:i + 1000, None] - d2) / r2[i:i + 1000, None]).max()))
        # a conforming mesh: each face in at most 2 tetrahedra; the faces in one bound a closed
        # surface whose enclosed volume (divergence theorem) is the tetrahedra's total
        faces = {}
        for t in tets:
            for skip, sign in ((0, 1), (1, -1), (2, 1), (3, -1)):
                f = [int(t[k]) for k in range(4) if k != skip]
                key = tuple(sorted(f))
                faces.setdefault(key, []).append((f, sign))
        shared_ok = all(len(v) <= 2 for v in faces.values())
        boundary = [v[0] for v in faces.values() if len(v) == 1]
        enclosed = 0.0
        for f, sign in boundary:  # outward: the face opposite vertex k, oriented by the tetrahedron
            p0, p1, p2 = pos[f[0]], pos[f[1]], pos[f[2]]
            enclosed += sign * np.dot(p0, np.cross(p1, p2)) / 6
        total = float(vol.sum())
        good &= report("tetrahedra", vol.min() > 0 and deepest < 1e-5 and shared_ok and len(np.unique(tets)) == len(pos)
                       and abs(enclosed - total) <= 1e-9 * abs(total),
                       "%d probes, %d tetrahedra, every probe a vertex: %s; smallest volume %.4g (> 0); deepest probe "
                       "inside a circumsphere %.2g of r^2 (< 1e-5); faces in at most 2 tetrahedra: %s; the %d faces in one "
                       "(the hull, and flat ones dropped between grid cells) enclose %.10g, the tetrahedra %.10g"
                       % (len(pos), len(tets), len(np.unique(tets)) == len(pos), vol.min(), deepest, shared_ok,
                          len(boundary), enclosed, total))
    return good


if __name__ == "__main__":
    lmbake, work, case = sys.argv[1], sys.argv[2], sys.argv[3]
    os.makedirs(work, exist_ok=True)
    cases = {"sky": sky, "point": point, "sealed": sealed, "solid": solid, "scale": scale, "volume": volume,
             "cornell": cornell, "node": node, "tetrahedra": tetrahedra,
             "adaptive": adaptive}
    sys.exit(0 if cases[case](lmbake, work) else 1)
