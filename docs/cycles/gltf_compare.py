#!/usr/bin/python3
"""pt against Blender Cycles 3.4 on a glTF file under an HDRI: where the two images differ.

    /usr/bin/python3 docs/cycles/gltf_compare.py FILE.gltf|.glb [--env HDRI] [--env-rotate DEG]
        [--env-strength S] [--res 320x240] [--spp 256] [--ref-spp 1024] [--max-depth 8] [--grid 4]
        [--pt PATH] [--label NAME] [--png OUT.png] [--masks]
    /usr/bin/python3 docs/cycles/gltf_compare.py --envcheck [--pt PATH]

Needs Debian's `blender` (Cycles 3.4), python3-openimageio and numpy, and a Release build of pt.

1. Reference: Cycles at --ref-spp through docs/cycles/gltf_scene.py (Blender's glTF importer,
   Principled BSDF set to Multiscatter GGX, the HDRI turned to pt's mapping), kept in build/refs/.
2. pt: `pt render FILE --env HDRI --env-rotate --env-strength --res --spp --max-depth`, twice with
   seeds 1 and 2. Their difference gives pt's own noise: RMSE(pt1, pt2) / sqrt(2).
3. Printed: the relative difference of the image means, (pt - Cycles) / Cycles, of the luminance
   (Rec. 709) over the whole image and over each block of a --grid x --grid partition; the RMSE of
   pt against Cycles over R, G, B of all pixels, absolute and as a share of each image's mean; and the
   part of that RMSE that noise does not explain, sqrt(max(0, RMSE^2 - noise_pt^2 - noise_ref^2)),
   with noise_ref = noise_pt * sqrt(spp / ref-spp) (the same kind of estimator, more samples).
4. A PNG (default docs/data/gltf-cycles-<label>.png): pt | Cycles | relative difference of the
   luminance, red where pt is brighter, blue where darker, full colour at 50%; the images
   tone-mapped by clamping and the sRGB curve, the block grid drawn on the difference.

--masks also prints the relative difference of the luminance means over each material's pixels: a
mask image from gltf_scene.py --masks (16 spp; only pixels wholly on one material count), cached.

--envcheck renders scenes/gltf-cycles/envcheck.glb (the sky alone) under scenes/gltf-cycles/bands.exr
at several turns, direct light only, in both renderers, and prints the mean absolute difference per
turn. A control pairs pt's map turned by 90 degrees more than Cycles': the check can fail.
"""
import argparse
import json
import math
import os
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "docs", "cycles", "gltf_scene.py")
LUM = np.array([0.2126, 0.7152, 0.0722])


def read_rgb(path):
    buf = oiio.ImageBuf(path)
    names = list(buf.spec().channelnames)
    px = buf.get_pixels(oiio.FLOAT)
    return np.stack([px[:, :, names.index(c)] for c in "RGB"], axis=-1).astype(np.float64)


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode != 0:
        sys.exit("gltf_compare.py: failed (%d): %s\n%s" % (r.returncode, " ".join(cmd), r.stdout[-3000:]))
    return r.stdout


def cycles(path, env, out, spp, w, h, depth, rotate, strength):
    if not os.path.exists(out):
        os.makedirs(os.path.dirname(out), exist_ok=True)
        run(["blender", "-b", "-noaudio", "--factory-startup", "-P", SCRIPT, "--", path, env, out + ".tmp.exr",
             str(spp), str(w), str(h), str(depth), repr(rotate), repr(strength)])
        os.replace(out + ".tmp.exr", out)
    return read_rgb(out)


def pt(binary, path, env, out, spp, w, h, depth, rotate, strength, seed):
    # Path traced as Cycles is: a bare model's default integrator is direct lighting.
    run([binary, "render", path, "--env", env, "--env-rotate", repr(rotate), "--env-strength", repr(strength),
         "--integrator", "path", "--res", "%dx%d" % (w, h), "--spp", str(spp), "--max-depth", str(depth), "--seed", str(seed),
         "--threads", "2", "-o", out])
    return read_rgb(out)


def srgb8(x):
    x = np.clip(x, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def write_png(path, a, b, grid):
    la, lb = a @ LUM, b @ LUM
    rel = (la - lb) / np.maximum(lb, 1e-3)
    t = np.clip(np.abs(rel) / 0.5, 0, 1)[..., None]
    diff = np.where(rel[..., None] > 0, np.array([1.0, 0.1, 0.1]), np.array([0.1, 0.3, 1.0])) * t
    h, w = la.shape
    for k in range(1, grid):
        diff[k * h // grid, :] = 0.5
        diff[:, k * w // grid] = 0.5
    gap = np.ones((h, 4, 3))
    img = np.concatenate([srgb8(a), gap, srgb8(b), gap, np.power(diff, 1 / 2.2)], axis=1)
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    buf = oiio.ImageBuf(np.ascontiguousarray(img.astype(np.float32)))
    buf.set_write_format(oiio.UINT8)
    buf.write(path)


def compare(o):
    w, h = (int(x) for x in o.res.split("x"))
    stem = os.path.splitext(os.path.basename(o.file))[0]
    env_stem = os.path.splitext(os.path.basename(o.env))[0]
    label = o.label or stem
    ref_path = os.path.join(ROOT, "build", "refs", "cycles-gltf-%s-%s-%dx%d-d%d-s%d-r%g-k%g.exr" % (
        stem, env_stem, w, h, o.max_depth, o.ref_spp, o.env_rotate, o.env_strength))
    ref = cycles(o.file, o.env, ref_path, o.ref_spp, w, h, o.max_depth, o.env_rotate, o.env_strength)
    tmp = os.path.join(ROOT, "build", "refs", "pt-gltf-%s" % label)
    a = pt(o.pt, o.file, o.env, tmp + "-1.exr", o.spp, w, h, o.max_depth, o.env_rotate, o.env_strength, 1)
    a2 = pt(o.pt, o.file, o.env, tmp + "-2.exr", o.spp, w, h, o.max_depth, o.env_rotate, o.env_strength, 2)
    if a.shape != ref.shape:
        sys.exit("gltf_compare.py: pt's image is %s, Cycles' %s" % (a.shape[:2], ref.shape[:2]))
    la, lr = a @ LUM, ref @ LUM
    print("%s: pt %s (%d spp, seeds 1 and 2) against Cycles 3.4 (%d spp), %dx%d, max depth %d, env %s "
          "rotate %g strength %g" % (label, o.pt, o.spp, o.ref_spp, w, h, o.max_depth, o.env, o.env_rotate,
                                     o.env_strength))
    print("mean luminance: pt %.5f  Cycles %.5f  relative difference %+.2f%%" % (
        la.mean(), lr.mean(), 100 * (la.mean() / lr.mean() - 1)))
    rmse = math.sqrt(np.mean((a - ref) ** 2))
    noise = math.sqrt(np.mean((a - a2) ** 2) / 2)
    noise_ref = noise * math.sqrt(o.spp / o.ref_spp)
    print("RMSE pt vs Cycles %.5f = %.2f%% of Cycles' mean, %.2f%% of pt's; pt's noise %.5f, Cycles' ~%.5f; "
          "unexplained by noise %.5f (%.2f%% of Cycles' mean)" % (
              rmse, 100 * rmse / ref.mean(), 100 * rmse / a.mean(), noise, noise_ref,
              math.sqrt(max(0.0, rmse ** 2 - noise ** 2 - noise_ref ** 2)),
              100 * math.sqrt(max(0.0, rmse ** 2 - noise ** 2 - noise_ref ** 2)) / ref.mean()))
    g = o.grid
    print("block means, (pt - Cycles) / Cycles in %, row 0 at the top:")
    for by in range(g):
        cells = []
        for bx in range(g):
            ys, xs = slice(by * h // g, (by + 1) * h // g), slice(bx * w // g, (bx + 1) * w // g)
            cells.append("%+6.1f" % (100 * (la[ys, xs].mean() / max(lr[ys, xs].mean(), 1e-9) - 1)))
        print("  " + " ".join(cells))
    if o.masks:
        mask_path = os.path.join(ROOT, "build", "refs", "mask-gltf-%s-%dx%d.exr" % (stem, w, h))
        if not os.path.exists(mask_path):
            run(["blender", "-b", "-noaudio", "--factory-startup", "-P", SCRIPT, "--", o.file, o.env, mask_path,
                 "16", str(w), str(h), "1", "0", "0", "--masks"])
        ids = read_rgb(mask_path)[:, :, 0]
        names = json.load(open(os.path.splitext(mask_path)[0] + ".json"))
        whole = np.abs(ids - np.round(ids)) < 1e-3
        print("per material, (pt - Cycles) / Cycles of the mean luminance over its pixels:")
        for i, name in sorted(names.items(), key=lambda kv: int(kv[0])):
            sel = whole & (np.round(ids) == int(i))
            if sel.sum() == 0:
                continue
            print("  %-24s %6d px  pt %.4f  Cycles %.4f  %+6.1f%%" % (
                name, sel.sum(), la[sel].mean(), lr[sel].mean(), 100 * (la[sel].mean() / lr[sel].mean() - 1)))
    png = o.png or os.path.join(ROOT, "docs", "data", "gltf-cycles-%s.png" % label)
    write_png(png, a, ref, g)
    print("wrote %s (pt | Cycles | relative difference: red pt brighter, blue darker, full at 50%%)" % png)


def envcheck(o):
    glb = os.path.join(ROOT, "scenes", "gltf-cycles", "envcheck.glb")
    env = os.path.join(ROOT, "scenes", "gltf-cycles", "bands.exr")
    tmp = os.path.join(ROOT, "build", "refs")
    os.makedirs(tmp, exist_ok=True)
    worst = 0.0
    for rot in (0.0, 90.0, 217.0, -45.0):
        c = cycles(glb, env, os.path.join(tmp, "cycles-envcheck-r%g.exr" % rot), 16, 160, 120, 1, rot, 1.0)
        p = pt(o.pt, glb, env, os.path.join(tmp, "pt-envcheck.exr"), 16, 160, 120, 1, rot, 1.0, 1)
        d = np.abs(p - c).mean() / c.mean()
        worst = max(worst, d)
        print("env-rotate %6.1f: mean |pt - Cycles| / mean Cycles = %.4f" % (rot, d))
    p = pt(o.pt, glb, env, os.path.join(tmp, "pt-envcheck.exr"), 16, 160, 120, 1, 90.0, 1.0, 1)
    c = read_rgb(os.path.join(tmp, "cycles-envcheck-r0.exr"))
    ctrl = np.abs(p - c).mean() / c.mean()
    print("control, pt turned 90 degrees more than Cycles: %.4f" % ctrl)
    ok = worst < 0.02 and ctrl > 0.2
    print("envcheck %s (each turn below 0.02, the control above 0.2)" % ("PASSED" if ok else "FAILED"))
    return 0 if ok else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("file", nargs="?")
    ap.add_argument("--envcheck", action="store_true")
    ap.add_argument("--env", default=os.path.join(ROOT, "scenes", "gltf-cycles", "courtyard.exr"))
    ap.add_argument("--env-rotate", type=float, default=0.0)
    ap.add_argument("--env-strength", type=float, default=1.0)
    ap.add_argument("--res", default="320x240")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--grid", type=int, default=4)
    ap.add_argument("--pt", default=os.path.join(ROOT, "build", "renderer", "pt"))
    ap.add_argument("--label")
    ap.add_argument("--png")
    ap.add_argument("--masks", action="store_true")
    o = ap.parse_args()
    if o.envcheck:
        return envcheck(o)
    if not o.file:
        ap.error("a glTF file, or --envcheck")
    compare(o)
    return 0


if __name__ == "__main__":
    sys.exit(main())
