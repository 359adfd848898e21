#!/usr/bin/env python3
"""Generates the leak suite's scenes (docs/leaks.md): levels where some region has no light path
to any light, so its lightmap texels and probes must read exactly 0, built the way blockouts and
modular levels are (continuous floor and ceiling quads running under walls, walls standing on a
floor with no shared edge).

usage: leak_scenes.py OUTDIR [SCALE]

  two-rooms-T.gltf   (T = 1, 2, 5, 20: wall thickness in cm) two sealed rooms side by side, each
                     ROOM (4 x 3 x 4 m; x SCALE), under one floor quad and one ceiling quad,
                     split by a wall T cm thick standing on the floor (a closed box without top
                     or bottom: no edge shared with floor or ceiling); a 500 cd lamp in room A
                     (x < 0). Room B (x > T / 2) has no light and no opening: every texel and
                     probe of it must read 0.
  corridor-L.gltf    an L-shaped corridor (1 m wide, 2.5 m tall, legs 6 m) with a lamp at the end
                     of one leg: the other leg is lit only around the corner (against --reference)
  box-floor-T.gltf   a floor quad under a lamp, a closed 1 m crate standing on it with no bottom
                     and no shared edge: the floor inside the crate must read 0 and the crate's
                     foot outside must not darken
  slab.gltf          a sunlit roof (a 10 x 10 slab 5 cm thick) over a room whose ceiling is a
                     second thin slab 2 cm under the roof: the room below, sealed, reads 0
  courtyard.gltf     a sunlit 12 x 12 courtyard (walls 4 m) with a closed 3 x 3 x 3 m hut in it
                     (walls 5 cm thick, no door): the hut's inside reads 0

Every scene's dark region is named in LEAK_SCENES with its box (the bench and the ctests read it).
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_scene import Scene, box, quad  # noqa: E402

ROOM = (4.0, 3.0, 4.0)  # one room's x, y, z extent in metres
LAMP_CD = 500.0
WALLS_CM = (1, 2, 5, 20)
GREY = (0.7, 0.7, 0.7)


def open_top(x0, y0, z0, x1, y1, z1, inward=False):
    """A box's four sides, no top and no bottom: walls standing on a floor under a ceiling."""
    return [tri for tri in box(x0, y0, z0, x1, y1, z1, inward=inward, bottom=False)
            if not all(abs(p[1] - y1) < 1e-9 for p in tri)]


def two_rooms(out, t_cm, scale=1.0):
    """Two sealed rooms split by a wall t_cm thick; returns (lit box, dark box, wall x range)."""
    s = Scene()
    grey = s.material("grey", GREY)
    w, h, d = (c * scale for c in ROOM)
    t = t_cm / 100.0 * scale
    x0, x1 = -w - t / 2, w + t / 2
    s.mesh("floor", quad((x0, 0, -d / 2), (x0, 0, d / 2), (x1, 0, d / 2), (x1, 0, -d / 2)), grey)
    s.mesh("ceiling", quad((x0, h, -d / 2), (x1, h, -d / 2), (x1, h, d / 2), (x0, h, d / 2)), grey)
    # the outer walls, facing in: a box without top or bottom
    s.mesh("outer_walls", open_top(x0, 0, -d / 2, x1, h, d / 2, inward=True), grey)
    # the dividing wall: a closed box's four sides, standing on the floor, touching the ceiling
    s.mesh("wall", open_top(-t / 2, 0, -d / 2, t / 2, h, d / 2), grey)
    s.light("lamp", "point", LAMP_CD, translation=(-w / 2 - t / 2, h / 2, 0.0))
    s.write(os.path.join(out, "two-rooms-%d.gltf" % t_cm))


def corridor(out):
    """An L of two 6 m legs, 1 m wide and 2.5 m tall: leg A along +x, leg B along +z from its end."""
    s = Scene()
    grey = s.material("grey", GREY)
    tris = []
    tris += box(0, 0, 0, 6, 2.5, 1, inward=True)            # leg A: x 0..6, z 0..1
    tris += box(5, 0, 1, 6, 2.5, 7, inward=True)            # leg B: x 5..6, z 1..7
    # open the joint: drop leg A's +z face where leg B meets it and leg B's -z face
    keep = []
    for tri in tris:
        on_a_side = all(abs(p[2] - 1) < 1e-9 for p in tri) and all(p[0] >= 5 - 1e-9 for p in tri)
        if not on_a_side:
            keep.append(tri)
    # leg A's +z face spans x 0..6 at z = 1: cut it to x 0..5
    keep = [tri for tri in keep if not all(abs(p[2] - 1) < 1e-9 for p in tri)]
    keep += quad((0, 0, 1), (0, 2.5, 1), (5, 2.5, 1), (5, 0, 1))
    s.mesh("corridor", keep, grey)
    s.light("lamp", "point", 100.0, translation=(0.5, 2.0, 0.5))
    s.write(os.path.join(out, "corridor-L.gltf"))


def box_floor(out):
    s = Scene()
    grey = s.material("grey", GREY)
    s.mesh("floor", quad((-3, 0, -3), (-3, 0, 3), (3, 0, 3), (3, 0, -3)), grey)
    s.mesh("crate", box(-0.5, 0, -0.5, 0.5, 1, 0.5, bottom=False), grey)
    s.light("lamp", "point", 200.0, translation=(1.2, 2.0, 0.7))
    s.write(os.path.join(out, "box-floor-T.gltf"))


def slab(out):
    s = Scene()
    grey = s.material("grey", GREY)
    s.mesh("ground", quad((-10, 0, -10), (-10, 0, 10), (10, 0, 10), (10, 0, -10)), grey)
    s.mesh("room_walls", open_top(-3, 0, -3, 3, 3, 3), grey)
    s.mesh("room_walls_in", open_top(-2.9, 0, -2.9, 2.9, 2.98, 2.9, inward=True), grey)
    s.mesh("ceiling_slab", box(-3, 2.98, -3, 3, 3.0, 3), grey)       # 2 cm
    s.mesh("roof", box(-5, 3.02, -5, 5, 3.07, 5), grey)              # 5 cm, 2 cm above
    s.light("sun", "directional", 1000.0, rotation=[-0.3826834, 0, 0, 0.9238795])
    s.write(os.path.join(out, "slab.gltf"))


def courtyard(out):
    s = Scene()
    grey = s.material("grey", GREY)
    s.mesh("ground", quad((-6, 0, -6), (-6, 0, 6), (6, 0, 6), (6, 0, -6)), grey)
    s.mesh("yard_walls", open_top(-6, 0, -6, 6, 4, 6, inward=True), grey)
    t = 0.05
    s.mesh("hut_out", box(-1.5, 0, -1.5, 1.5, 3, 1.5, bottom=False), grey)
    s.mesh("hut_in", box(-1.5 + t, 0, -1.5 + t, 1.5 - t, 3 - t, 1.5 - t, inward=True, bottom=False), grey)
    s.light("sun", "directional", 1000.0, rotation=[-0.2588190, 0, 0.0, 0.9659258])  # 30 deg off zenith
    s.write(os.path.join(out, "courtyard.gltf"))


# scene -> (dark box (min, max) that must read 0, lit box to compare with, dark side's wall plane
# (axis, coordinate, sign: + when the dark side is above it), at SCALE 1
def leak_scenes():
    w, h, d = ROOM
    out = {}
    for t_cm in WALLS_CM:
        t = t_cm / 100.0
        out["two-rooms-%d" % t_cm] = ((t / 2, 0, -d / 2), (w + t / 2, h, d / 2),
                                      (-w - t / 2, 0, -d / 2), (-t / 2, h, d / 2), (0, t / 2, 1))
    # the floor inside the crate, but for the texels dilated under its walls for filtering (2 rings,
    # texels/dilate.h) at the coarsest density the suite bakes (4 cm texels)
    out["box-floor-T"] = ((-0.37, 0, -0.37), (0.37, 0.999, 0.37), (-3, 0, -3), (3, 0, 3), None)
    out["slab"] = ((-2.9, 0, -2.9), (2.9, 2.98, 2.9), (-10, 0, -10), (10, 0, 10), None)
    out["courtyard"] = ((-1.45, 0, -1.45), (1.45, 2.95, 1.45), (-6, 0, -6), (6, 0, 6), None)
    return out


LEAK_SCENES = leak_scenes()


def main():
    out = sys.argv[1]
    scale = float(sys.argv[2]) if len(sys.argv) > 2 else 1.0
    os.makedirs(out, exist_ok=True)
    for t_cm in WALLS_CM:
        two_rooms(out, t_cm, scale)
    corridor(out)
    box_floor(out)
    slab(out)
    courtyard(out)


if __name__ == "__main__":
    main()
