#!/usr/bin/python3
"""The horizon checkerboard (scenes/horizon) chart of docs/textures.md: RMSE against a 16384-spp
reference at each sample count, MIP-mapped against bilinear lookups, from `pt bench converge` CSVs
(each may hold several runs: RMSE is their mean, time the fastest).

    /usr/bin/python3 docs/textures_chart.py MIPMAP.csv BILINEAR.csv -o docs/data/textures-horizon.png
"""
import argparse
import csv
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    rmse, seconds = defaultdict(list), defaultdict(list)
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            spp = int(r["spp"])
            rmse[spp].append(float(r["rmse"]))
            seconds[spp].append(float(r["seconds"]))
    spp = sorted(rmse)
    return spp, [sum(rmse[s]) / len(rmse[s]) for s in spp], [min(seconds[s]) for s in spp]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mipmap")
    ap.add_argument("bilinear")
    ap.add_argument("-o", "--out", default="textures-horizon.png")
    a = ap.parse_args()
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.6))
    for path, label in ((a.mipmap, "mipmap (ray footprint)"), (a.bilinear, "bilinear (finest level)")):
        spp, rmse, seconds = read(path)
        left.plot(spp, rmse, "o-", label=label)
        right.plot(seconds, rmse, "o-", label=label)
    for ax in (left, right):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylabel("RMSE against the bilinear 16k-spp reference")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    left.set_xlabel("samples per pixel")
    right.set_xlabel("render seconds, 1 thread (fastest of 6 alternating runs)")
    fig.suptitle("scenes/horizon at 384x216: a checkerboard plane to the horizon")
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)
    print(a.out)


if __name__ == "__main__":
    main()
