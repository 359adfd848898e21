"""Builds glTF 2.0 scenes in code for lmbake's tests, demos and benchmarks (tools/make_scenes.py
and the tests' own scenes): `Scene` (meshes, materials, textures, nodes,
KHR_lights_punctual, EXT_mesh_gpu_instancing; written with embedded buffers) and the geometry
the scenes are made of (quads, planes, boxes, spheres, bumped and smooth boxes)."""
import base64
import json
import math
import struct
import zlib


class GltfBuffer:
    """A glTF document with one binary buffer its views are appended to (4-byte aligned): what
    Scene here and make_levels.py's Glb build on."""

    def __init__(self, generator):
        self.doc = {"asset": {"version": "2.0", "generator": generator},
                    "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [],
                    "materials": [], "accessors": [], "bufferViews": [], "buffers": []}
        self.blob = bytearray()

    def view(self, data, target):
        """Appends data as a buffer view (target: 34962 vertices, 34963 indices, None); its index."""
        while len(self.blob) % 4:
            self.blob.append(0)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data),
                                        "target": target})
        self.blob += data
        return len(self.doc["bufferViews"]) - 1


class Scene(GltfBuffer):
    def __init__(self):
        super().__init__("lmbake tools/make_scenes.py")

    def _accessor(self, values, comps, is_index=False):
        if is_index:
            data = struct.pack("<%dI" % len(values), *values)
            acc = {"componentType": 5125, "count": len(values), "type": "SCALAR"}
        else:
            flat = [c for v in values for c in v]
            data = struct.pack("<%df" % len(flat), *flat)
            acc = {"componentType": 5126, "count": len(values), "type": "VEC%d" % comps}
            if comps == 3:
                acc["min"] = [min(v[i] for v in values) for i in range(3)]
                acc["max"] = [max(v[i] for v in values) for i in range(3)]
        acc["bufferView"] = self.view(data, 34963 if is_index else 34962)
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def byte_accessor(self, values):
        """Normalized unsigned-byte VEC4 values (COLOR_0); its accessor index."""
        flat = [c for v in values for c in v]
        acc = {"componentType": 5121, "normalized": True, "count": len(values), "type": "VEC4",
               "bufferView": self.view(struct.pack("<%dB" % len(flat), *flat), 34962)}
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, name, color, emissive=None, strength=None, double_sided=False):
        m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(color) + [1.0], "metallicFactor": 0.0}}
        if double_sided:
            m["doubleSided"] = True
        if emissive:
            m["emissiveFactor"] = list(emissive)
        if strength:
            m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
            self._use("KHR_materials_emissive_strength")
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def texture_png(self, rgb, size=2):
        """A size x size PNG of one 8-bit sRGB colour, as a data-URI image; returns the texture."""
        return self.texture_pixels([[tuple(rgb)] * size] * size)

    def texture_pixels(self, rows, sampler=None):
        """A PNG of 8-bit RGB (or RGBA, when pixels have 4 values) pixels (rows top to bottom) as a
        data-URI image, with an optional sampler (a glTF sampler object); returns the texture."""
        raw = b"".join(b"\0" + b"".join(bytes(p) for p in row) for row in rows)
        def chunk(kind, data):
            return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
        ihdr = struct.pack(">IIBBBBB", len(rows[0]), len(rows), 8, 6 if len(rows[0][0]) == 4 else 2, 0, 0, 0)
        png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
        self.doc.setdefault("images", []).append(
            {"uri": "data:image/png;base64," + base64.b64encode(png).decode(), "mimeType": "image/png"})
        tex = {"source": len(self.doc["images"]) - 1}
        if sampler is not None:
            self.doc.setdefault("samplers", []).append(sampler)
            tex["sampler"] = len(self.doc["samplers"]) - 1
        self.doc.setdefault("textures", []).append(tex)
        return len(self.doc["textures"]) - 1

    def _use(self, ext):
        used = self.doc.setdefault("extensionsUsed", [])
        if ext not in used:
            used.append(ext)

    def require(self, ext):
        self._use(ext)
        req = self.doc.setdefault("extensionsRequired", [])
        if ext not in req:
            req.append(ext)

    def mesh(self, name, tris, material, translation=(0, 0, 0), uv=False, uv_sets=None):
        """tris: list of ((p0, p1, p2)) counter-clockwise seen from the front; flat normals;
        uv: TEXCOORD_0 = (x, z) of each corner; uv_sets: functions of a corner's position
        giving TEXCOORD_0, TEXCOORD_1, ... instead."""
        pos, nrm, idx = [], [], []
        for a, b, c in tris:
            e1 = [b[i] - a[i] for i in range(3)]
            e2 = [c[i] - a[i] for i in range(3)]
            n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
            ln = math.sqrt(sum(x * x for x in n))
            n = [x / ln for x in n]
            for p in (a, b, c):
                idx.append(len(pos))
                pos.append(tuple(float(x) for x in p))
                nrm.append(tuple(n))
        prim = {"attributes": {"POSITION": self._accessor(pos, 3), "NORMAL": self._accessor(nrm, 3)},
                "indices": self._accessor(idx, 1, True)}
        if material is not None:  # None: no material, glTF's default
            prim["material"] = material
        if uv:
            uv_sets = [lambda p: (p[0], p[2])]
        for k, f in enumerate(uv_sets or []):
            prim["attributes"]["TEXCOORD_%d" % k] = self._accessor([tuple(f(p)) for p in pos], 2)
        self.doc["meshes"].append({"name": name, "primitives": [prim]})
        self.doc["nodes"].append({"name": name, "mesh": len(self.doc["meshes"]) - 1,
                                  "translation": list(translation)})
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def smooth_mesh(self, name, positions, normals, indices, material, translation=(0, 0, 0)):
        """An indexed mesh with the given vertex normals (shared vertices: smooth shading)."""
        prim = {"attributes": {"POSITION": self._accessor(positions, 3), "NORMAL": self._accessor(normals, 3)},
                "indices": self._accessor(indices, 1, True), "material": material}
        self.doc["meshes"].append({"name": name, "primitives": [prim]})
        self.doc["nodes"].append({"name": name, "mesh": len(self.doc["meshes"]) - 1, "translation": list(translation)})
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def instance(self, name, mesh_name, translation):
        """Another node of the mesh called mesh_name (an instance: the same mesh, its own lightmap)."""
        mesh = [m["name"] for m in self.doc["meshes"]].index(mesh_name)
        self.doc["nodes"].append({"name": name, "mesh": mesh, "translation": list(translation)})
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def gpu_instances(self, name, mesh_name, translations, scales=None):
        """A node drawing mesh_name once per translation through EXT_mesh_gpu_instancing (optional
        per-copy uniform scales)."""
        self._use("EXT_mesh_gpu_instancing")
        mesh = [m["name"] for m in self.doc["meshes"]].index(mesh_name)
        attrs = {"TRANSLATION": self._instance_accessor([tuple(t) for t in translations], 3)}
        if scales:
            attrs["SCALE"] = self._instance_accessor([(k, k, k) for k in scales], 3)
        self.doc["nodes"].append({"name": name, "mesh": mesh, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": attrs}}})
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def _instance_accessor(self, values, comps):
        flat = [c for v in values for c in v]
        data = struct.pack("<%df" % len(flat), *flat)
        while len(self.blob) % 4:
            self.blob.append(0)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)})
        self.blob += data
        self.doc["accessors"].append({"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": 5126,
                                      "count": len(values), "type": "VEC%d" % comps})
        return len(self.doc["accessors"]) - 1

    def light(self, name, kind, intensity, color=(1, 1, 1), translation=(0, 0, 0), rotation=None, **spot):
        self._use("KHR_lights_punctual")
        lights = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})["lights"]
        l = {"name": name, "type": kind, "intensity": intensity, "color": list(color)}
        if kind == "spot":
            l["spot"] = spot
        lights.append(l)
        node = {"name": name, "translation": list(translation),
                "extensions": {"KHR_lights_punctual": {"light": len(lights) - 1}}}
        if rotation:
            node["rotation"] = list(rotation)
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def write(self, path):
        self.doc["buffers"] = [{"byteLength": len(self.blob),
                                "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(self.blob)).decode()}]
        with open(path, "w") as f:
            json.dump(self.doc, f, indent=1)


# The emissive disk with a texture transform: TEXCOORD_1 = (x, z), the transform's texCoord picks it
# over TEXCOORD_0 (constant 0.1, 0.1); u' = 2 cos(r) x + 0.5 sin(r) z + 0.6 (r = 60 degrees) >= 0.5
# selects the white texel.


def srgb_to_linear(c8):
    c = c8 / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


# Furnace boxes (name -> albedo rho every face must bounce with): spec-gloss c_diff = diffuse x
# (1 - max specular); metalness = metallicFactor x the metallicRoughness texture's blue (linear);
# a base colour texture read through a transform and MIRRORED_REPEAT.


def quad(a, b, c, d):
    """Two triangles of the quad a b c d (counter-clockwise from the front)."""
    return [(a, b, c), (a, c, d)]


def plane(size, y=0.0):
    h = size / 2
    return quad((-h, y, h), (h, y, h), (h, y, -h), (-h, y, -h))  # faces +y


def box(x0, y0, z0, x1, y1, z1, inward=False, bottom=True):
    """Axis-aligned box faces, outward (or inward for a room)."""
    p = [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1), (x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1)]
    faces = [(4, 7, 6, 5), (0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0)]
    if bottom:
        faces.append((0, 1, 2, 3))
    tris = []
    for f in faces:
        q = [p[i] for i in f]
        if inward:
            q = q[::-1]
        tris += quad(*q)
    return tris


def turn_minus_z_to(d):
    """The rotation quaternion (x, y, z, w) turning -Z (a light's direction) into unit vector d."""
    axis = (d[1], -d[0], 0.0)  # (0, 0, -1) x d
    ln = math.sqrt(sum(x * x for x in axis))
    th = math.acos(max(-1.0, min(1.0, -d[2])))
    return [axis[0] / ln * math.sin(th / 2), axis[1] / ln * math.sin(th / 2), 0.0, math.cos(th / 2)]


# The directional lightmap test's sun: 50 degrees from the zenith, travelling toward +x and +z


def bump_normals(size):
    """A tangent-space normal map (8-bit RGB rows) of one round bump per tile: slope
    0.94 sin(2 pi r / 0.8) (up to 43 degrees) at distance r < 0.4 from the tile's centre."""
    rows = []
    for j in range(size):
        row = []
        for i in range(size):
            x, y = (i + 0.5) / size - 0.5, (j + 0.5) / size - 0.5
            r = math.hypot(x, y)
            g = -0.94 * math.sin(2 * math.pi * r / 0.8) if r < 0.4 else 0.0
            gx, gy = (g * x / r, g * y / r) if r > 0 else (0.0, 0.0)
            n = (-gx, gy, 1.0)
            ln = math.sqrt(sum(c * c for c in n))
            row.append(tuple(int(round((c / ln * 0.5 + 0.5) * 255)) for c in n))
        rows.append(row)
    return rows


def uv_sphere(r, rings=12, segments=24):
    """Positions, normals, indices of a latitude-longitude sphere (counter-clockwise outside)."""
    pos, nrm, idx = [], [], []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(segments + 1):  # a duplicated column at the date line, as UV spheres have
            ph = 2 * math.pi * j / segments
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            pos.append(tuple(r * c for c in n))
            nrm.append(n)
    for i in range(rings):
        for j in range(segments):
            a, b = i * (segments + 1) + j, (i + 1) * (segments + 1) + j
            if i > 0:
                idx += [a, a + 1, b]
            if i < rings - 1:
                idx += [a + 1, b + 1, b]
    return pos, nrm, idx


def smooth_box(h, turn=0.0):
    """A cube of half side h turned by `turn` radians about +y, 8 shared corners whose normals
    point out along the diagonals."""
    c, s = math.cos(turn), math.sin(turn)
    pos = [(c * x + s * z, y, -s * x + c * z) for x in (-h, h) for y in (-h, h) for z in (-h, h)]
    nrm = [tuple(v / (h * math.sqrt(3)) for v in p) for p in pos]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    idx = []
    for a, b, c, d in faces:
        idx += [a, b, c, a, c, d]
    return pos, nrm, idx
