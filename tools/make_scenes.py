#!/usr/bin/env python3
"""Generates lmbake's own test and demo scenes as glTF 2.0 (embedded buffers).

usage: make_scenes.py OUTDIR

  cornell-point.gltf  the demo: a 1 m Cornell box (5 walls, 2 blocks), a 10 cd point light
                      just under the ceiling (the AMIS paper's Figure 1 set-up)
  cornell-closed.gltf the same box closed (six walls of albedo 0.8, red and green sides), the
                      point light 5 cm under the ceiling: the defaults' accuracy scene
  point-plane.gltf    10 x 10 plane, point light of I = 100 cd at h = 2 above (0, 0)
  sun-box.gltf        10 x 10 plane, closed 1 m cube on it, directional light of 1000 lux
  sun-lamps.gltf      sun-box.gltf with two point lamps: lamp_a 200 cd (1, 0.8, 0.6) at (2.5, 1.5, 2),
                      lamp_b 100 cd (0.6, 0.8, 1) at (-2.5, 0.7, -1.5)
  disk.gltf           plane, emissive disk (64 segments, R = 0.5, L = 10 nits) facing down at h = 1
  sky-plane.gltf      10 x 10 plane and no light: lit by the config's sky (sky.* keys)
  sky-well.gltf       a disk (R = 0.5) at the bottom of a black open cylinder 1 deep: lit by
                      the sky through the opening only
  sky-bare-wall.gltf  the open plane and a wall on it with no material (materials.default)
  sun-plate.gltf      4 x 4 ground, a sun straight down, a plate 1.5 above the x < 0 half: the
                      shadow edge's penumbra (lights.sun_angle)
  alpha-cards.gltf    6 x 3 ground (albedo 0), a sun straight down (1000 lux), three 1 x 1 cards 1 m
                      above it facing up (ALPHA_CARDS): alphaMode MASK with a 2 x 2 checker of
                      texture alpha (NEAREST), BLEND with alpha 0.3, and KHR_materials_transmission 1
                      with base colour (0.2, 0.9, 0.2): what light each lets through
  two-sided-card.gltf 10 x 10 ground (albedo 0.5), a sun straight down (1000 lux), a 2 x 2 card 1 m
                      above it (albedo 0.8, doubleSided, facing up): the ground under the card is lit
                      only by the card's underside, which the sunlit ground lights
  moving.gltf         10 x 10 ground under a sun straight down, and boxes floating 0.5-1.5 m above it
                      (MOVING): a skinned character, a mesh with a morph target, a Crate_LOD0 with its
                      sibling Crate_LOD1, a Rock whose MSFT_lod names RockFar; moving-static.gltf: the
                      same with the character's extras.lightmap true
  checker-bounce.gltf a 4 x 4 floor whose base colour texture is a black and white checker of 1 cm
                      cells (400 x 400, mean albedo 0.5), a 4 x 4 ceiling of albedo 0 2 m above it and a
                      100 cd point light between them: the ceiling's indirect light is the floor's
                      bounce; flat-bounce.gltf: the floor's albedo 0.5 flat; dark-bounce.gltf: 0
  translucent-card.gltf the card over a black ground, KHR_materials_diffuse_transmission 1 (white):
                      the ground under it gets 1000 lux x the card's view factor
  many-lights.gltf    10 x 10 plane under 20 point lights (more than are looped: drawn by
                      their unshadowed irradiance at each point)
  disk-textured.gltf  the same disk with an emissive texture of sRGB 128/255 (linear 0.2159)
  disk-transform.gltf the same disk with a 2 x 1 emissive texture (black | white, NEAREST,
                      CLAMP_TO_EDGE) whose KHR_texture_transform (offset, rotation, scale and a
                      texCoord override to TEXCOORD_1 = (x, z)) lights the part of the disk where
                      x + 0.433 z >= -0.1 (DISK_TRANSFORM)
  sealed-room.gltf    closed 2 m room (inward faces), point light outside it
  sealed-room-camera.gltf  the same with a glTF camera at (0.3, 1.2, 0.4) looking along -z
  box-floor.gltf      plane with a closed 2 m cube on it, point light above the cube
  probe-point.gltf    black plane (albedo 0, 4 x 4) and a 100 cd point light 2 above it: a probe
                      above it sees the light alone
  probe-node.gltf     the same with a node "Hall" asking for an irradiance volume (extras.lightmap_probes
                      [4, 2, 3]; translation (0, 1, 0), 30 degrees about +y, scale (3, 2, 2.5));
                      probe-node-bad.gltf: its resolution [0, 2, 3]
  furnace.gltf        closed 2 m box, every face albedo 0.5 and emitting 1 nit (the furnace test;
                      also the benchmark's "light from everywhere" scene)
  furnace-*.gltf      the same box with other materials (FURNACE_MATERIALS: spec-gloss, a
                      metallicRoughness texture's blue channel, a mirrored base colour texture,
                      a base colour texture too large to read whole);
                      each states the albedo rho it must bounce with
  two-spots.gltf      the Cornell room without blocks, two point lights 3 cm from the left and
                      right walls: two bright spots in opposite directions (benchmark)
  contact.gltf        a 2 m room with two blocks and a thin-legged chair on its floor, a point light
                      near the ceiling (contact shadows for the irradiance cache's benchmark)
  grazing.gltf        a 4 m x 1 m x 0.6 m corridor, a point light 3 cm above the floor near one
                      end: the floor sees its spot at grazing angles (benchmark)
  instanced-boxes.gltf  a ground, 576 boxes through EXT_mesh_gpu_instancing (every other one 1.5 x
                      larger), a roof over the x < 0 half, a sun: instanced copies' lightmaps
  gap.gltf            two 1 m rooms side by side, a wall between them with a 4 cm slit from floor
                      to ceiling, a point light in the left room: the right room is lit through the
                      slit only (guided gathering's failure case in the benchmark, which lightmaps
                      the dark room alone: lightmap.exclude lit_room)

The analytic values the tests compare with are in tests/bake/check_analytic.py.
"""
import math
import os
import sys

# the builder and the geometry, re-exported: the tests call make_scenes.Scene, make_scenes.plane, ...
from gltf_scene import (Scene, box, bump_normals, plane, quad, smooth_box, srgb_to_linear,  # noqa: E402,F401
                        turn_minus_z_to, uv_sphere)


DISK_TRANSFORM = {"offset": [0.6, 0.25], "rotation": math.pi / 3, "scale": [2.0, 0.5], "texCoord": 1}
NEAREST_CLAMP = {"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}


FURNACE_MATERIALS = {
    "specgloss": 0.625 * (1 - 0.2),
    "metal-blue0": 0.5,
    "metal-blue128": 0.5 * (1 - 128 / 255.0),
    "metal-blue255": 0.0,
    "basecolor-mirror": srgb_to_linear(188),
    "basecolor-large": 0.5,
    "vertex-colour": 102 / 255.0,
}
LARGE_TEXTURE_WIDTH = 9000  # over lmbake's 4096 a side: read reduced 3x, averaging in linear light

# alpha-cards.gltf: card name -> the x of its corner (its node's translation (x, 1, -0.5)); each card
# spans [x, x + 1] x [-0.5, 0.5], its TEXCOORD_0 = (local x, local z) in [0, 1]^2
ALPHA_CARDS = {"mask": -2.0, "blend": -0.5, "glass": 1.0}
ALPHA_CHECKER = [[(255, 255, 255, 0), (255, 255, 255, 255)], [(255, 255, 255, 255), (255, 255, 255, 0)]]
BLEND_ALPHA = 0.3
GLASS_TINT = (0.2, 0.9, 0.2)

# 20 point lights 2 m above the plane (x, z, candela): more than lmbake evaluates exactly
MANY_LIGHTS = [(-4 + 2 * (k % 5), -3 + 2 * (k // 5), 10.0 + 7.0 * k) for k in range(20)]


def cornell_box(out, name, colours, light_y, closed):
    """A 1 m Cornell box (white, red left and green right walls, two blocks) with a 10 cd point
    light at height light_y; closed adds the front wall."""
    s = Scene()
    white, red, green = (s.material(n, c) for n, c in zip(("white", "red", "green"), colours))
    c = [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1), (0, 1, 0), (1, 1, 0), (1, 1, 1), (0, 1, 1)]
    s.mesh("floor", quad(c[0], c[3], c[2], c[1]), white)
    s.mesh("ceiling", quad(c[4], c[5], c[6], c[7]), white)
    s.mesh("back", quad(c[0], c[1], c[5], c[4]), white)
    if closed:
        s.mesh("front", quad(c[3], c[7], c[6], c[2]), white)
    s.mesh("left", quad(c[0], c[4], c[7], c[3]), red)
    s.mesh("right", quad(c[1], c[2], c[6], c[5]), green)
    s.mesh("tall_block", box(0.13, 0, 0.37, 0.43, 0.6, 0.67, bottom=False), white)
    s.mesh("short_block", box(0.55, 0, 0.15, 0.85, 0.3, 0.45, bottom=False), white)
    s.light("ceiling_point", "point", 10.0, translation=(0.5, light_y, 0.5))
    s.write(os.path.join(out, name))


def cornell(out):
    """The demo: open at the front, the light 3 cm under the ceiling."""
    cornell_box(out, "cornell-point.gltf", ((0.73, 0.73, 0.73), (0.65, 0.05, 0.05), (0.12, 0.45, 0.15)), 0.97, False)


def cornell_closed(out):
    """The defaults' accuracy scene: the box closed, walls of albedo 0.8 but for a red and a green
    one, the light 5 cm under the ceiling. Closed with bright walls, light bounces many times (the
    series converges at a ratio near 0.7), so it is where a cut-off or extrapolated bounce tail
    shows."""
    cornell_box(out, "cornell-closed.gltf", ((0.8, 0.8, 0.8), (0.8, 0.1, 0.1), (0.1, 0.8, 0.1)), 0.95, True)


def analytic(out):
    s = Scene()
    s.mesh("plane", plane(10), s.material("grey", (0.5, 0.5, 0.5)))
    s.light("point", "point", 100.0, translation=(0, 2, 0))
    s.write(os.path.join(out, "point-plane.gltf"))

    s = Scene()
    grey = s.material("grey", (0.5, 0.5, 0.5))
    s.mesh("plane", plane(10), grey)
    s.mesh("cube", box(-0.5, 0, -0.5, 0.5, 1, 0.5), grey)
    # sun 30 degrees from the zenith, light travelling toward -y and +x: node -Z rotated
    ang = math.radians(30)
    # rotation turning -Z into d = (sin a, -cos a, 0): about the axis (0,0,-1) x d
    d = (math.sin(ang), -math.cos(ang), 0.0)
    axis = (d[1], -d[0], 0.0)  # (0, 0, -1) x d
    ln = math.sqrt(sum(x * x for x in axis))
    th = math.acos(-d[2])
    q = [axis[0] / ln * math.sin(th / 2), axis[1] / ln * math.sin(th / 2), 0.0, math.cos(th / 2)]
    s.light("sun", "directional", 1000.0, rotation=q)
    s.write(os.path.join(out, "sun-box.gltf"))
    # the same with two coloured point lamps (light groups: a sun and the lamps)
    s.light("lamp_a", "point", 200.0, color=(1.0, 0.8, 0.6), translation=(2.5, 1.5, 2.0))
    s.light("lamp_b", "point", 100.0, color=(0.6, 0.8, 1.0), translation=(-2.5, 0.7, -1.5))
    s.write(os.path.join(out, "sun-lamps.gltf"))

    s = Scene()
    s.mesh("plane", plane(6), s.material("grey", (0.5, 0.5, 0.5)))
    n, r, h = 64, 0.5, 1.0
    ring = [(r * math.cos(2 * math.pi * k / n), h, r * math.sin(2 * math.pi * k / n)) for k in range(n)]
    disk = [((0, h, 0), ring[k], ring[(k + 1) % n]) for k in range(n)]  # faces -y
    s.mesh("disk", disk, s.material("emitter", (0.0, 0.0, 0.0), emissive=(1, 1, 1), strength=10.0))
    s.write(os.path.join(out, "disk.gltf"))

    s = Scene()
    s.mesh("plane", plane(6), s.material("grey", (0.5, 0.5, 0.5)))
    mat = s.material("emitter", (0.0, 0.0, 0.0), emissive=(1, 1, 1), strength=10.0)
    s.doc["materials"][mat]["emissiveTexture"] = {"index": s.texture_png((128, 128, 128))}
    s.mesh("disk", disk, mat, uv=True)
    s.write(os.path.join(out, "disk-textured.gltf"))

    s = Scene()
    s.mesh("plane", plane(6), s.material("grey", (0.5, 0.5, 0.5)))
    mat = s.material("emitter", (0.0, 0.0, 0.0), emissive=(1, 1, 1), strength=10.0)
    tex = s.texture_pixels([[(0, 0, 0), (255, 255, 255)]], NEAREST_CLAMP)
    s.doc["materials"][mat]["emissiveTexture"] = {"index": tex, "texCoord": 0,
                                                  "extensions": {"KHR_texture_transform": DISK_TRANSFORM}}
    s.require("KHR_texture_transform")
    s.mesh("disk", disk, mat, uv_sets=[lambda p: (0.1, 0.1), lambda p: (p[0], p[2])])
    s.write(os.path.join(out, "disk-transform.gltf"))

    s = Scene()
    s.mesh("plane", plane(10), s.material("grey", (0.5, 0.5, 0.5)))
    for k, (x, z, i) in enumerate(MANY_LIGHTS):
        s.light("lamp%d" % k, "point", i, translation=(x, 2, z))
    s.write(os.path.join(out, "many-lights.gltf"))

    s = Scene()
    s.mesh("room", box(-1, 0, -1, 1, 2, 1, inward=True), s.material("grey", (0.5, 0.5, 0.5)))
    s.light("outside", "point", 1000.0, translation=(3, 1, 0))
    s.write(os.path.join(out, "sealed-room.gltf"))
    # the same room with a glTF camera in it (the preview's start view takes it)
    s.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}]
    s.doc["nodes"].append({"name": "view", "camera": 0, "translation": [0.3, 1.2, 0.4]})
    s.doc["scenes"][0]["nodes"].append(len(s.doc["nodes"]) - 1)
    s.write(os.path.join(out, "sealed-room-camera.gltf"))

    s = Scene()
    grey = s.material("grey", (0.5, 0.5, 0.5))
    s.mesh("plane", plane(6), grey)
    s.mesh("cube", box(-1, 0, -1, 1, 2, 1), grey)
    s.light("above", "point", 100.0, translation=(1.6, 4, 0.6))
    s.write(os.path.join(out, "box-floor.gltf"))

    s = Scene()
    s.mesh("plane", plane(4), s.material("black", (0.0, 0.0, 0.0)))
    s.light("point", "point", 100.0, translation=(0.3, 2, -0.2))
    s.write(os.path.join(out, "probe-point.gltf"))
    half = math.radians(30) / 2
    s.doc["nodes"].append({"name": "Hall", "translation": [0, 1, 0], "rotation": [0, math.sin(half), 0, math.cos(half)],
                           "scale": [3, 2, 2.5], "extras": {"lightmap_probes": [4, 2, 3]}})
    s.doc["scenes"][0]["nodes"].append(len(s.doc["nodes"]) - 1)
    s.write(os.path.join(out, "probe-node.gltf"))
    s.doc["nodes"][-1]["extras"]["lightmap_probes"] = [0, 2, 3]
    s.write(os.path.join(out, "probe-node-bad.gltf"))


PLATE_HEIGHT = 1.5  # sun-plate.gltf
WELL = (0.5, 1.0)  # sky-well.gltf: radius and depth of the well; its opening subtends atan(R / H)


def sky(out):
    """Scenes lit by the sky alone (no punctual light): the tests set sky.* in their config."""
    s = Scene()
    s.mesh("plane", plane(10), s.material("grey", (0.5, 0.5, 0.5)))
    s.write(os.path.join(out, "sky-plane.gltf"))

    # a disk at the bottom of a black, open cylinder: a point at the centre sees the sky through
    # the opening only, E = pi L sin^2(alpha), alpha = atan(R / H)
    s = Scene()
    r, h, n = WELL[0], WELL[1], 96
    ring = [(r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n)) for k in range(n)]
    floor = [((0, 0, 0), (ring[(k + 1) % n][0], 0, ring[(k + 1) % n][1]), (ring[k][0], 0, ring[k][1]))
             for k in range(n)]  # faces +y
    wall = []
    for k in range(n):
        a, b = ring[k], ring[(k + 1) % n]
        wall += quad((a[0], 0, a[1]), (b[0], 0, b[1]), (b[0], h, b[1]), (a[0], h, a[1]))  # faces inward
    s.mesh("floor", floor, s.material("grey", (0.5, 0.5, 0.5)))
    s.mesh("wall", wall, s.material("black", (0.0, 0.0, 0.0)))
    s.write(os.path.join(out, "sky-well.gltf"))

    # the open plane beside a wall 2 high and 0.1 thick with no material (glTF's default material: metal)
    s = Scene()
    s.mesh("plane", plane(10), s.material("grey", (0.5, 0.5, 0.5)))
    s.mesh("wall", box(-0.05, 0, -5, 0.05, 2, 5, bottom=False), None)
    s.write(os.path.join(out, "sky-bare-wall.gltf"))

    # a sun straight down and a thin plate at PLATE_HEIGHT over the ground's x < 0 half: the
    # penumbra along x = 0 is PLATE_HEIGHT x tan(lights.sun_angle) wide
    s = Scene()
    grey = s.material("grey", (0.5, 0.5, 0.5))
    s.mesh("ground", plane(4), grey)
    y = PLATE_HEIGHT
    s.mesh("plate", quad((-3, y, -3), (-3, y, 3), (0, y, 3), (0, y, -3)), grey)  # faces -y
    s.light("sun", "directional", 1000.0, rotation=[-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)])  # -Z -> -Y
    s.write(os.path.join(out, "sun-plate.gltf"))


def furnace_variant(out, name):
    """The furnace box (Le = 1 nit) with material `name` of FURNACE_MATERIALS; TEXCOORD_0 = (x, z)."""
    s = Scene()
    mat = s.material("furnace-" + name, (0.5, 0.5, 0.5), emissive=(1, 1, 1))
    m = s.doc["materials"][mat]
    pbr = m["pbrMetallicRoughness"]
    if name == "specgloss":
        # the fallback metal-rough material would bounce nothing: spec-gloss must win
        pbr.update({"baseColorFactor": [0.1, 0.1, 0.1, 1.0], "metallicFactor": 1.0})
        m["extensions"] = {"KHR_materials_pbrSpecularGlossiness": {
            "diffuseFactor": [0.625, 0.625, 0.625, 1.0], "specularFactor": [0.2, 0.2, 0.2], "glossinessFactor": 0.5}}
        s.require("KHR_materials_pbrSpecularGlossiness")
    elif name == "metal-blue0":
        # texel 0 says metal (blue 255), texel 1 dielectric (blue 0; red and green 255); the
        # transform maps (x, z) in [-1, 1]^2 to u' = 0.1 z + 1 in [0.9, 1.1]: texel 1 with
        # CLAMP_TO_EDGE (REPEAT would read texel 0 above u' = 1, and no transform texel 0 for x < 0.5)
        tex = s.texture_pixels([[(0, 0, 255), (255, 255, 0)]], NEAREST_CLAMP)
        pbr["metallicFactor"] = 1.0
        pbr["metallicRoughnessTexture"] = {"index": tex, "extensions": {"KHR_texture_transform": {
            "offset": [1.0, 0.5], "rotation": math.pi / 2, "scale": [0.1, 0.1]}}}
        s.require("KHR_texture_transform")
    elif name in ("metal-blue128", "metal-blue255"):
        blue = 128 if name == "metal-blue128" else 255
        rg = 255 if blue == 128 else 0  # red and green unlike blue: reading the wrong channel shows
        pbr["metallicFactor"] = 1.0
        pbr["metallicRoughnessTexture"] = {"index": s.texture_pixels([[(rg, rg, blue)] * 2] * 2)}
    elif name == "basecolor-mirror":
        # u' = 0.1 x - 0.75 in [-0.85, -0.65], texel index floor(2 u') = -2: MIRRORED_REPEAT reads
        # texel 1 (sRGB 188) there; REPEAT and CLAMP_TO_EDGE would read texel 0 (white)
        tex = s.texture_pixels([[(255, 255, 255), (188, 188, 188)]],
                               {"magFilter": 9728, "wrapS": 33648, "wrapT": 10497})
        pbr["baseColorFactor"] = [1.0, 1.0, 1.0, 1.0]
        pbr["baseColorTexture"] = {"index": tex, "extensions": {"KHR_texture_transform": {
            "offset": [-0.75, 0.0], "scale": [0.1, 0.1]}}}
        s.require("KHR_texture_transform")
    elif name == "basecolor-large":
        # 9000 x 2 sRGB columns alternating 255 and 0 (linear 1 and 0): albedo 0.5 on average.
        # Read reduced 3x, each pixel averages 3 columns; averaged before sRGB decoding, the
        # mean would be 0.246 instead
        row = [(255, 255, 255) if x % 2 == 0 else (0, 0, 0) for x in range(LARGE_TEXTURE_WIDTH)]
        pbr["baseColorFactor"] = [1.0, 1.0, 1.0, 1.0]
        pbr["baseColorTexture"] = {"index": s.texture_pixels([row, row])}
    s.mesh("room", box(-1, 0, -1, 1, 2, 1, inward=True), mat, uv=True)
    if name == "vertex-colour":
        # COLOR_0 multiplies the base colour (1): normalized unsigned bytes 102 / 255 = 0.4, linear
        # (no sRGB decoding: it would give 0.133), its alpha 255 ignored by an opaque material
        pbr["baseColorFactor"] = [1.0, 1.0, 1.0, 1.0]
        prim = s.doc["meshes"][-1]["primitives"][0]
        count = s.doc["accessors"][prim["attributes"]["POSITION"]]["count"]
        prim["attributes"]["COLOR_0"] = s.byte_accessor([(102, 102, 102, 255)] * count)
    s.write(os.path.join(out, "furnace-%s.gltf" % name))


def indirect(out):
    s = Scene()
    mat = s.material("furnace", (0.5, 0.5, 0.5), emissive=(1, 1, 1))
    s.mesh("room", box(-1, 0, -1, 1, 2, 1, inward=True), mat)
    s.write(os.path.join(out, "furnace.gltf"))

    for name in FURNACE_MATERIALS:
        furnace_variant(out, name)

    s = Scene()
    white = s.material("white", (0.73, 0.73, 0.73))
    s.mesh("room", box(0, 0, 0, 1, 1, 1, inward=True), white)
    s.light("left_spot", "point", 5.0, translation=(0.03, 0.5, 0.5))
    s.light("right_spot", "point", 5.0, translation=(0.97, 0.5, 0.5))
    s.write(os.path.join(out, "two-spots.gltf"))

    s = Scene()
    white = s.material("white", (0.73, 0.73, 0.73))
    s.mesh("corridor", box(0, 0, 0, 4, 0.6, 1, inward=True), white)
    s.light("floor_spot", "point", 5.0, translation=(0.5, 0.03, 0.5))
    s.write(os.path.join(out, "grazing.gltf"))

    s = Scene()
    white = s.material("white", (0.73, 0.73, 0.73))
    wood = s.material("wood", (0.45, 0.3, 0.2))
    s.mesh("room", box(0, 0, 0, 2, 1.5, 2, inward=True), white)
    s.mesh("block_a", box(0.2, 0, 1.2, 0.6, 0.4, 1.6, bottom=False), white)
    s.mesh("block_b", box(0.75, 0, 1.3, 0.95, 0.2, 1.5, bottom=False), white)
    chair = box(1.0, 0.42, 0.5, 1.45, 0.47, 0.95)  # seat
    for x, z in ((1.0, 0.5), (1.42, 0.5), (1.0, 0.92), (1.42, 0.92)):  # 3 cm legs
        chair += box(x, 0, z, x + 0.03, 0.42, z + 0.03, bottom=False)
    chair += box(1.0, 0.47, 0.91, 1.45, 0.95, 0.95)  # back
    s.mesh("chair", chair, wood)
    s.light("lamp", "point", 8.0, translation=(1.6, 1.4, 1.6))
    s.write(os.path.join(out, "contact.gltf"))

    s = Scene()
    white = s.material("white", (0.73, 0.73, 0.73))
    lit = [t for k, t in enumerate(box(0, 0, 0, 1, 1, 1, inward=True)) if k // 2 != 2]  # no face at x = 1
    dark = [t for k, t in enumerate(box(1, 0, 0, 2, 1, 1, inward=True)) if k // 2 != 4]  # no face at x = 1
    for z0, z1 in ((0, 0.48), (0.52, 1)):  # the divider at x = 1, a 4 cm slit from floor to ceiling
        q = [(1, 0, z0), (1, 0, z1), (1, 1, z1), (1, 1, z0)]  # faces -x (the lit room)
        lit += quad(*q)
        dark += quad(*q[::-1])
    s.mesh("lit_room", lit, white)
    s.mesh("dark_room", dark, white)
    s.light("lamp", "point", 5.0, translation=(0.5, 0.9, 0.5))
    s.write(os.path.join(out, "gap.gltf"))


DIR_SUN = (math.sin(math.radians(50)) * math.cos(math.radians(20)), -math.cos(math.radians(50)),
           math.sin(math.radians(50)) * math.sin(math.radians(20)))
DIR_SUN_LUX = 1000.0


RIM_GAP = 0.001  # the emitter quad hangs 1 mm under the ceiling (bevy's Cornell box: 0.9 mm)
RIM_HALF = 0.3   # half its side
RIM_TURN = math.radians(20)  # turned about the vertical: its outline crosses texels at every offset


def rim_corner(sx, sz):
    """A corner of the fixture quad (sx, sz = -1 or 1) in world x, z."""
    c, s = math.cos(RIM_TURN), math.sin(RIM_TURN)
    return (RIM_HALF * (c * sx - s * sz), RIM_HALF * (s * sx + c * sz))


def artists(out):
    """Scenes for what artists see: light fixtures flush under a ceiling, sealed double-sided rooms."""
    for name, double in (("rim-front", False), ("rim-double", True)):
        s = Scene()
        s.mesh("room", box(-1, 0, -1, 1, 2, 1, inward=True), s.material("grey", (0.5, 0.5, 0.5), double_sided=double))
        y = 2 - RIM_GAP
        q = [rim_corner(sx, sz) for sx, sz in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        s.mesh("fixture", quad(*[(x, y, z) for x, z in q]),  # faces -y
               s.material("panel", (0.8, 0.8, 0.8), emissive=(1, 1, 1), strength=20.0, double_sided=double))
        s.write(os.path.join(out, name + ".gltf"))

    s = Scene()
    s.mesh("room", box(-1, 0, -1, 1, 2, 1, inward=True), s.material("grey", (0.5, 0.5, 0.5), double_sided=True))
    s.light("outside", "point", 1000.0, translation=(3, 1, 0))
    s.light("sun", "directional", 1000.0, rotation=[-0.3826834, 0, 0, 0.9238795])  # 45 deg down
    s.mesh("outside_panel", quad((3, 0.5, -0.5), (3, 0.5, 0.5), (3, 1.5, 0.5), (3, 1.5, -0.5)),  # faces -x, both sides
           s.material("panel", (0.8, 0.8, 0.8), emissive=(1, 1, 1), strength=20.0, double_sided=True))
    s.write(os.path.join(out, "sealed-room-double.gltf"))

    # directional lightmaps: a plane lit from one side by a sun
    s = Scene()
    s.mesh("plane", plane(4), s.material("grey", (0.5, 0.5, 0.5)))
    s.light("sun", "directional", DIR_SUN_LUX, rotation=turn_minus_z_to(DIR_SUN))
    s.write(os.path.join(out, "dir-plane.gltf"))

    # the same plane with a normal map of round bumps (the preview's directional view); the sun
    # low, 70 degrees from the zenith, so the bumps' sides facing it and away differ a lot
    s = Scene()
    grey = s.material("bumpy", (0.6, 0.6, 0.6))
    s.doc["materials"][grey]["normalTexture"] = {"index": s.texture_pixels(bump_normals(64), {"wrapS": 10497, "wrapT": 10497})}
    s.mesh("plane", plane(4), grey, uv_sets=[lambda p: ((p[0] + 2) * 1.5, (p[2] + 2) * 1.5)])
    low = (math.sin(math.radians(70)), -math.cos(math.radians(70)), 0.0)
    s.light("sun", "directional", DIR_SUN_LUX, rotation=turn_minus_z_to(low))
    s.write(os.path.join(out, "dir-bumps.gltf"))

    # seams: a UV sphere and a smooth-normal cube (its faces are separate charts) in a dim
    # emissive room, a lamp above and to the side: light that varies smoothly over both
    s = Scene()
    s.mesh("room", box(-3, -1, -3, 3, 5, 3, inward=True), s.material("sky", (0.5, 0.5, 0.5), emissive=(0.3, 0.3, 0.3)))
    grey = s.material("grey", (0.7, 0.7, 0.7))
    s.smooth_mesh("sphere", *uv_sphere(0.5), grey, translation=(-0.8, 1, 0))
    s.smooth_mesh("cube", *smooth_box(0.4, math.radians(40)), grey, translation=(0.8, 1, 0))  # two faces to the camera
    # two instances of one floor tile side by side: their shared edge is a seam across instances
    tile = quad((-0.5, 0, 0.5), (0.5, 0, 0.5), (0.5, 0, -0.5), (-0.5, 0, -0.5))
    s.mesh("tile", tile, grey, translation=(-0.5, 0, 0))
    s.instance("tile_b", "tile", (0.5, 0, 0))
    s.light("lamp", "point", 40.0, translation=(-1.5, 3.0, 2.0))
    s.write(os.path.join(out, "seams.gltf"))


INSTANCED_GRID = 24  # instanced-boxes.gltf: a GRID x GRID grid of boxes, 1 apart
ROOF_HEIGHT = 3.0


def instanced(out):
    """A 30 x 30 ground, a 24 x 24 grid of 0.5 boxes (open at the bottom, standing on the ground)
    through EXT_mesh_gpu_instancing (576 copies of one mesh: every other one 1.5 x larger), a roof
    3 above the x < 0 half facing down, a sun 30 degrees off vertical: the copies under the roof
    get indirect light only."""
    s = Scene()
    grey = s.material("grey", (0.6, 0.6, 0.6))
    s.mesh("ground", plane(30), grey)
    s.mesh("box", box(-0.25, 0, -0.25, 0.25, 0.5, 0.25, bottom=False), s.material("box", (0.7, 0.7, 0.7)))
    s.doc["scenes"][0]["nodes"].pop()  # the mesh is drawn only through the instancing node
    s.doc["nodes"].pop()
    n = INSTANCED_GRID
    ts = [((i - n / 2 + 0.5) * 1.0, 0.0, (j - n / 2 + 0.5) * 1.0) for i in range(n) for j in range(n)]
    s.gpu_instances("boxes", "box", ts, [1.0 if (k % 2 == 0) else 1.5 for k in range(len(ts))])
    roof = quad((-15, ROOF_HEIGHT, 15), (0, ROOF_HEIGHT, 15), (0, ROOF_HEIGHT, -15), (-15, ROOF_HEIGHT, -15))
    roof = [(a, c, b) for a, b, c in roof]  # facing down, at what it shades (it blocks the sun either way)
    s.mesh("roof", roof, grey)
    s.light("sun", "directional", 1000.0, rotation=[-0.5, 0.0, 0.0, math.sqrt(0.75)])  # (0, -0.866, -0.5): 30 deg off vertical
    s.write(os.path.join(out, "instanced-boxes.gltf"))


def alpha_cards(out):
    s = Scene()
    black = s.material("ground", (0.0, 0.0, 0.0))
    s.mesh("ground", quad((-3, 0, 1.5), (3, 0, 1.5), (3, 0, -1.5), (-3, 0, -1.5)), black)
    card = quad((0, 0, 1), (1, 0, 1), (1, 0, 0), (0, 0, 0))  # faces +y; TEXCOORD_0 = (x, z)
    mask = s.material("card-mask", (0.5, 0.5, 0.5))
    m = s.doc["materials"][mask]
    m["alphaMode"] = "MASK"
    m["alphaCutoff"] = 0.5
    m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": s.texture_pixels(ALPHA_CHECKER, NEAREST_CLAMP)}
    blend = s.material("card-blend", (0.5, 0.5, 0.5))
    s.doc["materials"][blend]["alphaMode"] = "BLEND"
    s.doc["materials"][blend]["pbrMetallicRoughness"]["baseColorFactor"][3] = BLEND_ALPHA
    glass = s.material("card-glass", GLASS_TINT)
    s.doc["materials"][glass]["extensions"] = {"KHR_materials_transmission": {"transmissionFactor": 1.0}}
    s.require("KHR_materials_transmission")
    for name, mat in (("mask", mask), ("blend", blend), ("glass", glass)):
        s.mesh("card-" + name, card, mat, translation=(ALPHA_CARDS[name], 1.0, -0.5), uv=True)
    s.light("sun", "directional", 1000.0, rotation=[-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)])  # -Z turned to -y
    s.write(os.path.join(out, "alpha-cards.gltf"))


def translucent_card(out):
    """The card of two-sided-card transmitting all its diffuse light (KHR_materials_diffuse_transmission
    1, white) over a black ground: the ground under it gets the sun through it, diffusely."""
    s = Scene()
    s.mesh("ground", plane(10), s.material("ground", (0.0, 0.0, 0.0)))
    card = s.material("card", (0.8, 0.8, 0.8))
    s.doc["materials"][card]["extensions"] = {"KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 1.0}}
    s.require("KHR_materials_diffuse_transmission")
    s.mesh("card", quad((-1, 1, 1), (1, 1, 1), (1, 1, -1), (-1, 1, -1)), card)  # faces +y
    s.light("sun", "directional", 1000.0, rotation=[-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)])
    s.write(os.path.join(out, "translucent-card.gltf"))


def two_sided_card(out):
    translucent_card(out)
    s = Scene()
    s.mesh("ground", plane(10), s.material("ground", (0.5, 0.5, 0.5)))
    card = s.material("card", (0.8, 0.8, 0.8), double_sided=True)
    s.mesh("card", quad((-1, 1, 1), (1, 1, 1), (1, 1, -1), (-1, 1, -1)), card)  # faces +y
    s.light("sun", "directional", 1000.0, rotation=[-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)])
    s.write(os.path.join(out, "two-sided-card.gltf"))


# moving.gltf: node name -> (x, z) of its floating 1 x 1 box's centre, and whether it is static
# scenery (lightmapped, casts baked shadows)
MOVING = {"Character": ((-2.5, 0.0), False), "Blob": ((-2.5, 2.5), False), "Crate_LOD0": ((2.5, 0.0), True),
          "Crate_LOD1": ((2.5, -2.5), False), "Rock": ((0.0, 2.5), True), "RockFar": ((0.0, -2.5), False)}


def moving(out, character_static=False):
    s = Scene()
    grey = s.material("grey", (0.5, 0.5, 0.5))
    s.mesh("ground", plane(10), grey)
    for name, ((x, z), _) in MOVING.items():
        s.mesh(name, box(x - 0.5, 0.5, z - 0.5, x + 0.5, 1.5, z + 0.5), grey)
    nodes = {n["name"]: k for k, n in enumerate(s.doc["nodes"])}
    prim = s.doc["meshes"][s.doc["nodes"][nodes["Character"]]["mesh"]]["primitives"][0]
    count = s.doc["accessors"][prim["attributes"]["POSITION"]]["count"]
    prim["attributes"]["JOINTS_0"] = s.byte_accessor([(0, 0, 0, 0)] * count)
    s.doc["accessors"][prim["attributes"]["JOINTS_0"]].pop("normalized")
    prim["attributes"]["WEIGHTS_0"] = s._accessor([(1.0, 0.0, 0.0, 0.0)] * count, 4)
    s.doc["nodes"].append({"name": "Hips", "translation": [-2.5, 1.0, 0.0]})
    s.doc["scenes"][0]["nodes"].append(len(s.doc["nodes"]) - 1)
    s.doc["skins"] = [{"joints": [len(s.doc["nodes"]) - 1]}]
    s.doc["nodes"][nodes["Character"]]["skin"] = 0
    if character_static:
        s.doc["nodes"][nodes["Character"]]["extras"] = {"lightmap": True}
    blob = s.doc["meshes"][s.doc["nodes"][nodes["Blob"]]["mesh"]]["primitives"][0]
    blob["targets"] = [{"POSITION": s._accessor([(0.0, 0.1, 0.0)] * count, 3)}]
    s.doc["meshes"][s.doc["nodes"][nodes["Blob"]]["mesh"]]["weights"] = [0.0]
    s.doc["nodes"][nodes["Rock"]]["extensions"] = {"MSFT_lod": {"ids": [nodes["RockFar"]]}}
    s._use("MSFT_lod")
    s.light("sun", "directional", 1000.0, rotation=[-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)])
    s.write(os.path.join(out, "moving-static.gltf" if character_static else "moving.gltf"))


def checker_bounce(out):
    for name in ("checker", "flat", "dark"):
        s = Scene()
        floor = s.material("floor", (0.0, 0.0, 0.0) if name == "dark" else (1.0, 1.0, 1.0) if name == "checker" else
                           (0.5, 0.5, 0.5))
        if name == "checker":
            rows = [[(255, 255, 255) if (x + y) % 2 else (0, 0, 0) for x in range(400)] for y in range(400)]
            s.doc["materials"][floor]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": s.texture_pixels(rows)}
        s.mesh("floor", plane(4), floor, uv_sets=[lambda p: ((p[0] + 2) / 4, (p[2] + 2) / 4)])
        s.mesh("ceiling", [(a, c, b) for a, b, c in plane(4, 2.0)], s.material("ceiling", (0.0, 0.0, 0.0)))
        s.light("lamp", "point", 100.0, translation=(0.0, 1.0, 0.0))
        s.write(os.path.join(out, "%s-bounce.gltf" % name))


if __name__ == "__main__":
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    cornell(out)
    cornell_closed(out)
    analytic(out)
    sky(out)
    indirect(out)
    artists(out)
    instanced(out)
    alpha_cards(out)
    two_sided_card(out)
    moving(out)
    moving(out, character_static=True)
    checker_bounce(out)
