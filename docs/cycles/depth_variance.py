#!/usr/bin/python3
"""Per-bounce variance of pt and Cycles: each renderer's variance per sample of images truncated
at max depth d (pt's --max-depth d; Cycles' max bounces d - 1), from the spread over seeds.

    /usr/bin/python3 docs/cycles/depth_variance.py scenes/hex-room/centre.json --depths 1,2,3,4,12 \
        [--seeds 4] [--spp 32] [--res 256] [--pt build/renderer/pt] [--pt-arg=--flag ...]

For each d it prints both renderers' variance per sample (the mean over pixels and R, G, B of the
variance between seeds, times spp) and pt's over Cycles'; with --blocks it also prints that ratio
per 32 x 32 block. The variance of an unbiased render is its MSE, so a ratio r at depth d means pt
needs r times Cycles' samples for the same error in the paths up to d bounces (with Sobol points
the error falls faster than 1/spp, so compare at equal spp). Needs blender and python3-openimageio
(docs/cycles.md).
"""
import argparse
import os
import subprocess
import tempfile

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def read(path):
    return oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--depths", default="1,2,3,12")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--res", type=int, default=256)
    ap.add_argument("--pt", default=os.path.join(ROOT, "build", "renderer", "pt"))
    ap.add_argument("--pt-arg", action="append", default=[])
    ap.add_argument("--blocks", action="store_true", help="print pt/Cycles per 32x32 block too")
    a = ap.parse_args()
    script = os.path.join(ROOT, "docs", "cycles", "pt_scene.py")
    with tempfile.TemporaryDirectory() as tmp:
        for d in (int(x) for x in a.depths.split(",")):
            var = {}
            for who in ("cycles", "pt"):
                imgs = []
                for s in range(1, a.seeds + 1):
                    out = os.path.join(tmp, "%s.exr" % who)
                    if who == "cycles":
                        cmd = ["blender", "-b", "-noaudio", "--factory-startup", "-P", script, "--", a.scene, out, str(a.spp),
                               str(a.res), str(a.res), str(d), str(s)]
                    else:
                        cmd = [a.pt, "render", a.scene, "--res", "%dx%d" % (a.res, a.res), "--spp", str(a.spp), "--max-depth",
                               str(d), "--seed", str(s), "-o", out, "-q"] + a.pt_arg
                    subprocess.run(cmd, capture_output=True, check=True)
                    imgs.append(read(out))
                var[who] = np.stack(imgs).var(0, ddof=1).mean(-1) * a.spp  # per pixel, per sample
            c, p = var["cycles"].mean(), var["pt"].mean()
            print("depth %2d: variance per sample Cycles %.4e, pt %.4e, pt/Cycles %.3f" % (d, c, p, p / c), flush=True)
            if a.blocks:
                b = 32
                h, w = var["pt"].shape
                blk = lambda v: v[:h - h % b, :w - w % b].reshape(h // b, b, w // b, b).sum((1, 3))
                with np.errstate(invalid="ignore", divide="ignore"):
                    print(np.array2string(blk(var["pt"]) / blk(var["cycles"]), precision=2, max_line_width=200))


if __name__ == "__main__":
    main()
