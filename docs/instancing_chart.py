#!/usr/bin/python3
"""Instancing against flattening (docs/architecture.md, "Geometry and instances"): render seconds
and peak memory against the number of copies, per backend, from renderer/bench/instancing_sweep.sh's
CSV.

    /usr/bin/python3 docs/instancing_chart.py OUT/instancing.csv -o docs/data/instancing.png
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("-o", "--output", required=True)
    args = ap.parse_args()
    rows = list(csv.DictReader(open(args.csv, newline="")))
    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(10, 4))
    styles = {("instanced", "embree"): "C0-o", ("instanced", "bvh"): "C1-o",
              ("flattened", "embree"): "C0--s", ("flattened", "bvh"): "C1--s"}
    for (mode, backend), style in styles.items():
        sel = sorted((int(r["copies"]), r) for r in rows if r["mode"] == mode and r["backend"] == backend)
        if not sel:
            continue
        x = [c for c, _ in sel]
        label = f"{backend}, {mode}"
        ax_t.plot(x, [float(r["build_s"]) + float(r["render_s"]) for _, r in sel], style, label=label)
        ax_m.plot(x, [float(r["peak_mb"]) for _, r in sel], style, label=label)
    for ax, title in ((ax_t, "build + render seconds (320x180, 4 spp)"), (ax_m, "peak memory (MB)")):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("copies of a 71k-triangle mesh")
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.tight_layout()
    fig.savefig(args.output, dpi=90)


if __name__ == "__main__":
    main()
