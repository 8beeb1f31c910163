#!/usr/bin/python3
"""Where the error is: the MSE of images against a reference, split by what each pixel sees first.

    /usr/bin/python3 docs/cycles/pixel_classes.py REF.exr --aov AOV.exr IMAGE.exr ...
    /usr/bin/python3 docs/cycles/pixel_classes.py REF.exr --luminance IMAGE.exr ...

--aov: classes from a pt render with `--aov albedo,normal` at the same resolution (e.g.
`pt render scenes/hex-room/centre.json --res 256x256 --spp 4 --aov albedo,normal -o aov.exr`):
pixels whose first hit is a mirror (albedo 0.95, the rooms' mirrors), split into the flat mirror
(the most common normal among them) and curved ones; emitters (albedo 0); the rest diffuse.
--luminance: classes by the reference's luminance: emitters seen directly (> 2), lit surfaces
(0.3-2), dark surfaces (< 0.3), as in docs/light-tree.md.
For each image: the MSE (mean over pixels and R, G, B) of each class and its share of the total.
"""
import argparse

import numpy as np
import OpenImageIO as oiio


def read(path):
    b = oiio.ImageBuf(path)
    px = b.get_pixels(oiio.FLOAT)
    return {c: px[:, :, i].astype(np.float64) for i, c in enumerate(b.spec().channelnames)}


def rgb(channels, prefix=""):
    return np.stack([channels[prefix + c] for c in "RGB"], -1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reference")
    ap.add_argument("images", nargs="+")
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--aov")
    g.add_argument("--luminance", action="store_true")
    a = ap.parse_args()
    ref = rgb(read(a.reference))
    if a.aov:
        aov = read(a.aov)
        albedo = rgb(aov, "albedo.")
        n = np.stack([aov["N." + c] for c in "XYZ"], -1)
        mirror = np.abs(albedo - 0.95).max(-1) < 0.02
        normals, counts = np.unique(np.round(n[mirror], 3), axis=0, return_counts=True)
        flat = mirror & (np.abs(n - normals[counts.argmax()]).max(-1) < 0.01) if mirror.any() else mirror
        emitter = np.abs(albedo).max(-1) < 0.01
        classes = {"flat mirror": flat, "curved mirror": mirror & ~flat, "emitter": emitter,
                   "diffuse": ~mirror & ~emitter}
    else:
        lum = ref.mean(-1)
        classes = {"emitters (>2)": lum > 2, "lit (0.3-2)": (lum >= 0.3) & (lum <= 2), "dark (<0.3)": lum < 0.3}
    print("pixels: " + ", ".join("%s %d" % (k, m.sum()) for k, m in classes.items()))
    for path in a.images:
        se = ((rgb(read(path)) - ref) ** 2).mean(-1)
        total = se.sum()
        print("%s: MSE %.4e; " % (path, se.mean()) + "; ".join(
            "%s %.4e (%.0f%%)" % (k, se[m].mean() if m.any() else 0.0, 100 * se[m].sum() / total) for k, m in classes.items()))


if __name__ == "__main__":
    main()
