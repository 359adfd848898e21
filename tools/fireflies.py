#!/usr/bin/env python3
"""Counts fireflies in baked lightmaps: valid texels brighter (luminance) than 4x the median of
the valid texels in their 5x5 neighbourhood (issue 14's measure).

usage: fireflies.py BAKE_OUT_DIR [--list N]
Valid texels come from the -mask.png (output.formats: [exr, mask]) when there is one, else
every texel whose EXR value is not exactly 0. Prints one line per atlas and the total.
"""
import os
import sys

import numpy as np
import OpenImageIO as oiio


def read(path):
    inp = oiio.ImageInput.open(path)
    img = inp.read_image("float")
    inp.close()
    return img


def fireflies(exr, mask=None, factor=4.0, radius=2):
    """[(x, y, luminance, neighbourhood median)] of the atlas's outliers."""
    lum = 0.2126 * exr[..., 0] + 0.7152 * exr[..., 1] + 0.0722 * exr[..., 2]
    valid = (mask > 0.9) if mask is not None else (lum != 0)
    h, w = lum.shape
    pad = np.pad(np.where(valid, lum, np.nan), radius, constant_values=np.nan)
    windows = np.lib.stride_tricks.sliding_window_view(pad, (2 * radius + 1, 2 * radius + 1))
    flat = windows.reshape(h, w, -1)
    centre = (2 * radius + 1) * radius + radius
    others = np.delete(flat, centre, axis=2)
    with np.errstate(all="ignore"):
        med = np.nanmedian(others, axis=2)
    out = valid & np.isfinite(med) & (lum > factor * med)
    ys, xs = np.nonzero(out)
    return [(int(x), int(y), float(lum[y, x]), float(med[y, x])) for y, x in zip(ys, xs)]


def main():
    out = sys.argv[1]
    show = int(sys.argv[sys.argv.index("--list") + 1]) if "--list" in sys.argv else 0
    total, texels = 0, 0
    for f in sorted(os.listdir(out)):
        if not f.endswith(".exr") or f.endswith("-dir.exr"):
            continue
        exr = read(os.path.join(out, f))[..., :3]
        mpath = os.path.join(out, f[:-4] + "-mask.png")
        mask = read(mpath)[..., 0] if os.path.exists(mpath) else None
        found = fireflies(exr, mask)
        n = int(((mask > 0.9) if mask is not None else (exr.sum(axis=2) != 0)).sum())
        print("%s: %d fireflies among %d valid texels" % (f, len(found), n))
        for x, y, l, m in sorted(found, key=lambda t: -t[2] / max(t[3], 1e-30))[:show]:
            print("  (%d, %d): %.4g, %.1fx the median around it" % (x, y, l, l / max(m, 1e-30)))
        total += len(found)
        texels += n
    print("total: %d fireflies among %d valid texels" % (total, texels))


if __name__ == "__main__":
    main()
