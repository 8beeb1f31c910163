#!/usr/bin/python3
"""The cost of splitting a frame into parts (pt render --part K/N), measured on this machine, and
what it projects for a cluster. Every figure comes from running the real `pt` as separate
processes, one part after another, as N nodes would run them (each with all this machine's cores).

    # 1. Overhead: the one-machine render, then the N parts and their merge, side by side per N.
    /usr/bin/python3 renderer/bench/split_cost.py measure --scene scenes/cornell-box --res 512x512 \\
        --spp 512 --parts 1,2,4,8,16 --csv docs/data/split_measure.csv
    # 2. Fixed costs and render rates at 1920x1080 (Cornell box and scenes/dense), and the merge
    #    cost, for the projection to 10 and 100 nodes.
    /usr/bin/python3 renderer/bench/split_cost.py project --csv docs/data/split_project.csv
    # 3. The chart (and a Markdown table beside it).
    /usr/bin/python3 renderer/bench/split_cost.py chart docs/data/split_measure.csv \\
        docs/data/split_project.csv -o docs/data/split_cost.png

A part's wall time is split into what `pt render --timing` reports (load, build, render, write:
hashing the inputs and writing the EXR) and the rest, "start" (exec, dynamic loading, parsing);
its fixed cost is everything but render. The overhead of a split is (sum of the parts' wall times
- the one-machine wall time) / the one-machine wall time; the merge is reported beside it.

The projection for N nodes (one part per node, parts in parallel, then the merge):
    T(1) = F1 + W / r          T(N) = F(N) + u(N) * W / (N r) + M(N)        speed-up = T(1) / T(N)
W = width x height x spp samples, r = samples per second of one node (measured here), F1 and F(N)
the fixed costs of a whole render and of one part, u the load imbalance (slowest part's render
over the mean, measured at N = 16 and taken as holding at 10 and 100), M(N) = a + b N the merge
(fitted to merges of 2 and 8 parts). Scheduling latency and the shared filesystem are not in it.

Needs Debian's python3-matplotlib; no other package.
"""
import argparse
import csv
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict

FIELDS = ["scene", "res", "spp", "split", "parts", "kind", "index", "wall", "cpu", "start", "load", "build", "render",
          "write"]
TIMING = re.compile(r"pt: timing: load ([\d.]+) build ([\d.]+) render ([\d.]+) write ([\d.]+) seconds")


def run(cmd):
    """Runs a pt command; returns (wall seconds, CPU seconds (user + system), its timing line's
    numbers or None). CPU time is what a busy shared machine disturbs least."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if p.returncode != 0:
        sys.exit("split_cost: failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stderr))
    m = TIMING.search(p.stderr)
    return (wall, cpu), (tuple(float(x) for x in m.groups()) if m else None)


def row(scene, res, spp, split, parts, kind, index, times, timing):
    wall, cpu = times
    load, build, render, write = timing if timing else (0.0, 0.0, 0.0, 0.0)
    return dict(scene=scene, res=res, spp=spp, split=split, parts=parts, kind=kind, index=index, wall="%.4f" % wall,
                cpu="%.4f" % cpu,
                start="%.4f" % max(0.0, wall - load - build - render - write), load="%.4f" % load,
                build="%.4f" % build, render="%.4f" % render, write="%.4f" % write)


def render_cmd(args, scene, res, spp, out, extra=()):
    cmd = [args.pt, "render", scene, "--res", res, "--spp", str(spp), "-q", "--timing", "-o", out]
    if args.threads:
        cmd += ["--threads", str(args.threads)]
    return cmd + list(extra)


def split_parts(args, writer, work, scene, res, spp, split, n):
    """Renders the n parts one after another, then merges them; returns the rows."""
    rows, paths = [], []
    for k in range(n):
        path = os.path.join(work, "part%d.exr" % k)
        times, timing = run(render_cmd(args, scene, res, spp, path, ["--part", "%d/%d" % (k, n), "--split", split]))
        rows.append(row(scene, res, spp, split, n, "part", k, times, timing))
        paths.append(path)
    times, _ = run([args.pt, "merge", *paths, "-q", "-o", os.path.join(work, "merged.exr")])
    rows.append(row(scene, res, spp, split, n, "merge", 0, times, None))
    for p in paths:
        os.remove(p)
    for r in rows:
        writer.writerow(r)
    return rows


def measure(args):
    parts = [int(x) for x in args.parts.split(",")]
    splits = args.split.split(",")
    with tempfile.TemporaryDirectory(prefix="pt-split-", dir=args.dir) as work, open(args.csv, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        writer.writeheader()
        for n in parts:
            # A/B side by side: the one-machine render right before each N's parts.
            times, timing = run(render_cmd(args, args.scene, args.res, args.spp, os.path.join(work, "one.exr")))
            one = row(args.scene, args.res, args.spp, "", 1, "one", 0, times, timing)
            writer.writerow(one)
            for split in splits:
                rows = split_parts(args, writer, work, args.scene, args.res, args.spp, split, n)
                f.flush()
                prt = [r for r in rows if r["kind"] == "part"]
                total = sum(float(r["wall"]) for r in prt)
                cpu = sum(float(r["cpu"]) for r in prt)
                fixed = statistics.mean(float(r["wall"]) - float(r["render"]) for r in prt)
                print("N=%-3d %-8s one %.2f s, parts %.2f s: overhead %+.1f%% (CPU time %+.1f%%), fixed %.3f s/part, "
                      "merge %.2f s" % (n, split, float(one["wall"]), total, 100 * (total / float(one["wall"]) - 1),
                                        100 * (cpu / float(one["cpu"]) - 1), fixed, float(rows[-1]["wall"])), flush=True)


def project(args):
    scenes = [("cornell", args.cornell), ("dense", args.dense)]
    res, big_spp = args.res, 100  # a part of 1/100 of the samples takes one sample per pixel
    with tempfile.TemporaryDirectory(prefix="pt-split-", dir=args.dir) as work, open(args.csv, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        writer.writeheader()
        for name, scene in scenes:
            if not os.path.exists(scene):
                sys.exit("split_cost: %s not found (scenes/dense/dense.obj: build/renderer/pt gen dense "
                         "scenes/dense/dense.obj)" % scene)
            for rep in range(args.repeat):
                # The whole render's fixed cost and the render rate: one sample per pixel, whole frame.
                times, timing = run(render_cmd(args, scene, res, 1, os.path.join(work, "one.exr")))
                writer.writerow(row(name, res, 1, "", 1, "one", rep, times, timing))
                # One part at N = 10 and 100: its fixed cost (regions write only their tiles; a
                # sample part writes the whole frame's sums).
                for n in (10, 100):
                    for split in ("regions", "samples"):
                        spp = big_spp if split == "samples" else 1
                        extra = ["--part", "0/%d" % n, "--split", split]
                        if split == "samples":
                            extra[1] = "0/%d" % big_spp  # one sample per pixel; the file is the same for any N
                        times, timing = run(render_cmd(args, scene, res, spp, os.path.join(work, "p.exr"), extra))
                        writer.writerow(row(name, res, spp, split, n, "part", rep, times, timing))
                f.flush()
            # The merge: 2 and 8 parts of each split (Cornell only: it reads files, not scenes).
            if name != "cornell":
                continue
            for split in ("regions", "samples"):
                for n in (2, 8):
                    spp = n if split == "samples" else 1
                    paths = []
                    for k in range(n):
                        path = os.path.join(work, "m%d.exr" % k)
                        run(render_cmd(args, scene, res, spp, path, ["--part", "%d/%d" % (k, n), "--split", split]))
                        paths.append(path)
                    for rep in range(args.repeat):
                        times, _ = run([args.pt, "merge", *paths, "-q", "-o", os.path.join(work, "merged.exr")])
                        writer.writerow(row(name, res, spp, split, n, "merge", rep, times, None))
                    for p in paths:
                        os.remove(p)
                    f.flush()
    print("wrote", args.csv)


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def best(rows, key):
    """Best of the repeats (the least disturbed run on a shared machine)."""
    return min(float(r[key]) for r in rows)


def projection(measured, projected):
    """Speed-up on N nodes for each scene and split at 1920x1080 x 1024 spp; returns (curves, notes)."""
    by = defaultdict(list)
    for r in projected:
        by[(r["scene"], r["split"], r["parts"], r["kind"])].append(r)
    # Load imbalance from the measured runs at the largest N.
    u = {}
    n_max = max(int(r["parts"]) for r in measured)
    for split in ("regions", "samples"):
        renders = [float(r["render"]) for r in measured if r["kind"] == "part" and r["split"] == split and int(r["parts"]) == n_max]
        u[split] = max(renders) / statistics.mean(renders) if renders else 1.0
    # Merge a + b N from the 2- and 8-part merges.
    merge = {}
    for split in ("regions", "samples"):
        m2, m8 = best(by[("cornell", split, "2", "merge")], "wall"), best(by[("cornell", split, "8", "merge")], "wall")
        b = (m8 - m2) / 6
        merge[split] = (m2 - 2 * b, b)
    curves, table = {}, []
    w, h = (int(v) for v in projected[0]["res"].split("x"))
    pixels, spp = w * h, 1024
    for scene in ("cornell", "dense"):
        one = by[(scene, "", "1", "one")]
        rate = pixels / best(one, "render")  # samples per second of one node
        f1 = min(float(r["wall"]) - float(r["render"]) for r in one)
        t1 = f1 + pixels * spp / rate
        for split in ("regions", "samples"):
            fixed = {n: min(float(r["wall"]) - float(r["render"]) for r in by[(scene, split, str(n), "part")]) for n in (10, 100)}
            a, b = merge[split]
            xs, ys = [], []
            for n in range(1, 101):
                fn = fixed[10] if n <= 10 else fixed[10] + (fixed[100] - fixed[10]) * (n - 10) / 90
                tn = t1 if n == 1 else fn + u[split] * pixels * spp / (n * rate) + max(0.0, a + b * n)
                xs.append(n)
                ys.append(t1 / tn)
            curves[(scene, split)] = (xs, ys)
            table.append((scene, split, rate / 1e6, f1, fixed[10], fixed[100], u[split], a + b * 10, a + b * 100, t1,
                          ys[9], ys[99]))
    return curves, table


def chart(args):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    measured, projected = read(args.measure), read(args.project)
    fig, axes = plt.subplots(1, 3, figsize=(19, 5.4))
    # 1. Overhead against N, in wall time and in CPU time (what a shared machine disturbs least).
    ax = axes[0]
    groups = defaultdict(list)
    # Pair each N's parts with the one-machine run just before them.
    last_one = None
    for r in measured:
        if r["kind"] == "one":
            last_one = r
        elif r["kind"] == "part":
            groups[(r["split"], int(r["parts"]))].append((r, last_one))
    lines = []
    for split, colour in (("regions", "tab:blue"), ("samples", "tab:orange")):
        ns = sorted(n for s, n in groups if s == split)
        if not ns:
            continue
        over = {}
        for key, ls in (("wall", "-"), ("cpu", "--")):
            over[key] = [100 * (sum(float(p[key]) for p, _ in groups[(split, n)]) / float(groups[(split, n)][0][1][key]) - 1)
                         for n in ns]
            ax.plot(ns, over[key], "o" + ls, color=colour, label="%s (%s time)" % (split, "wall" if key == "wall" else "CPU"))
        for n, o, c in zip(ns, over["wall"], over["cpu"]):
            lines.append((split, n, o, c))
    ax.axhline(5, color="grey", ls="--", lw=1, label="5%")
    ax.axhline(0, color="black", lw=0.5)
    ax.set_xscale("log", base=2)
    ax.set_xticks([1, 2, 4, 8, 16])
    ax.set_xticklabels(["1", "2", "4", "8", "16"])
    one_wall = statistics.mean(float(r["wall"]) for r in measured if r["kind"] == "one")
    one_cpu = statistics.mean(float(r["cpu"]) for r in measured if r["kind"] == "one")
    m0 = measured[0]
    ax.set_title("Overhead of N parts: sum of part times / one machine - 1\n%s %s %s spp, one machine %.0f s (%.0f CPU-s)"
                 % (os.path.basename(m0["scene"].rstrip("/")), m0["res"], m0["spp"], one_wall, one_cpu))
    ax.set_xlabel("parts N")
    ax.set_ylabel("overhead (%)")
    ax.legend()
    # 2. Where a part's time goes, at each N (regions), stacked.
    ax = axes[1]
    keys = ["start", "load", "build", "write"]
    colours = ["tab:grey", "tab:green", "tab:purple", "tab:red"]
    xs = []
    for split in ("regions", "samples"):
        for n in sorted(n for s, n in groups if s == split):
            parts = [r for r in measured if r["kind"] == "part" and r["split"] == split and int(r["parts"]) == n]
            xs.append(("%s\nN=%d" % (split[0], n), {k: statistics.mean(float(r[k]) for r in parts) for k in keys + ["render"]}))
    bottom = [0.0] * len(xs)
    for k, c in zip(keys, colours):
        vals = [v[k] for _, v in xs]
        ax.bar(range(len(xs)), vals, bottom=bottom, color=c, label=k)
        bottom = [b + v for b, v in zip(bottom, vals)]
    for i, (_, v) in enumerate(xs):
        ax.text(i, bottom[i], "%.2f s\nrender\n%.1f s" % (bottom[i], v["render"]), ha="center", va="bottom", fontsize=7)
    ax.set_xticks(range(len(xs)))
    ax.set_xticklabels([x for x, _ in xs], fontsize=8)
    ax.set_ylabel("fixed seconds per part (mean)")
    ax.set_title("Fixed cost per part (r = regions, s = samples),\nwith each part's render time above")
    ax.set_ylim(0, max(bottom) * 1.45)
    ax.legend(fontsize=8)
    # 3. Projection.
    ax = axes[2]
    curves, table = projection(measured, projected)
    styles = {("cornell", "regions"): ("tab:blue", "-"), ("cornell", "samples"): ("tab:blue", "--"),
              ("dense", "regions"): ("tab:red", "-"), ("dense", "samples"): ("tab:red", "--")}
    for key, (xs_, ys_) in curves.items():
        colour, ls = styles[key]
        ax.plot(xs_, ys_, color=colour, ls=ls, label="%s, %s" % key)
        for n in (10, 100):
            ax.plot([n], [ys_[n - 1]], "o", color=colour)
            ax.annotate("%.1f" % ys_[n - 1], (n, ys_[n - 1]), textcoords="offset points", xytext=(4, -10), fontsize=8)
    ax.plot([1, 100], [1, 100], color="grey", lw=0.8, ls=":", label="ideal")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("nodes (one part each)")
    ax.set_ylabel("speed-up over one node")
    ax.set_title("Projected speed-up, %s x 1024 spp\n(Cornell box; dense: 1.3 M triangles)" % projected[0]["res"])
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.output, dpi=110)
    md = os.path.splitext(args.output)[0] + ".md"
    with open(md, "w") as f:
        f.write("| split | N | overhead (wall time) | overhead (CPU time) |\n|---|---|---|---|\n")
        for split, n, o, c in lines:
            f.write("| %s | %d | %+.1f%% | %+.1f%% |\n" % (split, n, o, c))
        f.write("\n| scene | split | Msamples/s/node | fixed one (s) | fixed part N=10 (s) | N=100 (s) | imbalance "
                "| merge N=10 (s) | N=100 (s) | one node (s) | speed-up 10 | speed-up 100 |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|\n")
        for t in table:
            f.write("| %s | %s | %.2f | %.2f | %.2f | %.2f | %.3f | %.2f | %.2f | %.0f | %.1f | %.1f |\n" % t)
    print("wrote", args.output, "and", md)
    with open(md) as f:
        print(f.read())


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.normpath(os.path.join(here, "..", ".."))
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    for name in ("measure", "project"):
        s = sub.add_parser(name)
        s.add_argument("--pt", default=os.path.join(root, "build", "renderer", "pt"))
        s.add_argument("--threads", type=int, default=0, help="pt --threads (default: all cores)")
        s.add_argument("--dir", default=None, help="where the parts go (default: the system temp folder)")
        s.add_argument("--csv", required=True)
    m = sub.choices["measure"]
    m.add_argument("--scene", default=os.path.join(root, "scenes", "cornell-box"))
    m.add_argument("--res", default="512x512")
    m.add_argument("--spp", type=int, default=512)
    m.add_argument("--parts", default="1,2,4,8,16")
    m.add_argument("--split", default="regions,samples")
    pr = sub.choices["project"]
    pr.add_argument("--cornell", default=os.path.join(root, "scenes", "cornell-box"))
    pr.add_argument("--dense", default=os.path.join(root, "scenes", "dense"))
    pr.add_argument("--repeat", type=int, default=3, help="best of this many runs")
    pr.add_argument("--res", default="1920x1080", help="the frame the projection is for")
    c = sub.add_parser("chart")
    c.add_argument("measure")
    c.add_argument("project")
    c.add_argument("-o", "--output", required=True)
    args = p.parse_args()
    {"measure": measure, "project": project, "chart": chart}[args.command](args)


if __name__ == "__main__":
    main()
