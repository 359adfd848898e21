#!/usr/bin/env python3
"""Generates level-sized test scenes for the unwrap/pack benchmark and the real-level tests
(issue 10), as binary glTF (.glb). Deterministic: the same arguments give the same bytes.

usage: make_levels.py OUTDIR [single|instances|furnace|gpu|all|single:ROOMS|instances:COUNT|gpu:COUNT] ...
  (single:ROOMS: ROOMS x ROOMS rooms, level-single-ROOMS.glb; instances:COUNT: COUNT props,
   level-instances-COUNT.glb; the benchmark's size series)

  level-single.glb     one mesh, ~60k triangles, 10 x 10 rooms of 24 units (240 units
                       across): tiled floors, walls with door gaps, pillars, stairs, rows of
                       touching crates (their shared edges are non-manifold once welded:
                       ~3,600 edges with 4 faces) and 1,100 zero-area triangles; a sun and
                       a point light per row of rooms.
  level-instances.glb  ~1M triangles in 2,000 instances of 40 meshes (bumpy rocks, columns,
                       crates; 100-1,000 triangles each) on a 45 x 45 grid over 900 units,
                       turned and scaled; a ground of 20k triangles; a sun.
  level-gpu.glb        1,900 copies of a ~4,000-triangle prop through one EXT_mesh_gpu_instancing
                       node on a ground, a sun (gpu:COUNT: COUNT copies, level-gpu-COUNT.glb)
  furnace-08.glb       a closed 2 m box (inward faces), every face albedo 0.8 and emitting
                       1 nit: E converges to pi / (1 - 0.8) = 15.708 lux (bounces: auto test).
"""
import json
import math
import os
import struct
import sys

import numpy as np

from gltf_scene import GltfBuffer  # the document and its buffer, shared with make_scenes.py


class Mesh:
    """Triangles as numpy arrays: positions (n, 3) float32, indices (m, 3) uint32."""

    def __init__(self):
        self.pos = []
        self.idx = []
        self.count = 0

    def add(self, pos, idx):
        pos = np.asarray(pos, dtype=np.float64).reshape(-1, 3)
        idx = np.asarray(idx, dtype=np.int64).reshape(-1, 3)
        self.pos.append(pos)
        self.idx.append(idx + self.count)
        self.count += len(pos)

    def arrays(self):
        return (np.concatenate(self.pos).astype(np.float32), np.concatenate(self.idx).astype(np.uint32))

    def triangles(self):
        return sum(len(i) for i in self.idx)


def box(m, lo, hi, inward=False):
    """An axis-aligned box with 12 triangles, faces outward (or inward)."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    p = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (0, 4, 7, 3), (1, 2, 6, 5)]
    tris = []
    for a, b, c, d in quads:
        t = [(a, b, c), (a, c, d)]
        if inward:
            t = [(x, z, y) for x, y, z in t]
        tris += t
    m.add(p, tris)


def grid(m, x0, z0, size_x, size_z, nx, nz, y=0.0):
    """A floor tile grid facing +Y, nx x nz quads."""
    xs = np.linspace(x0, x0 + size_x, nx + 1)
    zs = np.linspace(z0, z0 + size_z, nz + 1)
    gx, gz = np.meshgrid(xs, zs, indexing="ij")
    pos = np.stack([gx.ravel(), np.full(gx.size, y), gz.ravel()], axis=1)
    i = np.arange(nx)[:, None] * (nz + 1) + np.arange(nz)[None, :]
    a, b, c, d = i, i + 1, i + nz + 2, i + nz + 1
    tris = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    m.add(pos, tris)


def cylinder(m, cx, cz, r, h, seg, y0=0.0):
    """Closed cylinder: seg side quads and two fan caps."""
    ang = np.arange(seg) * 2 * math.pi / seg
    ring = np.stack([cx + r * np.cos(ang), np.zeros(seg), cz + r * np.sin(ang)], 1)
    bottom, top = ring + [0, y0, 0], ring + [0, y0 + h, 0]
    pos = np.concatenate([bottom, top, [[cx, y0, cz], [cx, y0 + h, cz]]])
    k = np.arange(seg)
    n = (k + 1) % seg
    side = np.concatenate([np.stack([k, seg + n, n], 1), np.stack([k, seg + k, seg + n], 1)])
    caps = np.concatenate([np.stack([np.full(seg, 2 * seg), k, n], 1), np.stack([np.full(seg, 2 * seg + 1), seg + n, seg + k], 1)])
    m.add(pos, np.concatenate([side, caps]))


def bumpy_sphere(m, seg, rings, r, bump, seed):
    """UV sphere with a deterministic bumpy radius: 2 seg (rings - 1) triangles."""
    rng = np.random.default_rng(seed)
    phase = rng.uniform(0, 2 * math.pi, 3)
    th = np.linspace(0, math.pi, rings + 1)[1:-1]
    ph = np.arange(seg) * 2 * math.pi / seg
    T, P = np.meshgrid(th, ph, indexing="ij")
    rad = r * (1 + bump * np.sin(3 * P + phase[0]) * np.sin(2 * T + phase[1]) + 0.5 * bump * np.cos(5 * P + phase[2]))
    pos = np.stack([rad * np.sin(T) * np.cos(P), rad * np.cos(T), rad * np.sin(T) * np.sin(P)], -1).reshape(-1, 3)
    pos = np.concatenate([pos, [[0, r, 0], [0, -r, 0]]])
    nr = rings - 1
    tris = []
    for i in range(nr - 1):
        for j in range(seg):
            a, b = i * seg + j, i * seg + (j + 1) % seg
            c, d = a + seg, b + seg
            tris += [(a, b, d), (a, d, c)]
    north, south = nr * seg, nr * seg + 1
    for j in range(seg):
        tris.append((north, (j + 1) % seg, j))
        tris.append((south, (nr - 1) * seg + j, (nr - 1) * seg + (j + 1) % seg))
    m.add(pos, tris)


def degenerate(m, rng, n, extent):
    """n zero-area triangles: a repeated vertex or three collinear points."""
    for k in range(n):
        a = np.floor(rng.uniform(0, extent, 3) * [1, 0.01, 1])
        b = a + np.floor(rng.uniform(1, 4, 3))
        if k % 2:
            m.add([a, a, b], [(0, 1, 2)])
        else:  # exactly collinear: steps of 0.5 along x
            m.add([a, a + [0.5, 0, 0], a + [1.0, 0, 0]], [(0, 1, 2)])


def room(m, ox, oz, rng):
    size, h, t = 24.0, 4.0, 0.3
    grid(m, ox, oz, size, size, 9, 9)
    for k in range(3):  # walls along x and z in three pieces with two door gaps
        x0, x1 = ox + k * 8.5, ox + k * 8.5 + 7.0
        box(m, (x0, 0, oz), (x1, h, oz + t))
        z0, z1 = oz + k * 8.5, oz + k * 8.5 + 7.0
        box(m, (ox, 0, z0), (ox + t, h, z1))
        box(m, (x0, h, oz), (x1, h + 0.2, oz + t)) if k == 1 else None
        box(m, (ox + size - t, 0, z0), (ox + size, h, z1)) if (ox + oz) % 48 == 0 else None
    for p in range(2):
        cylinder(m, ox + 8 + 8 * p, oz + 12, 0.5, h, 16)
    for s in range(5):  # stairs
        box(m, (ox + 18, 0, oz + 3 + s * 0.6), (ox + 21, 0.3 * (s + 1), oz + 3.6 + s * 0.6))
    for c in range(10):  # a row of touching crates: shared faces weld into non-manifold edges
        box(m, (ox + 3 + c * 1.0, 0, oz + 20), (ox + 4 + c * 1.0, 1.0, oz + 21))
    degenerate(m, rng, 11, 24.0)


class Glb(GltfBuffer):
    def __init__(self):
        super().__init__("lmbake tools/make_levels.py")

    def material(self, name, albedo, emissive=None):
        mat = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": [albedo, albedo, albedo, 1.0],
                                                      "metallicFactor": 0.0, "roughnessFactor": 1.0}}
        if emissive:
            mat["emissiveFactor"] = emissive
        self.doc["materials"].append(mat)
        return len(self.doc["materials"]) - 1

    def mesh(self, name, m, material):
        pos, idx = m.arrays()
        pv = self.view(pos.tobytes(), 34962)
        iv = self.view(idx.tobytes(), 34963)
        acc = self.doc["accessors"]
        acc.append({"bufferView": pv, "componentType": 5126, "count": len(pos), "type": "VEC3",
                    "min": [float(v) for v in pos.min(0)], "max": [float(v) for v in pos.max(0)]})
        acc.append({"bufferView": iv, "componentType": 5125, "count": int(idx.size), "type": "SCALAR"})
        self.doc["meshes"].append({"name": name, "primitives": [{"attributes": {"POSITION": len(acc) - 2},
                                                                 "indices": len(acc) - 1, "material": material}]})
        return len(self.doc["meshes"]) - 1

    def node(self, node):
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def lights(self, lights, placements):
        self.doc.setdefault("extensionsUsed", []).append("KHR_lights_punctual")
        self.doc["extensions"] = {"KHR_lights_punctual": {"lights": lights}}
        for k, node in placements:
            node["extensions"] = {"KHR_lights_punctual": {"light": k}}
            self.node(node)

    def write(self, path):
        self.doc["buffers"] = [{"byteLength": len(self.blob)}]
        js = json.dumps(self.doc, separators=(",", ":")).encode()
        js += b" " * (-len(js) % 4)
        blob = bytes(self.blob) + b"\0" * (-len(self.blob) % 4)
        out = struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(blob))
        out += struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(blob), 0x004E4942) + blob
        with open(path, "wb") as f:
            f.write(out)


def sun_rotation():
    # node -Z pointing down and sideways: rotate -60 degrees about X then 30 about Y
    ax = math.radians(-60) / 2
    qx = (math.sin(ax), 0.0, 0.0, math.cos(ax))
    ay = math.radians(30) / 2
    qy = (0.0, math.sin(ay), 0.0, math.cos(ay))
    x1, y1, z1, w1 = qy
    x2, y2, z2, w2 = qx
    return [w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2, w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2, w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2]


def level_single(path, rooms=10):
    rng = np.random.default_rng(1)
    m = Mesh()
    for i in range(rooms):
        for j in range(rooms):
            room(m, i * 24.0, j * 24.0, rng)
    g = Glb()
    mat = g.material("Concrete", 0.6)
    g.node({"name": "Level", "mesh": g.mesh("Level", m, mat)})
    lights = [{"type": "directional", "intensity": 3.0, "name": "Sun"}]
    places = [(0, {"name": "Sun", "rotation": sun_rotation()})]
    for j in range(rooms):
        lights.append({"type": "point", "intensity": 500.0, "name": "Lamp %d" % j})
        places.append((len(lights) - 1, {"name": "Lamp %d" % j, "translation": [rooms * 12.0, 3.5, j * 24.0 + 12.0]}))
    g.lights(lights, places)
    g.write(path)
    return m.triangles()


def level_instances(path, count=2000):
    rng = np.random.default_rng(2)
    g = Glb()
    mat = g.material("Stone", 0.5)
    meshes, tris = [], []
    for k in range(40):
        m = Mesh()
        kind = k % 3
        if kind == 0:
            seg = 12 + (k * 7) % 22
            bumpy_sphere(m, seg, seg // 2 + 6, 1.0, 0.15, 100 + k)
        elif kind == 1:
            cylinder(m, 0.0, 0.0, 0.6, 4.0, 12 + (k * 5) % 64)
            box(m, (-0.8, 0.0, -0.8), (0.8, 0.3, 0.8))
            box(m, (-0.8, 4.0, -0.8), (0.8, 4.3, 0.8))
        else:
            n = 2 + k % 9
            for a in range(n):
                box(m, (a * 1.1, 0, 0), (a * 1.1 + 1, 1, 1))
                box(m, (a * 1.1, 1, 0), (a * 1.1 + 1, 2, 1)) if a % 2 else None
            bumpy_sphere(m, 20, 16, 0.5, 0.1, 300 + k)
        meshes.append(g.mesh("Prop%02d" % k, m, mat))
        tris.append(m.triangles())
    ground = Mesh()
    grid(ground, -450.0, -450.0, 900.0, 900.0, 100, 100)
    g.node({"name": "Ground", "mesh": g.mesh("Ground", ground, mat)})
    total = ground.triangles()
    # weights so that 2,000 instances hold about 1M triangles
    order = rng.integers(0, 40, 2000)
    for n in range(count):
        k = int(order[n])
        i, j = divmod(n, 45)
        ang = rng.uniform(0, 2 * math.pi)
        s = float(rng.uniform(0.5, 2.0))
        g.node({"name": "Prop%02d_%04d" % (k, n), "mesh": meshes[k],
                "translation": [-440.0 + i * 19.5, 0.0, -440.0 + j * 19.5],
                "rotation": [0.0, math.sin(ang / 2), 0.0, math.cos(ang / 2)], "scale": [s, s, s]})
        total += tris[k]
    g.lights([{"type": "directional", "intensity": 3.0, "name": "Sun"}],
             [(0, {"name": "Sun", "rotation": sun_rotation()})])
    g.write(path)
    return total


def level_gpu(path, count=1900):
    """A ground and `count` copies of one ~4,000-triangle bumpy sphere drawn through a single
    EXT_mesh_gpu_instancing node (like Blender's 24_gpu_instancing test: 1,900 teapots), turned
    and uniformly scaled, under a sun."""
    rng = np.random.default_rng(3)
    g = Glb()
    mat = g.material("Stone", 0.5)
    prop = Mesh()
    bumpy_sphere(prop, 64, 32, 1.0, 0.15, 7)
    mesh = g.mesh("Prop", prop, mat)
    ground = Mesh()
    side = int(math.ceil(math.sqrt(count)))
    grid(ground, -2.0, -2.0, side * 4.0 + 4.0, side * 4.0 + 4.0, 20, 20)
    g.node({"name": "Ground", "mesh": g.mesh("Ground", ground, mat)})
    t, r, sc = [], [], []
    for n in range(count):
        i, j = divmod(n, side)
        ang = rng.uniform(0, 2 * math.pi)
        k = float(rng.uniform(0.6, 1.4))
        t += [i * 4.0 + 2.0, 1.2 * k, j * 4.0 + 2.0]
        r += [0.0, math.sin(ang / 2), 0.0, math.cos(ang / 2)]
        sc += [k, k, k]
    acc = g.doc["accessors"]
    attrs = {}
    for name, vals, comps in (("TRANSLATION", t, 3), ("ROTATION", r, 4), ("SCALE", sc, 3)):
        v = g.view(np.array(vals, dtype=np.float32).tobytes(), None)
        del g.doc["bufferViews"][v]["target"]
        acc.append({"bufferView": v, "componentType": 5126, "count": count, "type": "VEC%d" % comps})
        attrs[name] = len(acc) - 1
    g.doc.setdefault("extensionsUsed", []).append("EXT_mesh_gpu_instancing")
    g.node({"name": "Props", "mesh": mesh, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": attrs}}})
    g.lights([{"type": "directional", "intensity": 3.0, "name": "Sun"}],
             [(0, {"name": "Sun", "rotation": sun_rotation()})])
    g.write(path)
    return ground.triangles() + count * prop.triangles()


def furnace(path, rho=0.8):
    g = Glb()
    mat = g.material("Furnace", rho, [1.0, 1.0, 1.0])
    m = Mesh()
    box(m, (-1, -1, -1), (1, 1, 1), inward=True)
    g.node({"name": "Box", "mesh": g.mesh("Box", m, mat)})
    g.write(path)
    return m.triangles()


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    which = sys.argv[2:] or ["all"]
    os.makedirs(out, exist_ok=True)
    jobs = {"single": ("level-single.glb", level_single), "instances": ("level-instances.glb", level_instances),
            "furnace": ("furnace-08.glb", furnace), "gpu": ("level-gpu.glb", level_gpu)}
    for key, (name, fn) in jobs.items():
        if "all" in which or key in which:
            n = fn(os.path.join(out, name))
            print("%s: %d triangles" % (os.path.join(out, name), n))
    for w in which:
        if ":" in w:
            key, size = w.split(":")
            name = "level-%s-%s.glb" % (key, size)
            n = jobs[key][1](os.path.join(out, name), int(size))
            print("%s: %d triangles" % (os.path.join(out, name), n))


if __name__ == "__main__":
    main()
