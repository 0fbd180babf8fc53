#!/usr/bin/env python3
"""Error against render time for the min-weight sweep of `whitted bench skip` (docs/performance.md).

Usage: python3 scripts/plot_skip.py skip.csv skip_min_weight.png

One panel per scene: linear RMSE against min_weight 0 (log scale) over the median render time,
each point labelled with its min_weight; the specialised min_weight 0 run is the reference (RMSE 0,
drawn at the bottom of the axis).
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(path, out):
    rows = defaultdict(list)
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if r["variant"] in ("specialised", "min_weight"):
                rows[r["scene"]].append(r)
    scenes = sorted(rows)
    if not scenes:
        print("plot_skip: no rows")
        return 1
    cols = min(3, len(scenes))
    nrows = (len(scenes) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(5 * cols, 3.8 * nrows), squeeze=False)
    for ax, scene in zip(axes.flat, scenes):
        pts = sorted(rows[scene], key=lambda r: float(r["min_weight"]))
        floor = 1e-7
        xs = [float(r["median_s"]) * 1e3 for r in pts]
        ys = [max(float(r["rmse_linear"]), floor) for r in pts]
        ax.plot(xs, ys, "o-")
        for r, x, y in zip(pts, xs, ys):
            ax.annotate(f'{float(r["min_weight"]):.2g}', (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
        ax.axhline(1e-3, color="grey", linestyle="--", linewidth=0.8)
        ax.set_yscale("log")
        ax.set_xlabel(f"median render time [ms, {pts[0].get('clock', 'wall')}]")
        ax.set_ylabel("RMSE vs min_weight 0 (linear)")
        ax.set_title(scene, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    for ax in list(axes.flat)[len(scenes):]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        print(__doc__)
        sys.exit(2)
    sys.exit(main(sys.argv[1], sys.argv[2]))
