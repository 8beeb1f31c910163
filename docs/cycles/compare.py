#!/usr/bin/python3
"""pt against Blender Cycles 3.4 on one scene: the time pt needs to reach the error Cycles reaches
at 64 spp, as a fraction of Cycles' time.

    /usr/bin/python3 docs/cycles/compare.py scenes/mirror-room [--rounds 3] [--max-depth 12]
        [--res 256] [--cycles-spp 64] [--ref-spp 4096] [--pt PATH] [--pt-arg=--flag ...] [--csv OUT]

Needs Debian's `blender` (Cycles 3.4) and `python3-openimageio` (apt-get install blender
python3-openimageio; neither is needed to build or test pt) and a Release build of pt.

1. Reference: a Cycles render at --ref-spp (4096) and --res x --res, made once by
   docs/cycles/pt_scene.py with seed 1000003 and kept in build/refs/cycles-<scene>-<res>-d<depth>.exr.
2. Rounds, alternating the two renderers so that machine load hits both alike:
   - Cycles at --cycles-spp (seed = round): its RMSE against the reference, and its own timings
     from the EXR metadata: render = path tracing only; sync = scene export + BVH build.
     `wall` is the whole blender process (start-up, Python scene building, sync, render, write).
   - `pt bench converge SCENE --reference REF --res --max-depth --min-spp 2 --max-spp 256
     --seed round`: pt's RMSE against the same reference at doubling spp, each a render from
     sample 0, timed as render() only (no scene loading or BVH build).
   - pt's time to Cycles' error: log(time) interpolated linearly in log(RMSE) between the two
     converge rows that bracket Cycles' RMSE of that round. ratio = that time / Cycles' render time
     (render only against render only).
   - Whole process, for the record: `pt render --spp S` timed as a process (load, BVH build,
     render, EXR write) at the spp S interpolated in the same way, against blender's wall time.
   - CPU time, the figure a shared machine disturbs least: the CPU seconds (user + system) of the
     whole process at S (pt) or --cycles-spp (Cycles) less those of the same process at 1 spp, so
     start-up, scene export and BVH build cancel; ratio_cpu = pt's difference / Cycles'. Both
     renderers run on --threads threads, so CPU seconds measure the same work wall time would on an
     idle machine.
3. Bias check: pt's MSE at its largest spp minus the reference's own noise (Cycles' 64-spp MSE / 65:
   its noise is that of 4096/64 = 64 times as many samples) bounds from above the squared
   difference between the images the two renderers converge to (a floor under pt's error); it is
   printed as a share of Cycles' 64-spp MSE. (The film's per-pixel variance is no estimate of pt's
   own noise here: with Owen-scrambled Sobol points the error falls faster than variance / n.)

Every RMSE is over all pixels and the R, G, B channels of the linear images.
"""
import argparse
import csv
import math
import os
import re
import resource
import shlex
import subprocess
import sys
import tempfile
import time

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "docs", "cycles", "pt_scene.py")


def read_rgb(path):
    buf = oiio.ImageBuf(path)
    spec = buf.spec()
    names = list(spec.channelnames)
    px = buf.get_pixels(oiio.FLOAT)
    rgb = np.stack([px[:, :, names.index(c)] for c in "RGB"], axis=-1).astype(np.float64)
    meta = {a.name: a.value for a in spec.extra_attribs}
    return rgb, meta


def seconds(text):
    """Cycles' "MM:SS.ss" (or "HH:MM:SS.ss") as seconds."""
    parts = [float(p) for p in text.split(":")]
    s = 0.0
    for p in parts:
        s = s * 60 + p
    return s


def cycles_timing(meta, key):
    for name, value in meta.items():
        if name.startswith("cycles.") and name.endswith("." + key):
            return seconds(value)
    raise RuntimeError("no cycles.*.%s in the EXR metadata" % key)


def run_timed(cmd):
    """Runs cmd; returns (completed process, wall seconds, CPU seconds of the child)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return p, wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def run_cycles(scene, out, spp, width, height, depth, seed, threads=0):
    cmd = ["blender", "-b", "-noaudio", "--factory-startup", "-P", SCRIPT, "--", scene, out, str(spp), str(width),
           str(height), str(depth), str(seed)]
    if threads:
        cmd[1:1] = ["-t", str(threads)]
    p, wall, cpu = run_timed(cmd)
    if p.returncode != 0 or not os.path.exists(out):
        sys.exit("compare.py: blender failed:\n" + p.stdout[-2000:] + p.stderr[-2000:])
    return wall, cpu


def rmse(a, b):
    return math.sqrt(np.mean((a - b) ** 2))


def interpolate(rows, target, key):
    """log(key) at log(rmse) = log(target) between the bracketing rows; extrapolated past the last
    two rows when pt never got there (flagged)."""
    for i, r in enumerate(rows):
        if r["rmse"] <= target:
            if i == 0:
                return rows[0][key], "below-first"
            a, b = rows[i - 1], r
            break
    else:
        a, b = rows[-2], rows[-1]
    f = (math.log(target) - math.log(a["rmse"])) / (math.log(b["rmse"]) - math.log(a["rmse"]))
    value = math.exp(math.log(a[key]) + f * (math.log(b[key]) - math.log(a[key])))
    return value, ("extrapolated" if rows[-1]["rmse"] > target else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--max-depth", type=int, default=None, help="pt's max depth (default: the scene's, else 8)")
    ap.add_argument("--res", default="256", help="N (N x N) or WxH (default 256)")
    ap.add_argument("--cycles-spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--min-spp", type=int, default=2)
    ap.add_argument("--max-spp", type=int, default=256)
    ap.add_argument("--pt", action="append", default=[],
                    help="LABEL=PATH [OPTION ...] of a pt binary and options of its own (repeat to compare several in the "
                         "same rounds; default pt=build/renderer/pt)")
    ap.add_argument("--pt-arg", action="append", default=[], help="extra pt option, e.g. --pt-arg=--rr=next-hit")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--csv", default=None, help="append one row per round here")
    a = ap.parse_args()
    try:
        w_h = [int(x) for x in a.res.lower().split("x")]
        a.width, a.height = (w_h[0], w_h[0]) if len(w_h) == 1 else tuple(w_h)
    except ValueError:
        sys.exit("compare.py: --res %s: expected N or WxH" % a.res)
    res_name = "%d" % a.width if a.width == a.height else "%dx%d" % (a.width, a.height)

    scene_json = a.scene if a.scene.endswith(".json") else os.path.join(a.scene, "scene.json")
    name = os.path.basename(os.path.dirname(os.path.abspath(scene_json)))
    if os.path.basename(scene_json) != "scene.json":  # a view of the scene: scenes/hex-room/centre.json
        name += "-" + os.path.splitext(os.path.basename(scene_json))[0]
    depth = a.max_depth
    if depth is None:
        import json
        depth = json.load(open(scene_json)).get("render", {}).get("max_depth", 8)
    refs = os.path.join(ROOT, "build", "refs")
    os.makedirs(refs, exist_ok=True)
    ref_path = os.path.join(refs, "cycles-%s-%s-d%d.exr" % (name, res_name, depth))
    if not os.path.exists(ref_path):
        print("making the Cycles reference %s (%d spp)..." % (ref_path, a.ref_spp), flush=True)
        tmp = ref_path + ".part.exr"
        wall, _ = run_cycles(a.scene, tmp, a.ref_spp, a.width, a.height, depth, 1000003)
        os.replace(tmp, ref_path)
        print("  %.0f s" % wall, flush=True)
    ref, ref_meta = read_rgb(ref_path)
    # The reference's own sample count (a reference made earlier may have another than --ref-spp).
    ref_spp = int(next((v for k, v in ref_meta.items() if k.startswith("cycles.") and k.endswith(".samples")), a.ref_spp))

    print("scene %s, %dx%d, pt max depth %d (Cycles max bounces %d), Cycles %d spp against a %d-spp Cycles reference, "
          "%d rounds; pt options %s" % (name, a.width, a.height, depth, depth - 1, a.cycles_spp, ref_spp, a.rounds,
                                        " ".join(a.pt_arg) or "(defaults)"), flush=True)
    pts = []
    for x in a.pt:
        label, cmd = x.split("=", 1)
        words = shlex.split(cmd)
        pts.append((label, words[0], words[1:]))
    pts = pts or [("pt", os.path.join(ROOT, "build", "renderer", "pt"), [])]
    hdr = "%5s %-9s %10s %9s %8s %8s | %10s %9s %9s %8s | %8s %8s | %7s %7s %7s" % (
        "round", "pt", "cy rmse", "cy render", "cy sync", "cy wall", "pt spp*", "pt render", "ratio", "flag", "pt proc",
        "ratio", "cy cpu", "pt cpu", "ratio")
    print(hdr, flush=True)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for rnd in range(1, a.rounds + 1):
            cy_path = os.path.join(tmp, "cycles.exr")
            cy_wall, cy_cpu = run_cycles(a.scene, cy_path, a.cycles_spp, a.width, a.height, depth, rnd, a.threads)
            _, cy_cpu1 = run_cycles(a.scene, os.path.join(tmp, "cycles1.exr"), 1, a.width, a.height, depth, rnd, a.threads)
            cy_img, meta = read_rgb(cy_path)
            cy_rmse = rmse(cy_img, ref)
            cy_render, cy_sync = cycles_timing(meta, "render_time"), cycles_timing(meta, "synchronization_time")

            for label, binary, own_args in pts:
                conv_csv = os.path.join(tmp, "converge.csv")
                cmd = [binary, "bench", "converge", a.scene, "--reference", ref_path, "--res", "%dx%d" % (a.width, a.height),
                       "--max-depth", str(depth), "--min-spp", str(a.min_spp), "--max-spp", str(a.max_spp), "--seed",
                       str(rnd), "--threads", str(a.threads), "--csv", conv_csv, "-q"] + a.pt_arg + own_args
                p = subprocess.run(cmd, capture_output=True, text=True)
                if p.returncode != 0:
                    sys.exit("compare.py: pt bench converge failed:\n" + p.stderr[-2000:])
                rows = []
                with open(conv_csv) as f:
                    for r in csv.DictReader(f):
                        rows.append({"spp": float(r["spp"]), "seconds": float(r["seconds"]), "rmse": float(r["rmse"]),
                                     "film_var": float(r["film_var"]), "rays": float(r["rays"])})
                pt_time, flag = interpolate(rows, cy_rmse, "seconds")
                pt_spp, _ = interpolate(rows, cy_rmse, "spp")

                # The whole process at that sample count (rounded up), for the record.
                spp_int = max(1, int(math.ceil(pt_spp)))
                out = os.path.join(tmp, "pt.exr")

                def pt_render(spp):
                    cmd = [binary, "render", a.scene, "--res", "%dx%d" % (a.width, a.height), "--max-depth", str(depth),
                           "--spp", str(spp), "--seed", str(rnd), "--threads", str(a.threads), "-o", out, "-q"] + \
                        [x for x in a.pt_arg + own_args if not x.startswith("--reference")]
                    p, wall, cpu = run_timed(cmd)
                    if p.returncode != 0:
                        sys.exit("compare.py: pt render failed:\n" + p.stderr[-2000:])
                    return wall, cpu

                pt_proc, pt_cpu = pt_render(spp_int)
                _, pt_cpu1 = pt_render(1)

                last = rows[-1]
                ref_var = cy_rmse ** 2 / (ref_spp / a.cycles_spp + 1)
                excess = last["rmse"] ** 2 - ref_var
                r = dict(scene=name, label=label, round=rnd, res=res_name, max_depth=depth, cycles_spp=a.cycles_spp,
                         cycles_rmse=cy_rmse, cycles_render_s=cy_render, cycles_sync_s=cy_sync, cycles_wall_s=cy_wall,
                         pt_spp=pt_spp, pt_render_s=pt_time, ratio_render=pt_time / cy_render, flag=flag,
                         pt_process_s=pt_proc, ratio_process=pt_proc / cy_wall,
                         cycles_cpu_s=cy_cpu - cy_cpu1, pt_cpu_s=pt_cpu - pt_cpu1,
                         ratio_cpu=(pt_cpu - pt_cpu1) / max(1e-9, cy_cpu - cy_cpu1), pt_max_spp_rmse=last["rmse"],
                         pt_excess_mse=excess, pt_args=" ".join(a.pt_arg + own_args))
                results.append(r)
                print("%5d %-9s %10.3e %9.2f %8.2f %8.2f | %10.1f %9.2f %9.3f %8s | %8.2f %8.3f | %7.2f %7.2f %7.3f" % (
                    rnd, label[:9], cy_rmse, cy_render, cy_sync, cy_wall, pt_spp, pt_time, r["ratio_render"], flag, pt_proc,
                    r["ratio_process"], r["cycles_cpu_s"], r["pt_cpu_s"], r["ratio_cpu"]), flush=True)
    for label, _, _ in pts:
        mine = [r for r in results if r["label"] == label]
        ratios = sorted(r["ratio_render"] for r in mine)
        proc = sorted(r["ratio_process"] for r in mine)
        cpu = sorted(r["ratio_cpu"] for r in mine)
        med = lambda v: v[len(v) // 2] if len(v) % 2 else 0.5 * (v[len(v) // 2 - 1] + v[len(v) // 2])
        print("%s: pt time to Cycles' %d-spp error / Cycles' time: render only median %.3f (range %.3f-%.3f); "
              "whole process median %.3f (range %.3f-%.3f); CPU time median %.3f (range %.3f-%.3f)" % (
                  label, a.cycles_spp, med(ratios), ratios[0], ratios[-1], med(proc), proc[0], proc[-1], med(cpu), cpu[0],
                  cpu[-1]))
    last = results[-1]
    print("bias check (%s): pt at %d spp RMSE %.3e; its MSE less the reference's noise %.2e "
          "(%.1f%% of Cycles' %d-spp MSE): an upper bound on the squared bias" % (last["label"], a.max_spp, last["pt_max_spp_rmse"], last["pt_excess_mse"],
                                              100 * last["pt_excess_mse"] / last["cycles_rmse"] ** 2, a.cycles_spp))
    if a.csv:
        new = not os.path.exists(a.csv)
        with open(a.csv, "a", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(results[0].keys()))
            if new:
                w.writeheader()
            w.writerows(results)


if __name__ == "__main__":
    main()
