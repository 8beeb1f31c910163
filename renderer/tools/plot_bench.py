#!/usr/bin/python3
"""Charts from the CSV files of `pt bench` (the C++ writes numbers, this draws them).

    /usr/bin/python3 renderer/tools/plot_bench.py FILE.csv [-o OUT.png] [--title TEXT]

The kind of CSV is recognised from its header:
  pt bench converge  -> RMSE against wall time on log-log axes, one line per configuration, with
                        the ideal 1/sqrt(N) slope, and an efficiency table 1 / (MSE x time)
                        printed as Markdown (and written beside the chart as OUT.md);
  pt bench rays      -> bars of Mrays/s per ray kind and backend, single- and multi-threaded;
  pt bench stability -> failures against distance from the origin, one line per method and variant.

Needs Debian's python3-matplotlib (apt-get install python3-matplotlib); no other package.
"""
import argparse
import csv
import math
import os
import sys
from collections import OrderedDict, defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: no rows")
    return rows


def converge(rows, out, title):
    cases = OrderedDict()
    for r in rows:
        cases.setdefault(r["case"] or os.path.basename(r["scene"]), []).append(r)
    fig, axes = plt.subplots(1, len(cases), figsize=(7 * len(cases), 5.2), squeeze=False)
    table = []
    for ax, (case, rs) in zip(axes[0], cases.items()):
        configs = OrderedDict()
        for r in rs:
            configs.setdefault(r["config"], []).append(r)
        anchor = None
        for config, cr in configs.items():
            cr.sort(key=lambda r: int(r["spp"]))
            t = [float(r["seconds"]) for r in cr]
            e = [float(r["rmse"]) for r in cr]
            ax.loglog(t, e, "o-", ms=3, label=config)
            if anchor is None or e[0] > anchor[1]:
                anchor = (t[0], e[0])
            last = cr[-1]
            mse, sec = float(last["mse"]), float(last["seconds"])
            slope = ""
            if len(cr) >= 3:
                # Least-squares slope of log RMSE against log spp: -0.5 is Monte Carlo's rate.
                xs = [math.log(int(r["spp"])) for r in cr]
                ys = [math.log(max(float(r["rmse"]), 1e-30)) for r in cr]
                mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
                slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
                slope = f"{slope:.2f}"
            table.append((case, config, int(last["spp"]), sec, float(last["rmse"]), slope,
                          1.0 / (mse * sec) if mse > 0 and sec > 0 else float("inf")))
        if anchor:
            t0, e0 = anchor
            tmax = max(float(r["seconds"]) for r in rs)
            ax.loglog([t0, tmax], [e0, e0 * math.sqrt(t0 / tmax)], "k--", lw=1, label="ideal 1/sqrt(N)")
        ax.set_xlabel("wall time (s)")
        ax.set_ylabel("RMSE against the reference")
        # "reference" is the case of every scene measured against an EXR: the title says enough.
        ax.set_title(title or "error vs time" if case == "reference" else f"{title or 'error vs time'}: {case}")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    md = ["| case | configuration | spp | time (s) | RMSE | slope | efficiency 1/(MSE·s) |",
          "|---|---|---:|---:|---:|---:|---:|"]
    for case, config, spp, sec, rmse, slope, eff in sorted(table, key=lambda x: (x[0], -x[6])):
        md.append(f"| {case} | {config} | {spp} | {sec:.3f} | {rmse:.4g} | {slope} | {eff:.4g} |")
    text = "\n".join(md)
    print(text)
    with open(os.path.splitext(out)[0] + ".md", "w") as f:
        f.write(text + "\n")


def rays(rows, out, title):
    speed = [r for r in rows if r["metric"] == "mrays_per_s"]
    groups = sorted({(r["kind"], int(r["threads"])) for r in speed}, key=lambda g: (g[1], g[0]))
    labels = [f"{k}\n{t} thread{'s' if t > 1 else ''}" for k, t in groups]
    value = {(r["kind"], int(r["threads"])): r for r in speed}
    backends = [b for b in ("embree", "bvh") if any(r[b] for r in speed)]
    fig, ax = plt.subplots(figsize=(1.3 * len(groups) + 3, 4.5))
    width = 0.8 / max(1, len(backends))
    for i, b in enumerate(backends):
        xs = [j + (i - (len(backends) - 1) / 2) * width for j in range(len(groups))]
        ys = [float(value[g][b]) if value[g][b] else 0.0 for g in groups]
        bars = ax.bar(xs, ys, width, label=b)
        if b == "bvh":
            for bar, g in zip(bars, groups):
                ratio = value[g]["bvh_over_embree_time"]
                if ratio:
                    ax.annotate(f"{float(ratio):.2f}x", (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                                ha="center", va="bottom", fontsize=7)
    ax.set_xticks(range(len(groups)))
    ax.set_xticklabels(labels, fontsize=8)
    ax.set_ylabel("Mrays/s (higher is better)")
    ax.set_title((title or "ray throughput") + "  (labels: BVH time / Embree time)")
    ax.legend()
    ax.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def stability_keys(r):
    """(panel, colour, line style) of a row: the thing measured, what is compared, the method."""
    test, variant, method = r["test"], r["variant"], r["method"]
    if "/" in variant:
        first, second = variant.split("/", 1)
        if test == "sphere":  # r=0.01/wrong-answer: a panel per kind of error, a colour per radius
            return f"{test}: {second}", first, method
        return f"{test}: {first}", second, method  # triangles/scaled: a colour per offset
    if test == "leaks":  # a colour per method, edges and vertices as line styles
        return test, method, variant
    return test, variant, method  # grazing: a colour per angle


def stability(rows, out, title):
    panels = OrderedDict()
    for r in rows:
        if float(r["distance"] or 0) > 0 and int(r["trials"]) > 0:
            panel, colour, style = stability_keys(r)
            panels.setdefault(panel, defaultdict(list))[(colour, style)].append(
                (float(r["distance"]), int(r["failures"]) / int(r["trials"])))
    if not panels:
        sys.exit("no rows with a distance to chart")
    cols = min(3, len(panels))
    nrows = (len(panels) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(6 * cols, 4.4 * nrows), squeeze=False)
    styles = ["-", "--", ":", "-."]
    markers = ["o", "s", "^", "v"]
    for ax, (panel, lines) in zip(axes.flat, panels.items()):
        colours = sorted({c for c, _ in lines})
        methods = sorted({m for _, m in lines})
        for (colour, method), pts in sorted(lines.items()):
            pts.sort()
            ci, mi = colours.index(colour), methods.index(method)
            # Zero failures are drawn at a floor so that they show on log axes.
            ax.loglog([p[0] for p in pts], [max(p[1], 1e-4) for p in pts], ls=styles[mi % 4],
                      marker=markers[mi % 4], ms=4 + 2 * (len(methods) - mi), mfc="none",
                      color=f"C{ci}", label=f"{colour} / {method}")
        ax.axhline(1e-4, color="k", lw=0.5, ls=":")
        ax.set_ylim(5e-5, 1.5)
        ax.set_xlabel("distance of the geometry from the origin")
        ax.set_ylabel("failure rate (at 1e-4: none)")
        ax.set_title(f"{title + ': ' if title else ''}{panel}")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, ncol=2)
    for ax in list(axes.flat)[len(panels):]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv")
    ap.add_argument("-o", "--output", help="PNG to write (default: the CSV's name with .png)")
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    rows = read(a.csv)
    out = a.output or os.path.splitext(a.csv)[0] + ".png"
    header = rows[0].keys()
    if "rmse" in header and "spp" in header:
        converge(rows, out, a.title)
    elif "metric" in header and "bvh_over_embree_time" in header:
        rays(rows, out, a.title)
    elif "failures" in header and "distance" in header:
        stability(rows, out, a.title)
    else:
        sys.exit(f"{a.csv}: not a CSV written by pt bench (header: {', '.join(header)})")
    print(f"wrote {out}", file=sys.stderr)


if __name__ == "__main__":
    main()
